// Asynchronous NMS (nms.hpp): drawn cases (two corner events 1 px and 1 us apart: one
// survives; far apart in space or time, or of other polarities: both; the tie rule),
// against the plain oracle (naive/nms_naive.hpp) on seeded random corner streams, with
// both rules; Suppressed<D> over threads identical to one thread; the pipeline's --nms.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "arcstar_test_streams.hpp"
#include "evcorner/arcstar.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/naive/nms_naive.hpp"
#include "evcorner/nms.hpp"
#include "evcorner/parallel_detect.hpp"
#include "evcorner/pipeline/detect.hpp"
#include "evcorner/registry.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

const SensorSize kS{32, 24};

NmsParams params(NmsRule rule, int radius = 2, std::int64_t time_us = 1000) {
    NmsParams p;
    p.rule = rule;
    p.radius = radius;
    p.time_us = time_us;
    return p;
}

Event ev(std::int64_t t, int x, int y, int p = 1) {
    return {t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), static_cast<std::uint8_t>(p)};
}

class NmsRules : public testing::TestWithParam<NmsRule> {};

TEST_P(NmsRules, NeighboursOnePixelAndOneMicrosecondApartKeepOne) {
    AsyncNms nms(kS, params(GetParam()));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10), 12.5));
    EXPECT_FALSE(nms.keep(ev(101, 11, 10), 11.0)) << "a weaker neighbour 1 px, 1 us later is suppressed";
}

TEST_P(NmsRules, StrongerLaterCornerIsKeptToo) {
    // Causal: the first was passed on already; the stronger second is kept as well.
    AsyncNms nms(kS, params(GetParam()));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10), 9.0));
    EXPECT_TRUE(nms.keep(ev(101, 11, 10), 11.0));
}

TEST_P(NmsRules, TieRuleTheFirstOfEqualsIsKept) {
    // window: an equal earlier score suppresses. decay: an equal *decayed* score does: at
    // the same time the first of equals is kept; 1 us later the earlier one has decayed
    // below, and the later one is kept too.
    AsyncNms nms(kS, params(GetParam()));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10), 10.0));
    EXPECT_FALSE(nms.keep(ev(100, 11, 11), 10.0)) << "equal score, same time: the earlier corner suppresses";
    EXPECT_EQ(nms.keep(ev(101, 12, 12), 10.0), GetParam() == NmsRule::decay) << "equal score, 1 us later";
    EXPECT_FALSE(nms.keep(ev(101, 12, 12), 10.0)) << "same pixel, same time, same score";
}

TEST_P(NmsRules, FarApartInSpaceBothSurvive) {
    AsyncNms nms(kS, params(GetParam(), 2));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10), 12.0));
    EXPECT_TRUE(nms.keep(ev(101, 13, 10), 8.0)) << "3 px away, radius 2";
    EXPECT_TRUE(nms.keep(ev(102, 10, 13), 8.0));
    EXPECT_FALSE(nms.keep(ev(103, 12, 12), 8.0)) << "the corner of the square is inside";
}

TEST_P(NmsRules, FarApartInTimeBothSurvive) {
    AsyncNms nms(kS, params(GetParam(), 2, 1000));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10), 12.0));
    // window: 1001 us later is outside; decay: 12 e^-(50000/1000) is far below 8.
    EXPECT_TRUE(nms.keep(ev(GetParam() == NmsRule::window ? 1101 : 50100, 11, 10), 8.0));
}

TEST_P(NmsRules, PolaritiesAreSeparate) {
    AsyncNms nms(kS, params(GetParam()));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10, 1), 12.0));
    EXPECT_TRUE(nms.keep(ev(101, 11, 10, 0), 8.0));
}

TEST_P(NmsRules, SuppressedCornersStillCount) {
    // Every corner is recorded: a suppressed corner still suppresses the weaker ones after it.
    AsyncNms nms(kS, params(GetParam(), 1));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10), 12.0));
    EXPECT_FALSE(nms.keep(ev(101, 11, 10), 11.0));
    EXPECT_FALSE(nms.keep(ev(102, 12, 10), 10.0)) << "2 px from the first: suppressed by the second";
}

