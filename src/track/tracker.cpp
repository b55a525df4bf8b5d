#include "evcorner/track/tracker.hpp"

#include <algorithm>
#include <stdexcept>

#include "corner_tracker.hpp"

namespace evcorner {

namespace {

/// HASTE with the front end it lacks: seeds from corner events, a cap on tracks.
class HasteTracker final : public Tracker {
public:
    HasteTracker(SensorSize size, HasteMethod m, const TrackerConfig& c)
        : haste_(size, params(m, c), c.seeds), config_(c), size_(size) {
        started_seeds_ = c.seeds.size();
        for (const auto& s : c.seeds) next_id_ = std::max(next_id_, s.id + 1);
        if (!(c.seed_radius >= 0)) throw std::invalid_argument("seed radius must not be negative");
    }

    std::span<const TrackState> process(const Event& e, bool corner) override {
        if (corner && config_.seed_from_corners && size_.contains(e) &&
            haste_.live_tracks() + haste_.pending_tracks() < config_.max_tracks &&
            !haste_.track_near(e.x, e.y, config_.seed_radius)) {
            haste_.start({e.t, static_cast<float>(e.x), static_cast<float>(e.y), 0.0f, next_id_++});
            ++corner_seeds_;
        }
        const auto out = haste_.process(e);
        for (const TrackState& s : out) initialised_ += s.why == TrackChange::initialised;
        return out;
    }

    [[nodiscard]] TrackerStats stats() const override {
        TrackerStats s;
        s.started = started_seeds_ - haste_.pending_tracks() + corner_seeds_;
        s.initialised = initialised_;
        s.skipped_seeds = haste_.skipped_seeds();
        s.updates = haste_.track_updates();
        s.live = haste_.live_tracks();
        return s;
    }

private:
    static HasteParams params(HasteMethod m, const TrackerConfig& c) {
        HasteParams p;
        p.method = m;
        p.init = c.init;
        p.stop = c.stop;
        p.authors_seed_time = c.authors_seed_time;
        return p;
    }

    Haste haste_;
    TrackerConfig config_;
    SensorSize size_;
    std::uint64_t next_id_ = 0, started_seeds_ = 0, corner_seeds_ = 0, initialised_ = 0;
};

template <HasteMethod M>
std::unique_ptr<Tracker> make_haste(SensorSize size, const TrackerConfig& c) {
    return std::make_unique<HasteTracker>(size, M, c);
}

const TrackerEntry kTrackers[] = {
    {"haste-correlation-star",
     "HASTE (Alzugaray and Chli, BMVC 2020): normalised template, uniform weights, incremental; the fastest",
     make_haste<HasteMethod::haste_correlation_star>, true},
    {"haste-difference-star", "HASTE: squared difference to the window's model, incremental",
     make_haste<HasteMethod::haste_difference_star>, true},
    {"haste-correlation", "HASTE: Gaussian-weighted correlation, each event sampled once",
     make_haste<HasteMethod::haste_correlation>, true},
    {"haste-difference", "HASTE: squared difference to the window's model, recomputed per event",
     make_haste<HasteMethod::haste_difference>, true},
    {"correlation", "multi-hypothesis tracker (Alzugaray and Chli, 3DV 2019): Gaussian correlation, recomputed per event",
     make_haste<HasteMethod::correlation>, true},
    {"corners",
     "corner events alone: each updates the nearest live track within --seed-radius (constant-velocity "
     "alpha-beta filter); far cheaper, for when every corner is a measurement",
     detail::make_corner_tracker},
};

}  // namespace

std::span<const TrackerEntry> tracker_registry() { return kTrackers; }

std::string tracker_names() {
    std::string s;
    for (const auto& t : kTrackers) s += (s.empty() ? "" : ", ") + std::string(t.name);
    return s;
}

const TrackerEntry& tracker_entry(std::string_view name) {
    for (const auto& t : kTrackers)
        if (t.name == name) return t;
    throw std::invalid_argument("unknown tracker '" + std::string(name) + "' (trackers: " + tracker_names() + ")");
}

std::vector<std::string> tracker_list(std::span<const std::string> names) {
    std::vector<std::string> out;
    const auto add = [&](std::string_view n) {
        if (std::find(out.begin(), out.end(), n) == out.end()) out.emplace_back(n);
    };
    for (const std::string& item : names) {
        std::size_t at = 0;
        while (at <= item.size()) {
            const std::size_t comma = std::min(item.find(',', at), item.size());
            const std::string_view name = std::string_view(item).substr(at, comma - at);
            at = comma + 1;
            if (name.empty()) continue;
            if (name == "all") {
                for (const TrackerEntry& t : kTrackers) add(t.name);
            } else {
                add(tracker_entry(name).name);
            }
        }
    }
    if (out.empty()) throw std::invalid_argument("no tracker named (trackers: " + tracker_names() + ")");
    return out;
}

}  // namespace evcorner
