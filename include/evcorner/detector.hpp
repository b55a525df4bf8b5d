#pragma once
// What every detector is: a small stateful object with one per-event verb.
//
//   bool process(const Event&) noexcept  -- update the state with the event and
//                                           answer whether it is a corner event.
//
// No files, threads or clocks inside a detector. Running one over a span of events
// is the free function detect(), written once for all detectors.

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>

#include "evcorner/event.hpp"

namespace evcorner {

template <class D>
concept Detector = requires(D& d, const Event& e) {
    { d.process(e) } noexcept -> std::same_as<bool>;
};

/// Runs `det` over `events` in order; is_corner[i] = 1 when events[i] is a corner.
/// Returns the number of corners. is_corner must be at least as long as events.
template <Detector D>
std::size_t detect(D& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    std::size_t corners = 0;
    for (std::size_t i = 0; i < events.size(); ++i) {
        const bool c = det.process(events[i]);
        is_corner[i] = static_cast<std::uint8_t>(c);
        corners += c;
    }
    return corners;
}

}  // namespace evcorner
