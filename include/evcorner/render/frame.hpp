#pragma once
// The frame around a figure: a title naming what is drawn, axes with ticks (sensor pixels,
// and time for the space-time view), and a legend. The figure itself (figures.hpp) is
// drawn first and pasted in: the frame reads its geometry, never its pixels. The frame is
// vector graphics (canvas.hpp): written as PNG, SVG or PDF, the body a raster inside it.

#include <cstdint>
#include <string>
#include <vector>

#include "evcorner/render/canvas.hpp"
#include "evcorner/render/figures.hpp"
#include "evcorner/render/image.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::render {

struct LegendEntry {
    Rgb colour;        ///< the swatch
    std::string text;  ///< what that colour means
};

/// A grey ramp from white to black, for the SAE: what white and black mean.
struct GreyRamp {
    std::string caption;     ///< before the ramp, e.g. "age of the newest event"
    std::string white_text;  ///< under its white end, e.g. "0"
    std::string black_text;  ///< under its black end, e.g. "50 ms"
};

struct FigureFrame {
    std::vector<std::string> title;  ///< lines above the figure, the first one the heading
    std::vector<LegendEntry> legend;
    bool grey_ramp = false;          ///< draw `ramp` in the legend
    GreyRamp ramp;
    /// Font size in image pixels; 0 picks one from the figure's size (readable from the
    /// smallest sensors to 1280x720 and larger: the text grows with the image).
    double text_size = 0;
};

inline constexpr Rgb kFrameBackground{255, 255, 255}, kFrameInk{30, 30, 30}, kAxisInk{60, 60, 60};

/// Where a framed figure's body went (tests and callers that want to find it).
struct Framed {
    Canvas figure;
    int body_x = 0, body_y = 0;  ///< top-left of the pasted body
    double text_size = 0;        ///< the font size used, px
};

/// The font size `text_size = 0` picks for a body of this size: 12 px, more for large bodies.
double auto_text_size(int body_width, int body_height) noexcept;

/// Ticks for [lo, hi]: multiples of 1, 2 or 5 times a power of ten, the smallest such step
/// at least `min_step`. Exposed for tests.
std::vector<double> nice_ticks(double lo, double hi, double min_step);
/// `value` with as many decimals as `step` needs ("0.5", "120").
std::string tick_label(double value, double step);

/// Fig. 2b and Fig. 6: `body` is the sensor upscaled by `scale` (size.width * scale wide).
/// Title above; the axes as a box around the body with pixel ticks, x below and y on
/// the left, (0, 0) top-left as on the sensor; legend below. The body is copied unchanged.
Framed frame_sensor_figure(const RgbImage& body, SensorSize size, int scale, const FigureFrame& frame);

/// Fig. 1b and Fig. 5b: `body` from render_space_time(size, t0, t1, style). The box's front
/// edges become the axes: x along the bottom, time (from t0) on the left, y along the depth
/// edge on the right, each with ticks and labels; title above, legend below.
Framed frame_space_time_figure(const RgbImage& body, SensorSize size, std::int64_t t0, std::int64_t t1,
                               const SpaceTimeStyle& style, const FigureFrame& frame);

}  // namespace evcorner::render
