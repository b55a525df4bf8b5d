// evcorner eval against a simulated scene's ground truth: --truth, a suite folder, the
// tables and files, and the figures of the CLI against the library's brute-force oracle.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_util.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/naive/truth_match_naive.hpp"
#include "evcorner/sim/truth.hpp"

namespace evcorner::test {
namespace {

using EvalTruthCli = CliTest;

// A small scene: a triangle and a square crossing a 64x48 sensor in 0.25 s.
constexpr const char* kScene =
    R"({"sensor": [64, 48], "duration_s": 0.25, "seed": 3, "camera": {"contrast": 0.2},
        "background": 0.5,
        "objects": [{"polygon": [[8, 8], [24, 10], [12, 24]], "intensity": 0.1, "motion": {"velocity": [80, 20]}},
                    {"polygon": [[40, 20], [52, 20], [52, 32], [40, 32]], "intensity": 0.9,
                     "motion": {"velocity": [-60, 10], "rotation_deg_s": 90, "center": [46, 26]}}]})";

std::vector<std::string> split(const std::string& line) {
    std::vector<std::string> f;
    std::size_t start = 0;
    for (;;) {
        const std::size_t c = line.find(',', start);
        f.push_back(line.substr(start, c == std::string::npos ? std::string::npos : c - start));
        if (c == std::string::npos) return f;
        start = c + 1;
    }
}

TEST_F(EvalTruthCli, PrecisionAndRecallAgreeWithTheOracle) {
    write("scene.json", kScene);
    ASSERT_EQ(run("simulate scene.json -o scene.npy --truth scene.truth.csv -q").status, 0);
    const CliResult r = run("eval scene.npy --truth scene.truth.csv -d efast,harris --repeat 1 -q --report rep");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("Against ground truth"), std::string::npos) << r.out;
    const std::string csv = slurp(dir_ / "rep/truth_table.csv");
    ASSERT_EQ(count_lines(csv), 3u) << csv;  // header, efast, harris
    // The efast row against the oracle on the corners `detect` finds.
    ASSERT_EQ(run("detect scene.npy -d efast -o corners.txt").status, 0);
    auto reader = io::open_event_reader((dir_ / "corners.txt").string(), {}, "auto");
    const std::vector<Event> corners = io::read_all_events(*reader);
    ASSERT_FALSE(corners.empty());
    const auto truth = sim::read_truth_csv((dir_ / "scene.truth.csv").string());
    const eval::TruthMatchResult want = naive::naive_match_truth(corners, truth, {});
    ASSERT_GT(want.true_positives, 0u);
    ASSERT_GT(want.recalled, 0u);
    const std::string row = csv.substr(csv.find("\nscene,efast,") + 1);
    const auto f = split(row.substr(0, row.find('\n')));
    ASSERT_EQ(f.size(), 17u) << row;  // ..., us_per_event, average_precision, smear
    EXPECT_EQ(f[3], std::to_string(corners.size()));
    EXPECT_EQ(f[4], std::to_string(want.true_positives));
    EXPECT_EQ(f[6], std::to_string(want.truth_samples));
    EXPECT_EQ(f[7], std::to_string(want.recalled));
    EXPECT_NEAR(std::stod(f[9]), eval::summarize_errors(want.errors).median, 1e-4);
    // JSON and report.
    const auto j = nlohmann::json::parse(slurp(dir_ / "rep/results.json"));
    EXPECT_EQ(j["truth_match"]["radius_px"], 3.5);
    EXPECT_EQ(j["runs"][0]["truth"]["true_positives"], want.true_positives);
    const std::string md = slurp(dir_ / "rep/report.md");
    EXPECT_NE(md.find("## Against ground truth"), std::string::npos);
    EXPECT_TRUE(fs::exists(dir_ / "rep/figures/scene.precision_speed.png"));
    EXPECT_TRUE(fs::exists(dir_ / "rep/figures/scene.efast.loc_error.png"));
    EXPECT_TRUE(fs::exists(dir_ / "rep/figures/scene.harris.truth_space_time.png"));
    // A smaller radius can only lose true positives.
    const CliResult s = run("eval scene.npy -d efast --repeat 1 -q --no-figures --match-radius 1 --report small");
    ASSERT_EQ(s.status, 0) << s.err;
    const std::string small = slurp(dir_ / "small/truth_table.csv");
    const auto g = split(small.substr(small.find('\n') + 1, small.find('\n', small.find('\n') + 1) - small.find('\n') - 1));
    EXPECT_LT(std::stoull(g[4]), want.true_positives);
}

