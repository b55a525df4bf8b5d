// evcorner render as a user runs it: refusals and their exit codes, the streamed figure
// against the figure drawn from the whole input in memory (what render did before it
// streamed), and the frame around the figures.

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "cli_test_util.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/eval/feature_tracks.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/render/figures.hpp"
#include "evcorner/render/frame.hpp"
#include "evcorner/render/image.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;
using render::RgbImage;

class CliRender : public test::CliTest {
protected:
    std::string sample() const { return "'" + sample_.string() + "'"; }

    // The whole sample in memory, its efast corners: the pipeline render had before it streamed.
    void load_whole_sample() {
        const auto reader = io::open_event_reader(sample_.string());
        events_ = io::read_all_events(*reader);
        AnyDetector det = make_detector("efast", kDavis240);
        std::vector<std::uint8_t> flags(events_.size());
        std::visit([&](auto& d) { detect(d, std::span<const Event>(events_), flags); }, det);
        for (std::size_t i = 0; i < events_.size(); ++i)
            if (flags[i]) corners_.push_back(events_[i]);
    }
    RgbImage png(const std::string& name) { return render::read_png((dir_ / name).string()); }

    std::vector<Event> events_, corners_;
};

// Whether `inner` appears pixel for pixel in `outer`; its top-left into *x, *y.
bool find_sub_image(const RgbImage& outer, const RgbImage& inner, int* x, int* y) {
    for (int oy = 0; oy + inner.height() <= outer.height(); ++oy)
        for (int ox = 0; ox + inner.width() <= outer.width(); ++ox) {
            bool same = true;
            for (int iy = 0; iy < inner.height() && same; ++iy)
                for (int ix = 0; ix < inner.width() && same; ++ix) same = outer.at(ox + ix, oy + iy) == inner.at(ix, iy);
            if (same) {
                *x = ox;
                *y = oy;
                return true;
            }
        }
    return false;
}

// Pixels of the rows [y0, y1) dark enough to be the frame's text or axes (anti-aliased:
// darker than mid-grey on the white frame).
int dark_pixels(const RgbImage& img, int y0, int y1) {
    int n = 0;
    for (int y = std::max(0, y0); y < std::min(img.height(), y1); ++y)
        for (int x = 0; x < img.width(); ++x) n += img.at(x, y).g < 128;
    return n;
}

// The first bytes of a file.
std::string file_head(const fs::path& p, std::size_t n) {
    std::ifstream in(p, std::ios::binary);
    std::string s(n, '\0');
    in.read(s.data(), static_cast<std::streamsize>(n));
    s.resize(static_cast<std::size_t>(in.gcount()));
    return s;
}

TEST_F(CliRender, RefusesOutputsThatAreNotPngSvgOrPdf) {
    for (const std::string name : {"x.jpg", "x.png.txt", "x", "-"}) {
        const auto r = run("render " + sample() + " -k sae -o " + name);
        EXPECT_EQ(r.status, 2) << name << r.err;
        EXPECT_NE(r.err.find("PNG, SVG or PDF images only"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir_ / name)) << name;
    }
    EXPECT_EQ(run("render " + sample() + " -k sae -o UPPER.PNG").status, 0);
    EXPECT_EQ(png("UPPER.PNG").width() > 0, true);
}

TEST_F(CliRender, WritesSvgAndPdfByTheOutputsExtension) {
    for (const std::string args : {"-k space-time --window 20", "-k corners --no-frame"}) {
        ASSERT_EQ(run("render " + sample() + " " + args + " -o f.svg").status, 0) << args;
        ASSERT_EQ(run("render " + sample() + " " + args + " -o f.Pdf").status, 0) << args;
        EXPECT_GT(fs::file_size(dir_ / "f.svg"), 1000u) << args;
        const std::string svg = file_head(dir_ / "f.svg", 200);
        EXPECT_TRUE(svg.starts_with("<?xml") && svg.find("<svg") != std::string::npos) << args << svg;
        EXPECT_TRUE(file_head(dir_ / "f.Pdf", 8).starts_with("%PDF-")) << args;
        EXPECT_GT(fs::file_size(dir_ / "f.Pdf"), 1000u) << args;
    }
}

TEST_F(CliRender, EmptyInputIsADataError) {
    write("empty.txt", "");
    for (const std::string kind : {"sae", "corners", "space-time", "labels"}) {
        const auto r = run("render empty.txt -k " + kind + " -o e.png");
        EXPECT_EQ(r.status, 1) << kind << r.err;
        EXPECT_NE(r.err.find("empty.txt: no events to draw"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir_ / "e.png"));
    }
}

