#pragma once
// The eFAST arc test on one circle of SAE timestamps.
//
// A circle of N timestamps T[0..N) (cyclic) *fires* when some contiguous arc of length
// L, Lmin <= L <= Lmax, has its oldest timestamp strictly newer than every timestamp on
// the rest of the circle (Mueggler et al., BMVC 2017, Sec. 2.2; docs/efast.md).
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
#include <iterator>
#include <utility>

#include "evcorner/cpu_paths.hpp"

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

/// AVX-512 (F, VL, BW, DQ): each circle's whole arc test for all its arcs at once
/// (circle16_fires, circle20_fires), by the definition: the arc of length L from pixel s
/// fires iff min(t[s .. s+L-1]) > max(t[s+L .. s+N-1]). With the circle in vector
/// registers and rot<J>() putting t[k+J] in lane k, the oldest of every arc of each
/// length and the newest of every rest are sliding minima and maxima, each built from two
/// shorter windows (sliding()); one compare per length decides. No data-dependent branch
/// and no arc growth. Only for code compiled for AVX-512.
// GCC 12 warns that the intrinsics' own pass-through operand (_mm512_undefined_epi32) is
// used uninitialised once they are inlined: it is never read (the mask is all ones).
EVCORNER_AVX512_WARNINGS_OFF
struct Avx512Search {
    // A 16-pixel circle in two vectors: t[0..8), t[8..16).
    struct Circle16 {
        __m512i v[2];
        // t[k + J] (mod 16) in lane k.
        template <int J>
        [[gnu::target(EVCORNER_AVX512_TARGET)]] Circle16 rot() const noexcept {
            constexpr int j = J % 16;
            if constexpr (j == 0) return *this;
            else if constexpr (j < 8) return {{_mm512_alignr_epi64(v[1], v[0], j), _mm512_alignr_epi64(v[0], v[1], j)}};
            else if constexpr (j == 8) return {{v[1], v[0]}};
            else return {{_mm512_alignr_epi64(v[0], v[1], j - 8), _mm512_alignr_epi64(v[1], v[0], j - 8)}};
        }
        // Any of the 16 lanes where a > b.
        [[gnu::target(EVCORNER_AVX512_TARGET)]] friend unsigned any_greater(const Circle16& a, const Circle16& b) noexcept {
            return static_cast<unsigned>(_mm512_cmpgt_epi64_mask(a.v[0], b.v[0]) | _mm512_cmpgt_epi64_mask(a.v[1], b.v[1]));
        }
    };
    // A 20-pixel circle extended periodically to 32 lanes, lane m holding t[m mod 20], in
    // four vectors (t[0..8), t[8..16), t[16..20) t[0..4), t[4..12)): any 8 cyclically
    // consecutive pixels t[a..a+8) (a < 20) are lanes a..a+8 < 32, one valignq away.
    struct Circle20 {
        __m512i v[4];
        template <int A>
        [[gnu::target(EVCORNER_AVX512_TARGET)]] __m512i window() const noexcept {
            if constexpr (A % 8 == 0) return v[A / 8];
            else return _mm512_alignr_epi64(v[A / 8 + 1], v[A / 8], A % 8);
        }
        // t[k + J] (mod 20) in lane k.
        template <int J>
        [[gnu::target(EVCORNER_AVX512_TARGET)]] Circle20 rot() const noexcept {
            return {{window<J % 20>(), window<(8 + J) % 20>(), window<(16 + J) % 20>(), window<(24 + J) % 20>()}};
        }
        // Any of the first 20 lanes where a > b (lanes 20..23 repeat lanes 0..3).
        [[gnu::target(EVCORNER_AVX512_TARGET)]] friend unsigned any_greater(const Circle20& a, const Circle20& b) noexcept {
            return static_cast<unsigned>(_mm512_cmpgt_epi64_mask(a.v[0], b.v[0]) | _mm512_cmpgt_epi64_mask(a.v[1], b.v[1]) |
                                         _mm512_cmpgt_epi64_mask(a.v[2], b.v[2]));
        }
    };

