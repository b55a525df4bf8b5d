// evcorner eval: the paper's Tables 1 and 2 for every detector on every sequence.
//
// Data flows one way: sequence -> detector -> corner events -> feature-track labeller
// (a sink). Detection time is measured around the detector's batch call only, with a
// fresh detector per run, median over --repeat runs.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "eval_common.hpp"
#include "evcorner/any_detector.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/eval/feature_tracks.hpp"
#include "evcorner/eval/metrics.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/render/figures.hpp"

namespace evcorner::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct EvalOptions {
    std::vector<std::string> inputs;
    std::string detectors = "efast,harris,harris-global";
    int repeat = 5;
    std::string report;
    bool no_figures = false;
    bool quiet = false;
    InputOptions in;
    eval::FeatureTrackParams params;
    std::string overlap = "any";
};

struct Sequence {
    std::string name;
    fs::path file;
};

// The paper's Table 1 (Red., FT in %): spatially-adaptive Harris, then eFAST.
struct PaperRow {
    double harris_red, harris_ft, efast_red, efast_ft;
};
const std::map<std::string, PaperRow>& paper_table1() {
    static const std::map<std::string, PaperRow> t{
        {"shapes_rotation", {92.7, 74.1, 88.9, 74.7}},     {"shapes_translation", {91.7, 78.3, 87.8, 77.5}},
        {"shapes_6dof", {90.6, 77.1, 87.0, 76.8}},         {"dynamic_rotation", {95.1, 53.3, 96.4, 46.4}},
        {"dynamic_translation", {95.3, 62.1, 96.7, 52.1}}, {"dynamic_6dof", {95.4, 55.9, 96.4, 49.4}},
        {"poster_rotation", {92.6, 35.3, 95.7, 30.5}},     {"poster_translation", {92.3, 39.5, 95.8, 35.9}},
        {"poster_6dof", {92.4, 35.3, 95.6, 32.1}},         {"boxes_rotation", {92.1, 32.9, 96.7, 25.2}},
        {"boxes_translation", {92.4, 37.0, 96.7, 30.5}},   {"boxes_6dof", {92.7, 34.4, 96.8, 26.7}},
    };
    return t;
}

std::vector<Sequence> find_sequences(const std::vector<std::string>& inputs) {
    std::vector<Sequence> seqs;
    for (const auto& in : inputs) {
        const fs::path p(in);
        if (fs::is_directory(p)) {
            if (fs::is_regular_file(p / "events.txt")) {
                seqs.push_back({fs::absolute(p).lexically_normal().filename().string(), p / "events.txt"});
                continue;
            }
            std::vector<fs::path> dirs;
            for (const auto& d : fs::directory_iterator(p))
                if (d.is_directory() && fs::is_regular_file(d.path() / "events.txt")) dirs.push_back(d.path());
            std::sort(dirs.begin(), dirs.end());
            if (dirs.empty())
                throw std::invalid_argument(in + ": no <sequence>/events.txt inside (the dataset's layout)");
            for (const auto& d : dirs) seqs.push_back({d.filename().string(), d / "events.txt"});
        } else {
            // events.txt in a sequence folder takes the folder's name, other files their stem.
            const std::string name = p.filename() == "events.txt" && p.has_parent_path()
                                         ? fs::absolute(p).parent_path().filename().string()
                                         : p.stem().string();
            seqs.push_back({name, p});
        }
    }
    return seqs;
}

std::vector<std::string> split_detectors(const std::string& list) {
    std::vector<std::string> out;
    std::stringstream ss(list);
    for (std::string d; std::getline(ss, d, ',');) {
        if (d.empty()) continue;
        make_detector(d, kDavis240);  // throws for an unknown name
        out.push_back(d);
    }
    if (out.empty()) throw std::invalid_argument("-d: no detector named");
    return out;
}

std::string cell(double v) { return std::isnan(v) ? "-" : fmt::format("{:.1f}", v); }

