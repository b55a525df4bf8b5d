#include "evcorner/io/prophesee_header.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>

namespace evcorner::io {

namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
}

std::string lower(std::string_view s) {
    std::string r(s);
    for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return r;
}

std::optional<int> to_side(std::string_view s) {
    s = trim(s);
    int v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc{} || end != s.data() + s.size() || v < 1 || v > kMaxSensorSide) return std::nullopt;
    return v;
}

}  // namespace

void PropheseeHeader::add_line(std::string_view line) {
    if (!line.empty() && line.front() == '%') line.remove_prefix(1);
    line = trim(line);
    const auto sp = line.find_first_of(" \t");
    const std::string key = lower(line.substr(0, sp));
    const std::string_view value = sp == std::string_view::npos ? std::string_view{} : trim(line.substr(sp));
    if (key == "end") {
        ended = true;
    } else if (key == "evt") {
        evt = std::string(value);
    } else if (key == "format") {
        // "EVT3;height=720;width=1280"
        std::string_view rest = value;
        bool first = true;
        while (!rest.empty()) {
            const auto semi = rest.find(';');
            const std::string_view item = trim(rest.substr(0, semi));
            rest = semi == std::string_view::npos ? std::string_view{} : rest.substr(semi + 1);
            const std::string l = lower(item);
            if (first) {
                if (l == "evt2") evt = "2.0";
                else if (l == "evt21") evt = "2.1";
                else if (l == "evt3") evt = "3.0";
                else evt = std::string(item);
                first = false;
            } else if (l.rfind("width=", 0) == 0) {
                width = to_side(item.substr(6));
            } else if (l.rfind("height=", 0) == 0) {
                height = to_side(item.substr(7));
            }
        }
    } else if (key == "geometry") {
        const auto x = value.find_first_of("xX");
        if (x != std::string_view::npos) {
            width = to_side(value.substr(0, x));
            height = to_side(value.substr(x + 1));
        }
    } else if (key == "width") {
        width = to_side(value);
    } else if (key == "height") {
        height = to_side(value);
    } else if (key == "plugin_name") {
        plugin_name = lower(value);
    } else if (key == "sensor_generation") {
        sensor_generation = std::string(value);
    } else if (key == "data") {
        is_dat = lower(value).rfind("file containing", 0) == 0;
    }
}

std::optional<SensorSize> PropheseeHeader::sensor() const {
    if (width && height) return SensorSize{*width, *height};
    const std::string& p = plugin_name;
    auto has = [&](std::string_view s) { return p.find(s) != std::string::npos; };
    if (has("gen41") || has("imx636") || has("gen4")) return SensorSize{1280, 720};
    if (has("gen31") || has("gen3")) return SensorSize{640, 480};
    if (has("genx320") || has("imx8")) return SensorSize{320, 320};
    if (sensor_generation == "4.1" || sensor_generation == "4.0" || sensor_generation == "4")
        return SensorSize{1280, 720};
    if (sensor_generation == "3.1")
        return SensorSize{640, 480};
    return std::nullopt;
}

}  // namespace evcorner::io
