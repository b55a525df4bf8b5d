// Figures: sizes, colours where the inputs put them, PNG round trip and decoding.

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "evcorner/error.hpp"
#include "evcorner/render/figures.hpp"
#include "evcorner/render/font.hpp"
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


TEST(Font, EveryPrintableCharacterHasItsOwnGlyphInsideItsBox) {
    std::set<std::string> seen;
    for (int c = 32; c <= 126; ++c) {
        const std::string s(1, static_cast<char>(c));
        RgbImage img(20, 20, {255, 255, 255});
        draw_text(img, 5, 6, s, {0, 0, 0}, 2);
        int ink = 0;
        for (int y = 0; y < 20; ++y)
            for (int x = 0; x < 20; ++x) {
                if (img.at(x, y) != Rgb{0, 0, 0}) continue;
                ++ink;
                EXPECT_TRUE(x >= 5 && x < 5 + text_width(s, 2) && y >= 6 && y < 6 + text_height(2)) << s;
            }
        EXPECT_EQ(ink > 0, c != ' ') << "'" << s << "'";
        EXPECT_TRUE(seen.insert(std::string(img.bytes().begin(), img.bytes().end())).second) << "'" << s << "' looks like another character";
    }
    EXPECT_EQ(text_width("", 1), 0);
    EXPECT_EQ(text_width("ab", 1), 11);
    RgbImage img(10, 10, {255, 255, 255});
    draw_text(img, 0, 0, "\x01", {0, 0, 0});  // outside printable ASCII: a box, not nothing
    draw_text(img, -50, -50, "clipped", {0, 0, 0}, 3);
    EXPECT_EQ(img.at(0, 0), (Rgb{0, 0, 0}));
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

TEST(Frame, SensorFigureKeepsTheBodyAndDrawsAxesTitleLegend) {
    RgbImage body(80, 60, {0, 0, 0});
    body.set(3, 4, {1, 2, 3});
    FigureFrame f;
    f.title = {"a title"};
    f.legend = {{kOnBright, "ON corner"}};
    const Framed out = frame_sensor_figure(body, kSize, 2, f);
    for (int y = 0; y < body.height(); ++y)
        for (int x = 0; x < body.width(); ++x) ASSERT_EQ(out.image.at(out.body_x + x, out.body_y + y), body.at(x, y));
    EXPECT_EQ(out.image.at(out.body_x - 1, out.body_y + 10), kAxisInk);
    EXPECT_EQ(out.image.at(out.body_x + 10, out.body_y + body.height()), kAxisInk);
    int title_ink = 0, swatch = 0;
    for (int y = 0; y < out.body_y; ++y)
        for (int x = 0; x < out.image.width(); ++x) title_ink += out.image.at(x, y) == kFrameInk;
    for (int y = out.body_y + body.height(); y < out.image.height(); ++y)
        for (int x = 0; x < out.image.width(); ++x) swatch += out.image.at(x, y) == kOnBright;
    EXPECT_GT(title_ink, 20);
    EXPECT_EQ(swatch, kGlyphHeight * kGlyphHeight);
    EXPECT_THROW(frame_sensor_figure(body, kSize, 1, f), std::invalid_argument);
}

TEST(Frame, SpaceTimeFrameDrawsOverTheLayoutsEdges) {
    SpaceTimeStyle style;
    style.scale = 1;
    style.time_height = 100;
    const RgbImage body = render_space_time({}, {}, {}, kSize, 0, 10'000, style);
    FigureFrame f;
    f.title = {"space-time"};
    const Framed out = frame_space_time_figure(body, kSize, 0, 10'000, style, f);
    const SpaceTimeLayout lay = space_time_layout(kSize, style);
    int u = 0, v = 0;
    lay.project(0, kSize.height - 1, 0.5, u, v);  // on the time axis
    EXPECT_EQ(out.image.at(out.body_x + u, out.body_y + v), kAxisInk);
    lay.project(kSize.width / 2.0, kSize.height - 1, 0, u, v);  // on the x axis
    EXPECT_EQ(out.image.at(out.body_x + u, out.body_y + v), kAxisInk);
    EXPECT_THROW(frame_space_time_figure(body, kSize, 5, 5, style, f), std::invalid_argument);
    EXPECT_THROW(frame_space_time_figure(RgbImage(3, 3), kSize, 0, 10, style, f), std::invalid_argument);
}

}  // namespace
}  // namespace evcorner::render