INSTANTIATE_TEST_SUITE_P(BothRules, NmsRules, testing::Values(NmsRule::window, NmsRule::decay),
                         [](const auto& i) { return std::string(nms_rule_name(i.param)); });

TEST(Nms, WindowEdgeIsInclusive) {
    AsyncNms nms(kS, params(NmsRule::window, 2, 1000));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10), 12.0));
    EXPECT_FALSE(nms.keep(ev(1100, 11, 10), 8.0)) << "dt = time_us is inside the window";
}

TEST(Nms, DecayedScoreDecides) {
    // 12 e^(-dt/1000) against 8: equal at dt = 1000 ln 1.5 = 405.5 us.
    AsyncNms a(kS, params(NmsRule::decay, 2, 1000)), b(kS, params(NmsRule::decay, 2, 1000));
    EXPECT_TRUE(a.keep(ev(100, 10, 10), 12.0));
    EXPECT_FALSE(a.keep(ev(500, 11, 10), 8.0));
    EXPECT_TRUE(b.keep(ev(100, 10, 10), 12.0));
    EXPECT_TRUE(b.keep(ev(510, 11, 10), 8.0));
}

TEST(Nms, NegativeScoresDecayDownwards) {
    AsyncNms nms(kS, params(NmsRule::decay, 2, 1000));
    EXPECT_TRUE(nms.keep(ev(100, 10, 10), -1.0));
    EXPECT_TRUE(nms.keep(ev(1100, 11, 10), -2.0)) << "-1 decays to -e, below -2";
}

TEST(Nms, ParametersChecked) {
    EXPECT_THROW(AsyncNms(kS, params(NmsRule::window, -1)), std::invalid_argument);
    EXPECT_THROW(AsyncNms(kS, params(NmsRule::window, 2, 0)), std::invalid_argument);
    EXPECT_THROW(parse_nms_rule("max"), std::invalid_argument);
    EXPECT_EQ(parse_nms_rule("decay"), NmsRule::decay);
    AsyncNms n(kS, params(NmsRule::window, 2));
    EXPECT_THROW(n.use_code_path("sse9"), std::invalid_argument);
}

TEST(Nms, MatchesTheOracleOnRandomCornerStreams) {
    // Every code path of the window test this CPU runs; radii whose rows fill a vector
    // exactly, leave a remainder, or take several vectors (7 = 4 + 3, 15 = 8 + 7 cells).
    const std::vector<std::string> paths = AsyncNms::code_paths();
    ASSERT_FALSE(paths.empty());
    EXPECT_EQ(paths.back(), "portable");
    RecordProperty("nms_code_paths", static_cast<int>(paths.size()));
    for (const std::string& path : paths)
    for (const NmsRule rule : {NmsRule::window, NmsRule::decay})
        for (const int radius : {0, 1, 2, 3, 4, 7})
            for (std::uint64_t seed = 1; seed <= 5; ++seed) {
                SCOPED_TRACE(testing::Message() << path << " " << nms_rule_name(rule) << " radius " << radius
                                                << " seed " << seed);
                std::mt19937_64 rng(seed);
                const NmsParams p = params(rule, radius, 1 + static_cast<std::int64_t>(rng() % 300));
                AsyncNms fast(kS, p);
                fast.use_code_path(path);
                EXPECT_STREQ(fast.code_path(), path.c_str());
                naive::NmsNaive oracle(p);
                std::int64_t t = static_cast<std::int64_t>(rng() % 1000) - 500;
                std::size_t kept = 0, dropped = 0;
                for (int i = 0; i < 3000; ++i) {
                    t += static_cast<std::int64_t>(rng() % 4);                 // ties in time
                    if (rng() % 50 == 0) t -= static_cast<std::int64_t>(rng() % 5);  // a little out of order
                    const Event e = ev(t, static_cast<int>(rng() % 32), static_cast<int>(rng() % 24),
                                       static_cast<int>(rng() & 1));
                    // Few distinct scores (ties), now and then negative or NaN.
                    double s = static_cast<double>(rng() % 8) + (rng() % 3 == 0 ? 0.25 : 0.0);
                    if (rng() % 40 == 0) s = -s;
                    if (rng() % 100 == 0) s = kNoScore;
                    const bool a = fast.keep(e, s), b = oracle.keep(e, s);
                    ASSERT_EQ(a, b) << "corner " << i;
                    (a ? kept : dropped) += 1;
                }
                if (radius > 0) {
                    EXPECT_GT(kept, 0u);
                    EXPECT_GT(dropped, 0u);
                }
            }
}

