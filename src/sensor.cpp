#include "evcorner/sensor.hpp"

#include <charconv>

namespace evcorner {

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
