#pragma once
// eFAST: the event-based FAST corner detector of
//   E. Mueggler, C. Bartolozzi, D. Scaramuzza, "Fast Event-based Corner Detection",
//   BMVC 2017.
// Per event: write its timestamp into the SAE of its polarity; away from the border,
// it is a corner iff on that SAE the radius-3 circle has a contiguous arc of 3..6
// pixels all strictly newer than the rest of the circle, and the radius-4 circle one
// of 4..8 pixels (docs/efast.md gives the exact definition).

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "evcorner/arc_test.hpp"
#include "evcorner/circle.hpp"
#include "evcorner/corner_scores.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/efast_avx512.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/sae.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

/// eFAST has no parameters: the paper fixes its circles and arc lengths.
struct EFastParams {};

class EFast {
public:
    using Params = EFastParams;
    static constexpr int kArc3Min = 3, kArc3Max = 6;
    static constexpr int kArc4Min = 4, kArc4Max = 8;

    /// `planes` = 1 keeps one SAE plane for both polarities: only for a caller that feeds
    /// events of one polarity (ParallelDetector's parts), at half the memory. Throws
    /// std::invalid_argument for a side outside 1..kMaxSensorSide.
    explicit EFast(SensorSize size, int planes = 2) : sae_(checked_sensor_size(size, "eFAST"), planes) {}
    /// The detector contract's form (registry.hpp): eFAST has no parameters.
    EFast(SensorSize size, const EFastParams& /*params*/, int planes = 2) : EFast(size, planes) {}

    /// Bytes of state a detector over `size` holds (8 per pixel and plane), allocated
    /// as zero pages that are committed only where events land.
    [[nodiscard]] static constexpr std::uint64_t state_bytes(SensorSize size, int planes = 2) noexcept {
        return Sae::state_bytes(size, planes);
    }
    [[nodiscard]] static constexpr std::uint64_t state_bytes(SensorSize size, const EFastParams& /*params*/,
                                                             int planes = 2) noexcept {
        return Sae::state_bytes(size, planes);
    }

    /// What process() accepts: events on the sensor, polarity 0/1, time within the
    /// SAE's range (Sae::kMinTime..kMaxTime, about +-146 000 years).
    [[nodiscard]] EventLimits limits() const noexcept { return {sae_.size(), Sae::kMinTime, Sae::kMaxTime}; }

    /// Updates the SAE with `e` and answers whether `e` is a corner event. Throws
    /// InvalidEvent (state unchanged) for an event limits() does not accept.
    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    /// process() without the check: `e` must be accepted by limits().
    bool process_unchecked(const Event& e) noexcept { return process_unchecked_with<ScalarSearch>(e); }

    /// process_unchecked() with a chosen way of finding a circle's newest pixel (arc_test.hpp).
    template <class Search>
    bool process_unchecked_with(const Event& e) noexcept {
        taken_ = taken_.with({e.t, e.t});
        return View::template make<Search>(sae_).template process<Search, false>(e);
    }

    /// detect_unchecked() over a span with a chosen search. The sensor geometry and plane
    /// pointers are held in locals for the whole loop: stores of the one-byte flags may
    /// alias anything, so members would be reloaded (and offsets recomputed) every event.
    /// `span`: the batch's time span (detect() has it from its check pass), or
    /// TimeSpan::unknown(). On the AVX-512 path the loop leaves out the narrowed test's
    /// range check while every time this detector has taken, this batch's included, lies
    /// within a span narrower than efast_avx512::kNarrowSpan (17.9 minutes): no fired cell
    /// can then be out of range. (A separate pass to find a batch's span cost more than
    /// the check saves: on a replayed stream of millions of events it read the events from
    /// memory twice, 11-27 % more time.) An unknown span keeps the range check for good.
    template <class Search>
    std::size_t run_unchecked(std::span<const Event> events, std::span<std::uint8_t> is_corner,
                              const TimeSpan& span = TimeSpan::unknown()) noexcept {
        taken_ = taken_.with(span);
#ifdef EVCORNER_HAVE_AVX2_SEARCH
        if constexpr (std::is_same_v<Search, Avx512Search>)
            if (taken_.narrower_than(efast_avx512::kNarrowSpan)) return run_loop<Search, true>(events, is_corner);
#endif
        return run_loop<Search, false>(events, is_corner);
    }

