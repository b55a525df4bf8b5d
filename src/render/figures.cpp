#include "evcorner/render/figures.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

namespace evcorner::render {

namespace {
Rgb grey(int v) {
    const auto g = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
    return {g, g, g};
}

// A track sample's time in microseconds, none where it cannot be one (|t| of 9e12 s and more).
std::optional<std::int64_t> micros(double seconds) {
    if (!(std::abs(seconds) < 9e12)) return std::nullopt;
    return std::llround(seconds * 1e6);
}

// The sample's time in microseconds when render_tracks draws it: in (at - trail_us, at].
std::optional<std::int64_t> drawn_time(const TrackPoint& p, std::int64_t at, const TracksStyle& s) {
    const auto t = micros(p.t);
    if (t && *t <= at && *t > at - s.trail_us) return t;
    return std::nullopt;
}

// Liang-Barsky: the part of segment (x0, y0)-(x1, y1) inside [lo_x, hi_x] x [lo_y, hi_y],
// in place; false when none of it is.
bool clip_segment(double& x0, double& y0, double& x1, double& y1, double lo_x, double lo_y, double hi_x,
                  double hi_y) noexcept {
    const double dx = x1 - x0, dy = y1 - y0;
    double a = 0, b = 1;
    auto edge = [&](double p, double q) {
        if (p == 0) return q >= 0;
        const double r = q / p;
        if (p < 0) {
            if (r > b) return false;
            a = std::max(a, r);
        } else {
            if (r < a) return false;
            b = std::min(b, r);
        }
        return true;
    };
    if (!edge(-dx, x0 - lo_x) || !edge(dx, hi_x - x0) || !edge(-dy, y0 - lo_y) || !edge(dy, hi_y - y0)) return false;
    const double sx = x0, sy = y0;
    x0 = sx + a * dx;
    y0 = sy + a * dy;
    x1 = sx + b * dx;
    y1 = sy + b * dy;
    return true;
}
}  // namespace

RgbImage render_sae(std::span<const Event> events, SensorSize size, int polarity, std::int64_t at,
                    std::int64_t window_us) {
    if (window_us <= 0) throw std::invalid_argument("SAE figure: window must be > 0");
    std::vector<std::int64_t> sae(static_cast<std::size_t>(size.pixels()), INT64_MIN);
    for (const Event& e : events) {
        if (e.t > at) break;
        if (e.p == polarity && size.contains(e)) sae[static_cast<std::size_t>(e.y) * size.width + e.x] = e.t;
    }
    RgbImage img(size.width, size.height);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const std::int64_t t = sae[static_cast<std::size_t>(y) * size.width + x];
            if (t == INT64_MIN || at - t >= window_us) continue;
            const double age = static_cast<double>(at - t) / static_cast<double>(window_us);
            img.set(x, y, grey(static_cast<int>(std::lround(255.0 * (1.0 - age)))));
        }
    return img;
}

RgbImage render_recent_corners(std::span<const Event> events, std::span<const Event> corners, SensorSize size,
                               std::int64_t at, const RecentCornersStyle& s) {
    RgbImage img(size.width, size.height);
    for (const Event& e : events)
        if (e.t <= at && at - e.t < s.events_window_us) img.set(e.x, e.y, grey(150));
    const int half = s.corner_side / 2;
    // Older (dark) first, so the recent (bright) ones stay on top.
    for (int pass = 0; pass < 2; ++pass)
        for (const Event& c : corners) {
            if (c.t > at) continue;
            const std::int64_t age = at - c.t;
            const bool recent = age < s.recent_us;
            if (age >= s.older_us || recent != (pass == 1)) continue;
            const Rgb colour = c.p ? (recent ? kOnBright : kOnDark) : (recent ? kOffBright : kOffDark);
            img.fill_square(c.x - half, c.y - half, s.corner_side, colour);
        }
    return img;
}

