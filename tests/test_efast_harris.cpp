// The eFAST -> Harris cascade: Harris's split into update and score, the cascade against
// its plain oracle on seeded random streams at several sensor sizes, drawn grids, one
// polarity plane, and on every real recording: the cascade's corners are exactly the
// events both EFast and Harris, run separately, call corners.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "blob_stream.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/efast_harris.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/naive/efast_harris_naive.hpp"
#include "test_util.hpp"

namespace evcorner {
namespace {

// Events around drifting filled squares (edges and corners move with them), many equal
// timestamps, a share of uniform clutter (borders included), mostly one polarity so that
// windows fill up.
std::vector<Event> random_stream(SensorSize s, std::size_t n, std::uint64_t seed, int polarity = -1) {
    return test::blob_stream(s, n, seed, {.blobs = 3, .spread = 2.5, .clutter = 0.07, .round = true}, test::tie_steps,
                             [polarity](std::mt19937_64& rng) {
                                 return polarity >= 0 ? polarity : static_cast<int>(rng() % 4 == 0);
                             });
}

bool same_score(double fast, double naive) {
    if (std::isnan(fast) || std::isnan(naive)) return std::isnan(fast) && std::isnan(naive);
    return std::abs(fast - naive) <= 1e-9 * std::max(1.0, std::abs(naive));
}

std::string name_of(SensorSize s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

// ---------------------------------------------------------------- Harris's two halves

TEST(HarrisSplit, UpdateThenScoreLatestEqualsProcess) {
    std::size_t scored = 0;
    for (const SensorSize s : {SensorSize{9, 9}, SensorSize{40, 30}, SensorSize{240, 180}})
        for (const HarrisParams params : {HarrisParams{}, HarrisParams{5, 7, 0.05, 1.0}, HarrisParams{11, 40, 0.06, 10.0}}) {
            const auto events = random_stream(s, 8000, 31u * s.width + params.nl);
            Harris whole(s, params), split(s, params);
            for (std::size_t i = 0; i < events.size(); ++i) {
                const bool c = whole.process(events[i]);
                split.update_unchecked(events[i]);
                const double sc = split.score_latest(events[i]);
                ASSERT_TRUE(same_score(sc, whole.last_score())) << name_of(s) << " event " << i;
                ASSERT_EQ(c, sc > params.threshold) << name_of(s) << " event " << i;
                // score_latest() changes nothing: asking again gives the same.
                ASSERT_TRUE(same_score(split.score_latest(events[i]), sc));
                scored += !std::isnan(sc);
            }
            EXPECT_TRUE(std::isnan(split.last_score())) << "update_unchecked() and score_latest() leave last_score()";
        }
    EXPECT_GT(scored, 10000u);
}

// ---------------------------------------------------------------- against the oracle

struct OracleCase {
    SensorSize size;
    std::size_t events;
};
const OracleCase kCases[] = {{{8, 8}, 3000},       {{9, 9}, 3000},        {{17, 11}, 5000},  {{64, 64}, 20000},
                             {{240, 180}, 30000}, {{346, 260}, 20000}, {{1280, 720}, 30000}};

TEST(EFastHarrisOracle, SameCornersAndScoresEventForEvent) {
    std::size_t total = 0, candidates = 0, corners = 0, rejected = 0;
    for (const OracleCase& c : kCases)
        for (const HarrisParams params : {HarrisParams{}, HarrisParams{7, 20, 0.04, 2.0}, HarrisParams{11, 40, 0.06, 6.0}}) {
            SCOPED_TRACE(name_of(c.size) + " window " + std::to_string(params.window));
            const auto events = random_stream(c.size, c.events, 7919u * c.size.width + params.window);
            EFastHarris fast(c.size, params);
            naive::EFastHarrisNaive oracle(c.size, params.window, params.nl, params.k, params.threshold);
            naive::EFastNaive efast_only(c.size);
            std::size_t mismatches = 0;
            for (std::size_t i = 0; i < events.size(); ++i) {
                const bool a = fast.process(events[i]);
                const bool b = oracle.process(events[i]);
                const bool e = efast_only.process(events[i]);
                if ((a != b || !same_score(fast.last_score(), oracle.last_score())) && ++mismatches <= 3)
                    ADD_FAILURE() << "event " << i << ": fast " << a << " " << fast.last_score() << ", oracle " << b
                                  << " " << oracle.last_score();
                candidates += e;
                corners += b;
                rejected += e && !b;
            }
            EXPECT_EQ(mismatches, 0u);
            total += events.size();
        }
    // The comparison is not empty: eFAST candidates, cascade corners, and candidates
    // that Harris turned down.
    EXPECT_GT(candidates, 1000u);
    EXPECT_GT(corners, 200u);
    EXPECT_GT(rejected, 200u);
    std::printf("oracle: %zu events, %zu eFAST candidates, %zu cascade corners, %zu rejected by Harris\n", total,
                candidates, corners, rejected);
}

// The batch detect() (eFAST on its fastest path, blocks) equals process() event by event,
// flags and scores, whatever the split of the stream into calls.
TEST(EFastHarrisOracle, BatchDetectEqualsProcess) {
    std::printf("eFAST code path: %s\n", efast_code_path());
    for (const SensorSize s : {SensorSize{32, 24}, SensorSize{240, 180}, SensorSize{640, 480}}) {
        const auto events = random_stream(s, 20000, 5u * s.height);
        EFastHarris one(s);
        std::vector<std::uint8_t> want(events.size());
        std::vector<double> want_score(events.size());
        for (std::size_t i = 0; i < events.size(); ++i) {
            want[i] = one.process(events[i]);
            want_score[i] = one.last_score();
        }
        for (const std::size_t chunk : {std::size_t{1}, std::size_t{777}, std::size_t{2048}, events.size()}) {
            EFastHarris batch(s), scored(s);
            std::vector<std::uint8_t> got(events.size()), got2(events.size());
            std::vector<double> score(events.size());
            std::size_t corners = 0, corners2 = 0;
            for (std::size_t b = 0; b < events.size(); b += chunk) {
                const std::size_t n = std::min(chunk, events.size() - b);
                const std::span<const Event> part(events.data() + b, n);
                corners += detect(batch, part, std::span<std::uint8_t>(got.data() + b, n));
                corners2 += detect(scored, part, std::span<std::uint8_t>(got2.data() + b, n),
                                   std::span<double>(score.data() + b, n));
                ASSERT_TRUE(same_score(scored.last_score(), want_score[b + n - 1]));
                ASSERT_TRUE(same_score(batch.last_score(), want_score[b + n - 1]));
            }
            EXPECT_EQ(got, want) << name_of(s) << " chunk " << chunk;
            EXPECT_EQ(got2, want) << name_of(s) << " chunk " << chunk;
            EXPECT_EQ(corners, static_cast<std::size_t>(std::count(want.begin(), want.end(), 1)));
            EXPECT_EQ(corners2, corners);
            for (std::size_t i = 0; i < events.size(); ++i)
                ASSERT_TRUE(same_score(score[i], want_score[i])) << name_of(s) << " event " << i;
        }
        EXPECT_GT(std::count(want.begin(), want.end(), 1), 0) << name_of(s);
    }
}

// Every eFAST code path this CPU runs gives the cascade the same flags.
TEST(EFastHarrisOracle, EveryEFastCodePathAgrees) {
    // detect() uses the chosen path; the per-event process() uses the portable one, and
    // the test above holds them equal. Here: the cascade's flags equal eFAST's flags on
    // each path ANDed with Harris's.
    const SensorSize s{240, 180};
    const auto events = random_stream(s, 30000, 99);
    Harris harris(s);
    std::vector<std::uint8_t> h(events.size());
    detect(harris, std::span<const Event>(events), h);
    EFastHarris cascade(s);
    std::vector<std::uint8_t> c(events.size());
    detect(cascade, std::span<const Event>(events), c);
    for (const std::string& path : efast_code_paths()) {
        EFast e(s);
        std::vector<std::uint8_t> f(events.size());
        detect_on_path(path, e, events, f);
        for (std::size_t i = 0; i < events.size(); ++i) ASSERT_EQ(c[i], f[i] && h[i]) << path << " event " << i;
    }
}

TEST(EFastHarrisOracle, OnePlaneForOnePolarity) {
    for (const SensorSize s : {SensorSize{64, 64}, SensorSize{240, 180}})
        for (const int p : {0, 1}) {
            const auto events = random_stream(s, 20000, 17u * s.width + p, p);
            EFastHarris one(s, {}, 1);
            naive::EFastHarrisNaive oracle(s);
            std::size_t corners = 0;
            for (std::size_t i = 0; i < events.size(); ++i) {
                const bool a = one.process(events[i]);
                ASSERT_EQ(a, oracle.process(events[i])) << name_of(s) << " p " << p << " event " << i;
                ASSERT_TRUE(same_score(one.last_score(), oracle.last_score()));
                corners += a;
            }
            EXPECT_GT(corners, 0u);
        }
    EXPECT_EQ(EFastHarris({240, 180}, {}, 1).memory_bytes() * 2, EFastHarris({240, 180}).memory_bytes());
}

// ---------------------------------------------------------------- drawn grids

// On a 9x9 sensor: first every pixel at t = 1, then the lower-right 5x5 quadrant whose
// corner is the centre (4, 4), the centre last, at `t_quadrant`. With t_quadrant = 2 the
// quadrant is strictly newer: eFAST's circles see an arc of 5 (r = 3) and 6 (r = 4) newest
// pixels, and Harris's 25 newest pixels are the quadrant (score 14.4458).
EFastHarris& draw_quadrant(EFastHarris& det, std::int64_t t_quadrant) {
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 9; ++x) det.process({1, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 0});
    for (int y = 8; y >= 4; --y)
        for (int x = 8; x >= 4; --x)
            det.process({t_quadrant, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 0});
    return det;
}

TEST(EFastHarrisDrawn, OutsideCornerBothAgree) {
    EFastHarris det({9, 9});
    draw_quadrant(det, 2);
    EXPECT_NEAR(det.last_score(), 14.4458, 1e-4);
    // The centre event again: still the newest quadrant, a corner.
    EXPECT_TRUE(det.process({2, 4, 4, 0}));
}

TEST(EFastHarrisDrawn, HarrisBelowItsThresholdTurnsDownAnEFastCorner) {
    EFastHarris det({9, 9}, HarrisParams{9, 25, 0.04, 20.0});
    EXPECT_FALSE(draw_quadrant(det, 2).process({2, 4, 4, 0}));
    EXPECT_NEAR(det.last_score(), 14.4458, 1e-4) << "a candidate's score is kept even when Harris turns it down";
}

TEST(EFastHarrisDrawn, TiedTimestampsEFastSaysNoHarrisSaysYes) {
    // All at t = 1: eFAST's circles are all ties (no arc fires), while Harris breaks ties
    // by arrival and lights the quadrant.
    EFastHarris det({9, 9});
    EXPECT_FALSE(draw_quadrant(det, 1).process({1, 4, 4, 0}));
    EXPECT_TRUE(std::isnan(det.last_score())) << "no Harris score for an event eFAST rejects";
    Harris alone({9, 9});
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 9; ++x) alone.process({1, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 0});
    for (int y = 8; y >= 4; --y)
        for (int x = 8; x >= 4; --x) alone.process({1, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 0});
    EXPECT_TRUE(alone.process({1, 4, 4, 0}));
}

TEST(EFastHarrisDrawn, TooFewPixelsForHarrisIsNoCorner) {
    // The quadrant again, but pixel (0, 0) never fires and Harris wants nl = 81: its
    // window has only 80 fired pixels, so Harris gives no score; eFAST (which never reads
    // (0, 0)) still calls the centre a corner.
    EFastHarris det({9, 9}, HarrisParams{9, 81, 0.04, 8.0});
    EFast efast({9, 9});
    bool efast_says = false;
    auto fire = [&](std::int64_t t, int x, int y) {
        const Event e{t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 0};
        efast_says = efast.process(e);
        return det.process(e);
    };
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 9; ++x)
            if (x != 0 || y != 0) fire(1, x, y);
    for (int y = 8; y >= 4; --y)
        for (int x = 8; x >= 4; --x) fire(2, x, y);
    EXPECT_FALSE(fire(2, 4, 4));
    EXPECT_TRUE(efast_says);
    EXPECT_TRUE(std::isnan(det.last_score()));
}

