#include "evcorner/eval/truth_match.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace evcorner::eval {

std::string_view to_string(Credit c) noexcept { return c == Credit::all ? "all" : "nearest"; }
std::string_view to_string(Interpolation i) noexcept { return i == Interpolation::linear ? "linear" : "nearest"; }

Credit parse_credit(std::string_view s) {
    if (s == "all") return Credit::all;
    if (s == "nearest") return Credit::nearest;
    throw std::invalid_argument("credit must be all or nearest, not '" + std::string(s) + "'");
}

Interpolation parse_interpolation(std::string_view s) {
    if (s == "linear") return Interpolation::linear;
    if (s == "nearest") return Interpolation::nearest;
    throw std::invalid_argument("interpolation must be linear or nearest, not '" + std::string(s) + "'");
}

void validate(const TruthMatchParams& p) {
    if (!(p.radius > 0) || !std::isfinite(p.radius)) throw std::invalid_argument("the match radius must be > 0 px");
    if (p.tolerance_us < 0) throw std::invalid_argument("the time tolerance must be >= 0 us");
    if (p.speed_edges.empty() || p.speed_edges.front() != 0)
        throw std::invalid_argument("the speed bins must start at 0 px/s");
    for (std::size_t i = 1; i < p.speed_edges.size(); ++i)
        if (!(p.speed_edges[i] > p.speed_edges[i - 1])) throw std::invalid_argument("the speed bins must increase");
}

double TruthMatchResult::precision() const noexcept {
    return corner_events == 0 ? 0.0 : 100.0 * static_cast<double>(true_positives) / static_cast<double>(corner_events);
}

double TruthMatchResult::recall() const noexcept {
    return truth_samples == 0 ? 0.0 : 100.0 * static_cast<double>(recalled) / static_cast<double>(truth_samples);
}

double TruthMatchResult::smear() const noexcept {
    return visible_corner_us <= 0 ? 0.0 : static_cast<double>(true_positives) / (visible_corner_us / 1000.0);
}

ErrorSummary summarize_errors(std::span<const float> errors) {
    ErrorSummary s;
    if (errors.empty()) return s;
    std::vector<float> v(errors.begin(), errors.end());
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    s.median = n % 2 ? v[n / 2] : 0.5 * (static_cast<double>(v[n / 2 - 1]) + v[n / 2]);
    double sum = 0;
    for (const float e : v) sum += e;
    s.mean = sum / static_cast<double>(n);
    // Nearest rank: the smallest value with at least 90 % of the values at or below it.
    const auto rank = static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(n)));
    s.p90 = v[std::max<std::size_t>(rank, 1) - 1];
    return s;
}

TruthMatcher::TruthMatcher(std::span<const Event> corners, TruthMatchParams params)
    : TruthMatcher(corners, {}, std::move(params)) {}

TruthMatcher::TruthMatcher(std::span<const Event> corners, std::span<const double> scores, TruthMatchParams params)
    : corners_(corners), scores_(scores), p_(std::move(params)) {
    validate(p_);
    if (!scores_.empty() && scores_.size() != corners_.size())
        throw std::invalid_argument("TruthMatcher: " + std::to_string(scores_.size()) + " scores for " +
                                    std::to_string(corners_.size()) + " corner events");
    r_.is_true.assign(corners_.size(), 0);
    for (std::size_t k = 0; k < p_.speed_edges.size(); ++k)
        r_.bins.push_back({p_.speed_edges[k],
                           k + 1 < p_.speed_edges.size() ? p_.speed_edges[k + 1] : std::numeric_limits<double>::infinity(),
                           0, 0, 0, 0});
}

int TruthMatcher::bin_of(double speed) const noexcept {
    const auto it = std::upper_bound(p_.speed_edges.begin(), p_.speed_edges.end(), speed);
    return static_cast<int>(it - p_.speed_edges.begin()) - 1;  // speed >= 0, edges[0] = 0
}

std::uint32_t TruthMatcher::track_of(const sim::TruthCorner& c) {
    const std::int64_t key = (static_cast<std::int64_t>(c.object) << 32) | static_cast<std::uint32_t>(c.corner);
    const auto it = std::lower_bound(track_index_.begin(), track_index_.end(), std::make_pair(key, std::uint32_t{0}));
    if (it != track_index_.end() && it->first == key) return it->second;
    const auto id = static_cast<std::uint32_t>(tracks_.size());
    tracks_.emplace_back().key = key;
    track_index_.insert(it, {key, id});
    return id;
}

