#include "evcorner/render/frame.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

#include "evcorner/render/font.hpp"

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

// Shared layout arithmetic of both frames.
struct Ink {
    int ts;       // text scale
    int line;     // one line of text, with spacing
    int pad;      // around the canvas
    int tick;     // tick length
};

Ink ink_for(const FigureFrame& f) {
    const int ts = std::max(1, f.text_scale);
    return {ts, kCellHeight * ts + 2 * ts, 8 * ts, 4 * ts};
}

int widest(const std::vector<std::string>& lines, int ts) {
    int w = 0;
    for (const auto& l : lines) w = std::max(w, text_width(l, ts));
    return w;
}

// The legend's items laid out in rows no wider than `width`; returns the rows' count.
// With draw set, draws them with the first row's top at y.
int legend_rows(RgbImage* img, const FigureFrame& f, const Ink& k, int x0, int y, int width) {
    if (f.legend.empty() && !f.grey_ramp) return 0;
    const int swatch = kGlyphHeight * k.ts;
    const int ramp_w = 100 * k.ts;
    int x = x0, rows = 1;
    auto place = [&](int w) {
        if (x > x0 && x + w > x0 + width) {
            x = x0;
            ++rows;
        }
        const int at = x;
        x += w + 14 * k.ts;
        return at;
    };
    for (const LegendEntry& e : f.legend) {
        const int at = place(swatch + 4 * k.ts + text_width(e.text, k.ts));
        if (!img) continue;
        const int top = y + (rows - 1) * (k.line + 2 * k.ts);
        img->fill_rect(at, top, swatch, swatch, e.colour);
        // A thin outline keeps light swatches visible on the white background.
        img->line(at - 1, top - 1, at + swatch, top - 1, kAxisInk);
        img->line(at - 1, top + swatch, at + swatch, top + swatch, kAxisInk);
        img->line(at - 1, top - 1, at - 1, top + swatch, kAxisInk);
        img->line(at + swatch, top - 1, at + swatch, top + swatch, kAxisInk);
        draw_text(*img, at + swatch + 4 * k.ts, top, e.text, kFrameInk, k.ts);
    }
    if (f.grey_ramp) {
        const std::string& a = f.ramp.white_text;
        const std::string& b = f.ramp.black_text;
        const int cap = text_width(f.ramp.caption, k.ts) + 4 * k.ts;
        const int w = cap + text_width(a, k.ts) + 5 * k.ts + ramp_w + 5 * k.ts + text_width(b, k.ts);
        const int at = place(w);
        if (img) {
            const int top = y + (rows - 1) * (k.line + 2 * k.ts);
            int u = at;
            draw_text(*img, u, top, f.ramp.caption, kFrameInk, k.ts);
            u += cap;
            draw_text(*img, u, top, a, kFrameInk, k.ts);
            u += text_width(a, k.ts) + 5 * k.ts;
            for (int i = 0; i < ramp_w; ++i) {
                const auto g = static_cast<std::uint8_t>(std::lround(255.0 * (1.0 - static_cast<double>(i) / (ramp_w - 1))));
                img->fill_rect(u + i, top, 1, swatch, {g, g, g});
            }
            img->line(u - 1, top - 1, u + ramp_w, top - 1, kAxisInk);
            img->line(u - 1, top + swatch, u + ramp_w, top + swatch, kAxisInk);
            img->line(u - 1, top - 1, u - 1, top + swatch, kAxisInk);
            img->line(u + ramp_w, top - 1, u + ramp_w, top + swatch, kAxisInk);
            u += ramp_w + 5 * k.ts;
            draw_text(*img, u, top, b, kFrameInk, k.ts);
        }
    }
    return rows;
}

int legend_height(int rows, const Ink& k) { return rows == 0 ? 0 : rows * (k.line + 2 * k.ts) + k.pad / 2; }

void draw_title(RgbImage& img, const FigureFrame& f, const Ink& k) {
    for (std::size_t i = 0; i < f.title.size(); ++i)
        draw_text(img, k.pad, k.pad + static_cast<int>(i) * k.line, f.title[i], kFrameInk, k.ts);
}

int title_height(const FigureFrame& f, const Ink& k) {
    return k.pad + static_cast<int>(f.title.size()) * k.line + k.pad / 2;
}

