// The feature-track metric (docs/tracking-metrics.md) against tracks computed by hand, every
// rule: cropping, extrapolation, the one-row-early end, skipped and unmatched tracks, the
// asynchronous variant, the start alignment, association; track files read back; GT-free
// statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "evcorner/error.hpp"
#include "evcorner/eval/track_metrics.hpp"
#include "evcorner/track/track_file.hpp"
#include "evcorner/track/track_writer.hpp"
#include "io_test_util.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

using eval::evaluate_tracks;
using eval::TrackMetricOptions;
using test::TempDir;

// GT track `id`: x = 10 + 100 t, y = y0, sampled at t = 0, 0.1, .., 0.4.
std::vector<TrackPoint> line_gt(std::uint64_t id, double y0 = 5) {
    std::vector<TrackPoint> g;
    for (int k = 0; k <= 4; ++k) g.push_back({id, 0.1 * k, 10 + 10.0 * k, y0});
    return g;
}

// The same track with the given y offsets at the GT's times, from row `from` on.
std::vector<TrackPoint> offset_track(std::uint64_t id, const std::vector<double>& dy, int from = 0, double y0 = 5) {
    std::vector<TrackPoint> p;
    for (std::size_t k = 0; k < dy.size(); ++k) {
        const int r = from + static_cast<int>(k);
        p.push_back({id, 0.1 * r, 10 + 10.0 * r, y0 + dy[k]});
    }
    return p;
}

TEST(TrackMetrics, APerfectTrackHasFullAgeAndNoError) {
    const auto g = line_gt(0);
    const auto r = evaluate_tracks(g, g);
    EXPECT_EQ(r.counted_tracks, 1u);
    EXPECT_DOUBLE_EQ(r.fa, 1.0);
    EXPECT_DOUBLE_EQ(r.efa, 1.0);
    EXPECT_DOUBLE_EQ(r.fa_5, 1.0);
    EXPECT_DOUBLE_EQ(r.te_5, 0.0);
    EXPECT_EQ(r.inlier_ratio.size(), 31u);
}

// Errors at the GT rows 1..4: 0.5, 1.5, 3, 10.
//   e = 1:     first E > e is E[1] -> end = 0 -> fa 0
//   e = 2:     E[2] -> end = 1 (one row before the last good one, row 2) -> fa 0.1/0.4
//   e = 3..9:  E[3] -> end = 2 -> fa 0.5, te = mean(E[1], E[2]) = 2.25 (E[0] left out)
//   e >= 10:   none (10 > 10 is false) -> end = 4 -> fa 1
TEST(TrackMetrics, AgeEndsOneGtRowBeforeTheLastGoodOne) {
    const auto g = line_gt(0);
    const auto p = offset_track(0, {0, 0.5, 1.5, 3, 10});
    const auto r = evaluate_tracks(p, g);
    ASSERT_EQ(r.tracks.size(), 1u);
    const auto& age = r.tracks[0].age;
    EXPECT_DOUBLE_EQ(age[0], 0.0);
    EXPECT_DOUBLE_EQ(age[1], 0.25);
    for (int e = 3; e <= 9; ++e) EXPECT_DOUBLE_EQ(age[e - 1], 0.5) << "e = " << e;
    for (int e = 10; e <= 31; ++e) EXPECT_DOUBLE_EQ(age[e - 1], 1.0) << "e = " << e;
    EXPECT_DOUBLE_EQ(r.fa_5, 0.5);
    EXPECT_DOUBLE_EQ(r.te_5, 2.25);
    EXPECT_NEAR(r.fa, (0.25 + 7 * 0.5 + 22 * 1.0) / 31, 1e-15);
    EXPECT_NEAR(r.efa, r.fa, 1e-15);  // one track: r_e is 1 wherever a_e > 0
    EXPECT_DOUBLE_EQ(r.inlier_ratio[0], 0.0);
    EXPECT_DOUBLE_EQ(r.inlier_ratio[1], 1.0);
}

TEST(TrackMetrics, ANoErrorTrackLeavesOutTheFirstErrorOfItsMean) {
    const auto g = line_gt(0);
    const auto p = offset_track(0, {0, 4, 1, 1, 1});  // E = 4, 1, 1, 1
    const auto r = evaluate_tracks(p, g);
    EXPECT_DOUBLE_EQ(r.fa_5, 1.0);
    EXPECT_DOUBLE_EQ(r.te_5, 1.0);  // mean(E[1..]) = 1, not 1.75
    EXPECT_DOUBLE_EQ(r.tracks[0].age[0], 0.0);  // e = 1: E[0] = 4 > 1 at i = 0 -> end 0
}

