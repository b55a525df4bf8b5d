#pragma once
// Event-based Harris with a global binary surface, as described by
//   V. Vasco, A. Glover, C. Bartolozzi, "Fast event-based Harris corner detection
//   exploiting the advantages of event-driven cameras", IROS 2016
// (and summarised in Mueggler et al., BMVC 2017, Sec. 3.2). Per event: the binary
// surface of its polarity lights the N pixels (N = 1000) that fired most recently over
// the whole sensor; the event is a corner iff the Harris score of the w x w patch
// (w = 9) around it is > S = 8.
//
// State: an arrival-ordered SAE and, per polarity, the newest-N-distinct-pixels queue
// (NewestPixels): O(1) amortised per event, no allocation per event. Border rule as for
// the spatially-adaptive Harris: no score when the window leaves the sensor by more
// than one pixel on the far side (x > width - w/2) or at all on the near side.

#include <array>
#include <cstddef>
#include <cstdint>

#include "evcorner/arrival_sae.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/harris_score.hpp"
#include "evcorner/newest_pixels.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

struct HarrisGlobalParams {
    int n = 1000;            ///< newest distinct pixels per polarity lit over the sensor, >= 1
    int window = 9;          ///< patch side, odd, 5..15
    double k = 0.04;         ///< Harris k
    double threshold = 8.0;  ///< corner iff score > threshold
};

class HarrisGlobal {
public:
    using Params = HarrisGlobalParams;
    /// Throws std::invalid_argument for a parameter or a sensor side out of range (the
    /// message names it).
    explicit HarrisGlobal(SensorSize size, HarrisGlobalParams params = {});

    /// Bytes of state a detector over `size` holds: the arrival SAE (8 per pixel and
    /// polarity, framed by window/2 cells) and the two newest-N rings.
    [[nodiscard]] static std::uint64_t state_bytes(SensorSize size, const HarrisGlobalParams& params = {}) noexcept {
        return ArrivalSae::state_bytes(size, params.window / 2) +
               2 * NewestPixels::state_bytes(static_cast<std::size_t>(params.n > 0 ? params.n : 1),
                                             static_cast<std::size_t>(size.pixels() > 0 ? size.pixels() : 0));
    }

    /// What process() accepts: events on the sensor with polarity 0/1 (any time).
    [[nodiscard]] EventLimits limits() const noexcept { return {sae_.size()}; }

    /// Updates the state with `e` and answers whether `e` is a corner event. Throws
    /// InvalidEvent (state unchanged) for an event limits() does not accept.
    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    /// process() without the check: `e` must be accepted by limits().
    bool process_unchecked(const Event& e) noexcept;

    /// Score of the latest processed event; kNoScore (NaN) for a border event or before
    /// any event.
    [[nodiscard]] double last_score() const noexcept { return score_; }

    [[nodiscard]] const HarrisGlobalParams& params() const noexcept { return params_; }
    [[nodiscard]] SensorSize size() const noexcept { return sae_.size(); }
    [[nodiscard]] const ArrivalSae& sae() const noexcept { return sae_; }
    /// The newest-N set of polarity p (0 = OFF, 1 = ON).
    [[nodiscard]] const NewestPixels& newest(int p) const noexcept { return newest_[p != 0]; }
    [[nodiscard]] std::size_t memory_bytes() const noexcept {
        return sae_.memory_bytes() + newest_[0].memory_bytes() + newest_[1].memory_bytes();
    }

private:
    HarrisGlobalParams params_;
    HarrisScorer scorer_;
    ArrivalSae sae_;
    std::array<NewestPixels, 2> newest_;
    int radius_;
    double score_ = kNoScore;
};
static_assert(ScoredDetector<HarrisGlobal>);

}  // namespace evcorner
