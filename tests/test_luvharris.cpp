// luvHarris: the TOS on drawn grids (decay, reset, the event's pixel, border clipping),
// the look-up table against the plain definition on random surfaces, the whole detector
// against its oracle on seeded random streams at several sizes, determinism (twice, in
// chunks), the refresh points, parameter checks.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "evcorner/luvharris.hpp"
#include "evcorner/naive/luvharris_naive.hpp"

namespace evcorner {
namespace {

Event ev(std::int64_t t, int x, int y, int p = 0) {
    return {t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), static_cast<std::uint8_t>(p)};
}

std::vector<std::vector<int>> tos_of(const LuvHarris& d) {
    std::vector<std::vector<int>> g(static_cast<std::size_t>(d.size().height),
                                    std::vector<int>(static_cast<std::size_t>(d.size().width)));
    for (int y = 0; y < d.size().height; ++y)
        for (int x = 0; x < d.size().width; ++x) g[y][x] = d.tos(x, y);
    return g;
}

std::vector<int> flat_tos(const LuvHarris& d) {
    std::vector<int> v;
    for (int y = 0; y < d.size().height; ++y)
        for (int x = 0; x < d.size().width; ++x) v.push_back(d.tos(x, y));
    return v;
}

LuvHarrisParams tos_params(int k, int t) {
    LuvHarrisParams p;
    p.tos_size = k;
    p.tos_threshold = t;
    return p;
}

// ---------------------------------------------------------------- the TOS, drawn

TEST(LuvHarrisTos, EventPixelBecomes255NeighboursDecayByOne) {
    LuvHarris d({6, 4}, tos_params(3, 2));  // drop below 255 - 6 = 249
    d.process(ev(0, 1, 1));
    d.process(ev(1, 3, 1));  // 2 pixels away: outside the 3x3 of (1, 1)
    d.process(ev(2, 5, 3));  // corner of the sensor: its 3x3 clipped to 2x2
    d.process(ev(3, 2, 1));  // between the first two: both decay by one
    const std::vector<std::vector<int>> want{
        {0, 0, 0, 0, 0, 0},
        {0, 254, 255, 254, 0, 0},
        {0, 0, 0, 0, 0, 0},
        {0, 0, 0, 0, 0, 255},
    };
    EXPECT_EQ(tos_of(d), want);
}

TEST(LuvHarrisTos, SamePixelAgainStays255) {
    LuvHarris d({5, 5}, tos_params(3, 2));
    d.process(ev(0, 2, 2));
    d.process(ev(1, 2, 2));
    EXPECT_EQ(d.tos(2, 2), 255);
    d.process(ev(2, 2, 3));
    EXPECT_EQ(d.tos(2, 2), 254);
    EXPECT_EQ(d.tos(2, 3), 255);
}

TEST(LuvHarrisTos, ValuesBelowTheLimitDropToZero) {
    // k = 7, T = 2: limit 255 - 14 = 241. (3, 3) fired once, then its neighbour again and
    // again: 255 -> 254 ... -> 241 after 14 events (241 is not below 241), 240 after 15,
    // then 0 (240 < 241).
    LuvHarris d({9, 9});
    d.process(ev(0, 3, 3));
    for (int i = 1; i <= 14; ++i) d.process(ev(i, 4, 3));
    EXPECT_EQ(d.tos(3, 3), 241);
    d.process(ev(15, 4, 3));
    EXPECT_EQ(d.tos(3, 3), 240);
    d.process(ev(16, 4, 3));
    EXPECT_EQ(d.tos(3, 3), 0);
    EXPECT_EQ(d.tos(4, 3), 255);
    // Reach: (7, 3) is 3 columns from (4, 3), inside the 7x7; (8, 3) is not.
    d.process(ev(17, 7, 3));
    d.process(ev(18, 8, 3));
    d.process(ev(19, 4, 3));
    EXPECT_EQ(d.tos(7, 3), 253);  // decayed by (8, 3) and by (4, 3)
    EXPECT_EQ(d.tos(8, 3), 255);  // (4, 3) is 4 columns away
}

TEST(LuvHarrisTos, BorderClippingOnTinySensors) {
    LuvHarris one({1, 1});
    one.process(ev(0, 0, 0));
    one.process(ev(1, 0, 0));
    EXPECT_EQ(one.tos(0, 0), 255);
    LuvHarris d({2, 3}, tos_params(31, 8));  // the 31x31 covers it all
    d.process(ev(0, 0, 0));
    d.process(ev(1, 1, 2));
    EXPECT_EQ(d.tos(0, 0), 254);
    EXPECT_EQ(d.tos(1, 2), 255);
    EXPECT_EQ(d.tos(1, 0), 0);
    // And the oracle agrees on every pixel of a random stream on tiny sensors.
    for (const SensorSize s : {SensorSize{1, 1}, SensorSize{1, 7}, SensorSize{5, 2}, SensorSize{3, 3}}) {
        LuvHarris f(s, tos_params(5, 20));
        naive::TosNaive n(s, 5, 20);
        std::mt19937 rng(s.width * 10 + s.height);
        for (int i = 0; i < 500; ++i) {
            const int x = static_cast<int>(rng() % s.width), y = static_cast<int>(rng() % s.height);
            f.process(ev(i, x, y));
            n.update(x, y);
            ASSERT_EQ(flat_tos(f), n.v) << s.width << "x" << s.height << " event " << i;
        }
    }
}

// ---------------------------------------------------------------- the response

TEST(LuvHarrisResponse, EqualsTheFormulaInDoubles) {
    std::mt19937_64 rng(5);
    for (int i = 0; i < 10000; ++i) {
        const std::int64_t a = static_cast<std::int64_t>(rng() % (std::uint64_t{1} << 40));
        const std::int64_t c = static_cast<std::int64_t>(rng() % (std::uint64_t{1} << 40));
        const std::int64_t b = static_cast<std::int64_t>(rng() % (std::uint64_t{1} << 40)) - (std::int64_t{1} << 39);
        const std::int64_t k_q = static_cast<std::int64_t>(rng() % 16384);
        const long double want = (static_cast<long double>(a) * c - static_cast<long double>(b) * b -
                                  static_cast<long double>(k_q) / 65536 * (static_cast<long double>(a) + c) * (a + c));
        const double got = luv_harris_response(a, b, c, k_q, 1.0 / 65536);
        // One rounding of the result (2^-53 relative) at the magnitude of its terms.
        const long double tol =
            1e-15L * (static_cast<long double>(a) * c + static_cast<long double>(b) * b +
                      (static_cast<long double>(a) + c) * (a + c)) + 1;
        ASSERT_LE(std::fabs(static_cast<long double>(got) - want), tol) << a << " " << b << " " << c << " " << k_q;
    }
    EXPECT_EQ(luv_harris_response(0, 0, 0, 2621, 1.0), 0.0);
    EXPECT_EQ(luv_harris_response(3, 0, 3, 0, 1.0 / 65536), 9.0);
    EXPECT_EQ(luv_harris_response(4, 1, 2, 32768, 1.0 / 65536), 8 - 1 - 18.0);
}

// A bright quadrant's corner scores above its edges, which score below zero; a flat
// surface scores zero.
TEST(LuvHarrisTable, CornerPositiveEdgeNegativeFlatZero) {
    // A bright quadrant x, y >= 16 on a 32x32 sensor: k = 3, T = 84 (values drop to 0 only
    // below 3), so the quadrant stays at 247..255 while it is filled.
    LuvHarris d({32, 32}, tos_params(3, 84));
    for (int y = 16; y < 32; ++y)
        for (int x = 16; x < 32; ++x) d.process(ev(0, x, y));
    EXPECT_GE(d.tos(20, 20), 247);
    d.refresh();
    const auto want = naive::luv_harris_image_naive(flat_tos(d), {32, 32}, d.params());
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) ASSERT_EQ(d.table(x, y), want[static_cast<std::size_t>(y) * 32 + x]);
    EXPECT_EQ(d.table(2, 2), 0.0) << "flat (never fired) surface";
    EXPECT_GT(d.table(16, 16), 0.0) << "the quadrant's corner";
    EXPECT_LT(d.table(16, 24), 0.0) << "its left edge";
    EXPECT_LT(d.table(24, 16), 0.0) << "its top edge";
    EXPECT_GT(d.table(16, 16), 100 * std::abs(d.table(24, 24))) << "corner against the quadrant's inside";
}

