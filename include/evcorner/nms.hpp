#pragma once
// Asynchronous non-maximum suppression (docs/nms.md): one stage after any scored
// detector (scored_detector.hpp). It decides at each corner event's own time, from the
// past only (a downstream tracker cannot wait), deterministically:
//
//   keep(e, s) -- e a corner event of score s (NaN reads as -infinity). Looks at the
//                 latest earlier corner event at each pixel of e's polarity within the
//                 (2 radius + 1)^2 square centred on e (e's own pixel included), of
//                 time tc and score sc, dt = e.t - tc:
//     rule window: e is suppressed iff some such corner has dt <= time_us and sc >= s;
//     rule decay : e is suppressed iff some such corner has decayed(sc, dt) >= s, where
//                  decayed(s, dt) = s * exp(-dt / time_us) for s >= 0 and s / exp(..)
//                  for s < 0 (it falls with dt from s, for either sign), dt < 0 read as 0,
//                  weight 0 beyond 700 time constants (ANMS's decayed neighbour scores,
//                  Zhou et al. 2023).
//                 Tie rule: an EQUAL (decayed) score suppresses (>=): the first of equals
//                 is kept, as it was already passed on (decay: an equal score at dt > 0
//                 has decayed below, so a later equal corner is kept too).
//                 Then e becomes the latest corner of its pixel, suppressed or not.
//
// Every corner the detector finds is recorded, not only the kept ones: so whether a corner
// is kept depends only on the corners within `radius` of it, and the stage is local (a
// --threads part needs a halo of the detector's radius plus `radius`: parallel_detect.hpp).
// Polarities are separate (a corner is compared with corners of its own polarity).
//
// Suppressed<D> composes the stage with a scored detector D into a detector (the
// Detector concept; scored too): the pipeline, --threads and the bindings run it as any
// other. Its batch loop runs D's own scored batch loop, then the stage over the corners, a
// chunk of kNmsChunk events at a time (each chunk's events and scores still in the cache).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/zeroed_array.hpp"

namespace evcorner {

enum class NmsRule { window, decay };

struct NmsParams {
    NmsRule rule = NmsRule::window;
    int radius = 2;                 ///< half side of the square neighbourhood, px, 0..kMaxRadius
    std::int64_t time_us = 2000;    ///< window: the time window; decay: the decay constant; 1..kMaxTimeUs

    static constexpr int kMaxRadius = 15;
    static constexpr std::int64_t kMaxTimeUs = std::int64_t{1} << 40;
};

/// "window" or "decay".
const char* nms_rule_name(NmsRule r) noexcept;
/// NmsRule from "window" or "decay"; std::invalid_argument otherwise.
NmsRule parse_nms_rule(std::string_view name);
/// Throws std::invalid_argument naming the parameter when one is out of range.
void check_nms_params(const NmsParams& p);

class AsyncNms {
public:
    /// The times keep() takes (those of the SAE, sae.hpp).
    static constexpr std::int64_t kMinTime = -(std::int64_t{1} << 62) + 1;
    static constexpr std::int64_t kMaxTime = std::numeric_limits<std::int64_t>::max() - (std::int64_t{1} << 62);

    /// `planes` = 1: one plane for both polarities (a caller feeding one polarity only).
    AsyncNms(SensorSize size, const NmsParams& params, int planes = 2);

    [[nodiscard]] static std::uint64_t state_bytes(SensorSize size, int planes = 2) noexcept {
        return static_cast<std::uint64_t>(planes == 1 ? 1 : 2) * static_cast<std::uint64_t>(size.pixels()) *
               (sizeof(std::int64_t) + sizeof(double));
    }

    /// Decides corner event `e` (on the sensor, p 0/1) of score `score`, and records it.
    bool keep(const Event& e, double score) noexcept { return keep_(*this, e, score); }

    /// Runs keep() over the corners of a batch: is_corner[i] becomes 0 where events[i]
    /// is suppressed. Returns the corners kept.
    std::size_t filter(std::span<const Event> events, std::span<std::uint8_t> is_corner,
                       std::span<const double> score) noexcept {
        return filter_(*this, events, is_corner, score);
    }

    [[nodiscard]] const NmsParams& params() const noexcept { return params_; }

