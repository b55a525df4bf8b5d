#include "evcorner/any_detector.hpp"

#include <array>
#include <stdexcept>
#include <type_traits>

#include "evcorner/scored_detector.hpp"

namespace evcorner {

namespace {
constexpr std::array kInfos{
    DetectorInfo{"efast", "eFAST (Mueggler et al., BMVC 2017): arcs on the SAE circles of radius 3 and 4"},
    DetectorInfo{"harris", "spatially-adaptive Harris (Mueggler et al., BMVC 2017, Sec. 3.2): newest Nl pixels of the window"},
    DetectorInfo{"harris-global", "event-based Harris (Vasco et al., IROS 2016): newest N pixels of the sensor"},
};
}  // namespace

std::span<const DetectorInfo> detector_infos() noexcept { return kInfos; }

namespace {
[[noreturn]] void unknown_detector(std::string_view name) {
    std::string known;
    for (const auto& i : kInfos) known += (known.empty() ? "" : ", ") + std::string(i.name);
    throw std::invalid_argument("unknown detector '" + std::string(name) + "' (known: " + known + ")");
}
}  // namespace

std::uint64_t detector_state_bytes(std::string_view name, SensorSize size, const DetectorParams& params) {
    if (name == "efast") return EFast::state_bytes(size);
    if (name == "harris") return Harris::state_bytes(size, params.harris);
    if (name == "harris-global") return HarrisGlobal::state_bytes(size, params.harris_global);
    unknown_detector(name);
}

AnyDetector make_detector(std::string_view name, SensorSize size, const DetectorParams& params) {
    const std::uint64_t need = detector_state_bytes(name, size, params);  // unknown names throw here
    checked_sensor_size(size, std::string(name).c_str());
    require_state_fits(name, size, need, available_memory_bytes());
    if (name == "efast") return EFast(size);
    if (name == "harris") return Harris(size, params.harris);
    return HarrisGlobal(size, params.harris_global);
}

std::size_t detect(AnyDetector& d, std::span<const Event> events, std::span<std::uint8_t> is_corner) {
    return std::visit([&](auto& det) { return detect(det, events, is_corner); }, d);
}

std::size_t detect_unchecked(AnyDetector& d, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return std::visit([&](auto& det) { return detect_unchecked(det, events, is_corner); }, d);
}

bool has_score(const AnyDetector& d) noexcept {
    return std::visit([](const auto& det) { return ScoredDetector<std::decay_t<decltype(det)>>; }, d);
}

std::size_t memory_bytes(const AnyDetector& d) noexcept {
    return std::visit([](const auto& det) { return det.memory_bytes(); }, d);
}

}  // namespace evcorner
