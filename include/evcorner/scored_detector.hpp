#pragma once
// A detector that also reports a score for the event it has just processed.
//
//   double last_score() const noexcept  -- the score computed for the latest event
//                                          given to process(), or NaN (kNoScore) when
//                                          none was computed for it (border, too few
//                                          pixels, no event yet).

#include <concepts>
#include <limits>

#include "evcorner/detector.hpp"

namespace evcorner {

/// The value of last_score() when no score was computed. Golden files write -2 instead.
inline constexpr double kNoScore = std::numeric_limits<double>::quiet_NaN();

template <class D>
concept ScoredDetector = Detector<D> && requires(const D& d) {
    { d.last_score() } noexcept -> std::same_as<double>;
};

}  // namespace evcorner