    /// Whether every time this detector has taken lies within a span narrower than
    /// efast_avx512::kNarrowSpan (the AVX-512 loop then skips the range check; for tests).
    [[nodiscard]] bool times_within_narrow_span() const noexcept {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
        return taken_.narrower_than(efast_avx512::kNarrowSpan);
#else
        return false;
#endif
    }

    /// process_unchecked() that also writes the event's score (corner_scores.hpp,
    /// docs/scores.md): computed for corner events only, NaN (kNoScore) for the others.
    /// The binary paths above never compute it.
    bool process_scored_unchecked(const Event& e, double& score) noexcept {
        taken_ = taken_.with({e.t, e.t});
        return View::template make<ScalarSearch>(sae_).template process_scored<ScalarSearch>(e, score);
    }

    /// run_unchecked() with scores (score[i] as process_scored_unchecked() writes it). The
    /// scores start as NaN in one pass; the loop is run_unchecked()'s plus, for a corner
    /// only, a call to the score (out of line, so that the per-event path stays the
    /// binary one's). `span` as for run_unchecked(); this loop always keeps the range check.
    template <class Search>
    std::size_t run_scored_unchecked(std::span<const Event> events, std::span<std::uint8_t> is_corner,
                                     std::span<double> score, const TimeSpan& span = TimeSpan::unknown()) noexcept {
        taken_ = taken_.with(span);
        const View v = View::template make<Search>(sae_);
        std::fill_n(score.begin(), events.size(), kNoScore);
        std::size_t corners = 0;
        for (std::size_t i = 0; i < events.size(); ++i) {
            const Event& e = events[i];
            const bool c = v.template process<Search, false>(e);
            is_corner[i] = static_cast<std::uint8_t>(c);
            corners += c;
            if (c) [[unlikely]] {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
                if constexpr (std::is_same_v<Search, Avx512Search>) score[i] = v.score_avx512(e);
                else
#endif
                    score[i] = v.score(e);
            }
        }
        return corners;
    }

    [[nodiscard]] const Sae& sae() const noexcept { return sae_; }
    [[nodiscard]] SensorSize size() const noexcept { return sae_.size(); }
    [[nodiscard]] std::size_t memory_bytes() const noexcept { return sae_.memory_bytes(); }

private:
    template <class Search, bool InRange>
    std::size_t run_loop(std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
        const View v = View::template make<Search>(sae_);
        std::size_t corners = 0;
        for (std::size_t i = 0; i < events.size(); ++i) {
            const bool c = v.template process<Search, InRange>(events[i]);
            is_corner[i] = static_cast<std::uint8_t>(c);
            corners += c;
        }
        return corners;
    }

    // The per-event path on plain values: planes, width, the inner region.
    struct View {
        std::int64_t* plane[2];
        std::ptrdiff_t width;
        InnerRegion inner;  // the events whose circles lie on the sensor
        // Circle offsets: the AVX-512 path loads the circles through them (filled for it
        // only, so that a single process() does not pay for them).
        std::int64_t off3[16];
        std::int64_t off4[20];

        template <class Search>
        static View make(Sae& sae) noexcept {
            View v;  // the offsets stay unset (unread) on the other paths
            v.plane[0] = sae.plane(0);
            v.plane[1] = sae.plane(1);
            v.width = sae.size().width;
            v.inner = InnerRegion::of(sae.size().width, sae.size().height);
#ifdef EVCORNER_HAVE_AVX2_SEARCH
            if constexpr (std::is_same_v<Search, Avx512Search>) {
                for (int k = 0; k < 16; ++k) v.off3[k] = kCircle3[k].dy * v.width + kCircle3[k].dx;
                for (int k = 0; k < 20; ++k) v.off4[k] = kCircle4[k].dy * v.width + kCircle4[k].dx;
            }
#endif
            return v;
        }

