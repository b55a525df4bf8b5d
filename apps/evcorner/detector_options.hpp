#pragma once
// The detector options every command that runs detectors shares, generated from the
// registry (registry.hpp): -d with the list of detectors in its help, one --KEY option per
// distinct parameter key (--harris-window, ...) and -p/--param KEY=VALUE.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "evcorner/detector_config.hpp"
#include "evcorner/nms.hpp"

namespace evcorner::cli {

/// "\n  efast          eFAST (...)\n  harris ..." with each detector's parameters.
std::string detectors_help();

/// -d/--detector NAME, checked against the registry.
CLI::Option* add_detector_option(CLI::App& cmd, std::string& name, const std::string& help);

/// One --KEY option per parameter key of the registry, and -p/--param KEY=VALUE; the values
/// given land in `values` (each key at most once). In the "Detector parameters" group.
void add_param_options(CLI::App& cmd, ParamValues& values);

/// A comma-separated list of detector names ("all": every registered detector, in the
/// registry's order); throws std::invalid_argument for an unknown name or an empty list.
std::vector<std::string> parse_detector_list(const std::string& list);

/// "efast,harris,harris-global": every registered detector.
std::string all_detectors_list();

/// --nms (sets `on`), --nms-rule window|decay, --nms-radius PX, --nms-time US (nms.hpp), in
/// the "Non-maximum suppression" group.
/// `enabler`: another flag that turns NMS on too (eval's --compare-nms); the --nms-*
/// options are a usage error without --nms or it.
void add_nms_options(CLI::App& cmd, bool& on, NmsParams& params, std::string& rule, CLI::Option* enabler = nullptr);

}  // namespace evcorner::cli
