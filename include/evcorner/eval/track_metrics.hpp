#pragma once
// The feature-track benchmark's metric (docs/tracking-metrics.md, after Messikommer et al.,
// CVPR 2023): feature age (FA), expected feature age (EFA), FA and tracking error at 5 px,
// of predicted tracks against ground-truth (GT) tracks, both as TrackPoint rows.
//
// Per predicted id, at each threshold e = 1 .. 31 px ("synchronous", the benchmark's run):
//   G  the GT rows of the id; P the predicted rows (each in time order; of rows sharing a
//      time, the last one holds);
//   Gc G cut to P's first .. last time when G ends after P, else G; fewer than 2 rows: the
//      track is skipped (counted nowhere);
//   E  the distance of each Gc row after the first to P interpolated linearly at its time
//      (extrapolated beyond P's ends; a one-row P stays where it is);
//   the first E[i] > e ends the track at Gc row i - 1 (row 0 when i <= 1): the age stops one
//      GT sample before the last good one, as the published numbers were made;
//   fa = (Gc[end].t - Gc[0].t) / (G's last t - G's first t), 0 when end is row 0;
//   te = mean of E[1 .. end] (E[1 ..] when no E exceeds e; a track with no such E has none).
// "Asynchronous": instead of cutting G, P gets one more row at G's last time holding its last
// position (a tracker that reports nothing has not moved).
// Per sequence: r_e = share of the counted tracks with fa > 0, a_e = mean of the nonzero fa;
// FA = mean of a_e, EFA = mean of r_e a_e, FA@5 = a_5, TE@5 = mean te at e = 5 over the tracks
// with fa > 0 there.
//
// Which GT track a predicted one is measured against:
//   by id (the benchmark: predicted id k is the tracker seeded at GT track k's first sample);
//     the prediction's times are first shifted by the GT file's first time minus its own
//     (the benchmark aligns the files at their start; 0 when they already agree; off with
//     align_start = false);
//   by association (associate_px > 0; for trackers that seed themselves, such as a
//     detector-seeded front end): predicted tracks in order of their first time (then id)
//     each take the nearest GT track within associate_px of their first position at their
//     first time (GT positions interpolated between its samples), among the GT tracks alive
//     then and not taken yet; G is then that GT track from that time on (its rows at or after
//     the predicted track's first time). No time shift. A predicted track with no GT track in
//     reach is "unmatched" and counted nowhere;
//   by seed (seeds given; for a tracker seeded on GT positions at some time, as the HASTE
//     goldens are): the same, from each seed's time and position instead of the predicted
//     track's first sample (a tracker may first report later, and elsewhere); predicted id k
//     is matched through seed k.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "evcorner/track_point.hpp"

namespace evcorner::eval {

struct TrackMetricOptions {
    bool asynchronous = false;
    double associate_px = 0;  ///< > 0: associate by position (above), else by id
    /// By id: shift the prediction to the GT file's start (the benchmark's rule; off for
    /// predictions on the GT's clock whose first report comes after the GT's first sample).
    bool align_start = true;
    int max_threshold_px = 31;  ///< thresholds 1 .. this
    /// Where the tracks were seeded (id, t, x, y): when given, tracks are matched by their
    /// seeds (above), within associate_px (1 px when that is 0).
    std::span<const TrackPoint> seeds;
};

/// One predicted track's result.
struct TrackScore {
    std::uint64_t id = 0;     ///< predicted id
    std::uint64_t gt_id = 0;  ///< the GT track it was measured against
    bool skipped = false;     ///< fewer than 2 GT rows to compare
    std::vector<double> age;  ///< fa per threshold (index e - 1); empty when skipped
    double error_5 = 0;       ///< te at 5 px (meaningful when has_error_5)
    bool has_error_5 = false;
};

struct TrackEvaluation {
    double fa = 0, efa = 0, fa_5 = 0, te_5 = 0;
    /// Per threshold e (index e - 1): r_e and a_e; their means and standard deviations
    /// (population, over the thresholds).
    std::vector<double> inlier_ratio, age;
    double inlier_mean = 0, inlier_std = 0, age_mean = 0, age_std = 0;
    std::size_t predicted_tracks = 0;  ///< distinct ids in the prediction
    std::size_t gt_tracks = 0;         ///< distinct ids in the GT
    std::size_t counted_tracks = 0;    ///< measured (neither skipped nor unmatched)
    std::size_t skipped_tracks = 0;
    std::size_t unmatched_tracks = 0;  ///< no GT track of that id (or none in reach)
    double time_shift_s = 0;           ///< added to every predicted time (by id only)
    std::vector<TrackScore> tracks;    ///< per predicted id, in id order (association: first-time order)
};

/// Evaluates `predicted` against `gt` as above. Rows may come in any order.
TrackEvaluation evaluate_tracks(std::span<const TrackPoint> predicted, std::span<const TrackPoint> gt,
                                const TrackMetricOptions& options = {});

/// What can be said of tracks without ground truth.
struct TrackStatistics {
    std::size_t tracks = 0;
    std::size_t samples = 0;
    double lifetime_median_s = 0, lifetime_mean_s = 0;  ///< last t - first t per track
    double length_median_px = 0, length_mean_px = 0;    ///< path length per track (sum of steps)
    /// Jitter: root mean square, over every sample with a neighbour on each side in its track,
    /// of its distance from the straight line between those neighbours taken at its time. A
    /// straight, steady track has 0.
    double jitter_rms_px = 0;
    std::size_t jitter_samples = 0;
};

TrackStatistics track_statistics(std::span<const TrackPoint> tracks);

}  // namespace evcorner::eval