// ---------------------------------------------------------------- the table vs the oracle

std::vector<LuvHarrisParams> table_param_sets() {
    std::vector<LuvHarrisParams> sets;
    LuvHarrisParams p;
    sets.push_back(p);  // defaults: 5x5 gradient, 5x5 box
    p.gradient = 3;
    p.block = 3;
    p.k = 0.06;
    sets.push_back(p);
    p.gaussian_block = true;
    p.block = 9;
    p.gradient = 5;
    p.replicate_border = true;
    sets.push_back(p);
    LuvHarrisParams q;
    q.block = 15;
    q.k = 0.25;
    q.tos_threshold = 36;  // slow decay: a wide range of values
    sets.push_back(q);
    q.block = 1;
    q.k = 0.0;
    q.replicate_border = true;
    sets.push_back(q);
    return sets;
}

TEST(LuvHarrisTable, EqualsTheDefinitionOnRandomSurfaces) {
    std::size_t compared = 0, nonzero = 0;
    for (const SensorSize s : {SensorSize{1, 1}, SensorSize{2, 3}, SensorSize{7, 5}, SensorSize{33, 17},
                               SensorSize{64, 48}, SensorSize{240, 180}})
        for (const LuvHarrisParams& p : table_param_sets()) {
            LuvHarrisParams q = p;
            q.tos_threshold = std::min(p.tos_threshold + 30, 254 / p.tos_size);  // many grey levels
            LuvHarris d(s, q);
            std::mt19937_64 rng(static_cast<std::uint64_t>(s.width * 131 + s.height * 7 + q.block));
            const int n = static_cast<int>(std::min<std::int64_t>(s.pixels() / 2 + 3, 6000));
            for (int i = 0; i < n; ++i)
                d.process(ev(0, static_cast<int>(rng() % s.width), static_cast<int>(rng() % s.height)));
            d.refresh();
            const auto want = naive::luv_harris_image_naive(flat_tos(d), s, q);
            for (int y = 0; y < s.height; ++y)
                for (int x = 0; x < s.width; ++x) {
                    const double w = want[static_cast<std::size_t>(y) * s.width + x];
                    ASSERT_EQ(d.table(x, y), w) << s.width << "x" << s.height << " block " << q.block << " at (" << x
                                                << ", " << y << ")";
                    nonzero += w != 0.0;
                    ++compared;
                }
        }
    EXPECT_GT(nonzero, compared / 4);
    std::printf("table: %zu pixels compared, %zu non-zero\n", compared, nonzero);
}

