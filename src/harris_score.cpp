#include "evcorner/harris_score.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define EVCORNER_HARRIS_SCORE_AVX2 1
#endif

namespace evcorner {

HarrisScorer::HarrisScorer(int window, double k) : window_(window), k_(k) {
    if (window < kMinWindow || window > kMaxWindow || window % 2 == 0)
        throw std::invalid_argument("Harris window must be odd and within " +
                                    std::to_string(kMinWindow) + ".." + std::to_string(kMaxWindow) +
                                    " (got " + std::to_string(window) + ")");
    if (!std::isfinite(k)) throw std::invalid_argument("Harris k must be a finite number");

    const int g = window - 4;
    const double centre = (g - 1) / 2.0;
    double sum = 0;
    for (int r = 0; r < g; ++r)
        for (int c = 0; c < g; ++c) {
            const double d2 = (r - centre) * (r - centre) + (c - centre) * (c - centre);
            h_[r * g + c] = std::exp(-d2 / 2.0);  // sigma = 1
            sum += h_[r * g + c];
        }
    for (int i = 0; i < g * g; ++i) h_[i] /= sum;

    for (unsigned bits = 0; bits < 32; ++bits) {
        int s = 0, d = 0;
        for (int j = 0; j < 5; ++j)
            if (bits >> j & 1u) {
                s += kHarrisSmooth[j];
                d += kHarrisDeriv[j];
            }
        smooth5_[bits] = static_cast<std::int8_t>(s);
        deriv5_[bits] = static_cast<std::int8_t>(d);
    }
    for (unsigned bits = 0; bits < 512; ++bits)
        for (unsigned c = 0; c < 5; ++c) {
            const unsigned run = bits >> c & 31u;
            smooth9_[bits] |= static_cast<std::uint64_t>(smooth5_[run]) << (12 * c);
            deriv9_[bits] |= static_cast<std::uint64_t>(deriv5_[run] + 3) << (12 * c);
        }
    if (window == 9) {
        constexpr int kD2[6] = {0, 1, 2, 4, 5, 8};
        for (int i = 0; i < 6; ++i)
            for (int r = 0; r < 5; ++r)
                for (int c = 0; c < 5; ++c)
                    if ((r - 2) * (r - 2) + (c - 2) * (c - 2) == kD2[i]) h9_[i] = h_[r * 5 + c];
    }
}

double HarrisScorer::score9(const std::uint16_t* rows) const noexcept {
    // Field c of a word holds column c of a gradient row; 12-bit fields never carry: every
    // field stays within 0..96 (the gradients 12*I lie within -48..48, biased by +48).
    constexpr std::uint64_t kField = 0xFFF;
    constexpr std::uint64_t kOnes = 0x0001'0010'0100'1001ull;  // 1 in each of the 5 fields
    std::uint64_t sm[9], de[9];
    for (int r = 0; r < 9; ++r) {
        sm[r] = smooth9_[rows[r] & 511u];
        de[r] = deriv9_[rows[r] & 511u];
    }
    // Squared distance class of (|row - 2|, |column - 2|) -> index into h9_.
    constexpr int kClass[3][3] = {{0, 1, 3}, {1, 2, 4}, {3, 4, 5}};
    std::int64_t sa[6] = {}, sb[6] = {}, sc[6] = {};
    for (int r = 0; r < 5; ++r) {
        // 12 Ix = smooth along y of the derivative runs; 12 Iy = derivative along y of the
        // smooth runs; both + 48 per field (deriv9_ holds the runs + 3, the taps sum to 16).
        const std::uint64_t x = de[r] + 4 * de[r + 1] + 6 * de[r + 2] + 4 * de[r + 3] + de[r + 4];
        const std::uint64_t y = (sm[r] + 2 * sm[r + 1] + 48 * kOnes) - (2 * sm[r + 3] + sm[r + 4]);
        const int ar = r < 2 ? 2 - r : r - 2;
        for (int c = 0; c < 5; ++c) {
            const auto ix = static_cast<std::int64_t>(x >> (12 * c) & kField) - 48;
            const auto iy = static_cast<std::int64_t>(y >> (12 * c) & kField) - 48;
            const int k = kClass[ar][c < 2 ? 2 - c : c - 2];
            sa[k] += ix * ix;
            sb[k] += ix * iy;
            sc[k] += iy * iy;
        }
    }
    return weighted9(sa, sb, sc);
}

double HarrisScorer::weighted9(const std::int64_t* sa, const std::int64_t* sb, const std::int64_t* sc) const noexcept {
    double a = 0, b = 0, cc = 0;
    for (int k = 0; k < 6; ++k) {
        a += h9_[k] * static_cast<double>(sa[k]);
        b += h9_[k] * static_cast<double>(sb[k]);
        cc += h9_[k] * static_cast<double>(sc[k]);
    }
    constexpr double kScale2 = kHarrisKernelScale * kHarrisKernelScale;
    a /= kScale2;
    b /= kScale2;
    cc /= kScale2;
    return a * cc - b * b - k_ * (a + cc) * (a + cc);
}

#ifdef EVCORNER_HARRIS_SCORE_AVX2
namespace {

// Per 9-bit row, the five 5-wide runs' correlations with the taps as int16 lanes 0..4
// (lanes 5..7 zero): lane c = run at column c.
struct RunTables {
    alignas(16) std::int16_t smooth[512][8];
    alignas(16) std::int16_t deriv[512][8];
};
constexpr RunTables make_run_tables() {
    RunTables t{};
    for (unsigned bits = 0; bits < 512; ++bits)
        for (unsigned c = 0; c < 5; ++c) {
            int sm = 0, de = 0;
            for (unsigned j = 0; j < 5; ++j)
                if (bits >> (c + j) & 1u) {
                    sm += kHarrisSmooth[j];
                    de += kHarrisDeriv[j];
                }
            t.smooth[bits][c] = static_cast<std::int16_t>(sm);
            t.deriv[bits][c] = static_cast<std::int16_t>(de);
        }
    return t;
}
constexpr RunTables kRuns = make_run_tables();

}  // namespace

// Lanes = columns 0..4 of a gradient row (5..7 zero). 12 Ix and 12 Iy of the five rows,
// their products, then folded: rows r and 4 - r share their weights, and columns c and
// 4 - c, so the rows are added pairwise and lane c gets lane 4 - c: lanes 0, 1, 2 of the
// three folded vectors (|row - 2| = 2, 1, 0) hold the sums at |column - 2| = 2, 1, 0.
[[gnu::target("avx2")]] double HarrisScorer::score9_avx2(const std::uint16_t* rows) const noexcept {
    __m256i sm[9], de[9];
    for (int r = 0; r < 9; ++r) {
        const unsigned bits = rows[r] & 511u;
        sm[r] = _mm256_cvtepi16_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(kRuns.smooth[bits])));
        de[r] = _mm256_cvtepi16_epi32(_mm_load_si128(reinterpret_cast<const __m128i*>(kRuns.deriv[bits])));
    }
    __m256i xx[5], xy[5], yy[5];
    for (int r = 0; r < 5; ++r) {
        const __m256i mid = de[r + 2];
        const __m256i ix = _mm256_add_epi32(
            _mm256_add_epi32(_mm256_add_epi32(de[r], de[r + 4]), _mm256_slli_epi32(_mm256_add_epi32(de[r + 1], de[r + 3]), 2)),
            _mm256_add_epi32(_mm256_slli_epi32(mid, 2), _mm256_slli_epi32(mid, 1)));
        const __m256i iy = _mm256_add_epi32(_mm256_sub_epi32(sm[r], sm[r + 4]),
                                            _mm256_slli_epi32(_mm256_sub_epi32(sm[r + 1], sm[r + 3]), 1));
        xx[r] = _mm256_mullo_epi32(ix, ix);
        xy[r] = _mm256_mullo_epi32(ix, iy);
        yy[r] = _mm256_mullo_epi32(iy, iy);
    }
    const __m256i mirror = _mm256_setr_epi32(4, 3, 5, 5, 5, 5, 5, 5);  // lane 5 is zero
    // f[q][a]: lanes 0, 1, 2 = the sums at |column - 2| = 2, 1, 0 of quantity q (Ix^2, Ix Iy,
    // Iy^2) over the rows at |row - 2| = 2 - a; lane 3 zero.
    __m128i f[3][3];
    const __m256i* const p[3] = {xx, xy, yy};
    for (int q = 0; q < 3; ++q) {
        const __m256i folded[3] = {_mm256_add_epi32(p[q][0], p[q][4]), _mm256_add_epi32(p[q][1], p[q][3]), p[q][2]};
        for (int a = 0; a < 3; ++a)
            f[q][a] = _mm256_castsi256_si128(_mm256_add_epi32(folded[a], _mm256_permutevar8x32_epi32(folded[a], mirror)));
    }
    // Transposed: t[a][c] = (Ix^2, Ix Iy, Iy^2, 0) at (|row - 2|, |column - 2|) = (2 - a, 2 - c).
    __m128i t[3][3];
    const __m128i zero = _mm_setzero_si128();
    for (int a = 0; a < 3; ++a) {
        const __m128i lo01 = _mm_unpacklo_epi32(f[0][a], f[1][a]);  // q0c0 q1c0 q0c1 q1c1
        const __m128i hi01 = _mm_unpackhi_epi32(f[0][a], f[1][a]);  // q0c2 q1c2 0 0
        const __m128i lo2 = _mm_unpacklo_epi32(f[2][a], zero);      // q2c0 0 q2c1 0
        const __m128i hi2 = _mm_unpackhi_epi32(f[2][a], zero);      // q2c2 0 0 0
        t[a][0] = _mm_unpacklo_epi64(lo01, lo2);
        t[a][1] = _mm_unpackhi_epi64(lo01, lo2);
        t[a][2] = _mm_unpacklo_epi64(hi01, hi2);
    }
    // The six weight classes (score9's kClass, squared distance 0, 1, 2, 4, 5, 8), the three
    // quantities side by side as exact int32 sums, weighted in score9's order (no fused
    // multiply-add: the same roundings as weighted9).
    const __m128i classes[6] = {t[2][2], _mm_add_epi32(t[2][1], t[1][2]), t[1][1],
                                _mm_add_epi32(t[2][0], t[0][2]), _mm_add_epi32(t[1][0], t[0][1]), t[0][0]};
    __m256d acc = _mm256_setzero_pd();
    for (int k = 0; k < 6; ++k)
        acc = _mm256_add_pd(acc, _mm256_mul_pd(_mm256_set1_pd(h9_[k]), _mm256_cvtepi32_pd(classes[k])));
    alignas(32) double abc[4];
    _mm256_store_pd(abc, acc);
    constexpr double kScale2 = kHarrisKernelScale * kHarrisKernelScale;
    const double a = abc[0] / kScale2, b = abc[1] / kScale2, cc = abc[2] / kScale2;
    return a * cc - b * b - k_ * (a + cc) * (a + cc);
}
#else
double HarrisScorer::score9_avx2(const std::uint16_t* rows) const noexcept { return score(rows); }
#endif

