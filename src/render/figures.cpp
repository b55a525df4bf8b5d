#include "evcorner/render/figures.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace evcorner::render {

namespace {
Rgb grey(int v) {
    const auto g = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
    return {g, g, g};
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

}  // namespace evcorner::render
