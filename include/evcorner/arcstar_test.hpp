#pragma once
// The two per-event tests of Arc* (Alzugaray and Chli, "Asynchronous Corner Detection and
// Tracking for Event Cameras in Real Time", RA-L 2018), shared by ArcStar (arcstar.hpp) and
// FA-Harris (fa_harris.hpp), which uses Arc* as its candidate stage. docs/arcstar.md gives
// the exact definitions; both work on stored SAE values (sae.hpp: t + Sae::kBias, 0 = never
// fired), whose order is the order of the times.
//
// - The filter: an event passes iff its pixel never fired with its polarity, or the
//   latest event there of its polarity is more than `window` us older, or the pixel fired
//   with the other polarity since. The caller records the event as the pixel's latest in
//   every case.
// - The arc test on one circle: grow an arc from the first newest pixel, taking the
//   newer of the two frontier pixels each time (ties: counter-clockwise), Lmin-1 times
//   unconditionally, then on to the whole circle, where a frontier pixel at least as new
//   as the arc's oldest (seg) extends the arc to everything visited so far. The circle
//   passes iff the final size is within Lmin..Lmax or (unless minority_only) within
//   N-Lmax..N-Lmin.

#include <cstdint>

#include <type_traits>
#include <utility>

#include "evcorner/arc_test.hpp"
#include "evcorner/circle.hpp"
#include "evcorner/cpu_paths.hpp"
#include "evcorner/efast_avx512.hpp"
#include "evcorner/sae.hpp"

