// evcorner simulate --gt-tracks, evcorner track seeded from them, and evcorner eval-tracks,
// run as a user runs them.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "cli_test_util.hpp"
#include "evcorner/sim/truth.hpp"
#include "evcorner/track/track_file.hpp"

namespace evcorner::test {
namespace {

class CliTracks : public CliTest {};

TEST_F(CliTracks, GtTracksAreTheVisibleTruthCornersInThePixelIndexConvention) {
    // 50 Hz GT and the truth CSV at the same period: two ways to the same corners.
    const auto r = run("simulate --preset shapes -o ev.npy --gt-tracks gt.txt --gt-rate 50 --truth truth.csv "
                       "--truth-every 20000");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("gt tracks"), std::string::npos) << r.err;
    const auto gt = read_track_points((dir_ / "gt.txt").string());
    const auto truth = sim::read_truth_csv((dir_ / "truth.csv").string());
    std::size_t visible = 0;
    for (const auto& c : truth) visible += c.state == sim::CornerState::visible;
    ASSERT_GT(visible, 100u);
    EXPECT_EQ(gt.size(), visible);  // one sample per visible corner and time, no more
    // Per (time, rounded position) the truth corner at x - 0.5, y - 0.5; and every track
    // sampled at consecutive 20 ms steps (a hidden corner ends its track).
    std::map<std::int64_t, std::vector<std::pair<double, double>>> at;
    for (const auto& c : truth)
        if (c.state == sim::CornerState::visible) at[c.t_us].emplace_back(c.x - 0.5, c.y - 0.5);
    std::map<std::uint64_t, double> last_t;
    for (const auto& p : gt) {
        const auto t_us = std::llround(p.t * 1e6);
        ASSERT_EQ(t_us % 20000, 0) << p.t;
        bool found = false;
        for (const auto& [x, y] : at[t_us]) found = found || (std::abs(x - p.x) < 1e-4 && std::abs(y - p.y) < 1e-4);
        EXPECT_TRUE(found) << "track " << p.id << " at t " << p.t << " (" << p.x << ", " << p.y << ")";
        if (last_t.count(p.id)) EXPECT_EQ(std::llround((p.t - last_t[p.id]) * 1e6), 20000) << "track " << p.id;
        last_t[p.id] = p.t;
    }
}

TEST_F(CliTracks, GtAgainstItselfIsPerfectAndTheJsonSaysWhatThePrintSays) {
    ASSERT_EQ(run("simulate --preset shapes -o ev.npy --gt-tracks gt.txt -q").status, 0);
    const auto r = run("eval-tracks gt.txt gt.txt");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("FA           1.0000"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("TE@5         0.0000 px"), std::string::npos) << r.out;
    const auto j = run("eval-tracks gt.txt gt.txt --async --json -");
    ASSERT_EQ(j.status, 0) << j.err;
    const auto doc = nlohmann::json::parse(j.out);
    EXPECT_EQ(doc["metric"]["mode"], "asynchronous");
    EXPECT_DOUBLE_EQ(doc["metric"]["fa"].get<double>(), 1.0);
    EXPECT_EQ(doc["metric"]["predicted_tracks"], doc["metric"]["gt_tracks"]);
    EXPECT_EQ(doc["metric"]["age"].size(), 31u);
}

TEST_F(CliTracks, GtSeededTrackerRunsAndIsScored) {
    ASSERT_EQ(run("simulate --preset shapes -o ev.npy --gt-tracks gt.txt -q").status, 0);
    const auto gt = read_track_points((dir_ / "gt.txt").string());
    std::map<std::uint64_t, int> ids;
    for (const auto& p : gt) ids[p.id] = 1;
    const auto t = run("track ev.npy --tracker haste-correlation-star --init uncentered --seeds gt.txt -o tracks.txt");
    ASSERT_EQ(t.status, 0) << t.err;
    EXPECT_NE(t.err.find(std::to_string(ids.size()) + " started"), std::string::npos) << t.err;  // a seed per GT track
    const auto e = run("eval-tracks tracks.txt gt.txt --no-align --json scores.json");
    ASSERT_EQ(e.status, 0) << e.err;
    const auto doc = nlohmann::json::parse(slurp(dir_ / "scores.json"));
    const double fa = doc["metric"]["fa"].get<double>();
    EXPECT_GT(fa, 0.2);  // HASTE follows the shapes' corners for part of their life
    EXPECT_LT(fa, 1.0);
    EXPECT_EQ(doc["metric"]["unmatched_tracks"], 0);
    EXPECT_EQ(doc["metric"]["time_shift_s"], 0.0);
    EXPECT_NE(e.out.find("FA@5"), std::string::npos);
    EXPECT_NE(e.out.find("tracks       " + std::to_string(ids.size()) + " predicted"), std::string::npos) << e.out;
}

TEST_F(CliTracks, StatisticsWithoutGtAndUsageErrors) {
    write("t.txt", "0 0.0 1 1\n0 0.1 2 1\n0 0.2 3 1\n");
    const auto s = run("eval-tracks t.txt");
    ASSERT_EQ(s.status, 0) << s.err;
    EXPECT_NE(s.out.find("tracks       1 (3 samples)"), std::string::npos) << s.out;
    EXPECT_NE(s.out.find("jitter       0.000 px"), std::string::npos) << s.out;
    EXPECT_EQ(run("eval-tracks t.txt --async").status, 2);
    EXPECT_EQ(run("eval-tracks t.txt t.txt --associate 2 --no-align").status, 2);
    write("bad.txt", "0 0.0 1 1\n0 0.1 two 1\n");
    const auto b = run("eval-tracks bad.txt t.txt");
    EXPECT_EQ(b.status, 1);
    EXPECT_NE(b.err.find("bad.txt:2:"), std::string::npos) << b.err;
    const auto w = run("eval-tracks t.txt t.txt --json t.txt");
    EXPECT_EQ(w.status, 2) << w.err;  // would overwrite an input
}

TEST_F(CliTracks, TheAuthorsGoldenRunIsScoredThroughItsSeeds) {
    if (!have_shared_data()) GTEST_SKIP() << "../shared/data is not beside the checkout (golden HASTE outputs)";
    // The goldens' sim-shapes input is the shapes preset; its truth does not depend on the
    // simulator's pixel model, so today's GT is the GT of those events.
    ASSERT_EQ(run("simulate --preset shapes -o ev.npy --gt-tracks gt.txt -q").status, 0);
    const fs::path g = shared_data() / "golden/haste/sim-shapes";
    const auto r = run("eval-tracks '" + (g / "haste_correlation_star.uncentered.txt.gz").string() + "' gt.txt --seeds '" +
                       (g / "seeds.txt").string() + "' --json -");
    ASSERT_EQ(r.status, 0) << r.err;
    const auto doc = nlohmann::json::parse(r.out);
    EXPECT_EQ(doc["metric"]["predicted_tracks"], 18);  // every seed initialised (README)
    EXPECT_EQ(doc["metric"]["unmatched_tracks"], 0);   // each seed lies on a truth corner
    EXPECT_GT(doc["metric"]["fa"].get<double>(), 0.2);
}

}  // namespace
}  // namespace evcorner::test
