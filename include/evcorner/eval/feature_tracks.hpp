#pragma once
// Feature-track ground truth (Mueggler, Bartolozzi, Scaramuzza, BMVC 2017, Sec. 3.1.2):
// a corner event is "correct" when it lies on a feature track found in the corner
// stream itself.
//
// A hypothesis is a pair of corner events a, b (t_a < t_b). Its axis is the straight
// line through them in (x, y, t); the cylinders are oblique: at every time t in
// [t_a, t_b] their cross-section is a disc centred on the axis point
// c(t) = a + (b - a)(t - t_a)/(t_b - t_a). A corner event e is inner when
// |e - c(t_e)| <= inner_radius, outer when inner_radius < |e - c(t_e)| <= outer_radius.
// The hypothesis is accepted (a feature track) when inner >= min_inner and
// outer <= max_outer_ratio * inner; its inner events are then labelled correct.
// docs/evaluation.md explains every choice the paper leaves open (the defaults below).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/event.hpp"

namespace evcorner::eval {

/// How accepted tracks that share corner events combine.
enum class TrackOverlap {
    /// Every hypothesis is judged on all corners; a corner is correct when it is inner to
    /// any accepted track (order-free, what "exhaustive search" implies).
    any,
    /// Anchors in time order; of an anchor's accepted hypotheses, the one with the most inner
    /// corners claims them, and claimed corners take no further part (neither counted nor pairs).
    exclusive,
};

struct FeatureTrackParams {
    double inner_radius = 3.0;      ///< px (paper)
    double outer_radius = 5.0;      ///< px (paper)
    int min_inner = 30;             ///< inner corner events needed (paper)
    double max_outer_ratio = 0.25;  ///< outer / inner at most this (paper)
    /// Longest time between the two corner events of a hypothesis; the cylinder spans
    /// exactly [t_a, t_b], so this is also the longest track segment.
    std::int64_t max_duration_us = 100'000;
    /// Largest image distance between the two corner events of a hypothesis (px).
    double max_length = 20.0;
    /// Pairs and cylinder contents of one polarity only (true), or of both (false).
    bool same_polarity = false;
    TrackOverlap overlap = TrackOverlap::any;
    /// Side of the spatial buckets of the index (px); changes speed, never the labels.
    int cell_size = 8;
};

/// Throws std::invalid_argument naming the first parameter out of range.
void validate(const FeatureTrackParams& p);

/// Parses "any" / "exclusive"; throws std::invalid_argument otherwise.
TrackOverlap parse_track_overlap(std::string_view name);
std::string_view to_string(TrackOverlap o) noexcept;

struct FeatureTrackResult {
    std::vector<std::uint8_t> on_track;  ///< one per corner event, in input order: 1 = correct
    std::size_t labelled = 0;            ///< corners with on_track = 1
    std::uint64_t hypotheses = 0;        ///< pairs evaluated
    std::uint64_t accepted = 0;          ///< pairs accepted as feature tracks

    /// FT: labelled / corners in percent (0 for no corners).
    [[nodiscard]] double ft_percent() const noexcept {
        return on_track.empty() ? 0.0 : 100.0 * static_cast<double>(labelled) / static_cast<double>(on_track.size());
    }
};

/// Labels every corner event of `corners` (any order: they are taken in time order, ties in
/// input order; FeatureTrackStream gives the same on a time-ordered stream, in bounded memory).
/// Cost: a bucket index over (x, y) with time-sorted buckets; each anchor gathers only
/// the corners inside its reachable space-time box, never all corners, and counts a
/// partner's cylinders over the corners on the partner's side of the anchor (quadrant
/// lists, docs/evaluation.md) with SIMD loops chosen for the CPU at run time.
FeatureTrackResult label_feature_tracks(std::span<const Event> corners, const FeatureTrackParams& params = {});

/// Told now and then (every few thousand anchors, and at the end) how many corner events
/// have been anchors so far, of all: for a progress bar.
using LabelProgress = std::function<void(std::size_t done, std::size_t total)>;
/// label_feature_tracks() reporting its progress.
FeatureTrackResult label_feature_tracks(std::span<const Event> corners, const FeatureTrackParams& params,
                                        const LabelProgress& progress);

/// The labeller over a stream of corner events in time order, in memory bounded by the
/// events of one max_duration_us window (not by the stream's length): a corner's label is
/// final once the stream is past t + max_duration_us, since no hypothesis reaching it can
/// start later than it. Labels, counts and hypotheses are those of label_feature_tracks()
/// on the whole stream, however it is cut into batches.
class FeatureTrackStream {
public:
    /// `path`: a code path (feature_track_code_paths()), empty for the default; throws
    /// std::invalid_argument for bad parameters or a path this CPU does not run.
    explicit FeatureTrackStream(const FeatureTrackParams& params = {}, std::string_view path = {});
    ~FeatureTrackStream();
    FeatureTrackStream(FeatureTrackStream&&) noexcept;
    FeatureTrackStream& operator=(FeatureTrackStream&&) noexcept;

    /// Appends corner events, in time order (ties allowed), also across calls; an event
    /// earlier than the one before it throws std::invalid_argument naming its position in
    /// the stream (counted from 0) and both times, and leaves the stream as it was before
    /// the call. Returns the labels that became final, 1 = on a track, in input order,
    /// continuing those returned before; valid until the next call.
    std::span<const std::uint8_t> push(std::span<const Event> corners);
    /// Ends the stream: the labels of every corner not yet returned. Later pushes throw
    /// std::logic_error.
    std::span<const std::uint8_t> finish();

    [[nodiscard]] std::uint64_t corners() const noexcept;     ///< corner events pushed
    [[nodiscard]] std::uint64_t labelled() const noexcept;    ///< labels returned with 1
    [[nodiscard]] std::uint64_t hypotheses() const noexcept;  ///< pairs evaluated so far
    [[nodiscard]] std::uint64_t accepted() const noexcept;    ///< pairs accepted so far
    /// Corner events held now, and the most held after any push returned: with W the most
    /// corner events within any max_duration_us of the stream (both ends included), at most
    /// 4 W + 4096, whatever the stream's length or the batches (a push holds its batch too
    /// while it runs).
    [[nodiscard]] std::size_t retained() const noexcept;
    [[nodiscard]] std::size_t max_retained() const noexcept;

private:
    struct State;
    std::unique_ptr<State> s_;
};

/// The code path label_feature_tracks() takes: "avx512", "avx2" or "portable" (the
/// environment variable EVCORNER_LABEL_PATH forces one this CPU runs). Every path gives
/// the same result.
const char* feature_track_code_path() noexcept;
/// Every code path this CPU runs, fastest first.
std::vector<std::string> feature_track_code_paths();
/// label_feature_tracks() on a named path (one of feature_track_code_paths(); else
/// std::invalid_argument).
FeatureTrackResult label_feature_tracks_on_path(std::string_view path, std::span<const Event> corners,
                                                const FeatureTrackParams& params = {});

}  // namespace evcorner::eval