TEST_F(CliRender, AtOutsideTheStreamAndBadWindowsAreUsageErrors) {
    // The sample runs from 51.980787 s to 52.026841 s.
    for (const std::string at : {"60", "51.9", "+1", "-1"}) {
        const auto r = run("render " + sample() + " -k corners --at " + at + " -o x.png");
        EXPECT_EQ(r.status, 2) << at << r.err;
        EXPECT_NE(r.err.find("--at " + at), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("51.980787 s"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("52.026841 s"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir_ / "x.png"));
    }
    for (const std::string w : {"-5", "0", "abc"}) {
        const auto r = run("render " + sample() + " -k space-time --window=" + w + " -o x.png");
        EXPECT_EQ(r.status, 2) << w << r.err;
        EXPECT_NE(r.err.find("--window: must be a number of milliseconds > 0"), std::string::npos) << r.err;
    }
    // Both ends of the stream are inside it.
    EXPECT_EQ(run("render " + sample() + " -k sae --at 51.980787 -o a.png").status, 0);
    EXPECT_EQ(run("render " + sample() + " -k sae --at 52.026841 -o b.png").status, 0);
}

TEST_F(CliRender, StreamedFiguresEqualTheWholeInputInMemory) {
    load_whole_sample();
    const std::int64_t first = events_.front().t, last = events_.back().t;
    const SensorSize size = kDavis240;
    struct Case {
        std::string args;
        RgbImage expected;
    };
    const std::int64_t mid = first + 30'000;
    std::vector<Case> cases;
    cases.push_back({"-k sae", render::upscale(render::render_sae(events_, size, 1, last, 50'000), 2)});
    cases.push_back({"-k sae --polarity 0 --window 10 --at +0.03",
                     render::upscale(render::render_sae(events_, size, 0, mid, 10'000), 2)});
    cases.push_back({"-k corners", render::upscale(render::render_recent_corners(events_, corners_, size, last), 2)});
    render::RecentCornersStyle narrow;
    narrow.older_us = 20'000;
    cases.push_back({"-k corners --window 20 --at +0.03 --scale 1",
                     render::render_recent_corners(events_, corners_, size, mid, narrow)});
    cases.push_back({"-k space-time --window 20 --at +0.03",
                     render::render_space_time(events_, corners_, {}, size, mid - 20'000, mid)});
    // "-S" counts back from the last event, which streaming learns only at the end.
    cases.push_back({"-k space-time --window 15 --at -0.01",
                     render::render_space_time(events_, corners_, {}, size, last - 25'000, last - 10'000)});
    for (const auto overlap : {eval::TrackOverlap::any, eval::TrackOverlap::exclusive}) {
        eval::FeatureTrackParams p;
        p.overlap = overlap;
        p.max_duration_us = 10'000;  // shorter than the sample, so that the window's edges matter
        const auto labels = eval::label_feature_tracks(corners_, p).on_track;
        cases.push_back({"-k labels --ft-max-duration 10000 --ft-overlap " + std::string(eval::to_string(overlap)) +
                             " --window 12 --at +0.025",
                         render::render_space_time(events_, corners_, labels, size, first + 13'000, first + 25'000)});
    }
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const std::string name = "case" + std::to_string(i) + ".png";
        const auto r = run("render " + sample() + " --no-frame " + cases[i].args + " -o " + name);
        ASSERT_EQ(r.status, 0) << cases[i].args << r.err;
        const RgbImage got = png(name);
        ASSERT_EQ(got.width(), cases[i].expected.width()) << cases[i].args;
        ASSERT_EQ(got.height(), cases[i].expected.height()) << cases[i].args;
        EXPECT_TRUE(got.bytes() == cases[i].expected.bytes()) << cases[i].args;
    }
}

TEST_F(CliRender, CornersFromAFileGiveTheSameFigureAsDetecting) {
    ASSERT_EQ(run("detect " + sample() + " -o c.txt").status, 0);
    for (const std::string kind : {"corners", "space-time", "space-time --window 20", "labels --window 20", "labels"}) {
        ASSERT_EQ(run("render " + sample() + " --no-frame -k " + kind + " -o a.png").status, 0) << kind;
        const auto r = run("render " + sample() + " --no-frame -k " + kind + " --corners c.txt -o b.png");
        ASSERT_EQ(r.status, 0) << kind << r.err;
        EXPECT_TRUE(png("a.png").bytes() == png("b.png").bytes()) << kind;
    }
}

TEST_F(CliRender, FramesHoldTheFigureWithTitleAxesAndLegend) {
    for (const std::string kind : {"sae", "corners"}) {
        ASSERT_EQ(run("render " + sample() + " --no-frame -k " + kind + " -o bare.png").status, 0);
        const auto r = run("render " + sample() + " -k " + kind + " -o framed.png");
        ASSERT_EQ(r.status, 0) << r.err;
        const RgbImage bare = png("bare.png"), framed = png("framed.png");
        int bx = 0, by = 0;
        ASSERT_TRUE(find_sub_image(framed, bare, &bx, &by)) << kind << ": the figure is not inside the frame unchanged";
        // Title text above the figure, tick labels and legend below it.
        EXPECT_GT(dark_pixels(framed, 0, by - 1), 200) << kind;
        EXPECT_GT(dark_pixels(framed, by + bare.height() + 1, framed.height()), 200) << kind;
        // The axes: a box one pixel outside the figure, with ticks pointing outwards.
        for (int y = by - 1; y <= by + bare.height(); ++y) {
            ASSERT_EQ(framed.at(bx - 1, y), render::kAxisInk) << kind << " left axis at row " << y;
            ASSERT_EQ(framed.at(bx + bare.width(), y), render::kAxisInk) << kind << " right edge at row " << y;
        }
        for (int x = bx - 1; x <= bx + bare.width(); ++x)
            ASSERT_EQ(framed.at(x, by + bare.height()), render::kAxisInk) << kind << " x axis at column " << x;
        int ticks = 0;  // x ticks below the axis
        for (int x = bx; x < bx + bare.width(); ++x) ticks += framed.at(x, by + bare.height() + 2) == render::kAxisInk;
        EXPECT_GE(ticks, 4) << kind;
        EXPECT_NE(r.err.find("t = 52.026841 s"), std::string::npos) << r.err;
    }
    for (const std::string kind : {"space-time", "labels"}) {
        ASSERT_EQ(run("render " + sample() + " --no-frame -k " + kind + " --window 20 -o bare.png").status, 0);
        ASSERT_EQ(run("render " + sample() + " -k " + kind + " --window 20 -o framed.png").status, 0);
        const RgbImage bare = png("bare.png"), framed = png("framed.png");
        EXPECT_GT(framed.width(), bare.width());
        EXPECT_GT(framed.height(), bare.height());
        EXPECT_GT(dark_pixels(framed, 0, 40), 200) << kind << ": no title";
        EXPECT_GT(dark_pixels(framed, framed.height() - 30, framed.height()), 100) << kind << ": no legend";
        int axis = 0;
        for (int y = 0; y < framed.height(); ++y)
            for (int x = 0; x < framed.width(); ++x) axis += framed.at(x, y) == render::kAxisInk;
        EXPECT_GT(axis, 480 + 360 * 2) << kind << ": axes missing";  // three edges, their ticks, the swatches
    }
}

TEST_F(CliRender, SpaceTimeDefaultsToAReadableWindow) {
    const auto r = run("render " + sample() + " -k space-time -o st.png");
    ASSERT_EQ(r.status, 0) << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.err, m, std::regex(R"(space-time \d+x\d+, ([0-9.]+) ms from t0 = ([0-9.]+) s to ([0-9.]+) s, (\d+) events)")))
        << r.err;
    const double window_ms = std::stod(m[1]);
    const long drawn = std::stol(m[4]);
    // The sample spans 46 ms with 30 000 events: the default draws a part of it, ending at the last event.
    EXPECT_LT(window_ms, 46);
    EXPECT_GT(window_ms, 0);
    EXPECT_EQ(m[3].str(), "52.026841");
    EXPECT_LE(drawn, 20'000);
    EXPECT_GE(drawn, 15'000);
}

// Two tracks over a handful of events, on a 240x180 sensor (a text file's default):
// track 0 runs along row 30 from x = 20 to 60, track 1 down column 100 from y = 50 to 120,
// at 10 ms steps. The figure is drawn at the last event, t = 1.05 s, with the default
// 100 ms trail: track 0's sample at 0.9 s is too old, its sample at 1.2 s too new.
TEST_F(CliRender, TracksKindDrawsEachTrackAsATrailInItsColour) {
    write("ev.txt",
          "1.000000 5 5 1\n"
          "1.020000 200 150 0\n"
          "1.050000 5 5 1\n");
    write("tracks.txt",
          "# id t x y\n"
          "0 0.900000 20 150\n"
          "0 1.010000 20 30\n"
          "1 1.010000 100 50\n"
          "0 1.020000 33.3 30\n"
          "1 1.030000 100 85\n"
          "0 1.030000 46.7 30\n"
          "1 1.040000 100 120\n"
          "0 1.040000 60 30\n"
          "0 1.200000 200 30\n");
    const auto bare = run("render ev.txt -k tracks --tracks tracks.txt --no-frame -o bare.png");
    ASSERT_EQ(bare.status, 0) << bare.err;
    EXPECT_NE(bare.err.find("trails of the last 100 ms, 2 tracks"), std::string::npos) << bare.err;
    const RgbImage img = png("bare.png");
    ASSERT_EQ(img.width(), 480);
    ASSERT_EQ(img.height(), 360);
    const render::Rgb c0 = render::track_colour(0), c1 = render::track_colour(1);
    ASSERT_NE(c0, c1);
    // Sensor pixel (x, y) is the 2x2 block at (2x, 2y); these look at its lower right.
    auto at = [&](int x, int y) { return img.at(2 * x + 1, 2 * y + 1); };
    for (int x = 20; x <= 60; x += 5) EXPECT_EQ(at(x, 30), c0) << "track 0 at x = " << x;
    for (int y = 50; y <= 120; y += 10) EXPECT_EQ(at(100, y), c1) << "track 1 at y = " << y;
    // The dots at the latest samples: 3x3 sensor pixels centred on them.
    EXPECT_EQ(at(61, 31), c0);
    EXPECT_EQ(at(99, 121), c1);
    EXPECT_NE(at(58, 32), c0);  // beyond the dot
    // Away from the trails: black, the events grey; nothing of the samples outside the window.
    const render::Rgb black{0, 0, 0}, grey{150, 150, 150};
    EXPECT_EQ(at(40, 80), black);
    EXPECT_EQ(at(20, 100), black) << "the 0.9 s sample is older than the trail";
    EXPECT_EQ(at(150, 30), black) << "the 1.2 s sample is after --at";
    EXPECT_EQ(at(5, 5), grey);
    EXPECT_EQ(at(200, 150), grey);

    // The framed figure holds that one unchanged.
    const auto framed = run("render ev.txt -k tracks --tracks tracks.txt -o out.png");
    ASSERT_EQ(framed.status, 0) << framed.err;
    ASSERT_TRUE(fs::exists(dir_ / "out.png"));
    int bx = 0, by = 0;
    EXPECT_TRUE(find_sub_image(png("out.png"), img, &bx, &by));

    // --at and --window pick the window as for -k corners: (1.015 s, 1.025 s] holds track
    // 0's sample of 1.02 s alone (a dot, no trail) and none of track 1's.
    const auto narrow = run("render ev.txt -k tracks --tracks tracks.txt --no-frame --at 1.025 --window 10 -o n.png");
    ASSERT_EQ(narrow.status, 0) << narrow.err;
    EXPECT_NE(narrow.err.find("trails of the last 10 ms, 1 track"), std::string::npos) << narrow.err;
    const RgbImage n = png("n.png");
    EXPECT_EQ(n.at(2 * 33 + 1, 2 * 30 + 1), c0);
    EXPECT_EQ(n.at(2 * 50 + 1, 2 * 30 + 1), black);
    EXPECT_EQ(n.at(2 * 100 + 1, 2 * 50 + 1), black);
}

TEST_F(CliRender, TracksKindAndTracksOptionGoTogether) {
    write("ev.txt", "1.000000 5 5 1\n1.050000 5 5 1\n");
    write("tracks.txt", "0 1.01 20 30\n0 1.02 30 30\n");
    const auto missing = run("render ev.txt -k tracks -o t.png");
    EXPECT_EQ(missing.status, 2) << missing.err;
    EXPECT_NE(missing.err.find("-k tracks needs --tracks FILE"), std::string::npos) << missing.err;
    const auto other = run("render ev.txt -k corners --tracks tracks.txt -o t.png");
    EXPECT_EQ(other.status, 2) << other.err;
    EXPECT_NE(other.err.find("--tracks applies to -k tracks only (this is -k corners)"), std::string::npos)
        << other.err;
    const auto corners = run("render ev.txt -k tracks --tracks tracks.txt --corners ev.txt -o t.png");
    EXPECT_EQ(corners.status, 2) << corners.err;
    EXPECT_NE(corners.err.find("--corners applies to -k corners or space-time or labels only (this is -k tracks)"),
              std::string::npos)
        << corners.err;
    EXPECT_FALSE(fs::exists(dir_ / "t.png"));
}

}  // namespace
}  // namespace evcorner
