// Every code path must round alike (and as the reference in the tests): no fused
// multiply-add contraction, whatever the target (the AVX-512 one enables FMA).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=off")
#endif

#include "evcorner/eval/feature_tracks.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "evcorner/cpu_paths.hpp"

namespace evcorner::eval {

void validate(const FeatureTrackParams& p) {
    auto fail = [](const std::string& what) { throw std::invalid_argument("feature tracks: " + what); };
    if (!(p.inner_radius > 0)) fail("inner radius must be > 0");
    if (!(p.outer_radius >= p.inner_radius)) fail("outer radius must be >= the inner radius");
    if (p.min_inner < 2) fail("minimum inner events must be >= 2");
    if (!(p.max_outer_ratio >= 0)) fail("outer-to-inner ratio must be >= 0");
    if (p.max_duration_us <= 0) fail("maximum track duration must be > 0");
    if (p.max_duration_us > (std::int64_t{1} << 24))
        fail("maximum track duration must be <= 16.7 s (times are held as float microseconds)");
    if (!(p.max_length > 0)) fail("maximum pair distance must be > 0");
    if (p.cell_size < 1) fail("cell size must be >= 1");
}

TrackOverlap parse_track_overlap(std::string_view name) {
    if (name == "any") return TrackOverlap::any;
    if (name == "exclusive") return TrackOverlap::exclusive;
    throw std::invalid_argument("feature tracks: overlap must be 'any' or 'exclusive', not '" + std::string(name) + "'");
}

std::string_view to_string(TrackOverlap o) noexcept { return o == TrackOverlap::any ? "any" : "exclusive"; }

namespace {

// Corner events in time order, with buckets of (group, cell) holding positions into it.
// Positions inside a bucket are ascending, hence in time order.
struct Index {
    std::vector<std::int64_t> t;
    std::vector<float> x, y;
    std::vector<std::uint32_t> bucket_begin;  // CSR offsets, size buckets + 1
    std::vector<std::uint32_t> bucket_items;
    int cells_x = 0, cells_y = 0, groups = 1, cell = 8;
    std::vector<std::uint8_t> group;

