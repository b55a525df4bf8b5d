// Scores of eFAST and Arc* (corner_scores.hpp, docs/scores.md): they never change a binary
// decision (seeded random streams, every Arc* variant, the golden files where
// ../shared/data exists); a score exactly where there is a corner; drawn timestamp grids
// where the more corner-like pattern scores higher; and every registered detector runs
// scored through the registry's entry and the pipeline.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "arcstar_test_streams.hpp"
#include "evcorner/arcstar.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/text_reader.hpp"
#include "evcorner/naive/scores_naive.hpp"
#include "evcorner/pipeline/detect.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/scored_detector.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

// Binary flags of a fresh detector and the scored run of another: identical flags, a
// score (in [7, 15)) exactly for the corners; the per-event scored verb agrees too.
template <class D, class Make>
void expect_scores_keep_decisions(const std::vector<Event>& ev, Make make, const std::string& what) {
    D bin = make(), sc = make(), one = make();
    std::vector<std::uint8_t> f0(ev.size()), f1(ev.size());
    std::vector<double> s(ev.size());
    const std::size_t c0 = detect(bin, std::span<const Event>(ev), f0);
    const std::size_t c1 = detect(sc, std::span<const Event>(ev), f1, s);
    ASSERT_GT(c0, 0u) << what << ": no corners to compare";
    EXPECT_EQ(c0, c1) << what;
    for (std::size_t i = 0; i < ev.size(); ++i) {
        ASSERT_EQ(f0[i], f1[i]) << what << " event " << i;
        if (f1[i]) {
            ASSERT_GE(s[i], 7.0) << what << " event " << i;
            ASSERT_LT(s[i], 15.0) << what << " event " << i;
        } else {
            ASSERT_TRUE(std::isnan(s[i])) << what << " event " << i;
        }
        double s1 = 0;
        ASSERT_EQ(process_scored_unchecked(one, ev[i], s1), f0[i] != 0) << what << " event " << i;
        ASSERT_TRUE(f0[i] ? s1 == s[i] : std::isnan(s1)) << what << " event " << i;
    }
}

TEST(Scores, EFastScoresNeverChangeDecisions) {
    for (const SensorSize z : {SensorSize{64, 48}, SensorSize{240, 180}})
        for (std::uint64_t seed = 1; seed <= 4; ++seed) {
            const auto ev = test::arcstar_stream(z, 60000, seed, 40, 60000);
            expect_scores_keep_decisions<EFast>(ev, [z] { return EFast(z); }, "efast seed " + std::to_string(seed));
        }
}

TEST(Scores, ArcStarScoresNeverChangeDecisions) {
    for (int variant = 0; variant < 4; ++variant)
        for (std::uint64_t seed = 1; seed <= 3; ++seed) {
            ArcStarParams p;
            p.filter = variant != 1;
            p.minority_only = variant == 2;
            p.zero_init = variant == 3;
            const SensorSize z{64, 48};
            const auto ev = test::arcstar_stream(z, 60000, seed, 40, 60000);
            expect_scores_keep_decisions<ArcStar>(ev, [z, p] { return ArcStar(z, p); },
                                                  "arcstar variant " + std::to_string(variant) + " seed " +
                                                      std::to_string(seed));
        }
}

// A random circle of stored times at `now`: a contiguous newer run of random length over
// an older background, times from `distinct` values each (ties), 0 (never fired) where the
// draw is 0. Firing arcs of every length are common, not only by chance.
template <int N>
std::array<std::int64_t, N> random_circle(std::mt19937_64& rng, int distinct, std::int64_t now) {
    std::array<std::int64_t, N> t{};
    const int run = 1 + static_cast<int>(rng() % (N - 1));
    const int at = static_cast<int>(rng() % N);
    for (int i = 0; i < N; ++i) {
        const bool in_run = (i - at + N) % N < run;
        const std::int64_t v = static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(distinct));
        t[static_cast<std::size_t>(i)] = v == 0 ? 0 : (in_run ? now - v : now - distinct - v);
    }
    return t;
}