// The table as refreshes leave it (copied TOS tiles, stale values computed when read, or
// the whole table after many events) equals the whole table recomputed from the TOS of the
// refresh point, after random runs of events of random lengths, whichever pixels were read
// in between.
TEST(LuvHarrisTable, IncrementalEqualsAFullRecompute) {
    std::vector<LuvHarrisParams> sets;
    for (const int g : {3, 5})
        for (const int b : {1, 3, 5, 7, 9, 15}) {
            LuvHarrisParams p;
            p.gradient = g;
            p.block = b;
            p.replicate_border = b % 4 == 1;
            p.tos_size = b == 7 ? 15 : b == 3 ? 3 : 7;
            sets.push_back(p);
        }
    for (const int b : {3, 5, 9}) {
        LuvHarrisParams p;
        p.gaussian_block = true;
        p.block = b;
        p.gradient = b == 5 ? 3 : 5;
        p.replicate_border = b != 9;
        sets.push_back(p);
    }
    std::uint64_t lazy = 0, full = 0, computed = 0, possible = 0, checked = 0;
    for (const SensorSize s : {SensorSize{9, 7}, SensorSize{33, 17}, SensorSize{64, 48}})
        for (std::size_t k = 0; k < sets.size(); ++k) {
            LuvHarrisParams p = sets[k];
            p.refresh_us = 0;
            p.refresh_events = std::int64_t{1} << 40;  // refreshed by the test only
            LuvHarris d(s, p);
            std::mt19937_64 rng(static_cast<std::uint64_t>(s.width) * 1000 + k);
            std::uniform_real_distribution<double> unit(0.0, 1.0);
            double bx = unit(rng) * s.width, by = unit(rng) * s.height;
            for (int round = 0; round < 40; ++round) {
                // Mostly short runs (values computed when read), now and then a long one.
                const std::int64_t n = round % 9 == 8 ? s.pixels() : 1 + static_cast<std::int64_t>(rng() % 12);
                for (std::int64_t i = 0; i < n; ++i) {
                    bx = std::clamp(bx + (unit(rng) - 0.5) * 2, 0.0, s.width - 1.0);
                    by = std::clamp(by + (unit(rng) - 0.5) * 2, 0.0, s.height - 1.0);
                    const bool noise = rng() % 8 == 0;
                    const int x = noise ? static_cast<int>(rng() % s.width) : static_cast<int>(bx);
                    const int y = noise ? static_cast<int>(rng() % s.height) : static_cast<int>(by);
                    d.process(ev(round, x, y));
                }
                const std::uint64_t fulls = d.full_refreshes();
                d.refresh();
                (d.full_refreshes() > fulls ? full : lazy) += 1;
                const auto want = naive::luv_harris_image_naive(flat_tos(d), s, p);
                // Read every pixel, or a random third of them (the others stay stale).
                const bool all = round % 5 == 4;
                for (int y = 0; y < s.height; ++y)
                    for (int x = 0; x < s.width; ++x) {
                        if (!all && rng() % 3 != 0) continue;
                        ASSERT_EQ(d.table(x, y), want[static_cast<std::size_t>(y) * s.width + x])
                            << s.width << "x" << s.height << " set " << k << " round " << round << " at (" << x
                            << ", " << y << ")";
                        ++checked;
                    }
            }
            computed += d.table_values_computed();
            possible += d.refreshes() * static_cast<std::uint64_t>(s.pixels());
        }
    EXPECT_GT(lazy, full);
    EXPECT_GT(full, 0u);
    EXPECT_LT(computed, possible / 2) << "most values are never computed";
    std::printf("incremental: %llu lazy and %llu full refreshes, %llu values compared, %llu of %llu computed\n",
                static_cast<unsigned long long>(lazy), static_cast<unsigned long long>(full),
                static_cast<unsigned long long>(checked), static_cast<unsigned long long>(computed),
                static_cast<unsigned long long>(possible));
}

