// The figures evcorner eval writes into its report: framed (title, axes, legend), charts
// with axes and legends, PNG by default and SVG / PDF on request; and the FT column's
// reason where FT is 0 because no feature track was accepted.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_util.hpp"
#include "evcorner/render/charts.hpp"
#include "evcorner/render/frame.hpp"
#include "evcorner/render/image.hpp"

namespace evcorner::test {
namespace {

using RenderEval = CliTest;

// A small scene: a triangle crossing a 64x48 sensor in 0.2 s.
constexpr const char* kScene =
    R"({"sensor": [64, 48], "duration_s": 0.2, "seed": 5, "camera": {"contrast": 0.2}, "background": 0.5,
        "objects": [{"polygon": [[8, 8], [24, 10], [12, 24]], "intensity": 0.1, "motion": {"velocity": [80, 20]}}]})";

std::string head(const fs::path& p, std::size_t n) { return slurp(p).substr(0, n); }

// Pixels darker than mid-grey in the rows [y0, y1): text and axes on the white frame.
int dark_rows(const render::RgbImage& img, int y0, int y1) {
    int n = 0;
    for (int y = std::max(0, y0); y < std::min(img.height(), y1); ++y)
        for (int x = 0; x < img.width(); ++x) n += img.at(x, y).g < 128;
    return n;
}

TEST_F(RenderEval, FiguresAreFramedAndChartsHaveAxesAndLegends) {
    write("scene.json", kScene);
    ASSERT_EQ(run("simulate scene.json -o scene.npy --truth scene.truth.csv -q").status, 0);
    const CliResult r = run("eval scene.npy --truth scene.truth.csv -d efast,harris --repeat 1 -q --report rep");
    ASSERT_EQ(r.status, 0) << r.err;
    const fs::path figs = dir_ / "rep/figures";
    // The SAE: larger than the 2x sensor it frames, with the axis box around it.
    const render::RgbImage sae = render::read_png((figs / "scene.sae.png").string());
    EXPECT_GT(sae.width(), 2 * 64 + 40);
    EXPECT_GT(sae.height(), 2 * 48 + 60);
    EXPECT_EQ(sae.at(0, 0), render::kFrameBackground);
    EXPECT_GT(dark_rows(sae, 0, 30), 50);  // the title
    int axis_rows = 0;                     // rows holding the axis box's two sides (2 x 48 of them)
    for (int y = 0; y < sae.height(); ++y) {
        int n = 0;
        for (int x = 0; x < sae.width(); ++x) n += sae.at(x, y) == render::kAxisInk;
        axis_rows += n >= 2;
    }
    EXPECT_GE(axis_rows, 2 * 48);
    // A chart: its size, the x axis in the axis colour, the first series in the legend.
    const render::RgbImage pr = render::read_png((figs / "scene.pr.png").string());
    const render::ChartLayout l;
    ASSERT_GE(pr.width(), l.width);
    EXPECT_EQ(pr.at(l.plot_x + 10, l.plot_y + l.plot_h), render::kChartAxis);
    int legend = 0;
    for (int y = l.plot_y; y < l.plot_y + 50; ++y)
        for (int x = l.plot_x + l.plot_w + 10; x < pr.width(); ++x) legend += pr.at(x, y) == render::series_colour(0);
    EXPECT_GT(legend, 10);
    for (const char* f : {"scene.efast.corners.png", "scene.efast.labels.png", "scene.space_time.png",
                          "scene.precision_speed.png", "scene.recall_speed.png", "scene.efast.loc_error.png",
                          "scene.efast.truth_space_time.png"})
        EXPECT_TRUE(head(figs / f, 4) == "\x89PNG") << f;
}

TEST_F(RenderEval, FigureFormatSvgAndPdf) {
    for (const std::string fmt : {"svg", "pdf"}) {
        const std::string rep = "rep-" + fmt;
        const CliResult r = run("eval '" + sample_.string() + "' -d efast --repeat 1 -q --figure-format " + fmt +
                                " --report " + rep);
        ASSERT_EQ(r.status, 0) << r.err;
        for (const std::string f : {"shapes_translation.sae", "shapes_translation.space_time", "shapes_translation.efast.corners",
                                   "shapes_translation.efast.labels"}) {
            const fs::path p = dir_ / rep / "figures" / (f + "." + fmt);
            ASSERT_TRUE(fs::exists(p)) << p;
            EXPECT_GT(fs::file_size(p), 1000u) << p;
            if (fmt == "svg")
                EXPECT_TRUE(head(p, 5) == "<?xml" && head(p, 300).find("<svg") != std::string::npos) << p;
            else
                EXPECT_EQ(head(p, 5), "%PDF-") << p;
            EXPECT_FALSE(fs::exists(dir_ / rep / "figures" / (f + ".png"))) << f;
        }
        const std::string md = slurp(dir_ / rep / "report.md");
        EXPECT_NE(md.find("figures/shapes_translation.efast.corners." + fmt + ")"), std::string::npos) << md;
    }
    const CliResult bad = run("eval '" + sample_.string() + "' -d efast --figure-format jpg --report r");
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.err.find("--figure-format"), std::string::npos) << bad.err;
}

TEST_F(RenderEval, FtOfZeroSaysNoTrackReachedTheMinimum) {
    const CliResult r = run("eval '" + sample_.string() +
                            "' -d efast --repeat 1 -q --no-figures --ft-min-inner 100000 --report rep");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string why = "no track reached 100000 inner corner events";
    // The text table: the cell marked, the reason below it.
    EXPECT_NE(r.out.find("0.0*"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("* shapes_translation efast: FT 0.0: " + why), std::string::npos) << r.out;
    // The Markdown report: the reason in the cell.
    const std::string md = slurp(dir_ / "rep/report.md");
    EXPECT_NE(md.find("| 0.0 (" + why), std::string::npos) << md;
    // JSON: the number, and the reason beside it.
    const auto j = nlohmann::json::parse(slurp(dir_ / "rep/results.json"));
    ASSERT_EQ(j["runs"].size(), 1u);
    EXPECT_EQ(j["runs"][0]["ft_percent"], 0.0);
    EXPECT_NE(j["runs"][0]["ft_note"].get<std::string>().find(why), std::string::npos);
    // The truth table's FT column says it too.
    write("scene.json", kScene);
    ASSERT_EQ(run("simulate scene.json -o scene.npy --truth scene.truth.csv -q").status, 0);
    const CliResult t = run("eval scene.npy --truth scene.truth.csv -d efast --repeat 1 -q --no-figures "
                            "--ft-min-inner 100000 --report rept");
    ASSERT_EQ(t.status, 0) << t.err;
    const std::string truth_part = t.out.substr(t.out.find("Against ground truth"));
    EXPECT_NE(truth_part.find("* scene efast: FT 0.0: " + why), std::string::npos) << t.out;
    EXPECT_NE(slurp(dir_ / "rept/report.md").find("| 0.0 (" + why), std::string::npos);
    // With the default minimum, tracks are found: no note.
    const CliResult ok = run("eval '" + sample_.string() + "' -d efast --repeat 1 -q --no-figures --report rep2");
    ASSERT_EQ(ok.status, 0) << ok.err;
    EXPECT_EQ(ok.out.find("0.0*"), std::string::npos) << ok.out;
    EXPECT_FALSE(nlohmann::json::parse(slurp(dir_ / "rep2/results.json"))["runs"][0].contains("ft_note"));
}

}  // namespace
}  // namespace evcorner::test
