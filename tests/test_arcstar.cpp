// Arc* on drawn timestamp grids (an outside corner, an inside corner, a straight edge, bar
// ends, ties), the 50 ms filter's behaviour (first event of a pixel, a burst under 50 ms,
// a polarity flip, the window's edge, the zero-initialised variant), the parameters and
// bad events, and the batch loops against the oracle (the delayed radius-4 test, the
// AVX-512 test's 32-bit range across batches). Every grid outcome is also asserted for the
// oracle.

#include <gtest/gtest.h>

#include <algorithm>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "evcorner/arcstar.hpp"
#include "evcorner/cpu_paths.hpp"
#include "evcorner/naive/arcstar_naive.hpp"
#include "grid_test_util.hpp"

namespace evcorner {
namespace {

using test::Cell;
using test::parse_grid;

// Feeds the grid (first events of their pixels: all pass the filter) then 'E' at t = 1000;
// returns the fast detector's answer after checking that the oracle gives the same.
bool grid_is_corner(const std::vector<std::string>& rows, const ArcStarParams& params = {}) {
    const SensorSize size{20, 20};
    ArcStar fast(size, params);
    naive::ArcStarNaive oracle(size, params);
    const Event e = test::feed_grid(rows, fast, oracle, 1);
    const bool c = fast.process(e);
    EXPECT_EQ(c, oracle.process(e));
    return c;
}

// Newest pixels (9) in the quadrant below and right of the event, older ones (2) elsewhere:
// radius 3 sees an arc of 3 newest pixels, radius 4 one of 4. Minority arcs: a corner.
const std::vector<std::string> kOutsideCorner = {
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 E 2 2 2 2",
    "2 2 2 2 2 9 9 9 9",
    "2 2 2 2 2 9 9 9 9",
    "2 2 2 2 2 9 9 9 9",
    "2 2 2 2 2 9 9 9 9",
};

// The complement: the older quadrant is the only one below-right: radius 3 has a newest
// arc of 13 = N - Lmin pixels, radius 4 one of 16 = N - Lmin: majority arcs.
const std::vector<std::string> kInsideCorner = {
    "9 9 9 9 9 9 9 9 9",
    "9 9 9 9 9 9 9 9 9",
    "9 9 9 9 9 9 9 9 9",
    "9 9 9 9 9 9 9 9 9",
    "9 9 9 9 E 9 9 9 9",
    "9 9 9 9 9 2 2 2 2",
    "9 9 9 9 9 2 2 2 2",
    "9 9 9 9 9 2 2 2 2",
    "9 9 9 9 9 2 2 2 2",
};

// A horizontal edge: the rows below the event are newer. Radius 3: 7 newest pixels,
// neither a minority (<= 6) nor a majority (>= 10) arc.
const std::vector<std::string> kStraightEdge = {
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 E 2 2 2 2",
    "9 9 9 9 9 9 9 9 9",
    "9 9 9 9 9 9 9 9 9",
    "9 9 9 9 9 9 9 9 9",
    "9 9 9 9 9 9 9 9 9",
};

// The end of a 5-pixel-wide bar coming from below: 5 newest pixels on each circle.
const std::vector<std::string> kWideBarEnd = {
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 E 2 2 2 2",
    "2 2 9 9 9 9 9 2 2",
    "2 2 9 9 9 9 9 2 2",
    "2 2 9 9 9 9 9 2 2",
    "2 2 9 9 9 9 9 2 2",
};

// A 3-pixel-wide bar end: 3 newest pixels on radius 3 (an arc), but only 3 on radius 4,
// where the forced growth to Lmin = 4 takes an old pixel: seg drops to the old value, every
// other pixel ties with it and grows the arc to the whole circle (20): not a corner.
const std::vector<std::string> kNarrowBarEnd = {
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 2 2 2 2 2",
    "2 2 2 2 E 2 2 2 2",
    "2 2 2 9 9 9 2 2 2",
    "2 2 2 9 9 9 2 2 2",
    "2 2 2 9 9 9 2 2 2",
    "2 2 2 9 9 9 2 2 2",
};

std::vector<std::string> replace(std::vector<std::string> rows, char from, char to) {
    for (auto& r : rows) std::replace(r.begin(), r.end(), from, to);
    return rows;
}

TEST(ArcStarGrid, OutsideCornerIsACorner) {
    EXPECT_TRUE(grid_is_corner(kOutsideCorner));
    EXPECT_TRUE(grid_is_corner(kOutsideCorner, {.minority_only = true}));
}

TEST(ArcStarGrid, InsideCornerIsACornerOnlyThroughTheMajorityArcs) {
    EXPECT_TRUE(grid_is_corner(kInsideCorner));
    EXPECT_FALSE(grid_is_corner(kInsideCorner, {.minority_only = true}));
}

TEST(ArcStarGrid, StraightEdgeIsNotACorner) {
    EXPECT_FALSE(grid_is_corner(kStraightEdge));
    EXPECT_FALSE(grid_is_corner(kStraightEdge, {.minority_only = true}));
}

TEST(ArcStarGrid, BarEnds) {
    EXPECT_TRUE(grid_is_corner(kWideBarEnd));
    EXPECT_FALSE(grid_is_corner(kNarrowBarEnd));
}

TEST(ArcStarGrid, Ties) {
    // The newest quadrant tied with the rest: one value everywhere, every pixel grows the
    // arc, size N on both circles: not a corner.
    EXPECT_FALSE(grid_is_corner(replace(kOutsideCorner, '9', '2')));
    // Newer by one tick is enough.
    EXPECT_TRUE(grid_is_corner(replace(kOutsideCorner, '9', '3')));
    // Never-fired pixels are the oldest of all: the corner over an unlit background.
    EXPECT_TRUE(grid_is_corner(replace(kOutsideCorner, '2', '.')));
}

// ---- the batch loop: a corner's radius-4 test runs one passing event late

// The AVX-512 batch loop (ArcStar::View::run_moved) tests a candidate's radius-4 circle
// after the next passing event's radius-3 test, and must do it before that event's write
// (the other loops test it at once; they are held to the same stream). Here the next
// passing event after the corner E lands on E's radius-4 circle (dx = -4, dy = 0), same
// polarity, 60 ms later (so that it passes the filter), newer than everything: seen by E's
// radius-4 test, it would break E's arc (not a corner). A
// rejected event (E's pixel again, 1 us later) comes in between. Every loop, the whole
// stream and the stream cut right after E (the candidate then waits for the next span),
// must give the oracle's flags, E a corner.
template <class Run>
void expect_batch_equals_oracle(const char* path, Run run) {
    const SensorSize size{20, 20};
    int ex = -1, ey = -1;
    std::vector<Event> events;
    for (const test::Cell& c : parse_grid(kOutsideCorner, 5, 5, ex, ey))
        events.push_back({c.t, static_cast<std::uint16_t>(c.x), static_cast<std::uint16_t>(c.y), 1});
    const std::size_t corner = events.size();
    const auto at = [](int x, int y, std::int64_t t) {
        return Event{t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1};
    };
    events.push_back(at(ex, ey, 1000));      // E: a corner
    events.push_back(at(ex, ey, 1001));      // rejected by the filter (1 us after E)
    events.push_back(at(ex - 4, ey, 60000));  // on E's radius-4 circle: passes, newest of all
    events.push_back(at(ex + 1, ey, 60001));
    naive::ArcStarNaive oracle(size);
    std::vector<std::uint8_t> want;
    for (const Event& e : events) want.push_back(oracle.process(e));
    ASSERT_EQ(want[corner], 1);
    ASSERT_EQ(want[corner + 1], 0);
    for (const std::size_t cut : {events.size(), corner + 1}) {
        ArcStar det(size);
        std::vector<std::uint8_t> got(events.size(), 7);
        const std::span<const Event> all(events);
        const std::span<std::uint8_t> flags(got);
        const std::size_t n = run(det, all.first(cut), flags.first(cut)) +
                              run(det, all.subspan(cut), flags.subspan(cut));
        EXPECT_EQ(got, want) << path << ", cut after " << cut;
        EXPECT_EQ(n, static_cast<std::size_t>(std::count(want.begin(), want.end(), 1))) << path;
    }
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
[[gnu::target("avx2"), gnu::flatten]] std::size_t run_avx2(ArcStar& det, std::span<const Event> events,
                                                           std::span<std::uint8_t> flags) {
    return det.run_unchecked<Avx2Search>(events, flags);
}
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] std::size_t run_avx512(ArcStar& det,
                                                                              std::span<const Event> events,
                                                                              std::span<std::uint8_t> flags) {
    return det.run_unchecked<Avx512Search>(events, flags);
}
#endif

TEST(ArcStarBatch, RadiusFourTestSeesTheSaeOfItsOwnEvent) {
    expect_batch_equals_oracle("portable", [](ArcStar& d, std::span<const Event> e, std::span<std::uint8_t> f) {
        return d.run_unchecked<ScalarSearch>(e, f);
    });
    expect_batch_equals_oracle("detect()", [](ArcStar& d, std::span<const Event> e, std::span<std::uint8_t> f) {
        return detect(d, e, f);
    });
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    if (cpu_runs_avx2()) expect_batch_equals_oracle("avx2", run_avx2);
    if (cpu_runs_avx512()) expect_batch_equals_oracle("avx512", run_avx512);
    else GTEST_LOG_(INFO) << "no AVX-512 on this CPU: that loop not run";
#endif
}

// ---- the AVX-512 test's range across batches

// The AVX-512 test holds a circle as 32-bit ages relative to its event, exact while every
// fired pixel lies at most kRange - kAhead - 1 us before the event (and at most kAhead
// after it; checked per circle, else the portable test); a loop that left the check out
// for batches whose own span is small would be wrong here, as would one off by one at the
// edge (a variant that decided it per batch from every time the detector took was
// measured and dropped: docs/arcstar.md). On a 9x9 sensor (only the centre is off the
// border) pixel 0 of the radius-3 circle fires at t = 0 in a first batch; pixels 14 and 15
// of that circle, an arc of four pixels of the radius-4 circle and then the centre fire
// `last - 6 .. last` in a second. Exactly, pixels 14, 15, 0 form a separating arc of 3
// (pixel 0 is newer than the never-fired rest): a corner. Were pixel 0 taken as never
// fired, or its age wrapped or saturated, the radius-3 arc would be the whole circle: no
// corner. With last = kRange - kAhead - 1 pixel 0 is in range; with kRange - kAhead,
// 2^30, 2^31 + 5 and 2^32 + 5 (an age whose low 32 bits are in range) it is not, though
// the second batch's own span is.
std::vector<Event> range_edge_stream(std::int64_t last) {
    const auto on = [](const Offset& o, std::int64_t t) {
        return Event{t, static_cast<std::uint16_t>(4 + o.dx), static_cast<std::uint16_t>(4 + o.dy), 1};
    };
    std::vector<Event> events{on(kCircle3[0], 0)};
    events.push_back(on(kCircle3[14], last - 6));
    events.push_back(on(kCircle3[15], last - 5));
    for (int k = 0; k < 4; ++k) events.push_back(on(kCircle4[static_cast<std::size_t>(k)], last - 4 + k));
    events.push_back(on(Offset{0, 0}, last));
    return events;
}

template <class First, class Second>
void expect_range_edges_exact(const char* path, First first, Second second) {
    const SensorSize size{9, 9};
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    constexpr std::int64_t kEdge = ArcStarAvx512::kRange - ArcStarAvx512::kAhead;
#else
    constexpr std::int64_t kEdge = (std::int64_t{1} << 30) - (std::int64_t{1} << 20);
#endif
    for (const std::int64_t last : {kEdge - 1, kEdge, std::int64_t{1} << 30, (std::int64_t{1} << 31) + 5,
                                    (std::int64_t{1} << 32) + 5}) {
        const std::vector<Event> events = range_edge_stream(last);
        naive::ArcStarNaive oracle(size);
        std::vector<std::uint8_t> want;
        for (const Event& e : events) want.push_back(oracle.process(e));
        ASSERT_EQ(want.back(), 1) << last;
        ArcStar det(size);
        std::vector<std::uint8_t> got(events.size(), 7);
        const std::span<const Event> all(events);
        const std::span<std::uint8_t> flags(got);
        first(det, all.first(1), flags.first(1));
        second(det, all.subspan(1), flags.subspan(1));
        EXPECT_EQ(got, want) << path << ", last event at " << last;
    }
}

TEST(ArcStarBatch, RelativeTimesExactAcrossBatchesAtTheRangeEdge) {
    const auto portable = [](ArcStar& d, std::span<const Event> e, std::span<std::uint8_t> f) {
        return d.run_unchecked<ScalarSearch>(e, f);
    };
    const auto one_by_one = [](ArcStar& d, std::span<const Event> e, std::span<std::uint8_t> f) {
        for (std::size_t i = 0; i < e.size(); ++i) f[i] = static_cast<std::uint8_t>(d.process(e[i]));
        return std::size_t{0};
    };
    const auto whole = [](ArcStar& d, std::span<const Event> e, std::span<std::uint8_t> f) { return detect(d, e, f); };
    expect_range_edges_exact("portable", portable, portable);
    expect_range_edges_exact("detect()", whole, whole);
    expect_range_edges_exact("process() then detect()", one_by_one, whole);
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    if (cpu_runs_avx512()) {
        expect_range_edges_exact("avx512", run_avx512, run_avx512);
        expect_range_edges_exact("process() then avx512", one_by_one, run_avx512);
        expect_range_edges_exact("portable then avx512", portable, run_avx512);
    } else {
        GTEST_LOG_(INFO) << "no AVX-512 on this CPU: that loop not run";
    }
#endif
}

// First events of their pixels pass the filter at the earliest times too (stored 1 and 2,
// below the window, so "never fired" must be told apart from an old time there), in the
// batch loops (a variant of the AVX-512 loop that folded the never-fired test into the
// window test for batches above the window was measured and dropped: docs/arcstar.md).
TEST(ArcStarBatch, FirstEventsPassAtTheEarliestTimes) {
    const SensorSize size{9, 9};
    const std::vector<Event> events{{Sae::kMinTime, 1, 1, 1}, {Sae::kMinTime + 1, 2, 1, 0}};
    const auto check = [&](const char* path, auto run) {
        ArcStar det(size);
        std::vector<std::uint8_t> flags(events.size());
        run(det, std::span<const Event>(events), std::span<std::uint8_t>(flags));
        EXPECT_EQ(det.sae().at(1, 1, 1), Sae::kMinTime) << path;
        EXPECT_EQ(det.sae().at(0, 2, 1), Sae::kMinTime + 1) << path;
    };
    check("detect()", [](ArcStar& d, std::span<const Event> e, std::span<std::uint8_t> f) { return detect(d, e, f); });
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    if (cpu_runs_avx512()) check("avx512", run_avx512);
#endif
}

// ---- the filter

const SensorSize kSensor{30, 30};
Event ev(std::int64_t t, int x, int y, int p) {
    return {t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), static_cast<std::uint8_t>(p)};
}

TEST(ArcStarFilter, FirstEventOfAPixelPasses) {
    ArcStar det(kSensor);
    det.process(ev(5, 10, 10, 1));
    EXPECT_EQ(det.sae().at(1, 10, 10), 5);
    EXPECT_EQ(det.latest(1, 10, 10), 5);
    // The other polarity's first event at the same pixel, 1 us later, passes too.
    det.process(ev(6, 10, 10, 0));
    EXPECT_EQ(det.sae().at(0, 10, 10), 6);
}

TEST(ArcStarFilter, BurstUnder50msPassesOnlyItsFirstEvent) {
    ArcStar det(kSensor);
    for (std::int64_t t = 100000; t <= 300000; t += 10000) {
        det.process(ev(t, 10, 10, 1));
        EXPECT_EQ(det.latest(1, 10, 10), t);            // the latest time follows every event
        EXPECT_EQ(det.sae().at(1, 10, 10), 100000);     // the filtered SAE keeps the first
    }
    // Exactly 50 ms after the latest event is still too soon (strict).
    det.process(ev(350000, 10, 10, 1));
    EXPECT_EQ(det.sae().at(1, 10, 10), 100000);
    // More than 50 ms after the latest one passes.
    det.process(ev(400001, 10, 10, 1));
    EXPECT_EQ(det.sae().at(1, 10, 10), 400001);
}

TEST(ArcStarFilter, PolarityFlipPasses) {
    ArcStar det(kSensor);
    det.process(ev(1000, 10, 10, 1));   // ON, passes (first)
    det.process(ev(11000, 10, 10, 0));  // OFF, passes (first of its polarity)
    det.process(ev(21000, 10, 10, 1));  // ON 20 ms after ON, but OFF fired since: passes
    EXPECT_EQ(det.sae().at(1, 10, 10), 21000);
    det.process(ev(31000, 10, 10, 1));  // ON again, no OFF since: rejected
    EXPECT_EQ(det.sae().at(1, 10, 10), 21000);
    EXPECT_EQ(det.latest(1, 10, 10), 31000);
}

TEST(ArcStarFilter, PixelsAreFilteredApart) {
    ArcStar det(kSensor);
    det.process(ev(1000, 10, 10, 1));
    det.process(ev(2000, 11, 10, 1));  // a neighbour's first event passes
    EXPECT_EQ(det.sae().at(1, 11, 10), 2000);
}

TEST(ArcStarFilter, RejectedEventIsNotACornerAndLeavesTheSaeAlone) {
    // An outside corner drawn on the filtered SAE, then the centre pixel fires twice: its
    // first event is a corner, the second (1 us later, rejected) is not.
    ArcStar det({20, 20});
    int ex = -1, ey = -1;
    for (const Cell& c : parse_grid(kOutsideCorner, 5, 5, ex, ey))
        det.process(ev(c.t, c.x, c.y, 1));
    EXPECT_TRUE(det.process(ev(1000, ex, ey, 1)));
    EXPECT_FALSE(det.process(ev(1001, ex, ey, 1)));
    EXPECT_EQ(det.sae().at(1, ex, ey), 1000);
    // Without the filter the second is a corner too.
    ArcStar unfiltered({20, 20}, {.filter = false});
    for (const Cell& c : parse_grid(kOutsideCorner, 5, 5, ex, ey))
        unfiltered.process(ev(c.t, c.x, c.y, 1));
    EXPECT_TRUE(unfiltered.process(ev(1000, ex, ey, 1)));
    EXPECT_TRUE(unfiltered.process(ev(1001, ex, ey, 1)));
}

TEST(ArcStarFilter, ZeroInitialisedVariantRejectsFirstEventsInTheFirstWindow) {
    ArcStar never(kSensor), zero(kSensor, {.zero_init = true});
    for (ArcStar* d : {&never, &zero}) {
        d->process(ev(30000, 10, 10, 1));   // before 50 ms
        d->process(ev(50001, 12, 10, 1));   // just after
    }
    EXPECT_EQ(never.sae().at(1, 10, 10), 30000);
    EXPECT_EQ(zero.sae().at(1, 10, 10), Sae::kNever);
    EXPECT_EQ(zero.latest(1, 10, 10), 30000);
    EXPECT_EQ(never.sae().at(1, 12, 10), 50001);
    EXPECT_EQ(zero.sae().at(1, 12, 10), 50001);
}

TEST(ArcStarFilter, WindowIsAParameter) {
    ArcStar det(kSensor, {.filter_us = 100});
    det.process(ev(1000, 10, 10, 1));
    det.process(ev(1100, 10, 10, 1));  // 100 us: rejected
    EXPECT_EQ(det.sae().at(1, 10, 10), 1000);
    det.process(ev(1201, 10, 10, 1));  // 101 us after the latest: passes
    EXPECT_EQ(det.sae().at(1, 10, 10), 1201);
}

TEST(ArcStarFilter, BorderEventsAreFilteredAndWrittenButNeverCorners) {
    ArcStar det(kSensor, {.filter = false});
    for (int x : {0, 3, 26, 29})
        for (int y : {0, 3, 15, 26, 29}) {
            EXPECT_FALSE(det.process(ev(100, x, y, 0)));
            EXPECT_EQ(det.sae().at(0, x, y), 100);
        }
}

// ---- parameters, bad events, memory

TEST(ArcStarParams, OutOfRangeIsRejectedWithItsName) {
    try {
        ArcStar det(kSensor, {.filter_us = -1});
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("filter_us"), std::string::npos) << e.what();
    }
    EXPECT_THROW(ArcStar(kSensor, {.filter_us = ArcStar::kMaxFilterUs + 1}), std::invalid_argument);
    EXPECT_NO_THROW(ArcStar(kSensor, {.filter_us = ArcStar::kMaxFilterUs}));
    EXPECT_THROW(ArcStar(SensorSize{0, 10}), std::invalid_argument);
    EXPECT_THROW(ArcStar(SensorSize{10, 70000}), std::invalid_argument);
}