TEST(TrackMetrics, SynchronousCutsTheGtToThePredictionAsynchronousHoldsItsLastPosition) {
    const auto g = line_gt(0);
    const auto p = offset_track(0, {0, 0, 0});  // rows at t = 0, 0.1, 0.2 on the GT
    const auto sync = evaluate_tracks(p, g);
    // Gc = GT rows 0..0.2, E = 0, 0: end = row 2, fa = 0.2 / 0.4 at every e
    EXPECT_DOUBLE_EQ(sync.fa, 0.5);
    EXPECT_DOUBLE_EQ(sync.fa_5, 0.5);
    TrackMetricOptions o;
    o.asynchronous = true;
    const auto async = evaluate_tracks(p, g, o);
    // P held at x = 30 until t = 0.4: E = 0, 0, 10, 20
    const auto& age = async.tracks[0].age;
    for (int e = 1; e <= 9; ++e) EXPECT_DOUBLE_EQ(age[e - 1], 0.25) << "e = " << e;
    for (int e = 10; e <= 19; ++e) EXPECT_DOUBLE_EQ(age[e - 1], 0.5) << "e = " << e;
    for (int e = 20; e <= 31; ++e) EXPECT_DOUBLE_EQ(age[e - 1], 1.0) << "e = " << e;
}

TEST(TrackMetrics, APredictionStartingLateIsExtrapolatedBackNotHeld) {
    // P on the GT's line from t = 0.2 on; G does not end after P, so Gc = G, and the GT row
    // at t = 0.1 meets P extended along its first segment (x = 20): no error. Held at its
    // first position (x = 30) it would be 10 px off and fail every threshold below 10.
    // Another track (id 9) comes first in both files, so that their first rows agree in time
    // and nothing is shifted.
    std::vector<TrackPoint> g = line_gt(0), p = offset_track(0, {0, 0, 0}, 2);
    p.insert(p.begin(), {9, 0.0, 100, 100});
    g.insert(g.begin(), {9, 0.0, 100, 100});
    const auto r = evaluate_tracks(p, g);
    EXPECT_DOUBLE_EQ(r.time_shift_s, 0.0);
    ASSERT_EQ(r.tracks.size(), 2u);
    EXPECT_EQ(r.tracks[0].id, 0u);
    for (int e = 1; e <= 31; ++e) EXPECT_DOUBLE_EQ(r.tracks[0].age[e - 1], 1.0) << "e = " << e;
    EXPECT_TRUE(r.tracks[1].skipped);  // id 9: one GT row
}

TEST(TrackMetrics, TheFilesFirstRowsAreAlignedFirst) {
    // The same late-starting P alone: the benchmark shifts it by 0 - 0.2 s, to t = 0 .. 0.2,
    // where it lies 20 px behind the GT, and the GT (ending after it) is cut to 0 .. 0.2.
    const auto g = line_gt(0);
    const auto r = evaluate_tracks(offset_track(0, {0, 0, 0}, 2), g);
    EXPECT_DOUBLE_EQ(r.time_shift_s, -0.2);
    for (int e = 1; e <= 19; ++e) EXPECT_DOUBLE_EQ(r.tracks[0].age[e - 1], 0.0) << "e = " << e;
    for (int e = 20; e <= 31; ++e) EXPECT_DOUBLE_EQ(r.tracks[0].age[e - 1], 0.5) << "e = " << e;
}

TEST(TrackMetrics, SkippedAndUnmatchedTracksCountNowhere) {
    std::vector<TrackPoint> g = line_gt(0);
    const auto gt1 = line_gt(1, 50);
    g.insert(g.end(), gt1.begin(), gt1.end());
    std::vector<TrackPoint> p = offset_track(0, {0, 0, 0, 0, 0});
    // id 1: rows between two GT samples: Gc is empty -> skipped
    p.push_back({1, 0.05, 15, 50});
    p.push_back({1, 0.08, 18, 50});
    // id 2: no such GT track -> unmatched
    p.push_back({2, 0.1, 0, 0});
    p.push_back({2, 0.2, 0, 0});
    const auto r = evaluate_tracks(p, g);
    EXPECT_EQ(r.predicted_tracks, 3u);
    EXPECT_EQ(r.gt_tracks, 2u);
    EXPECT_EQ(r.counted_tracks, 1u);
    EXPECT_EQ(r.skipped_tracks, 1u);
    EXPECT_EQ(r.unmatched_tracks, 1u);
    EXPECT_DOUBLE_EQ(r.inlier_ratio[4], 1.0);
    EXPECT_DOUBLE_EQ(r.efa, 1.0);
}

