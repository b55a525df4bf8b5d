#include "evcorner/eval/track_metrics.hpp"

#include "evcorner/eval/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace evcorner::eval {

namespace {

struct Sample {
    double t, x, y;
};
using Track = std::vector<Sample>;

// Tracks by id, each in time order; of rows sharing a time, the last one in the input holds.
std::map<std::uint64_t, Track> group(std::span<const TrackPoint> rows, double shift) {
    std::map<std::uint64_t, Track> by_id;
    for (const TrackPoint& p : rows) by_id[p.id].push_back({p.t + shift, p.x, p.y});
    for (auto& [id, tr] : by_id) {
        std::stable_sort(tr.begin(), tr.end(), [](const Sample& a, const Sample& b) { return a.t < b.t; });
        std::size_t n = 0;
        for (std::size_t i = 0; i < tr.size(); ++i) {
            if (n > 0 && tr[n - 1].t == tr[i].t)
                tr[n - 1] = tr[i];
            else
                tr[n++] = tr[i];
        }
        tr.resize(n);
    }
    return by_id;
}

// P (time order, distinct times, not empty) at time t: linear between its samples, extended
// along its first and last segments beyond its ends; a single sample stays put.
Sample at(const Track& p, double t) {
    if (p.size() == 1) return {t, p[0].x, p[0].y};
    std::size_t i = static_cast<std::size_t>(
        std::upper_bound(p.begin(), p.end(), t, [](double v, const Sample& s) { return v < s.t; }) - p.begin());
    i = std::clamp<std::size_t>(i, 1, p.size() - 1);
    const Sample& a = p[i - 1];
    const Sample& b = p[i];
    const double w = (t - a.t) / (b.t - a.t);
    return {t, a.x + (b.x - a.x) * w, a.y + (b.y - a.y) * w};
}

double mean(std::span<const double> v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

double stddev(std::span<const double> v) {
    const double m = mean(v);
    double s = 0;
    for (double x : v) s += (x - m) * (x - m);
    return v.empty() ? 0.0 : std::sqrt(s / static_cast<double>(v.size()));
}

// One predicted track P against its GT track G (both in time order).
TrackScore score(const Track& g, Track p, const TrackMetricOptions& o) {
    TrackScore s;
    Track gc;
    if (o.asynchronous) {
        gc = g;
        if (g.back().t > p.back().t) p.push_back({g.back().t, p.back().x, p.back().y});
    } else if (g.back().t > p.back().t) {
        for (const Sample& r : g)
            if (r.t >= p.front().t && r.t <= p.back().t) gc.push_back(r);
    } else {
        gc = g;
    }
    const double span = g.back().t - g.front().t;
    if (gc.size() < 2 || !(span > 0)) {
        s.skipped = true;
        return s;
    }
    std::vector<double> err(gc.size() - 1);
    for (std::size_t k = 1; k < gc.size(); ++k) {
        const Sample q = at(p, gc[k].t);
        err[k - 1] = std::hypot(gc[k].x - q.x, gc[k].y - q.y);
    }
    s.age.resize(static_cast<std::size_t>(o.max_threshold_px));
    for (int e = 1; e <= o.max_threshold_px; ++e) {
        const auto bad = std::find_if(err.begin(), err.end(), [&](double v) { return v > e; });
        std::size_t end;
        std::span<const double> kept;
        if (bad != err.end()) {
            const auto i = static_cast<std::size_t>(bad - err.begin());
            end = i > 1 ? i - 1 : 0;
            if (end > 0) kept = std::span<const double>(err).subspan(1, end);
        } else {
            end = gc.size() - 1;
            kept = std::span<const double>(err).subspan(1);
        }
        const double fa = end == 0 ? 0.0 : (gc[end].t - gc[0].t) / span;
        s.age[static_cast<std::size_t>(e - 1)] = fa;
        if (e == 5 && fa > 0 && !kept.empty()) {
            s.error_5 = mean(kept);
            s.has_error_5 = true;
        }
    }
    return s;
}

}  // namespace

TrackEvaluation evaluate_tracks(std::span<const TrackPoint> predicted, std::span<const TrackPoint> gt,
                                const TrackMetricOptions& o) {
    TrackEvaluation r;
    const bool by_id = !(o.associate_px > 0) && o.seeds.empty();
    if (by_id && o.align_start && !predicted.empty() && !gt.empty() && predicted.front().t != gt.front().t)
        r.time_shift_s = gt.front().t - predicted.front().t;
    const std::map<std::uint64_t, Track> pred = group(predicted, r.time_shift_s);
    const std::map<std::uint64_t, Track> truth = group(gt, 0);
    r.predicted_tracks = pred.size();
    r.gt_tracks = truth.size();

    // Position-based matching: where and when each predicted track starts (its seed, or its
    // first sample), taken in time order (then id), each the nearest free GT track in reach.
    const bool by_seed = !o.seeds.empty();
    std::map<std::uint64_t, Sample> start;
    if (by_seed) {
        for (const TrackPoint& p : o.seeds) start.emplace(p.id, Sample{p.t, p.x, p.y});
    } else if (!by_id) {
        for (const auto& [id, tr] : pred) start.emplace(id, tr.front());
    }
    std::vector<std::pair<std::uint64_t, Sample>> starts(start.begin(), start.end());
    std::stable_sort(starts.begin(), starts.end(), [](const auto& a, const auto& b) { return a.second.t < b.second.t; });
    const double radius = o.associate_px > 0 ? o.associate_px : 1.0;
    std::map<std::uint64_t, std::pair<std::uint64_t, double>> matched;  // predicted id -> GT id, from time
    std::map<std::uint64_t, bool> taken;
    for (const auto& [id, first] : starts) {
        double best = std::numeric_limits<double>::infinity();
        std::uint64_t best_id = 0;
        for (const auto& [gid, gtr] : truth) {
            if (taken.count(gid) || gtr.front().t > first.t || gtr.back().t < first.t) continue;
            const Sample q = at(gtr, first.t);
            const double d = std::hypot(q.x - first.x, q.y - first.y);
            if (d <= radius && d < best) {
                best = d;
                best_id = gid;
            }
        }
        if (best <= radius) {
            taken[best_id] = true;
            matched[id] = {best_id, first.t};
        }
    }

    std::vector<std::pair<std::uint64_t, const Track*>> order;  // predicted tracks in evaluation order
    for (const auto& [id, tr] : pred) order.emplace_back(id, &tr);
    if (!by_id && !by_seed)
        std::stable_sort(order.begin(), order.end(),
                         [](const auto& a, const auto& b) { return a.second->front().t < b.second->front().t; });
    for (const auto& [id, tr] : order) {
        Track g;
        std::uint64_t gt_id = id;
        if (by_id) {
            const auto it = truth.find(id);
            if (it == truth.end()) {
                ++r.unmatched_tracks;
                continue;
            }
            g = it->second;
        } else {
            const auto m = matched.find(id);
            if (m == matched.end()) {
                ++r.unmatched_tracks;
                continue;
            }
            gt_id = m->second.first;
            for (const Sample& q : truth.at(gt_id))
                if (q.t >= m->second.second) g.push_back(q);
        }
        TrackScore s = score(g, *tr, o);
        s.id = id;
        s.gt_id = gt_id;
        if (s.skipped)
            ++r.skipped_tracks;
        else
            ++r.counted_tracks;
        r.tracks.push_back(std::move(s));
    }

    const auto thresholds = static_cast<std::size_t>(o.max_threshold_px);
    r.inlier_ratio.assign(thresholds, 0.0);
    r.age.assign(thresholds, 0.0);
    std::vector<double> ra(thresholds);
    for (std::size_t e = 0; e < thresholds; ++e) {
        std::size_t alive = 0;
        double sum = 0;
        for (const TrackScore& s : r.tracks) {
            if (s.skipped || s.age[e] <= 0) continue;
            ++alive;
            sum += s.age[e];
        }
        r.inlier_ratio[e] = r.counted_tracks == 0 ? 0.0 : static_cast<double>(alive) / static_cast<double>(r.counted_tracks);
        r.age[e] = alive == 0 ? 0.0 : sum / static_cast<double>(alive);
        ra[e] = r.inlier_ratio[e] * r.age[e];
    }
    r.fa = mean(r.age);
    r.efa = mean(ra);
    r.inlier_mean = mean(r.inlier_ratio);
    r.inlier_std = stddev(r.inlier_ratio);
    r.age_mean = r.fa;
    r.age_std = stddev(r.age);
    if (thresholds >= 5) {
        r.fa_5 = r.age[4];
        std::vector<double> te;
        for (const TrackScore& s : r.tracks)
            if (!s.skipped && s.age[4] > 0 && s.has_error_5) te.push_back(s.error_5);
        r.te_5 = mean(te);
    }
    return r;
}

TrackStatistics track_statistics(std::span<const TrackPoint> rows) {
    TrackStatistics st;
    const std::map<std::uint64_t, Track> tracks = group(rows, 0);
    st.tracks = tracks.size();
    std::vector<double> life, length;
    double sq = 0;
    for (const auto& [id, tr] : tracks) {
        st.samples += tr.size();
        life.push_back(tr.back().t - tr.front().t);
        double len = 0;
        for (std::size_t i = 1; i < tr.size(); ++i) len += std::hypot(tr[i].x - tr[i - 1].x, tr[i].y - tr[i - 1].y);
        length.push_back(len);
        for (std::size_t i = 1; i + 1 < tr.size(); ++i) {
            const Sample& a = tr[i - 1];
            const Sample& b = tr[i + 1];
            const double w = (tr[i].t - a.t) / (b.t - a.t);
            sq += std::pow(std::hypot(tr[i].x - (a.x + (b.x - a.x) * w), tr[i].y - (a.y + (b.y - a.y) * w)), 2);
            ++st.jitter_samples;
        }
    }
    st.lifetime_median_s = median(life);
    st.lifetime_mean_s = mean(life);
    st.length_median_px = median(length);
    st.length_mean_px = mean(length);
    st.jitter_rms_px = st.jitter_samples ? std::sqrt(sq / static_cast<double>(st.jitter_samples)) : 0.0;
    return st;
}

}  // namespace evcorner::eval
