#pragma once
// Where a tracker starts a track: at the first event at or after time t, at (x, y) with
// patch angle theta, under the given id.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace evcorner {

struct TrackSeed {
    std::int64_t t;      ///< microseconds
    float x;             ///< pixel-index convention, as TrackState
    float y;
    float theta;         ///< radians
    std::uint64_t id;
};

/// Seeds from a HASTE seeds file: whitespace-separated tokens `t,x,y,theta[,id]` (t in
/// decimal seconds, read exactly to the microsecond; theta radians; id 0 when omitted).
/// A file whose first line has no comma is a track file (track_file.hpp: `id t x y` rows,
/// such as ground-truth tracks): each track's first row seeds it, under its id, theta 0 (as
/// the feature-track benchmark seeds a tracker at the GT's first samples).
/// Throws InputError naming the file and line of a malformed token.
std::vector<TrackSeed> read_seeds_file(const std::string& path);

}  // namespace evcorner
