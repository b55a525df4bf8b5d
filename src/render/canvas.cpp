#include "evcorner/render/canvas.hpp"

#include <cairo-ft.h>
#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/io/output_file.hpp"

namespace evcorner::render {

FigureFormat parse_figure_format(std::string_view name) {
    if (name == "png") return FigureFormat::png;
    if (name == "svg") return FigureFormat::svg;
    if (name == "pdf") return FigureFormat::pdf;
    throw std::invalid_argument("figure format must be png, svg or pdf, not '" + std::string(name) + "'");
}

std::string_view figure_extension(FigureFormat f) noexcept {
    switch (f) {
        case FigureFormat::svg: return ".svg";
        case FigureFormat::pdf: return ".pdf";
        case FigureFormat::png: break;
    }
    return ".png";
}

std::optional<FigureFormat> figure_format_of(std::string_view path) noexcept {
    if (path.size() < 4) return std::nullopt;
    std::string ext(path.substr(path.size() - 4));
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    for (const FigureFormat f : {FigureFormat::png, FigureFormat::svg, FigureFormat::pdf})
        if (ext == figure_extension(f)) return f;
    return std::nullopt;
}

namespace {

constexpr const char* kFontFiles[] = {
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",  // fonts-dejavu-core (Debian)
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
};

// The figures' font face, made once and kept for the process's life (reachable from this
// static, so no leak): the DejaVu Sans file through FreeType, else Cairo's fontconfig lookup.
cairo_font_face_t* figure_font() {
    static cairo_font_face_t* const face = [] {
        static FT_Library library = nullptr;
        if (FT_Init_FreeType(&library) == 0) {
            for (const char* file : kFontFiles) {
                FT_Face ft = nullptr;
                if (FT_New_Face(library, file, 0, &ft) != 0) continue;
                cairo_font_face_t* f = cairo_ft_font_face_create_for_ft_face(ft, 0);
                if (cairo_font_face_status(f) == CAIRO_STATUS_SUCCESS) return f;
                cairo_font_face_destroy(f);
                FT_Done_Face(ft);
            }
        }
        return cairo_toy_font_face_create("DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    }();
    return face;
}

// Grey anti-aliasing, no hinting: the same glyph shapes and advances on every system.
void use_figure_font(cairo_t* cr, double size) {
    cairo_set_font_face(cr, figure_font());
    cairo_set_font_size(cr, size);
    cairo_font_options_t* opt = cairo_font_options_create();
    cairo_font_options_set_antialias(opt, CAIRO_ANTIALIAS_GRAY);
    cairo_font_options_set_hint_style(opt, CAIRO_HINT_STYLE_NONE);
    cairo_font_options_set_hint_metrics(opt, CAIRO_HINT_METRICS_OFF);
    cairo_font_options_set_subpixel_order(opt, CAIRO_SUBPIXEL_ORDER_DEFAULT);
    cairo_set_font_options(cr, opt);
    cairo_font_options_destroy(opt);
}

// A context on a 1x1 surface for measuring text; one per thread, kept.
cairo_t* measuring_context() {
    thread_local struct Holder {
        cairo_surface_t* s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1);
        cairo_t* cr = cairo_create(s);
        ~Holder() {
            cairo_destroy(cr);
            cairo_surface_destroy(s);
        }
    } h;
    return h.cr;
}

void set_colour(cairo_t* cr, Rgb c) { cairo_set_source_rgb(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0); }

// An image surface holding `img` (Cairo's RGB24: one 32-bit word per pixel, 0x00RRGGBB).
cairo_surface_t* surface_of(const RgbImage& img) {
    cairo_surface_t* s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, img.width(), img.height());
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) throw std::runtime_error("figure: cannot allocate an image");
    cairo_surface_flush(s);
    unsigned char* data = cairo_image_surface_get_data(s);
    const int stride = cairo_image_surface_get_stride(s);
    const std::uint8_t* src = img.bytes().data();
    for (int y = 0; y < img.height(); ++y) {
        auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
        for (int x = 0; x < img.width(); ++x, src += 3)
            row[x] = std::uint32_t{src[0]} << 16 | std::uint32_t{src[1]} << 8 | std::uint32_t{src[2]};
    }
    cairo_surface_mark_dirty(s);
    return s;
}

cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length) {
    static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
    return CAIRO_STATUS_SUCCESS;
}

}  // namespace