        // InRange: as efast_avx512::corner() takes it (the AVX-512 path only).
        template <class Search, bool InRange>
        bool process(const Event& e) const noexcept {
            std::int64_t* const centre = plane[e.p & 1] + static_cast<std::ptrdiff_t>(e.y) * width + e.x;
            const std::int64_t st = Sae::stored(e.t);
            *centre = st;  // the SAE update, border events included
            if (!inner.holds(e.x, e.y)) return false;  // a border event
            // Offsets from compile-time circle coordinates: the loads address rows
            // centre + dy * width with constant column offsets.
            const std::ptrdiff_t w = width;
#ifdef EVCORNER_HAVE_AVX2_SEARCH
            if constexpr (std::is_same_v<Search, Avx512Search>) {
                return efast_avx512::corner<InRange>(centre, w * 8, st);
            } else
#endif
            {
                return circle_fires<kCircle3.size(), kArc3Min, kArc3Max, Search>(
                           centre, [w](int k) { return kCircle3[k].dy * w + kCircle3[k].dx; }) &&
                       circle_fires<kCircle4.size(), kArc4Min, kArc4Max, Search>(
                           centre, [w](int k) { return kCircle4[k].dy * w + kCircle4[k].dx; });
            }
        }

        // The score of a corner event `e` from the SAE just updated with it (out of line:
        // the per-event path stays the binary one's).
        [[gnu::noinline]] double score(const Event& e) const noexcept {
            return efast_score(plane[e.p & 1] + static_cast<std::ptrdiff_t>(e.y) * width + e.x, width,
                               Sae::stored(e.t));
        }
#ifdef EVCORNER_HAVE_AVX2_SEARCH
        // The same on the AVX-512 path: the circles loaded into registers as its arc test
        // loads them, the test's masks kept, the score from them (corner_scores.hpp).
        [[gnu::noinline, gnu::target(EVCORNER_AVX512_TARGET), gnu::flatten]] double score_avx512(const Event& e) const noexcept {
            return efast_score_avx512(plane[e.p & 1] + static_cast<std::ptrdiff_t>(e.y) * width + e.x, off3, off4,
                                      Sae::stored(e.t));
        }
#endif

        // process() and, for a corner, its score.
        template <class Search>
        bool process_scored(const Event& e, double& s) const noexcept {
            const bool c = process<Search, false>(e);
            s = c ? score(e) : kNoScore;
            return c;
        }
    };

    Sae sae_;
    TimeSpan taken_;  // the times of every event taken (written into the SAE) so far
};
static_assert(Detector<EFast>);
static_assert(ScoredDetector<EFast>);

/// detect() for eFAST: the same flags, with the fastest code this CPU runs (AVX-512,
/// else AVX2, else portable), chosen once per process; the environment variable
/// EVCORNER_EFAST_PATH=portable|avx2|avx512 forces one this CPU runs. Overload
/// resolution picks it over the generic detect() of detector.hpp. Checks as that one
/// does (InvalidEvent before any event is processed).
std::size_t detect(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner);
/// detect() without the checks: every event accepted by det.limits(), is_corner at
/// least as long as events.
std::size_t detect_unchecked(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept;
/// detect_unchecked() for a caller that knows times holding the batch's (`span`, as
/// check_events_span() gives it): the AVX-512 loop may then leave out its range check
/// (EFast::run_unchecked). ParallelDetector's parts take this one.
std::size_t detect_unchecked(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             const TimeSpan& span) noexcept;

/// detect() with scores (scored_detector.hpp) on the same code path as detect(): the
/// flags are those of detect(); score[i] is eFAST's score for a corner, NaN otherwise.
std::size_t detect(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                   std::span<double> score);
std::size_t detect_unchecked(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept;

/// The code path detect(EFast&, ...) takes: "avx512", "avx2" or "portable".
const char* efast_code_path() noexcept;
/// Every code path this CPU runs, fastest first.
std::vector<std::string> efast_code_paths();
/// detect() on a named path (one of efast_code_paths(); else std::invalid_argument), checked.
std::size_t detect_on_path(std::string_view path, EFast& det, std::span<const Event> events,
                           std::span<std::uint8_t> is_corner);

}  // namespace evcorner
