#pragma once
// Checking events at the library's boundary: an event a detector may take lies on its
// sensor (x < width, y < height) and has polarity 0 or 1 (and, for eFAST, a time its
// state can hold). The detectors' process() and detect() check; their *_unchecked forms
// do not, for a caller whose reader has validated already (every evcorner reader does).
// An event that fails the check would be written outside the detector's state.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

/// What a detector accepts: events on `size`, polarity 0/1, time within [t_min, t_max].
struct EventLimits {
    SensorSize size;
    std::int64_t t_min = std::numeric_limits<std::int64_t>::min();
    std::int64_t t_max = std::numeric_limits<std::int64_t>::max();

    [[nodiscard]] constexpr bool accepts(const Event& e) const noexcept {
        // Non-short-circuit: one branch-free test, which the batch pass vectorises.
        return (e.x < size.width) & (e.y < size.height) & (e.p <= 1) & (e.t >= t_min) & (e.t <= t_max);
    }
};

/// The error for an event a detector cannot take. what() names the event (its index in
/// the batch when there is one), what is wrong with it and the sensor.
class InvalidEvent : public std::invalid_argument {
public:
    static constexpr std::size_t kNoIndex = static_cast<std::size_t>(-1);
    InvalidEvent(const Event& e, const EventLimits& limits, std::size_t index = kNoIndex);

    [[nodiscard]] const Event& event() const noexcept { return event_; }
    /// Position in the batch given to detect(), or kNoIndex for a single process().
    [[nodiscard]] std::size_t index() const noexcept { return index_; }
    [[nodiscard]] SensorSize sensor() const noexcept { return sensor_; }

private:
    Event event_;
    std::size_t index_;
    SensorSize sensor_;
};

/// The least and the greatest time in a batch of events (lo > hi for no events).
struct TimeSpan {
    std::int64_t lo = std::numeric_limits<std::int64_t>::max();
    std::int64_t hi = std::numeric_limits<std::int64_t>::min();

    /// Every time: what a caller that does not know a batch's span passes.
    [[nodiscard]] static constexpr TimeSpan unknown() noexcept {
        return {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()};
    }
    [[nodiscard]] constexpr bool empty() const noexcept { return lo > hi; }
    /// The span holding both this one and `o`.
    [[nodiscard]] constexpr TimeSpan with(const TimeSpan& o) const noexcept {
        return {lo < o.lo ? lo : o.lo, hi > o.hi ? hi : o.hi};
    }
    /// Whether every two times in the span lie less than `width` us apart (an empty span
    /// does). Exact for any times (hi - lo in unsigned arithmetic).
    [[nodiscard]] constexpr bool narrower_than(std::int64_t width) const noexcept {
        return empty() || static_cast<std::uint64_t>(hi) - static_cast<std::uint64_t>(lo) <
                              static_cast<std::uint64_t>(width);
    }
    friend constexpr bool operator==(const TimeSpan&, const TimeSpan&) = default;
};

/// Index of the first event that `limits` does not accept, or events.size() if none.
/// One tight pass: blocks of events are tested without a branch per event, with AVX-512
/// or AVX2 where the CPU has it (chosen at run time).
[[nodiscard]] std::size_t first_invalid_event(std::span<const Event> events, const EventLimits& limits) noexcept;
/// The same, and in `span` the batch's time span (found in the same pass; meaningful
/// only when every event is accepted).
[[nodiscard]] std::size_t first_invalid_event(std::span<const Event> events, const EventLimits& limits,
                                              TimeSpan& span) noexcept;

/// The passes first_invalid_event() may take on this CPU ("avx512", "avx2", "portable"),
/// the one it takes first.
[[nodiscard]] std::vector<std::string> event_check_paths();
/// first_invalid_event() on a named pass (one of event_check_paths(); else
/// std::invalid_argument): for tests and benchmarks.
[[nodiscard]] std::size_t first_invalid_event_on_path(std::string_view path, std::span<const Event> events,
                                                      const EventLimits& limits, TimeSpan& span);
/// Throws InvalidEvent unless `limits` accepts `e`.
inline void check_event(const Event& e, const EventLimits& limits) {
    if (!limits.accepts(e)) [[unlikely]]
        throw InvalidEvent(e, limits);
}

/// Throws InvalidEvent for the first event `limits` does not accept; nothing is changed
/// by the check, so a detector that checks first is left as it was.
inline void check_events(std::span<const Event> events, const EventLimits& limits) {
    const std::size_t i = first_invalid_event(events, limits);
    if (i != events.size()) [[unlikely]]
        throw InvalidEvent(events[i], limits, i);
}
/// check_events() that also answers the batch's time span, from the same pass.
[[nodiscard]] inline TimeSpan check_events_span(std::span<const Event> events, const EventLimits& limits) {
    TimeSpan span;
    const std::size_t i = first_invalid_event(events, limits, span);
    if (i != events.size()) [[unlikely]]
        throw InvalidEvent(events[i], limits, i);
    return span;
}

}  // namespace evcorner
