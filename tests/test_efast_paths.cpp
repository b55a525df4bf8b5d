// eFAST's code paths agree: every loop this CPU runs (portable, AVX2, AVX-512), the one
// detect() picks, and the naive oracle, event for event; the AVX2 and AVX-512 pieces
// against the portable ones on random circles.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <optional>
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

// The AVX-512 path tests the radius-3 circle on 32-bit times relative to the event's,
// exact within [-2^30, 2^30) us of it, and sends any other event to its 64-bit test
// (efast_avx512.hpp). These streams put fired circle pixels beyond that range: gaps of
// about and above 2^30 us, times near both ends of the SAE's range.
constexpr std::int64_t kNarrow = std::int64_t{1} << 30;

// How many of the oracle's corners have a fired radius-3 pixel (of the event's polarity)
// outside [t - 2^30, t + 2^30): the corners only the exact test decides.
std::size_t corners_beyond_the_narrow_range(const std::vector<Event>& events, SensorSize s) {
    naive::EFastNaive oracle(s);
    std::vector<std::int64_t> last[2];
    std::vector<bool> fired[2];
    for (int p = 0; p < 2; ++p) {
        last[p].assign(static_cast<std::size_t>(s.pixels()), 0);
        fired[p].assign(static_cast<std::size_t>(s.pixels()), false);
    }
    std::size_t n = 0;
    for (const Event& e : events) {
        const std::size_t i = static_cast<std::size_t>(e.y) * static_cast<std::size_t>(s.width) + e.x;
        last[e.p][i] = e.t;
        fired[e.p][i] = true;
        if (!oracle.process(e)) continue;
        bool beyond = false;
        for (const Offset& o : kCircle3) {
            const std::size_t j = static_cast<std::size_t>((e.y + o.dy) * s.width + e.x + o.dx);
            beyond |= fired[e.p][j] && (last[e.p][j] < e.t - kNarrow || last[e.p][j] >= e.t + kNarrow);
        }
        n += beyond;
    }
    return n;
}

TEST(EFastPaths, AgreeAcrossGapsBeyondTheNarrowRange) {
    const SensorSize s{240, 180};
    // Gaps every 8000 events: just inside and just outside 2^30, 2^31, 2^40 us.
    const std::int64_t gaps[] = {kNarrow - 3, kNarrow + 1, 2 * kNarrow, std::int64_t{1} << 40, kNarrow};
    for (const std::int64_t start : {std::int64_t{0}, Sae::kMinTime, Sae::kMaxTime - (std::int64_t{1} << 42)}) {
        std::vector<Event> events = blob_stream(s, 80000, 11);
        std::int64_t shift = start;
        for (std::size_t i = 0; i < events.size(); ++i) {
            if (i > 0 && i % 8000 == 0) shift += gaps[(i / 8000) % std::size(gaps)];
            events[i].t += shift;
        }
        ASSERT_LE(events.back().t, Sae::kMaxTime);
        EXPECT_GT(corners_beyond_the_narrow_range(events, s), 20u) << "start " << start;
        expect_paths_agree(events, s);
    }
}

// Drawn: an arc on each circle (4 of 16, 5 of 20) fired at time `arc`, the rest of both
// circles at time `rest` (or never, by default); then the event in the centre at time
// `now`. The arc is newer than the rest at any distance in time, so it is a corner on
// every path, although fired pixels far outside the 32-bit range would all narrow to
// one value there (and to the never-fired pixels' one).
void expect_old_arc_fires(std::int64_t arc, std::int64_t now, std::optional<std::int64_t> rest = std::nullopt) {
    const SensorSize s{20, 20};
    const int x0 = 10, y0 = 10;
    std::vector<Event> events;
    auto add = [&](std::int64_t t, int dx, int dy) {
        events.push_back({t, static_cast<std::uint16_t>(x0 + dx), static_cast<std::uint16_t>(y0 + dy), 1});
    };
    for (int k = 0; k < 4; ++k) add(arc, kCircle3[k].dx, kCircle3[k].dy);
    for (int k = 0; k < 5; ++k) add(arc, kCircle4[k].dx, kCircle4[k].dy);
    if (rest) {
        for (int k = 4; k < 16; ++k) add(*rest, kCircle3[k].dx, kCircle3[k].dy);
        for (int k = 5; k < 20; ++k) add(*rest, kCircle4[k].dx, kCircle4[k].dy);
    }
    add(now, 0, 0);
    naive::EFastNaive oracle(s);
    std::vector<std::uint8_t> expected;
    for (const Event& e : events) expected.push_back(oracle.process(e));
    ASSERT_EQ(expected.back(), 1) << "arc " << arc << ", event " << now;
    for (const std::string& path : efast_code_paths()) {
        EFast det(s);
        std::vector<std::uint8_t> got(events.size(), 7);
        detect_on_path(path, det, events, got);
        EXPECT_EQ(got, expected) << path << ": arc " << arc << ", event " << now;
    }
}

