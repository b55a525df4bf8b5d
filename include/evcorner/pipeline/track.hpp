#pragma once
// The tracking pipeline: events from a reader, optionally through a registered detector
// (whose corner events seed tracks: the front end), through a registered tracker
// (track/tracker.hpp), to a sink of track states. `evcorner track` is this plus option
// parsing and printing; the bindings call the same functions.
//
//   run_track(reader, options, sink)   any EventReader in, states to a callback
//   track_file(files, options)         paths in and out, as `evcorner track` takes them
//
// Data flows one way: reader -> [detector ->] tracker -> sink. An input error is rethrown
// and a file output is then absent. Tracking time is measured around the tracker's calls.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

#include "evcorner/io/event_reader.hpp"
#include "evcorner/pipeline/detect.hpp"
#include "evcorner/track/tracker.hpp"
#include "evcorner/track/track_writer.hpp"

namespace evcorner::pipeline {

struct TrackOptions {
    std::string tracker = "haste-correlation-star";  ///< a name of tracker_registry()
    TrackerConfig config;                            ///< seeds, stopping rules, HASTE's start
    /// Seed from this detector's corner events (config.seed_from_corners is then set);
    /// nullopt: config.seeds only.
    std::optional<DetectOptions> detect;
};

struct TrackSummary {
    std::string tracker;
    std::string detector;  ///< empty without one
    SensorSize sensor;
    std::uint64_t events = 0;
    std::uint64_t corners = 0;  ///< with a detector
    std::uint64_t states = 0;   ///< states written
    TrackerStats stats;
    double track_s = 0;  ///< in the tracker's calls
    double wall_s = 0;

    /// Tracking time per (event, track) pair processed; NaN without any.
    [[nodiscard]] double ns_per_update() const noexcept;
    /// Tracking time per event of the stream; NaN without events.
    [[nodiscard]] double ns_per_event() const noexcept;
};

using TrackStatesFn = std::function<void(std::span<const TrackState>)>;

/// Throws std::invalid_argument (a usage error) for an unknown tracker, no seeds and no
/// detector, or detector options check_detect_options() refuses (threads > 1 included:
/// the tracker runs on one thread).
void check_track_options(const TrackOptions& options);

/// Runs the tracker (and the detector) over every event of `reader` (sensor:
/// reader.sensor(), else `fallback`); `sink` gets the states each event produced, in order.
TrackSummary run_track(io::EventReader& reader, const TrackOptions& options, const TrackStatesFn& sink,
                       SensorSize fallback = kDavis240);

struct TrackFiles {
    std::string input;            ///< a file, or "-" for standard input
    std::string format = "auto";  ///< input format (io/open.hpp)
    io::ReaderOptions reader;
    std::string output = "-";     ///< the track file ("-": standard output)
    std::optional<TrackFormat> tracks_format;  ///< nullopt: from the output's extension
};

/// Opens the input and the output (after checking that the output is not the input and
/// can be created), runs run_track() and closes the output; on any error it is absent.
TrackSummary track_file(const TrackFiles& files, const TrackOptions& options);

}  // namespace evcorner::pipeline
