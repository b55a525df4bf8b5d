// The Harris detectors against their plain definitions: naive oracles on seeded random
// streams at several sensor sizes, drawn patches with known scores, the newest-N queue
// against a recomputation, parameter validation.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/harris.hpp"
#include "evcorner/harris_global.hpp"
#include "evcorner/harris_score.hpp"
#include "evcorner/naive/harris_naive.hpp"
#include "evcorner/newest_pixels.hpp"

namespace evcorner {
namespace {

// Events around a few slowly drifting blobs, so windows fill up and scores vary; time
// repeats often (ties must be broken by arrival, not by time).
std::vector<Event> random_stream(SensorSize size, std::size_t count, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> spread(0.0, 2.5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double cx[3], cy[3];
    for (int b = 0; b < 3; ++b) {
        cx[b] = unit(rng) * size.width;
        cy[b] = unit(rng) * size.height;
    }
    std::vector<Event> events;
    std::int64_t t = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const int b = static_cast<int>(rng() % 3);
        cx[b] += spread(rng) * 0.05;
        cy[b] += spread(rng) * 0.05;
        int x, y;
        if (unit(rng) < 0.1) {  // some noise anywhere
            x = static_cast<int>(rng() % size.width);
            y = static_cast<int>(rng() % size.height);
        } else {
            x = static_cast<int>(std::lround(cx[b] + spread(rng)));
            y = static_cast<int>(std::lround(cy[b] + spread(rng)));
            x = std::clamp(x, 0, size.width - 1);
            y = std::clamp(y, 0, size.height - 1);
        }
        t += static_cast<std::int64_t>(rng() % 3);  // 0: same time as the previous event
        events.push_back({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                          static_cast<std::uint8_t>(rng() % 4 == 0)});  // mostly OFF: denser
    }
    return events;
}

bool same_score(double fast, double naive) {
    if (std::isnan(fast) || std::isnan(naive)) return std::isnan(fast) && std::isnan(naive);
    return std::abs(fast - naive) <= 1e-9 * std::max(1.0, std::abs(naive));
}

struct Case {
    SensorSize size;
    std::size_t events;
};
const Case kCases[] = {{{9, 9}, 3000},     {{12, 7}, 3000},   {{16, 16}, 8000}, {{31, 17}, 8000},
                       {{240, 180}, 20000}, {{346, 260}, 10000}, {{1280, 720}, 20000}};

TEST(Harris, MatchesNaiveOracleOnRandomStreams) {
    std::size_t total_scored = 0, total_corners = 0;
    for (const Case& c : kCases)
        for (const HarrisParams params : {HarrisParams{}, HarrisParams{5, 7, 0.05, 1.0}, HarrisParams{7, 30, 0.04, 4.0},
                                          HarrisParams{11, 40, 0.06, 10.0}, HarrisParams{9, 1, 0.04, -1.0}}) {
            SCOPED_TRACE(std::to_string(c.size.width) + "x" + std::to_string(c.size.height) + " window " +
                         std::to_string(params.window) + " nl " + std::to_string(params.nl));
            const auto events = random_stream(c.size, c.events, 1000u * c.size.width + params.nl);
            // One fast detector per selection code this CPU runs (harris_select.hpp).
            std::vector<Harris> fast;
            for (const std::string& path : harris_code_paths()) {
                fast.emplace_back(c.size, params);
                fast.back().set_code_path(harris_path_named(path));
            }
            naive::HarrisNaive slow(c.size, params.window, params.nl, params.k, params.threshold);
            std::size_t scored = 0, corners = 0, mismatches = 0;
            for (std::size_t i = 0; i < events.size(); ++i) {
                const bool b = slow.process(events[i]);
                for (Harris& f : fast) {
                    const bool a = f.process(events[i]);
                    const bool ok = a == b && same_score(f.last_score(), slow.last_score());
                    if (!ok && ++mismatches <= 3)
                        ADD_FAILURE() << harris_path_name(f.code_path()) << " event " << i << ": fast " << a << " "
                                      << f.last_score() << ", naive " << b << " " << slow.last_score();
                }
                scored += !std::isnan(slow.last_score());
                corners += b;
            }
            EXPECT_EQ(mismatches, 0u);
            if (c.size.width > params.window && c.size.height > params.window) {
                EXPECT_GT(scored, 0u) << "the stream should exercise the scoring";
            }
            total_scored += scored;
            total_corners += corners;
        }
    EXPECT_GT(total_scored, 100000u);
    EXPECT_GT(total_corners, 1000u);
}

TEST(HarrisGlobal, MatchesNaiveOracleOnRandomStreams) {
    std::size_t total_corners = 0;
    for (const Case& c : kCases)
        for (const HarrisGlobalParams params : {HarrisGlobalParams{}, HarrisGlobalParams{1, 9, 0.04, 8.0},
                                                HarrisGlobalParams{30, 5, 0.05, 1.0}, HarrisGlobalParams{200, 7, 0.04, 2.0}}) {
            SCOPED_TRACE(std::to_string(c.size.width) + "x" + std::to_string(c.size.height) + " n " +
                         std::to_string(params.n) + " window " + std::to_string(params.window));
            const auto events = random_stream(c.size, std::min<std::size_t>(c.events, 4000), 77u * c.size.height + params.n);
            HarrisGlobal fast(c.size, params);
            naive::HarrisGlobalNaive slow(c.size, params.n, params.window, params.k, params.threshold);
            std::size_t mismatches = 0, corners = 0;
            for (std::size_t i = 0; i < events.size(); ++i) {
                const bool a = fast.process(events[i]);
                const bool b = slow.process(events[i]);
                const bool ok = a == b && same_score(fast.last_score(), slow.last_score());
                if (!ok && ++mismatches <= 3)
                    ADD_FAILURE() << "event " << i << ": fast " << a << " " << fast.last_score() << ", naive " << b
                                  << " " << slow.last_score();
                corners += b;
            }
            EXPECT_EQ(mismatches, 0u);
            total_corners += corners;
        }
    EXPECT_GT(total_corners, 1000u) << "the streams should exercise the scoring";
}

// The newest-N set kept by the queue is the one found by walking the history back.
TEST(NewestPixels, EqualsRecomputationFromHistory) {
    for (const std::size_t pixels : {1u, 2u, 5u, 40u, 300u})
        for (const std::size_t n : {1u, 2u, 3u, 10u, 64u, 1000u}) {
            SCOPED_TRACE("pixels " + std::to_string(pixels) + " n " + std::to_string(n));
            std::mt19937_64 rng(pixels * 7919 + n);
            std::vector<std::uint64_t> latest(pixels, 0);
            NewestPixels queue(n, pixels);
            std::vector<std::size_t> history;
            for (std::uint64_t seq = 1; seq <= 5000; ++seq) {
                // Skewed: a few hot pixels re-fire often, so stale entries pile up.
                const std::size_t id = rng() % 2 ? rng() % std::min<std::size_t>(pixels, 3) : rng() % pixels;
                const std::uint64_t previous = latest[id];
                latest[id] = seq;
                queue.push(id, seq, previous, latest.data());
                history.push_back(id);

                std::set<std::size_t> expected;
                for (auto it = history.rbegin(); it != history.rend() && expected.size() < n; ++it)
                    expected.insert(*it);
                std::set<std::size_t> got;
                for (std::size_t p = 0; p < pixels; ++p)
                    if (latest[p] != 0 && latest[p] >= queue.threshold()) got.insert(p);
                ASSERT_EQ(got, expected) << "after event " << seq;
                ASSERT_EQ(queue.size(), expected.size());
            }
        }
}

// ---------------------------------------------------------------- drawn patches

using Grid = std::vector<std::string>;  // '#' lit, '.' dark; 9 rows of 9

// Fires the lit pixels of `g` on a 9x9 sensor, the centre last, and returns the score
// the detector gives the centre event.
double detector_score(const Grid& g) {
    Harris det({9, 9}, HarrisParams{9, 25, 0.04, 8.0});
    std::int64_t t = 0;
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 9; ++x)
            if (g[y][x] == '#' && !(x == 4 && y == 4))
                det.process({++t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1});
    det.process({++t, 4, 4, 1});
    return det.last_score();
}

double naive_score(const Grid& g) {
    std::vector<std::vector<int>> p(9, std::vector<int>(9));
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 9; ++x) p[y][x] = g[y][x] == '#';
    return naive::harris_score_naive(p, 0.04);
}

