#include "evcorner/sim/coverage.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "evcorner/sim/coverage_walk.hpp"

namespace evcorner::sim {

namespace {

// Adds into one or two dense arrays of `stride` doubles per row.
template <bool Dual>
struct DenseSink {
    double* acc;
    double* acc2;
    std::size_t stride;
    struct Row {
        double* acc;
        double* acc2;
        void add(int k, double v, double v2) noexcept {
            acc[k] += v;
            if constexpr (Dual) acc2[k] += v2;
        }
        void add_pair(int k, double v0, double v1, double w0, double w1) noexcept {
            add(k, v0, w0);
            add(k + 1, v1, w1);
        }
    };
    Row row(int r) const noexcept {
        const std::size_t i = static_cast<std::size_t>(r) * stride;
        return {acc + i, Dual ? acc2 + i : nullptr};
    }
    void rows(int, int) noexcept {}
    void flat(double, double, double) noexcept {}
};

}  // namespace

void accumulate_polygon(std::span<const Vec2> poly, double weight, double* acc, std::size_t stride, int width,
                        int height) noexcept {
    DenseSink<false> sink{acc, nullptr, stride};
    walk_coverage<false>(poly, weight, 0.0, width, height, sink);
}

void accumulate_polygon2(std::span<const Vec2> poly, double weight, double* acc, double weight2, double* acc2,
                         std::size_t stride, int width, int height) noexcept {
    DenseSink<true> sink{acc, acc2, stride};
    walk_coverage<true>(poly, weight, weight2, width, height, sink);
}

std::vector<double> polygon_coverage(std::span<const Vec2> poly, SensorSize size) {
    const std::size_t stride = static_cast<std::size_t>(size.width) + 2;
    std::vector<double> acc(stride * static_cast<std::size_t>(size.height), 0.0);
    accumulate_polygon(poly, 1.0, acc.data(), stride, size.width, size.height);
    std::vector<double> cov(static_cast<std::size_t>(size.pixels()));
    for (int y = 0; y < size.height; ++y) {
        double s = 0;
        for (int x = 0; x < size.width; ++x) {
            s += acc[static_cast<std::size_t>(y) * stride + static_cast<std::size_t>(x)];
            cov[static_cast<std::size_t>(y) * static_cast<std::size_t>(size.width) + static_cast<std::size_t>(x)] =
                std::clamp(s, 0.0, 1.0);
        }
    }
    return cov;
}

double pixel_coverage(std::span<const Vec2> poly, int x, int y) noexcept {
    const double px = x, py = y;
    const std::size_t n = poly.size();
    double cov = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 a = poly[i], b = poly[(i + 1) % n];
        // Outside the row band, horizontal (no area to its right) or right of the pixel: nothing.
        if ((a.y <= py && b.y <= py) || (a.y >= py + 1.0 && b.y >= py + 1.0) || a.y == b.y) continue;
        if (a.x >= px + 1.0 && b.x >= px + 1.0) continue;
        // As walk_coverage: an edge going up (in y) adds, one going down subtracts.
        const bool down = a.y < b.y;
        const Vec2 lo = down ? a : b, hi = down ? b : a;
        const double ya = std::max(lo.y, py), yb = std::min(hi.y, py + 1.0);
        const double h = (down ? -1.0 : 1.0) * (yb - ya);
        const double dxdy = (hi.x - lo.x) / (hi.y - lo.y);
        const double xa = lo.x + (ya - lo.y) * dxdy, xb = lo.x + (yb - lo.y) * dxdy;
        const double xl = std::min(xa, xb), xr = std::max(xa, xb);
        // The part of the pixel right of the edge, as a fraction, averaged over the band:
        // 1 where the edge is left of the pixel, x + 1 - X inside it, 0 right of it.
        if (xr <= px) {
            cov += h;
            continue;
        }
        if (xl >= px + 1.0) continue;
        const double len = xr - xl;
        if (len < 1e-12) {
            cov += h * std::clamp(px + 1.0 - 0.5 * (xl + xr), 0.0, 1.0);
            continue;
        }
        const double left = std::max(0.0, std::min(xr, px) - xl);  // where the fraction is 1
        const double m0 = std::max(xl, px), m1 = std::min(xr, px + 1.0);
        const double mid = m1 > m0 ? (m1 - m0) * (px + 1.0 - 0.5 * (m0 + m1)) : 0.0;
        cov += h * ((left + mid) / len);
    }
    return cov;
}

}  // namespace evcorner::sim
