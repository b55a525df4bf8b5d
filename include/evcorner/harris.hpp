#pragma once
// Spatially-adaptive event-based Harris, the improved baseline of
//   E. Mueggler, C. Bartolozzi, D. Scaramuzza, "Fast Event-based Corner Detection",
//   BMVC 2017, Sec. 3.2 (docs/harris.md gives the exact definition).
// Per event: the binary w x w patch around it (w = 9) lights the Nl = 25 pixels of its
// polarity that fired most recently in that window (distinct pixels, ties broken by
// arrival); the event is a corner iff the Harris score of the patch is > S = 8.
//
// State: an arrival-ordered SAE (per pixel and polarity, the sequence number of its
// latest event). The Nl newest pixels of a window are selected from the w*w sequence
// numbers directly (harris_select.hpp); no lists, no allocation per event.

#include <cstddef>
#include <cstdint>

#include "evcorner/arrival_sae.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/harris_score.hpp"
#include "evcorner/harris_select.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

struct HarrisParams {
    int window = 9;          ///< patch side, odd, 5..15
    int nl = 25;             ///< newest distinct pixels lit in the patch, 1..window^2
    double k = 0.04;         ///< Harris k
    double threshold = 8.0;  ///< corner iff score > threshold
};

class Harris {
public:
    using Params = HarrisParams;
    /// Throws std::invalid_argument for a parameter or a sensor side out of range (the
    /// message names it). `planes` = 1 keeps one plane of state for both polarities: only
    /// for a caller that feeds events of one polarity (ParallelDetector's parts), at half
    /// the memory.
    explicit Harris(SensorSize size, HarrisParams params = {}, int planes = 2);

    /// Bytes of state a detector over `size` holds: 8 per pixel and plane, the sensor
    /// framed by window/2 cells on each side; zero pages committed only where events land.
    [[nodiscard]] static std::uint64_t state_bytes(SensorSize size, const HarrisParams& params = {}, int planes = 2) noexcept {
        return ArrivalSae::state_bytes(size, params.window / 2, planes);
    }

    /// What process() accepts: events on the sensor with polarity 0/1 (any time).
    [[nodiscard]] EventLimits limits() const noexcept { return {sae_.size()}; }

    /// Updates the state with `e` and answers whether `e` is a corner event. Throws
    /// InvalidEvent (state unchanged) for an event limits() does not accept.
    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    /// process() without the check: `e` must be accepted by limits(). The same as
    /// update_unchecked(e), then score_latest(e) compared with the threshold.
    bool process_unchecked(const Event& e) noexcept;

    /// The two halves of process_unchecked(), for a caller that keeps the state current
    /// with every event but scores only some (the eFAST -> Harris cascade):
    /// update_unchecked() records `e` (accepted by limits()) and computes nothing; it
    /// leaves last_score() as it was.
    void update_unchecked(const Event& e) noexcept { sae_.update_unchecked(e); }
    /// update_unchecked() for every event of `events`, in order.
    void update_unchecked(std::span<const Event> events) noexcept { sae_.update_unchecked(events); }
    /// The score of `e`'s window as process() would compute it: `e` must be the latest
    /// event given to update_unchecked(). kNoScore for a border event or too few pixels.
    /// Changes nothing (last_score() included).
    [[nodiscard]] double score_latest(const Event& e) const noexcept;

    /// Score of the latest processed event; kNoScore (NaN) for a border event, when fewer
    /// than nl distinct pixels of its polarity have fired in its window, or before any event.
    [[nodiscard]] double last_score() const noexcept { return score_; }

    [[nodiscard]] const HarrisParams& params() const noexcept { return params_; }
    [[nodiscard]] SensorSize size() const noexcept { return sae_.size(); }
    [[nodiscard]] const ArrivalSae& sae() const noexcept { return sae_; }
    [[nodiscard]] std::size_t memory_bytes() const noexcept { return sae_.memory_bytes(); }

    /// The code that selects the window's newest pixels (harris_select.hpp): chosen at
    /// construction (harris_default_path()); set_code_path() picks another one the CPU runs
    /// (harris_path_named()), for tests and benchmarks. Every path lights the same pixels.
    [[nodiscard]] HarrisPath code_path() const noexcept { return path_; }
    void set_code_path(HarrisPath path) noexcept { path_ = path; }

private:
    [[nodiscard]] double score_window(const Event& e) const noexcept;

    HarrisParams params_;
    HarrisScorer scorer_;
    ArrivalSae sae_;
    int radius_;
    HarrisPath path_;
    double score_ = kNoScore;
};
static_assert(ScoredDetector<Harris>);

/// The name of the code that selects a 9x9 window's newest pixels in a new Harris
/// (harris_default_path(): the fastest this CPU runs, or EVCORNER_HARRIS_PATH=portable|avx2|avx512);
/// other windows always take the portable code. Same lit pixels either way.
const char* harris_code_path() noexcept;

}  // namespace evcorner