TEST(ArcStarEvents, BadEventsThrowAndChangeNothing) {
    ArcStar det(kSensor);
    det.process(ev(1000, 10, 10, 1));
    for (const Event& bad : {ev(2000, 30, 10, 1), ev(2000, 10, 30, 1), ev(2000, 10, 10, 2),
                             ev(Sae::kMaxTime + 1, 10, 10, 1), ev(Sae::kMinTime - 1, 10, 10, 1)}) {
        EXPECT_THROW(det.process(bad), InvalidEvent);
        std::vector<std::uint8_t> flags(2);
        const std::vector<Event> batch{ev(900000, 10, 10, 1), bad};
        EXPECT_THROW(detect(det, std::span<const Event>(batch), flags), InvalidEvent);
    }
    // Nothing was recorded: not even the good first event of the rejected batch.
    EXPECT_EQ(det.latest(1, 10, 10), 1000);
    EXPECT_EQ(det.sae().at(1, 10, 10), 1000);
}

TEST(ArcStarMemory, StateBytesMatchTheAllocation) {
    for (SensorSize s : {SensorSize{240, 180}, SensorSize{17, 13}, SensorSize{1280, 720}}) {
        ArcStar det(s);
        EXPECT_EQ(det.memory_bytes(), ArcStar::state_bytes(s));
        EXPECT_EQ(ArcStar::state_bytes(s), 32u * static_cast<std::uint64_t>(s.pixels()));
    }
}

}  // namespace
}  // namespace evcorner