// Pixel ticks of a sensor side of `n` pixels drawn `scale` image pixels each: at least
// a label's width plus some air apart, and at least 30 text pixels.
std::vector<double> pixel_ticks(int n, int scale, const Ink& k) {
    const double label_px = text_width(std::to_string(n - 1), k.ts) + 10.0 * k.ts;
    return nice_ticks(0, n - 1, std::max(label_px, 30.0 * k.ts) / scale);
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
    Framed out{RgbImage(width, height, kFrameBackground), left, top};
    draw_title(out.image, f, k);
    out.image.paste(body, left, top);
    return out;
}

}  // namespace

Framed frame_sensor_figure(const RgbImage& body, SensorSize size, int scale, const FigureFrame& f) {
    if (body.width() != size.width * scale || body.height() != size.height * scale)
        throw std::invalid_argument("sensor figure frame: the body is not the sensor at this scale");
    const Ink k = ink_for(f);
    const auto xt = pixel_ticks(size.width, scale, k);
    const auto yt = pixel_ticks(size.height, scale, k);
    int ylab = 0;
    for (const double v : yt) ylab = std::max(ylab, text_width(tick_label(v, 1), k.ts));
    const std::string ycap = "y [px]", xcap = "x [px]";
    const int left = k.pad + std::max(ylab + 3 * k.ts + k.tick, text_width(ycap, k.ts)) + 1;
    const int top = title_height(f, k) + k.line + text_height(k.ts) / 2;  // the y caption's row above the box
    const int last_label = text_width(tick_label(xt.back(), 1), k.ts);
    int width = left + body.width() + 1 + std::max(k.pad, last_label / 2 + k.pad / 2);
    width = std::max(width, widest(f.title, k.ts) + 2 * k.pad);
    const int legend_top = top + body.height() + 1 + k.tick + 2 * k.ts + 2 * k.line + k.pad / 2;

    Framed out = start_frame(body, f, k, left, top, width, legend_top);
    RgbImage& img = out.image;
    // The axes: a box one pixel outside the body.
    const int x0 = left - 1, y0 = top - 1, x1 = left + body.width(), y1 = top + body.height();
    img.line(x0, y0, x1, y0, kAxisInk);
    img.line(x0, y1, x1, y1, kAxisInk);
    img.line(x0, y0, x0, y1, kAxisInk);
    img.line(x1, y0, x1, y1, kAxisInk);
    for (const double v : xt) {
        const int u = left + static_cast<int>(v) * scale + scale / 2;
        img.line(u, y1 + 1, u, y1 + k.tick, kAxisInk);
        const std::string s = tick_label(v, 1);
        draw_text(img, u - text_width(s, k.ts) / 2, y1 + k.tick + 2 * k.ts, s, kFrameInk, k.ts);
    }
    draw_text(img, left + body.width() / 2 - text_width(xcap, k.ts) / 2, y1 + k.tick + 2 * k.ts + k.line, xcap,
              kFrameInk, k.ts);
    for (const double v : yt) {
        const int w = top + static_cast<int>(v) * scale + scale / 2;
        img.line(x0 - k.tick, w, x0 - 1, w, kAxisInk);
        const std::string s = tick_label(v, 1);
        draw_text(img, x0 - k.tick - 3 * k.ts - text_width(s, k.ts), w - text_height(k.ts) / 2, s, kFrameInk, k.ts);
    }
    draw_text(img, std::max(k.pad, x0 - text_width(ycap, k.ts)), top - k.line, ycap, kFrameInk, k.ts);
    legend_rows(&img, f, k, k.pad, legend_top, width - 2 * k.pad);
    return out;
}

