// evcorner track: events in, feature tracks out.
//
// A front for the library's tracking pipeline (pipeline/track.hpp): options in, the
// summary out. Data flows one way there: reader -> [detector ->] tracker -> track file.

#include <cmath>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "detector_options.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/pipeline/track.hpp"
#include "evcorner/track/tracker.hpp"

namespace evcorner::cli {

namespace {

struct TrackCommand {
    pipeline::TrackFiles files;
    pipeline::TrackOptions run;
    std::string seeds;
    std::string detector;
    std::string init = "centered";
    std::string tracks_format;
    std::string size;
    std::string summary_json;
    ParamValues params;
    bool nms = false;
    NmsParams nms_params;
    std::string nms_rule = "window";
    double max_idle_ms = -1;
    double min_separation = -1;
    bool quiet = false;
};

void print_summary(const TrackCommand& o, const pipeline::TrackSummary& t) {
    fmt::print(stderr, "evcorner track: {}\n", o.files.input == "-" ? "<stdin>" : o.files.input);
    const std::string start = tracker_entry(t.tracker).takes_init ? " (" + o.init + " start)" : std::string();
    fmt::print(stderr, "  tracker      {}{} on a {}x{} sensor\n", t.tracker, start, t.sensor.width, t.sensor.height);
    if (!t.detector.empty())
        fmt::print(stderr, "  seeds        corners of {}{}: {} corner events\n", t.detector, o.nms ? " after NMS" : "",
                   t.corners);
    else
        fmt::print(stderr, "  seeds        {} from {}\n", o.run.config.seeds.size(), o.seeds);
    fmt::print(stderr, "  events       {}\n", t.events);
    fmt::print(stderr, "  tracks       {} started, {} initialised, {} seeds skipped, {} running at the end\n",
               t.stats.started, t.stats.initialised, t.stats.skipped_seeds, t.stats.live);
    fmt::print(stderr, "  states       {} written to {}\n", t.states, o.files.output == "-" ? "<stdout>" : o.files.output);
    if (t.stats.updates > 0)
        fmt::print(stderr, "  tracking     {:.1f} ns per in-range event and track ({} of them), {:.1f} ns per event\n",
                   t.ns_per_update(), t.stats.updates, t.ns_per_event());
    fmt::print(stderr, "  wall time    {:.3f} s\n", t.wall_s);
}

void write_summary_json(const TrackCommand& o, const pipeline::TrackSummary& t) {
    const auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    nlohmann::json j = {{"input", o.files.input},
                        {"tracker", t.tracker},
                        {"init", o.init},
                        {"detector", t.detector.empty() ? nlohmann::json(nullptr) : nlohmann::json(t.detector)},
                        {"width", t.sensor.width},
                        {"height", t.sensor.height},
                        {"events", t.events},
                        {"corners", t.corners},
                        {"states", t.states},
                        {"tracks_started", t.stats.started},
                        {"tracks_initialised", t.stats.initialised},
                        {"seeds_skipped", t.stats.skipped_seeds},
                        {"updates", t.stats.updates},
                        {"ns_per_update", num(t.ns_per_update())},
                        {"ns_per_event", num(t.ns_per_event())},
                        {"track_s", t.track_s},
                        {"wall_s", t.wall_s}};
    io::OutputFile out(o.summary_json);
    out.write(j.dump(2));
    out.write("\n");
    out.close();
}

void run_track(TrackCommand& o) {
    io::check_output_paths({{"EVENTS", o.files.input}}, {{"-o", o.files.output}, {"--summary-json", o.summary_json}});
    io::check_outputs_creatable({{"-o", o.files.output}, {"--summary-json", o.summary_json}});
    if (o.seeds.empty() == o.detector.empty())
        throw CLI::ValidationError("--seeds/-d", "give exactly one of --seeds FILE and -d DETECTOR");
    if (!o.size.empty()) o.files.reader.sensor = parse_sensor_size(o.size);  // validated by CLI11
    if (!o.tracks_format.empty()) o.files.tracks_format = parse_track_format(o.tracks_format);  // validated
    TrackerConfig& c = o.run.config;
    c.init = o.init == "centered" ? HasteInit::centered : HasteInit::uncentered;
    if (!o.seeds.empty()) {
        c.seeds = read_seeds_file(o.seeds);
        if (c.seeds.empty()) throw CLI::ValidationError("--seeds", o.seeds + " holds no seed");
    } else {
        pipeline::DetectOptions d;
        d.detector.name = o.detector;
        d.detector.params = o.params;
        d.param_prefix = "--";
        if (o.nms) {
            o.nms_params.rule = parse_nms_rule(o.nms_rule);
            d.nms = o.nms_params;
        }
        o.run.detect = d;
        // A front end's stopping rules (docs/tracking.md); HASTE alone has none.
        c.stop.max_idle_us = 200000;
        c.stop.min_separation = 3;
    }
    if (o.max_idle_ms >= 0) c.stop.max_idle_us = static_cast<std::int64_t>(std::llround(o.max_idle_ms * 1000));
    if (o.min_separation >= 0) c.stop.min_separation = o.min_separation;
    const pipeline::TrackSummary t = pipeline::track_file(o.files, o.run);
    if (!o.quiet) print_summary(o, t);
    if (!o.summary_json.empty()) write_summary_json(o, t);
}

std::string trackers_help() {
    std::string s;
    for (const TrackerEntry& t : tracker_registry()) s += fmt::format("\n  {:<24}{}", t.name, t.summary);
    return s;
}

}  // namespace

void add_track_command(CLI::App& app) {
    auto o = std::make_shared<TrackCommand>();
    CLI::App* cmd = app.add_subcommand(
        "track",
        "Track features through an event stream and write their tracks.\n"
        "Tracks start at the seeds of a file (--seeds: HASTE's 't,x,y,theta[,id]' tokens, t in\n"
        "seconds, theta in radians, pixel-index coordinates) or at the corner events of a\n"
        "detector (-d: a corner farther than --seed-radius from every track starts one). Output:\n"
        "one row per track state (initialised, moved, stopped). A summary goes to standard error.\n"
        "HASTE trackers after Alzugaray & Chli (3DV 2019, BMVC 2020); reference implementation\n"
        "ialzugaray/haste, MIT licence, (c) 2021 Vision for Robotics Lab, ETH Zurich.");
    cmd->add_option("EVENTS", o->files.input, "Event file, or - for standard input")->required();
    cmd->add_option("--tracker", o->run.tracker, "Tracker:" + trackers_help())
        ->capture_default_str()
        ->check([](const std::string& s) {
            try {
                (void)tracker_entry(s);
                return std::string();
            } catch (const std::exception& e) {
                return std::string(e.what());
            }
        });
    cmd->add_option("--seeds", o->seeds, "Seeds file: whitespace-separated 't,x,y,theta[,id]' tokens (HASTE's layout), or a track file "
                    "of 'id t x y' rows (such as simulate --gt-tracks): each track's first row seeds it");
    add_detector_option(*cmd, o->detector, "Seed tracks from this detector's corner events:" + detectors_help());
    cmd->add_option("--init", o->init,
                    "How a track's first window of 193 events is filled: centered (96 before the seed, 97 from it; "
                    "the authors' default) or uncentered (193 from the seed on)")
        ->capture_default_str()
        ->check(CLI::IsMember({"centered", "uncentered"}));
    cmd->add_option("--tracks-format", o->tracks_format,
                    "ddft ('id t x y' rows; the default, and for .txt), haste ('t,x,y,theta,id', 6 decimals), csv "
                    "(header id,t,x,y,theta,change; the default for .csv), npy (the default for .npy)")
        ->check(CLI::IsMember({"ddft", "haste", "csv", "npy"}));
    cmd->add_option("-o,--output", o->files.output, "Track file (- = standard output)")->capture_default_str();
    cmd->add_option("--seed-radius", o->run.config.seed_radius,
                    "With -d: a corner event closer than this to a track (running or starting) starts none, px")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1e4));
    cmd->add_option("--max-tracks", o->run.config.max_tracks,
                    "With -d: at most this many tracks at once; corners beyond it start none")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000000));
    cmd->add_option("--max-idle", o->max_idle_ms,
                    "A track with no state change for this long stops, ms; 0 = never [default: 200 with -d, 0 with "
                    "--seeds]")
        ->check(CLI::Range(0.0, 1e9));
    cmd->add_option("--min-separation", o->min_separation,
                    "When two tracks come closer than this, the younger stops, px; 0 = never [default: 3 with -d, 0 "
                    "with --seeds]")
        ->check(CLI::Range(0.0, 1e4));
    add_nms_options(*cmd, o->nms, o->nms_params, o->nms_rule);
    add_param_options(*cmd, o->params);
    add_reader_options(*cmd, o->files.format, o->files.reader);
    cmd->add_option("--size", o->size, "Sensor size WxH [default: the file's own size, else 240x180]")
        ->check([](const std::string& s) {
            return parse_sensor_size(s) ? std::string() : "expected WxH with sides 1..65536, e.g. 346x260";
        });
    cmd->add_option("--summary-json", o->summary_json,
                    "Also write the summary as JSON (keys include states, tracks_started, updates, ns_per_update)");
    cmd->add_flag("-q,--quiet", o->quiet, "No summary");
    cmd->footer(
        "Examples:\n"
        "  evcorner track events.txt --tracker haste-correlation-star -d arcstar -o tracks.txt\n"
        "  evcorner track events.txt --tracker haste-difference-star --seeds seeds.txt --init uncentered "
        "--tracks-format haste -o tracks.txt\n"
        "Tracks are evaluated against ground truth with 'evcorner eval-tracks' (docs/tracking.md).");
    cmd->callback([o] { run_track(*o); });
}

}  // namespace evcorner::cli