// The fast arc extent of one circle (corner_scores.hpp: growth, suffix maxima) against the
// definition tried plainly (naive/scores_naive.hpp): the same length and the same margin,
// bit for bit, or no firing arc for both. Random circles from few distinct times (ties),
// with never-fired pixels (0) and the event's time.
template <int N, int Lmin, int Lmax>
void expect_efast_extent_is_definition(std::uint64_t seed, int distinct) {
    std::mt19937_64 rng(seed);
    int fired = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const std::int64_t now = 1000 + static_cast<std::int64_t>(rng() % 100);
        const std::array<std::int64_t, N> t = random_circle<N>(rng, distinct, now);
        const auto want = naive::shortest_firing_arc(t, Lmin, Lmax, now);
        const detail::ArcExtent got = detail::efast_arc_extent<N, Lmin, Lmax>(t.data(), now);
        ASSERT_EQ(got.length, want ? want->length : 0) << "seed " << seed << " trial " << trial;
        if (want) {
            ++fired;
            ASSERT_EQ(got.margin, want->margin) << "seed " << seed << " trial " << trial;
        }
    }
    EXPECT_GT(fired, 1000) << "too few firing circles to compare";
}

TEST(Scores, EFastArcExtentIsTheDefinition) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed)
        for (const int distinct : {3, 8, 1000}) {
            expect_efast_extent_is_definition<16, 3, 6>(seed, distinct);
            expect_efast_extent_is_definition<20, 4, 8>(seed, distinct);
        }
}

// eFAST's score on the AVX-512 path (efast_score_avx512: the arc test's masks, masked
// reductions) against the definition written plainly, bit for bit, on pairs of random
// circles that both fire (ties, never-fired pixels). Skips where the CPU lacks AVX-512.
TEST(Scores, EFastAvx512ScoreIsTheDefinition) {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    const auto paths = efast_code_paths();
    if (std::find(paths.begin(), paths.end(), "avx512") == paths.end()) GTEST_SKIP() << "no AVX-512 on this CPU";
    std::int64_t off3[16], off4[20];
    for (int k = 0; k < 16; ++k) off3[k] = k;
    for (int k = 0; k < 20; ++k) off4[k] = 16 + k;
    for (std::uint64_t seed = 1; seed <= 3; ++seed)
        for (const int distinct : {3, 8, 1000}) {
            std::mt19937_64 rng(seed);
            int compared = 0;
            for (int trial = 0; trial < 20000; ++trial) {
                const std::int64_t now = 1000 + static_cast<std::int64_t>(rng() % 100);
                const auto c3 = random_circle<16>(rng, distinct, now);
                const auto c4 = random_circle<20>(rng, distinct, now);
                const auto want = naive::efast_score_naive(c3, c4, now);
                if (!want) continue;  // not a corner: no score to compare
                std::int64_t cells[36];
                std::copy(c3.begin(), c3.end(), cells);
                std::copy(c4.begin(), c4.end(), cells + 16);
                ASSERT_EQ(efast_score_avx512(cells, off3, off4, now), *want)
                    << "seed " << seed << " distinct " << distinct << " trial " << trial;
                ++compared;
            }
            EXPECT_GT(compared, 100) << "too few corners to compare";
        }
#else
    GTEST_SKIP() << "no AVX-512 code on this target";
#endif
}

// Arc*'s fast arc extent (doubled circle, times recorded as they join) against its growth
// written with cyclic indices (naive/scores_naive.hpp): same length and margin, bit for bit.
template <int N, int Lmin>
void expect_arcstar_extent_is_growth(std::uint64_t seed, int distinct) {
    std::mt19937_64 rng(seed);
    int with_margin = 0, without = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const std::int64_t now = 1000 + static_cast<std::int64_t>(rng() % 100);
        const std::array<std::int64_t, N> t = random_circle<N>(rng, distinct, now);
        const naive::ArcFound want = naive::arcstar_arc_naive(t, Lmin, now);
        const detail::ArcExtent got = detail::arcstar_arc_extent<N, Lmin>(t.data(), now);
        ASSERT_EQ(got.length, want.length) << "seed " << seed << " trial " << trial;
        ASSERT_EQ(got.margin, want.margin) << "seed " << seed << " trial " << trial;
        (want.margin > 0 ? with_margin : without) += 1;
    }
    EXPECT_GT(with_margin, 1000);
    EXPECT_GT(without, 1000);
}

