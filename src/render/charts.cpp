#include "evcorner/render/charts.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

#include "evcorner/render/font.hpp"

namespace evcorner::render {

namespace {
constexpr Rgb kWhite{255, 255, 255}, kBlack{0, 0, 0}, kGrid{220, 220, 220};
constexpr int kLeft = 48, kTop = 24, kPlotW = 420, kPlotH = 220, kBottom = 40;
}  // namespace

Rgb series_colour(std::size_t index) noexcept {
    static constexpr Rgb palette[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                      {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                                      {188, 189, 34},  {23, 190, 207}};
    return palette[index % (sizeof(palette) / sizeof(palette[0]))];
}

RgbImage render_line_chart(const std::string& title, const std::vector<std::string>& categories,
                           const std::vector<ChartSeries>& series, double y_max, const std::string& y_label) {
    if (categories.empty() || !(y_max > 0)) throw std::invalid_argument("line chart: no categories or y_max <= 0");
    const int legend_w = 130;
    RgbImage img(kLeft + kPlotW + legend_w, kTop + kPlotH + kBottom, kWhite);
    draw_text(img, kLeft, 6, title, kBlack);
    // Axes, horizontal grid at fifths with labels.
    for (int k = 0; k <= 5; ++k) {
        const int y = kTop + kPlotH - k * kPlotH / 5;
        img.line(kLeft, y, kLeft + kPlotW, y, k == 0 ? kBlack : kGrid);
        const std::string lab = fmt::format("{:g}", y_max * k / 5);
        draw_text(img, kLeft - 4 - text_width(lab), y - 3, lab, kBlack);
    }
    img.line(kLeft, kTop, kLeft, kTop + kPlotH, kBlack);
    draw_text(img, 2, kTop - 12, y_label, kBlack);
    const auto n = static_cast<int>(categories.size());
    const auto x_of = [&](int i) { return kLeft + (2 * i + 1) * kPlotW / (2 * n); };
    for (int i = 0; i < n; ++i) {
        const std::string& c = categories[static_cast<std::size_t>(i)];
        draw_text(img, x_of(i) - text_width(c) / 2, kTop + kPlotH + 6 + (i % 2) * 10, c, kBlack);
    }
    const auto y_of = [&](double v) {
        return kTop + kPlotH - static_cast<int>(std::lround(std::clamp(v / y_max, 0.0, 1.0) * kPlotH));
    };
    for (std::size_t s = 0; s < series.size(); ++s) {
        const ChartSeries& ser = series[s];
        for (int i = 0; i < n && i < static_cast<int>(ser.y.size()); ++i) {
            const double v = ser.y[static_cast<std::size_t>(i)];
            if (std::isnan(v)) continue;
            img.fill_square(x_of(i) - 2, y_of(v) - 2, 5, ser.colour);
            if (i + 1 < static_cast<int>(ser.y.size()) && !std::isnan(ser.y[static_cast<std::size_t>(i) + 1]))
                for (int d = -1; d <= 0; ++d)
                    img.line(x_of(i), y_of(v) + d, x_of(i + 1), y_of(ser.y[static_cast<std::size_t>(i) + 1]) + d,
                             ser.colour);
        }
        const int ly = kTop + 4 + static_cast<int>(s) * 12;
        img.fill_rect(kLeft + kPlotW + 10, ly, 10, 7, ser.colour);
        draw_text(img, kLeft + kPlotW + 24, ly, ser.name, kBlack);
    }
    return img;
}

RgbImage render_histogram(const std::string& title, std::span<const float> values, double lo, double hi, int bins,
                          const std::string& x_label, Rgb colour) {
    if (bins < 1 || !(hi > lo)) throw std::invalid_argument("histogram: bins < 1 or hi <= lo");
    std::vector<std::uint64_t> count(static_cast<std::size_t>(bins), 0);
    for (const float v : values) {
        if (!(v >= lo)) continue;
        const auto k = std::min<std::int64_t>(bins - 1, static_cast<std::int64_t>((v - lo) / (hi - lo) * bins));
        ++count[static_cast<std::size_t>(k)];
    }
    const std::uint64_t top = std::max<std::uint64_t>(1, *std::max_element(count.begin(), count.end()));
    RgbImage img(kLeft + kPlotW + 20, kTop + kPlotH + kBottom, kWhite);
    draw_text(img, kLeft, 6, title, kBlack);
    const std::string top_label = fmt::format("{}", top);
    draw_text(img, kLeft - 4 - text_width(top_label), kTop - 3, top_label, kBlack);
    draw_text(img, kLeft - 10, kTop + kPlotH - 3, "0", kBlack);
    img.line(kLeft, kTop, kLeft, kTop + kPlotH, kBlack);
    img.line(kLeft, kTop + kPlotH, kLeft + kPlotW, kTop + kPlotH, kBlack);
    for (int k = 0; k < bins; ++k) {
        const int x0 = kLeft + k * kPlotW / bins, x1 = kLeft + (k + 1) * kPlotW / bins;
        const int h = static_cast<int>(std::lround(static_cast<double>(count[static_cast<std::size_t>(k)]) /
                                                   static_cast<double>(top) * kPlotH));
        img.fill_rect(x0 + 1, kTop + kPlotH - h, std::max(1, x1 - x0 - 1), h, colour);
    }
    for (int k = 0; k <= 4; ++k) {
        const double v = lo + (hi - lo) * k / 4;
        const std::string lab = fmt::format("{:g}", v);
        const int x = kLeft + k * kPlotW / 4;
        img.line(x, kTop + kPlotH, x, kTop + kPlotH + 3, kBlack);
        draw_text(img, x - text_width(lab) / 2, kTop + kPlotH + 6, lab, kBlack);
    }
    draw_text(img, kLeft + kPlotW / 2 - text_width(x_label) / 2, kTop + kPlotH + 20, x_label, kBlack);
    return img;
}

}  // namespace evcorner::render