TEST(EFastHarrisDrawn, OtherPolarityIsIndependent) {
    EFastHarris det({9, 9});
    draw_quadrant(det, 2);
    EXPECT_FALSE(det.process({3, 4, 4, 1})) << "nothing of polarity 1 has fired around it";
    EXPECT_TRUE(det.process({3, 4, 4, 0}));
}

TEST(EFastHarris, ParametersAndSensorAreChecked) {
    EXPECT_THROW(EFastHarris({0, 180}), std::invalid_argument);
    EXPECT_THROW(EFastHarris({240, 180}, HarrisParams{8, 25, 0.04, 8}), std::invalid_argument);
    EXPECT_THROW(EFastHarris({240, 180}, HarrisParams{9, 82, 0.04, 8}), std::invalid_argument);
    EXPECT_THROW(EFastHarris({240, 180}, HarrisParams{9, 25, 0.04, NAN}), std::invalid_argument);
    EXPECT_THROW(EFastHarris({240, 180}).process({0, 240, 0, 0}), InvalidEvent);
    EXPECT_EQ(EFastHarris::state_bytes({240, 180}), EFast::state_bytes({240, 180}) + Harris::state_bytes({240, 180}));
    EXPECT_EQ(EFastHarris({240, 180}).memory_bytes(), EFastHarris::state_bytes({240, 180}));
}

