#pragma once
// A detector that also reports a score for the event it has just processed.
//
//   double last_score() const noexcept  -- the score computed for the latest event
//                                          given to process(), or NaN (kNoScore) when
//                                          none was computed for it (border, too few
//                                          pixels, no event yet).

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

#include "evcorner/detector.hpp"

namespace evcorner {

/// The value of last_score() when no score was computed. Golden files write -2 instead.
inline constexpr double kNoScore = std::numeric_limits<double>::quiet_NaN();

template <class D>
concept ScoredDetector = Detector<D> && requires(const D& d) {
    { d.last_score() } noexcept -> std::same_as<double>;
};

/// detect() with scores, without the checks (see detect_unchecked in detector.hpp).
template <ScoredDetector D>
std::size_t detect_unchecked(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept {
    std::size_t corners = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const bool c = det.process_unchecked(events[i]);
        is_corner[i] = static_cast<std::uint8_t>(c);
        score[i] = det.last_score();
        corners += c;
    }
    return corners;
}

/// detect() that also keeps the scores: score[i] = the detector's last_score() after
/// events[i]. Checks as detect() does (is_corner and score at least as long as events).
template <ScoredDetector D>
std::size_t detect(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                   std::span<double> score) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    detail::check_flags(events.size(), score.size(), "detect (scores)");
    check_events(events, det.limits());
    return detect_unchecked(det, events, is_corner, score);
}

}  // namespace evcorner
