// Corner events against ground truth (eval/truth_match.hpp): drawn cases whose answer is
// worked out by hand, and seeded random cases against the brute-force oracle
// (naive/truth_match_naive.hpp).

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include "evcorner/error.hpp"
#include "evcorner/eval/truth_match.hpp"
#include "evcorner/naive/truth_match_naive.hpp"
#include "evcorner/sim/truth.hpp"

namespace evcorner::eval {
namespace {

using sim::CornerState;
using sim::TruthCorner;

TruthCorner row(std::int64_t t, int obj, int c, double x, double y, CornerState s = CornerState::visible,
                double vx = 0, double vy = 0) {
    TruthCorner r;
    r.t_us = t;
    r.object = obj;
    r.corner = c;
    r.x = x;
    r.y = y;
    r.vx = vx;
    r.vy = vy;
    r.angle_deg = 90;
    r.state = s;
    return r;
}

Event ev(std::int64_t t, int x, int y) {
    return {t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1};
}

void expect_same(const TruthMatchResult& a, const TruthMatchResult& b) {
    EXPECT_EQ(a.corner_events, b.corner_events);
    EXPECT_EQ(a.true_positives, b.true_positives);
    EXPECT_EQ(a.truth_samples, b.truth_samples);
    EXPECT_EQ(a.recalled, b.recalled);
    EXPECT_EQ(a.is_true, b.is_true);
    ASSERT_EQ(a.errors.size(), b.errors.size());
    for (std::size_t i = 0; i < a.errors.size(); ++i) EXPECT_FLOAT_EQ(a.errors[i], b.errors[i]) << i;
    ASSERT_EQ(a.bins.size(), b.bins.size());
    for (std::size_t k = 0; k < a.bins.size(); ++k) {
        EXPECT_EQ(a.bins[k].events, b.bins[k].events) << k;
        EXPECT_EQ(a.bins[k].true_positives, b.bins[k].true_positives) << k;
        EXPECT_EQ(a.bins[k].samples, b.bins[k].samples) << k;
        EXPECT_EQ(a.bins[k].recalled, b.bins[k].recalled) << k;
    }
}

// One corner moving +x at 10 px per 100 us (100 000 px/s), sampled at 0, 100, 200 us:
//   t_us   0     100    200
//   x      10.0  20.0   30.0     (y = 5.0 always)
// Events (pixel centres x + 0.5):
//   (events at pixel row 4: y 4.5, 0.5 px off in y)
//   t=50  at pixel 14 -> 14.5 vs interpolated 15.0: 0.5 px in x, a hit
//   t=50  at pixel 20 -> 20.5 vs 15.0: 5.5 px, a miss (it is where the corner is at t=100)
//   t=150 at pixel 27 -> 27.5 vs 25.0: 2.5 px, a hit
TEST(TruthMatch, DrawnMovingCorner) {
    const std::vector<TruthCorner> truth{row(0, 0, 0, 10, 5, CornerState::visible, 1e5),
                                         row(100, 0, 0, 20, 5, CornerState::visible, 1e5),
                                         row(200, 0, 0, 30, 5, CornerState::visible, 1e5)};
    const std::vector<Event> corners{ev(50, 14, 4), ev(50, 20, 4), ev(150, 27, 4)};
    TruthMatchParams p;
    p.tolerance_us = 60;
    const TruthMatchResult r = match_truth(corners, truth, p);
    EXPECT_EQ(r.corner_events, 3u);
    EXPECT_EQ(r.true_positives, 2u);
    EXPECT_EQ(r.is_true, (std::vector<std::uint8_t>{1, 0, 1}));
    ASSERT_EQ(r.errors.size(), 2u);
    EXPECT_NEAR(r.errors[0], std::hypot(0.5, 0.5), 1e-6);  // y: 4.5 against 5.0
    EXPECT_NEAR(r.errors[1], std::hypot(2.5, 0.5), 1e-6);
    // Samples: t=0 (hit at 50, 50 us away: found), t=100 (hits at 50 and 150: found),
    // t=200 (hit at 150: found). With 40 us, none is.
    EXPECT_EQ(r.truth_samples, 3u);
    EXPECT_EQ(r.recalled, 3u);
    p.tolerance_us = 40;
    EXPECT_EQ(match_truth(corners, truth, p).recalled, 0u);
    // Nearest-sample interpolation: at t=50 the sample of t=0 (x=10): 14.5 is 4.5 px away.
    p.interpolation = Interpolation::nearest;
    const TruthMatchResult n = match_truth(corners, truth, p);
    EXPECT_EQ(n.is_true, (std::vector<std::uint8_t>{0, 0, 0}));  // 150 -> t=100 (tie to the earlier): 7.5 px
    expect_same(n, naive::naive_match_truth(corners, truth, p));
}

// Two corners 2 px apart; one event between them matches both. Credit::all credits both
// corners' samples, Credit::nearest only the nearer. An occluded corner matches nothing and
// an event far from everything is a false positive.
TEST(TruthMatch, DrawnSeveralCornersAndOcclusion) {
    std::vector<TruthCorner> truth;
    for (const std::int64_t t : {0, 100}) {
        truth.push_back(row(t, 0, 0, 50.0, 50.0));
        truth.push_back(row(t, 0, 1, 52.0, 50.0));
        truth.push_back(row(t, 1, 0, 100.0, 100.0, CornerState::occluded));
    }
    const std::vector<Event> corners{ev(100, 50, 49), ev(100, 99, 99), ev(100, 10, 10)};
    TruthMatchParams p;
    TruthMatchResult r = match_truth(corners, truth, p);
    EXPECT_EQ(r.is_true, (std::vector<std::uint8_t>{1, 0, 0}));
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_NEAR(r.errors[0], std::sqrt(0.5), 1e-6);  // (50.5, 49.5) to corner 0 at (50, 50)
    EXPECT_EQ(r.truth_samples, 4u);       // the occluded corner's samples do not count
    EXPECT_EQ(r.recalled, 4u);
    p.credit = Credit::nearest;
    r = match_truth(corners, truth, p);
    EXPECT_EQ(r.recalled, 2u);
    expect_same(r, naive::naive_match_truth(corners, truth, p));
}

TEST(TruthMatch, Summary) {
    const std::vector<float> e{4, 1, 3, 2, 10, 5, 6, 7, 8, 9};
    const ErrorSummary s = summarize_errors(e);
    EXPECT_DOUBLE_EQ(s.median, 5.5);
    EXPECT_DOUBLE_EQ(s.mean, 5.5);
    EXPECT_DOUBLE_EQ(s.p90, 9);
    EXPECT_DOUBLE_EQ(summarize_errors({}).median, 0);
}

TEST(TruthMatch, RejectsBadParametersAndSamples) {
    TruthMatchParams p;
    p.radius = 0;
    EXPECT_THROW(validate(p), std::invalid_argument);
    p = {};
    p.speed_edges = {10, 20};
    EXPECT_THROW(validate(p), std::invalid_argument);
    p = {};
    p.tolerance_us = -1;
    EXPECT_THROW(validate(p), std::invalid_argument);
    TruthMatcher m({}, {});
    const std::vector<TruthCorner> a{row(100, 0, 0, 1, 1)}, b{row(100, 0, 0, 1, 1)};
    m.add_sample(a);
    EXPECT_THROW(m.add_sample(b), std::invalid_argument);
    EXPECT_EQ(parse_credit("nearest"), Credit::nearest);
    EXPECT_THROW(parse_credit("most"), std::invalid_argument);
    EXPECT_THROW(parse_interpolation("cubic"), std::invalid_argument);
}

// Random scenes: a few corners wandering, appearing, hiding; random events near and far.
TEST(TruthMatch, MatchesOracleOnRandomCases) {
    std::uint64_t hits = 0, misses = 0, recalled = 0;
    for (int seed = 1; seed <= 60; ++seed) {
        std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
        std::uniform_real_distribution<double> u(0, 1);
        const int n_corners = 1 + static_cast<int>(rng() % 5);
        const int n_samples = 1 + static_cast<int>(rng() % 12);
        const std::int64_t every = 20 + static_cast<std::int64_t>(rng() % 100);
        std::vector<TruthCorner> truth;
        std::vector<double> x(static_cast<std::size_t>(n_corners)), y(x.size());
        for (std::size_t c = 0; c < x.size(); ++c) x[c] = 5 + 20 * u(rng), y[c] = 5 + 20 * u(rng);
        for (int s = 0; s < n_samples; ++s) {
            for (int c = 0; c < n_corners; ++c) {
                auto& cx = x[static_cast<std::size_t>(c)];
                auto& cy = y[static_cast<std::size_t>(c)];
                cx += 3 * (u(rng) - 0.5);
                cy += 3 * (u(rng) - 0.5);
                if (u(rng) < 0.1) continue;  // a corner missing from a sample
                const double r = u(rng);
                const CornerState st = r < 0.7 ? CornerState::visible : r < 0.85 ? CornerState::occluded : CornerState::outside;
                truth.push_back(row(s * every, c / 2, c % 2, cx, cy, st, 400 * u(rng), 400 * u(rng)));
            }
        }
        const int n_events = static_cast<int>(rng() % 60);
        std::vector<Event> corners;
        for (int i = 0; i < n_events; ++i)
            corners.push_back(ev(static_cast<std::int64_t>(u(rng) * (n_samples + 1) * every) - every / 2 + 1,
                                 static_cast<int>(u(rng) * 30), static_cast<int>(u(rng) * 30)));
        std::sort(corners.begin(), corners.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
        for (auto& e : corners) e.t = std::max<std::int64_t>(e.t, 0);
        TruthMatchParams p;
        p.radius = 1 + 4 * u(rng);
        p.tolerance_us = static_cast<std::int64_t>(rng() % 200);
        p.credit = rng() % 2 ? Credit::all : Credit::nearest;
        p.interpolation = rng() % 3 ? Interpolation::linear : Interpolation::nearest;
        p.speed_edges = {0, 100, 250};
        SCOPED_TRACE("seed " + std::to_string(seed));
        const TruthMatchResult fast = match_truth(corners, truth, p);
        expect_same(fast, naive::naive_match_truth(corners, truth, p));
        hits += fast.true_positives;
        misses += fast.corner_events - fast.true_positives;
        recalled += fast.recalled;
    }
    // The cases exercise both outcomes, or the comparison says little.
    EXPECT_GT(hits, 20u);
    EXPECT_GT(misses, 20u);
    EXPECT_GT(recalled, 20u);
}

TEST(TruthMatch, ReaderGivesOneSampleAtATime) {
    const std::string path = ::testing::TempDir() + "truth_match_reader.csv";
    {
        std::ofstream out(path);
        out << sim::kTruthHeader << "\n"
            << "0,0,0,1.0,2.0,90.0,0,0,0,1,visible\n0,0,1,3.0,4.0,90.0,0,0,0,0,occluded\n"
            << "100,0,0,1.5,2.0,90.0,0,0,0,1,visible\n100,0,1,3.0,4.0,90.0,0,0,0,0,outside\n";
    }
    sim::TruthReader reader(path);
    std::vector<TruthCorner> rows;
    ASSERT_TRUE(reader.next_sample(rows));
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[1].state, CornerState::occluded);
    ASSERT_TRUE(reader.next_sample(rows));
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0].t_us, 100);
    EXPECT_DOUBLE_EQ(rows[0].x, 1.5);
    EXPECT_FALSE(reader.next_sample(rows));
    {
        std::ofstream out(path);
        out << sim::kTruthHeader << "\n100,0,0,1.0,2.0,90.0,0,0,0,1,visible\n50,0,0,1.0,2.0,90.0,0,0,0,1,visible\n";
    }
    sim::TruthReader bad(path);
    try {
        while (bad.next_sample(rows)) {
        }
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(":3"), std::string::npos) << e.what();
    }
    std::remove(path.c_str());
}

}  // namespace
}  // namespace evcorner::eval