void SpaceTimeLayout::project(double x, double y, double tau, int& u, int& v) const noexcept {
    const double k = style.scale;
    u = margin + static_cast<int>(std::lround(k * (x + style.depth * (size.height - 1 - y))));
    v = margin + static_cast<int>(std::lround(k * (style.time_height * (1.0 - tau) + style.depth * y)));
}

SpaceTimeLayout space_time_layout(SensorSize size, const SpaceTimeStyle& s) {
    if (s.scale < 1 || s.time_height < 1) throw std::invalid_argument("space-time figure: bad style");
    SpaceTimeLayout l;
    l.size = size;
    l.style = s;
    const double k = s.scale;
    const double depth_px = s.depth * size.height;
    l.margin = 4 * s.scale;
    l.width = static_cast<int>(std::ceil(k * (size.width + depth_px))) + 2 * l.margin;
    l.height = static_cast<int>(std::ceil(k * (s.time_height + depth_px))) + 2 * l.margin;
    return l;
}

RgbImage render_space_time(std::span<const Event> events, std::span<const Event> corners,
                           std::span<const std::uint8_t> labels, SensorSize size, std::int64_t t0,
                           std::int64_t t1, const SpaceTimeStyle& s) {
    if (t1 <= t0) throw std::invalid_argument("space-time figure: empty interval");
    if (!labels.empty() && labels.size() != corners.size())
        throw std::invalid_argument("space-time figure: one label per corner event needed");
    const SpaceTimeLayout layout = space_time_layout(size, s);
    RgbImage img(layout.width, layout.height, {255, 255, 255});
    const double span = static_cast<double>(t1 - t0);
    auto project = [&](double x, double y, double tau, int& u, int& v) { layout.project(x, y, tau, u, v); };
    const Rgb frame{170, 170, 170};
    const double xs[4] = {0, static_cast<double>(size.width - 1), static_cast<double>(size.width - 1), 0};
    const double ys[4] = {0, 0, static_cast<double>(size.height - 1), static_cast<double>(size.height - 1)};
    for (int i = 0; i < 4; ++i) {
        int u0, v0, u1, v1, u2, v2, u3, v3;
        project(xs[i], ys[i], 0, u0, v0);
        project(xs[(i + 1) % 4], ys[(i + 1) % 4], 0, u1, v1);
        project(xs[i], ys[i], 1, u2, v2);
        project(xs[(i + 1) % 4], ys[(i + 1) % 4], 1, u3, v3);
        img.line(u0, v0, u1, v1, frame);
        img.line(u2, v2, u3, v3, frame);
        img.line(u0, v0, u2, v2, frame);
    }
    const Rgb event_grey{185, 185, 185};
    for (const Event& e : events) {
        if (e.t < t0 || e.t > t1) continue;
        int u, v;
        project(e.x, e.y, static_cast<double>(e.t - t0) / span, u, v);
        img.set(u, v, event_grey);
    }
    const int side = s.corner_side * s.scale;
    for (std::size_t i = 0; i < corners.size(); ++i) {
        const Event& c = corners[i];
        if (c.t < t0 || c.t > t1) continue;
        int u, v;
        project(c.x, c.y, static_cast<double>(c.t - t0) / span, u, v);
        const Rgb colour = labels.empty() ? (c.p ? kOnBright : kOffBright) : (labels[i] ? kOnTrack : kOffTrack);
        img.fill_square(u - side / 2, v - side / 2, side, colour);
    }
    return img;
}

Rgb track_colour(std::uint64_t id) noexcept {
    // Tableau 10 without its grey (events are grey), with a yellow instead.
    static constexpr std::array<Rgb, kTrackPaletteSize> palette{{{31, 119, 180},
                                                                 {255, 127, 14},
                                                                 {44, 160, 44},
                                                                 {214, 39, 40},
                                                                 {148, 103, 189},
                                                                 {140, 86, 75},
                                                                 {227, 119, 194},
                                                                 {188, 189, 34},
                                                                 {23, 190, 207},
                                                                 {255, 221, 0}}};
    return palette[id % palette.size()];
}

