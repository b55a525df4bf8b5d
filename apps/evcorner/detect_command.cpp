// evcorner detect: events in, corner events out.
//
// A front for the library's detection pipeline (pipeline/detect.hpp): options in, the
// summary out. Data flows one way there: reader -> detector -> writers.

#include <chrono>
#include <cstdio>
#include <exception>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "detector_options.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/pipeline/detect.hpp"
#include "evcorner/registry.hpp"
#include "progress.hpp"

namespace evcorner::cli {

namespace {

struct DetectOptions {
    pipeline::DetectFiles files;
    pipeline::DetectOptions run;
    std::string size;
    std::string summary_json;
    bool skip_invalid = false;
    bool nms = false;
    NmsParams nms_params;
    std::string nms_rule = "window";
    bool quiet = false;
    bool no_progress = false;
};

void print_summary(const DetectOptions& o, const pipeline::DetectSummary& t) {
    const double events = static_cast<double>(t.events);
    fmt::print(stderr, "evcorner detect: {}\n", o.files.input == "-" ? "<stdin>" : o.files.input);
    std::string params;
    for (const auto& [key, value] : o.run.detector.params) params += fmt::format(" {}={}", key, format_param_value(value));
    fmt::print(stderr, "  detector     {}{} on a {}x{} sensor\n", t.detector, params, t.sensor.width, t.sensor.height);
    fmt::print(stderr, "  events       {}\n", t.events);
    if (t.skipped > 0) fmt::print(stderr, "  skipped      {} (outside the sensor)\n", t.skipped);
    if (o.run.nms)
        fmt::print(stderr, "  nms          rule {}, radius {} px, {} {} us (the corners below are the kept ones)\n",
                   nms_rule_name(o.run.nms->rule), o.run.nms->radius,
                   o.run.nms->rule == NmsRule::window ? "window" : "decay", o.run.nms->time_us);
    fmt::print(stderr, "  corners      {}\n", t.corners);
    if (t.events > 0) {
        fmt::print(stderr, "  reduction    {:.2f} % of events removed\n", t.reduction_percent());
        if (t.threads > 1)
            fmt::print(stderr,
                       "  detection    {:.1f} ns/event ({} threads; {:.2f} M events/s; the rounds overlap "
                       "reading and writing)\n",
                       t.ns_per_event(), t.threads, events / t.detect_s / 1e6);
        else
            fmt::print(stderr, "  detection    {:.1f} ns/event (detector alone; {:.2f} M events/s)\n",
                       t.ns_per_event(), events / t.detect_s / 1e6);
    }
    if (!t.damaged.empty()) fmt::print(stderr, "  damaged      input ends at: {}\n", t.damaged);
    fmt::print(stderr, "  wall time    {:.3f} s ({:.2f} M events/s end to end)\n", t.wall_s,
               t.wall_s > 0 ? events / t.wall_s / 1e6 : 0.0);
}

void write_summary_json(const DetectOptions& o, const pipeline::DetectSummary& t) {
    nlohmann::json j;
    j["input"] = o.files.input;
    j["detector"] = t.detector;
    // The parameters given (the others are the detector's defaults).
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [key, value] : o.run.detector.params)
        std::visit([&](const auto& v) { params[key] = v; }, value);
    j["params"] = params;
    j["width"] = t.sensor.width;
    j["height"] = t.sensor.height;
    j["events"] = t.events;
    j["corners"] = t.corners;
    j["skipped"] = t.skipped;
    if (t.events > 0) {
        j["reduction_rate"] = t.reduction_percent();
        j["ns_per_event"] = t.ns_per_event();
    } else {
        j["reduction_rate"] = nullptr;
        j["ns_per_event"] = nullptr;
    }
    j["threads"] = t.threads;
    if (o.run.nms)
        j["nms"] = {{"rule", nms_rule_name(o.run.nms->rule)}, {"radius", o.run.nms->radius}, {"time_us", o.run.nms->time_us}};
    else
        j["nms"] = nullptr;
    j["detect_s"] = t.detect_s;
    j["wall_s"] = t.wall_s;
    if (t.damaged.empty())
        j["damaged"] = nullptr;
    else
        j["damaged"] = t.damaged;
    io::OutputFile out(o.summary_json);
    out.write(j.dump(2));
    out.write("\n");
    out.close();
}

void run_detect(DetectOptions& o) {
    // Before anything is opened: outputs onto the input or onto each other.
    io::check_output_paths({{"INPUT", o.files.input}},
                           {{"-o", o.files.output}, {"--mask", o.files.mask}, {"--summary-json", o.summary_json}});
    io::check_outputs_creatable({{"-o", o.files.output}, {"--mask", o.files.mask}, {"--summary-json", o.summary_json}});
    io::ReaderOptions& ropts = o.files.reader;
    ropts.skip_invalid = o.skip_invalid;
    if (!o.size.empty()) ropts.sensor = parse_sensor_size(o.size);  // validated by CLI11
    o.run.param_prefix = "--";
    if (o.nms) {
        o.nms_params.rule = parse_nms_rule(o.nms_rule);  // validated by CLI11
        o.run.nms = o.nms_params;
    }

    // The bar is drawn only on a terminal; the last update also tells how far a run that
    // stops at an input error got.
    std::optional<Progress> progress;
    pipeline::DetectProgress last;
    const pipeline::ProgressFn on_batch = [&](const pipeline::DetectProgress& p) {
        if (!progress) progress.emplace(!o.quiet && !o.no_progress, p.bytes_total);
        progress->update(p.bytes_consumed, p.events);
        last = p;
    };
    pipeline::DetectSummary t;
    try {
        t = pipeline::detect_file(o.files, o.run, on_batch);
    } catch (const InputError&) {
        // Output files are left absent; streams (standard output, FIFOs) keep what they got.
        if (progress) progress->finish();
        std::string files;
        for (const std::string* p : {&o.files.output, &o.files.mask, &o.summary_json})
            if (io::output_is_file(*p)) files += (files.empty() ? "" : ", ") + *p;
        if (!files.empty())
            fmt::print(stderr, "evcorner: {} not written (--allow-damaged keeps the result of the {} events before "
                               "the error)\n", files, last.events);
        if (!o.files.output.empty() && !io::output_is_file(o.files.output) && last.events > 0)
            fmt::print(stderr, "evcorner: the {} corners of the {} events before the error went to {}\n",
                       last.corners, last.events, o.files.output == "-" ? "standard output" : o.files.output);
        throw;
    }
    if (progress) progress->finish();
    // --allow-damaged: the valid part before the damage is the result.
    if (!t.damaged.empty())
        fmt::print(stderr, "evcorner: warning: {}; the {} events before it were processed\n", t.damaged, t.events);
    if (!o.quiet) print_summary(o, t);
    if (!o.summary_json.empty()) write_summary_json(o, t);
}

}  // namespace

