#pragma once
// luvHarris written plainly from its definition (docs/luvharris.md), as an oracle for the
// fast path: the TOS as a plain int image updated by the rule; the Harris image with
// every sum taken directly (2-D kernels, no separable passes, no ring buffers), the
// surface extended beyond the sensor by a function; the refresh points and the threshold
// rules as the definition states them. Slow on purpose. Only the last step, the exact
// response of the integer structure tensor, is the library's luv_harris_response().

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/luvharris.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::naive {

/// The Threshold-Ordinal Surface by its definition.
struct TosNaive {
    SensorSize size;
    int k, t;
    std::vector<int> v;  // v[y * width + x]
    TosNaive(SensorSize s, int k_, int t_) : size(s), k(k_), t(t_), v(static_cast<std::size_t>(s.pixels()), 0) {}
    int& at(int x, int y) { return v[static_cast<std::size_t>(y) * size.width + x]; }
    void update(int x, int y) {
        for (int dy = -k / 2; dy <= k / 2; ++dy)
            for (int dx = -k / 2; dx <= k / 2; ++dx) {
                if (!size.contains(x + dx, y + dy)) continue;
                int& c = at(x + dx, y + dy);
                c = c < 255 - k * t ? 0 : c - 1;
            }
        at(x, y) = 255;
    }
};

/// The Harris image of `surface` (width x height values) with the parameters of `p`:
/// value[y * width + x], computed from the definition.
inline std::vector<double> luv_harris_image_naive(const std::vector<int>& surface, SensorSize s,
                                                  const LuvHarrisParams& p) {
    const int g = p.gradient, hg = g / 2, b = p.block, hb = b / 2;
    const std::vector<int> smooth = g == 5 ? std::vector<int>{1, 4, 6, 4, 1} : std::vector<int>{1, 2, 1};
    const std::vector<int> deriv = g == 5 ? std::vector<int>{1, 2, 0, -2, -1} : std::vector<int>{1, 0, -1};
    std::vector<std::int64_t> w(static_cast<std::size_t>(b), 1);
    if (p.gaussian_block)  // binomial coefficients C(b-1, j)
        for (int j = 0; j < b; ++j) {
            std::int64_t c = 1;
            for (int i = 0; i < j; ++i) c = c * (b - 1 - i) / (i + 1);
            w[static_cast<std::size_t>(j)] = c;
        }
    // The surface beyond the sensor: 0, or its nearest pixel.
    auto ext = [&](int x, int y) -> std::int64_t {
        if (p.replicate_border) {
            x = std::clamp(x, 0, s.width - 1);
            y = std::clamp(y, 0, s.height - 1);
        } else if (!s.contains(x, y)) {
            return 0;
        }
        return surface[static_cast<std::size_t>(y) * s.width + x];
    };
    // Gradient images over the sensor and hb pixels around it; index (u + hb, v + hb).
    const int gw = s.width + 2 * hb, gh = s.height + 2 * hb;
    std::vector<std::int64_t> ix(static_cast<std::size_t>(gw) * gh), iy(ix.size());
    for (int v = -hb; v < s.height + hb; ++v)
        for (int u = -hb; u < s.width + hb; ++u) {
            std::int64_t sx = 0, sy = 0;
            for (int i = 0; i < g; ++i)      // kernel row (y)
                for (int j = 0; j < g; ++j) {  // kernel column (x)
                    const std::int64_t f = ext(u + j - hg, v + i - hg);
                    sx += smooth[i] * deriv[j] * f;
                    sy += deriv[i] * smooth[j] * f;
                }
            ix[static_cast<std::size_t>(v + hb) * gw + (u + hb)] = sx;
            iy[static_cast<std::size_t>(v + hb) * gw + (u + hb)] = sy;
        }
    const double gn = g == 5 ? 128.0 : 8.0;  // slope of a unit ramp under the kernel
    double ws = 0;
    for (const auto x : w) ws += static_cast<double>(x);
    const double d = gn * gn * ws * ws;
    const double scale = 1.0 / (d * d) / 65536.0;
    const auto k_q = static_cast<std::int64_t>(std::llround(p.k * 65536.0));
    std::vector<double> out(static_cast<std::size_t>(s.pixels()));
    for (int y = 0; y < s.height; ++y)
        for (int x = 0; x < s.width; ++x) {
            std::int64_t a = 0, bb = 0, c = 0;
            for (int i = 0; i < b; ++i)
                for (int j = 0; j < b; ++j) {
                    const std::size_t at = static_cast<std::size_t>(y + i) * gw + (x + j);  // (x + j - hb) + hb
                    const std::int64_t wt = w[static_cast<std::size_t>(i)] * w[static_cast<std::size_t>(j)];
                    a += wt * ix[at] * ix[at];
                    bb += wt * ix[at] * iy[at];
                    c += wt * iy[at] * iy[at];
                }
            out[static_cast<std::size_t>(y) * s.width + x] = luv_harris_response(a, bb, c, k_q, scale);
        }
    return out;
}

class LuvHarrisNaive {
public:
    LuvHarrisNaive(SensorSize s, const LuvHarrisParams& p)
        : s_(s), p_(p), tos_(s, p.tos_size, p.tos_threshold), table_(static_cast<std::size_t>(s.pixels()), 0.0) {}

    bool process(const Event& e) {
        // Refresh points: event time t0 + n P (n >= 1, t0 the first event's time): the
        // first event at or after a point that no earlier event reached; event counts
        // M, 2M, ... (0-based index).
        bool due = false;
        if (n_ == 0) {
            t0_ = e.t;
            last_point_ = 0;
        } else if (p_.refresh_us > 0 && e.t - t0_ >= p_.refresh_us) {
            const std::int64_t point = (e.t - t0_) / p_.refresh_us;  // latest point reached
            if (point > last_point_) {
                due = true;
                last_point_ = point;
            }
        }
        if (p_.refresh_events > 0 && n_ > 0 && n_ % static_cast<std::uint64_t>(p_.refresh_events) == 0) due = true;
        if (due) {
            table_ = luv_harris_image_naive(tos_.v, s_, p_);
            refreshed_ = true;
            ++refreshes_;
        }
        ++n_;
        tos_.update(e.x, e.y);
        if (!refreshed_) {
            score_ = std::numeric_limits<double>::quiet_NaN();
            return false;
        }
        const double v = table_[static_cast<std::size_t>(e.y) * s_.width + e.x];
        score_ = v;
        if (!p_.adaptive) return v > p_.threshold;
        bool corner = false;
        if (seen_ == 0) {
            mean_ = v;
            var_ = 0;
        } else {
            const double limit = mean_ + p_.sigmas * std::sqrt(var_);
            corner = v > limit;
            const double diff = v - mean_;
            const double incr = p_.alpha * diff;
            mean_ = mean_ + incr;
            var_ = (1.0 - p_.alpha) * (var_ + diff * incr);
        }
        ++seen_;
        return corner;
    }
    double last_score() const { return score_; }
    std::uint64_t refreshes() const { return refreshes_; }
    const TosNaive& tos() const { return tos_; }
    const std::vector<double>& table() const { return table_; }

private:
    SensorSize s_;
    LuvHarrisParams p_;
    TosNaive tos_;
    std::vector<double> table_;
    bool refreshed_ = false;
    std::uint64_t n_ = 0, refreshes_ = 0, seen_ = 0;
    std::int64_t t0_ = 0, last_point_ = 0;
    double mean_ = 0, var_ = 0;
    double score_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace evcorner::naive