namespace evcorner {

/// The latest (unfiltered) event times of one pixel, one per polarity, stored form.
/// Interleaved so that the filter's two reads and one write touch one 16-byte cell.
struct ArcStarLatest {
    std::int64_t t[2];
};

namespace detail {
/// c ? a : b as a conditional move: the compiler turns some such choices into branches,
/// and on the arc growth's data they mispredict.
template <class T>
inline T cmov(bool c, T a, T b) noexcept {
#if defined(__x86_64__) && defined(__GNUC__)
    const unsigned flag = c;
    __asm__("test %[f], %[f]\n\tcmovne %[a], %[b]" : [b] "+r"(b) : [a] "r"(a), [f] "r"(flag) : "cc");
    return b;
#else
    return c ? a : b;
#endif
}
}  // namespace detail

/// The Arc* filter on stored values: `st` the event's stored time, `own` and `other` the
/// pixel's latest stored times of the event's polarity and of the other one (0 = never).
/// `zero_init`: the authors' zero-initialised state, where a pixel that never fired reads
/// as time 0 rather than as never (so an event at t <= window there is rejected).
[[nodiscard]] inline bool arcstar_filter_passes(std::int64_t st, std::int64_t own, std::int64_t other,
                                                std::int64_t window, bool zero_init) noexcept {
    if (zero_init) {  // a parameter (predicted; a constant where the caller knows it)
        // A never-fired cell reads as time 0; conditional moves, not mask arithmetic.
        own = detail::cmov(own == 0, Sae::kBias, own);
        other = detail::cmov(other == 0, Sae::kBias, other);
    }
    // Non-short-circuit: one branch-free test.
    bool pass = (own == 0) | (st - own > window) | (other > own);
#if defined(__GNUC__)
    // Computed into a register here, so that the caller branches once on the outcome:
    // GCC otherwise splits the conditions into two branches, each mispredicting alone.
    __asm__("" : "+r"(pass));
#endif
    return pass;
}

/// Whether an Arc* arc of final `size` passes on a circle of N pixels.
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline bool arcstar_size_passes(int size, bool minority_only) noexcept {
    return (size <= Lmax) | (!minority_only & (size >= N - Lmax) & (size <= N - Lmin));
}

/// The final arc size of the Arc* growth on the circle t[0..N) given twice (t[k + N] ==
/// t[k]) from its first newest pixel `k` (the first index of the largest value).
/// Branch-free; each frontier's next value is loaded one step ahead, so that the chain
/// from one step's choice to the next is a compare and a conditional move, not a load.
template <int N, int Lmin, int Lmax>
[[nodiscard]] inline int arcstar_arc_size(const std::int64_t* t, int k) noexcept {
    static_assert(2 <= Lmin && Lmin <= Lmax && Lmax < N);
    using detail::min;
    // Frontiers as indices into the doubled circle: cw from k+1 up, ccw from k-1+N down;
    // N-1 steps in all keep both within [0, 2N).
    int cw = k + 1;
    int ccw = k - 1 + N;
    std::int64_t vc = t[cw], vd = t[ccw];           // the frontier values
    std::int64_t nc = t[cw + 1], nd = t[ccw - 1];   // the values one step beyond them
    std::int64_t min_cw = vc, min_ccw = vd;         // smallest visited per side, frontier included
    std::int64_t seg = t[k];
    int size = Lmin;
    // Every choice a conditional move (detail::cmov): one instruction where the mask form
    // of detail::select costs four, and never a branch on the data.
#pragma GCC unroll 32
    for (int it = 1; it < N; ++it) {
        const bool go_cw = vc > vd;
        const std::int64_t v = detail::cmov(go_cw, vc, vd);  // the value taken (the larger one)
        const std::int64_t side_min = detail::cmov(go_cw, min_cw, min_ccw);
        if (it < Lmin) {
            seg = detail::cmov(seg < side_min, seg, side_min);
        } else {
            const bool grow = v >= seg;
            size = detail::cmov(grow, it + 1, size);
            const std::int64_t grown = detail::cmov(seg < side_min, seg, side_min);
            seg = detail::cmov(grow, grown, seg);
        }
        // Advance the chosen side; its new frontier is the value loaded ahead.
        cw += go_cw;
        ccw -= !go_cw;
        vc = detail::cmov(go_cw, nc, vc);
        vd = detail::cmov(go_cw, vd, nd);
        min_cw = detail::cmov(min_cw < vc, min_cw, vc);
        min_ccw = detail::cmov(min_ccw < vd, min_ccw, vd);
        if (it + 1 < N) {
            nc = t[cw + 1];
            nd = t[ccw - 1];
        }
    }
    return size;
}

/// An exact shortcut for the commonest outcome on real data: whether the Arc* growth from
/// `k` (as in arcstar_arc_size) surely ends with size N, told from bit masks without
/// the growth. Proof (docs/arcstar.md): the growth consumes pixels in decreasing order of
/// their side's running minimum ("key"; ties counter-clockwise first), so with m the
/// circle's oldest value, held by at least two pixels besides k, the first of them is
/// consumed at step g = i1 + j1 - 1 (i1, j1: their distances from k clockwise and
/// counter-clockwise) and every pixel after it has key m. If g < Lmin, the forced growth
/// takes seg down to m and every later pixel grows the arc; otherwise any later pixel (all
/// lie on the far arc between those two) at least as new as `bound` >= seg grows it, seg
/// becomes m and so does every pixel after. Either way the last step grows: size N.
/// `bound`: the best oldest of the Lmin-windows through k, an upper bound of seg after the
/// forced growth. False means "not known", not "not N".
namespace detail {
// Bit k set where t[k] (k < N) equals m, and where t[k] >= bound: the masks of
// arcstar_surely_full, in circle order (not yet rotated). Portable form.
template <int N>
struct ArcMasks {
    static void get(const std::int64_t* t, std::int64_t m, std::int64_t bound, std::uint32_t& eq,
                    std::uint32_t& ge) noexcept {
        eq = 0;
        ge = 0;
#pragma GCC unroll 32
        for (int k = 0; k < N; ++k) {
            eq |= static_cast<std::uint32_t>(t[k] == m) << k;
            ge |= static_cast<std::uint32_t>(t[k] >= bound) << k;
        }
    }
    static std::int64_t oldest(const std::int64_t* t) noexcept {
        std::int64_t m = t[0];
#pragma GCC unroll 32
        for (int k = 1; k < N; ++k) m = min(m, t[k]);
        return m;
    }
};
#ifdef EVCORNER_HAVE_AVX2_SEARCH
// The same four lanes at a time (for code compiled for AVX2 only).
template <int N>
struct ArcMasksAvx2 {
    static_assert(N % 4 == 0);
    [[gnu::target("avx2")]] static void get(const std::int64_t* t, std::int64_t m,
                                                                        std::int64_t bound, std::uint32_t& eq,
                                                                        std::uint32_t& ge) noexcept {
        const __m256i vm = _mm256_set1_epi64x(m);
        const __m256i vb = _mm256_set1_epi64x(bound);
        eq = 0;
        ge = 0;
        for (int i = 0; i < N / 4; ++i) {
            const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(t + 4 * i));
            eq |= static_cast<std::uint32_t>(_mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(v, vm))))
                  << (4 * i);
            // t >= bound  <=>  !(bound > t)
            ge |= static_cast<std::uint32_t>(~_mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpgt_epi64(vb, v))) & 15)
                  << (4 * i);
        }
    }
    [[gnu::target("avx2")]] static std::int64_t oldest(const std::int64_t* t) noexcept {
        __m256i mn = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(t));
        for (int i = 1; i < N / 4; ++i) {
            const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(t + 4 * i));
            mn = _mm256_blendv_epi8(mn, v, _mm256_cmpgt_epi64(mn, v));
        }
        mn = _mm256_blendv_epi8(mn, _mm256_permute4x64_epi64(mn, 0x4E),
                                _mm256_cmpgt_epi64(mn, _mm256_permute4x64_epi64(mn, 0x4E)));
        mn = _mm256_blendv_epi8(mn, _mm256_shuffle_epi32(mn, 0x4E), _mm256_cmpgt_epi64(mn, _mm256_shuffle_epi32(mn, 0x4E)));
        return _mm256_extract_epi64(mn, 0);
    }
};
#endif
template <class Search, int N>
struct ArcMasksFor {
    using type = ArcMasks<N>;
};
#ifdef EVCORNER_HAVE_AVX2_SEARCH
template <int N>
struct ArcMasksFor<Avx2Search, N> {
    using type = ArcMasksAvx2<N>;
};
#endif
}  // namespace detail

