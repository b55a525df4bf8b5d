#include "evcorner/sim/gt_tracks.hpp"

#include <cmath>

namespace evcorner::sim {

void GtTrackSampler::sample(std::span<const TruthCorner> corners, std::vector<TrackState>& out) {
    if (live_.size() < corners.size()) live_.resize(corners.size());
    for (std::size_t i = 0; i < corners.size(); ++i) {
        const TruthCorner& c = corners[i];
        Live& l = live_[i];
        const bool visible = c.state == CornerState::visible;
        if (l.alive) {
            if (!visible) {
                if (l.pending.why != TrackChange::initialised) l.pending.why = TrackChange::stopped;
                out.push_back(l.pending);
                l.alive = false;
                continue;
            }
            out.push_back(l.pending);
        }
        if (!visible) continue;
        const TrackChange why = l.alive ? TrackChange::moved : TrackChange::initialised;
        if (!l.alive) l.pending.id = next_id_++;
        l.pending = {c.t_us, static_cast<float>(c.x - 0.5), static_cast<float>(c.y - 0.5), 0.0f, l.pending.id, why};
        l.alive = true;
    }
}

void GtTrackSampler::finish(std::vector<TrackState>& out) {
    for (Live& l : live_) {
        if (!l.alive) continue;
        if (l.pending.why != TrackChange::initialised) l.pending.why = TrackChange::stopped;
        out.push_back(l.pending);
        l.alive = false;
    }
}

std::int64_t gt_sample_time(std::uint64_t k, double rate_hz) noexcept {
    return std::llround(static_cast<double>(k) * 1e6 / rate_hz);
}

}  // namespace evcorner::sim