TEST_F(EvalTruthCli, SuiteFolderFindsEachTruthBesideItsEvents) {
    write("scene.json", kScene);
    fs::create_directories(dir_ / "suite");
    ASSERT_EQ(run("simulate scene.json -o suite/a.events.npy --truth suite/a.truth.csv --gt-tracks suite/a.gt-tracks.txt -q").status, 0);
    ASSERT_EQ(run("simulate scene.json -o suite/b.events.txt --truth suite/b.truth.csv -q").status, 0);
    fs::copy_file(dir_ / "scene.json", dir_ / "suite/a.json");
    write("suite/manifest.json", "{}");
    // A scene wider than 240 px: its .npy events carry no size, the scene beside gives it.
    write("suite/wide.json", R"({"sensor": [320, 40], "duration_s": 0.1, "seed": 1, "background": 0.5,
        "objects": [{"polygon": [[270, 10], [290, 10], [290, 30], [270, 30]], "intensity": 0.1,
                     "motion": {"velocity": [100, 0]}}]})");
    ASSERT_EQ(run("simulate suite/wide.json -o suite/wide.events.npy --truth suite/wide.truth.csv -q").status, 0);
    const CliResult r = run("eval suite -d efast --repeat 1 --no-progress --no-figures");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("skipped"), std::string::npos) << r.err;  // truths, GT tracks, scenes and manifest are known
    // Both scenes, by their names, in the ground-truth table; the same events give the same row.
    const auto a = r.out.find("\na "), b = r.out.find("\nb ");
    ASSERT_NE(a, std::string::npos) << r.out;
    ASSERT_NE(b, std::string::npos) << r.out;
    EXPECT_NE(r.out.find("\nwide "), std::string::npos) << r.out;
    EXPECT_EQ(r.out.substr(a + 2, r.out.find('\n', a + 1) - a - 2), r.out.substr(b + 2, r.out.find('\n', b + 1) - b - 2));
}

// PR curves and NMS in eval: --compare-nms gives NAME and NAME+nms rows; the +nms row's
// corners are those of `detect --nms`; the PR curve's lowest threshold is the table's row.
TEST_F(EvalTruthCli, CompareNmsAndPrCurve) {
    write("scene.json", kScene);
    ASSERT_EQ(run("simulate scene.json -o scene.npy --truth scene.truth.csv -q").status, 0);
    const CliResult r = run("eval scene.npy -d efast --compare-nms --nms-radius 2 --nms-time 2000 --repeat 1 -q "
                            "--report rep");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("Mean over the sequences"), std::string::npos) << r.out;
    const std::string csv = slurp(dir_ / "rep/truth_table.csv");
    ASSERT_EQ(count_lines(csv), 3u) << csv;
    const auto field = [&](const std::string& det) {
        const std::string row = csv.substr(csv.find("\nscene," + det + ",") + 1);
        return split(row.substr(0, row.find('\n')));
    };
    const auto plain = field("efast"), nms = field("efast+nms");
    ASSERT_EQ(plain.size(), 17u);
    ASSERT_EQ(nms.size(), 17u);
    ASSERT_EQ(run("detect scene.npy -d efast --nms --nms-radius 2 --nms-time 2000 -o kept.txt").status, 0);
    EXPECT_EQ(nms[3], std::to_string(count_lines(slurp(dir_ / "kept.txt"))));
    EXPECT_LT(std::stoull(nms[3]), std::stoull(plain[3]));
    for (const auto& f : {plain, nms}) {
        const double ap = std::stod(f[15]);
        EXPECT_GT(ap, 0.0);
        EXPECT_LE(ap, std::stod(f[8]) / 100 + 1e-9);  // AP <= full recall
    }
    // The last point of each curve (every corner event) is the row's precision and recall.
    const std::string pr = slurp(dir_ / "rep/pr_curve.csv");
    for (const auto& f : {plain, nms}) {
        const std::string key = "scene," + f[1] + ",";
        std::string last;
        for (std::size_t at = pr.find("\n" + key); at != std::string::npos; at = pr.find("\n" + key, at + 1))
            last = pr.substr(at + 1, pr.find('\n', at + 1) - at - 1);
        ASSERT_FALSE(last.empty()) << pr;
        const auto g = split(last);
        EXPECT_NEAR(std::stod(g[3]), std::stod(f[5]), 1e-3) << last;
        EXPECT_NEAR(std::stod(g[4]), std::stod(f[8]), 1e-3) << last;
    }
    EXPECT_TRUE(fs::exists(dir_ / "rep/figures/scene.pr.png"));
    const auto j = nlohmann::json::parse(slurp(dir_ / "rep/results.json"));
    EXPECT_EQ(j["nms"]["radius"], 2);
    EXPECT_TRUE(j["runs"][1]["truth"]["average_precision"].is_number());
    // --nms and --compare-nms together: usage.
    EXPECT_EQ(run("eval scene.npy -d efast --nms --compare-nms --repeat 1 -q").status, 2);
}

TEST_F(EvalTruthCli, Errors) {
    write("scene.json", kScene);
    ASSERT_EQ(run("simulate scene.json -o s.npy --truth t.csv -q").status, 0);
    ASSERT_EQ(run("simulate scene.json -o u.npy -q").status, 0);
    // --truth with two inputs: usage.
    CliResult r = run("eval s.npy u.npy --truth t.csv -d efast --repeat 1 -q");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--truth"), std::string::npos) << r.err;
    // A broken truth: the file and its line.
    write("bad.csv", std::string(sim::kTruthHeader) + "\n0,0,0,1.0,2.0,90,0,0,0,1,visible\n0,0,1,x,2.0,90,0,0,0,1,visible\n");
    r = run("eval s.npy --truth bad.csv -d efast --repeat 1 -q");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("bad.csv:3"), std::string::npos) << r.err;
    EXPECT_EQ(run("eval s.npy --match-radius 0 -d efast -q").status, 2);
    EXPECT_EQ(run("eval s.npy --match-credit most -d efast -q").status, 2);
    r = run("eval s.npy --speed-bins 5,10 -d efast -q --repeat 1");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("speed bins"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace evcorner::test
