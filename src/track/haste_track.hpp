#pragma once
// One HASTE track, float by float as docs/tracking.md gives it: the event window, the
// template, the 11 hypotheses and the five methods' scores. Private to the library
// (haste.cpp runs many of them in one pass; tests/reference/ holds a plain oracle).
//
// Every sum runs in index order (window k = 0..192; template cells column by column,
// cell (i, j) at j * 31 + i), in float: the reference app's Eigen reductions sum in SIMD
// lanes instead, which moves the last bits (docs/tracking.md, "Agreement").

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "evcorner/track/haste.hpp"
#include "haste_weights.hpp"

namespace evcorner::detail {

inline constexpr int kHastePatch = 31;
inline constexpr int kHasteCells = kHastePatch * kHastePatch;
inline constexpr int kHasteWindow = 193;
inline constexpr int kHasteMiddle = 96;
inline constexpr int kHasteHypotheses = 11;
inline constexpr float kHasteOmega = 1.0f / 193.0f;  // uniform weight; 193 of them sum to 1.0f
static_assert(kHasteOmega == 0x1.539094p-8f);
inline constexpr float kHasteDTheta = 0x1.1df46ap-4f;  // float(4 pi / 180)
inline constexpr float kHasteUpdate = 0.1f;
inline constexpr double kHasteHysteresis = 0.05;

struct WindowEvent {
    std::int64_t t;
    float x, y;
};

struct Hypothesis {
    float x, y, theta, c, s;
};

/// Patch coordinates of image point (u, v) under h; true when the bilinear cell is inside
/// (0 <= px, py < 30: row and column 30 are reached only as a +1 neighbour).
inline bool to_patch(const Hypothesis& h, float u, float v, float& px, float& py) noexcept {
    const float du = u - h.x, dv = v - h.y;
    px = (du * h.c + dv * h.s) + 15.0f;
    py = ((-du) * h.s + dv * h.c) + 15.0f;
    return px >= 0.0f && px < 30.0f && py >= 0.0f && py < 30.0f;
}

struct Bilinear {
    int cell;  ///< (i, j) = (trunc px, trunc py), at j * 31 + i
    float a, b, ab;
};
inline Bilinear bilinear(float px, float py) noexcept {
    const int i = static_cast<int>(px), j = static_cast<int>(py);
    const float a = px - static_cast<float>(i), b = py - static_cast<float>(j);
    return {j * kHastePatch + i, a, b, a * b};
}

/// Adds weight w at (px, py), shared bilinearly among the four cells.
inline void splat(float* p, float px, float py, float w) noexcept {
    const Bilinear q = bilinear(px, py);
    float* c = p + q.cell;
    c[kHastePatch + 1] += q.ab * w;
    c[kHastePatch] += (q.b - q.ab) * w;
    c[1] += (q.a - q.ab) * w;
    c[0] += (((1.0f - q.a) - q.b) + q.ab) * w;
}
/// The bilinear sample in its scalar form.
inline float sample_s(const float* p, float px, float py) noexcept {
    const Bilinear q = bilinear(px, py);
    const float* c = p + q.cell;
    return q.ab * c[kHastePatch + 1] + (q.b - q.ab) * c[kHastePatch] + (q.a - q.ab) * c[1] +
           (((1.0f - q.a) - q.b) + q.ab) * c[0];
}
/// The bilinear sample in its vector form (equal in exact arithmetic, not in float).
inline float sample_v(const float* p, float px, float py) noexcept {
    const Bilinear q = bilinear(px, py);
    const float* c = p + q.cell;
    return c[0] * ((1.0f - q.a) * (1.0f - q.b)) + c[kHastePatch] * ((1.0f - q.a) * q.b) +
           c[1] * (q.a * (1.0f - q.b)) + (c[kHastePatch + 1] * q.a) * q.b;
}

inline float cell_sum(const float* p) noexcept {
    float s = 0;
    for (int c = 0; c < kHasteCells; ++c) s += p[c];
    return s;
}

/// One track of method M. The window is a ring stored twice over (entry r and r + 193
/// equal), so that the 193 events from the oldest on are always contiguous.
template <HasteMethod M>
struct HasteTrack {
    static constexpr bool kGaussian = M == HasteMethod::correlation || M == HasteMethod::haste_correlation;
    static constexpr bool kStaleSamples = M == HasteMethod::haste_correlation;
    static constexpr bool kNormalised =
        M == HasteMethod::haste_correlation_star || M == HasteMethod::haste_difference_star;

