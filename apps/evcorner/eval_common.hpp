#pragma once
// What label, eval and render share: opening or loading an event file, running a
// detector over it, parsing a time option, and the feature-track options.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evcorner/registry.hpp"
#include "evcorner/eval/feature_tracks.hpp"
#include "evcorner/event.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/sensor.hpp"
#include "commands.hpp"

namespace evcorner::cli {

struct InputOptions {
    std::string format = "auto";
    std::string size;  ///< WxH, empty: the file's own, else 240x180
    io::ReaderOptions reader;  ///< the format table's reader options (add_reader_options)
};

struct LoadedEvents {
    std::vector<Event> events;
    SensorSize size;
};

/// Opens `path` for reading batch by batch, with the options of the command line.
std::unique_ptr<io::EventReader> open_events(const std::string& path, const InputOptions& o);

/// Reads every event of `path` into memory (label, bench: random access), with a progress
/// bar on standard error when `progress` and it is a terminal.
LoadedEvents load_events(const std::string& path, const InputOptions& o, bool progress = false);

/// The sensor events of `reader` are on: its own, else 240x180.
SensorSize sensor_of(const io::EventReader& reader);

/// Adds --format and the reader options (add_reader_options), and --size.
void add_load_options(CLI::App& cmd, InputOptions& o);

/// The feature-track parameters as options (--ft-*); `overlap` receives the name.
void add_feature_track_options(CLI::App& cmd, eval::FeatureTrackParams& p, std::string& overlap);
/// Completes `p` from the option strings; throws std::invalid_argument.
void finish_feature_track_params(eval::FeatureTrackParams& p, const std::string& overlap);

/// The corner events `detector` finds in `events` (a fresh detector).
std::vector<Event> detect_corners(const DetectorConfig& detector, const std::vector<Event>& events, SensorSize size);

/// A time option: seconds on the stream's clock ("51.99"), or "+S" seconds after
/// `first_us`, or "-S" seconds before `last_us`. Throws std::invalid_argument.
std::int64_t parse_time_option(const std::string& text, std::int64_t first_us, std::int64_t last_us);

}  // namespace evcorner::cli
