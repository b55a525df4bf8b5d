#pragma once
// What every detector is: a small stateful object with one per-event verb.
//
//   bool process(const Event&)                    -- check the event (event_check.hpp:
//                                                    on the sensor, polarity 0/1; throws
//                                                    InvalidEvent, state unchanged), update
//                                                    the state with it and answer whether
//                                                    it is a corner event.
//   bool process_unchecked(const Event&) noexcept -- the same without the check, for a
//                                                    caller that has validated the event
//                                                    (an unchecked bad event corrupts memory).
//   EventLimits limits() const noexcept           -- what process() accepts.
//
// No files, threads or clocks inside a detector. Running one over a span of events
// is the free function detect(), written once for all detectors: it checks the whole
// span in one tight pass before the first event, then runs the unchecked loop.

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include "evcorner/event.hpp"
#include "evcorner/event_check.hpp"

namespace evcorner {

template <class D>
concept Detector = requires(D& d, const D& cd, const Event& e) {
    { d.process_unchecked(e) } noexcept -> std::same_as<bool>;
    { d.process(e) } -> std::same_as<bool>;
    { cd.limits() } noexcept -> std::same_as<EventLimits>;
};

namespace detail {
inline void check_flags(std::size_t events, std::size_t flags, const char* what) {
    if (flags < events)
        throw std::invalid_argument(std::string(what) + ": " + std::to_string(flags) + " flags for " +
                                    std::to_string(events) + " events");
}
}  // namespace detail

/// detect() without the checks: `events` must all be accepted by det.limits() and
/// is_corner at least as long as events (else memory is corrupted).
template <Detector D>
std::size_t detect_unchecked(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    std::size_t corners = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const bool c = det.process_unchecked(events[i]);
        is_corner[i] = static_cast<std::uint8_t>(c);
        corners += c;
    }
    return corners;
}

/// Runs `det` over `events` in order; is_corner[i] = 1 when events[i] is a corner.
/// Returns the number of corners. Throws InvalidEvent (naming the first bad event) or
/// std::invalid_argument (is_corner shorter than events) before any event is processed.
template <Detector D>
std::size_t detect(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) {
    detail::check_flags(events.size(), is_corner.size(), "detect");
    check_events(events, det.limits());
    return detect_unchecked(det, events, is_corner);
}

}  // namespace evcorner
