// The circles' geometry: counts, distinctness, distance from the centre, symmetry,
// and the cyclic order (neighbours are adjacent pixels).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "evcorner/circle.hpp"

namespace evcorner {
namespace {

template <std::size_t N>
void expect_circle(const std::array<Offset, N>& c, int radius) {
    std::set<std::pair<int, int>> seen;
    for (const Offset& o : c) {
        EXPECT_TRUE(seen.insert({o.dx, o.dy}).second) << "duplicate (" << o.dx << "," << o.dy << ")";
        // Bresenham circle: every pixel within half a pixel of the true radius.
        const double r = std::hypot(o.dx, o.dy);
        EXPECT_LT(std::abs(r - radius), 0.5 + 1e-9) << "(" << o.dx << "," << o.dy << ")";
        EXPECT_LE(std::max(std::abs(o.dx), std::abs(o.dy)), kCircleMargin);
    }
    // Symmetric under x and y mirroring and under transposition.
    for (const Offset& o : c) {
        EXPECT_TRUE(seen.count({-o.dx, o.dy})) << "x-mirror of (" << o.dx << "," << o.dy << ")";
        EXPECT_TRUE(seen.count({o.dx, -o.dy})) << "y-mirror of (" << o.dx << "," << o.dy << ")";
        EXPECT_TRUE(seen.count({o.dy, o.dx})) << "transpose of (" << o.dx << "," << o.dy << ")";
    }
    // Cyclic order: consecutive pixels (and the last with the first) are 8-neighbours.
    for (std::size_t k = 0; k < N; ++k) {
        const Offset& a = c[k];
        const Offset& b = c[(k + 1) % N];
        EXPECT_LE(std::max(std::abs(a.dx - b.dx), std::abs(a.dy - b.dy)), 1) << "between " << k << " and " << k + 1;
    }
    // One turn, in one direction: the angle grows monotonically modulo 2 pi.
    double turned = 0;
    for (std::size_t k = 0; k < N; ++k) {
        const Offset& a = c[k];
        const Offset& b = c[(k + 1) % N];
        double d = std::atan2(b.dy, b.dx) - std::atan2(a.dy, a.dx);
        if (d > M_PI) d -= 2 * M_PI;
        if (d < -M_PI) d += 2 * M_PI;
        EXPECT_LT(d, 0) << "order reverses at " << k;
        turned += d;
    }
    EXPECT_NEAR(std::abs(turned), 2 * M_PI, 1e-9);
}

TEST(Circle, Radius3Has16DistinctSymmetricPixels) {
    EXPECT_EQ(kCircle3.size(), 16u);
    expect_circle(kCircle3, 3);
}

TEST(Circle, Radius4Has20DistinctSymmetricPixels) {
    EXPECT_EQ(kCircle4.size(), 20u);
    expect_circle(kCircle4, 4);
}

TEST(Circle, StartsBelowTheCentre) {
    EXPECT_EQ(kCircle3.front(), (Offset{0, 3}));
    EXPECT_EQ(kCircle4.front(), (Offset{0, 4}));
}

TEST(Circle, CirclesAreDisjoint) {
    for (const Offset& a : kCircle3)
        for (const Offset& b : kCircle4) EXPECT_NE(a, b);
}

}  // namespace
}  // namespace evcorner