void TruthMatcher::match_events_until(std::int64_t t_end, bool to_end) {
    if (cur_.empty() && !any_sample_) return;
    // Where each of cur_'s corners was at prev_ (index, or -1).
    std::vector<int> in_prev(cur_.size(), -1);
    if (!prev_.empty()) {
        std::vector<int> by_track(tracks_.size(), -1);
        for (std::size_t i = 0; i < prev_.size(); ++i) by_track[prev_track_[i]] = static_cast<int>(i);
        for (std::size_t j = 0; j < cur_.size(); ++j) in_prev[j] = by_track[cur_track_[j]];
    }
    const std::int64_t t1 = cur_.empty() ? 0 : cur_.front().t_us;
    const std::int64_t t0 = prev_.empty() ? t1 : prev_.front().t_us;
    const double r2 = p_.radius * p_.radius;
    const std::int64_t tol = p_.tolerance_us;
    std::vector<std::uint32_t> credited;
    for (; next_event_ < corners_.size() && (to_end || corners_[next_event_].t <= t_end); ++next_event_) {
        const Event& e = corners_[next_event_];
        const double ex = e.x + 0.5, ey = e.y + 0.5;
        double best = std::numeric_limits<double>::infinity(), best_speed = -1;
        std::uint32_t best_track = 0;
        credited.clear();
        const bool between = !prev_.empty() && e.t > t0 && e.t < t1;
        const double a = between ? static_cast<double>(e.t - t0) / static_cast<double>(t1 - t0) : 1.0;
        for (std::size_t j = 0; j < cur_.size(); ++j) {
            const sim::TruthCorner& c = cur_[j];
            double x = c.x, y = c.y, vx = c.vx, vy = c.vy;
            bool visible = c.state == sim::CornerState::visible;
            if (between && in_prev[j] >= 0) {
                const sim::TruthCorner& q = prev_[static_cast<std::size_t>(in_prev[j])];
                if (p_.interpolation == Interpolation::linear) {
                    x = q.x + a * (c.x - q.x);
                    y = q.y + a * (c.y - q.y);
                    vx = q.vx + a * (c.vx - q.vx);
                    vy = q.vy + a * (c.vy - q.vy);
                    visible = visible || q.state == sim::CornerState::visible;
                } else if (e.t - t0 <= t1 - e.t) {
                    x = q.x, y = q.y, vx = q.vx, vy = q.vy;
                    visible = q.state == sim::CornerState::visible;
                }
            }
            if (!visible) continue;
            const double dx = ex - x, dy = ey - y, d2 = dx * dx + dy * dy;
            if (d2 < best) {
                best = d2;
                best_speed = std::hypot(vx, vy);
                best_track = cur_track_[j];
            }
            if (d2 <= r2 && p_.credit == Credit::all) credited.push_back(cur_track_[j]);
        }
        const bool tp = best <= r2;
        if (tp && p_.credit == Credit::nearest) credited.push_back(best_track);
        if (best_speed >= 0) {
            SpeedBin& b = r_.bins[static_cast<std::size_t>(bin_of(best_speed))];
            ++b.events;
            b.true_positives += tp;
        }
        ++r_.corner_events;
        if (!tp) continue;
        ++r_.true_positives;
        r_.is_true[next_event_] = 1;
        r_.errors.push_back(static_cast<float>(std::sqrt(best)));
        for (const std::uint32_t id : credited) {
            if (!scores_.empty()) {
                const double sc = scores_[next_event_];
                tracks_[id].hits.push_back({e.t, std::isnan(sc) ? -std::numeric_limits<double>::infinity() : sc});
            }
            auto& open = tracks_[id].open;
            const std::int64_t lo = e.t - tol, hi = e.t + tol;
            if (open.size() > tracks_[id].first && lo <= open.back().second + 1)
                open.back().second = std::max(open.back().second, hi);
            else
                open.push_back({lo, hi});
        }
    }
}

