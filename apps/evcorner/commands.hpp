#pragma once
// The subcommands of the evcorner tool; each adds itself to the application.

#include <CLI/CLI.hpp>
#include <string>

#include "evcorner/io/event_reader.hpp"

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
/// --topic: the topic of a ROS bag to read (ReaderOptions::topic).
void add_topic_option(CLI::App& cmd, std::string& topic);
/// The options of the formats added with issue 16 (.npy columns, MATLAB variable and
/// columns), kept together so that each command adds and applies them in one line each.
struct MoreInputOptions {
    std::string npy_columns, mat_var, mat_columns;
    void apply(io::ReaderOptions& r) const {
        r.npy_columns = npy_columns;
        r.mat_var = mat_var;
        r.mat_columns = mat_columns;
    }
};
/// --npy-columns, --mat-var, --mat-columns.
void add_more_input_options(CLI::App& cmd, MoreInputOptions& o);
/// --to: the output format (detect, convert); an unknown name is a usage error.
void add_output_format_option(CLI::App& cmd, std::string& to);

}  // namespace evcorner::cli