    /// The code paths of the window rule's neighbourhood test this CPU runs, fastest
    /// first ("avx512", "avx2", "portable"); all decide alike (tests hold each to the
    /// oracle). A new stage takes the first, or the one EVCORNER_NMS_PATH names.
    [[nodiscard]] static std::vector<std::string> code_paths();
    /// This stage's path; use_code_path() switches it (std::invalid_argument for a path
    /// this CPU does not run).
    [[nodiscard]] const char* code_path() const noexcept { return path_name_; }
    void use_code_path(std::string_view name);
    [[nodiscard]] std::size_t memory_bytes() const noexcept { return cells_.size() * sizeof(std::int64_t); }

private:
    // Offset of e's polarity plane within each half of cells_.
    [[nodiscard]] std::size_t plane_of(const Event& e) const noexcept {
        return static_cast<std::size_t>(planes_ == 2 && (e.p & 1)) * static_cast<std::size_t>(size_.pixels());
    }
    // The code path's compiled pair of calls (keep, filter), chosen at construction; the
    // per-path bodies live in nms.cpp (struct NmsPath).
    friend struct NmsPath;
    using KeepFn = bool (*)(AsyncNms&, const Event&, double) noexcept;
    using FilterFn = std::size_t (*)(AsyncNms&, std::span<const Event>, std::span<std::uint8_t>,
                                     std::span<const double>) noexcept;
    NmsParams params_;
    SensorSize size_;
    KeepFn keep_;
    FilterFn filter_;
    const char* path_name_;
    int planes_;
    double inv_time_;
    // Per pixel (and plane) the latest corner: its time + 2^62 (0 = none: zero pages) in
    // the first half, its score's bits in the second: separate, so that a look at the
    // neighbourhood reads the times first and the scores only of rows with a corner recent
    // enough to matter. One allocation (as one plane of pairs was: the same memory).
    ZeroedArray<std::int64_t> cells_;
    [[nodiscard]] std::int64_t* times(const Event& e) noexcept { return cells_.data() + plane_of(e); }
    [[nodiscard]] const std::int64_t* times(const Event& e) const noexcept { return cells_.data() + plane_of(e); }
    [[nodiscard]] std::int64_t* score_bits(const Event& e) noexcept { return cells_.data() + cells_.size() / 2 + plane_of(e); }
};

/// A scored detector followed by AsyncNms: a detector whose corners are the kept ones.
template <ScoredDetector D>
class Suppressed {
public:
    using Params = typename D::Params;

    Suppressed(D det, const NmsParams& nms, int planes = 2)
        : det_(std::move(det)), nms_(det_.limits().size, nms, planes) {}

    /// The detector's limits, times within the stage's range (Sae::kMinTime..kMaxTime).
    [[nodiscard]] EventLimits limits() const noexcept {
        EventLimits l = det_.limits();
        l.t_min = l.t_min > AsyncNms::kMinTime ? l.t_min : AsyncNms::kMinTime;
        l.t_max = l.t_max < AsyncNms::kMaxTime ? l.t_max : AsyncNms::kMaxTime;
        return l;
    }
    bool process(const Event& e) {
        check_event(e, limits());
        return process_unchecked(e);
    }
    bool process_unchecked(const Event& e) noexcept {
        double s;
        return process_scored_unchecked(e, s);
    }
    /// The detector's score (for every event it scores), and kept or not.
    bool process_scored_unchecked(const Event& e, double& score) noexcept {
        const bool c = evcorner::process_scored_unchecked(det_, e, score);
        return c && nms_.keep(e, score);
    }

    [[nodiscard]] D& detector() noexcept { return det_; }
    [[nodiscard]] const D& detector() const noexcept { return det_; }
    [[nodiscard]] AsyncNms& nms() noexcept { return nms_; }
    [[nodiscard]] std::size_t memory_bytes() const noexcept {
        if constexpr (requires { det_.memory_bytes(); })
            return det_.memory_bytes() + nms_.memory_bytes();
        else
            return nms_.memory_bytes();
    }
    /// A score buffer for the batch loops (grown, never shrunk).
    std::span<double> scratch(std::size_t n) {
        if (scratch_.size() < n) scratch_.resize(n);
        return {scratch_.data(), n};
    }

private:
    D det_;
    AsyncNms nms_;
    std::vector<double> scratch_;
};

/// The batch loops of Suppressed<D>: D's own scored batch loop (eFAST's fastest path, ...),
/// then the stage over its corners, a chunk of kNmsChunk events at a time: the stage reads
/// each corner's event and score right after the detector wrote them, while they are in
/// the cache (over a whole file at once they were not: on a 374 000-event recording reading
/// them back cost as much as the suppression itself). Decisions do not depend on the chunk.
inline constexpr std::size_t kNmsChunk = 4096;
template <ScoredDetector D>
std::size_t detect_unchecked(Suppressed<D>& det, std::span<const Event> events, std::span<std::uint8_t> is_corner,
                             std::span<double> score) noexcept {
    std::size_t kept = 0;
    for (std::size_t at = 0; at < events.size(); at += kNmsChunk) {
        const std::size_t n = std::min(kNmsChunk, events.size() - at);
        const auto ev = events.subspan(at, n);
        const auto flags = is_corner.subspan(at, n);
        const auto sc = score.subspan(at, n);
        detect_unchecked(det.detector(), ev, flags, sc);
        kept += det.nms().filter(ev, flags, sc);
    }
    return kept;
}
template <ScoredDetector D>
std::size_t detect_unchecked(Suppressed<D>& det, std::span<const Event> events,
                             std::span<std::uint8_t> is_corner) noexcept {
    // The scratch scores of a chunk: allocated once, outside the per-event loop.
    std::span<double> score;
    try {
        score = det.scratch(std::min(events.size(), kNmsChunk));
    } catch (...) {
        std::size_t corners = 0;  // no memory for a buffer: event by event
        for (std::size_t i = 0; i < events.size(); ++i) corners += (is_corner[i] = det.process_unchecked(events[i]));
        return corners;
    }
    std::size_t kept = 0;
    for (std::size_t at = 0; at < events.size(); at += kNmsChunk) {
        const std::size_t n = std::min(kNmsChunk, events.size() - at);
        kept += detect_unchecked(det, events.subspan(at, n), is_corner.subspan(at, n), score.first(n));
    }
    return kept;
}
// The checked detect() of detector.hpp and scored_detector.hpp find these loops.

}  // namespace evcorner
