#pragma once
// The eFAST arc test on one circle of SAE timestamps.
//
// A circle of N timestamps T[0..N) (cyclic) *fires* when some contiguous arc of length
// L, Lmin <= L <= Lmax, has its oldest timestamp strictly newer than every timestamp on
// the rest of the circle (Mueggler et al., BMVC 2017, Sec. 2.2; docs/algorithms.md).
//
// arc_fires() is the linear-time form: a firing arc holds the circle's newest pixel and
// is exactly the set of the L newest pixels. Grow an arc from the newest pixel, always
// taking the newer of its two neighbours; at each length L in range the arc fires iff
// its oldest is strictly newer than every pixel outside it. Any arc that
// fires is found this way, because while the grown arc is a proper part of the firing
// set, one of its neighbours is in that set and newer than everything outside it.
// Before growing, an exact cheap test rejects most circles (see arc_fires_from()).
// arc_fires_naive() is the definition written plainly; tests hold the two together.

#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define EVCORNER_HAVE_AVX2_SEARCH 1
#endif

namespace evcorner {

namespace detail {
// Branch-free select: the per-event paths must not mispredict on data.
inline int select(bool c, int a, int b) noexcept {
    const int m = -static_cast<int>(c);
    return (a & m) | (b & ~m);
}
inline std::int64_t select(bool c, std::int64_t a, std::int64_t b) noexcept {
    const std::int64_t m = -static_cast<std::int64_t>(c);
    return (a & m) | (b & ~m);
}
inline std::int64_t max(std::int64_t a, std::int64_t b) noexcept { return a > b ? a : b; }
inline std::int64_t min(std::int64_t a, std::int64_t b) noexcept { return a < b ? a : b; }

// A value and its position on the circle; newer() keeps the newer of two.
struct Newest {
    std::int64_t t;
    int k;
};
inline Newest newer(Newest a, Newest b) noexcept {
#if defined(__x86_64__) && defined(__GNUC__)
    // One compare, two conditional moves. Written out because the compiler, left to
    // itself, turns some of these selects into branches, and they mispredict.
    __asm__("cmpq %[bt], %[at]\n\t"
            "cmovlq %[bt], %[at]\n\t"
            "cmovll %[bk], %[ak]"
            : [at] "+r"(a.t), [ak] "+r"(a.k)
            : [bt] "r"(b.t), [bk] "r"(b.k)
            : "cc");
    return a;
#else
    const bool g = b.t > a.t;
    return {max(a.t, b.t), select(g, b.k, a.k)};
#endif
}
// The newest of t[K...] by a balanced tournament: N-1 comparisons in log2(N) rounds
// rather than one serial chain of N.
template <int Lo, int Hi>
inline Newest newest_of(const std::int64_t* t) noexcept {
    if constexpr (Hi - Lo == 1) {
        return {t[Lo], Lo};
    } else {
        constexpr int Mid = Lo + (Hi - Lo) / 2;
        return newer(newest_of<Lo, Mid>(t), newest_of<Mid, Hi>(t));
    }
}
}  // namespace detail

template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_grows_from(const std::int64_t* t, int c, std::int64_t opposite) noexcept;

/// The arc test given the circle twice (t[k] == t[k + N], so that no index along an
/// arc needs a modulo) and the index of one of its newest pixels.
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires_from(const std::int64_t* t, int newest) noexcept {
    static_assert(2 <= Lmin && Lmin <= Lmax && 2 * Lmax - 2 < N);
    using detail::max;
    using detail::min;
    // Centre the work on a copy of the newest pixel whose +-(Lmax-1) neighbourhood
    // and opposite side all lie inside [0, 2N).
    const int c = newest + N * static_cast<int>(newest < Lmax);

    // Cheap rejection, exact: a firing arc holds the newest pixel and at least Lmin
    // pixels, so its oldest is at most `bound`, the best oldest of the Lmin-windows
    // through c; and it spans at most Lmax pixels, so the pixels Lmax or more steps
    // from c lie outside it and must all be older than its oldest.
    std::int64_t bound = INT64_MIN;
    for (int s = 0; s < Lmin; ++s) {
        std::int64_t w = t[c - s];
        for (int k = 1; k < Lmin; ++k) w = min(w, t[c - s + k]);
        bound = max(bound, w);
    }
    std::int64_t opposite = t[c + Lmax];
    for (int k = c + Lmax + 1; k <= c + N - Lmax; ++k) opposite = max(opposite, t[k]);
    if (opposite >= bound) return false;
    return arc_grows_from<N, Lmin, Lmax>(t, c, opposite);
}

/// The rest of arc_fires_from() once the cheap test has passed: `c` is a copy of the
/// newest pixel as arc_fires_from() centres it, `opposite` the newest of t[c+Lmax ..
/// c+N-Lmax].
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_grows_from(const std::int64_t* t, int c, std::int64_t opposite) noexcept {
    using detail::max;
    using detail::min;
    // The arc [c-a, c+b] (a, b < Lmax) leaves outside it the pixels c+b+1 .. c+N-a-1,
    // that is right[b] = newest of t[c+b+1 .. c+N-Lmax] and left[a] = newest of
    // t[c-Lmax+1 .. c-a-1]: suffix maxima, so that each length costs O(1) below.
    std::int64_t right[Lmax];
    std::int64_t left[Lmax];
    right[Lmax - 1] = opposite;
    left[Lmax - 1] = INT64_MIN;
#pragma GCC unroll 8
    for (int j = Lmax - 2; j >= 0; --j) {
        right[j] = max(right[j + 1], t[c + j + 1]);
        left[j] = max(left[j + 1], t[c - j - 1]);
    }

    // Grow the arc from c, taking the newer neighbour each time; at each length in
    // range it fires iff its oldest is strictly newer than everything outside it.
    // Branch-free: the outcome is data, and data mispredicts.
    int a = 0;
    int b = 0;
    std::int64_t oldest = t[c];
    bool fires = false;
#pragma GCC unroll 8
    for (int len = 2; len <= Lmax; ++len) {
        const std::int64_t l = t[c - a - 1];
        const std::int64_t r = t[c + b + 1];
        const bool go_left = l > r;
        a += go_left;
        b += !go_left;
        oldest = min(oldest, max(l, r));
        if (len >= Lmin) fires |= oldest > max(left[a], right[b]);
    }
    return fires;
}

/// How circle_fires() finds one newest pixel of t[0..N): the portable way, a tournament.
// newest() also completes the second copy t[N..2N) of t[0..N).
struct ScalarSearch {
    template <int N>
    static int newest(std::int64_t* t) noexcept {
#pragma GCC unroll 32
        for (int k = 0; k < N; ++k) t[k + N] = t[k];
        return detail::newest_of<0, N>(t).k;
    }
};

#ifdef EVCORNER_HAVE_AVX2_SEARCH
/// The same with AVX2: the maximum of the circle by four-wide compares, then the first
/// lane equal to it. Only for code compiled for AVX2 (efast.cpp picks it at run time
/// after checking the CPU; the function that inlines it carries target("avx2")).
struct Avx2Search {
    [[gnu::target("avx2"), gnu::always_inline]] static inline __m256i max(__m256i a, __m256i b) noexcept {
        return _mm256_blendv_epi8(b, a, _mm256_cmpgt_epi64(a, b));
    }
    template <int N>
    [[gnu::target("avx2")]] static int newest(std::int64_t* t) noexcept {
        static_assert(N % 4 == 0);
        __m256i v[N / 4];
        for (int i = 0; i < N / 4; ++i) {
            v[i] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(t + 4 * i));
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(t + N + 4 * i), v[i]);
        }
        __m256i m = v[0];
        for (int i = 1; i < N / 4; ++i) m = max(m, v[i]);
        m = max(m, _mm256_permute4x64_epi64(m, 0x4E));  // swap the 128-bit halves
        m = max(m, _mm256_shuffle_epi32(m, 0x4E));      // swap the 64-bit lanes
        unsigned mask = 0;
        for (int i = 0; i < N / 4; ++i)
            mask |= static_cast<unsigned>(_mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(v[i], m))))
                    << (4 * i);
        return __builtin_ctz(mask);
    }
};

