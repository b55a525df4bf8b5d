// evcorner render: the paper's figures as PNG images.
//
//   sae         Fig. 2b: SAE of one polarity, grey, newest bright
//   corners     Fig. 6:  events of the last 33 ms grey, corners of the last 33 / 100 ms
//   space-time  Fig. 1b: events and corner events over an interval, time upwards
//   labels      Fig. 5b: corner events in space-time, green on a feature track, red off

#include <algorithm>
#include <fmt/format.h>
#include <memory>
#include <string>

#include "commands.hpp"
#include "eval_common.hpp"
#include "evcorner/render/figures.hpp"

namespace evcorner::cli {

namespace {

struct RenderOptions {
    std::string input;
    std::string output;
    std::string kind = "corners";
    std::string detector = "efast";
    std::string corners_file;
    std::string at;
    double window_ms = 0;  // 0: the kind's default
    int scale = 2;
    int polarity = 1;
    int time_height = 360;
    InputOptions in;
    eval::FeatureTrackParams params;
    std::string overlap = "any";
};

void run_render(RenderOptions& o) {
    finish_feature_track_params(o.params, o.overlap);
    const LoadedEvents in = load_events(o.input, o.in);
    if (in.events.empty()) throw std::invalid_argument(o.input + ": no events to draw");
    const std::int64_t first = in.events.front().t, last = in.events.back().t;
    const std::int64_t at = o.at.empty() ? last : parse_time_option(o.at, first, last);
    std::vector<Event> corners;
    if (o.kind != "sae") {
        corners = o.corners_file.empty() ? detect_corners(o.detector, in.events, in.size)
                                         : load_events(o.corners_file, o.in).events;
    }
    const auto window_us = [&](double default_ms) {
        return static_cast<std::int64_t>(std::llround((o.window_ms > 0 ? o.window_ms : default_ms) * 1000.0));
    };
    render::RgbImage img;
    if (o.kind == "sae") {
        img = render::upscale(render::render_sae(in.events, in.size, o.polarity, at, window_us(50)), o.scale);
    } else if (o.kind == "corners") {
        render::RecentCornersStyle style;
        if (o.window_ms > 0) style.older_us = window_us(100);
        img = render::upscale(render::render_recent_corners(in.events, corners, in.size, at, style), o.scale);
    } else {
        // The interval ends at --at; by default it reaches back to the first event.
        const std::int64_t t0 = o.window_ms > 0 ? at - window_us(0) : first;
        if (at <= t0) throw std::invalid_argument("--at: the interval to draw is empty");
        render::SpaceTimeStyle style;
        style.scale = o.scale;
        style.time_height = o.time_height;
        std::vector<std::uint8_t> labels;
        if (o.kind == "labels") labels = eval::label_feature_tracks(corners, o.params).on_track;
        img = render::render_space_time(in.events, corners, labels, in.size, t0, at, style);
    }
    render::write_png(o.output, img);
    fmt::print(stderr, "render: {} {}x{} at t = {:.6f} s -> {}\n", o.kind, img.width(), img.height(),
               static_cast<double>(at) * 1e-6, o.output);
}

}  // namespace

void add_render_command(CLI::App& app) {
    auto o = std::make_shared<RenderOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Draw the paper's figures as PNG: SAE, corners, space-time view, labelled corners.\n"
        "Kinds: sae (Fig. 2b), corners (Fig. 6: events of the last 33 ms, corner events of the\n"
        "last 33 ms bright and 100 ms dark, green ON / red OFF), space-time (Fig. 1b) and labels\n"
        "(Fig. 5b: green on a feature track, red off it).");
    cmd->add_option("INPUT", o->input, "Event file (any format evcorner reads)")->required();
    cmd->add_option("-o,--output", o->output, "PNG file to write")->required();
    cmd->add_option("-k,--kind", o->kind, "sae, corners, space-time or labels")
        ->capture_default_str()
        ->check(CLI::IsMember({"sae", "corners", "space-time", "labels"}));
    cmd->add_option("-d,--detector", o->detector, "Detector for the corner events")
        ->capture_default_str()
        ->check([](const std::string& name) {
            for (const auto& d : detector_infos())
                if (d.name == name) return std::string();
            return "unknown detector '" + name + "'";
        });
    cmd->add_option("--corners", o->corners_file, "Take the corner events from this file instead of detecting");
    cmd->add_option("--at", o->at,
                    "Time drawn (end of the interval): seconds on the stream's clock, +S after the first "
                    "event, -S before the last [default: the last event]");
    cmd->add_option("--window", o->window_ms,
                    "Milliseconds: sae: age that fades to black [50]; corners: dark-corner span [100]; "
                    "space-time/labels: interval before --at [the whole stream]");
    cmd->add_option("--scale", o->scale, "Image pixels per sensor pixel")->capture_default_str()->check(CLI::Range(1, 16));
    cmd->add_option("--polarity", o->polarity, "sae: polarity shown, 1 = ON, 0 = OFF")
        ->capture_default_str()
        ->check(CLI::Range(0, 1));
    cmd->add_option("--time-height", o->time_height, "space-time/labels: height of the time axis, pixels before --scale")
        ->capture_default_str()
        ->check(CLI::Range(16, 4096));
    add_load_options(*cmd, o->in);
    add_feature_track_options(*cmd, o->params, o->overlap);
    cmd->footer(
        "Examples:\n"
        "  evcorner render events.txt -k corners -o fig6.png --at +0.04\n"
        "  evcorner render events.txt -k labels -d harris -o fig5b.png\n"
        "  evcorner render events.txt -k sae --polarity 0 --window 30 -o sae.png");
    cmd->callback([o] { run_render(*o); });
}

}  // namespace evcorner::cli
