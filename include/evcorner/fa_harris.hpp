#pragma once
// FA-Harris: the fast asynchronous Harris detector of
//   Li, Shi, Wang, Lin, Ding, Zhang, Chen, "FA-Harris: A Fast and Asynchronous Corner
//   Detector for Event Cameras", IROS 2019,
// as docs/fa_harris.md defines it. Per event: (1) border events (4 pixels) are not corners
// and change no state; (2) the Arc* filter (arcstar_test.hpp); a passing event writes the
// filtered SAE of its polarity; (3) candidate iff the Arc* arc test passes on both
// circles; (4) a candidate is a corner iff at least nl pixels of the window x window
// neighbourhood of its polarity's filtered SAE have passed the filter and the Harris score
// (harris_score.hpp) of the binary patch of the nl newest of them is > threshold.
//
// State: per pixel the latest (unfiltered) time of each polarity, and per polarity the
// filtered SAE and the arrival number of its latest write (newest = later time, ties
// broken by arrival). The planes carry a frame of never-fired cells, so that windows
// reach past the sensor without checks. No allocation per event.

#include <cstddef>
#include <cstdint>
#include <span>

#include "evcorner/arcstar.hpp"
#include "evcorner/arcstar_test.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/harris_score.hpp"
#include "evcorner/harris_select.hpp"
#include "evcorner/sae.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/zeroed_array.hpp"

namespace evcorner {

struct FaHarrisParams {
    bool filter = true;              ///< the Arc* filter; false: every event passes
    std::int64_t filter_us = 50000;  ///< its window in us, 0..ArcStar::kMaxFilterUs
    bool minority_only = false;      ///< Arc* candidates from minority arcs only
    bool zero_init = false;          ///< the Arc* authors' zero-initialised filter
    int window = 9;                  ///< Harris patch side, odd, 5..15
    int nl = 25;                     ///< newest filtered pixels lit in the patch, 1..window^2
    double k = 0.04;                 ///< Harris k
    double threshold = 8.0;          ///< corner iff score > threshold
};

class FaHarris {
public:
    using Params = FaHarrisParams;

    /// Throws std::invalid_argument for a parameter or a sensor side out of range.
    /// `planes` is accepted for the detector contract and ignored (the filter reads the
    /// other polarity).
    explicit FaHarris(SensorSize size, const Params& params = {}, int planes = 2);

    /// Bytes of state: the latest times (16 per pixel) and, per polarity, the filtered
    /// SAE and its arrival numbers (16 per cell) on the sensor framed by max(4, window/2).
    [[nodiscard]] static std::uint64_t state_bytes(SensorSize size, const Params& params = {}, int = 2) noexcept;

    /// What process() accepts: events on the sensor, polarity 0/1, time within the SAE's range.
    [[nodiscard]] EventLimits limits() const noexcept { return {size_, Sae::kMinTime, Sae::kMaxTime}; }

    /// Updates the state with `e` and answers whether `e` is a corner event. Throws
    /// InvalidEvent (state unchanged) for an event limits() does not accept.
    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    /// process() without the check: `e` must be accepted by limits().
    bool process_unchecked(const Event& e) noexcept;

    /// The Harris score of the latest event if it was an Arc* candidate with at least nl
    /// filtered pixels in its window; kNoScore (NaN) otherwise.
    [[nodiscard]] double last_score() const noexcept { return score_; }

    [[nodiscard]] const Params& params() const noexcept { return params_; }
    [[nodiscard]] SensorSize size() const noexcept { return size_; }
    /// The filtered SAE: time of the latest filtered event at (x, y), polarity p, or Sae::kNever.
    [[nodiscard]] std::int64_t filtered(int p, int x, int y) const noexcept {
        const std::int64_t v = sae_[plane(p) + index(x, y)];
        return v == 0 ? Sae::kNever : v - Sae::kBias;
    }
    [[nodiscard]] std::size_t memory_bytes() const noexcept {
        return latest_.size() * sizeof(ArcStarLatest) + (sae_.size() + arrival_.size()) * sizeof(std::int64_t);
    }

private:
    friend struct FaHarrisLoops;  // fa_harris.cpp: the per-event step and the batch loops of detect()
    [[nodiscard]] std::size_t index(int x, int y) const noexcept {
        return (static_cast<std::size_t>(y) + static_cast<std::size_t>(pad_)) * stride_ + static_cast<std::size_t>(x) +
               static_cast<std::size_t>(pad_);
    }
    [[nodiscard]] std::size_t plane(int p) const noexcept { return static_cast<std::size_t>(p & 1) * plane_size_; }
    // The Harris score of the window of (x, y), polarity p, the filtered SAE holding `now`
    // arrivals, its newest time `newest`, `in_time_order` as in_time_order_ (kNoScore for
    // fewer than nl filtered pixels).
    [[nodiscard]] double refine(int p, int x, int y, std::uint64_t now, std::int64_t newest,
                                bool in_time_order) const noexcept;

    Params params_;
    HarrisScorer scorer_;
    SensorSize size_;
    int pad_;
    std::size_t stride_;
    std::size_t plane_size_;
    ZeroedArray<ArcStarLatest> latest_;   // unframed: width x height
    ZeroedArray<std::int64_t> sae_;       // 2 framed planes, stored times
    ZeroedArray<std::uint64_t> arrival_;  // 2 framed planes, arrival numbers (0 = never)
    std::uint64_t arrivals_ = 0;
    std::int64_t newest_ = 0;             // the largest stored time in the filtered SAE
    // Whether every filtered write so far came in time order (no time below an earlier
    // one): then "later time, ties by later arrival" is "later arrival", and the newest nl
    // are selected on the arrival numbers alone (harris_select.hpp).
    bool in_time_order_ = true;
    HarrisPath path_;                     // harris_default_path(): selection and 9x9 score
    double score_ = kNoScore;
};
static_assert(ScoredDetector<FaHarris>);

/// detect() for FA-Harris: the same flags, with the fastest loop this CPU runs (AVX-512:
/// Arc*'s closed form for the candidate stage; else AVX2; else portable), chosen once per
/// process; EVCORNER_ARCSTAR_PATH=portable|avx2|avx512 forces one this CPU runs. Checks as
/// the generic detect() does. (detect() with scores is the generic one of scored_detector.hpp.)
std::size_t detect(FaHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner);
/// detect() without the checks.
std::size_t detect_unchecked(FaHarris& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept;

}  // namespace evcorner
