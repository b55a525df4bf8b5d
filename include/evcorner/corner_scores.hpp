#pragma once
// Scores for the two binary detectors, eFAST and Arc* (docs/scores.md), computed from the
// detector's own state at the event's time: its SAE (stored values, sae.hpp) on the two
// circles around the event. Only for corner events, after the binary decision, so that
// the binary paths never pay for them.
//
// Both scores share one form:  S = (16 - L3) + (20 - L4) - 15 + f,  f in [0, 1)
//  - L3, L4: the angular extent (in circle pixels) of the corner on the radius-3 and
//    radius-4 circle. The shorter the arc of newest pixels, the farther the pattern is
//    from a straight edge (an edge splits a circle in halves: 8 of 16, 10 of 20): the
//    integer part is ANMS's eFAST score (Zhou et al. 2023), 7 (L3 = 6, L4 = 8, the
//    bluntest corner) to 14 (L3 = 3, L4 = 4, the sharpest).
//  - f: how cleanly the arc stands out in time, the normalised timestamp margin
//    (oldest of the arc - newest of the rest) / (now - newest of the rest + 1), the
//    smaller of the two circles', clamped to [0, 1). It only orders corners of equal
//    arc lengths (a tie-breaker without units: no time constant).
// eFAST: L = the shortest arc length that fires on the circle (the firing arc of length L
// is the L newest pixels, all strictly newer than the rest). Arc*: L = min(size, N -
// size) for the final arc size of its growth (a majority arc's corner is its complement).

#include <algorithm>
#include <bit>
#include <cstdint>
#include <utility>

#include "evcorner/arc_test.hpp"
#include "evcorner/circle.hpp"
#include "evcorner/cpu_paths.hpp"

