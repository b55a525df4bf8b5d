#pragma once
// The subcommands of the evcorner tool; each adds itself to the application.

#include <CLI/CLI.hpp>
#include <string>

namespace evcorner::cli {

void add_detect_command(CLI::App& app);
void add_info_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_label_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_simulate_command(CLI::App& app);

/// The input-format options every command shares (--format, --csv-columns, --time-unit, --chip).
void add_input_options(CLI::App& cmd, std::string& format, std::string& csv_columns, std::string& time_unit,
                       std::string& chip);
/// --to: the output format (detect, convert); an unknown name is a usage error.
void add_output_format_option(CLI::App& cmd, std::string& to);

}  // namespace evcorner::cli
