#include "evcorner/any_detector.hpp"

#include <array>
#include <stdexcept>

namespace evcorner {

namespace {
constexpr std::array kInfos{
    DetectorInfo{"efast", "eFAST (Mueggler et al., BMVC 2017): arcs on the SAE circles of radius 3 and 4"},
};
}  // namespace

std::span<const DetectorInfo> detector_infos() noexcept { return kInfos; }

AnyDetector make_detector(std::string_view name, SensorSize size) {
    if (name == "efast") return EFast(size);
    std::string known;
    for (const auto& i : kInfos) known += (known.empty() ? "" : ", ") + std::string(i.name);
    throw std::invalid_argument("unknown detector '" + std::string(name) + "' (known: " + known + ")");
}

std::size_t memory_bytes(const AnyDetector& d) noexcept {
    return std::visit([](const auto& det) { return det.memory_bytes(); }, d);
}

}  // namespace evcorner
