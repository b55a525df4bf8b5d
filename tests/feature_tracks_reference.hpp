#pragma once
// The feature-track labeller as it was before the quadrant lists and the SIMD kernels
// (commit 88ecbd5): every partner's cylinders counted over all reachable corner events.
// Test oracle only: label_feature_tracks() must give the same labels and counters.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "evcorner/eval/feature_tracks.hpp"

namespace evcorner::eval {

namespace reference_detail {

// Corner events in time order, with buckets of (group, cell) holding positions into it.
// Positions inside a bucket are ascending, hence in time order.
struct Index {
    std::vector<std::int64_t> t;
    std::vector<float> x, y;
    std::vector<std::uint32_t> original;  // input position
    std::vector<std::uint32_t> bucket_begin;  // CSR offsets, size buckets + 1
    std::vector<std::uint32_t> bucket_items;
    int cells_x = 0, cells_y = 0, groups = 1, cell = 8;
    std::vector<std::uint8_t> group;

    [[nodiscard]] std::size_t bucket(int g, int cx, int cy) const noexcept {
        return (static_cast<std::size_t>(g) * cells_y + cy) * cells_x + cx;
    }
};

inline Index build_index(std::span<const Event> corners, const FeatureTrackParams& p) {
    Index ix;
    const std::size_t n = corners.size();
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return corners[a].t < corners[b].t; });
    int max_x = 0, max_y = 0;
    for (const Event& e : corners) {
        max_x = std::max<int>(max_x, e.x);
        max_y = std::max<int>(max_y, e.y);
    }
    ix.cell = p.cell_size;
    ix.cells_x = max_x / ix.cell + 1;
    ix.cells_y = max_y / ix.cell + 1;
    ix.groups = p.same_polarity ? 2 : 1;
    ix.t.resize(n);
    ix.x.resize(n);
    ix.y.resize(n);
    ix.group.resize(n);
    ix.original = order;
    const std::size_t buckets = static_cast<std::size_t>(ix.groups) * ix.cells_x * ix.cells_y;
    ix.bucket_begin.assign(buckets + 1, 0);
    std::vector<std::uint32_t> bucket_of(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Event& e = corners[order[i]];
        ix.t[i] = e.t;
        ix.x[i] = e.x;
        ix.y[i] = e.y;
        ix.group[i] = p.same_polarity ? static_cast<std::uint8_t>(e.p != 0) : 0;
        bucket_of[i] = static_cast<std::uint32_t>(ix.bucket(ix.group[i], e.x / ix.cell, e.y / ix.cell));
        ++ix.bucket_begin[bucket_of[i] + 1];
    }
    std::partial_sum(ix.bucket_begin.begin(), ix.bucket_begin.end(), ix.bucket_begin.begin());
    ix.bucket_items.resize(n);
    std::vector<std::uint32_t> fill(ix.bucket_begin.begin(), ix.bucket_begin.end() - 1);
    for (std::size_t i = 0; i < n; ++i) ix.bucket_items[fill[bucket_of[i]]++] = static_cast<std::uint32_t>(i);
    return ix;
}

// The corners one anchor can reach, relative to it, in time order (SoA for the scan).
struct Candidates {
    std::vector<std::uint32_t> pos;
    std::vector<float> dx, dy, dt;
    std::vector<std::int32_t> weight;  // 0: claimed (exclusive mode), else 1
    std::vector<std::pair<std::int64_t, std::uint32_t>> gathered;

    void clear() {
        pos.clear();
        dx.clear();
        dy.clear();
        dt.clear();
        weight.clear();
        gathered.clear();
    }
};

}  // namespace reference_detail

