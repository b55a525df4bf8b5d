// eFAST's code paths agree: the portable loop, the loop detect() picks for this CPU
// (AVX2 where available), and the naive oracle, event for event; the AVX2 newest-pixel
// search against the portable one on random circles.

#include <gtest/gtest.h>

#include <algorithm>
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
    EFast portable(s), chosen(s);
    naive::EFastNaive oracle(s);
    std::vector<std::uint8_t> a(events.size()), b(events.size());
    portable.run<ScalarSearch>(events, a);
    detect(chosen, std::span<const Event>(events), b);
    std::size_t corners = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const bool o = oracle.process(events[i]);
        ASSERT_EQ(a[i], o) << "portable, event " << i;
        ASSERT_EQ(b[i], o) << efast_code_path() << ", event " << i;
        corners += o;
    }
    EXPECT_GT(corners, 0u);
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
#endif

}  // namespace
}  // namespace evcorner
