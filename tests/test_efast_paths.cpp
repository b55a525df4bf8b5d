// eFAST's code paths agree: every loop this CPU runs (portable, AVX2, AVX-512), the one
// detect() picks, and the naive oracle, event for event; the AVX2 and AVX-512 pieces
// against the portable ones on random circles.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <random>
#include <vector>

#include "evcorner/efast.hpp"
#include "evcorner/io/text_reader.hpp"
#include "evcorner/naive/efast_naive.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

std::vector<Event> blob_stream(SensorSize s, std::size_t n, std::uint32_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> spread(0.0, 3.0);
    double bx = s.width / 2.0, by = s.height / 2.0, vx = 0.7, vy = -0.4;
    std::vector<Event> ev;
    std::int64_t t = 0;
    for (std::size_t i = 0; i < n; ++i) {
        t += static_cast<std::int64_t>(rng() % 3);
        bx += vx * 0.02;
        by += vy * 0.02;
        if (bx < 0 || bx >= s.width) vx = -vx;
        if (by < 0 || by >= s.height) vy = -vy;
        const bool clutter = unit(rng) < 0.05;
        const int x = clutter ? static_cast<int>(rng() % static_cast<unsigned>(s.width))
                              : std::clamp(static_cast<int>(bx + spread(rng)), 0, s.width - 1);
        const int y = clutter ? static_cast<int>(rng() % static_cast<unsigned>(s.height))
                              : std::clamp(static_cast<int>(by + spread(rng)), 0, s.height - 1);
        ev.push_back({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), static_cast<std::uint8_t>(rng() & 1)});
    }
    return ev;
}

void expect_paths_agree(const std::vector<Event>& events, SensorSize s) {
    naive::EFastNaive oracle(s);
    std::vector<std::uint8_t> expected(events.size());
    std::size_t corners = 0;
    for (std::size_t i = 0; i < events.size(); ++i) corners += expected[i] = oracle.process(events[i]);
    EXPECT_GT(corners, 0u);
    const auto paths = efast_code_paths();
    ASSERT_FALSE(paths.empty());
    EXPECT_EQ(paths.back(), "portable");
    for (const std::string& path : paths) {
        EFast det(s);
        std::vector<std::uint8_t> got(events.size(), 7);
        EXPECT_EQ(detect_on_path(path, det, events, got), corners) << path;
        for (std::size_t i = 0; i < events.size(); ++i) ASSERT_EQ(got[i], expected[i]) << path << ", event " << i;
    }
    EFast chosen(s);
    std::vector<std::uint8_t> got(events.size(), 7);
    detect(chosen, std::span<const Event>(events), got);
    EXPECT_EQ(got, expected) << efast_code_path();
}

TEST(EFastPaths, UnknownPathIsRefused) {
    EFast det(kDavis240);
    std::vector<Event> none;
    std::vector<std::uint8_t> flags;
    EXPECT_THROW(detect_on_path("sse9", det, none, flags), std::invalid_argument);
}

TEST(EFastPaths, AgreeOnRandomStreams) {
    RecordProperty("code_path", efast_code_path());
    for (const SensorSize s : {SensorSize{64, 48}, SensorSize{240, 180}, SensorSize{1280, 720}})
        expect_paths_agree(blob_stream(s, 80000, static_cast<std::uint32_t>(s.width)), s);
}

TEST(EFastPaths, AgreeOnTheBundledSample) {
    expect_paths_agree(io::read_text_file((test::bundled_data() / "ecd/shapes_translation/events.txt").string()),
                       kDavis240);
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
template <int N>
void avx2_search_matches(std::uint32_t seed) {
    std::mt19937_64 rng(seed);
    for (int round = 0; round < 100000; ++round) {
        std::int64_t a[2 * N], b[2 * N];
        const std::int64_t range = round % 2 ? 4 : 1000;  // many ties, few ties
        for (int k = 0; k < N; ++k) a[k] = b[k] = round % 7 == 0 && k % 3 == 0 ? INT64_MIN : static_cast<std::int64_t>(rng() % range);
        const int s = ScalarSearch::newest<N>(a);
        const int v = Avx2Search::newest<N>(b);
        ASSERT_EQ(b[v], a[s]) << "round " << round;  // both newest (ties may pick either)
        for (int k = 0; k < N; ++k) ASSERT_EQ(b[k + N], b[k]);
    }
}

TEST(EFastPaths, Avx2SearchFindsANewestPixel) {
    if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 on this CPU";
    avx2_search_matches<16>(1);
    avx2_search_matches<20>(2);
}

[[gnu::target(EVCORNER_AVX512_TARGET)]] bool circle16_fires_avx512(const std::int64_t* t) {
    alignas(64) static constexpr std::int64_t kOffsets[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
    return Avx512Search::circle16_fires(t, kOffsets);
}
[[gnu::target(EVCORNER_AVX512_TARGET)]] bool circle20_fires_avx512(const std::int64_t* t) {
    static constexpr std::int64_t kOffsets[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19};
    return Avx512Search::circle20_fires(t, kOffsets);
}

// Random circles of N pixels: many and few ties, planted arcs of 2..Lmax+1 newest pixels,
// never-fired pixels; the vector test must equal the definition on every one.
template <int N, int Lmin, int Lmax, class Test>
void vector_circle_test_matches(Test test, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    int fired = 0;
    for (int round = 0; round < 400000; ++round) {
        std::array<std::int64_t, N> t{};
        const std::int64_t range = round % 3 == 0 ? 3 : round % 3 == 1 ? N : 1000;
        for (auto& v : t) v = static_cast<std::int64_t>(rng() % range);
        if (round % 4 == 0) {
            const int start = static_cast<int>(rng() % N), len = 2 + static_cast<int>(rng() % Lmax);
            for (int k = 0; k < len; ++k) t[(start + k) % N] = range + static_cast<std::int64_t>(rng() % 5);
        }
        if (round % 11 == 0) t[rng() % N] = INT64_MIN;  // a pixel that never fired
        const bool expected = arc_fires_naive<N, Lmin, Lmax>(t);
        ASSERT_EQ(test(t.data()), expected) << "round " << round;
        fired += expected;
    }
    EXPECT_GT(fired, 10000);
}

TEST(EFastPaths, Avx512CircleTestsMatchTheDefinition) {
    if (!__builtin_cpu_supports("avx512f") || !__builtin_cpu_supports("avx512vl") ||
        !__builtin_cpu_supports("avx512bw") || !__builtin_cpu_supports("avx512dq"))
        GTEST_SKIP() << "no AVX-512 (F, VL, BW, DQ) on this CPU";
    vector_circle_test_matches<16, 3, 6>(circle16_fires_avx512, 7);
    vector_circle_test_matches<20, 4, 8>(circle20_fires_avx512, 8);
}
#endif

}  // namespace
}  // namespace evcorner
