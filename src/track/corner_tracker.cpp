#include "corner_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "evcorner/event_check.hpp"

namespace evcorner::detail {

namespace {

class CornerTracker final : public Tracker {
public:
    CornerTracker(SensorSize size, const TrackerConfig& c) : size_(size), c_(c) {
        if (size.width <= 0 || size.height <= 0) throw std::invalid_argument("corner tracker: empty sensor");
        if (!(c.seed_radius > 0)) throw std::invalid_argument("corner tracker: the radius must be above 0");
        if (!(c.seed_radius <= 1000)) throw std::invalid_argument("corner tracker: the radius is at most 1000 px");
        cell_ = corner_tracker_reach(c.seed_radius);
        reach_ = static_cast<float>(cell_);
        if (c_.stop.max_idle_us <= 0) c_.stop.max_idle_us = kCornerTrackerIdleUs;
        cols_ = (size.width + cell_ - 1) / cell_;
        rows_ = (size.height + cell_ - 1) / cell_;
        cells_.resize(static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_));
        seeds_ = c.seeds;
        std::stable_sort(seeds_.begin(), seeds_.end(), [](const TrackSeed& a, const TrackSeed& b) { return a.t < b.t; });
        for (const TrackSeed& s : seeds_) {
            if (!(s.x >= 0 && s.y >= 0 && s.x < static_cast<float>(size.width) && s.y < static_cast<float>(size.height)))
                throw std::invalid_argument("corner tracker: seed " + std::to_string(s.id) + " is off the sensor");
            next_id_ = std::max(next_id_, s.id + 1);
        }
    }

    std::span<const TrackState> process(const Event& e, bool corner) override {
        if (!size_.contains(e) || e.p > 1) throw InvalidEvent(e, EventLimits{size_});
        if (e.t < last_t_)
            throw std::invalid_argument("corner tracker: event at t = " + std::to_string(e.t) + " us comes after one at t = " +
                                        std::to_string(last_t_) + " us (events must be in time order)");
        last_t_ = e.t;
        out_.clear();
        if (e.t >= next_sweep_) sweep(e.t);
        while (next_seed_ < seeds_.size() && seeds_[next_seed_].t <= e.t) {
            const TrackSeed& s = seeds_[next_seed_++];
            start(s.x, s.y, s.id, e.t);
        }
        if (!corner) return out_;
        const float zx = static_cast<float>(e.x), zy = static_cast<float>(e.y);
        const int cx = e.x / cell_, cy = e.y / cell_;
        std::uint32_t best = kNone;
        float best_d2 = c_.seed_radius * c_.seed_radius;
        for (int gy = std::max(cy - 1, 0); gy <= std::min(cy + 1, rows_ - 1); ++gy)
            for (int gx = std::max(cx - 1, 0); gx <= std::min(cx + 1, cols_ - 1); ++gx) {
                auto& cell = cells_[static_cast<std::size_t>(gy) * static_cast<std::size_t>(cols_) + static_cast<std::size_t>(gx)];
                for (const std::uint32_t i : cell) {
                    const Track& t = tracks_[i];
                    if (e.t - t.t_last > c_.stop.max_idle_us) continue;  // expired: the next sweep stops it
                    ++updates_;
                    if (std::fabs(t.x - zx) > reach_ || std::fabs(t.y - zy) > reach_) continue;
                    const float dt = static_cast<float>(e.t - t.t_last) * 1e-6f;
                    const float px = t.x + t.vx * dt, py = t.y + t.vy * dt;
                    const float d2 = (px - zx) * (px - zx) + (py - zy) * (py - zy);
                    if (d2 < best_d2 || (d2 == best_d2 && best != kNone && t.id < tracks_[best].id)) {
                        best_d2 = d2;
                        best = i;
                    }
                }
            }
        if (best != kNone) {
            update(best, zx, zy, e.t);
        } else if (c_.seed_from_corners && live_ < c_.max_tracks) {
            start(zx, zy, next_id_++, e.t);
            ++corner_seeds_;
        }
        return out_;
    }

    [[nodiscard]] TrackerStats stats() const override {
        TrackerStats s;
        s.started = next_seed_ + corner_seeds_;
        s.initialised = s.started;
        s.updates = updates_;
        s.live = live_;
        return s;
    }

private:
    static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    struct Track {
        std::uint64_t id = 0;
        float x = 0, y = 0, vx = 0, vy = 0;
        std::int64_t t_last = 0;
        std::uint32_t cell = 0;
        bool live = false;
    };

    std::uint32_t cell_of(float x, float y) const noexcept {
        const int gx = std::clamp(static_cast<int>(x) / cell_, 0, cols_ - 1);
        const int gy = std::clamp(static_cast<int>(y) / cell_, 0, rows_ - 1);
        return static_cast<std::uint32_t>(gy * cols_ + gx);
    }

    void start(float x, float y, std::uint64_t id, std::int64_t t) {
        std::uint32_t i;
        if (!free_.empty()) {
            i = free_.back();
            free_.pop_back();
        } else {
            i = static_cast<std::uint32_t>(tracks_.size());
            tracks_.emplace_back();
        }
        Track& tr = tracks_[i];
        tr = {id, x, y, 0, 0, t, cell_of(x, y), true};
        cells_[tr.cell].push_back(i);
        ++live_;
        out_.push_back({t, x, y, 0.0f, id, TrackChange::initialised});
    }

