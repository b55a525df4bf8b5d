#include "evcorner/sim/coverage.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace evcorner::sim {

namespace {

inline void set_bit(std::uint64_t* row_bits, int k) noexcept {
    row_bits[static_cast<unsigned>(k) >> 6] |= std::uint64_t{1} << (static_cast<unsigned>(k) & 63u);
}

// One edge from (x0, y0) to (x1, y1), y0 < y1; h for a row is sign * its y-extent there.
// Dual: the same edge also into acc2 with sign2, every value computed as a pass of its own
// would (the same operations in the same order), so that one walk serves both.
// Record: also sets, in `bits` (words_per_row 64-bit words per row), the bit of every column
// whose acc entry it changes.

template <bool Record, bool Dual = false>
void accumulate_edge(double x0, double y0, double x1, double y1, double sign, double* acc, std::size_t stride, int width,
                     int height, std::uint64_t* bits, std::size_t words_per_row, double sign2 = 0,
                     double* acc2 = nullptr) noexcept {
    const double dxdy = (x1 - x0) / (y1 - y0);
    const int r0 = std::max(0, static_cast<int>(std::floor(y0)));
    const int r1 = std::min(height - 1, static_cast<int>(std::ceil(y1)) - 1);
    for (int r = r0; r <= r1; ++r) {
        const double ya = std::max(y0, static_cast<double>(r));
        const double yb = std::min(y1, static_cast<double>(r + 1));
        if (yb <= ya) continue;
        const double h = sign * (yb - ya);
        double* row = acc + static_cast<std::size_t>(r) * stride;
        [[maybe_unused]] const double h2 = Dual ? sign2 * (yb - ya) : 0.0;
        [[maybe_unused]] double* row2 = Dual ? acc2 + static_cast<std::size_t>(r) * stride : nullptr;
        [[maybe_unused]] std::uint64_t* cols = Record ? bits + static_cast<std::size_t>(r) * words_per_row : nullptr;
        const double xa = x0 + (ya - y0) * dxdy, xb = x0 + (yb - y0) * dxdy;
        const double xl = std::min(xa, xb), xr = std::max(xa, xb);
        if (xr <= 0) {  // wholly left of the sensor: covers every pixel of the row to its right
            row[0] += h;
            if constexpr (Dual) row2[0] += h2;
            if constexpr (Record) set_bit(cols, 0);
            continue;
        }
        if (xl >= width) continue;
        if (xr == xl) {
            const int k = static_cast<int>(std::floor(xl));
            row[k] += h * (k + 1 - xl);
            row[k + 1] += h * (xl - k);
            if constexpr (Dual) {
                row2[k] += h2 * (k + 1 - xl);
                row2[k + 1] += h2 * (xl - k);
            }
            if constexpr (Record) {
                set_bit(cols, k);
                set_bit(cols, k + 1);
            }
            continue;
        }
        const double per_x = h / (xr - xl);
        [[maybe_unused]] const double per_x2 = Dual ? h2 / (xr - xl) : 0.0;
        double lo = xl;
        if (lo < 0) {
            row[0] += per_x * (0 - lo);
            if constexpr (Dual) row2[0] += per_x2 * (0 - lo);
            if constexpr (Record) set_bit(cols, 0);
            lo = 0;
        }
        const double hi_end = std::min(xr, static_cast<double>(width));
        int k = static_cast<int>(std::floor(lo));
        while (lo < hi_end) {
            const double hi = std::min(hi_end, static_cast<double>(k + 1));
            const double hp = per_x * (hi - lo);
            const double xm = 0.5 * (lo + hi);
            row[k] += hp * (k + 1 - xm);
            row[k + 1] += hp * (xm - k);
            if constexpr (Dual) {
                const double hp2 = per_x2 * (hi - lo);
                row2[k] += hp2 * (k + 1 - xm);
                row2[k + 1] += hp2 * (xm - k);
            }
            if constexpr (Record) {
                set_bit(cols, k);
                set_bit(cols, k + 1);
            }
            lo = hi;
            ++k;
        }
    }
}

template <bool Record, bool Dual>
void accumulate(std::span<const Vec2> poly, double weight, double* acc, double weight2, double* acc2, std::size_t stride,
                int width, int height, std::uint64_t* bits, std::size_t words_per_row) noexcept {
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 a = poly[i], b = poly[(i + 1) % n];
        if (a.y == b.y) continue;  // horizontal edges bound no area to their right
        // Upward edges (b.y < a.y) add, downward ones subtract: a positive-area polygon covers +1.
        if (a.y < b.y)
            accumulate_edge<Record, Dual>(a.x, a.y, b.x, b.y, -weight, acc, stride, width, height, bits, words_per_row,
                                          -weight2, acc2);
        else
            accumulate_edge<Record, Dual>(b.x, b.y, a.x, a.y, weight, acc, stride, width, height, bits, words_per_row,
                                          weight2, acc2);
    }
}

}  // namespace

void accumulate_polygon(std::span<const Vec2> poly, double weight, double* acc, std::size_t stride, int width,
                        int height) noexcept {
    accumulate<false, false>(poly, weight, acc, 0.0, nullptr, stride, width, height, nullptr, 0);
}

void accumulate_polygon2(std::span<const Vec2> poly, double weight, double* acc, double weight2, double* acc2,
                         std::size_t stride, int width, int height) noexcept {
    accumulate<false, true>(poly, weight, acc, weight2, acc2, stride, width, height, nullptr, 0);
}

void accumulate_polygon(std::span<const Vec2> poly, double weight, double* acc, std::size_t stride, int width,
                        int height, std::uint64_t* written, std::size_t words_per_row) noexcept {
    accumulate<true, false>(poly, weight, acc, 0.0, nullptr, stride, width, height, written, words_per_row);
}

void accumulate_polygon2(std::span<const Vec2> poly, double weight, double* acc, double weight2, double* acc2,
                         std::size_t stride, int width, int height, std::uint64_t* written,
                         std::size_t words_per_row) noexcept {
    accumulate<true, true>(poly, weight, acc, weight2, acc2, stride, width, height, written, words_per_row);
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

}  // namespace evcorner::sim