/// An exact shortcut for the commonest outcome on real data: whether the Arc* growth from
/// `k` (as in arcstar_arc_size) surely ends with size N, told from bit masks without
/// the growth. Proof (docs/arcstar.md): the growth consumes pixels in decreasing order of
/// their side's running minimum ("key"; ties counter-clockwise first), so with m the
/// circle's oldest value, held by at least two pixels besides k, the first of them is
/// consumed at step g = i1 + j1 - 1 (i1, j1: their distances from k clockwise and
/// counter-clockwise) and every pixel after it has key m. If g < Lmin, the forced growth
/// takes seg down to m and every later pixel grows the arc; otherwise any later pixel (all
/// lie on the far arc between those two) at least as new as `bound` >= seg grows it, seg
/// becomes m and so does every pixel after. Either way the last step grows: size N.
/// `bound`: the best oldest of the Lmin-windows through k, an upper bound of seg after the
/// forced growth. False means "not known", not "not N". `t` is the circle twice.
template <int N, int Lmin, class Search = ScalarSearch>
[[nodiscard]] inline bool arcstar_surely_full(const std::int64_t* t, int k) noexcept {
    using detail::max;
    using detail::min;
    using Masks = typename detail::ArcMasksFor<Search, N>::type;
    const std::int64_t m = Masks::oldest(t);
    const int c = k + N * static_cast<int>(k < Lmin);  // a copy of k with +-(Lmin-1) inside [0, 2N)
    std::int64_t bound = INT64_MIN;
#pragma GCC unroll 8
    for (int s = 0; s < Lmin; ++s) {
        std::int64_t w = t[c - s];
        for (int q = 1; q < Lmin; ++q) w = min(w, t[c - s + q]);
        bound = max(bound, w);
    }
    std::uint32_t eq, ge;
    Masks::get(t, m, bound, eq, ge);
    // Rotate so that bit j is the pixel j steps clockwise from k; drop k itself.
    constexpr std::uint32_t kAll = (std::uint32_t{1} << N) - 1;
    const auto rot = [k](std::uint32_t x) {
        return ((x >> k) | (x << ((N - k) & 31))) & kAll;
    };
    const std::uint32_t oldest = rot(eq) & ~std::uint32_t{1};
    if (__builtin_popcount(oldest) < 2) return false;
    const int i1 = __builtin_ctz(oldest);
    const int hi = 31 - __builtin_clz(oldest);  // j1 = N - hi
    const std::uint32_t far = ((std::uint32_t{2} << hi) - 1) & ~((std::uint32_t{1} << i1) - 1);
    return (i1 + (N - hi) <= Lmin) | ((rot(ge) & far) != 0);
}

