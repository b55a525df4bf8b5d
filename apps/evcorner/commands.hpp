#pragma once
// The subcommands of the evcorner tool; each adds itself to the application.

#include <CLI/CLI.hpp>

namespace evcorner::cli {

void add_detect_command(CLI::App& app);

}  // namespace evcorner::cli