TEST(TrackMetrics, FeatureAgeAveragesOnlyLiveTracksExpectedAgeWeighsByTheirShare) {
    std::vector<TrackPoint> g = line_gt(0);
    const auto gt1 = line_gt(1, 50);
    g.insert(g.end(), gt1.begin(), gt1.end());
    std::vector<TrackPoint> p = offset_track(0, {0, 0, 0, 0, 0});
    const auto lost = offset_track(1, {40, 40, 40, 40, 40}, 0, 50);  // 40 px off: fa 0 at every e
    p.insert(p.end(), lost.begin(), lost.end());
    const auto r = evaluate_tracks(p, g);
    EXPECT_EQ(r.counted_tracks, 2u);
    EXPECT_DOUBLE_EQ(r.fa, 1.0);
    EXPECT_DOUBLE_EQ(r.efa, 0.5);
    EXPECT_DOUBLE_EQ(r.inlier_mean, 0.5);
    EXPECT_DOUBLE_EQ(r.inlier_std, 0.0);
}

TEST(TrackMetrics, ThePredictionIsShiftedToTheGtFilesStart) {
    const auto g = line_gt(0);
    auto p = g;
    for (auto& q : p) q.t += 0.001;
    const auto r = evaluate_tracks(p, g);
    EXPECT_NEAR(r.time_shift_s, -0.001, 1e-15);
    EXPECT_NEAR(r.fa, 1.0, 1e-12);
    EXPECT_NEAR(r.te_5, 0.0, 1e-9);
}

TEST(TrackMetrics, AssociationTakesTheNearestFreeGtTrackAtTheFirstTime) {
    std::vector<TrackPoint> g = line_gt(0, 5);
    const auto gt1 = line_gt(1, 50);
    g.insert(g.end(), gt1.begin(), gt1.end());
    // id 7 starts at t = 0.1 half a pixel from GT 1; id 8 later at the same place (GT 1 is
    // taken, GT 0 is 45 px away: unmatched); id 9 far from both.
    std::vector<TrackPoint> p = offset_track(7, {0.5, 0.5, 0.5, 0.5}, 1, 50);
    p.push_back({8, 0.2, 30, 50});
    p.push_back({8, 0.3, 40, 50});
    p.push_back({9, 0.1, 20, 30});
    p.push_back({9, 0.2, 30, 30});
    TrackMetricOptions o;
    o.associate_px = 3;
    const auto r = evaluate_tracks(p, g, o);
    EXPECT_EQ(r.counted_tracks, 1u);
    EXPECT_EQ(r.unmatched_tracks, 2u);
    ASSERT_EQ(r.tracks.size(), 1u);
    EXPECT_EQ(r.tracks[0].id, 7u);
    EXPECT_EQ(r.tracks[0].gt_id, 1u);
    // G = GT 1 from t = 0.1: fa = 0.3 / 0.3
    EXPECT_DOUBLE_EQ(r.fa_5, 1.0);
    EXPECT_DOUBLE_EQ(r.te_5, 0.5);
    EXPECT_DOUBLE_EQ(r.time_shift_s, 0.0);
}