// Suppressed<D> split over threads (the halo grown by the NMS radius): the same flags as
// one thread, for both rules and several radii.
template <class D, class MakeD>
void expect_threads_identical(const std::vector<Event>& events, SensorSize s, int det_radius, bool by_polarity,
                              MakeD make_d) {
    for (const NmsRule rule : {NmsRule::window, NmsRule::decay})
        for (const int r : {1, 3}) {
            SCOPED_TRACE(testing::Message() << nms_rule_name(rule) << " radius " << r);
            const NmsParams p = params(rule, r, 3000);
            auto make = [&](SensorSize z, int planes) { return Suppressed<D>(make_d(z, planes), p, planes); };
            Suppressed<D> one = make(s, 2);
            std::vector<std::uint8_t> want(events.size()), raw(events.size());
            const std::size_t kept = detect(one, std::span<const Event>(events), want);
            D plain = make_d(s, 2);
            const std::size_t all = detect(plain, std::span<const Event>(events), raw);
            ASSERT_GT(kept, 0u);
            ASSERT_LT(kept, all) << "NMS suppressed nothing: the comparison is weak";
            for (std::size_t i = 0; i < events.size(); ++i) ASSERT_LE(want[i], raw[i]) << "NMS only removes";
            for (const int threads : {2, 3}) {
                ParallelDetector<Suppressed<D>> par(s, threads, Locality(det_radius + r, by_polarity), make, 2);
                std::vector<std::uint8_t> got(events.size());
                std::size_t c = 0;
                for (std::size_t at = 0; at < events.size(); at += 20000) {
                    const std::size_t n = std::min<std::size_t>(20000, events.size() - at);
                    c += par.detect(std::span<const Event>(events).subspan(at, n), std::span<std::uint8_t>(got).subspan(at, n));
                }
                EXPECT_EQ(c, kept) << threads << " threads";
                for (std::size_t i = 0; i < events.size(); ++i) ASSERT_EQ(got[i], want[i]) << threads << " threads, event " << i;
            }
        }
}

TEST(Nms, ThreadsIdenticalToOneThreadEFast) {
    const SensorSize s{240, 180};
    const auto events = test::arcstar_stream(s, 120000, 7, 20, 10000);
    expect_threads_identical<EFast>(events, s, kCircleMargin, true, [](SensorSize z, int planes) { return EFast(z, planes); });
}

TEST(Nms, ThreadsIdenticalToOneThreadArcStar) {
    const SensorSize s{240, 180};
    const auto events = test::arcstar_stream(s, 120000, 8, 20, 60000);
    expect_threads_identical<ArcStar>(events, s, kCircleMargin, false,
                                      [](SensorSize z, int planes) { return ArcStar(z, {}, planes); });
}

TEST(Nms, ThreadsIdenticalToOneThreadHarris) {
    const SensorSize s{120, 90};
    const auto events = test::arcstar_stream(s, 40000, 9, 20, 10000);
    expect_threads_identical<Harris>(events, s, HarrisParams{}.window / 2, true,
                                     [](SensorSize z, int planes) { return Harris(z, {}, planes); });
}

