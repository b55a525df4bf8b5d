#pragma once
// eFAST's AVX-512 per-event path: the two circles of int64 SAE cells loaded by rows into
// vector registers (the layouts of Avx512Search, arc_test.hpp), and the arc tests on
// them: radius 3 on 32-bit times narrowed at load, radius 4 on the 64-bit cells, both
// with the arc lengths taken in pairs (corner(), below).
//
// A circle pixel (dx, dy) lies at centre + dy * width + dx. The seven (radius 3) or nine
// (radius 4) row pointers are formed from the centre and one or two loop-invariant row
// strides, and every pixel is one load at a constant displacement from its row pointer.
// The earlier form indexed a run-time table of 16 + 20 offsets: GCC 12 kept the offsets on
// the stack and moved half of the pixels through a stack slot (load offset, load pixel,
// store, reload into a vector): four instructions and a store-forwarding round trip per
// pixel instead of one load. Pixels are paired into 128-bit lanes by vmovq + vmovhpd,
// which read exactly the 8 bytes of each cell: a wider load over a row would cover cells
// that the previous events have just written, and a load that spans a pending narrower
// store cannot be forwarded (it waits until the store leaves the store buffer).
// Only for code compiled for AVX-512 (efast.cpp's detect_avx512; Arc*'s AVX-512 test,
// ArcStarAvx512 in arcstar_test.hpp, loads its circles through Rows and quad() too).

#include <cstddef>
#include <cstdint>

#include "evcorner/arc_test.hpp"
#include "evcorner/circle.hpp"
#include "evcorner/cpu_paths.hpp"

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// GCC 12 warns that the casts' undefined upper halves (_mm512_undefined_epi32) are used
// uninitialised once inlined: they are overwritten by the inserts.
EVCORNER_AVX512_WARNINGS_OFF
namespace evcorner::efast_avx512 {

// The rows y - R .. y + R around a centre, as three or five base pointers and the row
// stride in bytes: row dy is one of them plus 0, 1 or 2 strides, which x86 addresses
// directly (base + stride * scale + displacement), so that every pixel is one load and
// only the stride (loop-invariant) and the bases occupy registers.
template <int R>
struct Rows {
    const char* mid;    // row 0
    const char* low;    // row -3
    const char* high;   // row 3
    const char* lower;  // row -4 (R = 4)
    const char* higher; // row 4 (R = 4)
    std::ptrdiff_t stride;
    [[gnu::always_inline]] Rows(const std::int64_t* centre, std::ptrdiff_t stride_bytes, std::ptrdiff_t three_strides) noexcept
        : mid(reinterpret_cast<const char*>(centre)), low(mid - three_strides), high(mid + three_strides),
          lower(nullptr), higher(nullptr), stride(stride_bytes) {
        if constexpr (R == 4) {
            lower = low - stride;
            higher = high + stride;
        }
    }
    // The cell at (dx, dy) from the centre.
    template <int Dx, int Dy>
    [[gnu::always_inline]] const std::int64_t* at() const noexcept {
        static_assert(-R <= Dy && Dy <= R && R <= 4);
        const char* row;
        if constexpr (Dy == -4) row = lower;
        else if constexpr (Dy == -3) row = low;
        else if constexpr (Dy == -2) row = low + stride;
        else if constexpr (Dy == -1) row = low + 2 * stride;
        else if constexpr (Dy == 0) row = mid;
        else if constexpr (Dy == 1) row = mid + stride;
        else if constexpr (Dy == 2) row = mid + 2 * stride;
        else if constexpr (Dy == 3) row = high;
        else row = higher;
        return reinterpret_cast<const std::int64_t*>(row) + Dx;
    }
};

// Pixels K and K+1 of a circle (kCircle3 / kCircle4) in the two 64-bit lanes of a 128-bit vector.
template <const auto& Circle, int K, int R>
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline __m128i pair(const Rows<R>& r) noexcept {
    const std::int64_t* a = r.template at<Circle[K].dx, Circle[K].dy>();
    const std::int64_t* b = r.template at<Circle[K + 1].dx, Circle[K + 1].dy>();
    const __m128d lo = _mm_castsi128_pd(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a)));
    return _mm_castpd_si128(_mm_loadh_pd(lo, reinterpret_cast<const double*>(b)));
}

