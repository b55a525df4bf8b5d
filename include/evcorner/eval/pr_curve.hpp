#pragma once
// The precision-recall curve of a scored detector against ground truth (docs/evaluation.md,
// "Precision-recall curves"), from ONE matching pass with scores (truth_match.hpp):
//
//   threshold th     each distinct score of the corner events, from the largest down; the
//                    detector at th keeps the corner events of score >= th (NaN: -infinity)
//   precision(th)    true corner events of score >= th / corner events of score >= th
//   recall(th)       truth samples whose best recalling score (recalled_best) is >= th /
//                    all visible truth samples -- whether an event is true, and which samples
//                    it recalls, does not depend on the other events, so this is the recall
//                    of the matching run on the events of score >= th alone
//   average precision  AP = sum over the points k of (recall_k - recall_{k-1}) precision_k,
//                    recall_0 = 0: the area under the step curve (no interpolation, no
//                    trapezoids, which would reward the straight line between far points),
//                    up to the detector's full recall -- so AP <= recall at the lowest
//                    threshold; fractions, in [0, 1]
//
// Cost: a sort of the corner events' scores and of the recalled samples' best scores.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace evcorner::eval {

struct PrPoint {
    double threshold = 0;  ///< the score threshold (-infinity: every corner event)
    double precision = 0;  ///< %
    double recall = 0;     ///< %
};

struct PrCurve {
    std::vector<PrPoint> points;    ///< by threshold, largest first (recall rising)
    double average_precision = 0;   ///< AP, a fraction in [0, 1]
};

/// The curve of corner events of `scores` (true where `is_true`, same length), against
/// `truth_samples` visible samples of which those recalled have `recalled_best` scores.
/// Throws std::invalid_argument when the lengths differ or more are recalled than exist.
PrCurve pr_curve(std::span<const double> scores, std::span<const std::uint8_t> is_true,
                 std::span<const double> recalled_best, std::uint64_t truth_samples);

/// At most `n` >= 2 points of `c`: evenly spaced by index, the first and last always kept
/// (for tables and files; AP is computed on the whole curve).
std::vector<PrPoint> thin(const std::vector<PrPoint>& points, std::size_t n);

/// Interpolated precision (%) at each recall level (%): the largest precision at a recall
/// >= the level; NaN where the curve never reaches it (for the report's chart).
std::vector<double> precision_at_recall(const std::vector<PrPoint>& points, std::span<const double> levels);

}  // namespace evcorner::eval
