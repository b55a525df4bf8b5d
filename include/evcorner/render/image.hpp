#pragma once
// A small 8-bit RGB raster for the figures, with PNG in and out (libpng).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace evcorner::render {

struct Rgb {
    std::uint8_t r = 0, g = 0, b = 0;
    friend constexpr bool operator==(const Rgb&, const Rgb&) = default;
};

class RgbImage {
public:
    RgbImage() = default;
    /// Throws std::invalid_argument for a side < 1 or > 65535.
    RgbImage(int width, int height, Rgb fill = {});

    [[nodiscard]] int width() const noexcept { return width_; }
    [[nodiscard]] int height() const noexcept { return height_; }
    [[nodiscard]] bool contains(int x, int y) const noexcept {
        return x >= 0 && y >= 0 && x < width_ && y < height_;
    }
    [[nodiscard]] Rgb at(int x, int y) const noexcept {
        const std::uint8_t* p = &data_[index(x, y)];
        return {p[0], p[1], p[2]};
    }
    /// Sets the pixel; outside the image it does nothing.
    void set(int x, int y, Rgb c) noexcept {
        if (!contains(x, y)) return;
        std::uint8_t* p = &data_[index(x, y)];
        p[0] = c.r;
        p[1] = c.g;
        p[2] = c.b;
    }
    /// A filled square of side `side` with its top-left at (x, y), clipped.
    void fill_square(int x, int y, int side, Rgb c) noexcept {
        for (int dy = 0; dy < side; ++dy)
            for (int dx = 0; dx < side; ++dx) set(x + dx, y + dy, c);
    }
    /// A filled rectangle with its top-left at (x, y), clipped.
    void fill_rect(int x, int y, int w, int h, Rgb c) noexcept {
        for (int dy = 0; dy < h; ++dy)
            for (int dx = 0; dx < w; ++dx) set(x + dx, y + dy, c);
    }
    /// Copies `src` with its top-left at (x, y), clipped.
    void paste(const RgbImage& src, int x, int y) noexcept;
    /// A straight line, clipped (Bresenham).
    void line(int x0, int y0, int x1, int y1, Rgb c) noexcept;

    /// Row-major RGB bytes, 3 per pixel.
    [[nodiscard]] const std::vector<std::uint8_t>& bytes() const noexcept { return data_; }

private:
    [[nodiscard]] std::size_t index(int x, int y) const noexcept {
        return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
    }
    int width_ = 0, height_ = 0;
    std::vector<std::uint8_t> data_;
};

/// Each pixel becomes a factor x factor block (factor >= 1).
RgbImage upscale(const RgbImage& in, int factor);

/// Writes `image` as an 8-bit RGB PNG; throws OutputError naming the file.
void write_png(const std::string& path, const RgbImage& image);
/// Reads any PNG, converted to 8-bit RGB; throws InputError naming the file.
RgbImage read_png(const std::string& path);

}  // namespace evcorner::render
