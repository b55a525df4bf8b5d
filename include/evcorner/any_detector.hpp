#pragma once
// Picking a detector at run time: a std::variant of the concrete detectors, visited
// once outside the per-event loop so that the loop itself is statically dispatched.

#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "evcorner/efast.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/harris_global.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

using AnyDetector = std::variant<EFast, Harris, HarrisGlobal>;

struct DetectorInfo {
    std::string_view name;     ///< the name used on the command line
    std::string_view summary;  ///< one line for --help
};

/// Every detector evcorner can run, in the order --help lists them.
std::span<const DetectorInfo> detector_infos() noexcept;

/// Parameters of the detectors that have any; each detector reads its own.
struct DetectorParams {
    HarrisParams harris;
    HarrisGlobalParams harris_global;
};

/// Builds the detector called `name`; throws std::invalid_argument for an unknown name
/// or a parameter out of range.
AnyDetector make_detector(std::string_view name, SensorSize size, const DetectorParams& params = {});

/// Whether the detector reports a score (ScoredDetector).
bool has_score(const AnyDetector& d) noexcept;

/// Bytes of state the detector holds.
std::size_t memory_bytes(const AnyDetector& d) noexcept;

}  // namespace evcorner
