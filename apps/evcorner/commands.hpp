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
void add_track_command(CLI::App& app);
void add_eval_tracks_command(CLI::App& app);

/// --format (the format table's names and aliases, io/formats.hpp) and every reader
/// option of the table (io::reader_option_infos(): --csv-columns, --time-unit, --npy-columns,
/// --chip, --mat-var, --mat-columns, --topic), bound to `reader`, in the "Input" group: the
/// one place a command gets them. The options of the table a format does not take are
/// refused when the file is opened (io::check_reader_options).
void add_reader_options(CLI::App& cmd, std::string& format, io::ReaderOptions& reader);
/// --to: the output format (detect, convert); an unknown name is a usage error.
void add_output_format_option(CLI::App& cmd, std::string& to);

}  // namespace evcorner::cli