    void stop(std::uint32_t i, std::int64_t t) {
        Track& tr = tracks_[i];
        auto& cell = cells_[tr.cell];
        const auto at = std::find(cell.begin(), cell.end(), i);
        *at = cell.back();
        cell.pop_back();
        tr.live = false;
        --live_;
        free_.push_back(i);
        out_.push_back({t, tr.x, tr.y, 0.0f, tr.id, TrackChange::stopped});
    }

    void update(std::uint32_t i, float zx, float zy, std::int64_t t) {
        Track& tr = tracks_[i];
        const float dt = static_cast<float>(t - tr.t_last) * 1e-6f;
        const float px = tr.x + tr.vx * dt, py = tr.y + tr.vy * dt;
        const float rx = zx - px, ry = zy - py;
        tr.x = px + kCornerTrackerAlpha * rx;
        tr.y = py + kCornerTrackerAlpha * ry;
        if (dt > 0) {
            tr.vx += kCornerTrackerBeta * rx / dt;
            tr.vy += kCornerTrackerBeta * ry / dt;
        }
        tr.t_last = t;
        out_.push_back({t, tr.x, tr.y, 0.0f, tr.id, TrackChange::moved});
        if (!(tr.x >= 0 && tr.y >= 0 && tr.x < static_cast<float>(size_.width) && tr.y < static_cast<float>(size_.height))) {
            stop(i, t);
            return;
        }
        const std::uint32_t cell = cell_of(tr.x, tr.y);
        if (cell != tr.cell) {
            auto& old = cells_[tr.cell];
            *std::find(old.begin(), old.end(), i) = old.back();
            old.pop_back();
            cells_[cell].push_back(i);
            tr.cell = cell;
        }
        if (c_.stop.min_separation > 0) separate(i, t);
    }

    // When live tracks lie within min_separation of track i: i stops if one of them is older,
    // else they all stop (each younger than i).
    void separate(std::uint32_t i, std::int64_t t) {
        const double sep2 = c_.stop.min_separation * c_.stop.min_separation;
        const int cx = static_cast<int>(tracks_[i].cell) % cols_, cy = static_cast<int>(tracks_[i].cell) / cols_;
        const int reach = static_cast<int>(std::min(std::ceil(c_.stop.min_separation / cell_), double(std::max(cols_, rows_))));
        near_.clear();
        for (int gy = std::max(cy - reach, 0); gy <= std::min(cy + reach, rows_ - 1); ++gy)
            for (int gx = std::max(cx - reach, 0); gx <= std::min(cx + reach, cols_ - 1); ++gx)
                for (const std::uint32_t j : cells_[static_cast<std::size_t>(gy) * static_cast<std::size_t>(cols_) +
                                                    static_cast<std::size_t>(gx)]) {
                    if (j == i) continue;
                    const double dx = tracks_[i].x - tracks_[j].x, dy = tracks_[i].y - tracks_[j].y;
                    if (dx * dx + dy * dy >= sep2) continue;
                    if (tracks_[j].id < tracks_[i].id) {
                        stop(i, t);
                        return;
                    }
                    near_.push_back(j);
                }
        std::sort(near_.begin(), near_.end(), [&](std::uint32_t a, std::uint32_t b) { return tracks_[a].id < tracks_[b].id; });
        for (const std::uint32_t j : near_) stop(j, t);
    }

    // Stops every expired track, in id order.
    void sweep(std::int64_t t) {
        near_.clear();
        for (std::uint32_t i = 0; i < tracks_.size(); ++i)
            if (tracks_[i].live && t - tracks_[i].t_last > c_.stop.max_idle_us) near_.push_back(i);
        std::sort(near_.begin(), near_.end(), [&](std::uint32_t a, std::uint32_t b) { return tracks_[a].id < tracks_[b].id; });
        for (const std::uint32_t i : near_) stop(i, t);
        next_sweep_ = t + std::max<std::int64_t>(c_.stop.max_idle_us / 8, 1);
    }

    SensorSize size_;
    TrackerConfig c_;
    int cell_ = 8;  // px: the grid's cell side, the reach
    float reach_ = 8;
    int cols_ = 0, rows_ = 0;
    std::vector<std::vector<std::uint32_t>> cells_;
    std::vector<Track> tracks_;
    std::vector<std::uint32_t> free_;
    std::vector<std::uint32_t> near_;  // scratch: tracks to stop
    std::vector<TrackSeed> seeds_;
    std::size_t next_seed_ = 0;
    std::vector<TrackState> out_;
    std::uint64_t next_id_ = 0, corner_seeds_ = 0, updates_ = 0;
    std::size_t live_ = 0;
    std::int64_t last_t_ = std::numeric_limits<std::int64_t>::min(), next_sweep_ = std::numeric_limits<std::int64_t>::min();
};

}  // namespace

std::unique_ptr<Tracker> make_corner_tracker(SensorSize size, const TrackerConfig& config) {
    return std::make_unique<CornerTracker>(size, config);
}

}  // namespace evcorner::detail