    // Lane by lane, min (Max = false) or max of two circles.
    template <bool Max, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline C lanes(const C& a, const C& b) noexcept {
        C r;
        for (std::size_t i = 0; i < std::size(a.v); ++i)
            r.v[i] = Max ? _mm512_max_epi64(a.v[i], b.v[i]) : _mm512_min_epi64(a.v[i], b.v[i]);
        return r;
    }
    // The min (or max) of t[s .. s+L-1] in lane s: the window of the largest power of two
    // h < L at s, and the window of the other L - h pixels at s + h. Rotations by powers
    // of two recur, and rot<8> of a 16-pixel circle is free (its two vectors swapped);
    // shared sub-windows are computed once by the compiler (the intrinsics are pure).
    template <int L, bool Max, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline C sliding(const C& t) noexcept {
        if constexpr (L == 1) {
            return t;
        } else {
            constexpr int h = (L & (L - 1)) == 0 ? L / 2 : 1 << (31 - __builtin_clz(static_cast<unsigned>(L)));
            return lanes<Max>(sliding<h, Max>(t), sliding<L - h, Max>(t).template rot<h>());
        }
    }
    // Whether some arc of a length in Lmin..Lmax fires.
    template <int N, int Lmin, int Lmax, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline bool fires(const C& t) noexcept {
        unsigned any = 0;
        [&]<int... I>(std::integer_sequence<int, I...>) {
            ((any |= any_greater(sliding<Lmin + I, false>(t),
                                 sliding<N - Lmin - I, true>(t).template rot<Lmin + I>())),
             ...);
        }(std::make_integer_sequence<int, Lmax - Lmin + 1>{});
        return any != 0;
    }

    /// The 16-pixel circle with pixel k at centre[offsets[k]] (also Arc*'s, arcstar_test.hpp).
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline Circle16 load16(const std::int64_t* centre,
                                                                       const std::int64_t* offsets) noexcept {
        // Loaded one by one into the vectors: two vpgatherqq were slower, and a copy
        // through memory stalls on store forwarding.
        const std::int64_t* o = offsets;
        return {{_mm512_set_epi64(centre[o[7]], centre[o[6]], centre[o[5]], centre[o[4]], centre[o[3]], centre[o[2]],
                                  centre[o[1]], centre[o[0]]),
                 _mm512_set_epi64(centre[o[15]], centre[o[14]], centre[o[13]], centre[o[12]], centre[o[11]],
                                  centre[o[10]], centre[o[9]], centre[o[8]])}};
    }

    /// The 20-pixel circle with pixel k at centre[offsets[k]], extended to 32 lanes.
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline Circle20 load20(const std::int64_t* centre,
                                                                       const std::int64_t* offsets) noexcept {
        std::int64_t p[20];
        for (int k = 0; k < 20; ++k) p[k] = centre[offsets[k]];
        return {{_mm512_set_epi64(p[7], p[6], p[5], p[4], p[3], p[2], p[1], p[0]),
                 _mm512_set_epi64(p[15], p[14], p[13], p[12], p[11], p[10], p[9], p[8]),
                 _mm512_set_epi64(p[3], p[2], p[1], p[0], p[19], p[18], p[17], p[16]),
                 _mm512_set_epi64(p[11], p[10], p[9], p[8], p[7], p[6], p[5], p[4])}};
    }

    /// circle_fires<16, 3, 6> with the pixels at centre[offsets[k]].
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline bool circle16_fires(const std::int64_t* centre,
                                                                           const std::int64_t* offsets) noexcept {
        return fires<16, 3, 6>(load16(centre, offsets));
    }

    /// circle_fires<20, 4, 8> with the pixels at centre[offsets[k]].
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline bool circle20_fires(const std::int64_t* centre,
                                                                           const std::int64_t* offsets) noexcept {
        return fires<20, 4, 8>(load20(centre, offsets));
    }
};
EVCORNER_AVX512_WARNINGS_ON
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
