#pragma once
// A figure drawn as vector graphics with Cairo: lines, rectangles, anti-aliased text in
// DejaVu Sans, and raster images pasted pixel for pixel. The drawing is kept as its steps
// and replayed onto each output: PNG (rasterised), SVG or PDF.
//
// Coordinates are image pixels: pixel (x, y) covers [x, x + 1) x [y, y + 1), so a line one
// pixel wide along the pixel centres of row y runs at y + 0.5 and covers that row exactly.
// The font is read from the file fonts-dejavu-core installs
// (/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf), without fontconfig; only when that
// file is missing does Cairo ask fontconfig for "DejaVu Sans". Hinting is off, so text
// widths scale with the size and do not depend on the system's font configuration.

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/render/image.hpp"

namespace evcorner::render {

enum class FigureFormat { png, svg, pdf };

/// "png", "svg" or "pdf" (lower case); throws std::invalid_argument otherwise.
FigureFormat parse_figure_format(std::string_view name);
/// ".png", ".svg", ".pdf".
std::string_view figure_extension(FigureFormat f) noexcept;
/// The format named by the path's extension (case-insensitive), none for another one.
std::optional<FigureFormat> figure_format_of(std::string_view path) noexcept;

enum class Align { left, centre, right };
/// Which part of the text's line box lies at the given y: the top of the font's ascent,
/// the middle of ascent + descent, the baseline, or the bottom of the descent.
enum class VAlign { top, middle, baseline, bottom };

/// Width in pixels of `text` (UTF-8) at font size `size` px.
double text_width(std::string_view text, double size);
/// Ascent + descent of the font at `size` px: the height of one line of text without leading.
double text_height(double size);

class Canvas {
public:
    /// Throws std::invalid_argument for a side < 1 or > 65535.
    Canvas(int width, int height, Rgb background = {255, 255, 255});
    /// A canvas of exactly `image` (what a figure without a frame is, written as SVG or PDF).
    explicit Canvas(const RgbImage& image);
    ~Canvas();
    Canvas(Canvas&&) noexcept;
    Canvas& operator=(Canvas&&) noexcept;
    Canvas(const Canvas&) = delete;
    Canvas& operator=(const Canvas&) = delete;

    [[nodiscard]] int width() const noexcept { return width_; }
    [[nodiscard]] int height() const noexcept { return height_; }

    /// A straight line, its ends squared off half the width beyond the end points: a
    /// one-pixel line between two pixel centres covers both end pixels.
    void line(double x0, double y0, double x1, double y1, Rgb c, double line_width = 1.0);
    /// Connected segments through `xy` (x0, y0, x1, y1, ...), round joins and ends.
    void polyline(const std::vector<double>& xy, Rgb c, double line_width = 1.0);
    void fill_rect(double x, double y, double w, double h, Rgb c);
    /// The outline of the rectangle, its stroke centred on the rectangle's edges.
    void stroke_rect(double x, double y, double w, double h, Rgb c, double line_width = 1.0);
    void fill_circle(double cx, double cy, double r, Rgb c);
    /// Copies `image` with its top-left at (x, y), pixel for pixel (no smoothing).
    void image(const RgbImage& image, int x, int y);
    /// `text` (UTF-8) at font size `size` px anchored at (x, y); `vertical` turns it a
    /// quarter turn anticlockwise (reading upwards), the anchors then along the turned text.
    void text(double x, double y, std::string_view text, double size, Rgb c, Align align = Align::left,
              VAlign valign = VAlign::top, bool vertical = false);

    /// The figure as pixels.
    [[nodiscard]] RgbImage rasterise() const;
    /// Writes the figure; throws OutputError naming the file.
    void write(const std::string& path, FigureFormat format) const;
    /// Writes the figure in the format of the path's extension (.png, .svg, .pdf); throws
    /// std::invalid_argument for another extension.
    void write(const std::string& path) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    int width_ = 0, height_ = 0;
};

}  // namespace evcorner::render