// ---------------------------------------------------------------- the detector vs the oracle

// Events around drifting blobs, 0-3 us apart (about 1000 events per refresh_us = 1000),
// both polarities (ignored), some uniform noise.
std::vector<Event> random_stream(SensorSize s, std::size_t n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> spread(0.0, 3.0);
    double bx[3], by[3];
    for (int b = 0; b < 3; ++b) {
        bx[b] = unit(rng) * s.width;
        by[b] = unit(rng) * s.height;
    }
    std::vector<Event> events;
    std::int64_t t = 5000;
    for (std::size_t i = 0; i < n; ++i) {
        t += static_cast<std::int64_t>(rng() % 4);
        const int b = static_cast<int>(rng() % 3);
        bx[b] = std::clamp(bx[b] + (unit(rng) - 0.5) * 0.3, 0.0, s.width - 1.0);
        by[b] = std::clamp(by[b] + (unit(rng) - 0.5) * 0.3, 0.0, s.height - 1.0);
        int x, y;
        if (unit(rng) < 0.1) {
            x = static_cast<int>(rng() % s.width);
            y = static_cast<int>(rng() % s.height);
        } else {
            x = std::clamp(static_cast<int>(std::lround(bx[b] + spread(rng))), 0, s.width - 1);
            y = std::clamp(static_cast<int>(std::lround(by[b] + spread(rng))), 0, s.height - 1);
        }
        events.push_back(ev(t, x, y, static_cast<int>(rng() & 1)));
    }
    return events;
}

