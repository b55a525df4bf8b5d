// Figures: sizes, colours where the inputs put them, PNG round trip and decoding; the
// Cairo-drawn frames and charts checked by pixels at known positions (never by bytes: text
// is anti-aliased), and their SVG / PDF files by their first bytes.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "evcorner/error.hpp"
#include "evcorner/render/figures.hpp"
#include "evcorner/render/canvas.hpp"
#include "evcorner/render/charts.hpp"
#include "evcorner/render/frame.hpp"
#include "evcorner/render/image.hpp"

namespace evcorner::render {
namespace {

namespace fs = std::filesystem;
constexpr SensorSize kSize{40, 30};

std::size_t distinct_colours(const RgbImage& img) {
    std::set<int> c;
    for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
            const Rgb p = img.at(x, y);
            c.insert(p.r << 16 | p.g << 8 | p.b);
        }
    return c.size();
}

TEST(Render, SaeNewestBrightOldDarkOtherPolarityBlack) {
    const std::vector<Event> ev{{0, 1, 1, 1}, {50'000, 2, 2, 1}, {99'000, 3, 3, 1}, {100'000, 4, 4, 1},
                                {100'000, 5, 5, 0}, {200'000, 6, 6, 1}};
    const RgbImage img = render_sae(ev, kSize, 1, 100'000, 100'000);
    EXPECT_EQ(img.width(), 40);
    EXPECT_EQ(img.height(), 30);
    EXPECT_EQ(img.at(4, 4), (Rgb{255, 255, 255}));  // newest
    EXPECT_EQ(img.at(2, 2).r, 128);                 // half the window old
    EXPECT_GT(img.at(3, 3).r, img.at(2, 2).r);
    EXPECT_EQ(img.at(1, 1), (Rgb{}));  // a full window old
    EXPECT_EQ(img.at(5, 5), (Rgb{}));  // the other polarity
    EXPECT_EQ(img.at(6, 6), (Rgb{}));  // after `at`
}

TEST(Render, RecentCornersBrightAndDarkByPolarity) {
    const std::vector<Event> ev{{90'000, 20, 20, 1}};
    const std::vector<Event> corners{{95'000, 10, 10, 1}, {95'000, 30, 10, 0}, {40'000, 10, 20, 1},
                                     {40'000, 30, 20, 0}, {0, 20, 5, 1}};
    const RgbImage img = render_recent_corners(ev, corners, kSize, 100'000);
    EXPECT_EQ(img.at(10, 10), kOnBright);
    EXPECT_EQ(img.at(30, 10), kOffBright);
    EXPECT_EQ(img.at(10, 20), kOnDark);
    EXPECT_EQ(img.at(30, 20), kOffDark);
    EXPECT_EQ(img.at(20, 5), (Rgb{}));        // older than 100 ms
    EXPECT_EQ(img.at(20, 20), (Rgb{150, 150, 150}));  // an event of the last 33 ms
}

TEST(Render, SpaceTimeDrawsLabelsInTheirColours) {
    std::vector<Event> ev, corners;
    for (int i = 0; i < 100; ++i) ev.push_back({i * 1000, static_cast<std::uint16_t>(i % 40), 15, 1});
    corners = {{10'000, 5, 5, 1}, {60'000, 30, 20, 0}};
    const std::vector<std::uint8_t> labels{1, 0};
    SpaceTimeStyle style;
    style.scale = 1;
    style.time_height = 100;
    const RgbImage img = render_space_time(ev, corners, labels, kSize, 0, 100'000, style);
    EXPECT_GT(img.width(), kSize.width);
    EXPECT_GT(img.height(), 100);
    bool green = false, red = false;
    for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
            green |= img.at(x, y) == kOnTrack;
            red |= img.at(x, y) == kOffTrack;
        }
    EXPECT_TRUE(green);
    EXPECT_TRUE(red);
    EXPECT_THROW(render_space_time(ev, corners, std::vector<std::uint8_t>{1}, kSize, 0, 1000), std::invalid_argument);
    EXPECT_THROW(render_space_time(ev, corners, {}, kSize, 5, 5), std::invalid_argument);
}

TEST(Render, PngRoundTripAndErrors) {
    RgbImage img(7, 5, {10, 20, 30});
    img.line(0, 0, 6, 4, {1, 2, 3});
    img.set(3, 2, {255, 0, 128});
    const RgbImage big = upscale(img, 3);
    EXPECT_EQ(big.width(), 21);
    EXPECT_EQ(big.at(11, 7), (Rgb{255, 0, 128}));  // (3, 2) scaled by 3
    EXPECT_EQ(big.at(0, 0), (Rgb{1, 2, 3}));
    EXPECT_EQ(big.at(20, 14), (Rgb{1, 2, 3}));  // the line's end (6, 4)
    EXPECT_EQ(big.at(20, 0), (Rgb{10, 20, 30}));
    const fs::path p = fs::temp_directory_path() / "evcorner-render-test.png";
    write_png(p.string(), big);
    const RgbImage back = read_png(p.string());
    fs::remove(p);
    ASSERT_EQ(back.width(), 21);
    ASSERT_EQ(back.height(), 15);
    EXPECT_EQ(back.bytes(), big.bytes());
    EXPECT_GE(distinct_colours(back), 3u);
    EXPECT_THROW(write_png("/no/such/dir/x.png", img), OutputError);
    EXPECT_THROW(read_png("/no/such/file.png"), InputError);
    EXPECT_THROW(RgbImage(0, 3), std::invalid_argument);
}


TEST(Frame, NiceTicksAndLabels) {
    EXPECT_EQ(nice_ticks(0, 239, 40), (std::vector<double>{0, 50, 100, 150, 200}));
    EXPECT_EQ(nice_ticks(0, 179, 21), (std::vector<double>{0, 50, 100, 150}));
    EXPECT_EQ(nice_ticks(0, 10, 1.5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
    const auto t = nice_ticks(0, 1, 0.3);
    ASSERT_EQ(t.size(), 3u);
    EXPECT_EQ(tick_label(t[1], 0.5), "0.5");
    EXPECT_EQ(tick_label(120, 20), "120");
    EXPECT_EQ(tick_label(-0.0001, 0.1), "0.0");
    EXPECT_THROW(nice_ticks(1, 0, 1), std::invalid_argument);
    EXPECT_THROW(nice_ticks(0, 1, 0), std::invalid_argument);
}

// Pixels of `img` in [x0, x1) x [y0, y1) darker than mid-grey: text and axes on white.
int dark_pixels(const RgbImage& img, int x0, int y0, int x1, int y1) {
    int n = 0;
    for (int y = std::max(0, y0); y < std::min(img.height(), y1); ++y)
        for (int x = std::max(0, x0); x < std::min(img.width(), x1); ++x) n += img.at(x, y).g < 128;
    return n;
}

int count_colour(const RgbImage& img, Rgb c, int y0 = 0, int y1 = 1 << 30) {
    int n = 0;
    for (int y = std::max(0, y0); y < std::min(img.height(), y1); ++y)
        for (int x = 0; x < img.width(); ++x) n += img.at(x, y) == c;
    return n;
}

TEST(Frame, SensorFigureKeepsTheBodyAndDrawsAxesTitleLegend) {
    RgbImage body(80, 60, {0, 0, 0});
    body.set(3, 4, {1, 2, 3});
    FigureFrame f;
    f.title = {"a title"};
    f.legend = {{kOnBright, "ON corner"}};
    const Framed out = frame_sensor_figure(body, kSize, 2, f);
    const RgbImage img = out.figure.rasterise();
    EXPECT_EQ(img.width(), out.figure.width());
    for (int y = 0; y < body.height(); ++y)
        for (int x = 0; x < body.width(); ++x) ASSERT_EQ(img.at(out.body_x + x, out.body_y + y), body.at(x, y));
    EXPECT_EQ(img.at(0, 0), kFrameBackground);
    EXPECT_EQ(img.at(out.body_x - 1, out.body_y + 10), kAxisInk);  // the left axis
    EXPECT_EQ(img.at(out.body_x + 10, out.body_y + body.height()), kAxisInk);  // the x axis
    EXPECT_EQ(img.at(out.body_x - 1, out.body_y - 1), kAxisInk);  // the box's corner
    EXPECT_EQ(out.text_size, 12);  // a small body: the smallest text
    // The title's ink in the title's rows, left of where its text ends.
    const int title_w = static_cast<int>(text_width("a title", out.text_size));
    EXPECT_GT(dark_pixels(img, 0, 0, out.body_x + title_w + 20, out.body_y - 1), 20);
    EXPECT_GT(count_colour(img, kOnBright, out.body_y + body.height()), 16);  // the legend's swatch
    EXPECT_THROW(frame_sensor_figure(body, kSize, 1, f), std::invalid_argument);
}

TEST(Frame, TextGrowsWithTheFigure) {
    EXPECT_EQ(auto_text_size(480, 360), 12);
    EXPECT_GT(auto_text_size(1280, 960), 20);   // 640x480 at scale 2
    EXPECT_GT(auto_text_size(2560, 1440), auto_text_size(1280, 960));  // 1280x720 at scale 2
    EXPECT_LE(auto_text_size(60000, 60000), 64);
    // A 640x480 sensor's space-time frame: its tick labels as tall as a line of that size.
    const SensorSize vga{640, 480};
    SpaceTimeStyle style;
    style.time_height = 100;
    const RgbImage body = render_space_time({}, {}, {}, vga, 0, 10'000, style);
    FigureFrame f;
    f.title = {"space-time"};
    const Framed out = frame_space_time_figure(body, vga, 0, 10'000, style, f);
    EXPECT_EQ(out.text_size, auto_text_size(body.width(), body.height()));
    EXPECT_GE(out.text_size, 20);
    // The title's rows hold ink about a text size high.
    const RgbImage img = out.figure.rasterise();
    int first = -1, last = -1;
    for (int y = 0; y < out.body_y; ++y)
        if (dark_pixels(img, 0, y, img.width(), y + 1) > 0) {
            if (first < 0) first = y;
            last = y;
        }
    ASSERT_GE(first, 0);
    EXPECT_GE(last - first + 1, out.text_size * 0.6);
    EXPECT_LE(last - first + 1, out.text_size * 1.3);
}

TEST(Frame, SpaceTimeFrameDrawsOverTheLayoutsEdges) {
    SpaceTimeStyle style;
    style.scale = 1;
    style.time_height = 100;
    const RgbImage body = render_space_time({}, {}, {}, kSize, 0, 10'000, style);
    FigureFrame f;
    f.title = {"space-time"};
    const Framed out = frame_space_time_figure(body, kSize, 0, 10'000, style, f);
    const RgbImage img = out.figure.rasterise();
    const SpaceTimeLayout lay = space_time_layout(kSize, style);
    int u = 0, v = 0;
    lay.project(0, kSize.height - 1, 0.5, u, v);  // on the time axis
    EXPECT_EQ(img.at(out.body_x + u, out.body_y + v), kAxisInk);
    EXPECT_EQ(img.at(out.body_x + u + 3, out.body_y + v), body.at(u + 3, v));  // the body beside it
    lay.project(kSize.width / 2.0, kSize.height - 1, 0, u, v);  // on the x axis
    EXPECT_EQ(img.at(out.body_x + u, out.body_y + v), kAxisInk);
    lay.project(kSize.width - 1, kSize.height / 2.0, 0, u, v);  // on the y (depth) axis: anti-aliased, dark
    EXPECT_LT(img.at(out.body_x + u, out.body_y + v).g, 200);
    EXPECT_THROW(frame_space_time_figure(body, kSize, 5, 5, style, f), std::invalid_argument);
    EXPECT_THROW(frame_space_time_figure(RgbImage(3, 3), kSize, 0, 10, style, f), std::invalid_argument);
}

TEST(Canvas, LinesRectanglesAndImagesLandOnTheirPixels) {
    Canvas c(40, 30, {250, 250, 250});
    c.line(2.5, 5.5, 30.5, 5.5, {10, 20, 30});  // pixel centres of row 5, columns 2..30
    c.fill_rect(10, 10, 5, 4, {200, 0, 0});
    RgbImage patch(3, 2, {0, 0, 255});
    patch.set(1, 1, {0, 255, 0});
    c.image(patch, 20, 20);
    const RgbImage img = c.rasterise();
    EXPECT_EQ(img.at(0, 0), (Rgb{250, 250, 250}));
    EXPECT_EQ(img.at(2, 5), (Rgb{10, 20, 30}));
    EXPECT_EQ(img.at(30, 5), (Rgb{10, 20, 30}));
    EXPECT_EQ(img.at(31, 5), (Rgb{250, 250, 250}));
    EXPECT_EQ(img.at(16, 4), (Rgb{250, 250, 250}));
    EXPECT_EQ(img.at(16, 6), (Rgb{250, 250, 250}));
    EXPECT_EQ(img.at(10, 10), (Rgb{200, 0, 0}));
    EXPECT_EQ(img.at(14, 13), (Rgb{200, 0, 0}));
    EXPECT_EQ(img.at(15, 13), (Rgb{250, 250, 250}));
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) EXPECT_EQ(img.at(20 + x, 20 + y), patch.at(x, y));
    EXPECT_EQ(Canvas(patch).rasterise().bytes(), patch.bytes());
    EXPECT_THROW(Canvas(0, 5), std::invalid_argument);
}

TEST(Canvas, TextHasInkWhereItIsAnchoredAndWidthsScale) {
    const double w = text_width("Corner events", 20);
    EXPECT_GT(w, 60);
    EXPECT_NEAR(text_width("Corner events", 40), 2 * w, 1.0);  // unhinted: widths scale
    EXPECT_LT(text_width("ii", 20), text_width("WW", 20));     // a proportional font
    EXPECT_EQ(text_width("", 20), 0);
    EXPECT_NEAR(text_height(20), 2 * text_height(10), 0.5);
    Canvas c(200, 60);
    c.text(10, 10, "Corner events", 20, {0, 0, 0});
    c.text(190, 50, "x", 12, {0, 0, 0}, Align::right, VAlign::bottom);
    const RgbImage img = c.rasterise();
    const int right = 10 + static_cast<int>(std::ceil(w));
    EXPECT_GT(dark_pixels(img, 10, 10, right, 10 + static_cast<int>(text_height(20))), 50);
    EXPECT_EQ(dark_pixels(img, 0, 0, 200, 10), 0);          // nothing above the top anchor
    EXPECT_EQ(dark_pixels(img, right + 2, 0, 200, 40), 0);  // nor right of its advance
    EXPECT_GT(dark_pixels(img, 170, 30, 190, 50), 3);       // the right/bottom-anchored "x"
    EXPECT_EQ(dark_pixels(img, 190, 30, 200, 60), 0);
}

TEST(Canvas, SvgAndPdfFilesStartWithTheirMagic) {
    Canvas c(120, 80);
    c.line(0.5, 0.5, 100.5, 70.5, {0, 0, 0});
    c.text(5, 5, "SVG and PDF", 12, {0, 0, 0});
    c.image(RgbImage(4, 4, {255, 0, 0}), 50, 50);
    const fs::path dir = fs::temp_directory_path() / "evcorner-render-canvas-test";
    fs::create_directories(dir);
    const auto head = [](const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        std::string s(64, '\0');
        in.read(s.data(), 64);
        s.resize(static_cast<std::size_t>(in.gcount()));
        return s;
    };
    c.write((dir / "a.svg").string());
    c.write((dir / "a.PDF").string());
    c.write((dir / "a.png").string(), FigureFormat::png);
    EXPECT_GT(fs::file_size(dir / "a.svg"), 100u);
    EXPECT_GT(fs::file_size(dir / "a.PDF"), 100u);
    const std::string svg = head(dir / "a.svg");
    EXPECT_TRUE(svg.starts_with("<?xml") && svg.find("<svg") != std::string::npos) << svg;
    EXPECT_TRUE(head(dir / "a.PDF").starts_with("%PDF-"));
    EXPECT_TRUE(head(dir / "a.png").starts_with("\x89PNG"));
    EXPECT_EQ(read_png((dir / "a.png").string()).at(51, 51), (Rgb{255, 0, 0}));
    EXPECT_THROW(c.write((dir / "a.jpg").string()), std::invalid_argument);
    EXPECT_THROW(c.write("/no/such/dir/a.svg"), OutputError);
    fs::remove_all(dir);
    EXPECT_EQ(figure_format_of("x.Svg"), FigureFormat::svg);
    EXPECT_EQ(figure_format_of("x.png.txt"), std::nullopt);
    EXPECT_EQ(parse_figure_format("pdf"), FigureFormat::pdf);
    EXPECT_THROW(parse_figure_format("jpg"), std::invalid_argument);
}

TEST(Charts, LineChartHasAxesTicksTitleAndLegend) {
    const std::vector<std::string> cats{"0-50", "50-100", "100-200", "200+"};
    const std::vector<ChartSeries> series{{"efast", series_colour(0), {10, 50, std::nan(""), 90}},
                                          {"harris", series_colour(1), {20, 20, 20, 20}}};
    const Canvas c = render_line_chart("precision against speed", cats, series, 100, "speed [px/s]", "precision [%]");
    const RgbImage img = c.rasterise();
    const ChartLayout l;
    ASSERT_EQ(img.width(), l.width);
    ASSERT_EQ(img.height(), l.height);
    EXPECT_EQ(img.at(2, 2), kChartBackground);
    const int base = l.plot_y + l.plot_h;  // the x axis's row
    EXPECT_EQ(img.at(l.plot_x + l.plot_w / 3, base), kChartAxis);
    EXPECT_EQ(img.at(l.plot_x - 1, l.plot_y + l.plot_h / 3), kChartAxis);  // the y axis's column
    EXPECT_EQ(img.at(l.plot_x - 3, base - static_cast<int>(std::lround(0.4 * l.plot_h))), kChartAxis);  // tick 40
    // Harris's line at y = 20 runs across the plot in its colour; efast's 10 -> 50 rises.
    const int y20 = base - static_cast<int>(std::lround(0.2 * l.plot_h));
    const double slot = static_cast<double>(l.plot_w) / 4;
    EXPECT_EQ(img.at(static_cast<int>(l.plot_x + 2 * slot), y20), series_colour(1));
    const int mid_x = static_cast<int>(l.plot_x + slot), mid_y = base - static_cast<int>(0.3 * l.plot_h);
    int on_line = 0;  // the line is 2 px wide, anti-aliased at its edges
    for (int y = mid_y - 3; y <= mid_y + 3; ++y) on_line += img.at(mid_x, y) == series_colour(0);
    EXPECT_GE(on_line, 1);
    // Between the NaN's neighbours (categories 1 and 3) no efast line: the gap.
    EXPECT_NE(img.at(static_cast<int>(l.plot_x + 2.5 * slot), base - static_cast<int>(0.7 * l.plot_h)), series_colour(0));
    EXPECT_GT(dark_pixels(img, l.plot_x, 0, l.plot_x + l.plot_w, l.plot_y - 2), 80);  // the title
    EXPECT_GT(dark_pixels(img, l.plot_x, base + 6, l.plot_x + l.plot_w, l.height), 80);  // tick numbers, x label
    EXPECT_GT(dark_pixels(img, 0, l.plot_y, 28, base), 30);                             // the y label
    // The legend: each series' colour right of the plot, and its name.
    const int lx = l.plot_x + l.plot_w + 10;
    int swatch = 0;
    for (int y = l.plot_y; y < l.plot_y + 40; ++y)
        for (int x = lx; x < img.width(); ++x) swatch += img.at(x, y) == series_colour(0);
    EXPECT_GT(swatch, 10);
    EXPECT_GT(dark_pixels(img, lx, l.plot_y, img.width(), l.plot_y + 50), 40);
    EXPECT_THROW(render_line_chart("t", {}, series, 100, "x", "y"), std::invalid_argument);
}

TEST(Charts, HistogramBarsReachTheirCounts) {
    // 0.5 three times, 1.5 once, 9.9 six times; 20 (>= hi) counts in the last bin, -1 nowhere.
    std::vector<float> v{0.5f, 0.5f, 0.5f, 1.5f, 9.9f, 9.9f, 9.9f, 9.9f, 9.9f, 20.0f, -1.0f};
    const Canvas c = render_histogram("errors", v, 0, 10, 10, "error [px]", "count", "true positives", {60, 90, 200});
    const RgbImage img = c.rasterise();
    const ChartLayout l;
    const int base = l.plot_y + l.plot_h;
    const Rgb bar{60, 90, 200};
    // The count axis ends at the largest count (6): a bar of 3 reaches half way, of 6 the top.
    const auto bar_height = [&](int bin) {
        const int x = l.plot_x + bin * l.plot_w / 10 + l.plot_w / 20;
        int h = 0;
        while (img.at(x, base - 1 - h) == bar) ++h;
        return h;
    };
    EXPECT_NEAR(bar_height(0), l.plot_h / 2, 2);
    EXPECT_NEAR(bar_height(1), l.plot_h / 6, 2);
    EXPECT_EQ(bar_height(5), 0);
    EXPECT_NEAR(bar_height(9), l.plot_h, 2);
    EXPECT_EQ(img.at(l.plot_x + 20, base), kChartAxis);
    EXPECT_GT(dark_pixels(img, 0, 0, l.width, l.plot_y - 2), 30);  // the title
    EXPECT_THROW(render_histogram("t", v, 1, 1, 5, "x", "y", ""), std::invalid_argument);
}

}  // namespace
}  // namespace evcorner::render
