#pragma once
// The Harris score of a binary patch, as the event-based Harris detectors compute it
// (Vasco, Glover, Bartolozzi, IROS 2016; Mueggler et al., BMVC 2017, Sec. 3.2, eq. 3-4):
//   Ix, Iy = "valid" correlation of the w x w binary patch with the 5x5 kernels
//            Gx = outer([1,4,6,4,1], [1,2,0,-2,-1]) / 12 and Gy = Gx^T  -> (w-4)^2 maps;
//   A, B, C = sums of h*Ix^2, h*Ix*Iy, h*Iy^2 with h a (w-4)^2 Gaussian, sigma 1, sum 1;
//   H = A*C - B^2 - k*(A+C)^2.
// For w = 9 this is exactly the definition of docs/harris.md (5x5 gradient maps, 5x5 Gaussian).
//
// The patch is given as one bit mask per row (bit c = column c). Gradients are summed
// in integers with 12*G (integer coefficients) and scaled once at the end, so the result
// equals the double-precision definition up to rounding (~1e-15 relative). For w = 9 the
// gradients come five at a time from per-row tables (five 12-bit fields in one word), and
// the products are summed exactly in integers per distinct Gaussian weight (6 of them)
// before the 6 weights are applied.

#include <array>
#include <cstdint>

namespace evcorner {

/// Smoothing and derivative taps of the 5x5 kernel: Gx[i][j] = kSmooth[i] * kDeriv[j] / 12,
/// i the row (y), j the column (x).
inline constexpr std::array<int, 5> kHarrisSmooth{1, 4, 6, 4, 1};
inline constexpr std::array<int, 5> kHarrisDeriv{1, 2, 0, -2, -1};
inline constexpr double kHarrisKernelScale = 12.0;

class HarrisScorer {
public:
    static constexpr int kMinWindow = 5;
    static constexpr int kMaxWindow = 15;

    /// `window` odd in kMinWindow..kMaxWindow; throws std::invalid_argument otherwise
    /// (and for a non-finite k).
    HarrisScorer(int window, double k);

    [[nodiscard]] int window() const noexcept { return window_; }
    [[nodiscard]] double k() const noexcept { return k_; }
    /// Gaussian weight at (row, column) of the (w-4)^2 gradient map.
    [[nodiscard]] double weight(int r, int c) const noexcept { return h_[r * (window_ - 4) + c]; }

    /// The score of the patch whose row r is `rows[r]` (window() rows).
    [[nodiscard]] double score(const std::uint16_t* rows) const noexcept;
    /// score() of a 9x9 patch with AVX2 vectors: the same value bit for bit (the same integer
    /// sums per Gaussian weight, weighted in the same order). Only on a CPU that runs AVX2
    /// (elsewhere, and in builds for other CPUs, it is score()).
    [[nodiscard]] double score9_avx2(const std::uint16_t* rows) const noexcept;

private:
    template <int W>
    [[nodiscard]] double score_fixed(const std::uint16_t* rows) const noexcept;
    [[nodiscard]] double score9(const std::uint16_t* rows) const noexcept;
    // The 6 sums per Gaussian weight class of 144 Ix^2, 144 Ix Iy, 144 Iy^2 -> the score.
    [[nodiscard]] double weighted9(const std::int64_t* sa, const std::int64_t* sb, const std::int64_t* sc) const noexcept;

    int window_;
    double k_;
    std::array<double, (kMaxWindow - 4) * (kMaxWindow - 4)> h_{};
    // Correlation of a 5-pixel run (bit j = column j) with the taps.
    std::array<std::int8_t, 32> smooth5_{};
    std::array<std::int8_t, 32> deriv5_{};
    // The 9x9 window (the default): per 9-bit row, the five 5-wide runs' correlations packed
    // in 12-bit fields of one word (field c = run at column c): smooth (0..16) and
    // derivative + 3 (0..6), so that whole gradient rows are summed in one word (score9).
    std::array<std::uint64_t, 512> smooth9_{};
    std::array<std::uint64_t, 512> deriv9_{};
    // The 5x5 Gaussian's distinct weights, by squared distance from the centre 0, 1, 2, 4, 5, 8.
    std::array<double, 6> h9_{};
};

}  // namespace evcorner
