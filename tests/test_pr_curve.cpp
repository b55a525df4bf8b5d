// Precision-recall curves (eval/pr_curve.hpp) from one scored matching pass
// (eval/truth_match.hpp): a drawn case worked out by hand, and seeded random cases against
// a brute-force oracle that re-runs the matcher on the events of score >= each threshold.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "evcorner/eval/pr_curve.hpp"
#include "evcorner/eval/truth_match.hpp"
#include "evcorner/sim/truth.hpp"

namespace evcorner::eval {
namespace {

using sim::CornerState;
using sim::TruthCorner;

TruthCorner row(std::int64_t t, int obj, double x, double y, CornerState s = CornerState::visible) {
    TruthCorner r;
    r.t_us = t;
    r.object = obj;
    r.corner = 0;
    r.x = x;
    r.y = y;
    r.angle_deg = 90;
    r.state = s;
    return r;
}

Event ev(std::int64_t t, int x, int y) { return {t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1}; }

// Two still corners, A at (10.5, 10.5) and B at (30.5, 30.5), sampled at 0, 1000, 2000 us
// (6 visible samples); tolerance 400 us, radius 1.5 px.
//   event  t     at      score  true  recalls
//   e0     0     A        5     yes   A@0
//   e1     1000  (50,50)  4     no    -
//   e2     1000  B        3     yes   B@1000
//   e3     2000  A        3     yes   A@2000
//   e4     2000  (60,60)  1     no    -
// threshold 5: P 1/1, R 1/6; 4: P 1/2, R 1/6; 3: P 3/4, R 3/6; 1: P 3/5, R 3/6.
// AP = 1/6 * 1 + 0 * 1/2 + 2/6 * 3/4 + 0 = 1/6 + 1/4 = 5/12.
TEST(PrCurve, DrawnCaseByHand) {
    std::vector<TruthCorner> truth;
    for (std::int64_t t : {0, 1000, 2000}) {
        truth.push_back(row(t, 0, 10.5, 10.5));
        truth.push_back(row(t, 1, 30.5, 30.5));
    }
    const std::vector<Event> corners{ev(0, 10, 10), ev(1000, 50, 50), ev(1000, 30, 30), ev(2000, 10, 10), ev(2000, 60, 60)};
    const std::vector<double> scores{5, 4, 3, 3, 1};
    TruthMatchParams p;
    p.radius = 1.5;
    p.tolerance_us = 400;
    const TruthMatchResult m = match_truth(corners, scores, truth, p);
    ASSERT_EQ(m.truth_samples, 6u);
    ASSERT_EQ(m.recalled, 3u);
    ASSERT_EQ(m.recalled_best.size(), 3u);
    const PrCurve c = pr_curve(scores, m.is_true, m.recalled_best, m.truth_samples);
    ASSERT_EQ(c.points.size(), 4u);
    const double th[] = {5, 4, 3, 1}, pr[] = {100, 50, 75, 60}, rc[] = {100.0 / 6, 100.0 / 6, 50, 50};
    for (std::size_t k = 0; k < 4; ++k) {
        EXPECT_EQ(c.points[k].threshold, th[k]) << k;
        EXPECT_NEAR(c.points[k].precision, pr[k], 1e-9) << k;
        EXPECT_NEAR(c.points[k].recall, rc[k], 1e-9) << k;
    }
    EXPECT_NEAR(c.average_precision, 5.0 / 12.0, 1e-12);
    // Corner time: 2 visible corners x 2000 us; 3 true positives in 4 corner-ms.
    EXPECT_DOUBLE_EQ(m.visible_corner_us, 4000.0);
    EXPECT_DOUBLE_EQ(m.smear(), 0.75);
}

TEST(PrCurve, BestScoreIsTheLargestWithinTolerance) {
    // One corner sampled at 0 and 1000 us; events at 100 (score 9, recalls only the first
    // sample: tolerance 500) and 900 (score 2, recalls only the second) and 1400 (score 7,
    // the second too). Best scores: 9 for the first, 7 for the second.
    const std::vector<TruthCorner> truth{row(0, 0, 5.5, 5.5), row(1000, 0, 5.5, 5.5)};
    const std::vector<Event> corners{ev(100, 5, 5), ev(900, 5, 5), ev(1400, 5, 5)};
    const std::vector<double> scores{9, 2, 7};
    TruthMatchParams p;
    p.tolerance_us = 500;
    const TruthMatchResult m = match_truth(corners, scores, truth, p);
    EXPECT_EQ(m.recalled_best, (std::vector<double>{9, 7}));
}

TEST(PrCurve, RefusesMismatchedLengths) {
    const std::vector<Event> corners{ev(0, 1, 1)};
    const std::vector<double> two{1, 2};
    EXPECT_THROW(TruthMatcher(corners, two, TruthMatchParams{}), std::invalid_argument);
    const std::vector<std::uint8_t> one{1};
    EXPECT_THROW((void)pr_curve(two, one, {}, 0), std::invalid_argument);
    const std::vector<double> best{1, 2};
    EXPECT_THROW((void)pr_curve(std::vector<double>{1}, one, best, 1), std::invalid_argument);
}

// Seeded random scenes: moving and blinking corners, events near and far, scores from a
// small set (ties) and NaN; every point against the matcher run on the thresholded events.
TEST(PrCurve, RandomScenesAgainstPerThresholdOracle) {
    for (int seed = 1; seed <= 30; ++seed) {
        std::mt19937 rng(static_cast<unsigned>(seed));
        std::uniform_real_distribution<double> u(0, 1);
        std::vector<TruthCorner> truth;
        const int n_corners = 1 + seed % 4;
        std::vector<double> x0(n_corners), y0(n_corners), vx(n_corners);
        for (int c = 0; c < n_corners; ++c) {
            x0[c] = 5 + 30 * u(rng);
            y0[c] = 5 + 30 * u(rng);
            vx[c] = 4 * u(rng) - 2;
        }
        for (std::int64_t t = 0; t <= 5000; t += 250)
            for (int c = 0; c < n_corners; ++c)
                truth.push_back(row(t, c, x0[c] + vx[c] * static_cast<double>(t) / 1000.0, y0[c],
                                    u(rng) < 0.2 ? CornerState::occluded : CornerState::visible));
        std::vector<Event> corners;
        std::vector<double> scores;
        for (std::int64_t t = 0; t <= 5200; t += 1 + static_cast<std::int64_t>(u(rng) * 60)) {
            int x, y;
            if (u(rng) < 0.6) {
                const int c = static_cast<int>(u(rng) * n_corners) % n_corners;
                x = static_cast<int>(x0[c] + vx[c] * static_cast<double>(t) / 1000.0 + 6 * u(rng) - 3);
                y = static_cast<int>(y0[c] + 6 * u(rng) - 3);
            } else {
                x = static_cast<int>(45 * u(rng));
                y = static_cast<int>(45 * u(rng));
            }
            corners.push_back(ev(t, std::max(0, x), std::max(0, y)));
            scores.push_back(u(rng) < 0.05 ? std::nan("") : std::floor(u(rng) * 8));
        }
        TruthMatchParams p;
        p.radius = 2.0;
        p.tolerance_us = 300;
        p.credit = seed % 2 ? Credit::all : Credit::nearest;
        const TruthMatchResult m = match_truth(corners, scores, truth, p);
        ASSERT_EQ(m.recalled_best.size(), m.recalled) << seed;
        const PrCurve c = pr_curve(scores, m.is_true, m.recalled_best, m.truth_samples);
        std::set<double, std::greater<>> ths;
        for (const double s : scores) ths.insert(std::isnan(s) ? -std::numeric_limits<double>::infinity() : s);
        ASSERT_EQ(c.points.size(), ths.size()) << seed;
        double ap = 0, prev_r = 0;
        std::size_t k = 0;
        for (const double th : ths) {
            std::vector<Event> kept;
            for (std::size_t i = 0; i < corners.size(); ++i) {
                const double s = std::isnan(scores[i]) ? -std::numeric_limits<double>::infinity() : scores[i];
                if (s >= th) kept.push_back(corners[i]);
            }
            const TruthMatchResult o = match_truth(kept, truth, p);
            EXPECT_EQ(c.points[k].threshold, th) << seed;
            EXPECT_NEAR(c.points[k].precision, o.precision(), 1e-9) << seed << " th " << th;
            EXPECT_NEAR(c.points[k].recall, o.recall(), 1e-9) << seed << " th " << th;
            ap += (o.recall() / 100 - prev_r) * o.precision() / 100;
            prev_r = o.recall() / 100;
            ++k;
        }
        EXPECT_NEAR(c.average_precision, ap, 1e-12) << seed;
        // The lowest threshold is the unthresholded run.
        EXPECT_NEAR(c.points.back().recall, m.recall(), 1e-9) << seed;
        EXPECT_NEAR(c.points.back().precision, m.precision(), 1e-9) << seed;
    }
}

TEST(PrCurve, ThinKeepsEndsAndInterpolatedPrecisionIsMonotone) {
    std::vector<PrPoint> pts;
    for (int k = 0; k < 10; ++k) pts.push_back({double(10 - k), 100.0 - 5 * k + (k % 2 ? 20 : 0), 10.0 * k});
    const auto t = thin(pts, 4);
    ASSERT_EQ(t.size(), 4u);
    EXPECT_EQ(t.front().threshold, 10);
    EXPECT_EQ(t.back().threshold, 1);
    const std::vector<double> levels{0, 50, 95};
    const auto pr = precision_at_recall(pts, levels);
    // precision_k = 100 - 5k (+20 for odd k): 100 115 90 105 80 95 70 85 60 75.
    EXPECT_DOUBLE_EQ(pr[0], 115.0);  // the largest of all
    EXPECT_DOUBLE_EQ(pr[1], 95.0);   // the largest at recall >= 50 (k >= 5)
    EXPECT_TRUE(std::isnan(pr[2]));  // recall never reaches 95 %
}

}  // namespace
}  // namespace evcorner::eval