std::vector<LuvHarrisParams> detector_param_sets() {
    std::vector<LuvHarrisParams> sets;
    LuvHarrisParams p;  // defaults: adaptive, every 1000 us
    sets.push_back(p);
    p.refresh_us = 0;
    p.refresh_events = 700;
    p.adaptive = false;
    p.threshold = 1e6;
    sets.push_back(p);
    p.refresh_us = 333;
    p.refresh_events = 1000;
    p.adaptive = true;
    p.sigmas = 1.0;
    p.alpha = 0.01;
    p.gradient = 3;
    p.gaussian_block = true;
    p.block = 5;
    p.replicate_border = true;
    sets.push_back(p);
    return sets;
}

bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

TEST(LuvHarrisOracle, SameCornersAndScoresEventForEvent) {
    std::size_t total = 0, corners = 0, refreshes = 0;
    for (const SensorSize s : {SensorSize{1, 1}, SensorSize{9, 7}, SensorSize{40, 30}, SensorSize{240, 180},
                               SensorSize{346, 260}})
        for (const LuvHarrisParams& p : detector_param_sets()) {
            const std::size_t n = s.pixels() > 50000 ? 6000 : 12000;  // the oracle's refresh is slow
            const auto events = random_stream(s, n, static_cast<std::uint64_t>(s.width) * 17 + p.block);
            LuvHarris fast(s, p);
            naive::LuvHarrisNaive oracle(s, p);
            std::size_t c = 0;
            for (std::size_t i = 0; i < events.size(); ++i) {
                const bool a = fast.process(events[i]);
                const bool b = oracle.process(events[i]);
                ASSERT_EQ(a, b) << s.width << "x" << s.height << " event " << i;
                ASSERT_TRUE(same(fast.last_score(), oracle.last_score()))
                    << s.width << "x" << s.height << " event " << i << ": " << fast.last_score() << " vs "
                    << oracle.last_score();
                c += a;
            }
            EXPECT_EQ(fast.refreshes(), oracle.refreshes());
            if (s.pixels() > 100) {
                EXPECT_GT(c, 0u) << s.width << "x" << s.height;
                EXPECT_LT(c, events.size() / 2) << s.width << "x" << s.height;
            }
            total += events.size();
            corners += c;
            refreshes += fast.refreshes();
        }
    std::printf("oracle: %zu events, %zu corners, %zu refreshes\n", total, corners, refreshes);
}

TEST(LuvHarrisOracle, HdSensor) {
    const SensorSize s{1280, 720};
    LuvHarrisParams p;
    p.refresh_us = 0;
    p.refresh_events = 1500;
    const auto events = random_stream(s, 4000, 1280);
    LuvHarris fast(s, p);
    naive::LuvHarrisNaive oracle(s, p);
    std::size_t c = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const bool a = fast.process(events[i]);
        ASSERT_EQ(a, oracle.process(events[i])) << i;
        ASSERT_TRUE(same(fast.last_score(), oracle.last_score())) << i;
        c += a;
    }
    EXPECT_EQ(fast.refreshes(), 2u);
    EXPECT_GT(c, 0u);
}

// ---------------------------------------------------------------- determinism