RgbImage render_tracks(std::span<const Event> events, std::span<const TrackPoint> tracks, SensorSize size,
                       std::int64_t at, const TracksStyle& s) {
    if (s.scale < 1 || s.line_width < 1 || s.dot_side < 1)
        throw std::invalid_argument("tracks figure: scale, line width and dot side must be >= 1");
    RgbImage sensor(size.width, size.height);
    for (const Event& e : events)
        if (e.t <= at && at - e.t < s.events_window_us) sensor.set(e.x, e.y, grey(150));
    RgbImage img = upscale(sensor, s.scale);

    struct Sample {
        std::uint64_t id;
        std::int64_t t;
        double x, y;
    };
    std::vector<Sample> drawn;
    for (const TrackPoint& p : tracks) {
        if (const auto t = drawn_time(p, at, s)) drawn.push_back({p.id, *t, p.x, p.y});
    }
    std::stable_sort(drawn.begin(), drawn.end(),
                     [](const Sample& a, const Sample& b) { return a.id != b.id ? a.id < b.id : a.t < b.t; });

    // Sample coordinates far beyond any sensor (65535 px) are left out of the segments
    // that reach them, so that nothing below overflows.
    constexpr double kFar = 1e12;
    auto usable = [&](const Sample& p) { return std::abs(p.x) < kFar && std::abs(p.y) < kFar; };
    const double k = s.scale;
    // Top-left of a square brush of side `side` image pixels centred on the sample: on the
    // centre of its pixel, so a brush of one sensor pixel covers exactly that pixel's block,
    // and a dot of 3 the 3x3 block Fig. 6 draws for a corner there.
    auto corner_of = [&](double v, int side) { return (v + 0.5) * k - side / 2.0; };
    auto pixel = [](double v) { return static_cast<int>(std::floor(v + 0.5)); };
    const int line = s.line_width * s.scale, dot = s.dot_side * s.scale;
    for (std::size_t i = 1; i < drawn.size(); ++i) {
        const Sample &a = drawn[i - 1], &b = drawn[i];
        if (a.id != b.id || !usable(a) || !usable(b)) continue;
        double x0 = corner_of(a.x, line), y0 = corner_of(a.y, line), x1 = corner_of(b.x, line),
               y1 = corner_of(b.y, line);
        if (!clip_segment(x0, y0, x1, y1, -line - 1.0, -line - 1.0, img.width() + 1.0, img.height() + 1.0)) continue;
        const Rgb c = track_colour(a.id);
        // Bresenham over the brush's top-left, stamping the brush at every step.
        int u0 = pixel(x0), v0 = pixel(y0);
        const int u1 = pixel(x1), v1 = pixel(y1);
        const int du = std::abs(u1 - u0), dv = -std::abs(v1 - v0);
        const int su = u0 < u1 ? 1 : -1, sv = v0 < v1 ? 1 : -1;
        int err = du + dv;
        for (;;) {
            img.fill_square(u0, v0, line, c);
            if (u0 == u1 && v0 == v1) break;
            const int e2 = 2 * err;
            if (e2 >= dv) {
                err += dv;
                u0 += su;
            }
            if (e2 <= du) {
                err += du;
                v0 += sv;
            }
        }
    }
    // The dots last, on top of every trail.
    for (std::size_t i = 0; i < drawn.size(); ++i) {
        const Sample& p = drawn[i];
        if ((i + 1 < drawn.size() && drawn[i + 1].id == p.id) || !usable(p)) continue;
        const double x = corner_of(p.x, dot), y = corner_of(p.y, dot);
        if (x < -dot || y < -dot || x > img.width() || y > img.height()) continue;
        img.fill_square(pixel(x), pixel(y), dot, track_colour(p.id));
    }
    return img;
}

std::vector<std::uint64_t> drawn_track_ids(std::span<const TrackPoint> tracks, std::int64_t at,
                                           const TracksStyle& style) {
    std::vector<std::uint64_t> ids;
    for (const TrackPoint& p : tracks)
        if (drawn_time(p, at, style)) ids.push_back(p.id);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
}

}  // namespace evcorner::render
