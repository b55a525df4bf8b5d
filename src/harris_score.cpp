#include "evcorner/harris_score.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

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
}

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
        case 9: return score_fixed<9>(rows);
        case 11: return score_fixed<11>(rows);
        case 13: return score_fixed<13>(rows);
        default: return score_fixed<15>(rows);
    }
}

}  // namespace evcorner