/// Gathers the circle around `centre` (pixel k at centre[offset(k)]) and runs the Arc*
/// arc test on it; `Search` finds the first newest pixel (arc_test.hpp; all of them
/// return the first index of the largest value).
template <int N, int Lmin, int Lmax, class Search = ScalarSearch, class Offset>
[[nodiscard]] inline bool arcstar_circle_passes(const std::int64_t* centre, Offset offset, bool minority_only) noexcept {
    std::int64_t t[2 * N];
#pragma GCC unroll 32
    for (int k = 0; k < N; ++k) t[k] = centre[offset(k)];
    const int newest = Search::template newest<N>(t);
    if (arcstar_surely_full<N, Lmin, Search>(t, newest)) return arcstar_size_passes<N, Lmin, Lmax>(N, minority_only);
    return arcstar_size_passes<N, Lmin, Lmax>(arcstar_arc_size<N, Lmin, Lmax>(t, newest), minority_only);
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
/// Arc*'s arc test by its closed form (docs/arcstar.md, "The size in closed form"): the
/// growth ends with size S = the smallest L >= Lmin for which some arc of L pixels is
/// *separating* (its oldest strictly newer than every pixel outside it), or N if none.
/// So the circle passes iff a separating arc has a length in Lmin..Lmax, or (unless
/// minority_only) none has a length in Lmax+1..N-Lmax-1 and one has a length in
/// N-Lmax..N-Lmin. Every length is tested for all arcs at once, with the circle in vector
/// registers (as eFAST's AVX-512 path, Avx512Search): lane s holds the oldest of the L
/// pixels from s and the newest of the N-L pixels before s (the rest of that arc), both
/// grown one pixel per length from rotated copies of the circle; one subtraction per
/// two lengths (the sign of the oldest-of-arc's age minus the newest-of-rest's, the rest
/// of the longer arc against the oldest of the shorter: separation2()) and ORs of the
/// differences. No serial growth and no data-dependent branch. Only for code compiled
/// for AVX-512.
///
/// The circle is held as 32-bit ages relative to the event's time (order is all the test
/// reads; older = larger): 16 pixels fill one register instead of two. That is exact
/// while every fired pixel of the circle lies from 2^30 - 2^20 - 1 us (17.9 minutes)
/// before the event to 2^20 us after it (relative()); never-fired pixels get the age
/// 2^30, older than all of them. A circle outside that range (never on the real files)
/// takes the portable test (arcstar_circle_passes).
EVCORNER_AVX512_WARNINGS_OFF
struct ArcStarAvx512 {
    // Values per pixel of a 16-pixel circle: one register of 32-bit lanes.
    struct Lanes16 {
        __m512i v;
    };
    // The same for 20 pixels: lanes 0..19 of two registers (lanes 20..31 unused).
    struct Lanes20 {
        __m512i v[2];
    };
    // The 16-pixel circle; rot<J>() puts t[k + J] (mod 16) in lane k.
    struct Circle16 {
        __m512i v;
        template <int J>
        [[gnu::target(EVCORNER_AVX512_TARGET)]] Lanes16 rot() const noexcept {
            if constexpr (J % 16 == 0) return {v};
            else return {_mm512_alignr_epi32(v, v, J % 16)};
        }
    };
    // The 20-pixel circle extended periodically to 48 lanes (lane m: t[m mod 20]) in three
    // registers, so that any 16 cyclically consecutive pixels are one valignd away.
    struct Circle20 {
        __m512i v[3];
        template <int A>
        [[gnu::target(EVCORNER_AVX512_TARGET)]] __m512i window() const noexcept {
            static_assert(A < 32);
            if constexpr (A % 16 == 0) return v[A / 16];
            else return _mm512_alignr_epi32(v[A / 16 + 1], v[A / 16], A % 16);
        }
        template <int J>
        [[gnu::target(EVCORNER_AVX512_TARGET)]] Lanes20 rot() const noexcept {
            return {{window<J % 20>(), window<(16 + J) % 20>()}};
        }
    };

    // Lane by lane min (Max = false) or max.
    template <bool Max>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static Lanes16 lanes(const Lanes16& a, const Lanes16& b) noexcept {
        return {Max ? _mm512_max_epi32(a.v, b.v) : _mm512_min_epi32(a.v, b.v)};
    }
    template <bool Max>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static Lanes20 lanes(const Lanes20& a, const Lanes20& b) noexcept {
        return {{Max ? _mm512_max_epi32(a.v[0], b.v[0]) : _mm512_min_epi32(a.v[0], b.v[0]),
                 Max ? _mm512_max_epi32(a.v[1], b.v[1]) : _mm512_min_epi32(a.v[1], b.v[1])}};
    }
    // The lanes hold ages, not times (relative(): larger = older), so the oldest of a
    // set of pixels is their maximum and the newest their minimum.
    // The oldest of t[s .. s+L-1] in lane s, one pixel more per length.
    template <int N, int L, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline auto oldest_from(const C& t) noexcept {
        if constexpr (L == 1) return t.template rot<0>();
        else return lanes<true>(oldest_from<N, L - 1>(t), t.template rot<L - 1>());
    }
    // The newest of t[s-M .. s-1] in lane s: the rest of the arc of N-M pixels from s.
    template <int N, int M, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline auto newest_before(const C& t) noexcept {
        if constexpr (M == 1) return t.template rot<N - 1>();
        else return lanes<false>(newest_before<N, M - 1>(t), t.template rot<N - M>());
    }
    // Lane s of the result has its sign bit set iff the arc of L pixels from s is
    // separating: (age of the arc's oldest) - (age of the rest's newest) < 0. The ages
    // lie within [0, 2^30] (relative()), so the difference does not overflow. A
    // difference and an OR per length rather than a compare into a mask register and a
    // mask OR: the mask instructions were the bottleneck (radius 4: 38 -> 27 ns per test
    // in a loop of tests on this machine).
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static Lanes16 minus(const Lanes16& r, const Lanes16& o) noexcept {
        return {_mm512_sub_epi32(r.v, o.v)};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static Lanes20 minus(const Lanes20& r, const Lanes20& o) noexcept {
        return {{_mm512_sub_epi32(r.v[0], o.v[0]), _mm512_sub_epi32(r.v[1], o.v[1])}};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static Lanes16 or3(const Lanes16& a, const Lanes16& b,
                                                               const Lanes16& c) noexcept {
        return {_mm512_ternarylogic_epi32(a.v, b.v, c.v, 0xFE)};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static Lanes20 or3(const Lanes20& a, const Lanes20& b,
                                                               const Lanes20& c) noexcept {
        return {{_mm512_ternarylogic_epi32(a.v[0], b.v[0], c.v[0], 0xFE),
                 _mm512_ternarylogic_epi32(a.v[1], b.v[1], c.v[1], 0xFE)}};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static Lanes16 or2(const Lanes16& a, const Lanes16& b) noexcept {
        return {_mm512_or_si512(a.v, b.v)};
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static Lanes20 or2(const Lanes20& a, const Lanes20& b) noexcept {
        return {{_mm512_or_si512(a.v[0], b.v[0]), _mm512_or_si512(a.v[1], b.v[1])}};
    }
    // Whether any lane has its sign bit set. (Lanes 20..31 of a Lanes20 hold the arcs from
    // starts 0..11 again: harmless.)
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static bool any_negative(const Lanes16& a) noexcept {
        return _mm512_movepi32_mask(a.v) != 0;
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static bool any_negative(const Lanes20& a) noexcept {
        return _mm512_movepi32_mask(_mm512_or_si512(a.v[0], a.v[1])) != 0;
    }
    template <int N, int L, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline auto separation(const C& t) noexcept {
        return minus(oldest_from<N, L>(t), newest_before<N, N - L>(t));
    }
    // Sign bit set in lane s iff the arc of L or the arc of L + 1 pixels from s is
    // separating: the oldest of the L from s is newer than the newest of the N - L - 1
    // pixels before s.
    // (If t[s+L] is older than the L-arc's oldest, the L-arc's rest is older than it too;
    // else the (L+1)-arc has the same oldest and the shorter rest. The converse: the
    // L-arc's oldest is at least the (L+1)-arc's, its rest at least the (L+1)-arc's rest.)
    // One subtraction per two lengths (efast_avx512.hpp uses the same pairing).
    template <int N, int L, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline auto separation2(const C& t) noexcept {
        return minus(oldest_from<N, L>(t), newest_before<N, N - L - 1>(t));
    }
    // Sign bit set in lane s iff some arc of a length in L..Hi (L <= Hi) from s is
    // separating. (The recursions repeat sub-expressions; the intrinsics are pure, so the
    // compiler computes each once.)
    template <int N, int L, int Hi, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline auto separating(const C& t) noexcept {
        static_assert(L <= Hi);
        if constexpr (Hi == L) return separation<N, L>(t);
        else if constexpr (Hi == L + 1) return separation2<N, L>(t);
        else if constexpr (Hi == L + 2) return or2(separation2<N, L>(t), separation<N, Hi>(t));
        else if constexpr (Hi == L + 3) return or2(separation2<N, L>(t), separation2<N, L + 2>(t));
        else if constexpr (Hi == L + 4)
            return or3(separation2<N, L>(t), separation2<N, L + 2>(t), separation<N, Hi>(t));
        else return or3(separation2<N, L>(t), separation2<N, L + 2>(t), separating<N, L + 4, Hi>(t));
    }
    template <int N, int Lmin, int Lmax, class C>
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline bool passes(const C& t, bool minority_only) noexcept {
        static_assert(Lmax + 1 <= N - Lmax - 1);
        const bool minority = any_negative(separating<N, Lmin, Lmax>(t));
        const bool between = any_negative(separating<N, Lmax + 1, N - Lmax - 1>(t));
        const bool majority = any_negative(separating<N, N - Lmax, N - Lmin>(t));
        return minority | (!minority_only & !between & majority);
    }

    // The narrowed range: a fired pixel's age a = (st + kAhead) - q (st the event's stored
    // time, q the pixel's) is exact in 32 bits for a in [0, kRange), that is, for a pixel
    // fired at most kRange - kAhead - 1 us before the event (17.9 minutes) or at most
    // kAhead us after it (1.05 s; only a stream out of time order has such pixels). A
    // never-fired pixel gets the age kRange, older than every fired one in range.
    static constexpr std::int64_t kRange = std::int64_t{1} << 30;
    static constexpr std::int64_t kAhead = std::int64_t{1} << 20;
    // `st + kAhead` broadcast, for relative().
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline __m512i origin(std::int64_t st) noexcept {
        // In unsigned arithmetic: st + kAhead may wrap (st near INT64_MAX); relative()
        // computes modulo 2^64 and is exact all the same.
        return _mm512_set1_epi64(static_cast<std::int64_t>(static_cast<std::uint64_t>(st) + kAhead));
    }
    // An octet of stored times q as 32-bit ages from `o` (origin()), and in `inexact` the
    // lanes of fired pixels whose age is not in [0, kRange). Four instructions: the
    // subtraction, two vptestmq (fired; age outside the range, for fired lanes only) and
    // the narrowing, which writes kRange into the never-fired lanes. The ages are
    // computed modulo 2^64: st - q lies within (-2^63, 2^63), so the range [kAhead -
    // 2^63, kAhead + 2^63) of the true age holds one representative of each residue, and
    // a residue in [0, kRange) is the true age. (Ages, older = larger, rather than times
    // minus a base: a never-fired pixel must take the oldest value, and with ages that is
    // a merge constant of the narrowing, where with times it needed a vpmaxsd clamp and
    // a two-sided range check.)
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline __m256i relative(__m512i q, __m512i o,
                                                                        __mmask8& inexact) noexcept {
        const __m512i age = _mm512_sub_epi64(o, q);
        const __mmask8 fired = _mm512_test_epi64_mask(q, q);
        inexact = _mm512_mask_test_epi64_mask(fired, age, _mm512_set1_epi64(~(kRange - 1)));
        return _mm512_mask_cvtsepi64_epi32(_mm256_set1_epi32(static_cast<std::int32_t>(kRange)), fired, age);
    }

    // The circles' pixels are loaded by rows, as eFAST's AVX-512 path does
    // (efast_avx512.hpp): every pixel is one load at a constant displacement from one of
    // three (radius 3) or five (radius 4) row pointers plus 0, 1 or 2 row strides. The
    // stride is made opaque to the optimiser at every test (row_stride()): else GCC hoists
    // dy * width + dx for each of the 36 pixels out of the batch loop as an invariant of
    // its own and keeps most of them on the stack, so that every pixel cost a reload of its
    // offset before its load (14 of the radius-3 block's 129 instructions).
    [[gnu::always_inline]] static inline std::ptrdiff_t row_stride(std::ptrdiff_t w) noexcept {
        std::ptrdiff_t stride = w * static_cast<std::ptrdiff_t>(sizeof(std::int64_t));
        __asm__ volatile("" : "+r"(stride));
        return stride;
    }
    // The portable test for a circle outside the 32-bit range, out of line: inlined (as it
    // was), it let GCC keep the circle's loads for it, so the batch loop moved half of them
    // through general registers and the stack, and its AVX-512 code was 5x larger
    // (docs/arcstar.md, "Speed").
    template <int N, int Lmin, int Lmax, const auto& Circle>
    [[gnu::noinline, gnu::cold]] static bool portable_fallback(const std::int64_t* centre, std::ptrdiff_t w,
                                                               bool minority_only) noexcept {
        return arcstar_circle_passes<N, Lmin, Lmax>(
            centre, [w](int k) { return Circle[k].dy * w + Circle[k].dx; }, minority_only);
    }
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline __m512i octet(__m256i lo, __m256i hi) noexcept {
        return _mm512_inserti64x4(_mm512_castsi256_si512(lo), hi, 1);
    }

    /// The radius-3 test around `centre` (rows `w` cells wide) for an event of stored time st.
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline bool circle16_passes(const std::int64_t* centre,
                                                                            std::ptrdiff_t w, std::int64_t st,
                                                                            bool minority_only) noexcept {
        constexpr int N = 16, Lmin = 3, Lmax = 6;
        const std::ptrdiff_t stride = row_stride(w);
        const efast_avx512::Rows<3> r(centre, stride, 3 * stride);
        const __m256i q0 = efast_avx512::quad<kCircle3, 0>(r), q1 = efast_avx512::quad<kCircle3, 4>(r);
        const __m256i q2 = efast_avx512::quad<kCircle3, 8>(r), q3 = efast_avx512::quad<kCircle3, 12>(r);
        const __m512i o = origin(st);
        __mmask8 inexact0, inexact1;
        const __m256i lo = relative(octet(q0, q1), o, inexact0), hi = relative(octet(q2, q3), o, inexact1);
        if (!_kortestz_mask8_u8(inexact0, inexact1)) [[unlikely]]  // one kortestb
            return portable_fallback<N, Lmin, Lmax, kCircle3>(centre, w, minority_only);
        return passes<N, Lmin, Lmax>(Circle16{octet(lo, hi)}, minority_only);
    }
    /// The radius-4 test, the same way.
    [[gnu::target(EVCORNER_AVX512_TARGET)]] static inline bool circle20_passes(const std::int64_t* centre,
                                                                            std::ptrdiff_t w, std::int64_t st,
                                                                            bool minority_only) noexcept {
        constexpr int N = 20, Lmin = 4, Lmax = 8;
        const std::ptrdiff_t stride = row_stride(w);
        const efast_avx512::Rows<4> r(centre, stride, 3 * stride);
        const __m256i q0 = efast_avx512::quad<kCircle4, 0>(r), q1 = efast_avx512::quad<kCircle4, 4>(r);
        const __m256i q2 = efast_avx512::quad<kCircle4, 8>(r), q3 = efast_avx512::quad<kCircle4, 12>(r);
        const __m256i q4 = efast_avx512::quad<kCircle4, 16>(r);
        const __m512i w0 = octet(q0, q1), w1 = octet(q2, q3), w2 = octet(q4, q0);
        const __m512i o = origin(st);
        __mmask8 inexact0, inexact1, inexact2;
        const __m256i a = relative(w0, o, inexact0), b = relative(w1, o, inexact1), c = relative(w2, o, inexact2);
        if (!_kortestz_mask8_u8(_kor_mask8(inexact0, inexact1), inexact2)) [[unlikely]]
            return portable_fallback<N, Lmin, Lmax, kCircle4>(centre, w, minority_only);
        const __m512i v0 = octet(a, b);  // t[0..16)
        // t[16..20) into lanes 12..15, then t[16..20) t[0..12) and t[12..20) t[0..8).
        const __m512i c12 = _mm512_inserti32x4(v0, _mm256_castsi256_si128(c), 3);
        const __m512i v1 = _mm512_alignr_epi32(v0, c12, 12);
        const __m512i v2 = _mm512_alignr_epi32(v1, v0, 12);
        return passes<N, Lmin, Lmax>(Circle20{{v0, v1, v2}}, minority_only);
    }
};
EVCORNER_AVX512_WARNINGS_ON
#endif

/// Both Arc* circles around a pixel of an SAE plane `width` cells wide: the radius-3
/// test, then (only if it passed) the radius-4 one. Shared by ArcStar and FA-Harris.
class ArcStarCircles {
public:
    explicit ArcStarCircles(std::ptrdiff_t width) noexcept : width_(width) {}

    /// `centre` holds the event's own stored time (the caller has just written it).
    template <class Search, int Lmin3, int Lmax3, int Lmin4, int Lmax4>
    [[nodiscard]] bool pass(const std::int64_t* centre, bool minority_only) const noexcept {
        return pass_circle<Search, kCircle3.size(), Lmin3, Lmax3>(centre, *centre, minority_only) &&
               pass_circle<Search, kCircle4.size(), Lmin4, Lmax4>(centre, *centre, minority_only);
    }

    /// One circle's test alone (N = 16: radius 3, N = 20: radius 4), for an event of stored
    /// time `st` at `centre`. Reads only the circle, not the centre: the event's own write
    /// may come before or after it.
    template <class Search, int N, int Lmin, int Lmax>
    [[nodiscard]] bool pass_circle(const std::int64_t* centre, std::int64_t st, bool minority_only) const noexcept {
        static_assert(N == 16 || N == 20);
#ifdef EVCORNER_HAVE_AVX2_SEARCH
        if constexpr (std::is_same_v<Search, Avx512Search>) {
            static_assert((N == 16 && Lmin == 3 && Lmax == 6) || (N == 20 && Lmin == 4 && Lmax == 8));
            if constexpr (N == 16) return ArcStarAvx512::circle16_passes(centre, width_, st, minority_only);
            else return ArcStarAvx512::circle20_passes(centre, width_, st, minority_only);
        } else
#endif
        {
            // Offsets from compile-time circle coordinates: rows centre + dy * width with
            // constant column offsets.
            const std::ptrdiff_t w = width_;
            (void)st;
            return arcstar_circle_passes<N, Lmin, Lmax, Search>(
                centre,
                [w](int k) {
                    if constexpr (N == 16) return kCircle3[k].dy * w + kCircle3[k].dx;
                    else return kCircle4[k].dy * w + kCircle4[k].dx;
                },
                minority_only);
        }
    }

private:
    std::ptrdiff_t width_;
};

}  // namespace evcorner
