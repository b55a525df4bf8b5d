// evcorner label: feature-track ground truth for a corner-event stream.
//
// Corner events in (any readable format, any detector's), one 0/1 label per corner
// event out, and the share on feature tracks (FT, Mueggler et al. BMVC 2017, Sec. 3.1.2).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <span>
#include <string>
#include <vector>

#include "commands.hpp"
#include "eval_common.hpp"
#include "evcorner/error.hpp"
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
    // The corner events stream through the labeller batch by batch; each label is written
    // once final, so memory is bounded by one max-duration window, not by the file.
    const auto reader = open_events(o.input, o.in);
    std::unique_ptr<io::OutputFile> out;
    if (!o.output.empty()) out = std::make_unique<io::OutputFile>(o.output);
    eval::FeatureTrackStream stream(o.params);
    auto write = [&](std::span<const std::uint8_t> labels) {
        if (!out) return;
        for (std::size_t at = 0; at < labels.size(); at += 32768) {
            const std::size_t k = std::min<std::size_t>(32768, labels.size() - at);
            char* p = out->reserve(2 * k);
            for (const std::uint8_t l : labels.subspan(at, k)) {
                *p++ = l ? '1' : '0';
                *p++ = '\n';
            }
            out->commit(2 * k);
        }
    };
    double secs = 0;  // labelling only, not reading or writing
    auto timed = [&](auto&& step) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::span<const std::uint8_t> labels = step();
        secs += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        write(labels);
    };
    {
        Progress bar(!o.no_progress, reader->bytes_total());
        std::vector<Event> batch(std::size_t{1} << 16);
        for (;;) {
            const std::size_t n = reader->read(batch);
            if (n == 0 && reader->skipped_in_batch().empty()) break;
            const std::span<const Event> got(batch.data(), n);
            try {
                timed([&] { return stream.push(got); });
            } catch (const std::invalid_argument& e) {
                // Out of time order: name the file (the message names the event).
                std::string why = e.what();
                const std::string prefix = "feature tracks: ";
                if (why.starts_with(prefix)) why.erase(0, prefix.size());
                throw InputError(reader->name(), why + " (label streams; sort the corner events by time first)");
            }
            bar.update(reader->bytes_consumed(), stream.corners());
        }
        timed([&] { return stream.finish(); });
    }
    if (out) out->close();
    eval::FeatureTrackResult r;  // the figures (the labels went out as they came)
    r.labelled = stream.labelled();
    r.hypotheses = stream.hypotheses();
    r.accepted = stream.accepted();
    const std::uint64_t corners = stream.corners();
    const double ft = corners == 0 ? 0.0 : 100.0 * static_cast<double>(r.labelled) / static_cast<double>(corners);
    // Standard output carries the labels or the JSON when either goes there; the
    // human summary then goes to standard error.
    std::FILE* summary = o.output == "-" || o.json == "-" ? stderr : stdout;
    fmt::print(summary, "FT {:.2f} % ({} of {} corner events on feature tracks)\n", ft, r.labelled, corners);
    fmt::print(summary, "  {} hypotheses tried, {} accepted, {:.3f} s\n", r.hypotheses, r.accepted, secs);
    if (!o.json.empty()) {
        nlohmann::json j;
        j["input"] = o.input;
        j["corners"] = corners;
        j["on_track"] = r.labelled;
        j["ft_percent"] = ft;
        j["hypotheses"] = r.hypotheses;
        j["accepted"] = r.accepted;
        j["label_s"] = secs;
        io::OutputFile json(o.json);
        json.write(j.dump(2));
        json.write("\n");
        json.close();
    }
}

}  // namespace

void add_label_command(CLI::App& app) {
    auto o = std::make_shared<LabelOptions>();
    CLI::App* cmd = app.add_subcommand(
        "label",
        "Label corner events as on a feature track (1) or not (0) and print FT.\n"
        "The ground truth of Mueggler et al. (BMVC 2017, Sec. 3.1.2); FT is the share of corner\n"
        "events on tracks. Input: corner events of any detector in any format evcorner reads, in\n"
        "time order (as detectors write them): labelling streams, its memory does not grow with the\n"
        "file, and an event earlier than the one before it is an error.");
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
