#include "evcorner/render/charts.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

#include "evcorner/render/frame.hpp"

namespace evcorner::render {

Rgb series_colour(std::size_t index) noexcept {
    static constexpr Rgb palette[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                      {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                                      {188, 189, 34},  {23, 190, 207}};
    return palette[index % (sizeof(palette) / sizeof(palette[0]))];
}

namespace {

// Title above the plot, the y axis's ticks, numbers, grid and label; the plot's frame.
// Returns the canvas; `legend_w` more pixels right of the plot for the legend.
Canvas start_chart(const ChartLayout& l, int width, const std::string& title, const std::vector<double>& yticks,
                   double y_max, const std::string& y_label) {
    Canvas c(width, l.height, kChartBackground);
    const double fs = l.text_size;
    c.text(l.plot_x + l.plot_w / 2.0, 10, title, fs * 1.15, kChartInk, Align::centre);
    const double step = yticks.size() > 1 ? yticks[1] - yticks[0] : y_max;
    for (const double v : yticks) {
        const int y = l.plot_y + l.plot_h - static_cast<int>(std::lround(v / y_max * l.plot_h));
        if (v > 0) c.line(l.plot_x + 1, y + 0.5, l.plot_x + l.plot_w - 1, y + 0.5, kChartGrid);
        c.line(l.plot_x - 5, y + 0.5, l.plot_x - 1, y + 0.5, kChartAxis);
        c.text(l.plot_x - 8, y + 0.5, tick_label(v, step), fs, kChartInk, Align::right, VAlign::middle);
    }
    c.text(14, l.plot_y + l.plot_h / 2.0, y_label, fs, kChartInk, Align::centre, VAlign::top, true);
    return c;
}

// The plot's box over everything drawn inside it.
void close_chart(Canvas& c, const ChartLayout& l) {
    c.stroke_rect(l.plot_x - 0.5, l.plot_y - 0.5, l.plot_w + 1, l.plot_h + 1, kChartAxis);
}

}  // namespace

Canvas render_line_chart(const std::string& title, const std::vector<std::string>& categories,
                         const std::vector<ChartSeries>& series, double y_max, const std::string& x_label,
                         const std::string& y_label) {
    if (categories.empty() || !(y_max > 0)) throw std::invalid_argument("line chart: no categories or y_max <= 0");
    const ChartLayout l;
    const double fs = l.text_size;
    const int legend_x = l.plot_x + l.plot_w + 24, sample_w = 28;
    int names_w = 0;
    for (const ChartSeries& s : series) names_w = std::max(names_w, static_cast<int>(std::ceil(text_width(s.name, fs))));
    const int width = std::max(l.width, legend_x + sample_w + 8 + names_w + 16);
    const auto yticks = nice_ticks(0, y_max, y_max / 6);
    Canvas c = start_chart(l, width, title, yticks, y_max, y_label);

    const auto n = static_cast<int>(categories.size());
    const double slot = static_cast<double>(l.plot_w) / n;
    const auto x_of = [&](int i) { return l.plot_x + (i + 0.5) * slot; };
    const auto y_of = [&](double v) { return l.plot_y + l.plot_h - std::clamp(v / y_max, 0.0, 1.0) * l.plot_h; };
    // Every category gets a tick; labels every `every`-th so that they do not run together.
    double widest = 0;
    for (const auto& s : categories) widest = std::max(widest, text_width(s, fs));
    const int every = std::max(1, static_cast<int>(std::ceil((widest + 0.6 * fs) / slot)));
    const int base = l.plot_y + l.plot_h;
    for (int i = 0; i < n; ++i) {
        const double x = std::floor(x_of(i)) + 0.5;
        c.line(x, base + 1, x, base + 4, kChartAxis);
        if (i % every == 0) c.text(x, base + 8, categories[static_cast<std::size_t>(i)], fs, kChartInk, Align::centre);
    }
    c.text(l.plot_x + l.plot_w / 2.0, base + 8 + 1.6 * fs, x_label, fs, kChartInk, Align::centre);

    for (std::size_t s = 0; s < series.size(); ++s) {
        const ChartSeries& ser = series[s];
        std::vector<double> run;  // the current unbroken run of points
        const auto flush = [&] {
            c.polyline(run, ser.colour, 2.0);
            run.clear();
        };
        for (int i = 0; i < n && i < static_cast<int>(ser.y.size()); ++i) {
            const double v = ser.y[static_cast<std::size_t>(i)];
            if (std::isnan(v)) {
                flush();
                continue;
            }
            run.push_back(x_of(i));
            run.push_back(y_of(v));
        }
        flush();
        for (int i = 0; i < n && i < static_cast<int>(ser.y.size()); ++i) {
            const double v = ser.y[static_cast<std::size_t>(i)];
            if (!std::isnan(v)) c.fill_circle(x_of(i), y_of(v), 3.0, ser.colour);
        }
        const double ly = l.plot_y + 10 + static_cast<double>(s) * 1.6 * fs;
        c.line(legend_x, ly, legend_x + sample_w, ly, ser.colour, 2.0);
        c.fill_circle(legend_x + sample_w / 2.0, ly, 3.0, ser.colour);
        c.text(legend_x + sample_w + 8, ly, ser.name, fs, kChartInk, Align::left, VAlign::middle);
    }
    close_chart(c, l);
    return c;
}

Canvas render_histogram(const std::string& title, std::span<const float> values, double lo, double hi, int bins,
                        const std::string& x_label, const std::string& y_label, const std::string& legend,
                        Rgb colour) {
    if (bins < 1 || !(hi > lo)) throw std::invalid_argument("histogram: bins < 1 or hi <= lo");
    std::vector<std::uint64_t> count(static_cast<std::size_t>(bins), 0);
    for (const float v : values) {
        if (!(v >= lo)) continue;
        const auto k = std::min<std::int64_t>(bins - 1, static_cast<std::int64_t>((v - lo) / (hi - lo) * bins));
        ++count[static_cast<std::size_t>(k)];
    }
    const auto top = static_cast<double>(std::max<std::uint64_t>(1, *std::max_element(count.begin(), count.end())));
    // The count axis: whole numbers, up to the first tick at or above the largest count.
    auto yticks = nice_ticks(0, top, std::max(1.0, top / 5));
    const double ystep = yticks.size() > 1 ? yticks[1] - yticks[0] : top;
    const double y_max = std::ceil(top / ystep - 1e-9) * ystep;
    if (yticks.back() < y_max) yticks.push_back(y_max);
    const ChartLayout l;
    const double fs = l.text_size;
    Canvas c = start_chart(l, l.width, title, yticks, y_max, y_label);
    const int base = l.plot_y + l.plot_h;
    for (int k = 0; k < bins; ++k) {
        const double x0 = l.plot_x + static_cast<double>(k) * l.plot_w / bins;
        const double x1 = l.plot_x + static_cast<double>(k + 1) * l.plot_w / bins;
        const double h = static_cast<double>(count[static_cast<std::size_t>(k)]) / y_max * l.plot_h;
        c.fill_rect(std::round(x0) + 1, base - std::round(h), std::max(1.0, std::round(x1) - std::round(x0) - 1),
                    std::round(h), colour);
    }
    const auto xticks = nice_ticks(lo, hi, (hi - lo) / 6);
    const double xstep = xticks.size() > 1 ? xticks[1] - xticks[0] : hi - lo;
    for (const double v : xticks) {
        const double x = std::floor(l.plot_x + (v - lo) / (hi - lo) * l.plot_w) + 0.5;
        c.line(x, base + 1, x, base + 4, kChartAxis);
        c.text(x, base + 8, tick_label(v, xstep), fs, kChartInk, Align::centre);
    }
    c.text(l.plot_x + l.plot_w / 2.0, base + 8 + 1.6 * fs, x_label, fs, kChartInk, Align::centre);
    if (!legend.empty()) {
        const int legend_x = l.plot_x + l.plot_w + 24;
        const int sw = static_cast<int>(std::lround(0.8 * fs));
        c.fill_rect(legend_x, l.plot_y + 10 - sw / 2, sw, sw, colour);
        // The legend text wraps onto words' lines when it is wider than the space left.
        const double room = l.width - legend_x - sw - 8 - 6;
        std::vector<std::string> lines{""};
        std::size_t pos = 0;
        while (pos < legend.size()) {
            std::size_t end = legend.find(' ', pos);
            if (end == std::string::npos) end = legend.size();
            const std::string word = legend.substr(pos, end - pos);
            const std::string joined = lines.back().empty() ? word : lines.back() + " " + word;
            if (!lines.back().empty() && text_width(joined, fs) > room)
                lines.push_back(word);
            else
                lines.back() = joined;
            pos = end + 1;
        }
        for (std::size_t i = 0; i < lines.size(); ++i)
            c.text(legend_x + sw + 8, l.plot_y + 10 + static_cast<double>(i) * 1.3 * fs, lines[i], fs, kChartInk,
                   Align::left, VAlign::middle);
    }
    close_chart(c, l);
    return c;
}

}  // namespace evcorner::render
