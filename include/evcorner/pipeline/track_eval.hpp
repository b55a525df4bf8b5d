#pragma once
// Trackers against ground-truth (GT) tracks: every tracker asked for, under every seeding
// asked for, over one sequence, scored by the feature-track benchmark's metric
// (eval/track_metrics.hpp; docs/tracking-metrics.md). `evcorner eval --tracks` is this per
// sequence, plus printing.
//
//   evaluate_trackers(files, trackers, seedings)   one sequence: one row per tracker x seeding
//   evaluate_track_file(tracks, gt, seeds)         tracks already on disk (the authors' HASTE app's)
//
// The sequence's events are read into memory ONCE and replayed to every run (a suite's
// scenes are at most a few million events of 16 bytes; a long recording would want one read
// per run instead); each run is run_track() (pipeline/track.hpp) over them, its states kept
// in memory and scored. Seedings:
//   gt        the GT file itself: each GT id's first row seeds that id (read_seeds_file), HASTE's
//             uncentered start, no stopping rule beyond the tracker's own (seeds off [0, W) x [0, H),
//             which the trackers refuse, are left out and counted); scored by id without
//             the start shift (a tracker reports its first state later than its seed, on the
//             GT's clock: TrackMetricOptions::align_start = false)
//   detector  a detector's corner events seed the tracks (the front end of `evcorner track -d`,
//             with its defaults: seed radius 10 px, at most 200 tracks, max idle 200 ms, min
//             separation 3 px, centered start); scored by association: each track takes the
//             nearest free GT track within associate_px (3) at its first time
//   seeds     a HASTE seeds file (`t,x,y,theta,id`); scored through the seeds: track k against
//             the GT track nearest seed k at its time (within 1 px), from then on
// Each row: the synchronous FA, EFA, FA@5, TE@5 (the benchmark's mode) and the asynchronous FA.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "evcorner/detector_config.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/track/haste.hpp"

namespace evcorner::pipeline {

/// Where a seeding's tracks start, and how they are matched to GT (above).
enum class SeedingKind : std::uint8_t { gt, detector, seeds };

struct TrackSeeding {
    SeedingKind kind = SeedingKind::gt;
    std::string name;         ///< as the rows name it ("GT t0", the detector's name, ...)
    DetectorConfig detector;  ///< detector: the front end's detector (one thread, no NMS)
    std::string seeds_file;   ///< seeds: the file
    HasteInit init = HasteInit::uncentered;
    TrackStopRules stop;
    float seed_radius = 10;        ///< detector: pixels
    std::size_t max_tracks = 200;  ///< detector
};

/// "GT t0": the GT's first samples, uncentered, no stopping rules.
TrackSeeding gt_seeding();
/// A detector as the front end, with `evcorner track -d`'s defaults (above); named after it.
TrackSeeding detector_seeding(DetectorConfig detector);
/// The seeds of a file, uncentered unless told, no stopping rules; named `name`.
TrackSeeding seeds_seeding(std::string seeds_file, std::string name, HasteInit init = HasteInit::uncentered);

struct TrackEvalFiles {
    std::string sequence;         ///< the rows' name for it
    std::string events;           ///< the event file
    std::string format = "auto";  ///< its format (io/open.hpp)
    io::ReaderOptions reader;     ///< reader.sensor: the sensor when the file does not say
    std::string gt;               ///< the GT track file (`id t x y`, evcorner simulate --gt-tracks)
};

struct TrackEvalParams {
    double associate_px = 3;    ///< detector seedings: the association radius
    int max_threshold_px = 31;  ///< thresholds 1 .. this
};

/// One tracker under one seeding on one sequence.
struct TrackEvalRow {
    std::string sequence, tracker, seeding;
    SeedingKind kind = SeedingKind::gt;
    double fa = 0, efa = 0, fa_5 = 0, te_5 = 0;  ///< synchronous
    double fa_async = 0;                         ///< FA of the asynchronous variant
    std::size_t predicted_tracks = 0, gt_tracks = 0;
    std::size_t counted_tracks = 0;    ///< measured (synchronous)
    std::size_t skipped_tracks = 0;    ///< fewer than 2 GT samples to compare
    std::size_t unmatched_tracks = 0;  ///< no GT track of the id, or none in reach
    /// gt, seeds: seeds left out, off [0, W) x [0, H) where the trackers refuse them (a GT
    /// corner within half a pixel of the border); their GT tracks have no prediction and,
    /// as in the benchmark, count nowhere.
    std::size_t unseeded_tracks = 0;
    std::uint64_t states = 0;          ///< states the tracker reported
    std::uint64_t updates = 0;         ///< (event, track) pairs processed
    double ns_per_update = 0;          ///< tracking time per pair; NaN without a run (a file) or pairs
    double track_s = 0;                ///< in the tracker's calls
    /// The GT's sampling rate: 1 / the median step between consecutive samples of a GT track
    /// (0 when no track has two).
    double gt_rate_hz = 0;
};

/// After each row: for a progress line.
using TrackEvalRowFn = std::function<void(const TrackEvalRow&)>;

/// Every tracker of `trackers` (names of tracker_registry()) under every seeding, in that
/// order (tracker-major), over the events of `files`, scored against its GT. Checks every
/// name and seeding before reading events. Throws std::invalid_argument (an unknown tracker
/// or detector, a bad seeding) and InputError (an unreadable events, GT or seeds file).
std::vector<TrackEvalRow> evaluate_trackers(const TrackEvalFiles& files, std::span<const std::string> trackers,
                                            std::span<const TrackSeeding> seedings,
                                            const TrackEvalParams& params = {}, const TrackEvalRowFn& on_row = {});

/// A track file (any layout read_track_points() reads: the HASTE app's output too) against
/// the GT file `gt`, matched through the seeds of `seeds_file` (the seeds it was run from).
/// The row's tracker and seeding names are left empty; ns_per_update is NaN.
TrackEvalRow evaluate_track_file(const std::string& tracks, const std::string& gt, const std::string& seeds_file,
                                 const TrackEvalParams& params = {});

}  // namespace evcorner::pipeline
