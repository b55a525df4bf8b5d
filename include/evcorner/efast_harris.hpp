#pragma once
// The eFAST -> Harris cascade, which the paper's Discussion proposes (Mueggler,
// Bartolozzi, Scaramuzza, BMVC 2017, Sec. 4: "refine our corner event detections by
// post-processing them with the event-based Harris method"):
//   an event is a corner iff eFAST says corner AND the spatially-adaptive Harris, whose
//   state sees every event, scores the same event above its threshold.
// Its corner set is exactly the intersection of EFast's and Harris's (docs/efast_harris.md);
// the Harris score, the costly part, is computed only for eFAST's candidates (1-10 % of
// the events on the real recordings).
//
// State: eFAST's SAE and Harris's arrival-ordered SAE, side by side. The batch detect()
// runs eFAST on its fastest code path (efast.hpp: AVX-512, AVX2 or portable, chosen at
// run time) over blocks of events, then updates Harris with every event of the block and
// scores the candidates; a single process() takes eFAST's portable path.

#include <cstddef>
#include <cstdint>
#include <span>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

/// The cascade's parameters are its Harris stage's (eFAST has none): window, nl, k,
/// threshold, with Harris's defaults and ranges.
using EFastHarrisParams = HarrisParams;

class EFastHarris {
public:
    using Params = EFastHarrisParams;

    /// Throws std::invalid_argument for a sensor side outside 1..kMaxSensorSide or a
    /// Harris parameter out of range (the message names it). `planes` = 1: one plane of
    /// state per stage for both polarities, for a caller that feeds one polarity only
    /// (the cascade's decision depends on the event's own polarity alone).
    explicit EFastHarris(SensorSize size, const Params& params = {}, int planes = 2);

    /// Bytes of state: eFAST's SAE plus Harris's arrival SAE.
    [[nodiscard]] static std::uint64_t state_bytes(SensorSize size, const Params& params = {},
                                                   int planes = 2) noexcept {
        return EFast::state_bytes(size, planes) + Harris::state_bytes(size, params, planes);
    }

    /// What process() accepts: eFAST's limits (on the sensor, polarity 0/1, a time the
    /// SAE holds); Harris accepts any time.
    [[nodiscard]] EventLimits limits() const noexcept { return efast_.limits(); }

    /// Updates both stages with `e` and answers whether `e` is a corner event. Throws
    /// InvalidEvent (state unchanged) for an event limits() does not accept.
    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    /// process() without the check: `e` must be accepted by limits().
    bool process_unchecked(const Event& e) noexcept {
        harris_.update_unchecked(e);
        score_ = kNoScore;
        if (!efast_.process_unchecked(e)) return false;
        score_ = harris_.score_latest(e);
        return score_ > harris_.params().threshold;  // false for kNoScore (NaN)
    }

    /// The Harris score of the latest event when eFAST called it a candidate (kNoScore
    /// when Harris has none for it: border, fewer than nl pixels); kNoScore for every
    /// event eFAST rejected, and before any event.
    [[nodiscard]] double last_score() const noexcept { return score_; }

    [[nodiscard]] const Params& params() const noexcept { return harris_.params(); }
    [[nodiscard]] SensorSize size() const noexcept { return efast_.size(); }
    [[nodiscard]] const EFast& efast() const noexcept { return efast_; }
    [[nodiscard]] const Harris& harris() const noexcept { return harris_; }
    [[nodiscard]] std::size_t memory_bytes() const noexcept { return efast_.memory_bytes() + harris_.memory_bytes(); }

private:
    template <bool WithScores>
    friend std::size_t run_efast_harris(EFastHarris& det, std::span<const Event> events,
                                        std::span<std::uint8_t> is_corner, std::span<double> score) noexcept;

    EFast efast_;
    Harris harris_;
    double score_ = kNoScore;
};
static_assert(ScoredDetector<EFastHarris>);

/// detect() for the cascade: the same flags as process() event by event, with eFAST on
/// its fastest code path (efast_code_path()). Overload resolution picks these over the
/// generic ones of detector.hpp and scored_detector.hpp; they check as those do.
std::size_t detect(EFastHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner);
std::size_t detect_unchecked(EFastHarris& det, std::span<const Event> events,
                             std::span<std::uint8_t> is_corner) noexcept;
/// With scores: score[i] = last_score() after events[i].
std::size_t detect(EFastHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                   std::span<double> score);
std::size_t detect_unchecked(EFastHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept;

}  // namespace evcorner
