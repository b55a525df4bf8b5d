#pragma once
// Reading track files back: every layout TrackWriter writes (track_writer.hpp), and the
// HASTE app's output, gzip- or zstd-compressed or not.
//   .npy   the TrackWriter record layout
//   .csv   the header `id,t,x,y,theta,change`
//   other  text, one sample per line: `id t x y` (whitespace: ddft) or `t,x,y,theta,id`
//          (commas: haste); blank lines and lines starting with '#' are skipped
// Rows keep the file's order.

#include <string>
#include <vector>

#include "evcorner/track_point.hpp"

namespace evcorner {

/// Every sample of the track file `path`. Throws InputError naming the file and line
/// (or byte offset) of a malformed row: a wrong field count, a field that is not a finite
/// number, an id that is not a whole number >= 0, a text file mixing the two layouts.
std::vector<TrackPoint> read_track_points(const std::string& path);

}  // namespace evcorner
