#pragma once
// Two oracles for the simulator's pixel coverage (sim/coverage.hpp), written plainly:
//  - clipped: the polygon clipped to the pixel square (Sutherland-Hodgman; exact in area for
//    any simple polygon, convex or not, since the window is convex) and its shoelace area;
//  - supersampled: the fraction of n x n sample points of the pixel inside (even-odd rule),
//    off by at most about (edge length in the pixel) / n.

#include <cmath>
#include <span>
#include <vector>

#include "evcorner/sim/geometry.hpp"
#include "evcorner/sim/scene.hpp"

namespace evcorner::naive {

inline double clipped_pixel_coverage(std::span<const sim::Vec2> poly, int px, int py) {
    std::vector<sim::Vec2> cur(poly.begin(), poly.end()), next;
    // Keep the side where f(p) >= 0, for the four sides x >= px, x <= px+1, y >= py, y <= py+1.
    auto clip = [&](auto f) {
        next.clear();
        const std::size_t n = cur.size();
        for (std::size_t i = 0; i < n; ++i) {
            const sim::Vec2 a = cur[i], b = cur[(i + 1) % n];
            const double fa = f(a), fb = f(b);
            if (fa >= 0) next.push_back(a);
            if ((fa >= 0) != (fb >= 0)) {
                const double t = fa / (fa - fb);
                next.push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)});
            }
        }
        cur.swap(next);
    };
    clip([&](sim::Vec2 p) { return p.x - px; });
    clip([&](sim::Vec2 p) { return px + 1.0 - p.x; });
    clip([&](sim::Vec2 p) { return p.y - py; });
    clip([&](sim::Vec2 p) { return py + 1.0 - p.y; });
    if (cur.size() < 3) return 0.0;
    return std::abs(sim::signed_area(cur));
}

inline double supersampled_pixel_coverage(std::span<const sim::Vec2> poly, int px, int py, int n) {
    int hits = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            hits += sim::inside(poly, {px + (i + 0.5) / n, py + (j + 0.5) / n}) ? 1 : 0;
    return static_cast<double>(hits) / (static_cast<double>(n) * n);
}

}  // namespace evcorner::naive