TEST(Scores, ArcStarArcExtentIsTheGrowth) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed)
        for (const int distinct : {3, 8, 1000}) {
            expect_arcstar_extent_is_growth<16, 3>(seed, distinct);
            expect_arcstar_extent_is_growth<20, 4>(seed, distinct);
        }
}

// eFAST's scored run against the score computed plainly from its SAE after each event.
TEST(Scores, EFastScoresAreTheNaiveDefinition) {
    const SensorSize z{64, 48};
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
        const auto ev = test::arcstar_stream(z, 60000, seed, 40, 60000);
        EFast det(z);
        std::size_t corners = 0;
        for (std::size_t i = 0; i < ev.size(); ++i) {
            double s = 0;
            const bool c = process_scored_unchecked(det, ev[i], s);
            const std::int64_t* plane = det.sae().plane(ev[i].p);
            const auto cell = [&](int dx, int dy) { return plane[(ev[i].y + dy) * z.width + ev[i].x + dx]; };
            if (!c) continue;
            ++corners;
            std::array<std::int64_t, 16> c3;
            std::array<std::int64_t, 20> c4;
            for (int k = 0; k < 16; ++k) c3[static_cast<std::size_t>(k)] = cell(kCircle3[k].dx, kCircle3[k].dy);
            for (int k = 0; k < 20; ++k) c4[static_cast<std::size_t>(k)] = cell(kCircle4[k].dx, kCircle4[k].dy);
            const auto want = naive::efast_score_naive(c3, c4, Sae::stored(ev[i].t));
            ASSERT_TRUE(want.has_value()) << "seed " << seed << " event " << i;
            ASSERT_EQ(s, *want) << "seed " << seed << " event " << i;
        }
        EXPECT_GT(corners, 100u) << "seed " << seed;
    }
}

TEST(Scores, GoldenFilesUnchangedByScoredPaths) {
    EVCORNER_REQUIRE_SHARED_DATA();
    for (const auto& f : test::ecd_text_files()) {
        SCOPED_TRACE(f.golden_prefix);
        const auto ev = io::read_text_file(f.events.string());
        for (const char* name : {"efast", "arcstar"}) {
            const auto path = test::shared_data() / "golden" / (f.golden_prefix + "." + name + ".idx");
            if (!std::filesystem::exists(path)) continue;  // (slider_depth has no Arc* golden)
            const auto golden = test::read_index_file(path);
            AnyDetector d = make_detector(name, kDavis240);
            std::vector<std::uint8_t> flags(ev.size());
            std::vector<double> s(ev.size());
            std::visit([&](auto& det) {
                if constexpr (ScoredDetector<std::decay_t<decltype(det)>>) detect(det, std::span<const Event>(ev), flags, s);
            }, d);
            std::vector<std::uint64_t> got;
            for (std::size_t i = 0; i < flags.size(); ++i)
                if (flags[i]) got.push_back(i);
            EXPECT_EQ(got, golden) << name;
        }
    }
}

// A 9x9 drawn grid of SAE times around the centre (row y = -4..4, column x = -4..4): '.'
// never fired, a digit its time in ms. Fed pixel by pixel in time order, then the centre
// event at 10 ms; returns its score (NaN if not a corner).
template <class D>
double score_of_grid(const std::vector<std::string>& rows) {
    D det(SensorSize{9, 9});
    std::vector<Event> ev;
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 9; ++x)
            if (rows[static_cast<std::size_t>(y)][static_cast<std::size_t>(x)] != '.' && !(x == 4 && y == 4))
                ev.push_back({1000 * (rows[static_cast<std::size_t>(y)][static_cast<std::size_t>(x)] - '0'),
                              static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1});
    std::stable_sort(ev.begin(), ev.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
    ev.push_back({10000, 4, 4, 1});
    double s = 0;
    bool c = false;
    for (const Event& e : ev) c = process_scored_unchecked(det, e, s);
    return c ? s : kNoScore;
}