// Expected values computed independently (Python, the definition of docs/harris.md).
TEST(HarrisDrawn, StraightEdgeScoresAboutMinus3p5) {
    // A vertical edge 3 pixels wide through the centre; its last row has one pixel, to
    // make 25.
    const Grid edge25{
        "...###...", "...###...", "...###...", "...###...", "...###...",
        "...###...", "...###...", "...###...", ".....#...",
    };
    EXPECT_NEAR(naive_score(edge25), -3.37780215761821, 1e-9);
    EXPECT_NEAR(detector_score(edge25), -3.37780215761821, 1e-9);
    EXPECT_FALSE(detector_score(edge25) > 8.0);
}

TEST(HarrisDrawn, LitQuadrantScoresAbout14p5) {
    const Grid quadrant{
        ".........", ".........", ".........", ".........", "....#####",
        "....#####", "....#####", "....#####", "....#####",
    };
    EXPECT_NEAR(naive_score(quadrant), 14.4458, 1e-4);
    EXPECT_NEAR(detector_score(quadrant), 14.4458, 1e-4);
}

TEST(HarrisDrawn, OnlyTheNewest25PixelsAreLit) {
    // A full 9x9 patch fired first, then the quadrant: the quadrant's 25 pixels are the
    // newest, so the score is the quadrant's, not the flat patch's (0).
    Harris det({9, 9});
    std::int64_t t = 0;
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 9; ++x) det.process({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 0});
    for (int y = 8; y >= 4; --y)
        for (int x = 8; x >= 4; --x) det.process({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 0});
    EXPECT_NEAR(det.last_score(), 14.4458, 1e-4);  // the last event is the centre (4, 4)
    // The other polarity is untouched: fewer than 25 pixels there, no score.
    det.process({t, 4, 4, 1});
    EXPECT_TRUE(std::isnan(det.last_score()));
}

