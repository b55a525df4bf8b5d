#pragma once
// Arc*: the asynchronous corner detector of
//   I. Alzugaray, M. Chli, "Asynchronous Corner Detection and Tracking for Event Cameras
//   in Real Time", IEEE RA-L 2018,
// exact to its authors' implementation (docs/arcstar.md), on any sensor size.
// Per event: a 50 ms filter (an event passes iff its pixel has been quiet with its polarity
// for more than 50 ms, or fired with the other polarity since, or never fired); a passing
// event writes the filtered SAE of its polarity; away from the border it is a corner iff
// the Arc* arc test (arcstar_test.hpp) passes on the radius-3 and then the radius-4 circle.

#include <cstddef>
#include <cstdint>
#include <span>

#include "evcorner/arcstar_test.hpp"
#include "evcorner/circle.hpp"
#include "evcorner/corner_scores.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/sae.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/zeroed_array.hpp"

namespace evcorner {

struct ArcStarParams {
    bool filter = true;                ///< the published filter; false: every event passes
    std::int64_t filter_us = 50000;    ///< the filter window in us, 0..kMaxFilterUs
    bool minority_only = false;        ///< accept only arcs of Lmin..Lmax, not the majority arcs
    bool zero_init = false;            ///< the authors' zero-initialised filter (never = time 0)
};

class ArcStar {
public:
    using Params = ArcStarParams;
    static constexpr int kArc3Min = 3, kArc3Max = 6;
    static constexpr int kArc4Min = 4, kArc4Max = 8;
    static constexpr std::int64_t kMaxFilterUs = std::int64_t{1} << 40;  // about 12.7 days

    /// Throws std::invalid_argument for filter_us or a sensor side out of range. `planes`
    /// is accepted for the detector contract and ignored: the filter reads the other
    /// polarity, so both are always kept.
    explicit ArcStar(SensorSize size, const Params& params = {}, int planes = 2);

    /// Bytes of state: per pixel the latest time of each polarity and the filtered SAE of
    /// each polarity (32 bytes).
    [[nodiscard]] static constexpr std::uint64_t state_bytes(SensorSize size, const Params& = {}, int = 2) noexcept {
        return Sae::state_bytes(size, 2) + static_cast<std::uint64_t>(size.pixels()) * sizeof(ArcStarLatest);
    }

    /// What process() accepts: events on the sensor, polarity 0/1, time within the SAE's range.
    [[nodiscard]] EventLimits limits() const noexcept { return {sae_.size(), Sae::kMinTime, Sae::kMaxTime}; }

    /// Filters `e`, updates the state and answers whether `e` is a corner event. Throws
    /// InvalidEvent (state unchanged) for an event limits() does not accept.
    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    /// process() without the check: `e` must be accepted by limits().
    bool process_unchecked(const Event& e) noexcept { return View::make(*this).process<ScalarSearch>(e); }

    /// detect_unchecked() over a span with a chosen newest-pixel search (arc_test.hpp).
    template <class Search>
    std::size_t run_unchecked(std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
        const View v = View::make(*this);
        // The published parameters (filter on, never-fired passes) as compile-time constants:
        // the per-event filter then carries no tests of parameters.
        if (params_.filter && !params_.zero_init) return v.template run<Search, true>(events, is_corner);
        return v.template run<Search, false>(events, is_corner);
    }

    /// process_unchecked() that also writes the event's score (corner_scores.hpp,
    /// docs/scores.md): computed for corner events only, NaN (kNoScore) for the others.
    /// The binary paths never compute it.
    bool process_scored_unchecked(const Event& e, double& score) noexcept {
        return View::make(*this).process_scored<ScalarSearch>(e, score);
    }
    /// run_unchecked() with scores.
    template <class Search>
    std::size_t run_scored_unchecked(std::span<const Event> events, std::span<std::uint8_t> is_corner,
                                     std::span<double> score) noexcept {
        const View v = View::make(*this);
        if (params_.filter && !params_.zero_init) return v.template run_scored<Search, true>(events, is_corner, score);
        return v.template run_scored<Search, false>(events, is_corner, score);
    }

