#pragma once
// Built-in scenes: `evcorner simulate --preset NAME`, and the fixed benchmark suite
// (`--suite DIR`). Each is scene-file JSON (docs/simulate.md), generated here from fixed
// seeds, so a name always means the same scene.

#include <string>
#include <string_view>
#include <vector>

namespace evcorner::sim {

struct PresetInfo {
    std::string name;
    std::string summary;
    bool in_suite;  ///< part of the benchmark suite
};

/// Every built-in scene, the suite's in suite order.
const std::vector<PresetInfo>& presets();

/// The scene file text of preset `name`; throws std::invalid_argument naming the known ones.
std::string preset_scene_json(std::string_view name);

}  // namespace evcorner::sim
