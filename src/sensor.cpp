#include "evcorner/sensor.hpp"

#include <charconv>
#include <stdexcept>
#include <string>

namespace evcorner {

SensorSize checked_sensor_size(SensorSize size, const char* who) {
    if (size.width < 1 || size.height < 1 || size.width > kMaxSensorSide || size.height > kMaxSensorSide)
        throw std::invalid_argument(std::string(who) + ": sensor size " + std::to_string(size.width) + "x" +
                                    std::to_string(size.height) + " is outside 1x1.." + std::to_string(kMaxSensorSide) +
                                    "x" + std::to_string(kMaxSensorSide));
    return size;
}

std::optional<SensorSize> parse_sensor_size(std::string_view text) {
    const auto sep = text.find_first_of("xX");
    if (sep == std::string_view::npos) return std::nullopt;
    auto parse_side = [](std::string_view s) -> std::optional<int> {
        int v = 0;
        const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (ec != std::errc{} || end != s.data() + s.size()) return std::nullopt;
        if (v < 1 || v > kMaxSensorSide) return std::nullopt;
        return v;
    };
    const auto w = parse_side(text.substr(0, sep));
    const auto h = parse_side(text.substr(sep + 1));
    if (!w || !h) return std::nullopt;
    return SensorSize{*w, *h};
}

}  // namespace evcorner