    [[nodiscard]] const Params& params() const noexcept { return params_; }
    [[nodiscard]] SensorSize size() const noexcept { return sae_.size(); }
    /// The filtered SAE (only events that passed the filter).
    [[nodiscard]] const Sae& sae() const noexcept { return sae_; }
    /// The time of the latest event (filtered or not) at (x, y) of polarity p, or Sae::kNever.
    [[nodiscard]] std::int64_t latest(int p, int x, int y) const noexcept {
        const std::int64_t v = latest_[static_cast<std::size_t>(y) * static_cast<std::size_t>(size().width) +
                                        static_cast<std::size_t>(x)].t[p & 1];
        return v == 0 ? Sae::kNever : v - Sae::kBias;
    }
    [[nodiscard]] std::size_t memory_bytes() const noexcept {
        return sae_.memory_bytes() + latest_.size() * sizeof(ArcStarLatest);
    }

private:
    // The per-event path on plain values (held in locals over a whole span).
    struct View {
        std::int64_t* plane[2];
        ArcStarLatest* latest;
        std::ptrdiff_t width;
        int height;
        InnerRegion inner;  // the events whose circles lie on the sensor
        std::int64_t window;
        bool filter, minority_only, zero_init;
        ArcStarCircles circles;

        static View make(ArcStar& d) noexcept {
            return {{d.sae_.plane(0), d.sae_.plane(1)},
                    d.latest_.data(),
                    d.sae_.size().width,
                    d.sae_.size().height,
                    InnerRegion::of(d.sae_.size().width, d.sae_.size().height),
                    d.params_.filter_us,
                    d.params_.filter,
                    d.params_.minority_only,
                    d.params_.zero_init,
                    ArcStarCircles(d.sae_.size().width)};
        }

        // The batch loop: process() event by event; on the AVX-512 path (run_moved()) with
        // two branches moved away from the work they wait on, so that a mispredicted one
        // costs a pipeline refill rather than the latency of that work (docs/arcstar.md,
        // "The batch loop"):
        // - the filter runs one event ahead (event i+1's outcome is computed, and its
        //   latest time recorded, before event i's arc tests; the filter reads only the
        //   latest times, which nothing else writes);
        // - the radius-4 test of a candidate (a passing event whose radius-3 test passed)
        //   runs one passing event later, after that event's radius-3 test and before its
        //   SAE write. Exact: neither arc test reads its own event's centre, so the
        //   radius-4 test still reads the SAE as it stood right after the candidate's
        //   write (rejected events in between write only the filter's state).
        // The moved branches pay on the AVX-512 path (about 10 % less time on this
        // project's AMD EPYC); on the AVX2 path they cost about 10 % more
        // instructions (callgrind) and gained no time, so it and the portable path keep the
        // plain loop.
#ifdef EVCORNER_HAVE_AVX2_SEARCH
        template <class Search>
        static constexpr bool kMovedBranches = std::is_same_v<Search, Avx512Search>;
#else
        template <class Search>
        static constexpr bool kMovedBranches = false;
#endif
        template <class Search, bool Published>
        std::size_t run(std::span<const Event> events, std::span<std::uint8_t> is_corner) const noexcept {
            if constexpr (kMovedBranches<Search>) {
                // minority_only as a constant too (the published false, or true): the arc
                // tests' decision then reads no parameter.
                if (minority_only) return run_moved<Search, Published, true>(events, is_corner);
                return run_moved<Search, Published, false>(events, is_corner);
            } else {
                std::size_t corners = 0;
                for (std::size_t i = 0; i < events.size(); ++i) {
                    const bool c = process<Search, Published>(events[i]);
                    is_corner[i] = static_cast<std::uint8_t>(c);
                    corners += c;
                }
                return corners;
            }
        }
        template <class Search, bool Published, bool MinorityOnly>
        std::size_t run_moved(std::span<const Event> events, std::span<std::uint8_t> is_corner) const noexcept {
            std::size_t corners = 0;
            const std::int64_t* cand_centre = nullptr;  // the pending candidate, if any
            std::int64_t cand_st = 0;
            std::size_t cand = 0;
            bool pending = false;
            const std::size_t n = events.size();
            bool pass_next = n != 0 && filter_event<Published>(events[0]);
            for (std::size_t i = 0; i < n; ++i) {
                const Event& e = events[i];
                is_corner[i] = 0;
                const bool pass = pass_next;
                if (i + 1 < n) pass_next = filter_event<Published>(events[i + 1]);
                if (!pass) continue;
                const int p = e.p & 1;
                const std::ptrdiff_t at = static_cast<std::ptrdiff_t>(e.y) * width + e.x;
                const std::int64_t st = Sae::stored(e.t);
                std::int64_t* const centre = plane[p] + at;
                const bool r3 =
                    inside(e) && circles.pass_circle<Search, 16, kArc3Min, kArc3Max>(centre, st, MinorityOnly);
                if (pending) {
                    const bool c = circles.pass_circle<Search, 20, kArc4Min, kArc4Max>(cand_centre, cand_st, MinorityOnly);
                    is_corner[cand] = static_cast<std::uint8_t>(c);
                    corners += c;
                }
                *centre = st;
                pending = r3;
                cand_centre = centre;
                cand_st = st;
                cand = i;
            }
            if (pending) {
                const bool c = circles.pass_circle<Search, 20, kArc4Min, kArc4Max>(cand_centre, cand_st, MinorityOnly);
                is_corner[cand] = static_cast<std::uint8_t>(c);
                corners += c;
            }
            return corners;
        }