TEST(EFastPaths, ArcFiredLongAgoAgainstNeverFiredPixels) {
    const std::int64_t now = std::int64_t{1} << 41;
    for (const std::int64_t age : {std::int64_t{1}, kNarrow - 1, kNarrow, kNarrow + 1, 2 * kNarrow, now})
        expect_old_arc_fires(now - age, now);
    for (const std::int64_t ahead : {std::int64_t{1}, kNarrow - 1, kNarrow, 2 * kNarrow})
        expect_old_arc_fires(now + ahead, now);
    expect_old_arc_fires(Sae::kMinTime, Sae::kMinTime + 5);
    expect_old_arc_fires(Sae::kMinTime, Sae::kMaxTime);
    expect_old_arc_fires(Sae::kMaxTime, Sae::kMinTime);
    // Both the arc and the rest beyond the range, on either side of the event.
    expect_old_arc_fires(now - 2 * kNarrow, now, now - 4 * kNarrow);
    expect_old_arc_fires(now - kNarrow - 2, now, now - kNarrow - 3);
    expect_old_arc_fires(now + 4 * kNarrow, now, now + 2 * kNarrow);
    expect_old_arc_fires(now + 2 * kNarrow, now, now - 2 * kNarrow);
}

// The AVX-512 loop leaves out the range check while every time the detector has taken
// spans less than 2^30 us (EFast::run_unchecked). Drawn as above, the arc and the rest
// fed first (by detect(), by process() one event at a time, by detect() with scores, or
// by detect_unchecked(), whose span is unknown), then the centre event alone by detect() on each path: the
// detector must remember the earlier times: else at the largest age the arc and the
// older rest would both narrow to the saturated value, and the corner be lost.
TEST(EFastPaths, TheNarrowSpanCoversEveryEarlierBatch) {
    const SensorSize s{20, 20};
    const int x0 = 10, y0 = 10;
    const std::int64_t now = std::int64_t{1} << 41;
    enum class Feed { kDetect, kProcess, kUnchecked, kScored };
    for (const std::int64_t age : {std::int64_t{5}, kNarrow - 1001, kNarrow, 4 * kNarrow}) {
        std::vector<Event> first;
        auto add = [&](std::int64_t t, int dx, int dy) {
            first.push_back({t, static_cast<std::uint16_t>(x0 + dx), static_cast<std::uint16_t>(y0 + dy), 1});
        };
        for (int k = 0; k < 4; ++k) add(now - age, kCircle3[k].dx, kCircle3[k].dy);
        for (int k = 0; k < 5; ++k) add(now - age, kCircle4[k].dx, kCircle4[k].dy);
        for (int k = 4; k < 16; ++k) add(now - age - 1000, kCircle3[k].dx, kCircle3[k].dy);
        for (int k = 5; k < 20; ++k) add(now - age - 1000, kCircle4[k].dx, kCircle4[k].dy);
        std::sort(first.begin(), first.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
        const Event centre{now, static_cast<std::uint16_t>(x0), static_cast<std::uint16_t>(y0), 1};
        naive::EFastNaive oracle(s);
        for (const Event& e : first) oracle.process(e);
        ASSERT_TRUE(oracle.process(centre)) << "age " << age;
        for (const std::string& path : efast_code_paths())
            for (const Feed feed : {Feed::kDetect, Feed::kProcess, Feed::kUnchecked, Feed::kScored}) {
                EFast det(s);
                std::vector<std::uint8_t> flags(first.size());
                if (feed == Feed::kDetect) detect_on_path(path, det, first, flags);
                if (feed == Feed::kProcess)
                    for (const Event& e : first) det.process(e);
                if (feed == Feed::kUnchecked) detect_unchecked(det, first, flags);
                if (feed == Feed::kScored) {
                    std::vector<double> scores(first.size());
                    detect(det, first, flags, scores);
                }
                std::uint8_t got = 7;
                detect_on_path(path, det, std::span<const Event>(&centre, 1), std::span<std::uint8_t>(&got, 1));
                EXPECT_EQ(got, 1) << path << ", feed " << static_cast<int>(feed) << ", age " << age;
                const bool narrow = age + 1000 < kNarrow && feed != Feed::kUnchecked;
#ifdef EVCORNER_HAVE_AVX2_SEARCH
                EXPECT_EQ(det.times_within_narrow_span(), narrow) << path << ", age " << age;
#else
                (void)narrow;
#endif
            }
    }
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

// The radius-3 test on 32-bit times (efast_avx512::fires16_narrow); never-fired pixels
// (INT64_MIN here) as INT32_MIN, as the narrowing leaves them.
[[gnu::target(EVCORNER_AVX512_TARGET)]] bool circle16_fires_narrow(const std::int64_t* t) {
    alignas(64) std::int32_t v[16];
    for (int k = 0; k < 16; ++k) v[k] = t[k] == INT64_MIN ? INT32_MIN : static_cast<std::int32_t>(t[k]);
    return efast_avx512::fires16_narrow(_mm512_load_si512(v));
}

// The radius-4 test by pairs of lengths (efast_avx512::fires20_paired) on the same layout.
[[gnu::target(EVCORNER_AVX512_TARGET)]] bool circle20_fires_paired(const std::int64_t* t) {
    static constexpr std::int64_t kOffsets[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19};
    return efast_avx512::fires20_paired(Avx512Search::load20(t, kOffsets));
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
    vector_circle_test_matches<16, 3, 6>(circle16_fires_narrow, 9);
    vector_circle_test_matches<20, 4, 8>(circle20_fires_paired, 10);
    vector_circle_test_matches<20, 4, 8>(circle20_fires_avx512, 8);
}
#endif

}  // namespace
}  // namespace evcorner