// A corner whose newest pixels fill a sector right of and below the centre: arcs of 3 and
// 4 pixels (the sharpest eFAST accepts), a quadrant (5 and 6) and 135 degrees (6 and 8);
// everything else fired long ago.
const std::vector<std::string> kSharp = {
    "111111111",
    "111111111",
    "111111111",
    "111111111",
    "111119999",
    "111119999",
    "111111991",
    "111111911",
    "111111111",
};
const std::vector<std::string> kRight = {
    "111111111",
    "111111111",
    "111111111",
    "111111111",
    "111119999",
    "111199999",
    "111199999",
    "111199999",
    "111199999",
};
const std::vector<std::string> kBlunt = {
    "111111111",
    "111111111",
    "111111111",
    "111111111",
    "111119999",
    "111199999",
    "111999999",
    "119999999",
    "199999999",
};
// kRight with the rest just 1 ms older than the corner: the same arcs, a smaller margin.
const std::vector<std::string> kRightRecentRest = {
    "888888888",
    "888888888",
    "888888888",
    "888888888",
    "888889999",
    "888899999",
    "888899999",
    "888899999",
    "888899999",
};
// A straight edge: half of each circle new (not a corner for either detector).
const std::vector<std::string> kEdge = {
    "111111111",
    "111111111",
    "111111111",
    "111111111",
    "999999999",
    "999999999",
    "999999999",
    "999999999",
    "999999999",
};

// eFAST and Arc* (the two detectors whose scores are defined here, docs/scores.md) on the
// same drawn grids: one typed test.
template <class D>
class DrawnGrids : public ::testing::Test {};
struct DetectorName {
    template <class D>
    static std::string GetName(int) {
        return std::is_same_v<D, EFast> ? "EFast" : "ArcStar";
    }
};
using ArcDetectors = ::testing::Types<EFast, ArcStar>;
TYPED_TEST_SUITE(DrawnGrids, ArcDetectors, DetectorName);

TYPED_TEST(DrawnGrids, RankCornerLikeness) {
    using D = TypeParam;
    const double sharp = score_of_grid<D>(kSharp), right = score_of_grid<D>(kRight), blunt = score_of_grid<D>(kBlunt);
    ASSERT_FALSE(std::isnan(sharp));
    ASSERT_FALSE(std::isnan(right));
    ASSERT_FALSE(std::isnan(blunt));
    EXPECT_GT(sharp, right);
    EXPECT_GT(right, blunt);
    const double recent = score_of_grid<D>(kRightRecentRest);
    ASSERT_FALSE(std::isnan(recent));
    EXPECT_EQ(std::floor(recent), std::floor(right)) << "same arcs, same integer part";
    EXPECT_GT(right, recent) << "a larger timestamp margin ranks higher";
    EXPECT_TRUE(std::isnan(score_of_grid<D>(kEdge))) << "an edge is no corner and has no score";
}

TEST(Scores, EveryRegisteredDetectorHasAScore) {
    for (const DetectorInfo& d : detector_infos()) EXPECT_TRUE(d.has_score) << d.name;
}

TEST(Scores, PipelineWithScoreForEveryDetector) {
    // The bundled sample, --with-score through the library's pipeline: one score per
    // corner, the same corners as without.
    const std::string sample = (test::bundled_data() / "ecd/shapes_translation/events.txt").string();
    for (const DetectorInfo& d : detector_infos()) {
        SCOPED_TRACE(std::string(d.name));
        pipeline::DetectOptions o;
        o.detector.name = std::string(d.name);
        std::vector<std::vector<Event>> corners;
        for (bool with : {false, true}) {
            o.with_score = with;
            const auto reader = io::open_event_reader(sample);
            pipeline::CollectSink sink;
            pipeline::DetectSink* sinks[] = {&sink};
            pipeline::run_detect(*reader, o, sinks);
            if (with) {
                ASSERT_EQ(sink.scores.size(), sink.corners.size());
                for (double s : sink.scores) ASSERT_FALSE(std::isnan(s));
            }
            corners.push_back(sink.corners);
        }
        EXPECT_EQ(corners[0], corners[1]);
    }
}

}  // namespace
}  // namespace evcorner