TEST(LuvHarrisDeterminism, SameInputTwiceAndInChunks) {
    const SensorSize s{240, 180};
    const auto events = random_stream(s, 40000, 42);
    LuvHarris first(s);
    std::vector<std::uint8_t> want(events.size());
    std::vector<double> want_score(events.size());
    detect(first, std::span<const Event>(events), want, want_score);
    EXPECT_GT(std::count(want.begin(), want.end(), 1), 0);
    for (const std::size_t chunk : {std::size_t{1}, std::size_t{777}, std::size_t{4096}, events.size()}) {
        LuvHarris again(s);
        std::vector<std::uint8_t> got(events.size());
        std::vector<double> score(events.size());
        for (std::size_t b = 0; b < events.size(); b += chunk) {
            const std::size_t n = std::min(chunk, events.size() - b);
            detect(again, std::span<const Event>(events.data() + b, n), std::span<std::uint8_t>(got.data() + b, n),
                   std::span<double>(score.data() + b, n));
        }
        EXPECT_EQ(got, want) << "chunk " << chunk;
        for (std::size_t i = 0; i < events.size(); ++i) ASSERT_TRUE(same(score[i], want_score[i])) << i;
    }
}

// ---------------------------------------------------------------- refresh points

TEST(LuvHarrisRefresh, TimeRuleFromTheFirstEvent) {
    LuvHarrisParams p;  // refresh_us = 1000
    LuvHarris d({20, 20}, p);
    const std::pair<std::int64_t, std::uint64_t> steps[] = {
        {700, 0},   // t0 = 700: points at 1700, 2700, ...
        {1699, 0},  {1700, 1},  // the first event at or after 1700
        {1701, 1},  {2699, 1},  {2700, 2},
        {6000, 3},  // 3700, 4700 and 5700 passed without events: one refresh
        {6699, 3},  {6700, 4},
        {100, 4},   // time going back: nothing until the next point, 7700
        {7699, 4},  {7700, 5},
    };
    for (const auto& [t, want] : steps) {
        d.process(ev(t, 10, 10));
        EXPECT_EQ(d.refreshes(), want) << "t = " << t;
    }
}

TEST(LuvHarrisRefresh, CountRuleAndBoth) {
    LuvHarrisParams p;
    p.refresh_us = 0;
    p.refresh_events = 10;
    LuvHarris d({20, 20}, p);
    for (int i = 0; i < 35; ++i) {
        d.process(ev(0, 10, 10));
        EXPECT_EQ(d.refreshes(), static_cast<std::uint64_t>(i / 10)) << "event " << i;
        EXPECT_EQ(std::isnan(d.last_score()), i < 10) << "no score before the first refresh";
    }
    p.refresh_us = 100;
    LuvHarris both({20, 20}, p);
    // Events every 50 us: time points at 100, 200, ... (every second event), count points
    // at events 10, 20, ... (also on a time point: one refresh).
    for (int i = 0; i < 30; ++i) both.process(ev(i * 50, 10, 10));
    EXPECT_EQ(both.refreshes(), 14u);  // events 2, 4, ..., 28
}

TEST(LuvHarrisRefresh, TheEventAtAPointSeesTheSurfaceBeforeIt) {
    LuvHarrisParams p;
    p.refresh_us = 0;
    p.refresh_events = 5;
    p.adaptive = false;
    LuvHarris d({16, 16}, p);
    for (int i = 0; i < 5; ++i) d.process(ev(i, 6 + i, 6));
    const auto before = flat_tos(d);
    d.process(ev(5, 8, 9));  // the refresh point: table from the 5 earlier events only
    const auto want = naive::luv_harris_image_naive(before, {16, 16}, p);
    EXPECT_EQ(d.last_score(), want[9 * 16 + 8]);
    EXPECT_NE(flat_tos(d), before);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) ASSERT_EQ(d.table(x, y), want[static_cast<std::size_t>(y) * 16 + x]);
}