std::string table1_text(const eval::Table1& t, bool markdown) {
    std::string s;
    std::size_t w = 8;
    for (const auto& q : t.sequences) w = std::max(w, q.size());
    if (markdown) {
        s += "| sequence |";
        for (const auto& d : t.detectors) s += fmt::format(" {} Red. | {} FT |", d, d);
        s += "\n|---|";
        for (std::size_t i = 0; i < t.detectors.size(); ++i) s += "---:|---:|";
        s += "\n";
        for (std::size_t r = 0; r < t.sequences.size(); ++r) {
            s += "| " + t.sequences[r] + " |";
            for (const auto& c : t.cells[r]) s += fmt::format(" {} | {} |", cell(c.reduction), cell(c.ft));
            s += "\n";
        }
        return s;
    }
    s += fmt::format("{:<{}}", "", w);
    for (const auto& d : t.detectors) s += fmt::format("  {:>13}", d);
    s += fmt::format("\n{:<{}}", "sequence", w);
    for (std::size_t i = 0; i < t.detectors.size(); ++i) s += fmt::format("  {:>6} {:>6}", "Red.", "FT");
    s += "\n";
    for (std::size_t r = 0; r < t.sequences.size(); ++r) {
        s += fmt::format("{:<{}}", t.sequences[r], w);
        for (const auto& c : t.cells[r]) s += fmt::format("  {:>6} {:>6}", cell(c.reduction), cell(c.ft));
        s += "\n";
    }
    return s;
}

std::string table2_text(const eval::Table2& t, bool markdown) {
    std::string s;
    if (markdown) {
        s += "| detector | time per event [us] | max. event rate [e/s] |\n|---|---:|---:|\n";
        for (const auto& r : t) s += fmt::format("| {} | {:.3f} | {:.0f} |\n", r.detector, r.us_per_event, r.max_event_rate);
        return s;
    }
    s += fmt::format("{:<14}  {:>20}  {:>22}\n", "detector", "time per event [us]", "max. event rate [e/s]");
    for (const auto& r : t)
        s += fmt::format("{:<14}  {:>20.3f}  {:>22.0f}\n", r.detector, r.us_per_event, r.max_event_rate);
    return s;
}

std::string table1_csv(const std::vector<eval::RunRecord>& runs) {
    std::string s = "sequence,detector,events,corners,on_track,reduction_percent,ft_percent\n";
    for (const auto& r : runs)
        s += fmt::format("{},{},{},{},{},{:.4f},{:.4f}\n", r.sequence, r.detector, r.events, r.corners, r.on_track,
                         eval::reduction_rate(r.events, r.corners), eval::ft_percent(r.corners, r.on_track));
    return s;
}

std::string table2_csv(const eval::Table2& t) {
    std::string s = "detector,events,detect_s,us_per_event,max_event_rate\n";
    for (const auto& r : t)
        s += fmt::format("{},{},{:.9f},{:.6f},{:.1f}\n", r.detector, r.events, r.detect_s, r.us_per_event,
                         r.max_event_rate);
    return s;
}

void write_file(const fs::path& p, const std::string& text) {
    io::OutputFile out(p.string());
    out.write(text);
    out.close();
}

std::string paper_comparison_md(const eval::Table1& t) {
    const auto col = [&](const std::string& d) {
        const auto it = std::find(t.detectors.begin(), t.detectors.end(), d);
        return it == t.detectors.end() ? std::size_t(-1) : static_cast<std::size_t>(it - t.detectors.begin());
    };
    const std::size_t h = col("harris"), e = col("efast");
    std::string s =
        "| sequence | Harris Red. (paper) | Harris Red. (ours) | Harris FT (paper) | Harris FT (ours) | "
        "eFAST Red. (paper) | eFAST Red. (ours) | eFAST FT (paper) | eFAST FT (ours) |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (std::size_t r = 0; r < t.sequences.size(); ++r) {
        const auto it = paper_table1().find(t.sequences[r]);
        if (it == paper_table1().end()) continue;
        const PaperRow& p = it->second;
        const auto ours = [&](std::size_t c, bool ft) {
            if (c == std::size_t(-1)) return std::string("-");
            return cell(ft ? t.cells[r][c].ft : t.cells[r][c].reduction);
        };
        s += fmt::format("| {} | {:.1f} | {} | {:.1f} | {} | {:.1f} | {} | {:.1f} | {} |\n", t.sequences[r],
                         p.harris_red, ours(h, false), p.harris_ft, ours(h, true), p.efast_red, ours(e, false),
                         p.efast_ft, ours(e, true));
    }
    return s;
}

