#pragma once
// The event: one brightness change reported by one pixel.
//
// Plain data, 16 bytes, laid out so that a numpy structured array
// dtype([('t','<i8'),('x','<u2'),('y','<u2'),('p','u1'),('_','V3')]) maps onto it.
// Time is integer microseconds from the reader inward.

#include <cstdint>
#include <type_traits>

namespace evcorner {

struct Event {
    std::int64_t t;   ///< timestamp, microseconds
    std::uint16_t x;  ///< column, 0 at the left
    std::uint16_t y;  ///< row, 0 at the top
    std::uint8_t p;   ///< polarity: 1 = ON (brighter), 0 = OFF

    friend constexpr bool operator==(const Event&, const Event&) = default;
};

static_assert(sizeof(Event) == 16);
static_assert(alignof(Event) == 8);
static_assert(std::is_trivially_copyable_v<Event>);
static_assert(std::is_standard_layout_v<Event>);
static_assert(std::is_aggregate_v<Event>);

}  // namespace evcorner
