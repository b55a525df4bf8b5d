#pragma once
// Sensor geometry: the pixel array an event stream lives on.

#include <cstdint>
#include <optional>
#include <string_view>

#include "evcorner/event.hpp"

namespace evcorner {

struct SensorSize {
    int width = 0;
    int height = 0;

    [[nodiscard]] constexpr bool contains(int x, int y) const noexcept {
        return x >= 0 && y >= 0 && x < width && y < height;
    }
    [[nodiscard]] constexpr bool contains(const Event& e) const noexcept {
        return e.x < width && e.y < height;
    }
    [[nodiscard]] constexpr std::int64_t pixels() const noexcept {
        return std::int64_t{width} * height;
    }
    friend constexpr bool operator==(const SensorSize&, const SensorSize&) = default;
};

/// The DAVIS240C, the camera of the Event-Camera Dataset.
inline constexpr SensorSize kDavis240{240, 180};

/// Largest side the 16-bit event coordinates can address.
inline constexpr int kMaxSensorSide = 65536;

/// `size` when both sides lie within 1..kMaxSensorSide; else throws std::invalid_argument
/// naming `who` (the detector) and the size.
SensorSize checked_sensor_size(SensorSize size, const char* who);

/// Parses "WxH" (e.g. "1280x720"); nullopt when malformed or out of 1..65536.
std::optional<SensorSize> parse_sensor_size(std::string_view text);

}  // namespace evcorner