template <int W>
double HarrisScorer::score_fixed(const std::uint16_t* rows) const noexcept {
    constexpr int G = W - 4;
    // Per row: correlation of each 5-wide run with the taps, along x.
    int sm[W][G], de[W][G];
    for (int r = 0; r < W; ++r)
        for (int c = 0; c < G; ++c) {
            const unsigned run = (rows[r] >> c) & 31u;
            sm[r][c] = smooth5_[run];
            de[r][c] = deriv5_[run];
        }
    // Then along y: Ix = smooth(y) * deriv(x), Iy = deriv(y) * smooth(x); 12 times the
    // true gradients, exact in int.
    double a = 0, b = 0, cc = 0;
    for (int r = 0; r < G; ++r)
        for (int c = 0; c < G; ++c) {
            int ix = 0, iy = 0;
            for (int i = 0; i < 5; ++i) {
                ix += kHarrisSmooth[i] * de[r + i][c];
                iy += kHarrisDeriv[i] * sm[r + i][c];
            }
            const double h = h_[r * G + c];
            const double fx = ix, fy = iy;
            a += h * (fx * fx);
            b += h * (fx * fy);
            cc += h * (fy * fy);
        }
    constexpr double kScale2 = kHarrisKernelScale * kHarrisKernelScale;
    a /= kScale2;
    b /= kScale2;
    cc /= kScale2;
    return a * cc - b * b - k_ * (a + cc) * (a + cc);
}

double HarrisScorer::score(const std::uint16_t* rows) const noexcept {
    switch (window_) {
        case 5: return score_fixed<5>(rows);
        case 7: return score_fixed<7>(rows);
        case 9: return score9(rows);
        case 11: return score_fixed<11>(rows);
        case 13: return score_fixed<13>(rows);
        default: return score_fixed<15>(rows);
    }
}

}  // namespace evcorner
