#pragma once
// HASTE: multi-hypothesis patch trackers of event streams, after Alzugaray and Chli, 3DV 2019
// ("correlation") and BMVC 2020 (the four "haste-*"). Reference implementation
// ialzugaray/haste, MIT licence, (c) 2021 Vision for Robotics Lab, ETH Zurich; what it
// computes, float by float: docs/tracking.md.
//
// Each track keeps the last 193 events within 15 px of it, a 31x31 template built from
// them, and 11 hypotheses around its state (itself, +-1 px in x, y and both diagonals,
// +-4 degrees); every event in range rescores the hypotheses, and when one beats the
// state by the hysteresis margin the track moves there. The five methods differ in the
// score (weighted correlation with the template, or the squared difference between the
// normalised template and the window's model) and in what they update per event.
//
// Haste tracks many features in one pass: an event reaches only the tracks whose range it
// falls in (a grid of 16-pixel cells). One verb, process(event), returns the states it
// produced. No I/O inside.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/track/track_seed.hpp"
#include "evcorner/track/track_state.hpp"

namespace evcorner {

enum class HasteMethod : std::uint8_t {
    correlation,             ///< 3DV'19: Gaussian-weighted correlation, recomputed per event
    haste_correlation,       ///< BMVC'20: the same, each event sampled once (stale columns)
    haste_correlation_star,  ///< BMVC'20: uniform weights, normalised template, incremental
    haste_difference,        ///< BMVC'20: squared difference to the window's model, recomputed
    haste_difference_star,   ///< BMVC'20: the same, updated incrementally
};

/// How a track's first window is filled.
enum class HasteInit : std::uint8_t {
    centered,    ///< 96 in-range events before the seed, then 97 from it: the state's time is the seed's
    uncentered,  ///< 193 in-range events from the seed on: the state's time is 96 events later
};

/// Stopping rules beyond HASTE's own (a moved track whose 31x31 patch leaves the sensor stops).
struct TrackStopRules {
    /// A track with no state change for this long stops (0: never). Microseconds.
    std::int64_t max_idle_us = 0;
    /// When two live tracks come closer than this (pixels), the younger stops (0: never).
    double min_separation = 0;
};

struct HasteParams {
    HasteMethod method = HasteMethod::haste_correlation_star;
    HasteInit init = HasteInit::centered;
    TrackStopRules stop;
    /// The authors' start index: the first event whose time in seconds (as a double) is
    /// at least float(seed time in seconds). Default: the first event with t >= seed t
    /// exactly, in microseconds (float seconds move a seed by microseconds).
    bool authors_seed_time = false;
};

/// The five methods' names, as the command line spells them ("haste-correlation-star").
std::string_view haste_method_name(HasteMethod m) noexcept;
std::optional<HasteMethod> parse_haste_method(std::string_view name) noexcept;

class Haste {
public:
    static constexpr int kPatch = 31;         ///< template side
    static constexpr int kWindow = 193;       ///< events per window
    static constexpr float kRangeSquared = 225.f;  ///< in range: squared distance below (15 px)
    static constexpr int kMargin = 15;        ///< a moved state closer to the border stops

    /// Tracks features on `size` from `seeds` (any order; each starts at the first event
    /// at or after its time). Throws std::invalid_argument for a bad size, a seed off the
    /// sensor or two seeds with one id.
    Haste(SensorSize size, const HasteParams& params, std::vector<TrackSeed> seeds = {});
    ~Haste();
    Haste(Haste&&) noexcept;
    Haste& operator=(Haste&&) noexcept;

    /// Feeds one event; returns the states it produced, by track id (valid until the next
    /// call). Throws InvalidEvent for an event off the sensor and std::invalid_argument
    /// for a time before the previous event's (nothing changed then).
    std::span<const TrackState> process(const Event& e);

    /// Starts a track at the next event (for a front end that seeds as it goes). Throws
    /// std::invalid_argument when the id was used or the position is off the sensor.
    void start(const TrackSeed& seed);
    /// Whether some track (initialised or still collecting its window) is within `radius`
    /// pixels of (x, y).
    [[nodiscard]] bool track_near(float x, float y, float radius) const noexcept;

    [[nodiscard]] std::size_t live_tracks() const noexcept;     ///< initialised and running
    [[nodiscard]] std::size_t pending_tracks() const noexcept;  ///< seeds collecting their window or not yet due
    /// Seeds that could not start: centered init with fewer than 96 earlier events in range.
    [[nodiscard]] std::uint64_t skipped_seeds() const noexcept;
    /// In-range (event, track) pairs processed so far: HASTE's unit of work.
    [[nodiscard]] std::uint64_t track_updates() const noexcept;
    [[nodiscard]] EventLimits limits() const noexcept;
    [[nodiscard]] const HasteParams& params() const noexcept;

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace evcorner