#define EVCORNER_AVX512_TARGET "avx512f,avx512vl,avx512bw,avx512dq,avx2,bmi,bmi2,popcnt,lzcnt"
/// AVX-512 (F, VL, BW, DQ): each circle's whole arc test for all its arcs at once
/// (circle16_fires, circle20_fires), with native 64-bit min/max, lane rotations and
/// compares into mask registers.
struct Avx512Search {
    // A 16-pixel circle as two vectors: lo = t[0..8), hi = t[8..16).
    struct V16 {
        __m512i lo, hi;
    };
    // t[k + J] for every k (cyclic).
    template <int J>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline V16 rot(V16 v) noexcept {
        if constexpr (J == 0) return v;
        else if constexpr (J < 8) return {_mm512_alignr_epi64(v.hi, v.lo, J), _mm512_alignr_epi64(v.lo, v.hi, J)};
        else if constexpr (J == 8) return {v.hi, v.lo};
        else return {_mm512_alignr_epi64(v.lo, v.hi, J - 8), _mm512_alignr_epi64(v.hi, v.lo, J - 8)};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline V16 vmin(V16 a, V16 b) noexcept {
        return {_mm512_min_epi64(a.lo, b.lo), _mm512_min_epi64(a.hi, b.hi)};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline V16 vmax(V16 a, V16 b) noexcept {
        return {_mm512_max_epi64(a.lo, b.lo), _mm512_max_epi64(a.hi, b.hi)};
    }

    /// circle_fires<16, 3, 6> with the pixels at centre[offsets[k]], by the definition
    /// itself, for every arc at once and without a branch: the arc of length L starting at
    /// pixel s fires iff min(t[s .. s+L-1]) > max(t[s+L .. s+15]). Sliding minima of
    /// lengths 3..6 and sliding maxima of lengths 10..13 are built from lane rotations
    /// (each window from two shorter ones); 4 compares of 16 lanes decide. About 65
    /// vector instructions, against a data-dependent branch and the arc growth of
    /// arc_fires_from(). Only for code compiled for AVX-512.
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline bool circle16_fires(const std::int64_t* centre,
                                                                           const std::int64_t* offsets) noexcept {
        // Loaded one by one into the vectors: two vpgatherqq were slower, and a copy
        // through memory stalls on store forwarding.
        const std::int64_t* o = offsets;
        const V16 t{_mm512_set_epi64(centre[o[7]], centre[o[6]], centre[o[5]], centre[o[4]], centre[o[3]],
                                     centre[o[2]], centre[o[1]], centre[o[0]]),
                    _mm512_set_epi64(centre[o[15]], centre[o[14]], centre[o[13]], centre[o[12]], centre[o[11]],
                                     centre[o[10]], centre[o[9]], centre[o[8]])};
        const V16 r1 = rot<1>(t), r2 = rot<2>(t), r4 = rot<4>(t);
        // wL[s] = min(t[s .. s+L-1]): the oldest of the arc of length L from s.
        const V16 w2 = vmin(t, r1);
        const V16 w3 = vmin(w2, r2);
        const V16 w4 = vmin(w2, rot<2>(w2));
        const V16 w5 = vmin(w4, r4);
        const V16 w6 = vmin(w4, rot<4>(w2));
        // xM[s] = max(t[s .. s+M-1]); the rest of the arc (L, s) is x(16-L)[s+L].
        const V16 x2 = vmax(t, r1);
        const V16 x3 = vmax(x2, r2);
        const V16 x4 = vmax(x2, rot<2>(x2));
        const V16 x5 = vmax(x4, r4);
        const V16 x8 = vmax(x4, rot<4>(x4));
        const V16 rest3 = rot<3>(vmax(x8, rot<8>(x5)));  // max(t[s+3 .. s+15])
        const V16 rest4 = rot<4>(vmax(x8, rot<8>(x4)));  // max(t[s+4 .. s+15])
        const V16 rest5 = rot<5>(vmax(x8, rot<8>(x3)));  // max(t[s+5 .. s+15])
        const V16 rest6 = rot<6>(vmax(x8, rot<8>(x2)));  // max(t[s+6 .. s+15])
        const __mmask8 lo = _mm512_cmpgt_epi64_mask(w3.lo, rest3.lo) | _mm512_cmpgt_epi64_mask(w4.lo, rest4.lo) |
                            _mm512_cmpgt_epi64_mask(w5.lo, rest5.lo) | _mm512_cmpgt_epi64_mask(w6.lo, rest6.lo);
        const __mmask8 hi = _mm512_cmpgt_epi64_mask(w3.hi, rest3.hi) | _mm512_cmpgt_epi64_mask(w4.hi, rest4.hi) |
                            _mm512_cmpgt_epi64_mask(w5.hi, rest5.hi) | _mm512_cmpgt_epi64_mask(w6.hi, rest6.hi);
        return (lo | hi) != 0;
    }

    // A 20-pixel circle, periodically extended to 32 lanes: lane m holds t[m mod 20], in
    // four vectors (t[0..8), t[8..16), t[16..20) t[0..4), t[4..12)). Any 8 cyclically
    // consecutive pixels t[a..a+8) (a < 20) are then lanes a..a+8 < 32: one valignq.
    struct V20 {
        __m512i v[4];
    };
    template <int A>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline __m512i window20(const V20& x) noexcept {
        static_assert(A >= 0 && A < 20);
        if constexpr (A % 8 == 0) return x.v[A / 8];
        else return _mm512_alignr_epi64(x.v[A / 8 + 1], x.v[A / 8], A % 8);
    }
    // t[k + J] (mod 20) in lane k.
    template <int J>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline V20 rot20(const V20& x) noexcept {
        return {{window20<J % 20>(x), window20<(8 + J) % 20>(x), window20<(16 + J) % 20>(x),
                 window20<(24 + J) % 20>(x)}};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline V20 vmin(const V20& a, const V20& b) noexcept {
        return {{_mm512_min_epi64(a.v[0], b.v[0]), _mm512_min_epi64(a.v[1], b.v[1]),
                 _mm512_min_epi64(a.v[2], b.v[2]), _mm512_min_epi64(a.v[3], b.v[3])}};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline V20 vmax(const V20& a, const V20& b) noexcept {
        return {{_mm512_max_epi64(a.v[0], b.v[0]), _mm512_max_epi64(a.v[1], b.v[1]),
                 _mm512_max_epi64(a.v[2], b.v[2]), _mm512_max_epi64(a.v[3], b.v[3])}};
    }
    // Any lane of the first 20 (lanes 20..23 repeat lanes 0..3) where a > b.
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline unsigned any_greater(const V20& a, const V20& b) noexcept {
        return static_cast<unsigned>(_mm512_cmpgt_epi64_mask(a.v[0], b.v[0]) |
                                     _mm512_cmpgt_epi64_mask(a.v[1], b.v[1]) |
                                     _mm512_cmpgt_epi64_mask(a.v[2], b.v[2]));
    }

    /// circle_fires<20, 4, 8> with the pixels at centre[offsets[k]], as circle16_fires():
    /// the arc of length L from s fires iff min(t[s .. s+L-1]) > max(t[s+L .. s+19]),
    /// for all 20 starts and the lengths 4..8 at once, without a branch.
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline bool circle20_fires(const std::int64_t* centre,
                                                                           const std::int64_t* offsets) noexcept {
        const std::int64_t* o = offsets;
        std::int64_t p[20];
        for (int k = 0; k < 20; ++k) p[k] = centre[o[k]];
        const V20 t{{_mm512_set_epi64(p[7], p[6], p[5], p[4], p[3], p[2], p[1], p[0]),
                     _mm512_set_epi64(p[15], p[14], p[13], p[12], p[11], p[10], p[9], p[8]),
                     _mm512_set_epi64(p[3], p[2], p[1], p[0], p[19], p[18], p[17], p[16]),
                     _mm512_set_epi64(p[11], p[10], p[9], p[8], p[7], p[6], p[5], p[4])}};
        const V20 r1 = rot20<1>(t), r2 = rot20<2>(t), r4 = rot20<4>(t);
        // wL[s] = min(t[s .. s+L-1]).
        const V20 w2 = vmin(t, r1);
        const V20 w3 = vmin(w2, r2);
        const V20 w4 = vmin(w2, rot20<2>(w2));
        const V20 w5 = vmin(w4, r4);
        const V20 w6 = vmin(w4, rot20<4>(w2));
        const V20 w7 = vmin(w4, rot20<4>(w3));
        const V20 w8 = vmin(w4, rot20<4>(w4));
        // xM[s] = max(t[s .. s+M-1]); the rest of the arc (L, s) is x(20-L)[s+L].
        const V20 x2 = vmax(t, r1);
        const V20 x3 = vmax(x2, r2);
        const V20 x4 = vmax(x2, rot20<2>(x2));
        const V20 x5 = vmax(x4, r4);
        const V20 x6 = vmax(x4, rot20<4>(x2));
        const V20 x7 = vmax(x4, rot20<4>(x3));
        const V20 x8 = vmax(x4, rot20<4>(x4));
        const unsigned fires = any_greater(w4, rot20<4>(vmax(x8, rot20<8>(x8)))) |   // rest of 16
                               any_greater(w5, rot20<5>(vmax(x8, rot20<8>(x7)))) |   // rest of 15
                               any_greater(w6, rot20<6>(vmax(x8, rot20<8>(x6)))) |   // rest of 14
                               any_greater(w7, rot20<7>(vmax(x8, rot20<8>(x5)))) |   // rest of 13
                               any_greater(w8, rot20<8>(vmax(x8, rot20<8>(x4))));    // rest of 12
        return fires != 0;
    }
};
#endif

/// Gathers the circle around `centre` (pixel k at centre[offset(k)]) and runs the test.
template <int N, int Lmin, int Lmax, class Search = ScalarSearch, class Offset>
[[nodiscard]] inline bool circle_fires(const std::int64_t* centre, Offset offset) noexcept {
    std::int64_t t[2 * N];
#pragma GCC unroll 32
    for (int k = 0; k < N; ++k) t[k] = centre[offset(k)];
    const int newest = Search::template newest<N>(t);
    return arc_fires_from<N, Lmin, Lmax>(t, newest);
}

/// The arc test on N values.
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires(const std::array<std::int64_t, N>& t) noexcept {
    return circle_fires<N, Lmin, Lmax>(t.data(), [](int k) { return k; });
}

template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arc_fires_naive(const std::array<std::int64_t, N>& t) noexcept {
    for (int start = 0; start < N; ++start) {
        for (int len = Lmin; len <= Lmax; ++len) {
            bool inside_newer = true;
            for (int i = 0; i < len && inside_newer; ++i) {
                for (int j = len; j < N && inside_newer; ++j) {
                    if (t[(start + i) % N] <= t[(start + j) % N]) inside_newer = false;
                }
            }
            if (inside_newer) return true;
        }
    }
    return false;
}

}  // namespace evcorner