double text_width(std::string_view text, double size) {
    if (text.empty()) return 0;
    cairo_t* cr = measuring_context();
    use_figure_font(cr, size);
    const std::string s(text);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    return e.x_advance;
}

double text_height(double size) {
    cairo_t* cr = measuring_context();
    use_figure_font(cr, size);
    cairo_font_extents_t fe;
    cairo_font_extents(cr, &fe);
    return fe.ascent + fe.descent;
}

// The figure is kept as its drawing steps, replayed onto each target (an image surface for
// PNG, an SVG or PDF surface): every target gets the same Cairo calls, and no Cairo object
// outlives one output.
struct Canvas::Impl {
    std::vector<std::function<void(cairo_t*)>> steps;
};

Canvas::Canvas(int width, int height, Rgb background) : impl_(std::make_unique<Impl>()), width_(width), height_(height) {
    if (width < 1 || height < 1 || width > 65535 || height > 65535)
        throw std::invalid_argument("figure size must be 1..65535 on each side");
    fill_rect(0, 0, width, height, background);
}

Canvas::Canvas(const RgbImage& img) : Canvas(img.width(), img.height()) { image(img, 0, 0); }

Canvas::~Canvas() = default;
Canvas::Canvas(Canvas&&) noexcept = default;
Canvas& Canvas::operator=(Canvas&&) noexcept = default;

void Canvas::line(double x0, double y0, double x1, double y1, Rgb c, double line_width) {
    impl_->steps.push_back([=](cairo_t* cr) {
        set_colour(cr, c);
        cairo_set_line_width(cr, line_width);
        cairo_set_line_cap(cr, CAIRO_LINE_CAP_SQUARE);
        cairo_move_to(cr, x0, y0);
        cairo_line_to(cr, x1, y1);
        cairo_stroke(cr);
    });
}

void Canvas::polyline(const std::vector<double>& xy, Rgb c, double line_width) {
    if (xy.size() < 4) return;
    impl_->steps.push_back([=](cairo_t* cr) {
        set_colour(cr, c);
        cairo_set_line_width(cr, line_width);
        cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
        cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
        cairo_move_to(cr, xy[0], xy[1]);
        for (std::size_t i = 2; i + 1 < xy.size(); i += 2) cairo_line_to(cr, xy[i], xy[i + 1]);
        cairo_stroke(cr);
    });
}

void Canvas::fill_rect(double x, double y, double w, double h, Rgb c) {
    impl_->steps.push_back([=](cairo_t* cr) {
        set_colour(cr, c);
        cairo_rectangle(cr, x, y, w, h);
        cairo_fill(cr);
    });
}

void Canvas::stroke_rect(double x, double y, double w, double h, Rgb c, double line_width) {
    impl_->steps.push_back([=](cairo_t* cr) {
        set_colour(cr, c);
        cairo_set_line_width(cr, line_width);
        cairo_set_line_join(cr, CAIRO_LINE_JOIN_MITER);
        cairo_rectangle(cr, x, y, w, h);
        cairo_stroke(cr);
    });
}

void Canvas::fill_circle(double cx, double cy, double r, Rgb c) {
    impl_->steps.push_back([=](cairo_t* cr) {
        set_colour(cr, c);
        cairo_new_sub_path(cr);
        cairo_arc(cr, cx, cy, r, 0, 2 * M_PI);
        cairo_fill(cr);
    });
}

void Canvas::image(const RgbImage& img, int x, int y) {
    if (img.width() == 0) return;
    auto copy = std::make_shared<const RgbImage>(img);
    impl_->steps.push_back([copy, x, y](cairo_t* cr) {
        cairo_surface_t* s = surface_of(*copy);
        cairo_save(cr);
        cairo_set_source_surface(cr, s, x, y);
        cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
        cairo_rectangle(cr, x, y, copy->width(), copy->height());
        cairo_fill(cr);
        cairo_restore(cr);
        cairo_surface_destroy(s);
    });
}

