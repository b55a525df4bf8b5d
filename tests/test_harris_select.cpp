// The newest-nl selection of the adaptive Harris detector (harris_select.hpp), every code
// path this CPU runs, against a full sort of the window: drawn windows of random sequence
// numbers with recent, octave-spread and never-fired cells, streams far past 2^31 and 2^32
// events (31-bit ages capped, the exact fallback), every nl, several window sizes; and the
// AVX2 9x9 score against the portable one.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdint>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/harris.hpp"
#include "evcorner/harris_score.hpp"
#include "evcorner/harris_select.hpp"

namespace evcorner {
namespace {

constexpr std::size_t kStride = 19;  // cells between rows of the drawn windows (> 15)

// The oracle: light the nl nonzero cells with the largest sequence numbers (a full sort);
// false when fewer than nl are nonzero.
bool select_by_sorting(const std::vector<std::uint64_t>& cells, int w, int nl, std::vector<std::uint16_t>& rows) {
    std::vector<std::pair<std::uint64_t, int>> fired;
    for (int r = 0; r < w; ++r)
        for (int c = 0; c < w; ++c)
            if (const std::uint64_t s = cells[static_cast<std::size_t>(r) * kStride + c]; s != 0) fired.push_back({s, r * 16 + c});
    if (static_cast<int>(fired.size()) < nl) return false;
    std::sort(fired.begin(), fired.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    rows.assign(static_cast<std::size_t>(w), 0);
    for (int i = 0; i < nl; ++i) rows[static_cast<std::size_t>(fired[i].second / 16)] |= static_cast<std::uint16_t>(1u << (fired[i].second % 16));
    return true;
}

// A w x w window (rows kStride apart) of distinct sequence numbers <= now: ages drawn per
// `kind` (0: all within the last 300 arrivals; 1: log-uniform over the whole history;
// 2: half recent, half older than 2^31 arrivals), `never` the share of cells that never fired.
std::vector<std::uint64_t> draw_window(std::mt19937_64& rng, int w, std::uint64_t now, int kind, double never) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<std::uint64_t> cells(kStride * 15 + 15, 0);
    std::set<std::uint64_t> used;
    for (int r = 0; r < w; ++r)
        for (int c = 0; c < w; ++c) {
            if (unit(rng) < never) continue;
            for (int attempt = 0; attempt < 50; ++attempt) {  // a short history runs out of numbers
                std::uint64_t age = 0;
                if (kind == 0 || (kind == 2 && unit(rng) < 0.5)) {
                    age = rng() % 300;
                } else if (kind == 1) {
                    age = static_cast<std::uint64_t>(std::exp2(unit(rng) * std::log2(static_cast<double>(now))));
                } else {
                    age = (std::uint64_t{1} << 31) - 3 + rng() % 8;  // around the 31-bit cap
                }
                if (age >= now) continue;  // sequence numbers are >= 1
                const std::uint64_t seq = now - age;
                if (used.insert(seq).second) {
                    cells[static_cast<std::size_t>(r) * kStride + c] = seq;
                    break;
                }
            }
        }
    return cells;
}

TEST(HarrisSelect, EveryPathLightsTheNewestCellsOfDrawnWindows) {
    const std::uint64_t nows[] = {1,
                                  90,
                                  5000,
                                  1'000'000,
                                  (std::uint64_t{1} << 31) - 2,
                                  (std::uint64_t{1} << 31) - 1,
                                  std::uint64_t{1} << 31,
                                  (std::uint64_t{1} << 32) + 5,
                                  std::uint64_t{1} << 40,
                                  (std::uint64_t{1} << 55) + 7};  // the bucket code ranks keys seq << 8: seq < 2^56
    std::mt19937_64 rng(2026);
    std::size_t compared = 0, lit = 0, too_few = 0;
    for (const std::string& name : harris_code_paths()) {
        const HarrisPath path = harris_path_named(name);
        for (const int w : {5, 9, 11, 15})
            for (const std::uint64_t now : nows)
                for (int kind = 0; kind < 3; ++kind)
                    for (const double never : {0.0, 0.3, 0.8})
                        for (int trial = 0; trial < 6; ++trial) {
                            if (kind == 2 && now < (std::uint64_t{1} << 31) + 300) continue;
                            const auto cells = draw_window(rng, w, now, kind, never);
                            for (int nl = 1; nl <= w * w; nl += (w == 9 ? 1 : 7)) {
                                std::vector<std::uint16_t> expected;
                                const bool ok = select_by_sorting(cells, w, nl, expected);
                                std::uint16_t rows[15];
                                std::fill(rows, rows + 15, 0xFFFF);
                                const bool got = harris_select_newest(path, cells.data(), kStride, w, now, nl, rows);
                                ASSERT_EQ(got, ok) << name << " w " << w << " now " << now << " kind " << kind << " nl " << nl;
                                ++compared;
                                if (!ok) {
                                    ++too_few;
                                    continue;
                                }
                                ++lit;
                                for (int r = 0; r < w; ++r)
                                    EXPECT_EQ(rows[r] & ((1u << w) - 1), expected[static_cast<std::size_t>(r)])
                                        << name << " w " << w << " now " << now << " kind " << kind << " never " << never
                                        << " nl " << nl << " row " << r;
                            }
                        }
    }
    EXPECT_GT(lit, 10000u);
    EXPECT_GT(too_few, 1000u);
    RecordProperty("compared", static_cast<int>(compared));
}

TEST(HarrisScorer, Avx2ScoreEqualsThePortableOneBitForBit) {
    const auto paths = harris_code_paths();
    if (std::find(paths.begin(), paths.end(), "avx2") == paths.end()) GTEST_SKIP() << "this CPU has no AVX2";
    std::mt19937_64 rng(9);
    for (const double k : {0.04, 0.0, 0.15}) {
        const HarrisScorer scorer(9, k);
        for (int i = 0; i < 200000; ++i) {
            std::uint16_t rows[9];
            for (auto& r : rows) r = static_cast<std::uint16_t>(rng() & (i % 3 == 0 ? 0xFFFFu : 511u));  // high bits ignored
            const double portable = scorer.score(rows), avx2 = scorer.score9_avx2(rows);
            ASSERT_EQ(std::memcmp(&portable, &avx2, sizeof portable), 0) << "patch " << i << ": " << portable << " " << avx2;
        }
    }
}

TEST(HarrisSelect, PathsAreNamedAndCheckedAgainstTheCpu) {
    const auto paths = harris_code_paths();
    ASSERT_FALSE(paths.empty());
    EXPECT_EQ(paths.front(), harris_code_path());
    EXPECT_EQ(paths.back(), "portable");
    EXPECT_EQ(std::set<std::string>(paths.begin(), paths.end()).size(), paths.size());
    for (const std::string& name : paths) EXPECT_EQ(harris_path_name(harris_path_named(name)), name);
    EXPECT_THROW(harris_path_named("sse9"), std::invalid_argument);
    EXPECT_EQ(Harris(SensorSize{40, 30}).code_path(), harris_default_path());
}

}  // namespace
}  // namespace evcorner
