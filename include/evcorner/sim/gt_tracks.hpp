#pragma once
// Ground-truth feature tracks of a simulated scene: every truth corner (truth.hpp) as a track
// while it is visible, sampled at the times the caller gives (a fixed rate).
//
// One track per visible stretch: a corner that is hidden (occluded or off the sensor) at a
// sample ends its track at its last visible sample; seen again, it starts a new track under a
// new id. Ids count from 0 in the order tracks start (at one sample time, by object, then
// corner). Positions are in the trackers' pixel-index convention (TrackState: pixel u spans
// u - 0.5 .. u + 0.5), the truth's pixel-centre coordinates minus 0.5, so that a corner at the
// centre of pixel (u, v) is at (u, v). Each state says why: initialised (a track's first
// sample), moved, stopped (its last). A sample is emitted one sample late, once it is known
// whether the track goes on; finish() emits the last ones. Rows come in time order.

#include <cstdint>
#include <span>
#include <vector>

#include "evcorner/sim/truth.hpp"
#include "evcorner/track/track_state.hpp"

namespace evcorner::sim {

class GtTrackSampler {
public:
    /// Takes every corner of the scene at one sample time (corners_at's rows, in its order;
    /// times increasing from call to call) and appends the states now complete to `out`.
    void sample(std::span<const TruthCorner> corners, std::vector<TrackState>& out);
    /// Appends the last state of every live track (as stopped).
    void finish(std::vector<TrackState>& out);
    /// Tracks started so far.
    [[nodiscard]] std::uint64_t tracks() const noexcept { return next_id_; }

private:
    struct Live {
        bool alive = false;
        TrackState pending{};
    };
    std::vector<Live> live_;  // per corner, in corners_at's order
    std::uint64_t next_id_ = 0;
};

/// The sample times of a rate: t_k = round(k * 1e6 / rate_hz) microseconds, k = 0, 1, ...
/// rate_hz must be > 0 and at most 1e6.
std::int64_t gt_sample_time(std::uint64_t k, double rate_hz) noexcept;

}  // namespace evcorner::sim
