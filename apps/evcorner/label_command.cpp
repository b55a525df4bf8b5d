// evcorner label: feature-track ground truth for a corner-event stream.
//
// Corner events in (any readable format, any detector's), one 0/1 label per corner
// event out, and the share on feature tracks (FT, Mueggler et al. BMVC 2017, Sec. 3.1.2).

#include <chrono>
#include <cstdio>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "commands.hpp"
#include "eval_common.hpp"
#include "evcorner/eval/feature_tracks.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/output_paths.hpp"
#include "progress.hpp"

namespace evcorner::cli {

namespace {

struct LabelOptions {
    std::string input;
    std::string output;
    std::string json;
    bool no_progress = false;
    InputOptions in;
    eval::FeatureTrackParams params;
    std::string overlap = "any";
};

void run_label(LabelOptions& o) {
    finish_feature_track_params(o.params, o.overlap);
    if (o.output == "-" && o.json == "-")
        throw std::invalid_argument("-o - and --json - would both write to standard output; send one to a file");
    io::check_output_paths({{"CORNERS", o.input}}, {{"-o", o.output}, {"--json", o.json}});
    io::check_outputs_creatable({{"-o", o.output}, {"--json", o.json}});
    // Progress bars on standard error while reading and while labelling (terminal only).
    const LoadedEvents corners = load_events(o.input, o.in, !o.no_progress);
    const auto t0 = std::chrono::steady_clock::now();
    eval::FeatureTrackResult r;
    {
        Progress bar(!o.no_progress, corners.events.size());
        r = eval::label_feature_tracks(corners.events, o.params,
                                       [&](std::size_t done, std::size_t) { bar.update(done, done); });
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!o.output.empty()) {
        io::OutputFile out(o.output);
        std::string text;
        text.reserve(2 * r.on_track.size());
        for (const std::uint8_t l : r.on_track) {
            text += l ? '1' : '0';
            text += '\n';
        }
        out.write(text);
        out.close();
    }
    // Standard output carries the labels or the JSON when either goes there; the
    // human summary then goes to standard error.
    std::FILE* summary = o.output == "-" || o.json == "-" ? stderr : stdout;
    fmt::print(summary, "FT {:.2f} % ({} of {} corner events on feature tracks)\n", r.ft_percent(), r.labelled,
               r.on_track.size());
    fmt::print(summary, "  {} hypotheses tried, {} accepted, {:.3f} s\n", r.hypotheses, r.accepted, secs);
    if (!o.json.empty()) {
        nlohmann::json j;
        j["input"] = o.input;
        j["corners"] = r.on_track.size();
        j["on_track"] = r.labelled;
        j["ft_percent"] = r.ft_percent();
        j["hypotheses"] = r.hypotheses;
        j["accepted"] = r.accepted;
        j["label_s"] = secs;
        io::OutputFile out(o.json);
        out.write(j.dump(2));
        out.write("\n");
        out.close();
    }
}

}  // namespace

void add_label_command(CLI::App& app) {
    auto o = std::make_shared<LabelOptions>();
    CLI::App* cmd = app.add_subcommand(
        "label",
        "Label corner events as on a feature track (1) or not (0) and print FT.\n"
        "The ground truth of Mueggler et al. (BMVC 2017, Sec. 3.1.2); FT is the share of corner\n"
        "events on tracks. Input: corner events of any detector in any format evcorner reads.");
    cmd->add_option("CORNERS", o->input, "Corner-event file, or - for standard input")->required();
    cmd->add_option("-o,--output", o->output, "Write one line per corner event: 1 on a track, 0 not (- = stdout)");
    cmd->add_option("--json", o->json,
                    "Also write the figures as JSON to this file (- = stdout; the summary then goes to stderr)");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bar (shown only when stderr is a terminal)");
    add_load_options(*cmd, o->in);
    add_feature_track_options(*cmd, o->params, o->overlap);
    cmd->footer(
        "Examples:\n"
        "  evcorner detect events.txt -o corners.txt && evcorner label corners.txt -o labels.txt\n"
        "  evcorner detect events.txt -d harris -q | evcorner label - --ft-per-polarity");
    cmd->callback([o] { run_label(*o); });
}

}  // namespace evcorner::cli