TEST(TrackMetrics, SeedsMatchTracksWhereTheyWereSeededNotWhereTheyFirstReport) {
    std::vector<TrackPoint> g = line_gt(0, 5);
    const auto gt1 = line_gt(1, 50);
    g.insert(g.end(), gt1.begin(), gt1.end());
    // seeded at t = 0.1 on GT 1 (id 4) and on GT 0 (id 5); track 4 first reports at t = 0.2
    // and ends at 0.3; id 6 has no seed.
    const std::vector<TrackPoint> seeds = {{4, 0.1, 20, 50}, {5, 0.1, 20.5, 5}};
    std::vector<TrackPoint> p = offset_track(4, {0, 0}, 2, 50);
    const auto p5 = offset_track(5, {0, 0, 0, 0}, 1, 5);
    p.insert(p.end(), p5.begin(), p5.end());
    p.push_back({6, 0.1, 20, 50});
    TrackMetricOptions o;
    o.seeds = seeds;
    const auto r = evaluate_tracks(p, g, o);
    ASSERT_EQ(r.tracks.size(), 2u);
    EXPECT_EQ(r.unmatched_tracks, 1u);
    EXPECT_EQ(r.tracks[0].id, 4u);
    EXPECT_EQ(r.tracks[0].gt_id, 1u);
    EXPECT_EQ(r.tracks[1].gt_id, 0u);
    // track 4: G = GT 1 from the seed's time, 0.1 .. 0.4, cut to 0.2 .. 0.3: fa = 0.1 / 0.3
    // (from its first report, G would be 0.2 .. 0.4 and fa 0.5)
    EXPECT_DOUBLE_EQ(r.tracks[0].age[4], (0.3 - 0.2) / (0.4 - 0.1));
    EXPECT_DOUBLE_EQ(r.tracks[1].age[4], 1.0);
    EXPECT_DOUBLE_EQ(r.time_shift_s, 0.0);
}

TEST(TrackMetrics, ResultsDoNotDependOnRowOrder) {
    std::vector<TrackPoint> g = line_gt(0);
    const auto gt1 = line_gt(1, 50);
    g.insert(g.end(), gt1.begin(), gt1.end());
    std::vector<TrackPoint> p = offset_track(0, {0, 0.5, 1.5, 3, 10});
    const auto p1 = offset_track(1, {0, 2, 2, 7, 1}, 0, 50);
    p.insert(p.end(), p1.begin(), p1.end());
    const auto a = evaluate_tracks(p, g);
    // every row but the first reversed (the first rows decide the start alignment)
    std::vector<TrackPoint> q = p, h = g;
    std::reverse(q.begin() + 1, q.end());
    std::reverse(h.begin() + 1, h.end());
    const auto b = evaluate_tracks(q, h);
    EXPECT_GT(a.fa, 0.5);
    EXPECT_EQ(a.fa, b.fa);
    EXPECT_EQ(a.efa, b.efa);
    EXPECT_EQ(a.te_5, b.te_5);
}

TEST(TrackStatistics, LifetimeLengthAndJitter) {
    const std::vector<TrackPoint> t = {{0, 0, 0, 0}, {0, 1, 1, 0}, {0, 2, 2, 0},
                                       {1, 0, 0, 0}, {1, 1, 1, 1}, {1, 2, 2, 0}};
    const auto s = eval::track_statistics(t);
    EXPECT_EQ(s.tracks, 2u);
    EXPECT_EQ(s.samples, 6u);
    EXPECT_DOUBLE_EQ(s.lifetime_median_s, 2.0);
    EXPECT_DOUBLE_EQ(s.length_mean_px, (2 + 2 * std::sqrt(2.0)) / 2);
    EXPECT_EQ(s.jitter_samples, 2u);
    EXPECT_DOUBLE_EQ(s.jitter_rms_px, std::sqrt(0.5));
}

TEST(TrackFile, EveryLayoutTheWriterWritesReadsBack) {
    TempDir dir;
    const std::vector<TrackState> states = {{1000001, 10.25f, 20.5f, 0.5f, 3, TrackChange::initialised},
                                            {1500000, 11.0f, 21.0f, 0.25f, 3, TrackChange::moved},
                                            {2000000, 12.0f, 22.0f, 0.0f, 4, TrackChange::stopped}};
    for (const char* f : {"ddft", "haste", "csv", "npy"}) {
        const std::string ext = std::string(f) == "npy" ? ".npy" : std::string(f) == "csv" ? ".csv" : ".txt";
        const std::string path = dir.path(std::string("tracks-") + f + ext);
        TrackWriter w(path, *parse_track_format(f));
        w.write(states);
        w.close();
        const auto back = read_track_points(path);
        ASSERT_EQ(back.size(), states.size()) << f;
        for (std::size_t i = 0; i < states.size(); ++i) {
            EXPECT_EQ(back[i].id, states[i].id) << f;
            EXPECT_DOUBLE_EQ(back[i].t, static_cast<double>(states[i].t) / 1e6) << f;
            EXPECT_DOUBLE_EQ(back[i].x, states[i].x) << f;
            EXPECT_DOUBLE_EQ(back[i].y, states[i].y) << f;
        }
    }
}

