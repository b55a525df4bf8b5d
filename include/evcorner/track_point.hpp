#pragma once
// One sample of a feature track as track files and the tracking metric see it: track `id`
// at (x, y) at time t. Time in seconds, as in the feature-track benchmark's files; x, y in
// the pixel-index convention of TrackState (pixel u spans u-0.5 .. u+0.5).

#include <cstdint>

namespace evcorner {

struct TrackPoint {
    std::uint64_t id;
    double t;  ///< seconds
    double x;
    double y;

    friend constexpr bool operator==(const TrackPoint&, const TrackPoint&) = default;
};

}  // namespace evcorner