// Pixels K..K+3 in a 256-bit vector.
template <const auto& Circle, int K, int R>
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline __m256i quad(const Rows<R>& r) noexcept {
    // Named first: clang defines _mm256_inserti128_si256 as a macro, which would split the
    // template arguments' commas into macro arguments.
    const __m128i lo = pair<Circle, K>(r), hi = pair<Circle, K + 2>(r);
    return _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
}

[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline __m512i join(__m256i lo, __m256i hi) noexcept {
    return _mm512_inserti64x4(_mm512_castsi256_si512(lo), hi, 1);
}

/// The radius-3 circle around `centre` as Avx512Search::Circle16 (pixel k in lane k).
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline Avx512Search::Circle16 load16(
    const Rows<3>& r) noexcept {
    return {{join(quad<kCircle3, 0>(r), quad<kCircle3, 4>(r)), join(quad<kCircle3, 8>(r), quad<kCircle3, 12>(r))}};
}

/// The radius-4 circle around `centre` as Avx512Search::Circle20 (t[0..8), t[8..16),
/// t[16..20) t[0..4), t[4..12)).
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline Avx512Search::Circle20 load20(
    const Rows<4>& r) noexcept {
    const __m256i q0 = quad<kCircle4, 0>(r), q4 = quad<kCircle4, 4>(r), q8 = quad<kCircle4, 8>(r);
    const __m256i q12 = quad<kCircle4, 12>(r), q16 = quad<kCircle4, 16>(r);
    return {{join(q0, q4), join(q8, q12), join(q16, q0), join(q4, q8)}};
}

// The radius-3 test on 32-bit times. The order of the 16
// times is all the arc test reads, so they are narrowed at load time: u = q - lo with
// lo = st - 2^30 (st the event's stored time, q a cell), exact for every fired cell with
// u in [0, 2^31), that is, time within [-2^30, 2^30) us (about +-17.9 minutes) of the
// event's. Narrowed by signed saturation (vpmovsqd), a never-fired cell (q = 0, u = -lo)
// stays below every fired one: -lo < q - lo for q >= 1, and saturation keeps the order.
// A fired cell outside the range (found by two vptestmq per octet) sends the event to
// the 64-bit test, corner_exact(); a caller that knows no cell can be outside (EFast,
// while all its times span less than 2^30 us) leaves that check out (corner<true>).
// 16 pixels then fill one register instead of two.
//
// The test itself is the definition (the arc of L pixels from s fires iff its oldest m_L
// is strictly newer than R_L, the newest of the rest t[s+L .. s+15]) with the lengths
// taken in pairs: "the arc of L or the arc of L + 1 from s fires" is exactly
// m_L > R_{L+1}. (If t[s+L] < m_L, then R_L = max(t[s+L], R_{L+1}) < m_L; else
// m_{L+1} = m_L > R_{L+1}; the converse holds as m_{L+1} <= m_L and R_{L+1} <= R_L.) So
// the circle fires iff some lane has m_3 > R_4 or m_5 > R_6: R_6 is a 10-window of maxima
// (by doubling) rotated by 6, R_4 = max(R_6, t[s+4], t[s+5]), and the minima grow from
// rotations of t and of m_2: 18 vector operations in all, two of them compares. (The
// generic Avx512Search::fires, every window by doubling and one compare per length, needs
// about 33 on one register, 65 on two.)

// t[k + J] (mod 16) in lane k of 16 x int32.
template <int J>
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline __m512i rot16(__m512i t) noexcept {
    return _mm512_alignr_epi32(t, t, J);
}

/// Whether the radius-3 circle t (16 x int32, pixel k in lane k) has an arc of 3..6
/// pixels all strictly newer than the rest.
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline bool fires16_narrow(__m512i t) noexcept {
    // The oldest of t[s .. s+L-1] in lane s, L = 2, 3, 5.
    const __m512i r1 = rot16<1>(t);
    const __m512i m2 = _mm512_min_epi32(t, r1);
    const __m512i m3 = _mm512_min_epi32(m2, rot16<2>(t));
    const __m512i m5 = _mm512_min_epi32(m3, rot16<3>(m2));
    // The newest of t[s .. s+W-1] for W = 2, 4, 8, 10, then the rests t[s+6 .. s+15] and
    // t[s+4 .. s+15].
    const __m512i w2 = _mm512_max_epi32(t, r1);
    const __m512i w4 = _mm512_max_epi32(w2, rot16<2>(w2));
    const __m512i w8 = _mm512_max_epi32(w4, rot16<4>(w4));
    const __m512i w10 = _mm512_max_epi32(w8, rot16<8>(w2));
    const __m512i rest6 = rot16<6>(w10);
    const __m512i rest4 = _mm512_max_epi32(rest6, rot16<4>(w2));
    // No lane fires: both "oldest <= rest" masks are full (the second compare masked by
    // the first, so that the AND costs no mask instruction).
    __mmask16 none = _mm512_cmple_epi32_mask(m5, rest6);
    none = _mm512_mask_cmple_epi32_mask(none, m3, rest4);
    return !_kortestc_mask16_u8(none, none);  // kortestw's carry: all ones
}

/// Whether the radius-4 circle (64-bit, Avx512Search's layout: 32 lanes, lane m holding
/// t[m mod 20]) has an arc of 4..8 pixels all strictly newer than the rest, by the same
/// pairing: some lane with m_4 > R_5, m_6 > R_7 or m_8 > R_8. R_8 = the 12-window of
/// maxima rotated by 8, R_7 = max(R_8, t[s+7]), R_5 = max(R_7, t[s+5], t[s+6]).
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline bool fires20_paired(
    const Avx512Search::Circle20& t) noexcept {
    using C = Avx512Search::Circle20;
    constexpr bool kMin = false, kMax = true;
    const C r1 = t.rot<1>();
    const C m2 = Avx512Search::lanes<kMin>(t, r1);
    const C m4 = Avx512Search::lanes<kMin>(m2, m2.rot<2>());
    const C m6 = Avx512Search::lanes<kMin>(m4, m2.rot<4>());
    const C m8 = Avx512Search::lanes<kMin>(m4, m4.rot<4>());
    const C w2 = Avx512Search::lanes<kMax>(t, r1);
    const C w4 = Avx512Search::lanes<kMax>(w2, w2.rot<2>());
    const C w8 = Avx512Search::lanes<kMax>(w4, w4.rot<4>());
    const C w12 = Avx512Search::lanes<kMax>(w8, w4.rot<8>());
    const C rest8 = w12.rot<8>();
    const C rest7 = Avx512Search::lanes<kMax>(rest8, t.rot<7>());
    const C rest5 = Avx512Search::lanes<kMax>(rest7, w2.rot<5>());
    // All of the first 20 lanes (three registers; lanes 20..23 repeat 0..3) "oldest <=
    // rest" for the three pairs: one chain of masked compares.
    __mmask8 none = _mm512_cmple_epi64_mask(m8.v[0], rest8.v[0]);
    for (int i = 0; i < 3; ++i) {
        if (i > 0) none = _mm512_mask_cmple_epi64_mask(none, m8.v[i], rest8.v[i]);
        none = _mm512_mask_cmple_epi64_mask(none, m6.v[i], rest7.v[i]);
        none = _mm512_mask_cmple_epi64_mask(none, m4.v[i], rest5.v[i]);
    }
    return !_kortestc_mask8_u8(none, none);
}

// An octet of cells q narrowed to 32 bits (u = q - lo, saturated); `outside` gets the
// lanes of fired cells whose u is not in [0, 2^31).
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::always_inline]] inline __m256i narrow8(__m512i q, __m512i lo,
                                                                                    __mmask8& outside) noexcept {
    const __m512i u = _mm512_sub_epi64(q, lo);
    const __m512i high = _mm512_set1_epi64(~std::int64_t{0x7FFFFFFF});
    outside = _mm512_mask_test_epi64_mask(_mm512_test_epi64_mask(q, q), u, high);
    return _mm512_cvtsepi64_epi32(u);
}

