#pragma once
// Arc* and FA-Harris written plainly from their definitions (docs/arcstar.md,
// docs/fa_harris.md), as oracles for the fast paths: SAEs indexed (x, y) holding times
// with INT64_MIN for never fired, the filter as three plain conditions, the arc growth
// with modulo indices and ifs. Slow and simple on purpose.

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "evcorner/arcstar.hpp"
#include "evcorner/circle.hpp"
#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::naive {

inline constexpr std::int64_t kNeverNaive = INT64_MIN;

/// The final arc size of the Arc* growth on one circle T[0..N) (docs/arcstar.md), step by step.
template <int N>
int arcstar_size_naive(const std::array<std::int64_t, N>& T, int lmin) {
    auto mod = [](int i) { return ((i % N) + N) % N; };
    int kstar = 0;
    for (int k = 1; k < N; ++k)
        if (T[k] > T[kstar]) kstar = k;  // the first index of the largest
    std::int64_t seg = T[kstar];
    int cw = mod(kstar + 1), ccw = mod(kstar - 1);
    std::int64_t min_cw = T[cw], min_ccw = T[ccw];
    for (int it = 1; it <= lmin - 1; ++it) {
        if (T[cw] > T[ccw]) {
            if (min_cw < seg) seg = min_cw;
            cw = mod(cw + 1);
            if (T[cw] < min_cw) min_cw = T[cw];
        } else {
            if (min_ccw < seg) seg = min_ccw;
            ccw = mod(ccw - 1);
            if (T[ccw] < min_ccw) min_ccw = T[ccw];
        }
    }
    int size = lmin;
    for (int it = lmin; it <= N - 1; ++it) {
        if (T[cw] > T[ccw]) {
            if (T[cw] >= seg) {
                size = it + 1;
                if (min_cw < seg) seg = min_cw;
            }
            cw = mod(cw + 1);
            if (T[cw] < min_cw) min_cw = T[cw];
        } else {
            if (T[ccw] >= seg) {
                size = it + 1;
                if (min_ccw < seg) seg = min_ccw;
            }
            ccw = mod(ccw - 1);
            if (T[ccw] < min_ccw) min_ccw = T[ccw];
        }
    }
    return size;
}

/// The same size by its closed form (docs/arcstar.md, "The size in closed form"): the
/// smallest L in lmin..N-1 for which some arc of L pixels is separating (its oldest strictly
/// newer than every pixel outside it), or N if none. Tests hold it to arcstar_size_naive().
template <int N>
int arcstar_size_by_separation(const std::array<std::int64_t, N>& T, int lmin) {
    for (int len = lmin; len < N; ++len) {
        for (int start = 0; start < N; ++start) {
            std::int64_t oldest_in = INT64_MAX, newest_out = INT64_MIN;
            for (int i = 0; i < len; ++i) oldest_in = std::min(oldest_in, T[(start + i) % N]);
            for (int i = len; i < N; ++i) newest_out = std::max(newest_out, T[(start + i) % N]);
            if (oldest_in > newest_out) return len;
        }
    }
    return N;
}

/// The Arc* arc test on one circle: the size within lmin..lmax, or (unless
/// minority_only) within N-lmax..N-lmin.
template <int N>
bool arcstar_arc_naive(const std::array<std::int64_t, N>& T, int lmin, int lmax, bool minority_only) {
    const int size = arcstar_size_naive<N>(T, lmin);
    if (size <= lmax) return true;
    if (minority_only) return false;
    return size >= N - lmax && size <= N - lmin;
}

/// Plain per-pixel state shared by the Arc* and FA-Harris oracles.
class ArcStarStateNaive {
public:
    ArcStarStateNaive(SensorSize size, const ArcStarParams& params)
        : size_(size), params_(params) {
        for (int p = 0; p < 2; ++p) {
            latest_[p].assign(static_cast<std::size_t>(size.pixels()), kNeverNaive);
            filtered_[p].assign(static_cast<std::size_t>(size.pixels()), kNeverNaive);
        }
    }

    /// The filter: whether `e` passes; records e as the pixel's latest in every case.
    bool filter(const Event& e) {
        const int p = e.p;
        std::int64_t own = latest_[p][id(e.x, e.y)];
        std::int64_t other = latest_[1 - p][id(e.x, e.y)];
        if (params_.zero_init) {  // the authors' state: never fired reads as time 0
            if (own == kNeverNaive) own = 0;
            if (other == kNeverNaive) other = 0;
        }
        bool pass;
        if (!params_.filter) pass = true;
        else if (own == kNeverNaive) pass = true;
        else if (e.t - own > params_.filter_us) pass = true;
        else if (other > own) pass = true;
        else pass = false;
        latest_[p][id(e.x, e.y)] = e.t;
        return pass;
    }

    /// Both circles around (x, y) on polarity p's filtered SAE (the event away from the border).
    bool arc_test(int p, int x, int y) const {
        std::array<std::int64_t, 16> c3;
        for (int k = 0; k < 16; ++k) c3[k] = filtered(p, x + kCircle3[k].dx, y + kCircle3[k].dy);
        if (!arcstar_arc_naive<16>(c3, 3, 6, params_.minority_only)) return false;
        std::array<std::int64_t, 20> c4;
        for (int k = 0; k < 20; ++k) c4[k] = filtered(p, x + kCircle4[k].dx, y + kCircle4[k].dy);
        return arcstar_arc_naive<20>(c4, 4, 8, params_.minority_only);
    }

    std::int64_t filtered(int p, int x, int y) const { return filtered_[p][id(x, y)]; }
    void write_filtered(const Event& e) { filtered_[e.p][id(e.x, e.y)] = e.t; }
    SensorSize size() const { return size_; }

private:
    std::size_t id(int x, int y) const { return static_cast<std::size_t>(x) * size_.height + y; }
    SensorSize size_;
    ArcStarParams params_;
    std::vector<std::int64_t> latest_[2];
    std::vector<std::int64_t> filtered_[2];
};

class ArcStarNaive {
public:
    explicit ArcStarNaive(SensorSize size, const ArcStarParams& params = {}) : s_(size, params) {}

    bool process(const Event& e) {
        passed_ = s_.filter(e);
        if (!passed_) return false;
        s_.write_filtered(e);
        const SensorSize z = s_.size();
        if (e.x < 4 || e.x >= z.width - 4 || e.y < 4 || e.y >= z.height - 4) return false;
        return s_.arc_test(e.p, e.x, e.y);
    }

    /// Whether the latest event passed the filter.
    bool last_passed() const { return passed_; }

private:
    ArcStarStateNaive s_;
    bool passed_ = false;
};

}  // namespace evcorner::naive