void add_detect_command(CLI::App& app) {
    auto o = std::make_shared<DetectOptions>();
    std::string scored, local;
    for (const DetectorInfo& d : detector_infos()) {
        if (d.has_score) scored += (scored.empty() ? "" : ", ") + std::string(d.name);
        if (d.local()) local += (local.empty() ? "" : ", ") + std::string(d.name);
    }

    CLI::App* cmd = app.add_subcommand(
        "detect",
        "Detect corner events in an event stream and write them out.\n"
        "Input: any format evcorner reads (see --format), told by the content; '-' reads\n"
        "standard input. Event-Camera-Dataset text is 't x y p' per line, t in seconds,\n"
        "p = 1 ON / 0 OFF. Output: the corner events, as such text lines unless OUTPUT's\n"
        "extension or --to names another format. A summary (events, corners, reduction rate,\n"
        "detection time per event, wall time) goes to standard error.");
    cmd->add_option("INPUT", o->files.input, "Event file, or - for standard input")->required();
    o->run.detector.name = "efast";
    add_detector_option(*cmd, o->run.detector.name,
                        "Detector to run (its parameters: \"Detector parameters\" below, or -p KEY=VALUE):" +
                            detectors_help());
    cmd->add_option("-o,--output", o->files.output,
                    "Corner events (- = standard output, as 't x y p' lines); the format follows the "
                    "extension (.txt, .csv, .npy, .aedat4, .h5, .hdf5; others are refused; none = text). "
                    "AEDAT 4.0 and HDF5 record the sensor size the detector ran on")
        ->capture_default_str();
    add_output_format_option(*cmd, o->files.to);
    add_reader_options(*cmd, o->files.format, o->files.reader);
    cmd->add_option("--size", o->size,
                    "Sensor size WxH; events outside it are errors [default: the file's own "
                    "size, else 240x180, the DAVIS240C of the Event-Camera Dataset]")
        ->check([](const std::string& s) {
            return parse_sensor_size(s) ? std::string()
                                        : "expected WxH with sides 1..65536, e.g. 346x260";
        });
    cmd->add_option("--mask", o->files.mask,
                    "Also write one line per input event: 1 = corner, 0 = not (skipped events: 0)");
    cmd->add_option("--summary-json", o->summary_json,
                    "Also write the summary as JSON (keys include events, corners, "
                    "reduction_rate [%], ns_per_event). No two outputs may share a file or both be - "
                    "(standard output), and none may be the input");
    cmd->add_flag("--with-score", o->run.with_score,
                  "Write each corner's score with it: text 't x y p score', CSV and .npy a score column, HDF5 "
                  "events/score (not AEDAT 4.0); label, render and the readers read it back. Detectors "
                  "with a score: " + scored);
    add_nms_options(*cmd, o->nms, o->nms_params, o->nms_rule);
    add_param_options(*cmd, o->run.detector.params);
    cmd->add_option("-j,--threads", o->run.threads,
                    "Detection threads (local detectors: " + local +
                        "): the sensor splits into bands of rows (per polarity where the detector allows), "
                        "each with a halo of the detector's radius, handed out to the threads batch by batch; "
                        "reading and writing overlap detection; output identical to one thread, same order")
        ->capture_default_str()
        ->check(CLI::Range(1, 256));
    cmd->add_flag("--allow-damaged", o->run.allow_damaged,
                  "A malformed line or a damaged or cut-short file ends the input with a warning "
                  "and exit status 0, instead of an error: the events before it are the result");
    cmd->add_flag("--skip-invalid", o->skip_invalid,
                  "Skip events outside the sensor (counted in the summary) instead of failing");
    cmd->add_flag("-q,--quiet", o->quiet, "No summary and no progress bar");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bar (it shows only on a terminal)");
    static constexpr struct {
        const char* group;
        const char* options;
    } kGroups[] = {{"Input",
                    "--format --csv-columns --time-unit --chip --topic --npy-columns --mat-var --mat-columns --size "
                    "--skip-invalid --allow-damaged"},
                   {"Output", "--output --to --mask --summary-json --with-score --quiet --no-progress"},
                   {"Detector", "--detector --threads"}};
    for (const auto& g : kGroups) {
        std::istringstream names(g.options);
        for (std::string name; names >> name;) cmd->get_option(name)->group(g.group);
    }
    cmd->footer(
        "Examples:\n"
        "  evcorner detect events.txt -o corners.txt\n"
        "  evcorner detect recording.raw -o corners.npy      # Prophesee EVT 3 in, numpy out\n"
        "  evcorner detect events.txt --mask is_corner.txt --summary-json summary.json > corners.txt\n"
        "  evcorner detect events.txt -d harris --with-score | head\n"
        "  evcorner detect events.txt --nms --nms-radius 2 --nms-time 2000 -o corners.txt\n"
        "  evcorner detect events.txt -d harris-global --harris-n 2000\n"
        "  evcorner detect events.txt -d harris -p harris-window=11 -p harris-nl=40\n"
        "  evcorner detect hd_recording.raw --threads 2 -o corners.npy\n"
        "  cat events.txt | evcorner detect - --size 346x260 | head");
    cmd->callback([o] { run_detect(*o); });
}

}  // namespace evcorner::cli
