#include "evcorner/render/image.hpp"

#include <png.h>

#include <cstdlib>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner::render {

RgbImage::RgbImage(int width, int height, Rgb fill) : width_(width), height_(height) {
    if (width < 1 || height < 1 || width > 65535 || height > 65535)
        throw std::invalid_argument("image size must be 1..65535 on each side");
    data_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
    for (std::size_t i = 0; i < data_.size(); i += 3) {
        data_[i] = fill.r;
        data_[i + 1] = fill.g;
        data_[i + 2] = fill.b;
    }
}

void RgbImage::line(int x0, int y0, int x1, int y1, Rgb c) noexcept {
    const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
    const int sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (;;) {
        set(x0, y0, c);
        if (x0 == x1 && y0 == y1) return;
        const int e2 = 2 * err;
        if (e2 >= dy) {
            err += dy;
            x0 += sx;
        }
        if (e2 <= dx) {
            err += dx;
            y0 += sy;
        }
    }
}

void RgbImage::paste(const RgbImage& src, int x, int y) noexcept {
    for (int sy = 0; sy < src.height(); ++sy)
        for (int sx = 0; sx < src.width(); ++sx) set(x + sx, y + sy, src.at(sx, sy));
}

RgbImage upscale(const RgbImage& in, int factor) {
    if (factor < 1) throw std::invalid_argument("upscale factor must be >= 1");
    if (factor == 1) return in;
    RgbImage out(in.width() * factor, in.height() * factor);
    for (int y = 0; y < out.height(); ++y)
        for (int x = 0; x < out.width(); ++x) out.set(x, y, in.at(x / factor, y / factor));
    return out;
}

// libpng's simplified API (1.6+): no setjmp in our code, errors come back in the struct.
// The PNG is encoded in memory and written through OutputFile (a temporary file renamed
// on success, pending_file.hpp): libpng's own file writer removes the path when a write
// fails, even a device node or a link evcorner did not create.
void write_png(const std::string& path, const RgbImage& image) {
    if (image.width() == 0) throw OutputError(path, "empty image");
    auto fresh = [&] {
        png_image png{};
        png.version = PNG_IMAGE_VERSION;
        png.width = static_cast<png_uint_32>(image.width());
        png.height = static_cast<png_uint_32>(image.height());
        png.format = PNG_FORMAT_RGB;
        return png;
    };
    auto fail = [&](png_image& png) {
        const std::string reason = png.message[0] ? png.message : "cannot encode the PNG";
        png_image_free(&png);
        throw OutputError(path, reason);
    };
    // First call: the size the encoded image needs; second: the encoding.
    png_image png = fresh();
    png_alloc_size_t size = 0;
    if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.bytes().data(), 0, nullptr)) fail(png);
    std::vector<unsigned char> encoded(size);
    png = fresh();
    if (!png_image_write_to_memory(&png, encoded.data(), &size, 0, image.bytes().data(), 0, nullptr)) fail(png);
    io::OutputFile out(path);
    out.write(std::string_view(reinterpret_cast<const char*>(encoded.data()), size));
    out.close();
}

RgbImage read_png(const std::string& path) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, path.c_str()))
        throw InputError(path, png.message[0] ? png.message : "cannot read PNG");
    png.format = PNG_FORMAT_RGB;
    if (png.width < 1 || png.height < 1 || png.width > 65535 || png.height > 65535) {
        png_image_free(&png);
        throw InputError(path, "PNG size out of range");
    }
    RgbImage out(static_cast<int>(png.width), static_cast<int>(png.height));
    std::vector<std::uint8_t> buf(PNG_IMAGE_SIZE(png));
    if (!png_image_finish_read(&png, nullptr, buf.data(), 0, nullptr)) {
        const std::string reason = png.message[0] ? png.message : "cannot decode PNG";
        png_image_free(&png);
        throw InputError(path, reason);
    }
    for (int y = 0; y < out.height(); ++y)
        for (int x = 0; x < out.width(); ++x) {
            const std::size_t i = (static_cast<std::size_t>(y) * png.width + static_cast<std::size_t>(x)) * 3;
            out.set(x, y, {buf[i], buf[i + 1], buf[i + 2]});
        }
    return out;
}

}  // namespace evcorner::render