TEST(TrackFile, TextLayoutsPrintWhatPrintfPrints) {
    // Six decimals as printf's "%.6f" rounds them (ties to even, as glibc does), ids and
    // times in full: random values, exact ties (odd multiples of 1/128), signs, zero, extremes.
    std::vector<TrackState> states;
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<float> pos(-50.0f, 1300.0f);
    std::uniform_int_distribution<std::int64_t> t(-5000000, 4000000000000);
    for (int i = 0; i < 2000; ++i)
        states.push_back({t(rng), pos(rng), static_cast<float>(2 * i + 1) / 128.0f, pos(rng) * 1e-3f, rng(), TrackChange::moved});
    for (const float v : {0.0f, -0.0f, -0.0000004f, 0.0000005f, 1e-7f, -3.0078125f, 3.4e38f, -1e30f})
        states.push_back({0, v, -v, v, std::uint64_t(-1), TrackChange::stopped});
    TempDir dir;
    const auto lines_of = [](const std::string& text) {
        std::vector<std::string> v;
        std::istringstream in(text);
        for (std::string l; std::getline(in, l);) v.push_back(l);
        return v;
    };
    const auto seconds = [](std::int64_t us) {
        const std::uint64_t a = us < 0 ? 0 - static_cast<std::uint64_t>(us) : static_cast<std::uint64_t>(us);
        char b[64];
        std::snprintf(b, sizeof b, "%s%llu.%06llu", us < 0 ? "-" : "", static_cast<unsigned long long>(a / 1000000),
                      static_cast<unsigned long long>(a % 1000000));
        return std::string(b);
    };
    for (const char* f : {"ddft", "haste", "csv"}) {
        const std::string path = dir.path(std::string("printf-") + f + ".txt");
        TrackWriter w(path, *parse_track_format(f));
        w.write(states);
        w.close();
        std::ifstream in(path, std::ios::binary);
        std::vector<std::string> lines = lines_of(std::string(std::istreambuf_iterator<char>(in), {}));
        if (std::string(f) == "csv") lines.erase(lines.begin());  // the header
        ASSERT_EQ(lines.size(), states.size()) << f;
        for (std::size_t i = 0; i < states.size(); ++i) {
            const TrackState& s = states[i];
            char b[512];
            const auto id = static_cast<unsigned long long>(s.id);
            const std::string ts = seconds(s.t);
            if (std::string(f) == "ddft")
                std::snprintf(b, sizeof b, "%llu %s %.6f %.6f", id, ts.c_str(), double(s.x), double(s.y));
            else if (std::string(f) == "haste")
                std::snprintf(b, sizeof b, "%s,%.6f,%.6f,%.6f,%llu", ts.c_str(), double(s.x), double(s.y), double(s.theta), id);
            else
                std::snprintf(b, sizeof b, "%llu,%s,%.6f,%.6f,%.6f,%s", id, ts.c_str(), double(s.x), double(s.y),
                              double(s.theta), change_name(s.why));
            ASSERT_EQ(lines[i], b) << f << " row " << i;
        }
    }
}

TEST(TrackFile, MalformedRowsNameTheFileAndLine) {
    TempDir dir;
    const auto expect_error = [&](const std::string& name, const std::string& text, const std::string& part) {
        const std::string path = dir.write(name, text);
        try {
            read_track_points(path);
            ADD_FAILURE() << name << ": no error";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        }
    };
    expect_error("a.txt", "0 0.1 1 2\n0 0.2 1\n", ":2:");
    expect_error("b.txt", "0 0.1 1 2\n0.2,1,2,0,0\n", ":2:");
    expect_error("c.txt", "0 0.1 nan 2\n", ":1:");
    expect_error("d.txt", "-1 0.1 1 2\n", ":1:");
    expect_error("e.csv", "0,0.1,1,2,0,moved\n", ":1:");
    const char npy[] = "\x93NUMPY\x01\x00\x10\x00{'descr': '<f8'}";
    expect_error("f.npy", std::string(npy, sizeof npy - 1), "track array");
}

TEST(TrackFile, ReadsTheAuthorsGzippedOutput) {
    if (!test::have_shared_data()) GTEST_SKIP() << "../shared/data is not beside the checkout (golden HASTE outputs)";
    const auto p = read_track_points((test::shared_data() / "golden/haste/sim-shapes/correlation.uncentered.txt.gz").string());
    EXPECT_EQ(p.size(), 3483u);  // the README's line count
}

}  // namespace
}  // namespace evcorner
