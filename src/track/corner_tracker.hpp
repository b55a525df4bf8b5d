#pragma once
// The tracker on corner events alone ("corners" in the registry): every corner event is a
// measurement of the live track nearest to it, so the cost follows the corner events, not
// the events or the tracks' patches.
//
// Per event e (time order):
//   - due seeds (t <= e.t) start tracks at their positions (state initialised at e.t);
//   - a non-corner event does nothing more;
//   - a corner event at (x, y) is matched to the live track whose predicted position (its
//     position moved by its velocity over e.t - its last update) lies nearest, within
//     `radius` px, among the live tracks whose last position is within the reach
//     (corner_tracker_reach) of (x, y)
//     in both coordinates (what the grid looks at); ties: the older track. A track not
//     updated for longer than max_idle_us is expired: it takes no corner and stops at the
//     next sweep (below). Matched: an alpha-beta filter
//     (constant velocity): r = z - prediction; position = prediction + kAlpha r; velocity +=
//     kBeta r / dt; state moved. Unmatched: with seed_from_corners and fewer than max_tracks
//     live, a new track (velocity 0, initialised), ids counting up, never reused;
//   - a track whose position leaves the sensor stops; with min_separation, when an updated
//     track comes within it of others: it stops if one of them is older, else they stop;
//   - sweeps: at the first event at or after the next sweep time (the first event, then
//     every max_idle_us / 8 of stream time after the last sweep), before anything else,
//     every expired track stops (a stopped state at its last position, at the event's time).
// Several stops at one event come in id order.

#include <algorithm>
#include <memory>

#include "evcorner/track/tracker.hpp"

namespace evcorner::detail {

/// px: the grid's cell side, which is also how far (in each coordinate) a track's last
/// position may lie from a corner event that updates it: the radius rounded up, at least 8.
constexpr int corner_tracker_reach(float radius) noexcept {
    const int r = static_cast<int>(radius);
    return std::max(8, static_cast<float>(r) < radius ? r + 1 : r);
}
inline constexpr float kCornerTrackerAlpha = 0.5f;
inline constexpr float kCornerTrackerBeta = kCornerTrackerAlpha * kCornerTrackerAlpha / (2 - kCornerTrackerAlpha);
/// max_idle_us when the configuration gives none (0): corner tracks need a gap to end.
inline constexpr std::int64_t kCornerTrackerIdleUs = 50000;

std::unique_ptr<Tracker> make_corner_tracker(SensorSize size, const TrackerConfig& config);

}  // namespace evcorner::detail