Framed frame_space_time_figure(const RgbImage& body, SensorSize size, std::int64_t t0, std::int64_t t1,
                               const SpaceTimeStyle& style, const FigureFrame& f) {
    if (t1 <= t0) throw std::invalid_argument("space-time frame: empty interval");
    const SpaceTimeLayout lay = space_time_layout(size, style);
    if (body.width() != lay.width || body.height() != lay.height)
        throw std::invalid_argument("space-time frame: the body does not match the layout");
    const Ink k = ink_for(f);
    const double kx = style.scale;
    // Time ticks along the front-left edge (x = 0, y = H - 1), in the unit that suits the span.
    const TimeAxis unit = time_unit_for(t1 - t0);
    const double span = static_cast<double>(t1 - t0) / unit.divisor;
    const double time_px = kx * style.time_height;
    const auto tt = nice_ticks(0, span, std::max(1e-9, span * (k.line + 20.0 * k.ts) / time_px));
    const double tstep = tt.size() > 1 ? tt[1] - tt[0] : std::max(span, 1e-9);
    int tlab = 0;
    for (const double v : tt) tlab = std::max(tlab, text_width(tick_label(v, tstep), k.ts));
    const std::string tcap = fmt::format("t - t0 [{}]", unit.unit);
    const auto xt = pixel_ticks(size.width, style.scale, k);
    // y along the depth edge: each step moves depth * scale pixels right and up.
    // Labels stack vertically along it: a line of text apart at least.
    const double rise_per_y = std::max(1e-9, style.depth * kx);
    const auto yt = nice_ticks(0, size.height - 1, std::max(1.0, (k.line + 4.0 * k.ts) / rise_per_y));
    int ylab = 0;
    for (const double v : yt) ylab = std::max(ylab, text_width(tick_label(v, 1), k.ts));
    const std::string xcap = "x [px]", ycap = "y [px]";

    // The time caption stands left of the time axis's top end, the labels left of its ticks.
    const int left = k.pad + std::max(tlab + 6 * k.ts, text_width(tcap, k.ts) + 2 * k.ts) + k.tick - lay.margin;
    const int top = title_height(f, k);
    const int gap = 6 * k.ts;  // between a tick and its label, so that the tick reads as no minus sign
    ylab = std::max(ylab, text_width(ycap, k.ts));
    int width = left + body.width() + std::max(k.pad, ylab + k.tick + gap + k.pad - lay.margin);
    width = std::max(width, widest(f.title, k.ts) + 2 * k.pad);
    const int legend_top = top + body.height() + k.tick + 2 * k.ts + 2 * k.line - lay.margin + k.pad / 2;

    Framed out = start_frame(body, f, k, left, top, width, legend_top);
    RgbImage& img = out.image;
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
    img.line(ua, va, ub, vb, kAxisInk);  // x
    at(0, h1, 1, ub, vb);
    img.line(ua, va, ub, vb, kAxisInk);  // time
    at(w1, h1, 0, ua, va);
    at(w1, 0, 0, ub, vb);
    img.line(ua, va, ub, vb, kAxisInk);  // y
    for (const double v : xt) {
        int u, w;
        at(v, h1, 0, u, w);
        img.line(u, w + 1, u, w + k.tick, kAxisInk);
        const std::string s = tick_label(v, 1);
        draw_text(img, u - text_width(s, k.ts) / 2, w + k.tick + 2 * k.ts, s, kFrameInk, k.ts);
    }
    {
        int u, w;
        at(w1 / 2, h1, 0, u, w);
        draw_text(img, u - text_width(xcap, k.ts) / 2, w + k.tick + 2 * k.ts + k.line, xcap, kFrameInk, k.ts);
    }
    for (const double v : tt) {
        int u, w;
        at(0, h1, v / span, u, w);
        img.line(u - k.tick, w, u - 1, w, kAxisInk);
        const std::string s = tick_label(v, tstep);
        draw_text(img, u - k.tick - gap - text_width(s, k.ts), w - text_height(k.ts) / 2, s, kFrameInk, k.ts);
    }
    {
        int u, w;
        at(0, h1, 1, u, w);
        draw_text(img, u - 2 * k.ts - text_width(tcap, k.ts), w - k.line - 4 * k.ts, tcap, kFrameInk, k.ts);
    }
    for (const double v : yt) {
        int u, w;
        at(w1, v, 0, u, w);
        img.line(u + 1, w, u + k.tick, w, kAxisInk);
        draw_text(img, u + k.tick + gap, w - text_height(k.ts) / 2, tick_label(v, 1), kFrameInk, k.ts);
    }
    {
        int u, w;
        at(w1, 0, 0, u, w);
        draw_text(img, u + k.tick + gap, w - text_height(k.ts) / 2 - k.line, ycap, kFrameInk, k.ts);
    }
    legend_rows(&img, f, k, k.pad, legend_top, width - 2 * k.pad);
    return out;
}

}  // namespace evcorner::render
