#pragma once
// The edge walk behind the exact area coverage of coverage.hpp, as a template over what is
// done with each addition, so that the dense accumulation (accumulate_polygon) and the
// simulator's sparse one make exactly the same additions, in the same order.
//
// Each edge is cut at the row and column lines into pieces lying in one cell; a piece with
// signed height h (the edge's y-extent in the cell, positive upwards) and mean x xm in cell
// column k adds h (k + 1 - xm) to its own cell and h (xm - k) to the next one. The sink gets:
//   sink.row(r)             a row sink for row r (made once per row an edge crosses; it
//                           keeps the row's pointers in registers), on which:
//     row.add(k, v, v2)     add v at column k (and v2 into the second array when Dual)
//     row.add_pair(k, v0, v1, w0, w1)   add v0 at column k, then v1 at column k + 1 (and
//                           w0, w1 into the second array when Dual)
//   sink.rows(r0, r1)       a slanted edge crosses rows r0 .. r1 (called once per edge, before
//                           its rows' additions; not called when it crosses none)
//   sink.flat(y, xl, xr)    a horizontal edge at y from x = xl to x = xr (it adds nothing)
// Parts left of x = 0 add to column 0, parts right of x = width and outside rows
// [0, height) add nothing; rows() gets every row in [0, height) an edge crosses, wherever it
// lies in x.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

#include "evcorner/sim/scene.hpp"

namespace evcorner::sim {

/// One edge from (x0, y0) to (x1, y1), y0 < y1; h for a row is sign * its y-extent there
/// (sign2 for the second array).
template <bool Dual, class Sink>
void walk_coverage_edge(double x0, double y0, double x1, double y1, double sign, double sign2, int width, int height,
                        Sink& sink) {
    const double dxdy = (x1 - x0) / (y1 - y0);
    const int r0 = std::max(0, static_cast<int>(std::floor(y0)));
    const int r1 = std::min(height - 1, static_cast<int>(std::ceil(y1)) - 1);
    // Every row r0 .. r1 is crossed: r0 <= y0 < r0 + 1 (or r0 = 0 and y0 < 0 < y1) and
    // r1 < y1, so each row's part [ya, yb] below has yb > ya.
    if (r0 <= r1) sink.rows(r0, r1);
    // The part's top and its x carry from row to row: in every row after r0, ya is the row
    // line r (r > y0), which is the row before's yb (r < y1), so xa is the row before's xb,
    // the same expression of the same values (one multiplication a row less).
    double ya = std::max(y0, static_cast<double>(r0));
    double xa = x0 + (ya - y0) * dxdy;
    for (int r = r0; r <= r1; ++r) {
        const double yb = std::min(y1, static_cast<double>(r + 1));
        const double xb = x0 + (yb - y0) * dxdy;
        const double ya_row = ya, xa_row = xa;
        ya = yb;
        xa = xb;
        if (yb <= ya_row) continue;
        const double h = sign * (yb - ya_row);
        const double h2 = Dual ? sign2 * (yb - ya_row) : 0.0;
        const double xl = std::min(xa_row, xb), xr = std::max(xa_row, xb);
        auto row = sink.row(r);
        if (xr <= 0) {  // wholly left of the sensor: covers every pixel of the row to its right
            row.add(0, h, h2);
            continue;
        }
        if (xl >= width) continue;
        if (xr == xl) {
            const int k = static_cast<int>(xl);  // xl > 0: truncation is floor
            row.add_pair(k, h * (k + 1 - xl), h * (xl - k), Dual ? h2 * (k + 1 - xl) : 0.0, Dual ? h2 * (xl - k) : 0.0);
            continue;
        }
        const double per_x = h / (xr - xl);
        const double per_x2 = Dual ? h2 / (xr - xl) : 0.0;
        double lo = xl;
        if (lo < 0) {
            row.add(0, per_x * (0 - lo), Dual ? per_x2 * (0 - lo) : 0.0);
            lo = 0;
        }
        const double hi_end = std::min(xr, static_cast<double>(width));
        int k = static_cast<int>(lo);  // lo >= 0: truncation is floor
        // The column as a double too (k and k + 1 are exact in a double, so every value is
        // the one int-to-double conversions would give; this saves two conversions a piece).
        double kd = k;
        while (lo < hi_end) {
            const double kd1 = kd + 1.0;
            const double hi = std::min(hi_end, kd1);
            const double hp = per_x * (hi - lo);
            const double xm = 0.5 * (lo + hi);
            const double hp2 = Dual ? per_x2 * (hi - lo) : 0.0;
            row.add_pair(k, hp * (kd1 - xm), hp * (xm - kd), Dual ? hp2 * (kd1 - xm) : 0.0, Dual ? hp2 * (xm - kd) : 0.0);
            lo = hi;
            ++k;
            kd = kd1;
        }
    }
}

/// Every edge of `poly` with weight (weight2 into the second array when Dual).
template <bool Dual, class Sink>
void walk_coverage(std::span<const Vec2> poly, double weight, double weight2, int width, int height, Sink& sink) {
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 a = poly[i], b = poly[(i + 1) % n];
        if (a.y == b.y) {  // horizontal edges bound no area to their right
            sink.flat(a.y, std::min(a.x, b.x), std::max(a.x, b.x));
            continue;
        }
        // Upward edges (b.y < a.y) add, downward ones subtract: a positive-area polygon covers +1.
        if (a.y < b.y)
            walk_coverage_edge<Dual>(a.x, a.y, b.x, b.y, -weight, -weight2, width, height, sink);
        else
            walk_coverage_edge<Dual>(b.x, b.y, a.x, a.y, weight, weight2, width, height, sink);
    }
}

}  // namespace evcorner::sim