// ---------------------------------------------------------------- real recordings

struct RealFile {
    std::string name;
    test::fs::path path;
};

std::vector<RealFile> real_files() {
    std::vector<RealFile> files;
    for (const auto& f : test::ecd_text_files()) files.push_back({f.golden_prefix, f.events});
    const auto data = test::shared_data() / "real";
    for (const char* rec : {"IMU_rotDisk", "IMU_translBoxes"})
        files.push_back({rec, data / "davis240c-imu-pyaedattools" / (std::string(rec) + ".aedat")});
    std::vector<test::fs::path> dvs;
    for (const auto& entry : test::fs::directory_iterator(data / "dvs128-walking-ouyang"))
        if (entry.path().extension() == ".aedat") dvs.push_back(entry.path());
    std::sort(dvs.begin(), dvs.end());
    for (const auto& p : dvs) files.push_back({p.stem().string(), p});
    return files;
}

TEST(EFastHarrisReal, CornersAreTheIntersectionOfEFastAndHarris) {
    EVCORNER_REQUIRE_SHARED_DATA();
    const auto files = real_files();
    ASSERT_EQ(files.size(), 9u + 2u + 11u);
    std::size_t all_c = 0, all_e = 0, all_h = 0;
    for (const RealFile& f : files) {
        SCOPED_TRACE(f.name);
        const auto reader = io::open_event_reader(f.path.string());
        const auto events = io::read_all_events(*reader);
        const SensorSize s = reader->sensor().value_or(kDavis240);
        ASSERT_FALSE(events.empty());
        EFast efast(s);
        Harris harris(s);
        EFastHarris cascade(s);
        std::vector<std::uint8_t> e(events.size()), h(events.size()), c(events.size());
        std::vector<double> hs(events.size()), cs(events.size());
        const std::size_t ne = detect(efast, std::span<const Event>(events), e);
        const std::size_t nh = detect(harris, std::span<const Event>(events), h, hs);
        const std::size_t nc = detect(cascade, std::span<const Event>(events), c, cs);
        std::size_t both = 0, bad = 0;
        for (std::size_t i = 0; i < events.size(); ++i) {
            both += e[i] && h[i];
            if (c[i] != (e[i] && h[i]) && ++bad <= 3) ADD_FAILURE() << "event " << i;
            // The score: Harris's where eFAST said corner, else none.
            if (!same_score(cs[i], e[i] ? hs[i] : kNoScore) && ++bad <= 3) ADD_FAILURE() << "score of event " << i;
        }
        EXPECT_EQ(bad, 0u);
        EXPECT_EQ(nc, both);
        std::printf("%-45s %4dx%-4d %8zu events: efast %6zu, harris %6zu, cascade %6zu\n", f.name.c_str(), s.width,
                    s.height, events.size(), ne, nh, nc);
        all_c += nc;
        all_e += ne;
        all_h += nh;
    }
    // A real refinement: fewer corners than either detector, but not none.
    EXPECT_GT(all_c, 0u);
    EXPECT_LT(all_c, all_e);
    EXPECT_LT(all_c, all_h);
}

}  // namespace
}  // namespace evcorner