namespace evcorner {

namespace detail {
// (a - b) / (now - b + 1) in [0, 1): a the arc's oldest, b the rest's newest, stored values.
inline double time_margin(std::int64_t a, std::int64_t b, std::int64_t now) noexcept {
    if (a <= b) return 0.0;
    const double num = static_cast<double>(a - b);
    const double den = static_cast<double>(std::max(now, a) - b) + 1.0;
    const double f = num / den;
    // At most 1 - 2^-40, so that adding the integer part (7..14) stays below the next integer.
    constexpr double kBelowOne = 1.0 - 0x1p-40;
    return f < kBelowOne ? f : kBelowOne;
}

struct ArcExtent {
    int length = 0;      ///< 0: no arc in range
    double margin = 0;   ///< time_margin of that arc
};

// eFAST on one circle: the shortest firing length in Lmin..Lmax and its margin, on the
// doubled circle d[0..2N) (d[i] = d[i + N]: no modulo) with k its first newest pixel.
// The arc grows from k towards the newer neighbour (ties: right), Lmax - 1 steps; at
// length L it fires when its oldest is strictly newer than the rest's newest. The rest at
// length L is the pixels that join later (joined[L + 1 .. Lmax]) and those that never join
// (one cyclic segment), so the rest's newest for every L comes from suffix maxima of the
// joining order and one scan: O(N) in all. A firing arc is the L newest pixels of the
// circle, so the first L that fires is the definition's shortest (naive/scores_naive.hpp
// writes it plainly).
template <int N, int Lmin, int Lmax>
inline ArcExtent efast_arc_extent_doubled(const std::int64_t* d, int k, std::int64_t now) noexcept {
    static_assert(1 <= Lmin && Lmin <= Lmax && Lmax < N);
    // The arc is [k - a, k + b] (a + b + 1 pixels): its left neighbour is d[k + N - a - 1],
    // its right one d[k + b + 1], both within d.
    int a = 0, b = 0;
    std::int64_t oldest[Lmax + 1];  // oldest[L]: the arc's oldest at length L
    std::int64_t joined[Lmax + 1];  // joined[L]: the pixel that joins at length L
    oldest[1] = d[k];
    joined[1] = d[k];
#pragma GCC unroll 8
    for (int len = 2; len <= Lmax; ++len) {
        const std::int64_t l = d[k + N - a - 1];
        const std::int64_t r = d[k + b + 1];
        const bool go_left = l > r;
        a += go_left;
        b += !go_left;
        const std::int64_t v = go_left ? l : r;
        joined[len] = v;
        oldest[len] = std::min(oldest[len - 1], v);
    }
    // The pixels that never join: d[k + b + 1 .. k + N - a - 1], N - Lmax of them.
    std::int64_t rest = INT64_MIN;
    for (int j = k + b + 1; j < k + N - a; ++j) rest = std::max(rest, d[j]);
    // From the longest arc down: rest_newest[L] = max(rest, joined[L + 1 .. Lmax]).
    std::int64_t rest_newest[Lmax + 1];
    for (int len = Lmax; len >= Lmin; --len) {
        rest_newest[len] = rest;
        rest = std::max(rest, joined[len]);
    }
    for (int len = Lmin; len <= Lmax; ++len)
        if (oldest[len] > rest_newest[len]) return {len, time_margin(oldest[len], rest_newest[len], now)};
    return {};
}

// The circle t[0..N) twice into d[0..2N) (no modulo along an arc); returns the index of
// its first newest pixel. (Both arc extents below start from it.)
template <int N>
inline int doubled_circle(const std::int64_t* t, std::int64_t* d) noexcept {
    int k = 0;
    for (int i = 0; i < N; ++i) {
        d[i] = d[i + N] = t[i];
        if (t[i] > t[k]) k = i;
    }
    return k;
}

// The same on one circle t[0..N).
template <int N, int Lmin, int Lmax>
inline ArcExtent efast_arc_extent(const std::int64_t* t, std::int64_t now) noexcept {
    std::int64_t d[2 * N];
    const int k = doubled_circle<N>(t, d);
    return efast_arc_extent_doubled<N, Lmin, Lmax>(d, k, now);
}

// Arc* on one circle t[0..N): its growth (arcstar_test.hpp) written plainly on a doubled
// copy of the circle (no modulo), recording the times in the order in which pixels join,
// then min(size, N - size) and the margin of the final arc.
template <int N, int Lmin>
inline ArcExtent arcstar_arc_extent(const std::int64_t* t, std::int64_t now) noexcept {
    std::int64_t d[2 * N];
    const int k = doubled_circle<N>(t, d);
    std::int64_t joined[N];  // joined[i]: the time of the i-th pixel to join
    joined[0] = t[k];
    // The clockwise frontier d[cw] moves up from k + 1, the counter-clockwise one d[ccw]
    // down from k + N - 1: both stay within d over the N - 1 steps.
    int cw = k + 1, ccw = k + N - 1;
    std::int64_t min_cw = d[cw], min_ccw = d[ccw];
    std::int64_t seg = t[k];
    int size = Lmin;
    for (int it = 1; it < N; ++it) {
        const bool go_cw = d[cw] > d[ccw];
        const std::int64_t v = go_cw ? d[cw] : d[ccw];
        const std::int64_t side_min = go_cw ? min_cw : min_ccw;
        if (it < Lmin) {
            seg = std::min(seg, side_min);
        } else if (v >= seg) {
            size = it + 1;
            seg = std::min(seg, side_min);
        }
        joined[it] = v;
        if (go_cw) {
            ++cw;
            min_cw = std::min(min_cw, d[cw]);
        } else {
            --ccw;
            min_ccw = std::min(min_ccw, d[ccw]);
        }
    }
    std::int64_t in_oldest = INT64_MAX, out_newest = INT64_MIN;
    for (int i = 0; i < N; ++i) {
        if (i < size) in_oldest = std::min(in_oldest, joined[i]);
        else out_newest = std::max(out_newest, joined[i]);
    }
    // A majority arc: the corner is the complement (older inside than the arc around it).
    const bool majority = 2 * size > N;
    const double m = majority ? 0.0 : time_margin(in_oldest, out_newest, now);
    return {majority ? N - size : size, size == N ? 0.0 : m};
}

template <int N, class Circle>
inline void gather(const std::int64_t* centre, std::ptrdiff_t width, const Circle& circle, std::int64_t* t) noexcept {
    for (int k = 0; k < N; ++k) t[k] = centre[circle[k].dy * width + circle[k].dx];
}

// gather() into a doubled circle d[0..2N); returns the first newest pixel's index.
template <int N, class Circle>
inline int gather_doubled(const std::int64_t* centre, std::ptrdiff_t width, const Circle& circle,
                          std::int64_t* d) noexcept {
    int k = 0;
    std::int64_t newest = INT64_MIN;
#pragma GCC unroll 20
    for (int i = 0; i < N; ++i) {
        const std::int64_t v = centre[circle[i].dy * width + circle[i].dx];
        d[i] = v;
        d[i + N] = v;
        if (v > newest) {
            newest = v;
            k = i;
        }
    }
    return k;
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// eFAST's score on the AVX-512 path (Avx512Search, arc_test.hpp), for a corner only: the
// binary test computes, for every arc length L in range and every start s, whether the arc
// t[s .. s+L-1] fires (its oldest newer than the rest's newest), and keeps only "any". Run
// again keeping one bit mask per length, it gives the score with the circle in registers
// (no gather into memory, no data-dependent branch): L = the shortest length whose mask is
// not empty (the definition's shortest firing arc), s = its one start (the L newest pixels
// are one set, so one arc), and the arc's oldest and the rest's newest are masked
// reductions. Only for code compiled for AVX-512 (the scored AVX-512 loop of efast.cpp).
EVCORNER_AVX512_WARNINGS_OFF
struct Avx512Scored {
    using C16 = Avx512Search::Circle16;
    using C20 = Avx512Search::Circle20;
    // Bit s of m[L - Lmin]: the arc of length L from pixel s fires.
    template <int Lmin, int Lmax>
    struct Masks {
        unsigned m[Lmax - Lmin + 1];
    };

    // Bit k (k < N): a > b in lane k.
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline unsigned greater(const C16& a, const C16& b) noexcept {
        return static_cast<unsigned>(_mm512_cmpgt_epi64_mask(a.v[0], b.v[0])) |
               static_cast<unsigned>(_mm512_cmpgt_epi64_mask(a.v[1], b.v[1])) << 8;
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline unsigned greater(const C20& a, const C20& b) noexcept {
        // Pixels 16..19 are the first four lanes of the third vector (its others repeat 0..3).
        return static_cast<unsigned>(_mm512_cmpgt_epi64_mask(a.v[0], b.v[0])) |
               static_cast<unsigned>(_mm512_cmpgt_epi64_mask(a.v[1], b.v[1])) << 8 |
               (static_cast<unsigned>(_mm512_cmpgt_epi64_mask(a.v[2], b.v[2])) & 0xFu) << 16;
    }

    // Avx512Search::fires() keeping a mask per length: the same sliding minima and maxima.
    template <int N, int Lmin, int Lmax, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline Masks<Lmin, Lmax> masks(const C& t) noexcept {
        Masks<Lmin, Lmax> r;
        [&]<int... I>(std::integer_sequence<int, I...>) {
            ((r.m[I] = greater(Avx512Search::sliding<Lmin + I, false>(t),
                               Avx512Search::sliding<N - Lmin - I, true>(t).template rot<Lmin + I>())),
             ...);
        }(std::make_integer_sequence<int, Lmax - Lmin + 1>{});
        return r;
    }

    // The oldest (Max = false) or newest of the pixels whose bit is set in `in`.
    template <bool Max>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline std::int64_t reduce(const C16& t, unsigned in) noexcept {
        const __m512i fill = _mm512_set1_epi64(Max ? INT64_MIN : INT64_MAX);
        const __m512i a = _mm512_mask_blend_epi64(static_cast<__mmask8>(in), fill, t.v[0]);
        const __m512i b = _mm512_mask_blend_epi64(static_cast<__mmask8>(in >> 8), fill, t.v[1]);
        return Max ? _mm512_reduce_max_epi64(_mm512_max_epi64(a, b)) : _mm512_reduce_min_epi64(_mm512_min_epi64(a, b));
    }
    template <bool Max>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline std::int64_t reduce(const C20& t, unsigned in) noexcept {
        const __m512i fill = _mm512_set1_epi64(Max ? INT64_MIN : INT64_MAX);
        const __m512i a = _mm512_mask_blend_epi64(static_cast<__mmask8>(in), fill, t.v[0]);
        const __m512i b = _mm512_mask_blend_epi64(static_cast<__mmask8>(in >> 8), fill, t.v[1]);
        const __m512i c = _mm512_mask_blend_epi64(static_cast<__mmask8>((in >> 16) & 0xFu), fill, t.v[2]);
        return Max ? _mm512_reduce_max_epi64(_mm512_max_epi64(_mm512_max_epi64(a, b), c))
                   : _mm512_reduce_min_epi64(_mm512_min_epi64(_mm512_min_epi64(a, b), c));
    }

    // The shortest firing arc of a corner's circle `t` (N pixels in registers): the shortest
    // length whose mask has a bit, the one start s there (the L newest pixels are one set),
    // the arc's oldest and the rest's newest by masked reductions. No data-dependent branch.
    template <int N, int Lmin, int Lmax, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline ArcExtent extent(const C& t, std::int64_t now) noexcept {
        const Masks<Lmin, Lmax> m = masks<N, Lmin, Lmax>(t);
        unsigned lengths = 0;  // bit i: some arc of length Lmin + i fires
        for (int i = 0; i <= Lmax - Lmin; ++i) lengths |= static_cast<unsigned>(m.m[i] != 0) << i;
        if (lengths == 0) return {};  // not a corner (never for the events scored)
        const int i = __builtin_ctz(lengths);
        const int len = Lmin + i;
        const int s = __builtin_ctz(m.m[i]);
        constexpr unsigned kAll = (1u << N) - 1;
        const unsigned run = (1u << len) - 1;
        const unsigned arc = ((run << s) | (run >> (N - s))) & kAll;  // pixels s .. s+len-1 (mod N)
        return {len, time_margin(reduce<false>(t, arc), reduce<true>(t, ~arc & kAll), now)};
    }
};
EVCORNER_AVX512_WARNINGS_ON
#endif

inline double combine(ArcExtent c3, ArcExtent c4) noexcept {
    return static_cast<double>((16 - c3.length) + (20 - c4.length) - 15) + std::min(c3.margin, c4.margin);
}
}  // namespace detail

/// eFAST's score of a corner event whose SAE cell is `centre` (stored form, row stride
/// `width`), at stored time `now`. For a non-corner the value means nothing.
inline double efast_score(const std::int64_t* centre, std::ptrdiff_t width, std::int64_t now) noexcept {
    std::int64_t d3[32], d4[40];
    const int k3 = detail::gather_doubled<16>(centre, width, kCircle3, d3);
    const int k4 = detail::gather_doubled<20>(centre, width, kCircle4, d4);
    return detail::combine(detail::efast_arc_extent_doubled<16, 3, 6>(d3, k3, now),
                           detail::efast_arc_extent_doubled<20, 4, 8>(d4, k4, now));
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
/// efast_score() on the AVX-512 path: the circles around `centre` (pixel k of each at
/// centre[off3[k]], centre[off4[k]]) in registers, Avx512Search's arc test keeping its
/// masks, the score from them. Only for code compiled for AVX-512.
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] inline double efast_score_avx512(const std::int64_t* centre,
                                                                      const std::int64_t* off3,
                                                                      const std::int64_t* off4,
                                                                      std::int64_t now) noexcept {
    using S = detail::Avx512Scored;
    return detail::combine(S::extent<16, 3, 6>(Avx512Search::load16(centre, off3), now),
                           S::extent<20, 4, 8>(Avx512Search::load20(centre, off4), now));
}
#endif

/// Arc*'s score of a corner event whose filtered-SAE cell is `centre`, at stored time `now`.
inline double arcstar_score(const std::int64_t* centre, std::ptrdiff_t width, std::int64_t now) noexcept {
    std::int64_t t3[16], t4[20];
    detail::gather<16>(centre, width, kCircle3, t3);
    detail::gather<20>(centre, width, kCircle4, t4);
    return detail::combine(detail::arcstar_arc_extent<16, 3>(t3, now), detail::arcstar_arc_extent<20, 4>(t4, now));
}

}  // namespace evcorner
