#pragma once
// What every tracker is, and the list of them. A tracker is a small stateful object with
// one per-event verb: process(event, corner) takes every event of the stream, with the
// corner flag of the detector in front of it (false without one), and returns the track
// states that event produced (valid until the next call). No I/O inside.
//
// Every tracker evcorner runs is named in ONE place, tracker_registry(): adding one is
// one entry there. Commands, the pipeline (pipeline/track.hpp) and the bindings take the
// names, summaries and the constructor from it.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/track/haste.hpp"
#include "evcorner/track/track_seed.hpp"
#include "evcorner/track/track_state.hpp"

namespace evcorner {

/// Where tracks start and when they stop.
struct TrackerConfig {
    /// Tracks to start, each at the first event at or after its time.
    std::vector<TrackSeed> seeds;
    /// Also start a track at every corner event farther than seed_radius from every
    /// track (a front end fed by a detector); ids then count up from the seeds' largest + 1.
    bool seed_from_corners = false;
    float seed_radius = 10;       ///< pixels
    std::size_t max_tracks = 200;  ///< tracks (running or starting) at once; corners beyond start none
    TrackStopRules stop;
    /// HASTE only.
    HasteInit init = HasteInit::centered;
    bool authors_seed_time = false;
};

struct TrackerStats {
    std::uint64_t started = 0;        ///< tracks begun (seeds due, corners that seeded)
    std::uint64_t initialised = 0;    ///< of those, tracks that reported a first state
    std::uint64_t skipped_seeds = 0;  ///< seeds that could not start (docs/tracking.md)
    std::uint64_t updates = 0;        ///< (event, track) pairs processed
    std::size_t live = 0;             ///< running now
};

class Tracker {
public:
    virtual ~Tracker() = default;
    /// Throws InvalidEvent (off the sensor) or std::invalid_argument (time going back).
    virtual std::span<const TrackState> process(const Event& e, bool corner) = 0;
    [[nodiscard]] virtual TrackerStats stats() const = 0;
};

struct TrackerEntry {
    std::string_view name;     ///< on the command line
    std::string_view summary;  ///< one line for --help
    std::unique_ptr<Tracker> (*make)(SensorSize, const TrackerConfig&);
    bool takes_init = false;   ///< TrackerConfig::init applies (a patch tracker's start)
};

/// THE list, in the order --help gives it.
std::span<const TrackerEntry> tracker_registry();
/// The entry of `name`; throws std::invalid_argument naming the trackers there are.
const TrackerEntry& tracker_entry(std::string_view name);
/// "correlation, haste-correlation, ...".
std::string tracker_names();
/// Names as a command line gives them: each item one name, a comma-separated list of them,
/// or "all" (every tracker, in the registry's order); each tracker once, in the order first
/// named. Throws std::invalid_argument for an unknown name or when none is named.
std::vector<std::string> tracker_list(std::span<const std::string> names);

}  // namespace evcorner