void Canvas::text(double x, double y, std::string_view text, double size, Rgb c, Align align, VAlign valign,
                  bool vertical) {
    if (text.empty()) return;
    impl_->steps.push_back([=, s = std::string(text)](cairo_t* cr) {
        use_figure_font(cr, size);
        cairo_text_extents_t e;
        cairo_text_extents(cr, s.c_str(), &e);
        cairo_font_extents_t fe;
        cairo_font_extents(cr, &fe);
        double dx = 0, dy = 0;  // from the anchor to the baseline's start, along the text
        if (align == Align::centre) dx = -e.x_advance / 2;
        if (align == Align::right) dx = -e.x_advance;
        switch (valign) {
            case VAlign::top: dy = fe.ascent; break;
            case VAlign::middle: dy = (fe.ascent - fe.descent) / 2; break;
            case VAlign::baseline: dy = 0; break;
            case VAlign::bottom: dy = -fe.descent; break;
        }
        cairo_save(cr);
        cairo_translate(cr, x, y);
        if (vertical) cairo_rotate(cr, -M_PI / 2);
        set_colour(cr, c);
        cairo_move_to(cr, dx, dy);
        cairo_show_text(cr, s.c_str());
        cairo_restore(cr);
    });
}

namespace {
// Every step onto `cr`; its status after them.
cairo_status_t replay(const std::vector<std::function<void(cairo_t*)>>& steps, cairo_t* cr) {
    for (const auto& step : steps) step(cr);
    return cairo_status(cr);
}
}  // namespace

RgbImage Canvas::rasterise() const {
    cairo_surface_t* s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width_, height_);
    cairo_t* cr = cairo_create(s);
    const cairo_status_t st = replay(impl_->steps, cr);
    cairo_destroy(cr);
    cairo_surface_flush(s);
    if (st != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(s);
        throw std::runtime_error(std::string("figure: cannot rasterise: ") + cairo_status_to_string(st));
    }
    RgbImage out(width_, height_);
    const unsigned char* data = cairo_image_surface_get_data(s);
    const int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < height_; ++y) {
        const auto* row = reinterpret_cast<const std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
        for (int x = 0; x < width_; ++x) {
            const std::uint32_t p = row[x];
            out.set(x, y, {static_cast<std::uint8_t>(p >> 16), static_cast<std::uint8_t>(p >> 8),
                           static_cast<std::uint8_t>(p)});
        }
    }
    cairo_surface_destroy(s);
    return out;
}

void Canvas::write(const std::string& path, FigureFormat format) const {
    if (format == FigureFormat::png) {
        write_png(path, rasterise());
        return;
    }
    // Encoded in memory, then written through OutputFile (a temporary file renamed on success).
    std::string encoded;
    cairo_surface_t* s = format == FigureFormat::svg
                             ? cairo_svg_surface_create_for_stream(append_to_string, &encoded, width_, height_)
                             : cairo_pdf_surface_create_for_stream(append_to_string, &encoded, width_, height_);
    if (format == FigureFormat::pdf) cairo_pdf_surface_set_metadata(s, CAIRO_PDF_METADATA_CREATOR, "evcorner");
    cairo_t* cr = cairo_create(s);
    cairo_status_t st = replay(impl_->steps, cr);
    cairo_show_page(cr);
    if (st == CAIRO_STATUS_SUCCESS) st = cairo_status(cr);
    cairo_destroy(cr);
    cairo_surface_finish(s);
    if (st == CAIRO_STATUS_SUCCESS) st = cairo_surface_status(s);
    cairo_surface_destroy(s);
    if (st != CAIRO_STATUS_SUCCESS)
        throw OutputError(path, std::string("cannot encode the figure: ") + cairo_status_to_string(st));
    io::OutputFile out(path);
    out.write(encoded);
    out.close();
}

void Canvas::write(const std::string& path) const {
    const auto f = figure_format_of(path);
    if (!f) throw std::invalid_argument("figure file must end in .png, .svg or .pdf: " + path);
    write(path, *f);
}

}  // namespace evcorner::render