TEST(HarrisDrawn, FewerThanNlPixelsGiveNoScore) {
    Harris det({9, 9});
    std::int64_t t = 0;
    for (int i = 0; i < 24; ++i) {
        EXPECT_FALSE(det.process({++t, static_cast<std::uint16_t>(i % 9), static_cast<std::uint16_t>(i / 9), 0}));
        EXPECT_TRUE(std::isnan(det.last_score()));
    }
    det.process({++t, 4, 4, 0});  // the 25th distinct pixel
    EXPECT_FALSE(std::isnan(det.last_score()));
}

TEST(HarrisDrawn, BorderRuleUsesStrictGreaterOnTheFarSide) {
    // 240x180: x = 236 = width - 4 is scored, x = 237 and x = 3 are not.
    Harris det(kDavis240, HarrisParams{9, 1, 0.04, 8.0});
    det.process({0, 236, 90, 1});
    EXPECT_FALSE(std::isnan(det.last_score()));
    det.process({0, 237, 90, 1});
    EXPECT_TRUE(std::isnan(det.last_score()));
    det.process({0, 3, 90, 1});
    EXPECT_TRUE(std::isnan(det.last_score()));
    det.process({0, 100, 176, 1});
    EXPECT_FALSE(std::isnan(det.last_score()));
    det.process({0, 100, 177, 1});
    EXPECT_TRUE(std::isnan(det.last_score()));
}

TEST(HarrisScorer, FlatAndEmptyPatchesScoreZero) {
    const HarrisScorer s(9, 0.04);
    std::uint16_t empty[9] = {};
    std::uint16_t full[9];
    for (auto& r : full) r = 0x1FF;
    EXPECT_EQ(s.score(empty), 0.0);
    EXPECT_NEAR(s.score(full), 0.0, 1e-12);
    double sum = 0;
    for (int r = 0; r < 5; ++r)
        for (int c = 0; c < 5; ++c) sum += s.weight(r, c);
    EXPECT_NEAR(sum, 1.0, 1e-15);
    // Centre weight: 1 / sum of exp(-(i^2 + j^2) / 2) over the 5x5 = 1 / (1 + 2e^-0.5 + 2e^-2)^2.
    const double row = 1 + 2 * std::exp(-0.5) + 2 * std::exp(-2.0);
    EXPECT_NEAR(s.weight(2, 2), 1.0 / (row * row), 1e-15);
    EXPECT_NEAR(s.weight(0, 0), std::exp(-4.0) / (row * row), 1e-15);
}

// ---------------------------------------------------------------- validation

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "(no exception)";
}

TEST(HarrisParams, OutOfRangeParametersThrowNamingThem) {
    EXPECT_PRED2(contains, error_of([] { Harris({240, 180}, HarrisParams{8, 25, 0.04, 8}); }), "window must be odd and within 5..15");
    EXPECT_PRED2(contains, error_of([] { Harris({240, 180}, HarrisParams{1, 1, 0.04, 8}); }), "window");
    EXPECT_PRED2(contains, error_of([] { Harris({240, 180}, HarrisParams{17, 25, 0.04, 8}); }), "(got 17)");
    EXPECT_PRED2(contains, error_of([] { Harris({240, 180}, HarrisParams{9, 82, 0.04, 8}); }), "nl must be within 1..81");
    EXPECT_PRED2(contains, error_of([] { Harris({240, 180}, HarrisParams{5, 0, 0.04, 8}); }), "nl must be within 1..25");
    EXPECT_PRED2(contains, error_of([] { Harris({240, 180}, HarrisParams{9, 25, NAN, 8}); }), "k must be");
    EXPECT_PRED2(contains, error_of([] { Harris({240, 180}, HarrisParams{9, 25, 0.04, INFINITY}); }), "threshold must be");
    EXPECT_PRED2(contains, error_of([] { HarrisGlobal({240, 180}, HarrisGlobalParams{0, 9, 0.04, 8}); }), "n must be within 1..");
    EXPECT_PRED2(contains, error_of([] { HarrisGlobal({240, 180}, HarrisGlobalParams{1000, 4, 0.04, 8}); }), "window must be odd");
    EXPECT_EQ(error_of([] { Harris({240, 180}, HarrisParams{15, 225, 0.0, 0.0}); }), "(no exception)");
}

TEST(Harris, MemoryIsTheArrivalSae) {
    // Two polarities x (w + 8) x (h + 8) cells of 8 bytes (a 4-pixel frame of padding).
    EXPECT_EQ(Harris({240, 180}).memory_bytes(), 2u * 248 * 188 * 8);
    EXPECT_EQ(Harris({1280, 720}).memory_bytes(), 2u * 1288 * 728 * 8);
    EXPECT_EQ(HarrisGlobal({240, 180}).memory_bytes(), 2u * 248 * 188 * 8 + 2u * 2001 * 16);
}

}  // namespace
}  // namespace evcorner