// The batch loop of Suppressed<D> (the detector's loop and the stage's filter, a chunk of
// kNmsChunk events at a time, corners gathered a block at a time and prefetched ahead)
// decides as the stage does event by event, on every code path, in one call and in
// batches of odd sizes that cut chunks anywhere; with and without the caller's scores.
TEST(Nms, BatchLoopEqualsEventByEventOnEveryPath) {
    const SensorSize s{240, 180};
    const auto events = test::arcstar_stream(s, 3 * kNmsChunk + 777, 11, 20, 10000);
    for (const NmsRule rule : {NmsRule::window, NmsRule::decay})
        for (const int radius : {2, 5}) {
            const NmsParams p = params(rule, radius, 3000);
            Suppressed<EFast> one(EFast(s), p);
            std::vector<std::uint8_t> want(events.size());
            std::vector<double> want_score(events.size());
            std::size_t kept = 0;
            for (std::size_t i = 0; i < events.size(); ++i)
                kept += want[i] = one.process_scored_unchecked(events[i], want_score[i]);
            std::size_t raw = 0;
            {
                EFast plain(s);
                std::vector<std::uint8_t> f(events.size());
                raw = detect(plain, std::span<const Event>(events), f);
            }
            ASSERT_GT(kept, 0u);
            ASSERT_LT(kept, raw) << "NMS suppressed nothing: the comparison is weak";
            for (const std::string& path : AsyncNms::code_paths())
                for (const std::size_t batch : {events.size(), std::size_t{1000}, std::size_t{4097}}) {
                    SCOPED_TRACE(testing::Message() << path << " " << nms_rule_name(rule) << " radius " << radius
                                                    << " batch " << batch);
                    Suppressed<EFast> a(EFast(s), p), b(EFast(s), p);
                    a.nms().use_code_path(path);
                    b.nms().use_code_path(path);
                    std::vector<std::uint8_t> fa(events.size()), fb(events.size());
                    std::vector<double> sa(events.size());
                    std::size_t ca = 0, cb = 0;
                    for (std::size_t at = 0; at < events.size(); at += batch) {
                        const std::size_t n = std::min(batch, events.size() - at);
                        const auto ev = std::span<const Event>(events).subspan(at, n);
                        ca += detect(a, ev, std::span<std::uint8_t>(fa).subspan(at, n),
                                     std::span<double>(sa).subspan(at, n));
                        cb += detect(b, ev, std::span<std::uint8_t>(fb).subspan(at, n));
                    }
                    EXPECT_EQ(ca, kept);
                    EXPECT_EQ(cb, kept);
                    for (std::size_t i = 0; i < events.size(); ++i) {
                        ASSERT_EQ(fa[i], want[i]) << "event " << i;
                        ASSERT_EQ(fb[i], want[i]) << "event " << i;
                        if (want[i]) {
                            ASSERT_EQ(sa[i], want_score[i]) << "event " << i;
                        }
                    }
                }
        }
}

TEST(Nms, PipelineNmsEveryDetectorAndThreads) {
    const std::string sample = (test::bundled_data() / "ecd/shapes_translation/events.txt").string();
    for (const DetectorInfo& d : detector_infos()) {
        SCOPED_TRACE(std::string(d.name));
        std::vector<std::vector<Event>> runs;
        std::size_t plain = 0;
        for (const int threads : {0, 1, 2, 3}) {  // 0: no NMS
            if (threads > 1 && !d.local()) continue;
            pipeline::DetectOptions o;
            o.detector.name = std::string(d.name);
            o.threads = std::max(1, threads);
            o.batch = 4096;
            if (threads > 0) o.nms = NmsParams{};
            const auto reader = io::open_event_reader(sample);
            pipeline::CollectSink sink;
            pipeline::DetectSink* sinks[] = {&sink};
            const auto sum = pipeline::run_detect(*reader, o, sinks);
            EXPECT_EQ(sum.corners, sink.corners.size());
            if (threads == 0) {
                plain = sink.corners.size();
                continue;
            }
            runs.push_back(sink.corners);
        }
        ASSERT_FALSE(runs.empty());
        EXPECT_LT(runs[0].size(), plain) << "NMS removes corners on the sample";
        EXPECT_GT(runs[0].size(), 0u);
        for (std::size_t k = 1; k < runs.size(); ++k) EXPECT_EQ(runs[k], runs[0]) << "threads " << k + 1;
    }
}

TEST(Nms, PipelineChecksNmsParameters) {
    pipeline::DetectOptions o;
    o.detector.name = "efast";
    o.nms = params(NmsRule::window, 99);
    EXPECT_THROW(pipeline::check_detect_options(o), std::invalid_argument);
}

}  // namespace
}  // namespace evcorner