/// The 64-bit tests of both circles: the exact form, for an event whose radius-3 circle
/// holds a fired cell outside the narrowed range (never on the real files: it takes a
/// gap of 17.9 minutes). Out of line and cold, so that the loop keeps no value for it.
[[gnu::target(EVCORNER_AVX512_TARGET), gnu::noinline, gnu::cold]] inline bool corner_exact(
    const std::int64_t* centre, std::ptrdiff_t stride) noexcept {
    const std::ptrdiff_t three_strides = 3 * stride;
    return Avx512Search::fires<16, 3, 6>(load16(Rows<3>(centre, stride, three_strides))) &&
           Avx512Search::fires<20, 4, 8>(load20(Rows<4>(centre, stride, three_strides)));
}

/// The width of the narrowed range: a fired cell less than this many us from the
/// event's time (either way) narrows exactly.
inline constexpr std::int64_t kNarrowSpan = std::int64_t{1} << 30;

/// eFAST's decision for an event away from the border, on the SAE plane just updated
/// with it (`st` its stored time, already at `centre`): the radius-3 circle fires with an
/// arc of 3..6 (on 32-bit times, above) and the radius-4 one with 4..8 (64-bit).
/// `stride` is the row stride in bytes. `InRange`: the caller knows that every fired
/// cell lies less than kNarrowSpan us from st (EFast knows it while all the times it has
/// taken span less than that), so no cell needs the range test: two vptestmq per
/// octet, a kortestb and a branch fewer per event (about 6 % of the loop's time).
// Not always_inline: it is called from View::process(), which has no target attribute;
// detect_avx512's `flatten` inlines it there. (Tried before the 32-bit test: the radius-4
// test out of line, as a call, and the stride made opaque once more by an `asm volatile`
// before it: both made the loop about 1.5x slower. The plain `asm` on copies below, inside
// the branch, makes it faster: docs/performance.md.)
template <bool InRange>
[[gnu::target(EVCORNER_AVX512_TARGET)]] inline bool corner(const std::int64_t* centre, std::ptrdiff_t stride,
                                                           std::int64_t st) noexcept {
    // Opaque to the optimiser at every event: else GCC hoists stride + displacement for
    // each pixel out of the loop as an invariant of its own, and with 36 of them spills
    // most to the stack, which is the cost this form removes.
    __asm__ volatile("" : "+r"(stride));
    const std::ptrdiff_t three_strides = 3 * stride;
    const Rows<3> r3(centre, stride, three_strides);
    const __m512i lo = _mm512_set1_epi64(st - (std::int64_t{1} << 30));
    __mmask8 out0, out1;
    const __m256i n0 = narrow8(join(quad<kCircle3, 0>(r3), quad<kCircle3, 4>(r3)), lo, out0);
    const __m256i n1 = narrow8(join(quad<kCircle3, 8>(r3), quad<kCircle3, 12>(r3)), lo, out1);
    if constexpr (!InRange) {
        if (!_kortestz_mask8_u8(out0, out1)) [[unlikely]]  // one kortestb, not two kmovb and an OR
            return corner_exact(centre, stride);
    }
    if (!fires16_narrow(_mm512_inserti64x4(_mm512_castsi256_si512(n0), n1, 1))) [[likely]]  // 92 % of the events
        return false;
    // The radius-4 rows from copies of the centre and the stride that the optimiser
    // cannot see through: else GCC forms some of their addresses ahead of the branch
    // above, on the path of every event (about 6 instructions), for the 8 % that get here.
    const std::int64_t* c4 = centre;
    std::ptrdiff_t s4 = stride;
    __asm__("" : "+r"(c4), "+r"(s4));
    return fires20_paired(load20(Rows<4>(c4, s4, 3 * s4)));
}

}  // namespace evcorner::efast_avx512
EVCORNER_AVX512_WARNINGS_ON
#endif
