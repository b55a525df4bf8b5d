#pragma once
// The scores of docs/scores.md written plainly, as oracles for corner_scores.hpp; stored
// SAE values in, as the fast paths read them (0 = never fired, older than every real time).
// eFAST: on each circle every arc length from the shortest up and every start tried, the
// first arc whose pixels are all strictly newer than the rest gives L and the margin;
// S = (16 - L3) + (20 - L4) - 15 + the smaller margin. Arc*: its growth step by step with
// cyclic indices, the joining order recorded, then the final arc's L and margin.

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>

namespace evcorner::naive {

struct ArcFound {
    int length;
    double margin;
};

// (oldest of the arc - newest of the rest) / (now - newest of the rest + 1), the arc's
// oldest standing in for now when newer, at most 1 - 2^-40.
inline double margin_naive(std::int64_t oldest, std::int64_t newest_rest, std::int64_t now) {
    const double f = static_cast<double>(oldest - newest_rest) /
                     (static_cast<double>(std::max(now, oldest) - newest_rest) + 1.0);
    return std::min(f, 1.0 - 0x1p-40);
}

template <std::size_t N>
std::optional<ArcFound> shortest_firing_arc(const std::array<std::int64_t, N>& t, int lmin, int lmax, std::int64_t now) {
    for (int len = lmin; len <= lmax; ++len) {
        for (int start = 0; start < static_cast<int>(N); ++start) {
            std::int64_t oldest = INT64_MAX, newest_rest = INT64_MIN;
            for (int j = 0; j < static_cast<int>(N); ++j) {
                const std::int64_t v = t[static_cast<std::size_t>((start + j) % static_cast<int>(N))];
                if (j < len) oldest = std::min(oldest, v);
                else newest_rest = std::max(newest_rest, v);
            }
            if (oldest > newest_rest) return ArcFound{len, margin_naive(oldest, newest_rest, now)};
        }
    }
    return std::nullopt;
}

/// eFAST's score from its two circles (radius 3: 16 px, radius 4: 20 px) at stored time
/// `now`; nullopt where a circle has no firing arc (not a corner).
inline std::optional<double> efast_score_naive(const std::array<std::int64_t, 16>& c3,
                                               const std::array<std::int64_t, 20>& c4, std::int64_t now) {
    const auto a3 = shortest_firing_arc(c3, 3, 6, now);
    const auto a4 = shortest_firing_arc(c4, 4, 8, now);
    if (!a3 || !a4) return std::nullopt;
    return static_cast<double>((16 - a3->length) + (20 - a4->length) - 15) + std::min(a3->margin, a4->margin);
}

/// Arc*'s arc on one circle: {L = min(size, N - size), margin} for the growth's final arc
/// size (docs/arcstar.md: from the newest pixel towards the newer frontier, forced to lmin,
/// then extended to everything visited whenever the frontier pixel is at least as new as
/// the arc's oldest, which takes in the older pixels passed on that side); margin 0 for a
/// majority arc or a whole circle.
template <std::size_t N>
ArcFound arcstar_arc_naive(const std::array<std::int64_t, N>& t, int lmin, std::int64_t now) {
    const int n = static_cast<int>(N);
    const auto at = [&](int i) { return t[static_cast<std::size_t>(((i % n) + n) % n)]; };
    int k = 0;
    for (int i = 1; i < n; ++i)
        if (at(i) > at(k)) k = i;
    std::array<int, N> order{};
    order[0] = k;
    int cw = k + 1, ccw = k - 1;  // the next pixel on each side
    std::int64_t min_cw = at(cw), min_ccw = at(ccw);  // oldest passed or next on each side
    std::int64_t seg = at(k);
    int size = lmin;
    for (int it = 1; it < n; ++it) {
        const bool go_cw = at(cw) > at(ccw);
        const std::int64_t v = go_cw ? at(cw) : at(ccw);
        const std::int64_t side_min = go_cw ? min_cw : min_ccw;
        if (it < lmin) {
            seg = std::min(seg, side_min);
        } else if (v >= seg) {
            size = it + 1;
            seg = std::min(seg, side_min);
        }
        order[static_cast<std::size_t>(it)] = go_cw ? cw : ccw;
        if (go_cw) min_cw = std::min(min_cw, at(++cw));
        else min_ccw = std::min(min_ccw, at(--ccw));
    }
    std::int64_t in_oldest = INT64_MAX, out_newest = INT64_MIN;
    for (int i = 0; i < n; ++i) {
        const std::int64_t v = at(order[static_cast<std::size_t>(i)]);
        if (i < size) in_oldest = std::min(in_oldest, v);
        else out_newest = std::max(out_newest, v);
    }
    if (2 * size > n) return {n - size, 0.0};
    return {size, in_oldest > out_newest ? margin_naive(in_oldest, out_newest, now) : 0.0};
}

}  // namespace evcorner::naive
