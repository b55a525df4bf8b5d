// The fast Arc* against the plain oracle (naive/arcstar_naive.hpp), event for event, on
// seeded random streams at several sensor sizes with every parameter variant; and the
// arc test alone (size, shortcut, both newest-pixel searches) on random circles.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <string>
#include <vector>

#include "arcstar_test_streams.hpp"
#include "evcorner/arcstar.hpp"
#include "evcorner/naive/arcstar_naive.hpp"

namespace evcorner {
namespace {

// ---- the arc test alone

// Circles drawn from a small alphabet (many ties), with runs, so that every size occurs.
template <int N>
std::array<std::int64_t, N> random_circle(std::mt19937_64& rng) {
    std::array<std::int64_t, N> t{};
    const int alphabet = 2 + static_cast<int>(rng() % 12);
    const int mode = static_cast<int>(rng() % 3);
    for (int k = 0; k < N; ++k) {
        if (mode == 0) {
            t[k] = static_cast<std::int64_t>(rng() % alphabet);
        } else if (mode == 1) {
            t[k] = k > 0 && rng() % 3 != 0 ? t[k - 1] : static_cast<std::int64_t>(rng() % alphabet);
        } else {
            t[k] = (rng() % 4 == 0) ? 0 : static_cast<std::int64_t>(rng() % 1000000) + 1;  // 0 = never fired
        }
    }
    return t;
}

template <int N, int Lmin, int Lmax, class Search>
void check_circles(std::uint64_t seed, int count, int (&sizes)[N + 1]) {
    std::mt19937_64 rng(seed);
    for (int i = 0; i < count; ++i) {
        const auto c = random_circle<N>(rng);
        const int expected = naive::arcstar_size_naive<N>(c, Lmin);
        ++sizes[expected];
        std::int64_t t[2 * N];
        for (int k = 0; k < N; ++k) t[k] = c[k];
        const int newest = Search::template newest<N>(t);  // also fills t[N..2N)
        int first_max = 0;
        for (int k = 1; k < N; ++k)
            if (c[k] > c[first_max]) first_max = k;
        ASSERT_EQ(newest, first_max);
        ASSERT_EQ((arcstar_arc_size<N, Lmin, Lmax>(t, newest)), expected) << "circle #" << i;
        // The closed form (the AVX-512 path's definition) gives the same size.
        ASSERT_EQ(naive::arcstar_size_by_separation<N>(c, Lmin), expected) << "circle #" << i;
        // The shortcut, when it speaks, is right.
        if (arcstar_surely_full<N, Lmin, Search>(t, newest)) {
            ASSERT_EQ(expected, N) << "circle #" << i;
        }
        for (bool minority : {false, true}) {
            std::int64_t u[2 * N];
            for (int k = 0; k < N; ++k) u[k] = c[k];
            ASSERT_EQ((arcstar_circle_passes<N, Lmin, Lmax, Search>(u, [](int k) { return k; }, minority)),
                      naive::arcstar_arc_naive<N>(c, Lmin, Lmax, minority))
                << "circle #" << i;
        }
    }
}

TEST(ArcStarArc, FastSizeEqualsTheStepByStepDefinition) {
    int sizes16[17] = {}, sizes20[21] = {};
    check_circles<16, 3, 6, ScalarSearch>(1, 200000, sizes16);
    check_circles<20, 4, 8, ScalarSearch>(2, 200000, sizes20);
    // The drawn circles reach every size from Lmin to N.
    for (int s = 3; s <= 16; ++s) EXPECT_GT(sizes16[s], 0) << "size " << s;
    for (int s = 4; s <= 20; ++s) EXPECT_GT(sizes20[s], 0) << "size " << s;
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
[[gnu::target("avx2"), gnu::flatten]] void check_avx2(int (&s16)[17], int (&s20)[21]) {
    check_circles<16, 3, 6, Avx2Search>(3, 100000, s16);
    check_circles<20, 4, 8, Avx2Search>(4, 100000, s20);
}
TEST(ArcStarArc, Avx2PathEqualsTheDefinition) {
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 on this CPU";
    int s16[17] = {}, s20[21] = {};
    check_avx2(s16, s20);
}
#endif

// The AVX-512 path (closed form, all arcs at once) against the step-by-step definition.
#ifdef EVCORNER_HAVE_AVX2_SEARCH
template <int N, int Lmin, int Lmax>
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] void check_circles_avx512(std::uint64_t seed, int count,
                                                                              int (&sizes)[N + 1]) {
    std::mt19937_64 rng(seed);
    for (int i = 0; i < count; ++i) {
        const auto c = random_circle<N>(rng);
        ++sizes[naive::arcstar_size_naive<N>(c, Lmin)];
        // The circle drawn on a 9x9 grid (as a detector's plane holds it) around its centre.
        constexpr std::ptrdiff_t kGrid = 9;
        constexpr std::ptrdiff_t centre = 4 * kGrid + 4;
        std::array<std::int64_t, kGrid * kGrid> grid{};
        for (int k = 0; k < N; ++k) {
            const Offset o = N == 16 ? kCircle3[k] : kCircle4[k];
            grid[static_cast<std::size_t>(centre + o.dy * kGrid + o.dx)] = c[k];
        }
        // The event's stored time: just after the newest pixel (32-bit ages), or far away
        // (some or all fired pixels beyond 2^31: the portable fallback), or at the edge of
        // the narrowed range: the oldest fired pixel kRange - kAhead - 1 before the event
        // (the oldest age held, kRange - 1, one below the never-fired value kRange) and
        // kRange - kAhead before it (the first one that is not: the fallback).
        std::int64_t newest = 0, oldest_fired = INT64_MAX;
        for (std::int64_t v : c) {
            newest = std::max(newest, v);
            if (v != 0) oldest_fired = std::min(oldest_fired, v);
        }
        constexpr std::int64_t kRange = ArcStarAvx512::kRange, kAhead = ArcStarAvx512::kAhead;
        std::vector<std::int64_t> times = {newest + static_cast<std::int64_t>(rng() % 1000),
                                           (std::int64_t{1} << 31) + static_cast<std::int64_t>(rng() % 2000000)};
        if (oldest_fired != INT64_MAX) {
            times.push_back(oldest_fired + kRange - kAhead - 1);
            times.push_back(oldest_fired + kRange - kAhead);
        }
        // And the other edge, an event older than the pixels (unsorted input): the circle
        // moved up by 2^31 (order unchanged), the newest pixel kAhead after the event (age
        // 0, in range) and kAhead + 1 after it (the fallback).
        std::array<std::int64_t, kGrid * kGrid> later = grid;
        for (std::int64_t& v : later)
            if (v != 0) v += std::int64_t{1} << 31;
        const std::int64_t later_newest = newest + (std::int64_t{1} << 31);
        const std::size_t n_grid = times.size();
        if (newest != 0) {
            times.push_back(later_newest - kAhead);
            times.push_back(later_newest - kAhead - 1);
        }
        for (bool minority : {false, true}) {
            const bool want = naive::arcstar_arc_naive<N>(c, Lmin, Lmax, minority);
            for (std::size_t j = 0; j < times.size(); ++j) {
                const std::int64_t* const at = (j < n_grid ? grid.data() : later.data()) + centre;
                bool got;
                if constexpr (N == 16) got = ArcStarAvx512::circle16_passes(at, kGrid, times[j], minority);
                else got = ArcStarAvx512::circle20_passes(at, kGrid, times[j], minority);
                ASSERT_EQ(got, want) << "circle #" << i << ", event time #" << j;
            }
        }
    }
}
TEST(ArcStarArc, Avx512PathEqualsTheDefinition) {
    __builtin_cpu_init();
    if (!(__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
          __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq")))
        GTEST_SKIP() << "no AVX-512 on this CPU";
    int s16[17] = {}, s20[21] = {};
    check_circles_avx512<16, 3, 6>(5, 200000, s16);
    check_circles_avx512<20, 4, 8>(6, 200000, s20);
    for (int s = 3; s <= 16; ++s) EXPECT_GT(s16[s], 0) << "size " << s;
    for (int s = 4; s <= 20; ++s) EXPECT_GT(s20[s], 0) << "size " << s;
}
#endif

// ---- whole streams

struct Variant {
    const char* name;
    ArcStarParams params;
    std::int64_t step_us, pause_us;
};

const Variant kVariants[] = {
    {"published", {}, 2000, 60000},
    {"no_filter", {.filter = false}, 3, 0},
    {"minority_only", {.minority_only = true}, 2000, 60000},
    {"zero_init", {.zero_init = true}, 2000, 60000},
    {"short_window", {.filter_us = 40}, 30, 100},
    {"zero_window", {.filter_us = 0}, 2, 10},
    {"no_filter_minority", {.filter = false, .minority_only = true}, 3, 0},
};

class ArcStarVsOracle : public ::testing::TestWithParam<SensorSize> {};

TEST_P(ArcStarVsOracle, SameCornersEventForEventInEveryVariant) {
    const SensorSize s = GetParam();
    std::size_t streams = 0, events = 0;
    for (const Variant& v : kVariants) {
        std::size_t corners = 0, passed = 0;
        // One seed on an HD sensor: each stream allocates three HD states.
        const std::uint64_t seeds = s.pixels() > 500000 ? 1 : 3;
        for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
            const auto ev = test::arcstar_stream(s, 30000, seed * 7919 + static_cast<std::uint64_t>(s.width), v.step_us,
                                                 v.pause_us);
            ArcStar fast(s, v.params);
            ArcStar batch(s, v.params);
            naive::ArcStarNaive oracle(s, v.params);
            std::vector<std::uint8_t> flags(ev.size());
            detect(batch, std::span<const Event>(ev), flags);
            for (std::size_t i = 0; i < ev.size(); ++i) {
                const bool want = oracle.process(ev[i]);
                ASSERT_EQ(fast.process(ev[i]), want) << v.name << " seed " << seed << " event " << i;
                ASSERT_EQ(flags[i] != 0, want) << v.name << " (detect) seed " << seed << " event " << i;
                corners += want;
                passed += oracle.last_passed();
                // A passing event is in the filtered SAE.
                if (oracle.last_passed()) {
                    ASSERT_EQ(fast.sae().at(ev[i].p, ev[i].x, ev[i].y), ev[i].t);
                }
            }
            ++streams;
            events += ev.size();
        }
        // The streams exercise both outcomes, and the filter both ways.
        if (s.width >= 17 && s.height >= 13) {
            EXPECT_GT(corners, 0u) << v.name;
        }
        EXPECT_GT(passed, 0u) << v.name;
        if (v.params.filter) {
            EXPECT_LT(passed, seeds * 30000u) << v.name;
        } else {
            EXPECT_EQ(passed, seeds * 30000u) << v.name;
        }
    }
    std::printf("[ compared ] %zu streams, %zu events on %dx%d\n", streams, events, s.width, s.height);
}

INSTANTIATE_TEST_SUITE_P(Sizes, ArcStarVsOracle,
                         ::testing::Values(SensorSize{240, 180}, SensorSize{346, 260}, SensorSize{17, 13},
                                           SensorSize{1280, 720}, SensorSize{9, 9}, SensorSize{5, 300}),
                         [](const auto& info) {
                             return std::to_string(info.param.width) + "x" + std::to_string(info.param.height);
                         });

}  // namespace
}  // namespace evcorner
