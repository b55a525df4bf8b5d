#include "evcorner/io/event_checks.hpp"

#include <fmt/format.h>

namespace evcorner::io {

std::string outside_sensor_message(std::int64_t x, std::int64_t y, const std::optional<SensorSize>& sensor,
                                   bool keyword_spelling) {
    if (sensor)
        return fmt::format("event at x={} y={} lies outside the {}x{} sensor (set {}, or {} to skip such events)", x,
                           y, sensor->width, sensor->height, keyword_spelling ? "sensor=" : "--size",
                           keyword_spelling ? "skip_invalid=True" : "--skip-invalid");
    return fmt::format("event at x={} y={} does not fit 16-bit coordinates", x, y);
}

std::string backwards_message(std::int64_t previous, std::int64_t t) {
    // In unsigned arithmetic: the gap between two int64 times can exceed INT64_MAX.
    const std::uint64_t gap = static_cast<std::uint64_t>(previous) - static_cast<std::uint64_t>(t);
    return fmt::format("timestamp goes backwards ({} us before the previous event)", gap);
}

}  // namespace evcorner::io
