#pragma once
// Small charts for the evaluation report, drawn on an RgbImage with the bitmap font:
//   render_line_chart  y in [0, y_max] against categories (e.g. speed bins), one line per
//                      series, with a legend
//   render_histogram   bars of counts over equal bins of [lo, hi]

#include <span>
#include <string>
#include <vector>

#include "evcorner/render/image.hpp"

namespace evcorner::render {

struct ChartSeries {
    std::string name;
    Rgb colour;
    std::vector<double> y;  ///< one per category; NaN leaves a gap
};

/// A distinct colour per series index (a fixed palette, repeating).
Rgb series_colour(std::size_t index) noexcept;

RgbImage render_line_chart(const std::string& title, const std::vector<std::string>& categories,
                           const std::vector<ChartSeries>& series, double y_max, const std::string& y_label);

/// Counts of `values` in `bins` equal bins of [lo, hi] (values >= hi in the last bin); the
/// bars scaled to the largest count, which is printed.
RgbImage render_histogram(const std::string& title, std::span<const float> values, double lo, double hi, int bins,
                          const std::string& x_label, Rgb colour = {60, 90, 200});

}  // namespace evcorner::render