        // The filter for an event of polarity p and stored time st at pixel index `at`;
        // records it as the pixel's latest in every case.
        template <bool Published>
        bool filter_update(int p, std::ptrdiff_t at, std::int64_t st) const noexcept {
            ArcStarLatest& l = latest[at];
            const bool pass = !(Published || filter) |
                              arcstar_filter_passes(st, l.t[p], l.t[p ^ 1], window, !Published && zero_init);
            l.t[p] = st;
            return pass;
        }
        template <bool Published>
        bool filter_event(const Event& e) const noexcept {
            return filter_update<Published>(e.p & 1, static_cast<std::ptrdiff_t>(e.y) * width + e.x, Sae::stored(e.t));
        }
        // Whether e lies off the border (its circles on the sensor).
        bool inside(const Event& e) const noexcept { return inner.holds(e.x, e.y); }

        // Published: the caller knows filter && !zero_init.
        template <class Search, bool Published = false>
        bool process(const Event& e) const noexcept {
            const int p = e.p & 1;
            const std::ptrdiff_t i = static_cast<std::ptrdiff_t>(e.y) * width + e.x;
            const std::int64_t st = Sae::stored(e.t);
            ArcStarLatest& l = latest[i];
            const bool pass = !(Published || filter) |
                              arcstar_filter_passes(st, l.t[p], l.t[p ^ 1], window, !Published && zero_init);
            l.t[p] = st;
            if (!pass) return false;
            std::int64_t* const centre = plane[p] + i;
            *centre = st;
            // (Written out, not through filter_update() and inside(): with those GCC 12
            // compiles the AVX2 loop to 6 % more instructions.)
            if (e.x < kCircleMargin || e.x >= width - kCircleMargin || e.y < kCircleMargin ||
                e.y >= height - kCircleMargin)
                return false;
            return circles.pass<Search, kArc3Min, kArc3Max, kArc4Min, kArc4Max>(centre, minority_only);
        }

        // process() and, for a corner, its score from the filtered SAE just updated.
        template <class Search, bool Published = false>
        bool process_scored(const Event& e, double& score) const noexcept {
            const bool c = process<Search, Published>(e);
            score = kNoScore;
            if (c)
                score = arcstar_score(plane[e.p & 1] + static_cast<std::ptrdiff_t>(e.y) * width + e.x, width,
                                      Sae::stored(e.t));
            return c;
        }
        template <class Search, bool Published>
        std::size_t run_scored(std::span<const Event> events, std::span<std::uint8_t> is_corner,
                               std::span<double> score) const noexcept {
            std::size_t corners = 0;
            for (std::size_t i = 0; i < events.size(); ++i) {
                const bool c = process_scored<Search, Published>(events[i], score[i]);
                is_corner[i] = static_cast<std::uint8_t>(c);
                corners += c;
            }
            return corners;
        }
    };

    Params params_;
    Sae sae_;
    ZeroedArray<ArcStarLatest> latest_;
};
static_assert(Detector<ArcStar>);
static_assert(ScoredDetector<ArcStar>);

/// detect() for Arc*: the same flags, with the fastest code this CPU runs (AVX-512, else
/// AVX2, else portable), chosen once per process; EVCORNER_ARCSTAR_PATH=portable|avx2|avx512
/// forces one this CPU runs (any other value: the fastest). Checks as the generic
/// detect() does (InvalidEvent before any event is processed).
std::size_t detect(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner);
/// detect() without the checks.
std::size_t detect_unchecked(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept;
/// detect() with scores (scored_detector.hpp): the flags of detect(); score[i] is Arc*'s
/// score for a corner, NaN otherwise. Portable or AVX2 search (the scored path is not the
/// AVX-512 closed form, which finds no arc).
std::size_t detect(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                   std::span<double> score);
std::size_t detect_unchecked(ArcStar& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept;
/// The code path detect() runs: "avx512", "avx2" or "portable".
const char* arcstar_code_path() noexcept;

}  // namespace evcorner
