#pragma once
// Picking a detector at run time: a std::variant of the concrete detectors, visited
// once outside the per-event loop so that the loop itself is statically dispatched.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "evcorner/efast.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/harris_global.hpp"
#include "evcorner/sensor.hpp"
#include "evcorner/state_memory.hpp"

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

/// Bytes of state the detector called `name` needs over `size` (its static
/// state_bytes()); throws std::invalid_argument for an unknown name.
std::uint64_t detector_state_bytes(std::string_view name, SensorSize size, const DetectorParams& params = {});

/// Builds the detector called `name`; throws std::invalid_argument for an unknown name,
/// a parameter out of range or a sensor side outside 1..kMaxSensorSide, and, before
/// allocating, StateTooLarge (state_memory.hpp) when its state needs more memory than
/// available_memory_bytes() (e.g. "a 65536x65536 sensor needs 68.7 GB for efast's state
/// (16 B per pixel); 21.3 GB is available").
AnyDetector make_detector(std::string_view name, SensorSize size, const DetectorParams& params = {});

/// detect() on whichever detector `d` holds (checked; see detector.hpp).
std::size_t detect(AnyDetector& d, std::span<const Event> events, std::span<std::uint8_t> is_corner);
/// detect_unchecked() on whichever detector `d` holds.
std::size_t detect_unchecked(AnyDetector& d, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept;

/// Whether the detector reports a score (ScoredDetector).
bool has_score(const AnyDetector& d) noexcept;

/// Bytes of state the detector holds.
std::size_t memory_bytes(const AnyDetector& d) noexcept;

}  // namespace evcorner
