#pragma once
// A feature track's state as a tracker reports it: where track `id` is at time t, and
// why the tracker reports it now.

#include <cstdint>
#include <type_traits>

namespace evcorner {

/// Why a state is reported.
enum class TrackChange : std::uint8_t {
    initialised,  ///< the track's first state
    moved,        ///< the track moved (position or angle)
    stopped,      ///< the track's last state: a stopping rule ended it here
};

struct TrackState {
    std::int64_t t;      ///< microseconds
    float x;             ///< column of the feature's centre, pixel-index convention (pixel u spans u-0.5..u+0.5)
    float y;             ///< row
    float theta;         ///< patch angle, radians; positive turns +x toward +y
    std::uint64_t id;    ///< never reused within a run
    TrackChange why;

    friend constexpr bool operator==(const TrackState&, const TrackState&) = default;
};

static_assert(std::is_trivially_copyable_v<TrackState>);
static_assert(std::is_aggregate_v<TrackState>);

/// The name of a change: "initialised", "moved", "stopped".
constexpr const char* change_name(TrackChange c) noexcept {
    switch (c) {
        case TrackChange::initialised: return "initialised";
        case TrackChange::moved: return "moved";
        case TrackChange::stopped: return "stopped";
    }
    return "?";
}

}  // namespace evcorner
