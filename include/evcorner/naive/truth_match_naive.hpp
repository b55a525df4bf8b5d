#pragma once
// The oracle of eval::TruthMatcher: the definitions of eval/truth_match.hpp computed by brute
// force, every event against every corner, every truth sample against every event, with
// the whole truth in memory. For tests only.

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "evcorner/eval/truth_match.hpp"

namespace evcorner::naive {

struct NaiveCornerAt {
    bool visible = false;
    double x = 0, y = 0, vx = 0, vy = 0;
};

/// Corner `c` (a row of the later sample of the pair around t) at time t.
inline NaiveCornerAt naive_corner_at(std::span<const sim::TruthCorner> truth, const sim::TruthCorner& c,
                                     std::int64_t t, std::int64_t t0, bool between, eval::Interpolation interp) {
    NaiveCornerAt out{c.state == sim::CornerState::visible, c.x, c.y, c.vx, c.vy};
    if (!between) return out;
    for (const sim::TruthCorner& q : truth) {
        if (q.t_us != t0 || q.object != c.object || q.corner != c.corner) continue;
        const std::int64_t t1 = c.t_us;
        if (interp == eval::Interpolation::linear) {
            const double a = static_cast<double>(t - t0) / static_cast<double>(t1 - t0);
            out.x = q.x + a * (c.x - q.x);
            out.y = q.y + a * (c.y - q.y);
            out.vx = q.vx + a * (c.vx - q.vx);
            out.vy = q.vy + a * (c.vy - q.vy);
            out.visible = out.visible || q.state == sim::CornerState::visible;
        } else if (t - t0 <= t1 - t) {
            out = {q.state == sim::CornerState::visible, q.x, q.y, q.vx, q.vy};
        }
        break;
    }
    return out;
}

/// The sample times around t: (t0, t1) with t0 < t < t1 and between = true; else t1 = the
/// sample at t, or the first (t before it) or the last (t after it), between = false.
inline void naive_bracket(std::span<const sim::TruthCorner> truth, std::int64_t t, std::int64_t& t0,
                          std::int64_t& t1, bool& between) {
    std::int64_t below = std::numeric_limits<std::int64_t>::min(), above = std::numeric_limits<std::int64_t>::max();
    std::int64_t first = std::numeric_limits<std::int64_t>::max(), last = std::numeric_limits<std::int64_t>::min();
    bool exact = false;
    for (const auto& r : truth) {
        first = std::min(first, r.t_us);
        last = std::max(last, r.t_us);
        if (r.t_us == t) exact = true;
        if (r.t_us < t) below = std::max(below, r.t_us);
        if (r.t_us > t) above = std::min(above, r.t_us);
    }
    between = false;
    t0 = 0;
    if (exact) t1 = t;
    else if (t < first) t1 = first;
    else if (t > last) t1 = last;
    else {
        t0 = below;
        t1 = above;
        between = true;
    }
}

inline eval::TruthMatchResult naive_match_truth(std::span<const Event> corners,
                                                std::span<const sim::TruthCorner> truth,
                                                const eval::TruthMatchParams& p) {
    eval::TruthMatchResult r;
    const auto bin_of = [&](double speed) {
        std::size_t k = 0;
        while (k + 1 < p.speed_edges.size() && speed >= p.speed_edges[k + 1]) ++k;
        return k;
    };
    for (std::size_t k = 0; k < p.speed_edges.size(); ++k)
        r.bins.push_back({p.speed_edges[k],
                          k + 1 < p.speed_edges.size() ? p.speed_edges[k + 1] : std::numeric_limits<double>::infinity(),
                          0, 0, 0, 0});
    r.corner_events = corners.size();
    r.is_true.assign(corners.size(), 0);
    // matches[i]: the (object, corner) pairs event i credits.
    std::vector<std::vector<std::pair<int, int>>> credits(corners.size());
    for (std::size_t i = 0; i < corners.size() && !truth.empty(); ++i) {
        const Event& e = corners[i];
        std::int64_t t0 = 0, t1 = 0;
        bool between = false;
        naive_bracket(truth, e.t, t0, t1, between);
        double best = std::numeric_limits<double>::infinity(), best_speed = -1;
        std::pair<int, int> best_id{-1, -1};
        for (const sim::TruthCorner& c : truth) {
            if (c.t_us != t1) continue;
            const NaiveCornerAt at = naive_corner_at(truth, c, e.t, t0, between, p.interpolation);
            if (!at.visible) continue;
            const double dx = (e.x + 0.5) - at.x, dy = (e.y + 0.5) - at.y, d2 = dx * dx + dy * dy;
            if (d2 < best) {
                best = d2;
                best_speed = std::hypot(at.vx, at.vy);
                best_id = {c.object, c.corner};
            }
            if (d2 <= p.radius * p.radius && p.credit == eval::Credit::all) credits[i].push_back({c.object, c.corner});
        }
        const bool tp = best <= p.radius * p.radius;
        if (tp && p.credit == eval::Credit::nearest) credits[i].push_back(best_id);
        if (best_speed >= 0) {
            ++r.bins[bin_of(best_speed)].events;
            r.bins[bin_of(best_speed)].true_positives += tp;
        }
        if (tp) {
            ++r.true_positives;
            r.is_true[i] = 1;
            r.errors.push_back(static_cast<float>(std::sqrt(best)));
        }
    }
    for (const sim::TruthCorner& s : truth) {
        if (s.state != sim::CornerState::visible) continue;
        bool found = false;
        for (std::size_t i = 0; i < corners.size() && !found; ++i) {
            if (std::llabs(corners[i].t - s.t_us) > p.tolerance_us) continue;
            for (const auto& id : credits[i]) found = found || (id.first == s.object && id.second == s.corner);
        }
        const std::size_t k = bin_of(std::hypot(s.vx, s.vy));
        ++r.truth_samples;
        ++r.bins[k].samples;
        if (found) {
            ++r.recalled;
            ++r.bins[k].recalled;
        }
    }
    return r;
}

}  // namespace evcorner::naive