void run_eval(EvalOptions& o) {
    finish_feature_track_params(o.params, o.overlap);
    const std::vector<std::string> detectors = split_detectors(o.detectors);
    const std::vector<Sequence> seqs = find_sequences(o.inputs);
    fs::path fig_dir;
    if (!o.report.empty()) {
        fs::create_directories(o.report);
        if (!o.no_figures) fs::create_directories(fig_dir = fs::path(o.report) / "figures");
    }
    std::vector<eval::RunRecord> runs;
    nlohmann::json jruns = nlohmann::json::array();
    std::string figures_md;
    for (const auto& seq : seqs) {
        const LoadedEvents in = load_events(seq.file.string(), o.in);
        if (!o.quiet) fmt::print(stderr, "eval: {} ({} events)\n", seq.name, in.events.size());
        for (const auto& dname : detectors) {
            std::vector<std::uint8_t> flags(in.events.size());
            std::vector<double> times;
            for (int rep = 0; rep < o.repeat; ++rep) {
                AnyDetector det = make_detector(dname, in.size);
                const auto t0 = Clock::now();
                std::visit([&](auto& d) { detect(d, std::span<const Event>(in.events), flags); }, det);
                times.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
            }
            std::vector<Event> corners;
            for (std::size_t i = 0; i < in.events.size(); ++i)
                if (flags[i]) corners.push_back(in.events[i]);
            const auto l0 = Clock::now();
            const eval::FeatureTrackResult labels = eval::label_feature_tracks(corners, o.params);
            const double label_s = std::chrono::duration<double>(Clock::now() - l0).count();
            eval::RunRecord r{seq.name, dname, in.events.size(), corners.size(), labels.labelled, eval::median(times)};
            runs.push_back(r);
            jruns.push_back({{"sequence", r.sequence},
                             {"detector", r.detector},
                             {"events", r.events},
                             {"corners", r.corners},
                             {"on_track", r.on_track},
                             {"reduction_percent", eval::reduction_rate(r.events, r.corners)},
                             {"ft_percent", eval::ft_percent(r.corners, r.on_track)},
                             {"detect_s_median", r.detect_s},
                             {"detect_s_runs", times},
                             {"tracks_accepted", labels.accepted},
                             {"hypotheses", labels.hypotheses},
                             {"label_s", label_s}});
            if (!fig_dir.empty() && !in.events.empty()) {
                const std::int64_t t_first = in.events.front().t, t_last = in.events.back().t;
                const std::string stem = seq.name + "." + dname;
                render::write_png((fig_dir / (stem + ".corners.png")).string(),
                                  render::upscale(render::render_recent_corners(in.events, corners, in.size, t_last), 2));
                render::write_png((fig_dir / (stem + ".labels.png")).string(),
                                  render::render_space_time(in.events, corners, labels.on_track, in.size, t_first,
                                                            std::max(t_last, t_first + 1)));
                figures_md += fmt::format("| {} | {} | ![](figures/{}.corners.png) | ![](figures/{}.labels.png) |\n",
                                          seq.name, dname, stem, stem);
            }
        }
        if (!fig_dir.empty() && !in.events.empty()) {
            const std::int64_t t_first = in.events.front().t, t_last = in.events.back().t;
            render::write_png((fig_dir / (seq.name + ".sae.png")).string(),
                              render::upscale(render::render_sae(in.events, in.size, 1, t_last,
                                                                 std::max<std::int64_t>(1, t_last - t_first)),
                                              2));
            const std::vector<Event> corners = detect_corners(detectors.front(), in.events, in.size);
            render::write_png((fig_dir / (seq.name + ".space_time.png")).string(),
                              render::render_space_time(in.events, corners, {}, in.size, t_first,
                                                        std::max(t_last, t_first + 1)));
        }
    }
    const eval::Table1 t1 = eval::make_table1(runs);
    const eval::Table2 t2 = eval::make_table2(runs);
    fmt::print("Table 1: reduction rate (Red.) and corners on feature tracks (FT), %\n{}\n", table1_text(t1, false));
    fmt::print("Table 2: detection time per event (median of {} runs) and max. event rate\n{}", o.repeat,
               table2_text(t2, false));
    if (o.report.empty()) return;
    const fs::path dir(o.report);
    write_file(dir / "table1.csv", table1_csv(runs));
    write_file(dir / "table2.csv", table2_csv(t2));
    nlohmann::json j;
    j["repeat"] = o.repeat;
    j["feature_tracks"] = {{"inner_radius", o.params.inner_radius},
                           {"outer_radius", o.params.outer_radius},
                           {"min_inner", o.params.min_inner},
                           {"max_outer_ratio", o.params.max_outer_ratio},
                           {"max_duration_us", o.params.max_duration_us},
                           {"max_length", o.params.max_length},
                           {"same_polarity", o.params.same_polarity},
                           {"overlap", std::string(eval::to_string(o.params.overlap))}};
    j["runs"] = jruns;
    nlohmann::json jt2 = nlohmann::json::array();
    for (const auto& r : t2)
        jt2.push_back({{"detector", r.detector},
                       {"events", r.events},
                       {"detect_s", r.detect_s},
                       {"us_per_event", r.us_per_event},
                       {"max_event_rate", r.max_event_rate}});
    j["table2"] = jt2;
    write_file(dir / "results.json", j.dump(2) + "\n");
    std::string md = "# evcorner evaluation\n\n";
    md += fmt::format(
        "Feature tracks: inner {} px, outer {} px, at least {} inner corner events, outer/inner at most {}, "
        "pairs at most {} us and {} px apart, {}, overlap '{}' (docs/evaluation.md).\n"
        "Detection time: median of {} runs, detector batch call only.\n\n",
        o.params.inner_radius, o.params.outer_radius, o.params.min_inner, o.params.max_outer_ratio,
        o.params.max_duration_us, o.params.max_length, o.params.same_polarity ? "per polarity" : "both polarities",
        eval::to_string(o.params.overlap), o.repeat);
    md += "## Table 1: reduction rate and FT (%)\n\n" + table1_text(t1, true) + "\n";
    md += "### Beside the paper's Table 1 (whole one-minute sequences)\n\n" + paper_comparison_md(t1) + "\n";
    md += "## Table 2: time per event\n\n" + table2_text(t2, true) + "\n";
    md += "Paper (one core of an i7-3720QM, 2.6 GHz): Harris 11.6 us / 86,230 e/s; eFAST 0.78 us / 1,275,000 e/s.\n\n";
    if (!figures_md.empty()) {
        md += "## Figures\n\nCorners of the last 33 ms (bright) and 100 ms (dark), green ON, red OFF (Fig. 6); "
              "corner events in space-time over the whole sequence, green on a feature track, red off it "
              "(Fig. 5b). Per sequence also `figures/<sequence>.sae.png` (Fig. 2b) and "
              "`figures/<sequence>.space_time.png` (Fig. 1b, the first detector's corners).\n\n"
              "| sequence | detector | corners (Fig. 6) | labels (Fig. 5b) |\n|---|---|---|---|\n" +
              figures_md;
    }
    write_file(dir / "report.md", md);
    if (!o.quiet) fmt::print(stderr, "eval: report written to {}\n", o.report);
}

}  // namespace

