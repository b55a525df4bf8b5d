#pragma once
// Charts for the evaluation report, drawn with Cairo (canvas.hpp): a title, axes with
// ticks and numbers, axis labels, and a legend naming each series.
//   render_line_chart  y in [0, y_max] against categories (e.g. speed bins), one line per
//                      series
//   render_histogram   bars of counts over equal bins of [lo, hi]

#include <span>
#include <string>
#include <vector>

#include "evcorner/render/canvas.hpp"
#include "evcorner/render/image.hpp"

namespace evcorner::render {

struct ChartSeries {
    std::string name;
    Rgb colour;
    std::vector<double> y;  ///< one per category; NaN leaves a gap
};

/// A distinct colour per series index (a fixed palette, repeating).
Rgb series_colour(std::size_t index) noexcept;

inline constexpr Rgb kChartBackground{255, 255, 255}, kChartInk{30, 30, 30}, kChartAxis{60, 60, 60},
    kChartGrid{225, 225, 225};

/// Fixed geometry of both charts (tests find the plot area from it).
struct ChartLayout {
    int width = 760, height = 440;
    int plot_x = 70, plot_y = 44, plot_w = 500, plot_h = 310;  ///< the plot area, left of the legend
    double text_size = 13;                                     ///< font size, px
};

/// Throws std::invalid_argument for no categories or y_max <= 0. The legend, right of the
/// plot, names each series beside its line and marker.
Canvas render_line_chart(const std::string& title, const std::vector<std::string>& categories,
                         const std::vector<ChartSeries>& series, double y_max, const std::string& x_label,
                         const std::string& y_label);

/// Counts of `values` in `bins` equal bins of [lo, hi] (values >= hi in the last bin, below
/// lo and NaN left out); the count axis up to the largest count. `legend` names the bars
/// (empty: no legend). Throws std::invalid_argument for bins < 1 or hi <= lo.
Canvas render_histogram(const std::string& title, std::span<const float> values, double lo, double hi, int bins,
                        const std::string& x_label, const std::string& y_label, const std::string& legend,
                        Rgb colour = {60, 90, 200});

}  // namespace evcorner::render
