#pragma once
// A detector that also reports a score for the event it has just processed, one of:
//
//   double last_score() const noexcept  -- the score computed for the latest event
//                                          given to process(), or NaN (kNoScore) when
//                                          none was computed for it (border, too few
//                                          pixels, no event yet);
//   bool process_scored_unchecked(const Event&, double& score) noexcept
//                                       -- process_unchecked() that also writes the
//                                          event's score (NaN when none). For detectors
//                                          whose binary path must not pay for the score
//                                          (eFAST, Arc*: docs/scores.md).
//
// process_scored_unchecked(det, e, score) below is the one per-event scored verb for both.
// A score ranks: larger = more corner-like; it never changes the binary decision.

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
concept HasLastScore = requires(const D& d) {
    { d.last_score() } noexcept -> std::same_as<double>;
};
template <class D>
concept HasScoredStep = requires(D& d, const Event& e, double& s) {
    { d.process_scored_unchecked(e, s) } noexcept -> std::same_as<bool>;
};

template <class D>
concept ScoredDetector = Detector<D> && (HasLastScore<D> || HasScoredStep<D>);

/// The scored per-event verb of any scored detector: processes `e` (unchecked) and writes
/// its score (NaN when the detector computed none for it).
template <ScoredDetector D>
inline bool process_scored_unchecked(D& det, const Event& e, double& score) noexcept {
    if constexpr (HasScoredStep<D>) {
        return det.process_scored_unchecked(e, score);
    } else {
        const bool c = det.process_unchecked(e);
        score = det.last_score();
        return c;
    }
}

/// detect() with scores, without the checks (see detect_unchecked in detector.hpp).
template <ScoredDetector D>
std::size_t detect_unchecked(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept {
    std::size_t corners = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const bool c = process_scored_unchecked(det, events[i], score[i]);
        is_corner[i] = static_cast<std::uint8_t>(c);
        corners += c;
    }
    return corners;
}

/// detect() that also keeps the scores: score[i] = the score of events[i] (NaN where the
/// detector computed none). Checks as detect() does (is_corner and score at least as long
/// as events).
template <ScoredDetector D>
std::size_t detect(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                   std::span<double> score) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    detail::check_flags(events.size(), score.size(), "detect (scores)");
    check_events(events, det.limits());
    return detect_unchecked(det, events, is_corner, score);
}

}  // namespace evcorner