TEST(LuvHarrisThreshold, FixedAndAdaptive) {
    // Fixed: corner iff value > threshold.
    LuvHarrisParams p;
    p.refresh_us = 0;
    p.refresh_events = 1;
    p.adaptive = false;
    p.threshold = -1e300;
    LuvHarris any({16, 16}, p);
    EXPECT_FALSE(any.process(ev(0, 5, 5))) << "no table before the first refresh (before event 1)";
    EXPECT_TRUE(any.process(ev(1, 5, 6))) << "every value exceeds -1e300";
    EXPECT_TRUE(any.process(ev(2, 5, 7)));
    p.threshold = 1e300;
    LuvHarris none({16, 16}, p);
    for (int i = 0; i < 20; ++i) EXPECT_FALSE(none.process(ev(i, 5 + i % 3, 5 + i % 4)));
    // Adaptive: the first looked-up value only starts the statistics.
    LuvHarrisParams a;
    a.refresh_us = 0;
    a.refresh_events = 1;
    LuvHarris ad({16, 16}, a);
    ad.process(ev(0, 5, 5));
    EXPECT_FALSE(ad.process(ev(1, 5, 6)));
    EXPECT_EQ(ad.running_mean(), ad.last_score());
    EXPECT_EQ(ad.running_variance(), 0.0);
}

TEST(LuvHarrisParams, OutOfRangeParametersThrowNamingThem) {
    auto message = [](auto change) -> std::string {
        LuvHarrisParams p;
        change(p);
        try {
            LuvHarris d({240, 180}, p);
        } catch (const std::invalid_argument& e) {
            return e.what();
        }
        return "(no exception)";
    };
    EXPECT_NE(message([](auto& p) { p.tos_size = 8; }).find("tos_size must be odd"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.tos_threshold = 37; }).find("tos_threshold must be within 0..36"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.gradient = 7; }).find("gradient must be 3 or 5"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.block = 17; }).find("block must be odd and within 1..15"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.gaussian_block = true; p.block = 11; }).find("3..9 (gaussian)"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.k = 0.3; }).find("k must be"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.refresh_us = -1; }).find("refresh_us must be"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.refresh_events = -1; }).find("refresh_events must be"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.refresh_us = 0; }).find("cannot both be 0"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.alpha = 0; }).find("alpha must be"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.sigmas = NAN; }).find("sigmas must be"), std::string::npos);
    EXPECT_NE(message([](auto& p) { p.threshold = INFINITY; }).find("threshold must be"), std::string::npos);
    EXPECT_EQ(message([](auto&) {}), "(no exception)");
    EXPECT_THROW(LuvHarris({0, 5}), std::invalid_argument);
    EXPECT_THROW(LuvHarris({5, 5}).process(ev(0, 5, 0)), InvalidEvent);
    EXPECT_THROW(LuvHarris({5, 5}).process(ev(LuvHarris::kMaxTime + 1, 0, 0)), InvalidEvent);
}

TEST(LuvHarris, MemoryIsStateBytes) {
    for (const SensorSize s : {SensorSize{240, 180}, SensorSize{1280, 720}}) {
        EXPECT_EQ(LuvHarris(s).memory_bytes(), LuvHarris::state_bytes(s));
        const LuvHarris original(s);
        const LuvHarris copy(original);  // a copy holds the same buffers
        EXPECT_EQ(copy.memory_bytes(), LuvHarris::state_bytes(s));
        // The TOS (framed by 4) and its copy, the table and its stamps dominate; the
        // refresh's rings and the tile marks are small.
        const std::uint64_t main = 2u * static_cast<std::uint64_t>(s.width + 8) * (s.height + 8) + 12u * s.pixels();
        EXPECT_GE(LuvHarris::state_bytes(s), main);
        EXPECT_LT(LuvHarris::state_bytes(s), main + 200u * (s.width + 8) + s.pixels() / 7);  // 9 bytes per 8x8 tile
    }
}

}  // namespace
}  // namespace evcorner
