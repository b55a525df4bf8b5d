// eFAST on small drawn timestamp grids. Each grid is a 9x9 window of one polarity's
// SAE around the event in its centre ('.' = never fired, 'E' = the event itself);
// the cells are fed as events in time order, then the centre event is processed.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "evcorner/efast.hpp"
#include "evcorner/naive/efast_naive.hpp"
#include "grid_test_util.hpp"

namespace evcorner {
namespace {

using test::Cell;
using test::parse_grid;

struct Outcome {
    bool fast;
    bool naive;
};

// Feeds the grid (polarity p) and then the event 'E' (polarity ep, time 1000) to both
// the fast detector and the oracle; optional extra cells of the other polarity first.
Outcome run_grid(const std::vector<std::string>& rows, SensorSize size, int x0, int y0, int p = 1,
                 int ep = 1, const std::vector<std::string>& other = {}) {
    EFast fast(size);
    naive::EFastNaive oracle(size);
    int ex = -1, ey = -1;
    auto feed = [&](const std::vector<Cell>& cells, int pol) {
        for (const Cell& c : cells) {
            const Event e{c.t, static_cast<std::uint16_t>(c.x), static_cast<std::uint16_t>(c.y),
                          static_cast<std::uint8_t>(pol)};
            fast.process(e);
            oracle.process(e);
        }
    };
    if (!other.empty()) {
        int ox, oy;
        feed(parse_grid(other, x0, y0, ox, oy), 1 - p);
    }
    feed(parse_grid(rows, x0, y0, ex, ey), p);
    EXPECT_GE(ex, 0) << "grid has no 'E'";
    const Event e{1000, static_cast<std::uint16_t>(ex), static_cast<std::uint16_t>(ey),
                  static_cast<std::uint8_t>(ep)};
    return {fast.process(e), oracle.process(e)};
}

const SensorSize kSmall{20, 20};

// A 90-degree corner moving down-right: the newest pixels fill the quadrant below and
// right of the event. Radius 3 sees an arc of 3, radius 4 an arc of 4.
const std::vector<std::string> kRightAngle = {
    "1 1 1 1 1 1 1 1 1",
    "1 1 1 1 1 1 1 1 1",
    "1 1 1 1 1 1 1 1 1",
    "1 1 1 1 1 1 1 1 1",
    "1 1 1 1 E 1 1 1 1",
    "1 1 1 1 1 9 9 9 9",
    "1 1 1 1 1 9 9 9 9",
    "1 1 1 1 1 9 9 9 9",
    "1 1 1 1 1 9 9 9 9",
};

TEST(EFastGrid, RightAngleCornerFires) {
    const auto r = run_grid(kRightAngle, kSmall, 6, 6);
    EXPECT_TRUE(r.fast);
    EXPECT_TRUE(r.naive);
}

// A straight edge: the lower half is newer. Radius 3 sees 7 new pixels, more than 6.
TEST(EFastGrid, StraightEdgeDoesNotFire) {
    const std::vector<std::string> edge = {
        "1 1 1 1 1 1 1 1 1",
        "1 1 1 1 1 1 1 1 1",
        "1 1 1 1 1 1 1 1 1",
        "1 1 1 1 1 1 1 1 1",
        "1 1 1 1 E 1 1 1 1",
        "9 9 9 9 9 9 9 9 9",
        "9 9 9 9 9 9 9 9 9",
        "9 9 9 9 9 9 9 9 9",
        "9 9 9 9 9 9 9 9 9",
    };
    const auto r = run_grid(edge, kSmall, 6, 6);
    EXPECT_FALSE(r.fast);
    EXPECT_FALSE(r.naive);
}

// The right-angle corner, but one radius-3 pixel on the far side is as new as the
// arc: ties with the rest do not fire.
TEST(EFastGrid, ArcTiedWithTheRestDoesNotFire) {
    std::vector<std::string> tied = kRightAngle;
    tied[1] = "1 1 1 9 1 1 1 1 1";  // (-1,-3) on the radius-3 circle
    const auto r = run_grid(tied, kSmall, 6, 6);
    EXPECT_FALSE(r.fast);
    EXPECT_FALSE(r.naive);
}

// The same, but the outside pixel is one tick older than the arc: it fires again.
TEST(EFastGrid, ArcNewerByOneTickFires) {
    std::vector<std::string> almost = kRightAngle;
    almost[1] = "1 1 1 8 1 1 1 1 1";
    const auto r = run_grid(almost, kSmall, 6, 6);
    EXPECT_TRUE(r.fast);
    EXPECT_TRUE(r.naive);
}

// An acute corner: only 3 pixels of the radius-4 circle are new, fewer than 4.
TEST(EFastGrid, TooNarrowOnRadius4DoesNotFire) {
    const std::vector<std::string> narrow = {
        "1 1 1 1 1 1 1 1 1",
        "1 1 1 1 1 1 1 1 1",
        "1 1 1 1 1 1 1 1 1",
        "1 1 1 1 1 1 1 1 1",
        "1 1 1 1 E 1 1 1 1",
        "1 1 1 1 1 1 9 1 1",
        "1 1 1 1 1 9 9 1 1",
        "1 1 1 1 1 9 9 9 1",
        "1 1 1 1 1 9 9 1 1",
    };
    const auto r = run_grid(narrow, kSmall, 6, 6);
    EXPECT_FALSE(r.fast);
    EXPECT_FALSE(r.naive);
}

// Pixels that never fired are older than every event: a cold start where only the
// corner's quadrant has fired still makes a corner.
TEST(EFastGrid, NeverFiredPixelsCountAsOldest) {
    const std::vector<std::string> cold = {
        ". . . . . . . . .",
        ". . . . . . . . .",
        ". . . . . . . . .",
        ". . . . . . . . .",
        ". . . . E . . . .",
        ". . . . . 9 9 9 9",
        ". . . . . 9 9 9 9",
        ". . . . . 9 9 9 9",
        ". . . . . 9 9 9 9",
    };
    const auto r = run_grid(cold, kSmall, 6, 6);
    EXPECT_TRUE(r.fast);
    EXPECT_TRUE(r.naive);
}

// The very first events of a stream: nothing around has fired, all circle pixels tie.
TEST(EFastGrid, FirstEventsOfAColdStartAreNotCorners) {
    EFast d(kSmall);
    EXPECT_FALSE(d.process({0, 10, 10, 1}));
    EXPECT_FALSE(d.process({0, 10, 10, 0}));
    EXPECT_FALSE(d.process({1, 11, 10, 1}));
    // One new pixel on each circle is an arc of 1: too short.
    EXPECT_FALSE(d.process({2, 10, 13, 1}));
    EXPECT_FALSE(d.process({3, 10, 10, 1}));
}

// The SAE of each polarity is separate: the corner drawn in ON does not make an OFF
// event a corner, and OFF clutter does not spoil an ON corner.
TEST(EFastGrid, PolaritiesAreKeptApart) {
    auto r = run_grid(kRightAngle, kSmall, 6, 6, /*p=*/1, /*ep=*/0);
    EXPECT_FALSE(r.fast);
    EXPECT_FALSE(r.naive);

    const std::vector<std::string> clutter(9, "50 50 50 50 50 50 50 50 50");
    r = run_grid(kRightAngle, kSmall, 6, 6, /*p=*/1, /*ep=*/1, clutter);
    EXPECT_TRUE(r.fast);
    EXPECT_TRUE(r.naive);
}

// Events within 4 pixels of the border are never corners; at exactly 4 they may be.
TEST(EFastGrid, BorderEvents) {
    const SensorSize s{9, 9};  // one interior pixel: (4, 4)
    EXPECT_TRUE(run_grid(kRightAngle, s, 0, 0).fast);

    const SensorSize wide{13, 13};
    EXPECT_TRUE(run_grid(kRightAngle, wide, 4, 4).fast);   // event at (8, 8) = width-5
}

TEST(EFastGrid, BorderRowsAndColumnsNeverFire) {
    // Draw the corner so that the event lands on x = 3, y = 3, x = width-4, y = height-4.
    const SensorSize s{20, 20};
    for (const auto& [ex, ey] : {std::pair{3, 10}, {10, 3}, {16, 10}, {10, 16}}) {
        EFast d(s);
        naive::EFastNaive o(s);
        std::int64_t t = 0;
        for (int dy = 1; dy <= 4; ++dy)
            for (int dx = 1; dx <= 4; ++dx) {
                const int x = ex + dx, y = ey + dy;
                if (x >= s.width || y >= s.height) continue;
                const Event e{++t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1};
                d.process(e);
                o.process(e);
            }
        const Event e{100, static_cast<std::uint16_t>(ex), static_cast<std::uint16_t>(ey), 1};
        EXPECT_FALSE(d.process(e)) << ex << "," << ey;
        EXPECT_FALSE(o.process(e)) << ex << "," << ey;
    }
}

// The event's own timestamp is written first, for border events too.
TEST(EFastGrid, BorderEventsStillUpdateTheSurface) {
    EFast d({20, 20});
    d.process({7, 0, 0, 1});
    EXPECT_EQ(d.sae().at(1, 0, 0), 7);
    EXPECT_EQ(d.sae().at(0, 0, 0), Sae::kNever);
}

}  // namespace
}  // namespace evcorner