    std::uint64_t id = 0;
    float x = 0, y = 0, theta = 0;  // the state
    std::int64_t t = 0;             // its time
    bool initialised = false;
    int appended = 0;
    int start = 0;  // the ring's oldest entry
    std::array<WindowEvent, 2 * kHasteWindow> window{};
    std::array<Hypothesis, kHasteHypotheses> hyp{};
    std::array<float, kHasteHypotheses> score{};
    std::array<float, kHasteCells> tmpl{};
    // haste_correlation: the 11 x 193 samples, a ring of columns like the window's, each
    // column the 11 hypotheses' samples of one event padded to 16 (the score sums over k
    // for all hypotheses at once, each in k order).
    static constexpr int kLanes = 16;
    std::vector<float> samples;
    // The normalised template of the last renewal (star methods); the difference
    // matrices D_n (haste_difference_star).
    std::vector<float> normalised;
    std::vector<float> difference;

    HasteTrack() {
        if constexpr (kStaleSamples) samples.assign(std::size_t{kLanes} * 2 * kHasteWindow, 0.0f);
        if constexpr (kNormalised) normalised.assign(kHasteCells, 0.0f);
        if constexpr (M == HasteMethod::haste_difference_star)
            difference.assign(std::size_t{kHasteHypotheses} * kHasteCells, 0.0f);
    }

    [[nodiscard]] const WindowEvent& at(int k) const noexcept { return window[start + k]; }
    [[nodiscard]] bool in_range(float u, float v) const noexcept {
        const float du = u - x, dv = v - y;
        return du * du + dv * dv < Haste::kRangeSquared;
    }
    [[nodiscard]] Hypothesis state_hypothesis() const noexcept { return {x, y, theta, std::cos(theta), std::sin(theta)}; }

    /// Appends e; returns the evicted oldest event and sets `pos` to e's ring entry.
    WindowEvent append(const WindowEvent& e, int& pos) noexcept {
        const WindowEvent old = window[start];
        window[start] = e;
        window[start + kHasteWindow] = e;
        pos = start;
        start = start + 1 == kHasteWindow ? 0 : start + 1;
        return old;
    }

    /// An event in range of the seed before the window is full; true when it completes
    /// the window (the track is then initialised: its state reported).
    bool push_initial(const WindowEvent& e) noexcept {
        int pos;
        append(e, pos);
        if (++appended < kHasteWindow) return false;
        t = at(kHasteMiddle).t;
        const Hypothesis h = state_hypothesis();
        tmpl.fill(0.0f);
        for (int k = 0; k < kHasteWindow; ++k) {
            float px, py;
            if (to_patch(h, at(k).x, at(k).y, px, py))
                splat(tmpl.data(), px, py, kGaussian ? kHasteGaussianWeights[k] : kHasteOmega);
        }
        initialised = true;
        renew();
        return true;
    }

    /// An event in range of the running track; true when the state changed.
    bool push(const WindowEvent& e) noexcept {
        int pos;
        const WindowEvent old = append(e, pos);
        if constexpr (kStaleSamples) {
            float* col = samples.data() + std::size_t{kLanes} * pos;
            for (int n = 0; n < kHasteHypotheses; ++n) {
                float px, py;
                col[n] = to_patch(hyp[n], e.x, e.y, px, py) ? sample_s(tmpl.data(), px, py) : 0.0f;
            }
            std::copy(col, col + kLanes, col + std::size_t{kLanes} * kHasteWindow);
        }
        const WindowEvent middle = at(kHasteMiddle);
        update_scores(e, old);
        const bool moved = decide(middle.t);
        const float w = (kGaussian ? kHasteGaussianWeights[kHasteMiddle] : kHasteOmega) * kHasteUpdate;
        float px, py;
        if (to_patch(hyp[0], middle.x, middle.y, px, py)) splat(tmpl.data(), px, py, w);
        return moved;
    }

