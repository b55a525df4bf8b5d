#pragma once
// Corner events against a simulated scene's ground truth (sim/truth.hpp): precision, recall
// and localisation error (docs/evaluation.md, "Against ground truth", gives each choice and
// its reason).
//
//   event position   the pixel's centre, (x + 0.5, y + 0.5)
//   truth at time t  each corner's position (and velocity) interpolated linearly between the
//                    two samples around t (or, with Interpolation::nearest, the nearer
//                    sample's); visible at t when visible at either of the two samples (at a
//                    sample time exactly: that sample)
//   match            event e matches corner c when c is visible at t_e and lies within
//                    `radius` px of e's position at t_e
//   precision        corner events matching at least one corner / corner events; a true
//                    positive's localisation error is its distance to the nearest corner
//   recall           visible truth samples (c, s) with a corner event matching c at some
//                    t_e, |t_e - s| <= tolerance_us / visible truth samples
//   one event, several corners   it counts once for precision (error: the nearest); for
//                    recall it credits every corner it matches (Credit::all) or only the
//                    nearest (Credit::nearest)
//   with scores      (one per corner event) each recalled truth sample also gets the largest
//                    score among the events that recall it (recalled_best): what a score
//                    threshold needs for recall (pr_curve.hpp)
//   smear            true positives per visible corner per millisecond: the corner time is
//                    the sum over consecutive samples of (visible corners at the earlier) x
//                    (time between them)
//
// Streaming: the corner events (time order) are given whole, the truth one sample time at a
// time (add_sample, in time order); memory is the events, two samples and, per corner, the
// time intervals still open -- not the truth file.

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sim/truth.hpp"

namespace evcorner::eval {

enum class Credit : std::uint8_t { all, nearest };
enum class Interpolation : std::uint8_t { linear, nearest };

std::string_view to_string(Credit c) noexcept;
std::string_view to_string(Interpolation i) noexcept;
/// "all" / "nearest"; throws std::invalid_argument.
Credit parse_credit(std::string_view s);
/// "linear" / "nearest"; throws std::invalid_argument.
Interpolation parse_interpolation(std::string_view s);

struct TruthMatchParams {
    double radius = 3.5;               ///< px
    std::int64_t tolerance_us = 1000;  ///< recall's time window, either side
    Credit credit = Credit::all;
    Interpolation interpolation = Interpolation::linear;
    /// Image-speed bins (px/s) for precision and recall against speed: bin k is
    /// [edges[k], edges[k+1]), the last open-ended. An event falls in the bin of the nearest
    /// visible corner's speed at its time (none visible: not binned), a sample in its own.
    std::vector<double> speed_edges{0, 50, 100, 200, 400, 700};
};

/// Throws std::invalid_argument for a radius <= 0 or not finite, a negative tolerance, or
/// speed edges not starting at 0 and increasing.
void validate(const TruthMatchParams& p);

struct SpeedBin {
    double lo = 0, hi = 0;  ///< px/s; hi infinite for the last
    std::uint64_t events = 0, true_positives = 0;
    std::uint64_t samples = 0, recalled = 0;
};

struct TruthMatchResult {
    std::uint64_t corner_events = 0;
    std::uint64_t true_positives = 0;
    std::uint64_t truth_samples = 0;  ///< visible (corner, sample time) pairs
    std::uint64_t recalled = 0;
    std::vector<std::uint8_t> is_true;  ///< per corner event: 1 when it matches a corner
    std::vector<float> errors;          ///< per true positive, in event order: px
    std::vector<SpeedBin> bins;
    /// Per recalled truth sample (in the order decided), the largest score among the corner
    /// events that recall it (NaN read as -infinity); empty when no scores were given.
    std::vector<double> recalled_best;
    double visible_corner_us = 0;  ///< corner time: visible corners x time, us (see smear)

    [[nodiscard]] double precision() const noexcept;  ///< %; 0 without corner events
    [[nodiscard]] double recall() const noexcept;     ///< %; 0 without truth samples
    /// True positives per visible truth corner per millisecond; 0 without corner time.
    [[nodiscard]] double smear() const noexcept;
};

struct ErrorSummary {
    double median = 0, mean = 0, p90 = 0;  ///< px; 0 when empty
};
/// Median, mean and 90th percentile (nearest rank) of `errors`.
ErrorSummary summarize_errors(std::span<const float> errors);

class TruthMatcher {
public:
    /// `corners` in time order (a detector's output); kept by reference until finish().
    TruthMatcher(std::span<const Event> corners, TruthMatchParams params);
    /// With a score per corner event (kept by reference too): the result's recalled_best is
    /// filled. Throws std::invalid_argument when the lengths differ.
    TruthMatcher(std::span<const Event> corners, std::span<const double> scores, TruthMatchParams params);

    /// The truth rows of one sample time, later than the last one's. Throws
    /// std::invalid_argument for a time not later, or rows of several times.
    void add_sample(std::span<const sim::TruthCorner> rows);
    /// Matches what is left and returns the result.
    TruthMatchResult finish();

private:
    struct Track {
        std::int64_t key = 0;
        // The open recall intervals [lo, hi] of this corner's matches, merged, by time.
        std::vector<std::pair<std::int64_t, std::int64_t>> open;
        std::size_t first = 0;  // open[first..] are live
        // With scores: the credited events (time, score) in time order, hits[pushed..] not yet
        // in `window`, a deque of decreasing scores of those in the current sample's window.
        std::vector<std::pair<std::int64_t, double>> hits;
        std::size_t pushed = 0;
        std::vector<std::pair<std::int64_t, double>> window;
        std::size_t window_first = 0;
    };
    struct Pending {
        std::int64_t t;
        std::uint32_t track;
        double speed;
    };
    void match_events_until(std::int64_t t_end, bool to_end);
    void decide_samples_until(std::int64_t t_end, bool to_end);
    std::uint32_t track_of(const sim::TruthCorner& c);
    int bin_of(double speed) const noexcept;

    double best_for(Track& tr, std::int64_t s);
    std::span<const Event> corners_;
    std::span<const double> scores_;
    TruthMatchParams p_;
    std::size_t next_event_ = 0;
    std::vector<sim::TruthCorner> prev_, cur_;  // the two newest samples (prev_ may be empty)
    std::vector<std::uint32_t> prev_track_, cur_track_;
    std::vector<Track> tracks_;
    std::vector<std::pair<std::int64_t, std::uint32_t>> track_index_;  // key -> track, sorted
    std::vector<Pending> pending_;
    std::size_t pending_first_ = 0;
    TruthMatchResult r_;
    bool any_sample_ = false;
};

/// Everything in one call: the corner events against a truth already in memory (rows in
/// time order, as read_truth_csv gives them).
TruthMatchResult match_truth(std::span<const Event> corners, std::span<const sim::TruthCorner> truth,
                             const TruthMatchParams& params);
/// The same with a score per corner event (recalled_best filled).
TruthMatchResult match_truth(std::span<const Event> corners, std::span<const double> scores,
                             std::span<const sim::TruthCorner> truth, const TruthMatchParams& params);

}  // namespace evcorner::eval