void add_eval_command(CLI::App& app) {
    auto o = std::make_shared<EvalOptions>();
    CLI::App* cmd = app.add_subcommand(
        "eval",
        "Evaluate detectors on sequences: the paper's Tables 1 and 2, a report with figures.\n"
        "As Mueggler et al. (BMVC 2017) do: per sequence the reduction rate and the share of\n"
        "corner events on feature tracks (Table 1), per detector the time per event and the\n"
        "largest event rate it sustains (Table 2).");
    cmd->add_option("INPUTS", o->inputs,
                    "Sequence files, or folders in the dataset's layout <sequence>/events.txt")
        ->required();
    cmd->add_option("-d,--detectors", o->detectors, "Comma-separated detectors")->capture_default_str();
    cmd->add_option("--repeat", o->repeat, "Timed runs per detector and sequence (median)")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    cmd->add_option("--report", o->report, "Write table1.csv, table2.csv, results.json, report.md and figures/ here");
    cmd->add_flag("--no-figures", o->no_figures, "No PNG figures in the report");
    cmd->add_flag("-q,--quiet", o->quiet, "No progress lines");
    add_load_options(*cmd, o->in);
    add_feature_track_options(*cmd, o->params, o->overlap);
    cmd->footer(
        "Examples:\n"
        "  evcorner eval ../shared/data/real/ecd-stppp --report eval-report\n"
        "  evcorner eval a/events.txt b.txt -d efast,harris --repeat 3");
    cmd->callback([o] { run_eval(*o); });
}

}  // namespace evcorner::cli