    void make_hypotheses() noexcept {
        static constexpr float dx[kHasteHypotheses] = {0, 1, -1, 0, 0, 1, -1, -1, 1, 0, 0};
        static constexpr float dy[kHasteHypotheses] = {0, 0, 0, 1, -1, 1, 1, -1, -1, 0, 0};
        static constexpr float dt[kHasteHypotheses] = {0, 0, 0, 0, 0, 0, 0, 0, 0, kHasteDTheta, -kHasteDTheta};
        const float c = std::cos(theta), s = std::sin(theta);
        for (int n = 0; n < kHasteHypotheses; ++n) {
            Hypothesis& h = hyp[n];
            h.x = x + dx[n];
            h.y = y + dy[n];
            h.theta = theta + dt[n];
            h.c = n < 9 ? c : std::cos(h.theta);
            h.s = n < 9 ? s : std::sin(h.theta);
        }
    }

    /// The window's model under h: each event splatted with weight omega, oldest first.
    void model(const Hypothesis& h, float* m) const noexcept {
        std::fill(m, m + kHasteCells, 0.0f);
        for (int k = 0; k < kHasteWindow; ++k) {
            float px, py;
            if (to_patch(h, at(k).x, at(k).y, px, py)) splat(m, px, py, kHasteOmega);
        }
    }

    /// -sum of squared cells of (normalised - model of h); d receives the difference.
    float difference_score(const float* norm, const Hypothesis& h, float* d) const noexcept {
        model(h, d);
        float s = 0;
        for (int c = 0; c < kHasteCells; ++c) {
            d[c] = norm[c] - d[c] / 1.0f;
            s += d[c] * d[c];
        }
        return -s;
    }

    void normalise(float* out) const noexcept {
        const float sum = cell_sum(tmpl.data());
        for (int c = 0; c < kHasteCells; ++c) out[c] = tmpl[c] / sum;
    }

    /// New hypotheses around the state, and each method's data recomputed from them.
    void renew() noexcept {
        make_hypotheses();
        if constexpr (kStaleSamples) {
            for (int k = 0; k < kHasteWindow; ++k) {
                const int r = start + k;
                float* col = samples.data() + std::size_t{kLanes} * r;
                for (int n = 0; n < kHasteHypotheses; ++n) {
                    float px, py;
                    col[n] = to_patch(hyp[n], at(k).x, at(k).y, px, py) ? sample_v(tmpl.data(), px, py) : 0.0f;
                }
                const int mirror = r < kHasteWindow ? r + kHasteWindow : r - kHasteWindow;
                std::copy(col, col + kLanes, samples.data() + std::size_t{kLanes} * mirror);
            }
        }
        if constexpr (M == HasteMethod::haste_correlation_star) {
            normalise(normalised.data());
            for (int n = 0; n < kHasteHypotheses; ++n) {
                float s = 0;
                for (int k = 0; k < kHasteWindow; ++k) {
                    float px, py;
                    if (to_patch(hyp[n], at(k).x, at(k).y, px, py)) s += kHasteOmega * sample_v(normalised.data(), px, py);
                }
                score[n] = s;
            }
        }
        if constexpr (M == HasteMethod::haste_difference_star) {
            normalise(normalised.data());
            for (int n = 0; n < kHasteHypotheses; ++n)
                score[n] = difference_score(normalised.data(), hyp[n], difference.data() + std::size_t{kHasteCells} * n);
        }
        // correlation and haste_difference rescore from scratch on every event: nothing kept.
    }