inline FeatureTrackResult label_feature_tracks_reference(std::span<const Event> corners, const FeatureTrackParams& p = {}) {
    validate(p);
    if (corners.size() >= std::numeric_limits<std::uint32_t>::max())
        throw std::invalid_argument("feature tracks: at most 2^32 - 2 corner events");
    FeatureTrackResult result;
    const std::size_t n = corners.size();
    result.on_track.assign(n, 0);
    if (n == 0) return result;

    using namespace reference_detail;
    const Index ix = build_index(corners, p);
    std::vector<std::uint8_t> on_track(n, 0);  // by time-order position
    std::vector<std::uint8_t> claimed(n, 0);
    const bool exclusive = p.overlap == TrackOverlap::exclusive;
    const float r_in2 = static_cast<float>(p.inner_radius * p.inner_radius);
    const float r_out2 = static_cast<float>(p.outer_radius * p.outer_radius);
    const float len2 = static_cast<float>(p.max_length * p.max_length);
    // Every cylinder of an anchor lies within max_length + outer_radius of it.
    const double reach = p.max_length + p.outer_radius;
    const float reach2 = static_cast<float>(reach * reach);
    const auto min_inner = static_cast<std::size_t>(p.min_inner);

    Candidates c;
    for (std::size_t a = 0; a < n; ++a) {
        if (exclusive && claimed[a]) continue;
        const std::int64_t ta = ix.t[a];
        const std::int64_t t_end = ta + p.max_duration_us;
        const float xa = ix.x[a], ya = ix.y[a];
        const int g = ix.group[a];
        c.clear();
        const int cx0 = std::max(0, static_cast<int>(std::floor((xa - reach) / ix.cell)));
        const int cx1 = std::min(ix.cells_x - 1, static_cast<int>(std::floor((xa + reach) / ix.cell)));
        const int cy0 = std::max(0, static_cast<int>(std::floor((ya - reach) / ix.cell)));
        const int cy1 = std::min(ix.cells_y - 1, static_cast<int>(std::floor((ya + reach) / ix.cell)));
        for (int cy = cy0; cy <= cy1; ++cy) {
            for (int cx = cx0; cx <= cx1; ++cx) {
                const std::size_t b = ix.bucket(g, cx, cy);
                const auto first = ix.bucket_items.begin() + ix.bucket_begin[b];
                const auto last = ix.bucket_items.begin() + ix.bucket_begin[b + 1];
                // Ties at t_a belong to the cylinder too, whatever their order.
                auto it = std::lower_bound(first, last, ta,
                                           [&](std::uint32_t i, std::int64_t t) { return ix.t[i] < t; });
                for (; it != last && ix.t[*it] <= t_end; ++it) {
                    const float ddx = ix.x[*it] - xa, ddy = ix.y[*it] - ya;
                    if (ddx * ddx + ddy * ddy <= reach2) c.gathered.emplace_back(ix.t[*it], *it);
                }
            }
        }
        if (c.gathered.size() < min_inner) continue;
        std::sort(c.gathered.begin(), c.gathered.end());
        for (const auto& [t, i] : c.gathered) {
            c.pos.push_back(i);
            c.dx.push_back(ix.x[i] - xa);
            c.dy.push_back(ix.y[i] - ya);
            c.dt.push_back(static_cast<float>(t - ta));
            c.weight.push_back(exclusive && claimed[i] ? 0 : 1);
        }
        const std::size_t m = c.pos.size();
        const float* dx = c.dx.data();
        const float* dy = c.dy.data();
        const float* dt = c.dt.data();
        const std::int32_t* w = c.weight.data();

        // Partners in time order; `end` is one past the last candidate with t <= t_b.
        // any: every accepted hypothesis labels its inner corners at once. exclusive: the
        // anchor keeps its accepted hypothesis with the most inner corners, which claims them.
        std::size_t end = 0;
        std::int32_t best_inner = -1;
        std::size_t best_j = 0, best_end = 0;
        auto label_inner = [&](std::size_t j, std::size_t stop) {
            const float inv = 1.0f / dt[j];
            for (std::size_t k = 0; k < stop; ++k) {
                const float s = dt[k] * inv;
                const float ex = dx[k] - dx[j] * s, ey = dy[k] - dy[j] * s;
                if (ex * ex + ey * ey <= r_in2 && w[k] != 0) {
                    on_track[c.pos[k]] = 1;
                    if (exclusive) claimed[c.pos[k]] = 1;
                }
            }
        };
        for (std::size_t j = 0; j < m; ++j) {
            if (dt[j] <= 0.0f) continue;  // a pair needs t_b > t_a
            while (end < m && dt[end] <= dt[j]) ++end;
            if (end < min_inner) continue;  // fewer corners than needed in the whole time span
            if (w[j] == 0) continue;
            const float bx = dx[j], by = dy[j];
            if (bx * bx + by * by > len2) continue;
            const float inv = 1.0f / dt[j];
            // Integer counts keep this loop vectorisable (float sums would not reassociate).
            std::int32_t inner = 0, within_outer = 0;
            for (std::size_t k = 0; k < end; ++k) {
                const float s = dt[k] * inv;
                const float ex = dx[k] - bx * s, ey = dy[k] - by * s;
                const float d2 = ex * ex + ey * ey;
                inner += static_cast<std::int32_t>(d2 <= r_in2) & w[k];
                within_outer += static_cast<std::int32_t>(d2 <= r_out2) & w[k];
            }
            const std::int32_t outer = within_outer - inner;
            ++result.hypotheses;
            if (inner < p.min_inner ||
                static_cast<double>(outer) > p.max_outer_ratio * static_cast<double>(inner))
                continue;
            ++result.accepted;
            if (!exclusive) {
                label_inner(j, end);
            } else if (inner > best_inner) {
                best_inner = inner;
                best_j = j;
                best_end = end;
            }
        }
        if (exclusive && best_inner >= 0) label_inner(best_j, best_end);
    }
    for (std::size_t i = 0; i < n; ++i) {
        result.on_track[ix.original[i]] = on_track[i];
        result.labelled += on_track[i];
    }
    return result;
}

}  // namespace evcorner::eval
