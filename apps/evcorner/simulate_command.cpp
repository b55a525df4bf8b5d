// evcorner simulate: a scene of moving shapes in, events and their corners' ground truth out.
//
// Data flows one way: simulator -> event writer, with the truth sampled alongside at fixed
// times. Everything streams: memory does not grow with the scene's duration.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.hpp"
#include "evcorner/error.hpp"
#include "evcorner/io/event_writer.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/sim/gt_tracks.hpp"
#include "evcorner/sim/presets.hpp"
#include "evcorner/sim/scene.hpp"
#include "evcorner/sim/simulator.hpp"
#include "evcorner/sim/truth.hpp"
#include "evcorner/track/track_writer.hpp"
#include "progress.hpp"

namespace evcorner::cli {

namespace {

using Clock = std::chrono::steady_clock;
constexpr std::size_t kBatch = 1 << 16;

struct SimulateOptions {
    std::string scene;
    std::string preset;
    std::string suite;
    std::string output;
    std::string to = "auto";
    std::string truth;
    std::int64_t truth_every_us = 100;
    std::string gt_tracks;
    double gt_rate_hz = 100;
    bool print_scene = false;
    bool quiet = false;
    bool no_progress = false;
};

struct RunTotals {
    sim::SimStats stats;
    std::uint64_t events = 0;
    std::uint64_t truth_rows = 0;
    std::uint64_t gt_rows = 0, gt_tracks = 0;
    double wall_s = 0;
};

// What a run writes besides the events: the truth CSV and the GT tracks (each when named).
struct TruthOutputs {
    std::string truth;
    std::int64_t truth_every_us = 100;
    std::string gt_tracks;
    double gt_rate_hz = 100;
};

// Simulates `scene` into `events_path`, and the truth outputs named.
RunTotals run_scene(const sim::Scene& scene, const std::string& events_path, const std::string& to,
                    const TruthOutputs& outs, bool progress_on) {
    const std::string& truth_path = outs.truth;
    const std::int64_t every_us = outs.truth_every_us;
    const auto start = Clock::now();
    const std::string format = io::resolve_output_format(events_path, to);
    std::unique_ptr<io::EventWriter> writer = io::open_event_writer(events_path, format, scene.sensor);
    std::unique_ptr<sim::TruthWriter> truth;
    if (!truth_path.empty()) truth = std::make_unique<sim::TruthWriter>(truth_path);
    std::unique_ptr<TrackWriter> gt;
    if (!outs.gt_tracks.empty()) gt = std::make_unique<TrackWriter>(outs.gt_tracks, track_format_for(outs.gt_tracks));
    sim::GtTrackSampler gt_sampler;
    std::vector<TrackState> gt_rows;
    std::uint64_t gt_k = 0;

    sim::Simulator simulator(scene);
    const std::int64_t end_us = scene.duration_us();
    Progress progress(progress_on, static_cast<std::uint64_t>(end_us));
    std::vector<Event> batch;
    batch.reserve(kBatch + 4096);
    std::vector<sim::TruthCorner> corners;
    std::int64_t next_truth = 0;
    RunTotals totals;
    auto write_truth_until = [&](double t_us) {
        if (!truth) return;
        while (next_truth <= end_us && static_cast<double>(next_truth) <= t_us) {
            corners.clear();
            sim::corners_at(scene, next_truth, corners);
            truth->write(corners);
            next_truth += every_us;
        }
    };
    auto write_gt_until = [&](double t_us) {
        if (!gt) return;
        for (std::int64_t t; (t = sim::gt_sample_time(gt_k, outs.gt_rate_hz)) <= end_us && static_cast<double>(t) <= t_us;
             ++gt_k) {
            corners.clear();
            sim::corners_at(scene, t, corners);
            gt_rows.clear();
            gt_sampler.sample(corners, gt_rows);
            gt->write(gt_rows);
        }
    };
    write_truth_until(0);
    write_gt_until(0);
    while (simulator.step(batch)) {
        if (batch.size() >= kBatch) {
            writer->write(batch);
            totals.events += batch.size();
            batch.clear();
        }
        write_truth_until(simulator.time_us());
        write_gt_until(simulator.time_us());
        progress.update(static_cast<std::uint64_t>(simulator.time_us()), totals.events + batch.size());
    }
    writer->write(batch);
    totals.events += batch.size();
    progress.finish();
    writer->close();
    if (truth) {
        truth->close();
        totals.truth_rows = truth->rows();
    }
    if (gt) {
        write_gt_until(static_cast<double>(end_us));
        gt_rows.clear();
        gt_sampler.finish(gt_rows);
        gt->write(gt_rows);
        gt->close();
        totals.gt_rows = gt->rows();
        totals.gt_tracks = gt_sampler.tracks();
    }
    totals.stats = simulator.stats();
    totals.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
    return totals;
}

void print_summary(const std::string& what, const sim::Scene& scene, const RunTotals& t) {
    const double ev = static_cast<double>(t.events);
    fmt::print(stderr, "evcorner simulate: {}\n", what);
    fmt::print(stderr, "  scene        {}x{}, {:g} s, {} objects\n", scene.sensor.width, scene.sensor.height,
               scene.duration_s, scene.objects.size());
    fmt::print(stderr, "  events       {} ({} ON, {} OFF; {} noise; {} dropped by the refractory period)\n", t.events,
               t.stats.on, t.stats.off, t.stats.noise, t.stats.refractory);
    fmt::print(stderr, "  rate         {:.3f} M events per simulated second\n", ev / scene.duration_s / 1e6);
    fmt::print(stderr,
               "  steps        {} ({} retried shorter: a vertex moved 0.75 px or more; {} single-pixel samples "
               "within steps; largest |dL| between two samples of a pixel {:.3f} C)\n",
               t.stats.steps, t.stats.rejected_steps, t.stats.pixel_samples, t.stats.max_step_change);
    if (t.truth_rows > 0) fmt::print(stderr, "  truth        {} rows\n", t.truth_rows);
    if (t.gt_rows > 0) fmt::print(stderr, "  gt tracks    {} tracks, {} samples\n", t.gt_tracks, t.gt_rows);
    fmt::print(stderr, "  wall time    {:.3f} s ({:.2f} M simulated events/s)\n", t.wall_s,
               t.wall_s > 0 ? ev / t.wall_s / 1e6 : 0.0);
}

std::string extension_for(const std::string& to) {
    const std::string f = to == "auto" ? "npy" : to;
    if (f == "ecd-text" || f == "text") return ".txt";
    if (f == "h5" || f == "hdf5") return ".h5";
    return "." + f;
}

void run_suite(const SimulateOptions& o) {
    namespace fs = std::filesystem;
    const std::string ext = extension_for(o.to);
    (void)io::resolve_output_format("x" + ext, o.to == "auto" ? "npy" : o.to);  // a bad --to is a usage error
    std::error_code ec;
    fs::create_directories(o.suite, ec);
    if (ec) throw OutputError(o.suite, "cannot create the folder: " + ec.message());
    nlohmann::json manifest;
    manifest["suite"] = "evcorner simulate --suite";
    manifest["truth_every_us"] = o.truth_every_us;
    manifest["scenes"] = nlohmann::json::array();
    for (const sim::PresetInfo& p : sim::presets()) {
        if (!p.in_suite) continue;
        const std::string text = sim::preset_scene_json(p.name);
        const sim::Scene scene = sim::parse_scene(text, "preset " + p.name);
        const std::string scene_file = p.name + ".json", events_file = p.name + ".events" + ext,
                          truth_file = p.name + ".truth.csv", gt_file = p.name + ".gt-tracks.txt";
        const fs::path dir(o.suite);
        io::OutputFile sf((dir / scene_file).string());
        sf.write(text);
        sf.close();
        const TruthOutputs outs{(dir / truth_file).string(), o.truth_every_us, (dir / gt_file).string(), o.gt_rate_hz};
        const RunTotals t =
            run_scene(scene, (dir / events_file).string(), o.to == "auto" ? "npy" : o.to, outs, !o.quiet && !o.no_progress);
        if (!o.quiet) print_summary(o.suite + "/" + p.name, scene, t);
        manifest["scenes"].push_back({{"name", p.name},
                                      {"summary", p.summary},
                                      {"scene", scene_file},
                                      {"events", events_file},
                                      {"truth", truth_file},
                                      {"gt_tracks", gt_file},
                                      {"gt_rate_hz", o.gt_rate_hz},
                                      {"gt_track_count", t.gt_tracks},
                                      {"sensor", {scene.sensor.width, scene.sensor.height}},
                                      {"duration_s", scene.duration_s},
                                      {"event_count", t.events},
                                      {"on", t.stats.on},
                                      {"off", t.stats.off},
                                      {"noise", t.stats.noise},
                                      {"truth_rows", t.truth_rows},
                                      {"wall_s", t.wall_s}});
    }
    io::OutputFile mf((fs::path(o.suite) / "manifest.json").string());
    mf.write(manifest.dump(2));
    mf.write("\n");
    mf.close();
}

void run_simulate(const SimulateOptions& o) {
    const int sources = !o.scene.empty() + !o.preset.empty() + !o.suite.empty();
    if (sources != 1) throw std::invalid_argument("give exactly one of SCENE, --preset and --suite");
    if (o.truth_every_us < 1) throw std::invalid_argument("--truth-every: must be at least 1 us");
    if (!(o.gt_rate_hz > 0 && o.gt_rate_hz <= 1e6)) throw std::invalid_argument("--gt-rate: must be above 0 and at most 1e6 Hz");
    if (!o.suite.empty()) {
        if (!o.output.empty() || !o.truth.empty() || !o.gt_tracks.empty() || o.print_scene)
            throw std::invalid_argument("--suite writes its own files: -o, --truth, --gt-tracks and --print-scene do not apply");
        run_suite(o);
        return;
    }
    const std::string text = o.preset.empty() ? std::string() : sim::preset_scene_json(o.preset);
    if (o.print_scene) {
        if (o.preset.empty()) throw std::invalid_argument("--print-scene needs --preset");
        std::fputs(text.c_str(), stdout);
        return;
    }
    if (o.output.empty()) throw std::invalid_argument("-o: the events' output is required");
    io::check_output_paths({{"SCENE", o.scene}}, {{"-o", o.output}, {"--truth", o.truth}, {"--gt-tracks", o.gt_tracks}});
    io::check_outputs_creatable({{"-o", o.output}, {"--truth", o.truth}, {"--gt-tracks", o.gt_tracks}});
    const sim::Scene scene = o.preset.empty() ? sim::load_scene_file(o.scene) : sim::parse_scene(text, "preset " + o.preset);
    const RunTotals t = run_scene(scene, o.output, o.to, {o.truth, o.truth_every_us, o.gt_tracks, o.gt_rate_hz},
                                  !o.quiet && !o.no_progress);
    if (!o.quiet) print_summary(o.preset.empty() ? o.scene : "preset " + o.preset, scene, t);
}

}  // namespace

void add_simulate_command(CLI::App& app) {
    auto o = std::make_shared<SimulateOptions>();
    std::string names;
    for (const auto& p : sim::presets()) names += fmt::format("\n  {:<13} {}{}", p.name, p.summary, p.in_suite ? "" : " (not in the suite)");
    CLI::App* cmd = app.add_subcommand(
        "simulate",
        "Simulate an event camera watching moving shapes; write the events and the corners' ground truth.\n"
        "The scene (a JSON file, docs/simulate.md) gives the sensor, the camera (contrast threshold,\n"
        "its spread, refractory period, noise, hot pixels), a background and polygons or checkerboards\n"
        "moving by translation, rotation and scaling. Pixels see exact area coverage; an event fires\n"
        "each time a pixel's log intensity moves by the contrast threshold, at the interpolated time.\n"
        "The truth CSV lists every corner (polygon vertex, checkerboard grid point) every --truth-every\n"
        "microseconds: position, interior angle, velocity, visibility. A summary goes to standard error.");
    cmd->add_option("SCENE", o->scene, "Scene file (JSON)");
    cmd->add_option("--preset", o->preset, "A built-in scene instead of a file:" + names);
    cmd->add_option("--suite", o->suite,
                    "Write the benchmark suite (every preset not marked otherwise) into this folder: per scene "
                    "NAME.json, NAME.events.npy (or --to's format), NAME.truth.csv, NAME.gt-tracks.txt (at --gt-rate) and manifest.json");
    cmd->add_option("-o,--output", o->output,
                    "Events (- = standard output, as 't x y p' lines); the format follows the extension (.txt, "
                    ".csv, .npy, .aedat4, .h5, .hdf5) or --to");
    add_output_format_option(*cmd, o->to);
    cmd->add_option("--truth", o->truth, "Also write the ground truth CSV (header: t_us,object,corner,x,y,angle_deg,vx,vy,speed,visible,state)");
    cmd->add_option("--truth-every", o->truth_every_us, "Truth sample period, microseconds")->capture_default_str();
    cmd->add_option("--gt-tracks", o->gt_tracks,
                    "Also write ground-truth feature tracks: every truth corner as a track while it is visible "
                    "(a new id each time it is seen again), positions in the trackers' pixel-index convention (truth "
                    "x - 0.5, y - 0.5); `id t x y` rows (t seconds), or the layout of the extension (.csv, .npy) as "
                    "evcorner track writes; for evcorner eval-tracks");
    cmd->add_option("--gt-rate", o->gt_rate_hz, "GT track sample rate, Hz")->capture_default_str();
    cmd->add_flag("--print-scene", o->print_scene, "Print the --preset scene's JSON to standard output and stop");
    cmd->add_flag("-q,--quiet", o->quiet, "No summary and no progress bar");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bar (it shows only on a terminal)");
    cmd->footer(
        "Examples:\n"
        "  evcorner simulate data/scenes/shapes.json -o events.npy --truth truth.csv\n"
        "  evcorner simulate --preset shapes -o events.npy --gt-tracks gt.txt --gt-rate 200\n"
        "  evcorner simulate --preset checkerboard -o events.txt\n"
        "  evcorner simulate --preset polygons --print-scene > my_scene.json\n"
        "  evcorner simulate --suite suite/                # the benchmark suite, npy events");
    cmd->callback([o] { run_simulate(*o); });
}

}  // namespace evcorner::cli
