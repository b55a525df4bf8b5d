// evcorner eval-tracks: predicted feature tracks against ground-truth tracks, by the
// feature-track benchmark's metric (eval/track_metrics.hpp), and what the tracks say alone.

#include <cmath>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "evcorner/eval/track_metrics.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/track/track_file.hpp"
#include "evcorner/track/track_seed.hpp"

namespace evcorner::cli {

namespace {

struct EvalTracksOptions {
    std::string tracks;
    std::string gt;
    bool asynchronous = false;
    double associate_px = 0;
    bool no_align = false;
    std::string seeds;
    std::string json;
};

nlohmann::json statistics_json(const eval::TrackStatistics& s) {
    return {{"tracks", s.tracks},
            {"samples", s.samples},
            {"lifetime_median_s", s.lifetime_median_s},
            {"lifetime_mean_s", s.lifetime_mean_s},
            {"length_median_px", s.length_median_px},
            {"length_mean_px", s.length_mean_px},
            {"jitter_rms_px", s.jitter_rms_px},
            {"jitter_samples", s.jitter_samples}};
}

nlohmann::json metric_json(const eval::TrackEvaluation& r, const EvalTracksOptions& o) {
    nlohmann::json per_track = nlohmann::json::array();
    for (const eval::TrackScore& s : r.tracks)
        per_track.push_back({{"id", s.id},
                             {"gt_id", s.gt_id},
                             {"skipped", s.skipped},
                             {"fa_5", s.skipped ? nlohmann::json(nullptr) : nlohmann::json(s.age[4])},
                             {"te_5", s.has_error_5 ? nlohmann::json(s.error_5) : nlohmann::json(nullptr)}});
    return {{"mode", o.asynchronous ? "asynchronous" : "synchronous"},
            {"association", !o.seeds.empty() ? nlohmann::json({{"seeds", o.seeds}, {"radius_px", o.associate_px > 0 ? o.associate_px : 1.0}})
                            : o.associate_px > 0 ? nlohmann::json({{"radius_px", o.associate_px}})
                                                 : nlohmann::json("id")},
            {"thresholds_px", r.age.size()},
            {"fa", r.fa},
            {"efa", r.efa},
            {"fa_5", r.fa_5},
            {"te_5", r.te_5},
            {"inlier_ratio", r.inlier_ratio},
            {"age", r.age},
            {"inlier_mean", r.inlier_mean},
            {"inlier_std", r.inlier_std},
            {"age_mean", r.age_mean},
            {"age_std", r.age_std},
            {"predicted_tracks", r.predicted_tracks},
            {"gt_tracks", r.gt_tracks},
            {"counted_tracks", r.counted_tracks},
            {"skipped_tracks", r.skipped_tracks},
            {"unmatched_tracks", r.unmatched_tracks},
            {"aligned", o.associate_px > 0 || !o.seeds.empty() ? false : !o.no_align},
            {"time_shift_s", r.time_shift_s},
            {"tracks", per_track}};
}

void print_statistics(const eval::TrackStatistics& s) {
    fmt::print("  tracks       {} ({} samples)\n", s.tracks, s.samples);
    fmt::print("  lifetime     median {:.3f} s, mean {:.3f} s\n", s.lifetime_median_s, s.lifetime_mean_s);
    fmt::print("  length       median {:.1f} px, mean {:.1f} px\n", s.length_median_px, s.length_mean_px);
    fmt::print("  jitter       {:.3f} px RMS (over {} samples)\n", s.jitter_rms_px, s.jitter_samples);
}

void run_eval_tracks(const EvalTracksOptions& o) {
    if (!o.json.empty() && o.json != "-") {
        io::check_output_paths({{"TRACKS", o.tracks}, {"GT", o.gt}}, {{"--json", o.json}});
        io::check_outputs_creatable({{"--json", o.json}});
    }
    if (o.associate_px < 0 || !std::isfinite(o.associate_px))
        throw std::invalid_argument("--associate: a radius in pixels, > 0");
    if (o.gt.empty() && (o.asynchronous || o.associate_px > 0 || o.no_align || !o.seeds.empty()))
        throw std::invalid_argument("--async, --associate, --seeds and --no-align need GT");
    if (o.no_align && (o.associate_px > 0 || !o.seeds.empty()))
        throw std::invalid_argument("--no-align: tracks matched by position (--associate, --seeds) are never shifted");
    const std::vector<TrackPoint> pred = read_track_points(o.tracks);
    const eval::TrackStatistics stats = eval::track_statistics(pred);
    nlohmann::json j = {{"tracks_file", o.tracks}, {"statistics", statistics_json(stats)}};
    const bool to_stdout = o.json == "-";
    if (o.gt.empty()) {
        if (!to_stdout) {
            fmt::print("evcorner eval-tracks: {} (no GT: statistics only)\n", o.tracks);
            print_statistics(stats);
        }
    } else {
        const std::vector<TrackPoint> gt = read_track_points(o.gt);
        eval::TrackMetricOptions m;
        m.asynchronous = o.asynchronous;
        m.associate_px = o.associate_px;
        m.align_start = !o.no_align;
        std::vector<TrackPoint> seeds;
        if (!o.seeds.empty())
            for (const TrackSeed& sd : read_seeds_file(o.seeds))
                seeds.push_back({sd.id, static_cast<double>(sd.t) / 1e6, sd.x, sd.y});
        m.seeds = seeds;
        const eval::TrackEvaluation r = eval::evaluate_tracks(pred, gt, m);
        j["gt_file"] = o.gt;
        j["metric"] = metric_json(r, o);
        if (!to_stdout) {
            fmt::print("evcorner eval-tracks: {} against {} ({}, {})\n", o.tracks, o.gt,
                       o.asynchronous ? "asynchronous" : "synchronous",
                       !o.seeds.empty() ? fmt::format("matched through the seeds of {} within {:g} px", o.seeds,
                                                      o.associate_px > 0 ? o.associate_px : 1.0)
                       : o.associate_px > 0 ? fmt::format("associated within {:g} px", o.associate_px)
                                            : std::string("matched by id"));
            fmt::print("  FA           {:.4f}\n", r.fa);
            fmt::print("  EFA          {:.4f}\n", r.efa);
            fmt::print("  FA@5         {:.4f}\n", r.fa_5);
            fmt::print("  TE@5         {:.4f} px\n", r.te_5);
            fmt::print("  tracks       {} predicted, {} GT: {} counted, {} skipped (fewer than 2 GT samples to compare), "
                       "{} unmatched\n",
                       r.predicted_tracks, r.gt_tracks, r.counted_tracks, r.skipped_tracks, r.unmatched_tracks);
            if (r.time_shift_s != 0) fmt::print("  time shift   {:+.6f} s (the files aligned at their first rows)\n", r.time_shift_s);
            fmt::print("without GT:\n");
            print_statistics(stats);
        }
    }
    if (to_stdout) {
        fmt::print("{}\n", j.dump(2));
    } else if (!o.json.empty()) {
        io::OutputFile out(o.json);
        out.write(j.dump(2));
        out.write("\n");
        out.close();
    }
}

}  // namespace

void add_eval_tracks_command(CLI::App& app) {
    auto o = std::make_shared<EvalTracksOptions>();
    CLI::App* cmd = app.add_subcommand(
        "eval-tracks",
        "Feature tracks against ground-truth tracks: feature age (FA), expected feature age (EFA), FA and\n"
        "tracking error at 5 px (FA@5, TE@5), by the feature-track benchmark's metric (Messikommer et al.,\n"
        "CVPR 2023; docs/tracking.md): thresholds 1..31 px; synchronous (the GT cut to each track's span,\n"
        "as the benchmark runs) unless --async (a track holds its last position to the GT's end). Tracks are\n"
        "matched to GT by id (a tracker seeded at the GT's first samples: evcorner track --seeds GT), the\n"
        "prediction's times first shifted so that the files' first rows agree (not with --no-align), or with\n"
        "--associate PX by position (each track takes the nearest free GT track within PX at its first time;\n"
        "no shift), or with --seeds FILE through its seed (the same, at the seed's time and place). Without\n"
        "GT, and always besides: track count, lifetime, path length and jitter. Track files: `id t x y`\n"
        "(ddft), `t,x,y,theta,id` (haste), evcorner's .csv and .npy; gzip or zstd compressed too.");
    cmd->add_option("TRACKS", o->tracks, "Predicted tracks (evcorner track's output, any layout)")->required();
    cmd->add_option("GT", o->gt, "Ground-truth tracks (evcorner simulate --gt-tracks); omitted: statistics only");
    cmd->add_flag("--async", o->asynchronous, "The asynchronous variant: tracks are not cut, they hold their last position");
    cmd->add_option("--associate", o->associate_px,
                    "Match tracks to GT by position within this radius, pixels (for self-seeded trackers, such as "
                    "evcorner track -d DETECTOR)");
    cmd->add_option("--seeds", o->seeds,
                    "Match tracks to GT through the seeds they were started from (evcorner track --seeds FILE): track "
                    "k follows the GT track nearest seed k at its time (within --associate, default 1 px), from then on");
    cmd->add_flag("--no-align", o->no_align,
                  "Matched by id, take the prediction's times as they are (the benchmark shifts them so that the "
                  "files' first rows agree; wrong for a tracker on the GT's clock whose first report comes after "
                  "the GT's first sample, as HASTE's does)");
    cmd->add_option("--json", o->json, "Also write the results as JSON to this file (- = standard output, instead of the text)");
    cmd->footer(
        "Examples:\n"
        "  evcorner simulate --preset shapes -o ev.npy --gt-tracks gt.txt\n"
        "  evcorner track ev.npy --tracker haste-correlation-star --init uncentered --seeds gt.txt -o tracks.txt\n"
        "  evcorner eval-tracks tracks.txt gt.txt\n"
        "  evcorner track ev.npy --tracker haste-correlation-star -d arcstar -o fe.txt\n"
        "  evcorner eval-tracks fe.txt gt.txt --associate 3 --json -\n"
        "  evcorner eval-tracks haste-output.txt gt.txt --seeds seeds.txt   # a tracker seeded at some time");
    cmd->callback([o] { run_eval_tracks(*o); });
}

}  // namespace evcorner::cli