    void update_scores(const WindowEvent& e_new, const WindowEvent& e_old) noexcept {
        if constexpr (M == HasteMethod::correlation) {
            for (int n = 0; n < kHasteHypotheses; ++n) {
                float s = 0;
                for (int k = 0; k < kHasteWindow; ++k) {
                    float px, py;
                    const float v = to_patch(hyp[n], at(k).x, at(k).y, px, py) ? sample_v(tmpl.data(), px, py) : 0.0f;
                    s += kHasteGaussianWeights[k] * v;
                }
                score[n] = s;
            }
        } else if constexpr (M == HasteMethod::haste_correlation) {
            alignas(64) float s[kLanes] = {};
            const float* col = samples.data() + std::size_t{kLanes} * start;
            for (int k = 0; k < kHasteWindow; ++k, col += kLanes)
                for (int n = 0; n < kLanes; ++n) s[n] += col[n] * kHasteGaussianWeights[k];
            std::copy(s, s + kHasteHypotheses, score.begin());
        } else if constexpr (M == HasteMethod::haste_correlation_star) {
            for (int n = 0; n < kHasteHypotheses; ++n) {
                float px, py;
                const float a = to_patch(hyp[n], e_new.x, e_new.y, px, py) ? sample_s(normalised.data(), px, py) : 0.0f;
                const float b = to_patch(hyp[n], e_old.x, e_old.y, px, py) ? sample_s(normalised.data(), px, py) : 0.0f;
                score[n] += kHasteOmega * (a - b);
            }
        } else if constexpr (M == HasteMethod::haste_difference) {
            std::array<float, kHasteCells> norm, d;
            normalise(norm.data());
            for (int n = 0; n < kHasteHypotheses; ++n) score[n] = difference_score(norm.data(), hyp[n], d.data());
        } else {
            for (int n = 0; n < kHasteHypotheses; ++n) {
                float* d = difference.data() + std::size_t{kHasteCells} * n;
                score[n] = block_update(d, hyp[n], e_new, -1.0f, score[n]);
                score[n] = block_update(d, hyp[n], e_old, +1.0f, score[n]);
            }
        }
    }

    /// haste_difference_star: moves event e into (sign -1) or out of (+1) the model inside
    /// D, keeping -sum D^2 in step through the 2x2 block it touches.
    static float block_update(float* d, const Hypothesis& h, const WindowEvent& e, float sign, float s) noexcept {
        float px, py;
        if (!to_patch(h, e.x, e.y, px, py)) return s;
        const Bilinear q = bilinear(px, py);
        float* c = d + q.cell;
        float& b00 = c[0];
        float& b10 = c[1];
        float& b01 = c[kHastePatch];
        float& b11 = c[kHastePatch + 1];
        s += (b00 * b00 + b10 * b10) + (b01 * b01 + b11 * b11);
        b00 += ((((1.0f - q.a) - q.b) + q.ab) * sign) * kHasteOmega;
        b01 += ((q.b - q.ab) * sign) * kHasteOmega;
        b10 += ((q.a - q.ab) * sign) * kHasteOmega;
        b11 += (q.ab * sign) * kHasteOmega;
        s -= (b00 * b00 + b10 * b10) + (b01 * b01 + b11 * b11);
        return s;
    }

    /// The hysteresis decision; on a transition the state becomes the winner (at time t)
    /// and the hypotheses are renewed.
    bool decide(std::int64_t middle_t) noexcept {
        int best = 0;
        float hi = score[0], lo = score[0];
        for (int n = 1; n < kHasteHypotheses; ++n) {
            if (score[n] > hi) hi = score[n], best = n;
            if (score[n] < lo) lo = score[n];
        }
        if (!(score[0] < hi)) return false;
        const float margin = 1.0f - (score[0] - lo) / (hi - lo);
        if (!(static_cast<double>(margin) > kHasteHysteresis)) return false;
        x = hyp[best].x;
        y = hyp[best].y;
        theta = hyp[best].theta;
        t = middle_t;
        renew();
        return true;
    }
};

}  // namespace evcorner::detail