void TruthMatcher::decide_samples_until(std::int64_t t_end, bool to_end) {
    for (; pending_first_ < pending_.size() && (to_end || pending_[pending_first_].t <= t_end); ++pending_first_) {
        const Pending& s = pending_[pending_first_];
        Track& tr = tracks_[s.track];
        while (tr.first < tr.open.size() && tr.open[tr.first].second < s.t) ++tr.first;
        if (tr.first > 64 && tr.first * 2 > tr.open.size()) {
            tr.open.erase(tr.open.begin(), tr.open.begin() + static_cast<std::ptrdiff_t>(tr.first));
            tr.first = 0;
        }
        const bool found = tr.first < tr.open.size() && tr.open[tr.first].first <= s.t;
        SpeedBin& b = r_.bins[static_cast<std::size_t>(bin_of(s.speed))];
        ++b.samples;
        ++r_.truth_samples;
        if (found) {
            ++b.recalled;
            ++r_.recalled;
            if (!scores_.empty()) r_.recalled_best.push_back(best_for(tr, s.t));
        }
    }
    if (pending_first_ > 4096 && pending_first_ * 2 > pending_.size()) {
        pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(pending_first_));
        pending_first_ = 0;
    }
}

// The largest score of the track's credited events within tolerance of sample time s (the
// samples of a track come in time order: a sliding-window maximum).
double TruthMatcher::best_for(Track& tr, std::int64_t s) {
    const std::int64_t lo = s - p_.tolerance_us, hi = s + p_.tolerance_us;
    auto& w = tr.window;
    for (; tr.pushed < tr.hits.size() && tr.hits[tr.pushed].first <= hi; ++tr.pushed) {
        const auto h = tr.hits[tr.pushed];
        while (w.size() > tr.window_first && w.back().second <= h.second) w.pop_back();
        w.push_back(h);
    }
    while (tr.window_first < w.size() && w[tr.window_first].first < lo) ++tr.window_first;
    if (tr.window_first > 64 && tr.window_first * 2 > w.size()) {
        w.erase(w.begin(), w.begin() + static_cast<std::ptrdiff_t>(tr.window_first));
        tr.window_first = 0;
    }
    if (tr.pushed > 64 && tr.pushed * 2 > tr.hits.size()) {
        tr.hits.erase(tr.hits.begin(), tr.hits.begin() + static_cast<std::ptrdiff_t>(tr.pushed));
        tr.pushed = 0;
    }
    // A recalled sample has a credited event within tolerance: the window is not empty.
    return tr.window_first < w.size() ? w[tr.window_first].second : -std::numeric_limits<double>::infinity();
}

void TruthMatcher::add_sample(std::span<const sim::TruthCorner> rows) {
    if (rows.empty()) return;
    const std::int64_t t = rows.front().t_us;
    for (const auto& r : rows)
        if (r.t_us != t) throw std::invalid_argument("add_sample: rows of several times");
    if (any_sample_ && t <= cur_.front().t_us) throw std::invalid_argument("add_sample: times must increase");
    if (any_sample_) {
        std::size_t visible = 0;
        for (const auto& c : cur_) visible += c.state == sim::CornerState::visible;
        r_.visible_corner_us += static_cast<double>(visible) * static_cast<double>(t - cur_.front().t_us);
    }
    prev_.swap(cur_);
    prev_track_.swap(cur_track_);
    cur_.assign(rows.begin(), rows.end());
    cur_track_.resize(cur_.size());
    for (std::size_t j = 0; j < cur_.size(); ++j) cur_track_[j] = track_of(cur_[j]);
    any_sample_ = true;
    match_events_until(t, false);
    for (std::size_t j = 0; j < cur_.size(); ++j)
        if (cur_[j].state == sim::CornerState::visible)
            pending_.push_back({t, cur_track_[j], std::hypot(cur_[j].vx, cur_[j].vy)});
    // Every event up to t is matched: the samples up to t - tolerance have all their matches.
    decide_samples_until(t - p_.tolerance_us, false);
}

TruthMatchResult TruthMatcher::finish() {
    if (any_sample_) {
        // After the last sample: its corners, unmoved.
        prev_.clear();
        prev_track_.clear();
        match_events_until(0, true);
    } else {
        r_.corner_events = corners_.size();  // no truth: nothing to match
    }
    decide_samples_until(0, true);
    return std::move(r_);
}

TruthMatchResult match_truth(std::span<const Event> corners, std::span<const sim::TruthCorner> truth,
                             const TruthMatchParams& params) {
    return match_truth(corners, {}, truth, params);
}

TruthMatchResult match_truth(std::span<const Event> corners, std::span<const double> scores,
                             std::span<const sim::TruthCorner> truth, const TruthMatchParams& params) {
    TruthMatcher m(corners, scores, params);
    std::size_t i = 0;
    while (i < truth.size()) {
        std::size_t j = i;
        while (j < truth.size() && truth[j].t_us == truth[i].t_us) ++j;
        m.add_sample(truth.subspan(i, j - i));
        i = j;
    }
    return m.finish();
}

}  // namespace evcorner::eval
