// evcorner label, eval and render as a user runs them, on the bundled sample.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_test_util.hpp"

namespace evcorner {
namespace {

namespace fs = std::filesystem;

using test::slurp;

// Width and height from a PNG's IHDR chunk; (0, 0) when it is not a PNG.
std::pair<unsigned, unsigned> png_size(const fs::path& p) {
    const std::string b = slurp(p);
    if (b.size() < 24 || b.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || b.compare(12, 4, "IHDR") != 0) return {0, 0};
    auto be32 = [&](std::size_t o) {
        return (unsigned(static_cast<unsigned char>(b[o])) << 24) | (unsigned(static_cast<unsigned char>(b[o + 1])) << 16) |
               (unsigned(static_cast<unsigned char>(b[o + 2])) << 8) | unsigned(static_cast<unsigned char>(b[o + 3]));
    };
    return {be32(16), be32(20)};
}

class CliEval : public test::CliTest {
protected:
    // The exit status of "evcorner ARGS"; its standard error into *err when given.
    int run_status(const std::string& args, std::string* err = nullptr) {
        const test::CliResult r = run(args);
        if (err) *err = r.err;
        return r.status;
    }
};

TEST_F(CliEval, LabelWritesOneLabelPerCornerAndTheFtShare) {
    ASSERT_EQ(run_status("detect '" + sample_.string() + "' -q -o corners.txt"), 0);
    const std::size_t corners = test::read_index_file(test::bundled_data() / "ecd/shapes_translation/efast.golden.idx").size();
    std::string err;
    ASSERT_EQ(run_status("label corners.txt -o labels.txt --json l.json", &err), 0) << err;
    std::ifstream in(dir_ / "labels.txt");
    std::size_t lines = 0, ones = 0;
    for (std::string l; std::getline(in, l); ++lines) {
        ASSERT_TRUE(l == "0" || l == "1") << l;
        ones += l == "1";
    }
    EXPECT_EQ(lines, corners);
    EXPECT_GT(ones, 0u);
    EXPECT_LT(ones, corners);
    // The printed and JSON FT are the share of ones in the label file.
    const std::string json = slurp(dir_ / "l.json");
    EXPECT_NE(json.find("\"on_track\": " + std::to_string(ones)), std::string::npos) << json;
    // With the labels in a file, the FT line goes to standard output.
    const std::string out = slurp(dir_ / "out.stdout");
    EXPECT_NE(out.find(std::to_string(ones) + " of " + std::to_string(corners)), std::string::npos) << out;
}

TEST_F(CliEval, EvalWritesBothTablesAndTheReport) {
    std::string err;
    ASSERT_EQ(run_status("eval '" + (test::bundled_data() / "ecd").string() + "' -d efast,harris --repeat 1 -q --report rep",
                  &err),
              0)
        << err;
    const std::string t1 = slurp(dir_ / "rep/table1.csv");
    const std::string t2 = slurp(dir_ / "rep/table2.csv");
    // Reduction rate from the goldens' corner counts, not from the code.
    auto reduction = [](std::size_t corners) { return 100.0 * (1.0 - static_cast<double>(corners) / 30000.0); };
    const auto efast = test::read_index_file(test::bundled_data() / "ecd/shapes_translation/efast.golden.idx").size();
    const auto harris = test::read_index_file(test::bundled_data() / "ecd/shapes_translation/harris.golden.idx").size();
    for (const auto& [name, corners] : {std::pair{std::string("efast"), efast}, {std::string("harris"), harris}}) {
        const std::string prefix = "shapes_translation," + name + ",30000," + std::to_string(corners) + ",";
        const auto at = t1.find(prefix);
        ASSERT_NE(at, std::string::npos) << t1;
        std::istringstream row(t1.substr(at + prefix.size()));
        std::string on_track, red;
        std::getline(row, on_track, ',');
        std::getline(row, red, ',');
        EXPECT_NEAR(std::stod(red), reduction(corners), 1e-3) << name;
        EXPECT_NE(t2.find("\n" + name + ",30000,"), std::string::npos) << t2;
    }
    EXPECT_FALSE(slurp(dir_ / "rep/report.md").empty());
    EXPECT_NE(slurp(dir_ / "rep/results.json").find("\"ft_percent\""), std::string::npos);
    bool some_png = false;
    for (const auto& f : fs::directory_iterator(dir_ / "rep/figures")) some_png |= png_size(f.path()).first > 0;
    EXPECT_TRUE(some_png);
}

TEST_F(CliEval, RenderEveryKindAsPng) {
    for (const std::string kind : {"sae", "corners", "space-time", "labels"}) {
        std::string err;
        ASSERT_EQ(run_status("render '" + sample_.string() + "' -k " + kind + " -o " + kind + ".png", &err), 0) << kind << err;
        const auto [w, h] = png_size(dir_ / (kind + ".png"));
        EXPECT_GT(w, 0u) << kind;
        EXPECT_GT(h, 0u) << kind;
        if (kind == "sae" || kind == "corners") {  // the sensor at the default scale of 2, framed
            EXPECT_GT(w, 480u) << kind;
            EXPECT_GT(h, 360u) << kind;
        }
    }
    std::string err;
    EXPECT_NE(run_status("render '" + sample_.string() + "' -k nonsense -o x.png", &err), 0);
    EXPECT_NE(run_status("render no-such-file.txt -o x.png", &err), 0);
    EXPECT_NE(err.find("no-such-file.txt"), std::string::npos) << err;
}

}  // namespace
}  // namespace evcorner