    [[nodiscard]] std::size_t bucket(int g, int cx, int cy) const noexcept {
        return (static_cast<std::size_t>(g) * cells_y + cy) * cells_x + cx;
    }
};

// `corners` in time order (ties in any order: their order is the tie-break everywhere).
Index build_index(std::span<const Event> corners, const FeatureTrackParams& p) {
    Index ix;
    const std::size_t n = corners.size();
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
    const std::size_t buckets = static_cast<std::size_t>(ix.groups) * ix.cells_x * ix.cells_y;
    ix.bucket_begin.assign(buckets + 1, 0);
    std::vector<std::uint32_t> bucket_of(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Event& e = corners[i];
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

// The corners one anchor can reach, relative to it, in time order.
//
// Every cylinder of a partner b lies within outer_radius of the segment from the anchor
// to b, so it stays on b's side of both axes through the anchor, but for a margin. The
// reachable corners are therefore also kept in four quadrant lists, by the signs of
// (dx, dy), each holding the corners no further than `margin` px on the other side of
// either axis; a partner's cylinders are counted over its quadrant's list only. A corner
// left out lies more than outer_radius + 1 px from the cylinder axis at its time, also in
// float arithmetic (see count_cylinder), so it counts for neither cylinder: the counts,
// and so the labels, are those of a scan over all reachable corners.
//
// Each quadrant list is padded to a multiple of kLanes with corners that never count, so
// the SIMD loops have no scalar tail; a partner's scan covers its list up to the first
// corner after it in time, rounded up to kLanes, and masks the corners later than it.
constexpr std::size_t kLanes = 16;

constexpr std::size_t round_up(std::size_t n) { return (n + kLanes - 1) / kLanes * kLanes; }

// One quadrant's list (pointers into Candidates' buffers).
struct QuadrantView {
    const float* dx;
    const float* dy;
    const float* dt;
    const std::int32_t* weight;  // 0: claimed (exclusive mode), else 1
    std::uint8_t* inner;         // any mode: inner to an accepted track of this anchor
};

struct Candidates {
    std::vector<std::uint32_t> pos;  // time-order positions, ascending
    std::vector<std::uint64_t> bits;
    std::vector<float> dx, dy, dt;
    std::vector<std::int32_t> weight;
    // Quadrant q's list: [q * stride, q * stride + size[q]) of the q* buffers, then padding.
    std::size_t stride = 0;
    std::vector<float> qdx, qdy, qdt;
    std::vector<std::int32_t> qweight;
    std::vector<std::uint32_t> qlocal;  // candidate number
    std::vector<std::uint8_t> qinner;
    std::size_t size[4] = {0, 0, 0, 0};
    std::size_t end[4] = {0, 0, 0, 0};  // one past the last corner no later than the partner

    QuadrantView view(int q) noexcept {
        const std::size_t o = static_cast<std::size_t>(q) * stride;
        return {qdx.data() + o, qdy.data() + o, qdt.data() + o, qweight.data() + o, qinner.data() + o};
    }
};

// Fills the quadrant lists from the candidates (dx, dy, dt, weight of size m).
void build_quadrants(Candidates& c, float margin) {
    const std::size_t m = c.dx.size();
    c.stride = round_up(m);
    const std::size_t total = 4 * c.stride;
    if (c.qdx.size() < total) {
        c.qdx.resize(total);
        c.qdy.resize(total);
        c.qdt.resize(total);
        c.qweight.resize(total);
        c.qlocal.resize(total);
        c.qinner.resize(total);
    }
    std::size_t size[4] = {0, 0, 0, 0};
    for (std::size_t k = 0; k < m; ++k) {
        const float x = c.dx[k], y = c.dy[k];
        const bool px = x >= -margin, nx = x <= margin, py = y >= -margin, ny = y <= margin;
        const bool in[4] = {px && py, nx && py, px && ny, nx && ny};
        for (int q = 0; q < 4; ++q) {
            // Written unconditionally, kept only when the corner belongs (branch-free).
            const std::size_t at = static_cast<std::size_t>(q) * c.stride + size[q];
            c.qdx[at] = x;
            c.qdy[at] = y;
            c.qdt[at] = c.dt[k];
            c.qweight[at] = c.weight[k];
            c.qlocal[at] = static_cast<std::uint32_t>(k);
            size[q] += in[q];
        }
    }
    for (int q = 0; q < 4; ++q) {
        const std::size_t o = static_cast<std::size_t>(q) * c.stride;
        // Padding: latest of all (masked off by time) and far away.
        for (std::size_t k = size[q]; k < round_up(size[q]); ++k) {
            c.qdx[o + k] = 0;
            c.qdy[o + k] = 0;
            c.qdt[o + k] = std::numeric_limits<float>::max();
            c.qweight[o + k] = 0;
            c.qlocal[o + k] = 0;
        }
        std::fill_n(c.qinner.begin() + static_cast<std::ptrdiff_t>(o), round_up(size[q]), std::uint8_t{0});
        c.size[q] = size[q];
        c.end[q] = 0;
    }
}

// The axis of one hypothesis, relative to the anchor: the partner at (bx, by, tb), 1/tb.
struct Axis {
    float bx, by, tb, inv, r_in2, r_out2;
};

struct Cylinder {
    std::int32_t inner = 0, within_outer = 0;
};

// The cylinder counts over the first n (a multiple of kLanes) corners of a quadrant list,
// those later than the partner masked off. One expression for the distance, here and in
// mark_inner and the exclusive claim, so every code path rounds alike: s = dt*inv in
// [0, 1], c = b*s, e = d - c, d2 = ex*ex + ey*ey (no fused multiply-add: the file is compiled without
// contraction, see the pragma at its top). Exclusion by
// quadrant holds in this arithmetic: for bx >= 0, c_x = fl(bx*s) >= 0, so a corner with
// dx < -margin has fl(dx - c_x) <= dx < -(outer + 1) by monotone rounding.
// Integer counts keep the loop vectorisable (float sums would not reassociate).
template <bool Weighted>
[[gnu::always_inline]] inline Cylinder count_cylinder(const QuadrantView& q, std::size_t n, const Axis& a) noexcept {
    const float* __restrict dx = q.dx;
    const float* __restrict dy = q.dy;
    const float* __restrict dt = q.dt;
    const std::int32_t* __restrict w = q.weight;
    const float bx = a.bx, by = a.by, tb = a.tb, inv = a.inv, r_in2 = a.r_in2, r_out2 = a.r_out2;
    std::int32_t inner = 0, within_outer = 0;
    for (std::size_t k = 0; k < n; ++k) {
        const float s = dt[k] * inv;
        const float ex = dx[k] - bx * s, ey = dy[k] - by * s;
        const float d2 = ex * ex + ey * ey;
        std::int32_t take = static_cast<std::int32_t>(dt[k] <= tb);
        if constexpr (Weighted) take &= w[k];
        inner += static_cast<std::int32_t>(d2 <= r_in2) & take;
        within_outer += static_cast<std::int32_t>(d2 <= r_out2) & take;
    }
    return {inner, within_outer};
}

// Any mode: flags the inner corners among the first n (all weights are 1 there).
[[gnu::always_inline]] inline void mark_inner_impl(const QuadrantView& q, std::size_t n, const Axis& a) noexcept {
    const float* __restrict dx = q.dx;
    const float* __restrict dy = q.dy;
    const float* __restrict dt = q.dt;
    std::uint8_t* __restrict inner = q.inner;
    const float bx = a.bx, by = a.by, tb = a.tb, inv = a.inv, r_in2 = a.r_in2;
    for (std::size_t k = 0; k < n; ++k) {
        const float s = dt[k] * inv;
        const float ex = dx[k] - bx * s, ey = dy[k] - by * s;
        inner[k] |= static_cast<std::uint8_t>((ex * ex + ey * ey <= r_in2) & (dt[k] <= tb));
    }
}

using CountFn = Cylinder (*)(const QuadrantView&, std::size_t, const Axis&) noexcept;
using MarkFn = void (*)(const QuadrantView&, std::size_t, const Axis&) noexcept;

struct Kernels {
    const char* name;
    CountFn count;           // weights all 1
    CountFn count_weighted;  // exclusive mode
    MarkFn mark;
};

Cylinder count_portable(const QuadrantView& q, std::size_t n, const Axis& a) noexcept {
    return count_cylinder<false>(q, n, a);
}
Cylinder count_weighted_portable(const QuadrantView& q, std::size_t n, const Axis& a) noexcept {
    return count_cylinder<true>(q, n, a);
}
void mark_portable(const QuadrantView& q, std::size_t n, const Axis& a) noexcept { mark_inner_impl(q, n, a); }

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define EVCORNER_FT_SIMD_PATHS 1
// The same loops compiled for AVX2 and for AVX-512 (512-bit vectors); no FMA in either.
#define EVCORNER_FT_AVX2 "avx2"
#define EVCORNER_FT_AVX512 "avx512f,avx512vl,avx512bw,avx512dq,avx2,prefer-vector-width=512"
[[gnu::target(EVCORNER_FT_AVX2)]] Cylinder count_avx2(const QuadrantView& q, std::size_t n, const Axis& a) noexcept {
    return count_cylinder<false>(q, n, a);
}
[[gnu::target(EVCORNER_FT_AVX2)]] Cylinder count_weighted_avx2(const QuadrantView& q, std::size_t n,
                                                               const Axis& a) noexcept {
    return count_cylinder<true>(q, n, a);
}
[[gnu::target(EVCORNER_FT_AVX2)]] void mark_avx2(const QuadrantView& q, std::size_t n, const Axis& a) noexcept {
    mark_inner_impl(q, n, a);
}
[[gnu::target(EVCORNER_FT_AVX512)]] Cylinder count_avx512(const QuadrantView& q, std::size_t n,
                                                          const Axis& a) noexcept {
    return count_cylinder<false>(q, n, a);
}
[[gnu::target(EVCORNER_FT_AVX512)]] Cylinder count_weighted_avx512(const QuadrantView& q, std::size_t n,
                                                                   const Axis& a) noexcept {
    return count_cylinder<true>(q, n, a);
}
[[gnu::target(EVCORNER_FT_AVX512)]] void mark_avx512(const QuadrantView& q, std::size_t n, const Axis& a) noexcept {
    mark_inner_impl(q, n, a);
}
#endif

// The kernels this CPU runs, fastest first.
std::vector<Kernels> available_kernels() {
    std::vector<Kernels> k;
#ifdef EVCORNER_FT_SIMD_PATHS
    if (cpu_runs_avx512()) k.push_back({"avx512", count_avx512, count_weighted_avx512, mark_avx512});
    if (cpu_runs_avx2()) k.push_back({"avx2", count_avx2, count_weighted_avx2, mark_avx2});
#endif
    k.push_back({"portable", count_portable, count_weighted_portable, mark_portable});
    return k;
}

const std::vector<Kernels>& all_kernels() {
    static const std::vector<Kernels> k = available_kernels();
    return k;
}

const Kernels& chosen_kernels() noexcept {
    // EVCORNER_LABEL_PATH=portable (or avx2, avx512) forces a path this CPU runs.
    static const Kernels& c = forced_or_fastest(all_kernels(), "EVCORNER_LABEL_PATH");
    return c;
}

struct Counts {
    std::uint64_t hypotheses = 0, accepted = 0;
};

// Processes the anchors at positions [first, last) of the time-ordered `corners`, which hold
// every corner event that any of these anchors can reach (all with t_a <= t <= t_a +
// max_duration_us of each); `on_track` and `claimed` (exclusive mode) are per position and
// carry the state of earlier anchors. `progress(k)` is told now and then how many of the
// anchors are done.
void process_anchors(std::span<const Event> corners, std::size_t first, std::size_t last, std::uint8_t* on_track,
                     std::uint8_t* claimed, const FeatureTrackParams& p, const Kernels& kern, Counts& result,
                     const std::function<void(std::size_t)>& progress = {}) {
    if (first >= last) return;
    const Index ix = build_index(corners, p);
    const bool exclusive = p.overlap == TrackOverlap::exclusive;
    const float r_in2 = static_cast<float>(p.inner_radius * p.inner_radius);
    const float r_out2 = static_cast<float>(p.outer_radius * p.outer_radius);
    const float len2 = static_cast<float>(p.max_length * p.max_length);
    // Every cylinder of an anchor lies within max_length + outer_radius of it.
    const double reach = p.max_length + p.outer_radius;
    const float reach2 = static_cast<float>(reach * reach);
    const auto min_inner = static_cast<std::size_t>(p.min_inner);
    // Quadrant margin: whole pixels beyond the outer radius (coordinates are integers).
    const float margin = static_cast<float>(std::ceil(p.outer_radius) + 1.0);
    const CountFn count = exclusive ? kern.count_weighted : kern.count;

    Candidates c;
    std::vector<std::uint32_t> cursor(ix.bucket_begin.begin(), ix.bucket_begin.end() - 1);
    std::size_t lo = 0;
    for (std::size_t a = first; a < last; ++a) {
        if (progress && (a - first) % 4096 == 0) progress(a - first);
        if (exclusive && claimed[a]) continue;
        const std::int64_t ta = ix.t[a];
        const std::int64_t t_end = ta + p.max_duration_us;
        const float xa = ix.x[a], ya = ix.y[a];
        const int g = ix.group[a];
        c.pos.clear();
        // Positions of ties at t_a start at `lo`; every candidate's position is >= lo.
        while (ix.t[lo] < ta) ++lo;
        std::uint32_t max_pos = 0;
        const int cx0 = std::max(0, static_cast<int>(std::floor((xa - reach) / ix.cell)));
        const int cx1 = std::min(ix.cells_x - 1, static_cast<int>(std::floor((xa + reach) / ix.cell)));
        const int cy0 = std::max(0, static_cast<int>(std::floor((ya - reach) / ix.cell)));
        const int cy1 = std::min(ix.cells_y - 1, static_cast<int>(std::floor((ya + reach) / ix.cell)));
        for (int cy = cy0; cy <= cy1; ++cy) {
            for (int cx = cx0; cx <= cx1; ++cx) {
                const std::size_t b = ix.bucket(g, cx, cy);
                const std::uint32_t last = ix.bucket_begin[b + 1];
                // Ties at t_a belong to the cylinder too, whatever their order. Anchors come
                // in time order, so each bucket's first corner at or after t_a only moves on.
                std::uint32_t& first = cursor[b];
                while (first != last && ix.t[ix.bucket_items[first]] < ta) ++first;
                for (std::uint32_t it = first; it != last && ix.t[ix.bucket_items[it]] <= t_end; ++it) {
                    const std::uint32_t i = ix.bucket_items[it];
                    const float ddx = ix.x[i] - xa, ddy = ix.y[i] - ya;
                    if (ddx * ddx + ddy * ddy <= reach2) {
                        c.pos.push_back(i);
                        max_pos = std::max(max_pos, i);
                    }
                }
            }
        }
        if (c.pos.size() < min_inner) continue;
        // Positions are in time order (ties by position), so ordering them orders by time:
        // through a bitmap of [lo, max_pos] when it is small beside the candidates, else by sort.
        const std::size_t words = (max_pos - lo) / 64 + 1;
        if (words <= 4 * c.pos.size()) {
            c.bits.assign(words, 0);
            for (const std::uint32_t i : c.pos) c.bits[(i - lo) / 64] |= std::uint64_t{1} << ((i - lo) % 64);
            std::size_t k = 0;
            for (std::size_t wi = 0; wi < words; ++wi)
                for (std::uint64_t word = c.bits[wi]; word != 0; word &= word - 1)
                    c.pos[k++] = static_cast<std::uint32_t>(lo + wi * 64 + static_cast<std::size_t>(std::countr_zero(word)));
        } else {
            std::sort(c.pos.begin(), c.pos.end());
        }
        const std::size_t m = c.pos.size();
        c.dx.resize(m);
        c.dy.resize(m);
        c.dt.resize(m);
        c.weight.resize(m);
        for (std::size_t k = 0; k < m; ++k) {
            const std::uint32_t i = c.pos[k];
            c.dx[k] = ix.x[i] - xa;
            c.dy[k] = ix.y[i] - ya;
            c.dt[k] = static_cast<float>(ix.t[i] - ta);
            c.weight[k] = exclusive && claimed[i] ? 0 : 1;
        }
        build_quadrants(c, margin);
        const float* dx = c.dx.data();
        const float* dy = c.dy.data();
        const float* dt = c.dt.data();
        const std::int32_t* w = c.weight.data();

        // Partners in time order; `end` is one past the last candidate with t <= t_b (every
        // quadrant's own end follows it). any: every accepted hypothesis flags its inner
        // corners at once. exclusive: the anchor keeps its accepted hypothesis with the most
        // inner corners, which claims them.
        std::size_t end = 0;
        std::int32_t best_inner = -1;
        std::size_t best_j = 0;
        bool flagged = false;
        for (std::size_t j = 0; j < m; ++j) {
            if (dt[j] <= 0.0f) continue;  // a pair needs t_b > t_a
            while (end < m && dt[end] <= dt[j]) ++end;
            if (end < min_inner) continue;  // fewer corners than needed in the whole time span
            if (w[j] == 0) continue;
            const float bx = dx[j], by = dy[j];
            if (bx * bx + by * by > len2) continue;
            const int qi = (bx < 0.0f ? 1 : 0) | (by < 0.0f ? 2 : 0);
            const QuadrantView q = c.view(qi);
            std::size_t& q_end = c.end[qi];
            while (q_end < c.size[qi] && q.dt[q_end] <= dt[j]) ++q_end;
            ++result.hypotheses;
            // Inner corners are among the q_end: too few cannot make a track.
            if (q_end < min_inner) continue;
            const Axis axis{bx, by, dt[j], 1.0f / dt[j], r_in2, r_out2};
            const Cylinder cyl = count(q, round_up(q_end), axis);
            const std::int32_t outer = cyl.within_outer - cyl.inner;
            if (cyl.inner < p.min_inner ||
                static_cast<double>(outer) > p.max_outer_ratio * static_cast<double>(cyl.inner))
                continue;
            ++result.accepted;
            if (!exclusive) {
                kern.mark(q, round_up(q_end), axis);
                flagged = true;
            } else if (cyl.inner > best_inner) {
                best_inner = cyl.inner;
                best_j = j;
            }
        }
        if (flagged) {
            for (int qi = 0; qi < 4; ++qi) {
                const std::size_t o = static_cast<std::size_t>(qi) * c.stride;
                for (std::size_t k = 0; k < c.size[qi]; ++k)
                    if (c.qinner[o + k]) on_track[c.pos[c.qlocal[o + k]]] = 1;
            }
        }
        if (exclusive && best_inner >= 0) {
            // The best hypothesis claims its inner corners (scalar: once per anchor).
            const float bx = dx[best_j], by = dy[best_j];
            const int qi = (bx < 0.0f ? 1 : 0) | (by < 0.0f ? 2 : 0);
            const QuadrantView q = c.view(qi);
            const std::uint32_t* local = c.qlocal.data() + static_cast<std::size_t>(qi) * c.stride;
            const float inv = 1.0f / dt[best_j];
            for (std::size_t k = 0; k < c.size[qi] && q.dt[k] <= dt[best_j]; ++k) {
                const float s = q.dt[k] * inv;
                const float ex = q.dx[k] - bx * s, ey = q.dy[k] - by * s;
                if (ex * ex + ey * ey <= r_in2 && q.weight[k] != 0) {
                    const std::uint32_t i = c.pos[local[k]];
                    on_track[i] = 1;
                    claimed[i] = 1;
                }
            }
        }
    }
}

FeatureTrackResult label(std::span<const Event> corners, const FeatureTrackParams& p, const Kernels& kern,
                         const LabelProgress& progress = {}) {
    validate(p);
    if (corners.size() >= std::numeric_limits<std::uint32_t>::max())
        throw std::invalid_argument("feature tracks: at most 2^32 - 2 corner events");
    FeatureTrackResult result;
    const std::size_t n = corners.size();
    result.on_track.assign(n, 0);
    if (n == 0) return result;
    // Time order, ties by input position; a copy only when the input is not in it already.
    std::vector<std::uint32_t> order;
    std::vector<Event> sorted;
    std::span<const Event> in_order = corners;
    const bool is_sorted =
        std::is_sorted(corners.begin(), corners.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
    if (!is_sorted) {
        order.resize(n);
        std::iota(order.begin(), order.end(), 0u);
        std::stable_sort(order.begin(), order.end(),
                         [&](std::uint32_t a, std::uint32_t b) { return corners[a].t < corners[b].t; });
        sorted.resize(n);
        for (std::size_t i = 0; i < n; ++i) sorted[i] = corners[order[i]];
        in_order = sorted;
    }
    std::vector<std::uint8_t> on_track(n, 0);  // by time-order position
    std::vector<std::uint8_t> claimed(p.overlap == TrackOverlap::exclusive ? n : 0, 0);
    Counts counts;
    std::function<void(std::size_t)> tell;
    if (progress) tell = [&](std::size_t done) { progress(done, n); };
    process_anchors(in_order, 0, n, on_track.data(), claimed.data(), p, kern, counts, tell);
    result.hypotheses = counts.hypotheses;
    result.accepted = counts.accepted;
    for (std::size_t i = 0; i < n; ++i) {
        result.on_track[is_sorted ? i : order[i]] = on_track[i];
        result.labelled += on_track[i];
    }
    if (progress) progress(n, n);
    return result;
}

const Kernels& kernels_named(std::string_view path) {
    if (path.empty()) return chosen_kernels();
    for (const Kernels& k : all_kernels())
        if (path == k.name) return k;
    throw std::invalid_argument("feature tracks: code path '" + std::string(path) + "' does not run on this CPU");
}

}  // namespace

FeatureTrackResult label_feature_tracks(std::span<const Event> corners, const FeatureTrackParams& p) {
    return label(corners, p, chosen_kernels());
}

FeatureTrackResult label_feature_tracks(std::span<const Event> corners, const FeatureTrackParams& p,
                                        const LabelProgress& progress) {
    return label(corners, p, chosen_kernels(), progress);
}

// The window: corner events from the first one whose label may still change (time order,
// as pushed), with their labels and claims so far. Positions [0, done) have been anchors
// already (ties in time with the first anchor still to run).
struct FeatureTrackStream::State {
    FeatureTrackParams params;
    const Kernels* kern = nullptr;
    std::vector<Event> window;
    std::vector<std::uint8_t> on_track, claimed;
    std::size_t done = 0;
    std::vector<std::uint8_t> out;  // labels made final by the current call
    std::uint64_t pushed = 0, labelled = 0;
    Counts counts;
    std::size_t max_retained = 0;
    bool finished = false;

    // Runs the anchors [done, last) and hands out the labels of the corners no later
    // anchor can reach (earlier than the first anchor left).
    void run(std::size_t last) {
        const bool exclusive = params.overlap == TrackOverlap::exclusive;
        process_anchors(window, done, last, on_track.data(), exclusive ? claimed.data() : nullptr, params, *kern,
                        counts);
        std::size_t final_count = window.size();
        if (last < window.size()) {
            const std::int64_t next = window[last].t;
            final_count = static_cast<std::size_t>(
                std::lower_bound(window.begin(), window.end(), next,
                                 [](const Event& e, std::int64_t t) { return e.t < t; }) -
                window.begin());
        }
        const auto k = static_cast<std::ptrdiff_t>(final_count);
        out.insert(out.end(), on_track.begin(), on_track.begin() + k);
        labelled += static_cast<std::uint64_t>(std::count(on_track.begin(), on_track.begin() + k, 1));
        window.erase(window.begin(), window.begin() + k);
        on_track.erase(on_track.begin(), on_track.begin() + k);
        if (exclusive) claimed.erase(claimed.begin(), claimed.begin() + k);
        done = last - final_count;
    }
};

FeatureTrackStream::FeatureTrackStream(const FeatureTrackParams& params, std::string_view path)
    : s_(std::make_unique<State>()) {
    validate(params);
    s_->params = params;
    s_->kern = &kernels_named(path);
}

FeatureTrackStream::~FeatureTrackStream() = default;
FeatureTrackStream::FeatureTrackStream(FeatureTrackStream&&) noexcept = default;
FeatureTrackStream& FeatureTrackStream::operator=(FeatureTrackStream&&) noexcept = default;

std::span<const std::uint8_t> FeatureTrackStream::push(std::span<const Event> corners) {
    State& s = *s_;
    if (s.finished) throw std::logic_error("feature tracks: push() after finish()");
    s.out.clear();
    // Time order first, so that a refused batch changes nothing.
    std::int64_t prev = s.window.empty() ? std::numeric_limits<std::int64_t>::min() : s.window.back().t;
    for (std::size_t i = 0; i < corners.size(); ++i) {
        if (corners[i].t < prev)
            throw std::invalid_argument("feature tracks: corner event " + std::to_string(s.pushed + i) + " (t = " +
                                        std::to_string(corners[i].t) +
                                        " us) is earlier than the one before it (t = " + std::to_string(prev) +
                                        " us); the stream must be in time order");
        prev = corners[i].t;
    }
    if (s.window.size() + corners.size() >= std::numeric_limits<std::uint32_t>::max())
        throw std::invalid_argument("feature tracks: at most 2^32 - 2 corner events within one window");
    s.window.insert(s.window.end(), corners.begin(), corners.end());
    s.on_track.resize(s.window.size(), 0);
    if (s.params.overlap == TrackOverlap::exclusive) s.claimed.resize(s.window.size(), 0);
    s.pushed += corners.size();
    if (!s.window.empty()) {
        // Anchors whose every reachable corner is here: t_a + max_duration < the latest t
        // (a later push may still bring ties at the latest t).
        const std::int64_t latest = s.window.back().t;
        const auto ready = static_cast<std::size_t>(
            std::lower_bound(s.window.begin(), s.window.end(), latest - s.params.max_duration_us,
                             [](const Event& e, std::int64_t t) { return e.t < t; }) -
            s.window.begin());
        // Each run indexes the whole window: run when it has at least as many anchors to do
        // as corners it only reads (and at least 4096), so indexing costs O(1) per anchor.
        const std::size_t todo = ready > s.done ? ready - s.done : 0;
        if (todo > 0 && todo >= std::max<std::size_t>(4096, s.window.size() - todo)) s.run(ready);
    }
    s.max_retained = std::max(s.max_retained, s.window.size());
    return s.out;
}

std::span<const std::uint8_t> FeatureTrackStream::finish() {
    State& s = *s_;
    s.out.clear();
    if (!s.finished) {
        s.finished = true;
        if (!s.window.empty()) s.run(s.window.size());
        s.window = {};
        s.on_track = {};
        s.claimed = {};
    }
    return s.out;
}

std::uint64_t FeatureTrackStream::corners() const noexcept { return s_->pushed; }
std::uint64_t FeatureTrackStream::labelled() const noexcept { return s_->labelled; }
std::uint64_t FeatureTrackStream::hypotheses() const noexcept { return s_->counts.hypotheses; }
std::uint64_t FeatureTrackStream::accepted() const noexcept { return s_->counts.accepted; }
std::size_t FeatureTrackStream::retained() const noexcept { return s_->window.size(); }
std::size_t FeatureTrackStream::max_retained() const noexcept { return s_->max_retained; }

const char* feature_track_code_path() noexcept { return chosen_kernels().name; }

std::vector<std::string> feature_track_code_paths() {
    std::vector<std::string> names;
    for (const Kernels& k : all_kernels()) names.emplace_back(k.name);
    return names;
}

FeatureTrackResult label_feature_tracks_on_path(std::string_view path, std::span<const Event> corners,
                                                const FeatureTrackParams& p) {
    return label(corners, p, kernels_named(path));
}

}  // namespace evcorner::eval
