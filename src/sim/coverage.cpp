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
    void add(int r, int k, double v, double v2) noexcept {
        const std::size_t i = static_cast<std::size_t>(r) * stride + static_cast<std::size_t>(k);
        acc[i] += v;
        if constexpr (Dual) acc2[i] += v2;
    }
    void add_pair(int r, int k, double v0, double v1, double w0, double w1) noexcept {
        add(r, k, v0, w0);
        add(r, k + 1, v1, w1);
    }
    void span(int, double, double) noexcept {}
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

}  // namespace evcorner::sim
