#include "evcorner/render/frame.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>


namespace evcorner::render {

std::vector<double> nice_ticks(double lo, double hi, double min_step) {
    if (!(hi >= lo) || !(min_step > 0) || !std::isfinite(hi - lo))
        throw std::invalid_argument("ticks: need lo <= hi and a step > 0");
    double step = std::pow(10.0, std::floor(std::log10(min_step)));
    for (const double m : {1.0, 2.0, 5.0, 10.0})
        if (m * step >= min_step * (1 - 1e-9)) {
            step *= m;
            break;
        }
    std::vector<double> ticks;
    for (double k = std::ceil(lo / step - 1e-9); k * step <= hi * (1 + 1e-12) + 1e-12; k += 1) ticks.push_back(k * step);
    return ticks;
}

std::string tick_label(double value, double step) {
    const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
    std::string s = fmt::format("{:.{}f}", value, decimals);
    if (s.starts_with('-') && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);  // "-0.0"
    return s;
}

namespace {

// Shared layout arithmetic of both frames, in image pixels, from the font size.
struct Ink {
    double fs;  // font size
    int th;     // height of a line of text
    int line;   // one line of text, with spacing
    int pad;    // around the canvas
    int tick;   // tick length
    int gap;    // between a tick and its label
    int swatch; // a legend colour's side
    int space;  // between legend items
};

Ink ink_for(double fs) {
    const int th = static_cast<int>(std::ceil(text_height(fs)));
    return {fs,
            th,
            static_cast<int>(std::ceil(th * 1.15)),
            static_cast<int>(std::lround(0.8 * fs)),
            std::max(3, static_cast<int>(std::lround(0.35 * fs))),
            std::max(2, static_cast<int>(std::lround(0.3 * fs))),
            std::max(6, static_cast<int>(std::lround(0.75 * fs))),
            static_cast<int>(std::lround(1.2 * fs))};
}

int tw(const std::string& s, const Ink& k) { return static_cast<int>(std::ceil(text_width(s, k.fs))); }

int widest(const std::vector<std::string>& lines, const Ink& k) {
    int w = 0;
    for (const auto& l : lines) w = std::max(w, tw(l, k));
    return w;
}

// An outline one pixel outside the rectangle, so that light swatches show on white.
void outline(Canvas& c, int x, int y, int w, int h) { c.stroke_rect(x - 0.5, y - 0.5, w + 1, h + 1, kAxisInk); }

// The legend's items laid out in rows no wider than `width`; returns the rows' count.
// With a canvas, draws them with the first row's top at y.
int legend_rows(Canvas* c, const FigureFrame& f, const Ink& k, int x0, int y, int width) {
    if (f.legend.empty() && !f.grey_ramp) return 0;
    const int ramp_w = static_cast<int>(std::lround(8 * k.fs));
    const int inner = static_cast<int>(std::lround(0.4 * k.fs));
    int x = x0, rows = 1;
    auto place = [&](int w) {
        if (x > x0 && x + w > x0 + width) {
            x = x0;
            ++rows;
        }
        const int at = x;
        x += w + k.space;
        return at;
    };
    auto row_top = [&] { return y + (rows - 1) * (k.line + inner / 2); };
    for (const LegendEntry& e : f.legend) {
        const int at = place(k.swatch + inner + tw(e.text, k));
        if (!c) continue;
        const int top = row_top();
        const int sy = top + (k.line - k.swatch) / 2;
        c->fill_rect(at, sy, k.swatch, k.swatch, e.colour);
        outline(*c, at, sy, k.swatch, k.swatch);
        c->text(at + k.swatch + inner, top + k.line / 2.0, e.text, k.fs, kFrameInk, Align::left, VAlign::middle);
    }
    if (f.grey_ramp) {
        const std::string& a = f.ramp.white_text;
        const std::string& b = f.ramp.black_text;
        const int cap = tw(f.ramp.caption, k) + inner;
        const int w = cap + tw(a, k) + inner + ramp_w + inner + tw(b, k);
        const int at = place(w);
        if (c) {
            const int top = row_top();
            const double mid = top + k.line / 2.0;
            const int sy = top + (k.line - k.swatch) / 2;
            int u = at;
            c->text(u, mid, f.ramp.caption, k.fs, kFrameInk, Align::left, VAlign::middle);
            u += cap;
            c->text(u, mid, a, k.fs, kFrameInk, Align::left, VAlign::middle);
            u += tw(a, k) + inner;
            RgbImage ramp(ramp_w, k.swatch);
            for (int i = 0; i < ramp_w; ++i) {
                const auto g = static_cast<std::uint8_t>(std::lround(255.0 * (1.0 - static_cast<double>(i) / (ramp_w - 1))));
                ramp.fill_rect(i, 0, 1, k.swatch, {g, g, g});
            }
            c->image(ramp, u, sy);
            outline(*c, u, sy, ramp_w, k.swatch);
            u += ramp_w + inner;
            c->text(u, mid, b, k.fs, kFrameInk, Align::left, VAlign::middle);
        }
    }
    return rows;
}

int legend_height(int rows, const Ink& k) {
    return rows == 0 ? 0 : rows * (k.line + static_cast<int>(std::lround(0.2 * k.fs))) + k.pad / 2;
}

void draw_title(Canvas& c, const FigureFrame& f, const Ink& k) {
    for (std::size_t i = 0; i < f.title.size(); ++i)
        c.text(k.pad, k.pad + static_cast<int>(i) * k.line, f.title[i], k.fs, kFrameInk);
}

int title_height(const FigureFrame& f, const Ink& k) {
    return k.pad + static_cast<int>(f.title.size()) * k.line + k.pad / 2;
}

// Pixel ticks of a sensor side of `n` pixels drawn `scale` image pixels each: at least
// a label's width plus some air apart, and at least three font sizes.
std::vector<double> pixel_ticks(int n, int scale, const Ink& k) {
    const double label_px = tw(std::to_string(n - 1), k) + 1.0 * k.fs;
    return nice_ticks(0, n - 1, std::max(label_px, 3.0 * k.fs) / scale);
}

struct TimeAxis {
    double divisor;  // microseconds per unit
    const char* unit;
};

TimeAxis time_unit_for(std::int64_t span_us) {
    if (span_us < 1000) return {1.0, "us"};
    if (span_us < 10'000'000) return {1000.0, "ms"};
    return {1e6, "s"};
}

// The canvas both frames share: `width` wide, the legend's rows below `legend_top`, the
// title drawn and the body pasted at (left, top).
Framed start_frame(const RgbImage& body, const FigureFrame& f, const Ink& k, int left, int top, int width,
                   int legend_top) {
    const int rows = legend_rows(nullptr, f, k, k.pad, 0, width - 2 * k.pad);
    const int height = legend_top + legend_height(rows, k) + k.pad / 2;
    Framed out{Canvas(width, height, kFrameBackground), left, top, k.fs};
    draw_title(out.figure, f, k);
    out.figure.image(body, left, top);
    return out;
}

// A one-pixel line from the centre of pixel (x0, y0) to that of (x1, y1), both covered.
void pixel_line(Canvas& c, int x0, int y0, int x1, int y1) { c.line(x0 + 0.5, y0 + 0.5, x1 + 0.5, y1 + 0.5, kAxisInk); }

}  // namespace

double auto_text_size(int body_width, int body_height) noexcept {
    const double g = std::sqrt(static_cast<double>(std::max(1, body_width)) * std::max(1, body_height));
    return std::clamp(std::round(g / 50.0), 12.0, 64.0);
}

Framed frame_sensor_figure(const RgbImage& body, SensorSize size, int scale, const FigureFrame& f) {
    if (body.width() != size.width * scale || body.height() != size.height * scale)
        throw std::invalid_argument("sensor figure frame: the body is not the sensor at this scale");
    const Ink k = ink_for(f.text_size > 0 ? f.text_size : auto_text_size(body.width(), body.height()));
    const auto xt = pixel_ticks(size.width, scale, k);
    const auto yt = pixel_ticks(size.height, scale, k);
    int ylab = 0;
    for (const double v : yt) ylab = std::max(ylab, tw(tick_label(v, 1), k));
    const std::string ycap = "y [px]", xcap = "x [px]";
    const int left = k.pad + std::max(ylab + k.gap + k.tick, tw(ycap, k)) + 1;
    const int top = title_height(f, k) + k.line + k.th / 2;  // the y caption's row above the box
    const int last_label = tw(tick_label(xt.back(), 1), k);
    int width = left + body.width() + 1 + std::max(k.pad, last_label / 2 + k.pad / 2);
    width = std::max(width, widest(f.title, k) + 2 * k.pad);
    const int legend_top = top + body.height() + 1 + k.tick + k.gap + 2 * k.line + k.pad / 2;

    Framed out = start_frame(body, f, k, left, top, width, legend_top);
    Canvas& c = out.figure;
    // The axes: a box one pixel outside the body.
    const int x0 = left - 1, y0 = top - 1, x1 = left + body.width(), y1 = top + body.height();
    c.stroke_rect(x0 + 0.5, y0 + 0.5, x1 - x0, y1 - y0, kAxisInk);
    for (const double v : xt) {
        const int u = left + static_cast<int>(v) * scale + scale / 2;
        pixel_line(c, u, y1 + 1, u, y1 + k.tick);
        c.text(u + 0.5, y1 + 1 + k.tick + k.gap, tick_label(v, 1), k.fs, kFrameInk, Align::centre);
    }
    c.text(left + body.width() / 2.0, y1 + 1 + k.tick + k.gap + k.line, xcap, k.fs, kFrameInk, Align::centre);
    for (const double v : yt) {
        const int w = top + static_cast<int>(v) * scale + scale / 2;
        pixel_line(c, x0 - k.tick, w, x0 - 1, w);
        c.text(x0 - k.tick - k.gap, w + 0.5, tick_label(v, 1), k.fs, kFrameInk, Align::right, VAlign::middle);
    }
    c.text(std::max(k.pad, x0 - tw(ycap, k)), top - k.line - k.th / 2, ycap, k.fs, kFrameInk);
    legend_rows(&c, f, k, k.pad, legend_top, width - 2 * k.pad);
    return out;
}

Framed frame_space_time_figure(const RgbImage& body, SensorSize size, std::int64_t t0, std::int64_t t1,
                               const SpaceTimeStyle& style, const FigureFrame& f) {
    if (t1 <= t0) throw std::invalid_argument("space-time frame: empty interval");
    const SpaceTimeLayout lay = space_time_layout(size, style);
    if (body.width() != lay.width || body.height() != lay.height)
        throw std::invalid_argument("space-time frame: the body does not match the layout");
    const Ink k = ink_for(f.text_size > 0 ? f.text_size : auto_text_size(body.width(), body.height()));
    const double kx = style.scale;
    // Time ticks along the front-left edge (x = 0, y = H - 1), in the unit that suits the span.
    const TimeAxis unit = time_unit_for(t1 - t0);
    const double span = static_cast<double>(t1 - t0) / unit.divisor;
    const double time_px = kx * style.time_height;
    const auto tt = nice_ticks(0, span, std::max(1e-9, span * (k.line + 2.0 * k.fs) / time_px));
    const double tstep = tt.size() > 1 ? tt[1] - tt[0] : std::max(span, 1e-9);
    int tlab = 0;
    for (const double v : tt) tlab = std::max(tlab, tw(tick_label(v, tstep), k));
    const std::string tcap = fmt::format("t - t0 [{}]", unit.unit);
    const auto xt = pixel_ticks(size.width, style.scale, k);
    // y along the depth edge: each step moves depth * scale pixels right and up.
    // Labels stack vertically along it: a line of text apart at least.
    const double rise_per_y = std::max(1e-9, style.depth * kx);
    const auto yt = nice_ticks(0, size.height - 1, std::max(1.0, (k.line + 0.4 * k.fs) / rise_per_y));
    int ylab = 0;
    for (const double v : yt) ylab = std::max(ylab, tw(tick_label(v, 1), k));
    const std::string xcap = "x [px]", ycap = "y [px]";

    // The time caption stands left of the time axis's top end, the labels left of its ticks.
    const int left =
        std::max(0, k.pad + std::max(tlab + k.gap, tw(tcap, k) + k.gap) + k.tick - lay.margin);
    const int top = title_height(f, k);
    ylab = std::max(ylab, tw(ycap, k));
    int width = left + body.width() + std::max(k.pad, ylab + k.tick + k.gap + k.pad - lay.margin);
    width = std::max(width, widest(f.title, k) + 2 * k.pad);
    const int legend_top = top + body.height() + k.tick + k.gap + 2 * k.line - lay.margin + k.pad / 2;

    Framed out = start_frame(body, f, k, left, top, width, legend_top);
    Canvas& c = out.figure;
    auto at = [&](double x, double y, double tau, int& u, int& v) {
        lay.project(x, y, tau, u, v);
        u += left;
        v += top;
    };
    const double w1 = size.width - 1, h1 = size.height - 1;
    int ua, va, ub, vb;
    // The three axes over the box's grey edges.
    at(0, h1, 0, ua, va);
    at(w1, h1, 0, ub, vb);
    pixel_line(c, ua, va, ub, vb);  // x
    at(0, h1, 1, ub, vb);
    pixel_line(c, ua, va, ub, vb);  // time
    at(w1, h1, 0, ua, va);
    at(w1, 0, 0, ub, vb);
    pixel_line(c, ua, va, ub, vb);  // y
    for (const double v : xt) {
        int u, w;
        at(v, h1, 0, u, w);
        pixel_line(c, u, w + 1, u, w + k.tick);
        c.text(u + 0.5, w + 1 + k.tick + k.gap, tick_label(v, 1), k.fs, kFrameInk, Align::centre);
    }
    {
        int u, w;
        at(w1 / 2, h1, 0, u, w);
        c.text(u + 0.5, w + 1 + k.tick + k.gap + k.line, xcap, k.fs, kFrameInk, Align::centre);
    }
    for (const double v : tt) {
        int u, w;
        at(0, h1, v / span, u, w);
        pixel_line(c, u - k.tick, w, u - 1, w);
        c.text(u - k.tick - k.gap, w + 0.5, tick_label(v, tstep), k.fs, kFrameInk, Align::right, VAlign::middle);
    }
    {
        int u, w;
        at(0, h1, 1, u, w);
        c.text(u - k.gap, w - k.line / 2.0, tcap, k.fs, kFrameInk, Align::right, VAlign::bottom);
    }
    for (const double v : yt) {
        int u, w;
        at(w1, v, 0, u, w);
        pixel_line(c, u + 1, w, u + k.tick, w);
        c.text(u + 1 + k.tick + k.gap, w + 0.5, tick_label(v, 1), k.fs, kFrameInk, Align::left, VAlign::middle);
    }
    {
        int u, w;
        at(w1, 0, 0, u, w);
        c.text(u + 1 + k.tick + k.gap, w + 0.5 - k.line, ycap, k.fs, kFrameInk, Align::left, VAlign::middle);
    }
    legend_rows(&c, f, k, k.pad, legend_top, width - 2 * k.pad);
    return out;
}

}  // namespace evcorner::render
