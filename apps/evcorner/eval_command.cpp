// evcorner eval: the paper's Tables 1 and 2 for every detector on every sequence.
//
// Data flows one way: sequence -> detectors -> corner events -> feature-track labeller
// (a sink). The sequence is read batch by batch and never held: every batch goes to
// --repeat fresh detectors of each kind, which keep their corner events (what the
// labeller needs) and the figures keep a bounded summary (StreamFigures). A run's
// detection time is the sum of its detector's batch calls; the median over the --repeat
// detectors is reported.

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <fmt/format.h>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "commands.hpp"
#include "detector_options.hpp"
#include "eval_common.hpp"
#include "evcorner/registry.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/nms.hpp"
#include "evcorner/scored_detector.hpp"
#include "evcorner/eval/feature_tracks.hpp"
#include "evcorner/eval/metrics.hpp"
#include "evcorner/eval/pr_curve.hpp"
#include "evcorner/eval/truth_match.hpp"
#include "evcorner/render/charts.hpp"
#include "evcorner/sim/truth.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/io/output_file.hpp"
#include "evcorner/io/output_paths.hpp"
#include "evcorner/pipeline/track_eval.hpp"
#include "evcorner/render/figures.hpp"
#include "evcorner/render/frame.hpp"
#include "evcorner/track/tracker.hpp"
#include "progress.hpp"

namespace evcorner::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
constexpr std::size_t kBatch = std::size_t{1} << 16;

struct EvalOptions {
    std::vector<std::string> inputs;
    std::string detectors = all_detectors_list();
    ParamValues detector_params;
    int repeat = 5;
    std::string report;
    bool no_figures = false;
    std::string figure_format = "png";
    bool quiet = false;
    bool no_progress = false;
    InputOptions in;
    eval::FeatureTrackParams params;
    std::string overlap = "any";
    // Against ground truth (a simulated scene's truth CSV).
    std::string truth;
    eval::TruthMatchParams match;
    std::string credit = "all";
    std::string interpolation = "linear";
    std::vector<double> speed_edges;
    // Non-maximum suppression (nms.hpp): every detector with it, or with and without.
    bool nms = false, compare_nms = false;
    NmsParams nms_params;
    std::string nms_rule = "window";
    // Trackers against GT tracks (pipeline/track_eval.hpp).
    bool tracks = false;
    std::string trackers = "all";
    std::string tracks_golden;
};

// One evaluated kind: a detector, with or without NMS after it ("NAME+nms").
struct EvalKind {
    DetectorConfig config;
    std::optional<NmsParams> nms;
    std::string name;
};

struct Sequence {
    std::string name;  ///< unique among the inputs: rows, figures and CSV lines
    std::string base;  ///< the dataset's sequence name (folder of events.txt, else stem): the paper's rows
    fs::path file;
    std::string stem;  ///< the name as a file-name stem for the figures, unique too
    fs::path truth;    ///< its ground truth (simulate --truth), empty when none
};

// The truth beside an event file written by simulate: NAME.truth.csv for NAME.events.EXT
// (simulate --suite) or NAME.EXT; empty when there is none.
fs::path truth_beside(const fs::path& events) {
    std::string base = events.stem().string();
    if (base.size() > 7 && base.ends_with(".events")) base.resize(base.size() - 7);
    const fs::path t = events.parent_path() / (base + ".truth.csv");
    return fs::is_regular_file(t) && t != events ? t : fs::path();
}

// The sensor ("WxH") of the simulated scene NAME.json beside NAME.truth.csv, for event files
// that do not carry their size (.npy); empty when there is no such scene or it has no sensor.
std::string scene_sensor_beside(const Sequence& seq) {
    if (seq.truth.empty()) return {};
    const std::string t = seq.truth.string();
    const fs::path scene(t.substr(0, t.size() - 10) + ".json");
    if (!fs::is_regular_file(scene)) return {};
    std::ifstream in(scene);
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.contains("sensor") || !j["sensor"].is_array() || j["sensor"].size() != 2 ||
        !j["sensor"][0].is_number_integer() || !j["sensor"][1].is_number_integer())
        return {};
    return fmt::format("{}x{}", j["sensor"][0].get<long long>(), j["sensor"][1].get<long long>());
}

// Files of a suite folder that are not event files: the truths, the GT tracks, the scenes and
// the manifest.
bool is_suite_companion(const fs::path& p) {
    const std::string name = p.filename().string();
    if (name.ends_with(".truth.csv") || name.ends_with(".gt-tracks.txt") || name == "manifest.json") return true;
    return p.extension() == ".json" && fs::is_regular_file(p.parent_path() / (p.stem().string() + ".truth.csv"));
}

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

// A sequence's name as a file-name stem: the folders that make it unique joined by '_'.
std::string file_stem(std::string name) {
    std::replace(name.begin(), name.end(), '/', '_');
    return name;
}

// The extensions of the event files evcorner reads, as a help text lists them: a folder
// given as input contributes its files with these (io::is_event_input_path), besides
// <sequence>/events.txt folders and rosbag2 bag folders.
std::string event_extensions_text() {
    std::string text;
    for (const std::string_view e : io::input_file_extensions()) text += (text.empty() ? "" : " ") + std::string(e);
    std::string compressed;
    for (const std::string_view c : io::input_compression_extensions())
        compressed += (compressed.empty() ? "" : " ") + std::string(c);
    return text + ", .txt/.csv compressed " + compressed;
}

// A file's name without its extension, and without a compression's before it ("a" for
// a.txt.gz).
std::string file_stem_of(const fs::path& file) {
    fs::path stem = file.stem();
    std::string ext = file.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const auto compressions = io::input_compression_extensions();
    if (std::find(compressions.begin(), compressions.end(), ext) != compressions.end() && stem.has_extension())
        stem = stem.stem();
    return stem.string();
}

// The GT tracks beside an event file: NAME.gt-tracks.txt for NAME.events.EXT (simulate
// --suite) or NAME.EXT; empty when there is none.
fs::path gt_tracks_beside(const fs::path& events) {
    std::string base = file_stem_of(events);
    if (base.size() > 7 && base.ends_with(".events")) base.resize(base.size() - 7);
    const fs::path t = events.parent_path() / (base + ".gt-tracks.txt");
    return fs::is_regular_file(t) && t != events ? t : fs::path();
}

// Makes every name unique. Inputs of one name that are different files take, all alike,
// the fewest of these that tells them apart: level 0 the name; for a file named after its
// stem, level 1 its file name with the extension; then one parent folder more per level.
// The same file given twice keeps its name, with "#2", "#3" ... after the first.
void make_names_unique(std::vector<Sequence>& seqs) {
    std::vector<fs::path> abs;
    for (const auto& s : seqs) abs.push_back(fs::absolute(s.file).lexically_normal());
    auto level = [&](std::size_t i, int k) {
        const bool events_txt = abs[i].filename() == "events.txt";
        if (k == 0) return seqs[i].name;
        fs::path dir = abs[i].parent_path();
        std::string name = seqs[i].name;
        if (events_txt) {
            dir = dir.parent_path();  // the sequence folder is the name already
        } else {
            name = abs[i].filename().string();
            --k;
        }
        for (; k > 0 && dir.has_relative_path(); --k, dir = dir.parent_path()) name = dir.filename().string() + "/" + name;
        return name;
    };
    std::map<std::string, std::vector<std::size_t>> groups;
    for (std::size_t i = 0; i < seqs.size(); ++i) groups[seqs[i].name].push_back(i);
    std::vector<std::string> names(seqs.size());
    for (const auto& [name, members] : groups) {
        for (int k = 0;; ++k) {
            std::map<std::string, fs::path> file_of;
            bool apart = true;
            for (const std::size_t i : members) {
                const auto [it, added] = file_of.emplace(level(i, k), abs[i]);
                if (!added && it->second != abs[i]) apart = false;
            }
            // Different files in one folder tree always part within their path's length.
            if (apart || k > 256) {
                for (const std::size_t i : members) names[i] = level(i, k);
                break;
            }
        }
    }
    std::map<std::string, int> seen;
    for (std::size_t i = 0; i < seqs.size(); ++i) {
        seqs[i].name = names[i];
        if (++seen[names[i]] > 1) seqs[i].name += "#" + std::to_string(seen[names[i]]);
    }
}

std::vector<Sequence> find_sequences(const std::vector<std::string>& inputs) {
    std::vector<Sequence> seqs;
    for (const auto& in : inputs) {
        const fs::path p(in);
        if (fs::is_directory(p)) {
            const bool bag = io::is_event_input_path(p);  // a rosbag2 folder: one sequence
            if (bag || fs::is_regular_file(p / "events.txt")) {
                const std::string name = fs::absolute(p).lexically_normal().filename().string();
                seqs.push_back({name, name, bag ? p : p / "events.txt", {}, {}});
                continue;
            }
            // <sequence>/events.txt folders (the dataset's layout), rosbag2 folders and event files.
            std::vector<fs::path> dirs, bags, files, skipped;
            for (const auto& d : fs::directory_iterator(p)) {
                if (d.is_directory()) {
                    if (fs::is_regular_file(d.path() / "events.txt")) dirs.push_back(d.path());
                    else if (io::is_event_input_path(d.path())) bags.push_back(d.path());
                } else if (d.is_regular_file()) {
                    if (is_suite_companion(d.path())) continue;
                    (io::is_event_input_path(d.path()) ? files : skipped).push_back(d.path());
                }
            }
            std::sort(dirs.begin(), dirs.end());
            std::sort(bags.begin(), bags.end());
            std::sort(files.begin(), files.end());
            std::sort(skipped.begin(), skipped.end());
            if (dirs.empty() && bags.empty() && files.empty())
                throw std::invalid_argument(in + ": no <sequence>/events.txt folder, no rosbag2 folder (metadata.yaml) "
                                                 "and no event file (" + event_extensions_text() + ") inside");
            for (const auto& f : skipped)
                fmt::print(stderr, "eval: {}: skipped, not an event file by its extension\n", f.string());
            for (const auto& d : dirs) seqs.push_back({d.filename().string(), d.filename().string(), d / "events.txt", {}, {}});
            for (const auto& d : bags) seqs.push_back({d.filename().string(), d.filename().string(), d, {}, {}});
            for (const auto& f : files) seqs.push_back({file_stem_of(f), file_stem_of(f), f, {}, {}});
        } else {
            // events.txt in a sequence folder takes the folder's name, other files their stem.
            const std::string name = p.filename() == "events.txt" && p.has_parent_path()
                                         ? fs::absolute(p).parent_path().filename().string()
                                         : file_stem_of(p);
            seqs.push_back({name, name, p, {}, {}});
        }
    }
    // A simulated scene's events take the scene's name and its truth (or its GT tracks' name).
    for (Sequence& q : seqs) {
        q.truth = truth_beside(q.file);
        if (!q.truth.empty()) {
            q.name = q.base = q.truth.filename().string().substr(0, q.truth.filename().string().size() - 10);
        } else if (const fs::path gt = gt_tracks_beside(q.file); !gt.empty()) {
            q.name = q.base = gt.filename().string().substr(0, gt.filename().string().size() - 14);
        }
    }
    make_names_unique(seqs);
    // Figure stems: the name's folders joined by '_'; one that meets another name's gets a number.
    std::set<std::string> stems;
    for (auto& q : seqs) {
        q.stem = file_stem(q.name);
        for (int k = 2; !stems.insert(q.stem).second; ++k) q.stem = file_stem(q.name) + "#" + std::to_string(k);
    }
    return seqs;
}

// What the report's figures need from a sequence, kept while it streams by, in memory
// bounded by the sensor: per pixel the newest event (any polarity, and ON), which gives
// the SAE (Fig. 2b) and the grey events of the last 33 ms (Fig. 6) exactly; and for the
// space-time views (Figs. 1b, 5b) a uniform sample of at most kSample events (all of
// them in a shorter sequence; reservoir sampling, fixed seed).
class StreamFigures {
public:
    static constexpr std::size_t kSample = std::size_t{1} << 18;

    explicit StreamFigures(SensorSize size)
        : size_(size),
          newest_(static_cast<std::size_t>(size.pixels()), kNever),
          newest_on_(static_cast<std::size_t>(size.pixels()), kNever) {}

    void add(std::span<const Event> events) {
        for (const Event& e : events) {
            const std::size_t px = static_cast<std::size_t>(e.y) * size_.width + e.x;
            newest_[px] = e.t;
            if (e.p == 1) newest_on_[px] = e.t;
            if (seen_ < kSample) {
                sample_.push_back(e);
            } else if (seen_ == next_) {
                sample_[pick_(rng_)] = e;
                skip();
            }
            ++seen_;
        }
        if (!events.empty()) {
            if (first_t_ == kNever) first_t_ = events.front().t;
            last_t_ = events.back().t;
        }
    }

    [[nodiscard]] bool empty() const noexcept { return seen_ == 0; }
    [[nodiscard]] std::int64_t first_t() const noexcept { return first_t_; }
    [[nodiscard]] std::int64_t last_t() const noexcept { return last_t_; }
    /// The space-time sample (every event when there were at most kSample).
    [[nodiscard]] std::span<const Event> sample() const noexcept { return sample_; }
    /// One event per pixel that fired: its newest (polarity ON when `on_only`), in time order.
    [[nodiscard]] std::vector<Event> newest(bool on_only) const {
        const std::vector<std::int64_t>& t = on_only ? newest_on_ : newest_;
        std::vector<Event> out;
        for (int y = 0; y < size_.height; ++y)
            for (int x = 0; x < size_.width; ++x) {
                const std::int64_t v = t[static_cast<std::size_t>(y) * size_.width + x];
                if (v != kNever)
                    out.push_back({v, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                                   static_cast<std::uint8_t>(on_only ? 1 : 0)});
            }
        std::stable_sort(out.begin(), out.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
        return out;
    }

private:
    static constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min();

    // Algorithm L (Li 1994): the position of the next event to enter the full sample.
    void skip() {
        w_ *= std::exp(std::log(unit_(rng_)) / static_cast<double>(kSample));
        next_ += static_cast<std::uint64_t>(std::floor(std::log(unit_(rng_)) / std::log1p(-w_))) + 1;
    }

    SensorSize size_;
    std::vector<std::int64_t> newest_, newest_on_;
    std::vector<Event> sample_;
    std::uint64_t seen_ = 0;
    std::mt19937_64 rng_{20170904};
    std::uniform_real_distribution<double> unit_{std::nextafter(0.0, 1.0), 1.0};
    std::uniform_int_distribution<std::size_t> pick_{0, kSample - 1};
    double w_ = std::exp(std::log(std::uniform_real_distribution<double>(std::nextafter(0.0, 1.0), 1.0)(rng_)) /
                         static_cast<double>(kSample));
    std::uint64_t next_ = kSample + static_cast<std::uint64_t>(std::floor(std::log(unit_(rng_)) / std::log1p(-w_)));
    std::int64_t first_t_ = kNever, last_t_ = kNever;
};

// One detector kind on one sequence: --repeat fresh detectors fed the same batches.
struct DetectorRuns {
    std::string name;
    std::vector<AnyDetector> detectors;
    std::vector<double> seconds;  ///< per detector: the sum of its batch calls
    std::vector<Event> corners;   ///< the first detector's corner events
    std::vector<std::unique_ptr<AsyncNms>> nms;  ///< per detector with NMS, else empty
    bool scored = false;          ///< the first detector runs scored (NMS, or a truth's PR curve)
    std::vector<double> scores;   ///< then: its corner events' scores
};

// One batch through detector `d` (scored when `score` is not empty), then NMS when given.
void detect_batch(AnyDetector& d, AsyncNms* nms, std::span<const Event> events, std::span<std::uint8_t> flags,
                  std::span<double> score) {
    if (score.empty()) {
        detect(d, events, flags);
        return;
    }
    std::visit(
        [&](auto& det) {
            if constexpr (ScoredDetector<std::remove_cvref_t<decltype(det)>>)
                detect(det, events, flags, score);
            else
                detect(det, events, flags);  // not reached: has_score() is checked first
        },
        d);
    if (nms) nms->filter(events, flags, score);
}

std::string cell(double v) { return std::isnan(v) ? "-" : fmt::format("{:.1f}", v); }

// Why a Table 1 FT cell is what it is, where the number alone misleads: keyed by
// (sequence, detector), e.g. "no track reached 30 inner corner events".
using FtNotes = std::map<std::pair<std::string, std::string>, std::string>;

std::string table1_text(const eval::Table1& t, bool markdown, const FtNotes& notes = {}) {
    std::string s;
    const auto note = [&](std::size_t r, std::size_t c) {
        const auto it = notes.find({t.sequences[r], t.detectors[c]});
        return it == notes.end() ? std::string() : it->second;
    };
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
            for (std::size_t c = 0; c < t.cells[r].size(); ++c) {
                const std::string why = note(r, c);
                s += fmt::format(" {} | {}{} |", cell(t.cells[r][c].reduction), cell(t.cells[r][c].ft),
                                 why.empty() ? "" : " (" + why + ")");
            }
            s += "\n";
        }
        return s;
    }
    s += fmt::format("{:<{}}", "", w);
    for (const auto& d : t.detectors) s += fmt::format("  {:>13}", d);
    s += fmt::format("\n{:<{}}", "sequence", w);
    for (std::size_t i = 0; i < t.detectors.size(); ++i) s += fmt::format("  {:>6} {:>6}", "Red.", "FT");
    s += "\n";
    // A noted FT cell gets a '*' and the reason below the table (the columns stay aligned).
    std::string footnotes;
    for (std::size_t r = 0; r < t.sequences.size(); ++r) {
        s += fmt::format("{:<{}}", t.sequences[r], w);
        for (std::size_t c = 0; c < t.cells[r].size(); ++c) {
            const std::string why = note(r, c);
            s += fmt::format("  {:>6} {:>6}", cell(t.cells[r][c].reduction),
                             cell(t.cells[r][c].ft) + (why.empty() ? "" : "*"));
            if (!why.empty()) footnotes += fmt::format("* {} {}: FT {}: {}\n", t.sequences[r], t.detectors[c],
                                                       cell(t.cells[r][c].ft), why);
        }
        s += "\n";
    }
    return s + footnotes;
}

std::string table2_text(const eval::Table2& t, bool markdown) {
    std::string s;
    if (markdown) {
        s += "| detector | time per event [us] | max. event rate [e/s] |\n|---|---:|---:|\n";
        for (const auto& r : t) s += fmt::format("| {} | {:.3f} | {:.0f} |\n", r.detector, r.us_per_event, r.max_event_rate);
        return s;
    }
    s += fmt::format("{:<18}  {:>20}  {:>22}\n", "detector", "time per event [us]", "max. event rate [e/s]");
    for (const auto& r : t)
        s += fmt::format("{:<18}  {:>20.3f}  {:>22.0f}\n", r.detector, r.us_per_event, r.max_event_rate);
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

// The paper's rows beside ours, for the sequences named as in the dataset (`base`: the
// sequence of each row); empty when none is.
std::string paper_comparison_md(const eval::Table1& t, const std::map<std::string, std::string>& base) {
    const auto col = [&](const std::string& d) {
        const auto it = std::find(t.detectors.begin(), t.detectors.end(), d);
        return it == t.detectors.end() ? std::size_t(-1) : static_cast<std::size_t>(it - t.detectors.begin());
    };
    const std::size_t h = col("harris"), e = col("efast");
    std::string s =
        "| sequence | Harris Red. (paper) | Harris Red. (ours) | Harris FT (paper) | Harris FT (ours) | "
        "eFAST Red. (paper) | eFAST Red. (ours) | eFAST FT (paper) | eFAST FT (ours) |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    bool any = false;
    for (std::size_t r = 0; r < t.sequences.size(); ++r) {
        const auto b = base.find(t.sequences[r]);
        const auto it = paper_table1().find(b == base.end() ? t.sequences[r] : b->second);
        if (it == paper_table1().end()) continue;
        any = true;
        const PaperRow& p = it->second;
        const auto ours = [&](std::size_t c, bool ft) {
            if (c == std::size_t(-1)) return std::string("-");
            return cell(ft ? t.cells[r][c].ft : t.cells[r][c].reduction);
        };
        s += fmt::format("| {} | {:.1f} | {} | {:.1f} | {} | {:.1f} | {} | {:.1f} | {} |\n", t.sequences[r],
                         p.harris_red, ours(h, false), p.harris_ft, ours(h, true), p.efast_red, ours(e, false),
                         p.efast_ft, ours(e, true));
    }
    return any ? s : std::string();
}

// One detector's precision and recall per speed bin, for the charts.
struct ChartSeriesPair {
    std::string name;
    std::vector<double> precision, recall;
};

// One detector on one sequence against its ground truth.
struct TruthRow {
    std::string sequence, detector;
    std::uint64_t events = 0, corners = 0, on_track = 0;
    double detect_s = 0;
    eval::TruthMatchResult m;
    eval::ErrorSummary err;
    eval::PrCurve pr;  ///< empty points when the detector ran unscored
};

std::string ap_cell(const TruthRow& r, int digits = 3) {
    return r.pr.points.empty() ? std::string("-") : fmt::format("{:.{}f}", r.pr.average_precision, digits);
}

std::string speed_bin_label(const eval::SpeedBin& b) {
    return std::isinf(b.hi) ? fmt::format("{:g}+", b.lo) : fmt::format("{:g}-{:g}", b.lo, b.hi);
}

double us_per_event(const TruthRow& r) {
    return r.events == 0 ? 0.0 : r.detect_s * 1e6 / static_cast<double>(r.events);
}

std::string truth_table_text(const std::vector<TruthRow>& rows, bool markdown, const FtNotes& notes = {}) {
    std::string s;
    const auto note = [&](const TruthRow& r) {
        const auto it = notes.find({r.sequence, r.detector});
        return it == notes.end() ? std::string() : it->second;
    };
    if (markdown) {
        s += "| sequence | detector | corner events | precision % | recall % | AP | loc. median px | loc. mean px | "
             "loc. p90 px | Red. % | smear /corner/ms | FT % | time/event us |\n"
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        for (const auto& r : rows)
            s += fmt::format("| {} | {} | {} | {:.1f} | {:.1f} | {} | {:.2f} | {:.2f} | {:.2f} | {:.1f} | {:.2f} | {} | "
                             "{:.3f} |\n",
                             r.sequence, r.detector, r.corners, r.m.precision(), r.m.recall(), ap_cell(r), r.err.median,
                             r.err.mean, r.err.p90, eval::reduction_rate(r.events, r.corners), r.m.smear(),
                             fmt::format("{:.1f}", eval::ft_percent(r.corners, r.on_track)) +
                                 (note(r).empty() ? "" : " (" + note(r) + ")"),
                             us_per_event(r));
        return s;
    }
    std::size_t w = 8;
    for (const auto& r : rows) w = std::max(w, r.sequence.size());
    s += fmt::format("{:<{}}  {:<18} {:>9} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6} {:>8}\n", "sequence", w,
                     "detector", "corners", "P %", "R %", "AP", "med px", "mean", "p90", "Red.%", "smear", "FT %",
                     "us/ev");
    std::string footnotes;  // a noted FT gets a '*' and its reason below the table
    for (const auto& r : rows) {
        const std::string ft = fmt::format("{:.1f}", eval::ft_percent(r.corners, r.on_track));
        s += fmt::format("{:<{}}  {:<18} {:>9} {:>6.1f} {:>6.1f} {:>6} {:>6.2f} {:>6.2f} {:>6.2f} {:>6.1f} {:>6.2f} {:>6} "
                         "{:>8.3f}\n",
                         r.sequence, w, r.detector, r.corners, r.m.precision(), r.m.recall(), ap_cell(r), r.err.median,
                         r.err.mean, r.err.p90, eval::reduction_rate(r.events, r.corners), r.m.smear(),
                         ft + (note(r).empty() ? "" : "*"), us_per_event(r));
        if (!note(r).empty()) footnotes += fmt::format("* {} {}: FT {}: {}\n", r.sequence, r.detector, ft, note(r));
    }
    return s + footnotes;
}

std::string truth_table_csv(const std::vector<TruthRow>& rows) {
    std::string s =
        "sequence,detector,events,corners,true_positives,precision_percent,truth_samples,recalled,recall_percent,"
        "loc_median_px,loc_mean_px,loc_p90_px,reduction_percent,ft_percent,us_per_event,average_precision,"
        "smear_per_corner_ms\n";
    for (const auto& r : rows)
        s += fmt::format("{},{},{},{},{},{:.4f},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.6f},{},{:.4f}\n",
                         r.sequence, r.detector, r.events, r.corners, r.m.true_positives, r.m.precision(),
                         r.m.truth_samples, r.m.recalled, r.m.recall(), r.err.median, r.err.mean, r.err.p90,
                         eval::reduction_rate(r.events, r.corners), eval::ft_percent(r.corners, r.on_track),
                         us_per_event(r), r.pr.points.empty() ? std::string() : ap_cell(r, 6), r.m.smear());
    return s;
}

nlohmann::json pr_json(const eval::PrCurve& c) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& p : eval::thin(c.points, 200))
        j.push_back({std::isinf(p.threshold) ? nlohmann::json(nullptr) : nlohmann::json(p.threshold), p.precision,
                     p.recall});
    return j;
}

// Per detector kind, the mean over the sequences of the truth table's figures.
std::string truth_summary_text(const std::vector<TruthRow>& rows, bool markdown) {
    std::vector<std::string> order;
    std::map<std::string, std::vector<const TruthRow*>> by;
    for (const auto& r : rows) {
        if (!by.count(r.detector)) order.push_back(r.detector);
        by[r.detector].push_back(&r);
    }
    std::string s = markdown ? "| detector | sequences | precision % | recall % | AP | loc. median px | Red. % | smear "
                               "/corner/ms |\n|---|---:|---:|---:|---:|---:|---:|---:|\n"
                             : fmt::format("{:<18} {:>5} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6}\n", "detector", "seqs",
                                           "P %", "R %", "AP", "med px", "Red.%", "smear");
    for (const auto& d : order) {
        const auto& v = by[d];
        double p = 0, r = 0, ap = 0, med = 0, red = 0, sm = 0;
        bool has_ap = true;
        for (const TruthRow* t : v) {
            p += t->m.precision();
            r += t->m.recall();
            has_ap = has_ap && !t->pr.points.empty();
            ap += t->pr.average_precision;
            med += t->err.median;
            red += eval::reduction_rate(t->events, t->corners);
            sm += t->m.smear();
        }
        const double n = static_cast<double>(v.size());
        const std::string apc = has_ap ? fmt::format("{:.3f}", ap / n) : std::string("-");
        s += markdown ? fmt::format("| {} | {} | {:.1f} | {:.1f} | {} | {:.2f} | {:.1f} | {:.2f} |\n", d, v.size(), p / n,
                                    r / n, apc, med / n, red / n, sm / n)
                      : fmt::format("{:<18} {:>5} {:>6.1f} {:>6.1f} {:>6} {:>6.2f} {:>6.1f} {:>6.2f}\n", d, v.size(),
                                    p / n, r / n, apc, med / n, red / n, sm / n);
    }
    return s;
}

// The PR curves, each thinned to at most 200 points (AP is of the whole curve).
std::string pr_curve_csv(const std::vector<TruthRow>& rows) {
    std::string s = "sequence,detector,threshold,precision_percent,recall_percent\n";
    for (const auto& r : rows)
        for (const auto& p : eval::thin(r.pr.points, 200))
            s += fmt::format("{},{},{:.9g},{:.4f},{:.4f}\n", r.sequence, r.detector, p.threshold, p.precision, p.recall);
    return s;
}

std::string truth_speed_csv(const std::vector<TruthRow>& rows) {
    std::string s = "sequence,detector,speed_lo,speed_hi,events,true_positives,precision_percent,samples,recalled,"
                    "recall_percent\n";
    for (const auto& r : rows)
        for (const auto& b : r.m.bins)
            s += fmt::format("{},{},{:g},{},{},{},{},{},{},{}\n", r.sequence, r.detector, b.lo,
                             std::isinf(b.hi) ? std::string("inf") : fmt::format("{:g}", b.hi), b.events,
                             b.true_positives,
                             b.events ? fmt::format("{:.4f}", 100.0 * b.true_positives / b.events) : std::string(),
                             b.samples, b.recalled,
                             b.samples ? fmt::format("{:.4f}", 100.0 * b.recalled / b.samples) : std::string());
    return s;
}

// Streams `truth` once past one matcher per detector; keeps, for the space-time figure,
// the visible corners every millisecond (at most StreamFigures::kSample points).
std::vector<eval::TruthMatchResult> match_against_truth(const fs::path& truth, const std::vector<DetectorRuns>& kinds,
                                                        const eval::TruthMatchParams& params, bool progress,
                                                        std::vector<Event>* tracks) {
    std::vector<eval::TruthMatcher> matchers;
    for (const DetectorRuns& k : kinds) matchers.emplace_back(k.corners, k.scores, params);
    sim::TruthReader reader(truth.string());
    std::vector<sim::TruthCorner> rows;
    Progress bar(progress, reader.bytes_total());
    std::uint64_t n = 0;
    std::int64_t next_keep = std::numeric_limits<std::int64_t>::min();
    while (reader.next_sample(rows)) {
        for (auto& m : matchers) m.add_sample(rows);
        n += rows.size();
        bar.update(reader.bytes_consumed(), n);
        if (tracks && rows.front().t_us >= next_keep) {
            next_keep = rows.front().t_us + 1000;
            for (const auto& r : rows)
                if (r.state == sim::CornerState::visible && tracks->size() < StreamFigures::kSample)
                    tracks->push_back({r.t_us, static_cast<std::uint16_t>(std::max(0.0, r.x)),
                                       static_cast<std::uint16_t>(std::max(0.0, r.y)), 1});
        }
    }
    std::vector<eval::TruthMatchResult> out;
    for (auto& m : matchers) out.push_back(m.finish());
    return out;
}

// ---- Tracking against GT tracks (--tracks; pipeline/track_eval.hpp) ----

// One output of the authors' HASTE app in a --tracks-golden folder: <tracker>.<init>.txt.gz.
struct GoldenRun {
    std::string tracker;  ///< our name of it (haste_correlation_star -> haste-correlation-star)
    std::string init;     ///< centered, uncentered
    fs::path file;
};

std::vector<GoldenRun> golden_runs(const fs::path& dir) {
    std::vector<GoldenRun> runs;
    for (const auto& d : fs::directory_iterator(dir)) {
        std::string name = d.path().filename().string();
        if (!d.is_regular_file()) continue;
        for (const char* ext : {".txt.gz", ".txt.zst", ".txt"})
            if (name.ends_with(ext)) {
                name.resize(name.size() - std::string_view(ext).size());
                const auto dot = name.rfind('.');
                if (dot == std::string::npos) break;
                std::string tracker = name.substr(0, dot);
                std::replace(tracker.begin(), tracker.end(), '_', '-');
                const std::string init = name.substr(dot + 1);
                if (init == "centered" || init == "uncentered") runs.push_back({tracker, init, d.path()});
                break;
            }
    }
    std::sort(runs.begin(), runs.end(), [](const GoldenRun& a, const GoldenRun& b) {
        return std::tie(a.tracker, a.init) < std::tie(b.tracker, b.init);
    });
    return runs;
}


std::string fixed(double v, int digits) { return std::isfinite(v) ? fmt::format("{:.{}f}", v, digits) : "-"; }

std::string tracking_table_text(const std::vector<pipeline::TrackEvalRow>& rows, bool markdown) {
    std::string s;
    if (markdown) {
        s += "| sequence | tracker | seeding | FA | EFA | FA@5 | TE@5 px | FA async | tracks counted | unmatched | "
             "predicted | GT tracks | ns/update |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        for (const auto& r : rows)
            s += fmt::format("| {} | {} | {} | {:.3f} | {:.3f} | {:.3f} | {:.2f} | {:.3f} | {} | {} | {} | {} | {} |\n",
                             r.sequence, r.tracker, r.seeding, r.fa, r.efa, r.fa_5, r.te_5, r.fa_async,
                             r.counted_tracks, r.unmatched_tracks, r.predicted_tracks, r.gt_tracks,
                             fixed(r.ns_per_update, 0));
        return s;
    }
    std::size_t ws = 8, wt = 7, wd = 7;
    for (const auto& r : rows) {
        ws = std::max(ws, r.sequence.size());
        wt = std::max(wt, r.tracker.size());
        wd = std::max(wd, r.seeding.size());
    }
    s += fmt::format("{:<{}}  {:<{}}  {:<{}}  {:>6} {:>6} {:>6} {:>7} {:>8} {:>7} {:>9} {:>10}\n", "sequence", ws,
                     "tracker", wt, "seeding", wd, "FA", "EFA", "FA@5", "TE@5 px", "FA async", "counted", "unmatched",
                     "ns/update");
    for (const auto& r : rows)
        s += fmt::format("{:<{}}  {:<{}}  {:<{}}  {:>6.3f} {:>6.3f} {:>6.3f} {:>7.2f} {:>8.3f} {:>7} {:>9} {:>10}\n",
                         r.sequence, ws, r.tracker, wt, r.seeding, wd, r.fa, r.efa, r.fa_5, r.te_5, r.fa_async,
                         r.counted_tracks, r.unmatched_tracks, fixed(r.ns_per_update, 0));
    return s;
}

// Per tracker and seeding, the mean over the sequences (the benchmark's tables end so).
std::string tracking_mean_text(const std::vector<pipeline::TrackEvalRow>& rows, bool markdown) {
    std::vector<std::pair<std::string, std::string>> order;
    std::map<std::pair<std::string, std::string>, std::vector<const pipeline::TrackEvalRow*>> by;
    for (const auto& r : rows) {
        const auto key = std::make_pair(r.tracker, r.seeding);
        if (!by.count(key)) order.push_back(key);
        by[key].push_back(&r);
    }
    std::size_t wt = 7, wd = 7;
    for (const auto& [t, d] : order) {
        wt = std::max(wt, t.size());
        wd = std::max(wd, d.size());
    }
    std::string s = markdown ? "| tracker | seeding | sequences | FA | EFA | FA@5 | TE@5 px | FA async |\n"
                               "|---|---|---:|---:|---:|---:|---:|---:|\n"
                             : fmt::format("{:<{}}  {:<{}}  {:>4} {:>6} {:>6} {:>6} {:>7} {:>8}\n", "tracker", wt,
                                           "seeding", wd, "seqs", "FA", "EFA", "FA@5", "TE@5 px", "FA async");
    for (const auto& key : order) {
        const auto& v = by[key];
        double fa = 0, efa = 0, fa5 = 0, te5 = 0, fas = 0;
        for (const auto* r : v) {
            fa += r->fa;
            efa += r->efa;
            fa5 += r->fa_5;
            te5 += r->te_5;
            fas += r->fa_async;
        }
        const double n = static_cast<double>(v.size());
        s += markdown ? fmt::format("| {} | {} | {} | {:.3f} | {:.3f} | {:.3f} | {:.2f} | {:.3f} |\n", key.first,
                                    key.second, v.size(), fa / n, efa / n, fa5 / n, te5 / n, fas / n)
                      : fmt::format("{:<{}}  {:<{}}  {:>4} {:>6.3f} {:>6.3f} {:>6.3f} {:>7.2f} {:>8.3f}\n", key.first,
                                    wt, key.second, wd, v.size(), fa / n, efa / n, fa5 / n, te5 / n, fas / n);
    }
    return s;
}

nlohmann::json tracking_row_json(const pipeline::TrackEvalRow& r, bool authors) {
    static constexpr const char* kinds[] = {"gt", "detector", "seeds"};
    return {{"sequence", r.sequence},
            {"tracker", r.tracker},
            {"seeding", r.seeding},
            {"seeding_kind", kinds[static_cast<int>(r.kind)]},
            {"source", authors ? "the authors' HASTE app" : "evcorner"},
            {"fa", r.fa},
            {"efa", r.efa},
            {"fa_5", r.fa_5},
            {"te_5", r.te_5},
            {"fa_async", r.fa_async},
            {"predicted_tracks", r.predicted_tracks},
            {"gt_tracks", r.gt_tracks},
            {"counted_tracks", r.counted_tracks},
            {"skipped_tracks", r.skipped_tracks},
            {"unmatched_tracks", r.unmatched_tracks},
            {"unseeded_tracks", r.unseeded_tracks},
            {"states", r.states},
            {"updates", r.updates},
            {"ns_per_update", std::isfinite(r.ns_per_update) ? nlohmann::json(r.ns_per_update) : nlohmann::json(nullptr)},
            {"track_s", r.track_s},
            {"gt_rate_hz", r.gt_rate_hz}};
}

// What the tracking table is: the protocol, one item a line, for the report and the standard output.
std::vector<std::string> tracking_protocol(const std::vector<std::string>& detectors, const std::string& gt_rate,
                                           bool golden, const std::string& unseeded) {
    std::string dets;
    for (const auto& d : detectors) dets += (dets.empty() ? "" : ", ") + d;
    std::vector<std::string> lines{
        "Metric: the feature-track benchmark's (Messikommer et al., CVPR 2023; docs/tracking-metrics.md), "
        "synchronous mode (the GT cut to each track's span); thresholds 1..31 px; FA async: the asynchronous "
        "variant (a track holds its last position to the GT's end).",
        "GT: NAME.gt-tracks.txt beside the events (every visible truth corner as a track, a new id per visible "
        "stretch), sampled at " + gt_rate + " Hz, pixel-index convention (pixel u spans u-0.5..u+0.5, as the "
        "trackers report).",
        "Seeding GT t0: each GT track's first sample seeds the tracker under its id (uncentered start, no "
        "stopping rule beyond the tracker's); scored by id, without the start shift. A GT track starting within "
        "half a pixel of the border (off [0, W) x [0, H), where the trackers refuse a seed) is not seeded and, "
        "having no prediction, counts nowhere, as in the benchmark" + unseeded + ".",
        "Seeding " + (dets.empty() ? std::string("DETECTOR") : dets) +
            ": the detector's corner events seed the tracks (the front end of evcorner track -d: seed radius "
            "10 px, at most 200 tracks, centered start, max idle 200 ms, min separation 3 px); scored by "
            "association: in order of their first time, each track takes the nearest GT track not yet taken "
            "within 3 px of its first position at its first time and is measured against it from then on; a "
            "track with none in reach is unmatched and counted nowhere."};
    if (golden)
        lines.push_back("Seedings golden seeds (uncentered, centered): the seeds.txt of --tracks-golden, HASTE's start "
                        "either way, for our trackers and the authors' HASTE app alike; each track is scored against "
                        "the GT track nearest its seed (within 1 px) from the seed's time on.");
    lines.push_back("ns/update: tracking time per (event, track) pair processed, one thread.");
    return lines;
}

void run_eval(EvalOptions& o) {
    finish_feature_track_params(o.params, o.overlap);
    const std::vector<std::string> detectors = parse_detector_list(o.detectors);
    check_params_taken(detectors, o.detector_params, "--");
    if (o.nms && o.compare_nms) throw CLI::ValidationError("--nms and --compare-nms: give one of them");
    std::optional<NmsParams> nms;
    if (o.nms || o.compare_nms) {
        o.nms_params.rule = parse_nms_rule(o.nms_rule);
        check_nms_params(o.nms_params);
        nms = o.nms_params;
    }
    std::vector<EvalKind> configs;
    for (const auto& d : detectors) {
        DetectorConfig c = config_for(d, o.detector_params);
        check_detector_config(c, "--");
        if (nms && !detector_info(d).has_score)
            throw std::invalid_argument("--nms: detector '" + d + "' has no score to suppress by");
        if (!o.nms) configs.push_back({c, std::nullopt, d});
        if (nms) configs.push_back({c, nms, d + "+nms"});
    }
    std::vector<std::string> trackers;
    if (o.tracks) {
        try {
            trackers = tracker_list(std::span(&o.trackers, 1));
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(std::string("--trackers: ") + e.what());
        }
        if (!o.tracks_golden.empty() && !fs::is_regular_file(fs::path(o.tracks_golden) / "seeds.txt"))
            throw std::invalid_argument("--tracks-golden: " + o.tracks_golden + " holds no seeds.txt");
    }
    std::vector<Sequence> seqs = find_sequences(o.inputs);
    o.match.credit = eval::parse_credit(o.credit);
    o.match.interpolation = eval::parse_interpolation(o.interpolation);
    if (!o.speed_edges.empty()) o.match.speed_edges = o.speed_edges;
    eval::validate(o.match);
    if (!o.truth.empty()) {
        if (seqs.size() != 1)
            throw std::invalid_argument("--truth: give exactly one event file (got " + std::to_string(seqs.size()) +
                                        " sequences); a suite folder finds each scene's truth beside its events");
        seqs[0].truth = o.truth;
    }
    std::vector<TruthRow> truth_rows;
    fs::path fig_dir;
    if (!o.report.empty()) {
        // The report's files must not land on an input (--report pointing into the data).
        std::vector<io::NamedPath> inputs, outputs;
        for (const Sequence& seq : seqs) inputs.push_back({"INPUTS", seq.file.string()});
        for (const Sequence& seq : seqs)
            if (!seq.truth.empty()) inputs.push_back({"--truth", seq.truth.string()});
        for (const char* name : {"table1.csv", "table2.csv", "results.json", "report.md", "truth_table.csv",
                                 "truth_speed.csv", "pr_curve.csv"})
            outputs.push_back({"--report", (fs::path(o.report) / name).string()});
        io::check_output_paths(inputs, outputs);
        io::check_output_folder({"--report", o.report});
        fs::create_directories(o.report);
        if (!o.no_figures) fs::create_directories(fig_dir = fs::path(o.report) / "figures");
    }
    std::vector<eval::RunRecord> runs;
    nlohmann::json jruns = nlohmann::json::array();
    FtNotes ft_notes;
    std::string figures_md, truth_figures_md, speed_figures_md, pr_figures_md;
    const render::FigureFormat fig_format = render::parse_figure_format(o.figure_format);
    const std::string ext(render::figure_extension(fig_format));
    // figures/<name><ext>, in the --figure-format.
    const auto save_figure = [&](const std::string& name, const render::Canvas& c) {
        c.write((fig_dir / (name + ext)).string(), fig_format);
    };
    const auto sensor_figure = [&](const render::RgbImage& body, SensorSize size, int scale,
                                   std::vector<std::string> title, std::vector<render::LegendEntry> legend) {
        render::FigureFrame f;
        f.title = std::move(title);
        f.legend = std::move(legend);
        return render::frame_sensor_figure(body, size, scale, f).figure;
    };
    const auto space_time_figure = [&](std::span<const Event> events, std::span<const Event> corners,
                                       std::span<const std::uint8_t> labels, SensorSize size, std::int64_t t0,
                                       std::int64_t t1, std::vector<std::string> title,
                                       std::vector<render::LegendEntry> legend) {
        render::FigureFrame f;
        f.title = std::move(title);
        f.legend = std::move(legend);
        const render::RgbImage body = render::render_space_time(events, corners, labels, size, t0, t1);
        return render::frame_space_time_figure(body, size, t0, t1, {}, f).figure;
    };
    const auto interval = [](std::int64_t t0, std::int64_t t1) {
        return fmt::format("t = {:.6f} s to {:.6f} s", static_cast<double>(t0) * 1e-6, static_cast<double>(t1) * 1e-6);
    };
    const render::Rgb event_grey{185, 185, 185};
    const bool show_progress = !o.quiet && !o.no_progress;
    std::vector<Event> batch(kBatch);
    std::vector<std::uint8_t> flags(kBatch);
    std::vector<double> scores(kBatch);
    for (const auto& seq : seqs) {
        InputOptions in = o.in;
        if (in.size.empty()) in.size = scene_sensor_beside(seq);
        const auto reader = open_events(seq.file.string(), in);
        const SensorSize size = sensor_of(*reader);
        std::vector<DetectorRuns> kinds;
        for (const EvalKind& kind : configs) {
            DetectorRuns k{kind.name, {}, std::vector<double>(static_cast<std::size_t>(o.repeat), 0.0), {}, {}, false, {}};
            for (int rep = 0; rep < o.repeat; ++rep) {
                k.detectors.push_back(make_detector(kind.config, size, "--"));
                if (kind.nms) k.nms.push_back(std::make_unique<AsyncNms>(size, *kind.nms));
            }
            // Scores for NMS, and for the PR curve against a truth.
            k.scored = has_score(k.detectors.front()) && (kind.nms || !seq.truth.empty());
            kinds.push_back(std::move(k));
        }
        std::unique_ptr<StreamFigures> figs;
        if (!fig_dir.empty()) figs = std::make_unique<StreamFigures>(size);
        if (!o.quiet) fmt::print(stderr, "eval: {}: reading {} and detecting\n", seq.name, seq.file.string());
        std::uint64_t n_events = 0;
        {
            Progress bar(show_progress, reader->bytes_total());
            for (;;) {
                const std::size_t n = reader->read(batch);
                if (n == 0 && reader->skipped_in_batch().empty()) break;
                const std::span<const Event> events(batch.data(), n);
                for (DetectorRuns& k : kinds) {
                    for (std::size_t rep = 0; rep < k.detectors.size(); ++rep) {
                        // Timed: the detector's batch call (and NMS's) only. With NMS every run
                        // is scored; without, only the first when a truth wants its scores.
                        const bool scored = k.scored && (!k.nms.empty() || rep == 0);
                        const std::span<double> sc = scored ? std::span<double>(scores.data(), n) : std::span<double>();
                        const auto t0 = Clock::now();
                        detect_batch(k.detectors[rep], k.nms.empty() ? nullptr : k.nms[rep].get(), events,
                                     std::span<std::uint8_t>(flags.data(), n), sc);
                        k.seconds[rep] += std::chrono::duration<double>(Clock::now() - t0).count();
                        if (rep == 0)
                            for (std::size_t i = 0; i < n; ++i)
                                if (flags[i]) {
                                    k.corners.push_back(events[i]);
                                    if (scored) k.scores.push_back(scores[i]);
                                }
                    }
                }
                if (figs) figs->add(events);
                n_events += n;
                bar.update(reader->bytes_consumed(), n_events);
            }
        }
        std::vector<eval::TruthMatchResult> matched;
        std::vector<Event> truth_tracks;
        if (!seq.truth.empty()) {
            if (!o.quiet) fmt::print(stderr, "eval: {}: matching against {}\n", seq.name, seq.truth.string());
            matched = match_against_truth(seq.truth, kinds, o.match, show_progress, figs ? &truth_tracks : nullptr);
        }
        if (!o.quiet) fmt::print(stderr, "eval: {}: {} events; labelling\n", seq.name, n_events);
        std::vector<ChartSeriesPair> speed_series;
        std::vector<render::ChartSeries> pr_series;
        const std::vector<double> recall_levels = [] {
            std::vector<double> v;
            for (int r = 0; r <= 100; r += 5) v.push_back(r);
            return v;
        }();
        for (DetectorRuns& k : kinds) {
            k.detectors.clear();  // their state is no longer needed
            k.nms.clear();
            std::vector<Event>& corners = k.corners;
            const auto l0 = Clock::now();
            eval::FeatureTrackResult labels;
            {
                Progress bar(show_progress, corners.size());
                labels = eval::label_feature_tracks(corners, o.params,
                                                    [&](std::size_t done, std::size_t) { bar.update(done, done); });
            }
            const double label_s = std::chrono::duration<double>(Clock::now() - l0).count();
            eval::RunRecord r{seq.name, k.name, n_events, corners.size(), labels.labelled, eval::median(k.seconds)};
            runs.push_back(r);
            // FT 0 says nothing by itself: no corners, or none on an accepted track.
            std::string ft_note;
            if (corners.empty())
                ft_note = "no corner events";
            else if (labels.accepted == 0)
                ft_note = fmt::format("no track reached {} inner corner events with outer <= {} x inner",
                                      o.params.min_inner, o.params.max_outer_ratio);
            if (!ft_note.empty()) ft_notes[{seq.name, k.name}] = ft_note;
            nlohmann::json jtruth;
            if (!matched.empty()) {
                TruthRow tr{seq.name, k.name, n_events, corners.size(), labels.labelled, r.detect_s,
                            std::move(matched[static_cast<std::size_t>(&k - kinds.data())]), {}, {}};
                tr.err = eval::summarize_errors(tr.m.errors);
                if (k.scored) {
                    tr.pr = eval::pr_curve(k.scores, tr.m.is_true, tr.m.recalled_best, tr.m.truth_samples);
                    pr_series.push_back({k.name, render::series_colour(pr_series.size()),
                                         eval::precision_at_recall(tr.pr.points, recall_levels)});
                }
                tr.m.recalled_best = {};
                std::vector<double>().swap(k.scores);
                nlohmann::json jbins = nlohmann::json::array();
                ChartSeriesPair sp{k.name, {}, {}};
                for (const auto& b : tr.m.bins) {
                    jbins.push_back({{"speed_lo", b.lo},
                                     {"speed_hi", std::isinf(b.hi) ? nlohmann::json(nullptr) : nlohmann::json(b.hi)},
                                     {"events", b.events},
                                     {"true_positives", b.true_positives},
                                     {"samples", b.samples},
                                     {"recalled", b.recalled}});
                    sp.precision.push_back(b.events ? 100.0 * b.true_positives / b.events : std::nan(""));
                    sp.recall.push_back(b.samples ? 100.0 * b.recalled / b.samples : std::nan(""));
                }
                speed_series.push_back(std::move(sp));
                jtruth = {{"file", seq.truth.string()},
                          {"true_positives", tr.m.true_positives},
                          {"precision_percent", tr.m.precision()},
                          {"truth_samples", tr.m.truth_samples},
                          {"recalled", tr.m.recalled},
                          {"recall_percent", tr.m.recall()},
                          {"loc_median_px", tr.err.median},
                          {"loc_mean_px", tr.err.mean},
                          {"loc_p90_px", tr.err.p90},
                          {"smear_per_corner_ms", tr.m.smear()},
                          {"average_precision",
                           tr.pr.points.empty() ? nlohmann::json(nullptr) : nlohmann::json(tr.pr.average_precision)},
                          {"pr_curve", pr_json(tr.pr)},
                          {"speed_bins", jbins}};
                if (figs && !figs->empty()) {
                    const std::string stem = seq.stem + "." + k.name;
                    save_figure(stem + ".loc_error",
                                render::render_histogram(seq.name + " " + k.name + ": localisation error of the " +
                                                             std::to_string(tr.m.true_positives) + " true positives",
                                                         tr.m.errors, 0.0, o.match.radius, 14,
                                                         "distance to the nearest truth corner [px]",
                                                         "true positives", k.name + " true positives"));
                    const std::int64_t t0 = figs->first_t(), t1 = std::max(figs->last_t(), figs->first_t() + 1);
                    save_figure(stem + ".truth_space_time",
                                space_time_figure(truth_tracks, corners, tr.m.is_true, size, t0, t1,
                                                  {seq.name + " " + k.name + ": corner events against the truth",
                                                   interval(t0, t1)},
                                                  {{event_grey, "truth corner (every ms)"},
                                                   {render::kOnTrack, "true corner event"},
                                                   {render::kOffTrack, "false corner event"}}));
                    truth_figures_md += fmt::format(
                        "| {} | {} | ![](figures/{}.loc_error{}) | ![](figures/{}.truth_space_time{}) |\n",
                        seq.name, k.name, stem, ext, stem, ext);
                }
                tr.m.errors = {};
                tr.m.is_true = {};
                truth_rows.push_back(std::move(tr));
            }
            jruns.push_back({{"sequence", r.sequence},
                             {"file", seq.file.string()},
                             {"detector", r.detector},
                             {"events", r.events},
                             {"corners", r.corners},
                             {"on_track", r.on_track},
                             {"reduction_percent", eval::reduction_rate(r.events, r.corners)},
                             {"ft_percent", eval::ft_percent(r.corners, r.on_track)},
                             {"detect_s_median", r.detect_s},
                             {"detect_s_runs", k.seconds},
                             {"tracks_accepted", labels.accepted},
                             {"hypotheses", labels.hypotheses},
                             {"label_s", label_s},
                             {"truth", jtruth}});
            if (!ft_note.empty()) jruns.back()["ft_note"] = ft_note;
            if (figs && !figs->empty()) {
                const std::int64_t t_first = figs->first_t(), t_last = figs->last_t();
                const std::string stem = seq.stem + "." + k.name;
                save_figure(stem + ".corners",
                            sensor_figure(render::upscale(render::render_recent_corners(figs->newest(false), corners,
                                                                                        size, t_last),
                                                          2),
                                          size, 2,
                                          {seq.name + " " + k.name + ": corner events (Fig. 6)",
                                           fmt::format("t = {:.6f} s; events of the last 33 ms, corners of the last "
                                                       "33 ms bright, 33 to 100 ms dark",
                                                       static_cast<double>(t_last) * 1e-6)},
                                          {{{150, 150, 150}, "event"},
                                           {render::kOnBright, "ON corner, last 33 ms"},
                                           {render::kOnDark, "ON corner, 33 to 100 ms"},
                                           {render::kOffBright, "OFF corner, last 33 ms"},
                                           {render::kOffDark, "OFF corner, 33 to 100 ms"}}));
                const std::int64_t t1 = std::max(t_last, t_first + 1);
                save_figure(stem + ".labels",
                            space_time_figure(figs->sample(), corners, labels.on_track, size, t_first, t1,
                                              {seq.name + " " + k.name +
                                                   ": corner events labelled by feature tracks (Fig. 5b)",
                                               interval(t_first, t1) + "; FT " +
                                                   cell(eval::ft_percent(corners.size(), labels.labelled)) + " %" +
                                                   (ft_note.empty() ? "" : " (" + ft_note + ")")},
                                              {{event_grey, "event"},
                                               {render::kOnTrack, "corner event on a feature track"},
                                               {render::kOffTrack, "corner event on no track"}}));
                figures_md += fmt::format("| {} | {} | ![](figures/{}.corners{}) | ![](figures/{}.labels{}) |\n",
                                          seq.name, k.name, stem, ext, stem, ext);
            }
            if (&k != &kinds.front()) std::vector<Event>().swap(corners);  // the first detector's draw Fig. 1b
        }
        if (!pr_series.empty() && !fig_dir.empty()) {
            std::vector<std::string> cats;
            for (const double r : recall_levels) cats.push_back(fmt::format("{:g}", r));
            save_figure(seq.stem + ".pr",
                        render::render_line_chart(seq.name + ": precision (interpolated) against recall", cats,
                                                  pr_series, 100, "recall [%]", "precision [%]"));
            pr_figures_md += fmt::format("| {} | ![](figures/{}.pr{}) |\n", seq.name, seq.stem, ext);
        }
        if (!speed_series.empty() && !fig_dir.empty()) {
            std::vector<std::string> cats;
            for (const auto& b : truth_rows.back().m.bins) cats.push_back(speed_bin_label(b));
            std::vector<render::ChartSeries> ps, rs;
            for (std::size_t i = 0; i < speed_series.size(); ++i) {
                ps.push_back({speed_series[i].name, render::series_colour(i), speed_series[i].precision});
                rs.push_back({speed_series[i].name, render::series_colour(i), speed_series[i].recall});
            }
            save_figure(seq.stem + ".precision_speed",
                        render::render_line_chart(seq.name + ": precision against image speed", cats, ps, 100,
                                                  "image speed [px/s]", "precision [%]"));
            save_figure(seq.stem + ".recall_speed",
                        render::render_line_chart(seq.name + ": recall against image speed", cats, rs, 100,
                                                  "image speed [px/s]", "recall [%]"));
            speed_figures_md += fmt::format("| {} | ![](figures/{}.precision_speed{}) | ![](figures/{}.recall_speed{}) |\n",
                                            seq.name, seq.stem, ext, seq.stem, ext);
        }
        if (figs && !figs->empty()) {
            const std::int64_t t_first = figs->first_t(), t_last = figs->last_t();
            {
                render::FigureFrame f;
                f.title = {seq.name + ": SAE of the ON events (Fig. 2b)",
                           fmt::format("t = {:.6f} s", static_cast<double>(t_last) * 1e-6)};
                f.grey_ramp = true;
                f.ramp = {"age of the newest ON event:", "0",
                          fmt::format("{:.6f} s or never", static_cast<double>(t_last - t_first) * 1e-6)};
                save_figure(seq.stem + ".sae",
                            render::frame_sensor_figure(
                                render::upscale(render::render_sae(figs->newest(true), size, 1, t_last,
                                                                   std::max<std::int64_t>(1, t_last - t_first)),
                                                2),
                                size, 2, f)
                                .figure);
            }
            const std::int64_t t1 = std::max(t_last, t_first + 1);
            save_figure(seq.stem + ".space_time",
                        space_time_figure(figs->sample(), kinds.front().corners, {}, size, t_first, t1,
                                          {seq.name + " " + kinds.front().name +
                                               ": events and corner events in space-time (Fig. 1b)",
                                           interval(t_first, t1)},
                                          {{event_grey, "event"},
                                           {render::kOnBright, "ON corner event"},
                                           {render::kOffBright, "OFF corner event"}}));
        }
    }
    // Trackers against the GT tracks beside the sequences (--tracks): the library runs them.
    std::vector<pipeline::TrackEvalRow> track_rows, golden_rows;
    std::vector<std::string> without_gt_tracks;
    std::string golden_note, gt_rate;
    if (o.tracks) {
        std::vector<pipeline::TrackSeeding> seedings{pipeline::gt_seeding()};
        for (const auto& d : detectors) seedings.push_back(pipeline::detector_seeding(config_for(d, o.detector_params)));
        std::set<double> rates;
        std::string shapes_name;
        fs::path shapes_gt;
        for (const Sequence& seq : seqs) {
            const fs::path gt = gt_tracks_beside(seq.file);
            if (gt.empty()) {
                without_gt_tracks.push_back(seq.name);
                continue;
            }
            pipeline::TrackEvalFiles f;
            f.sequence = seq.name;
            f.events = seq.file.string();
            f.format = o.in.format;
            f.reader = o.in.reader;
            const std::string size = o.in.size.empty() ? scene_sensor_beside(seq) : o.in.size;
            if (!size.empty()) f.reader.sensor = parse_sensor_size(size);
            f.gt = gt.string();
            std::vector<pipeline::TrackSeeding> these = seedings;
            const bool golden = !o.tracks_golden.empty() && seq.base == "shapes" && shapes_name.empty();
            if (golden) {
                // Our trackers from the authors' seeds, both starts: each authors' row has its twin.
                const std::string seeds = (fs::path(o.tracks_golden) / "seeds.txt").string();
                these.push_back(pipeline::seeds_seeding(seeds, "golden seeds (uncentered)", HasteInit::uncentered));
                these.push_back(pipeline::seeds_seeding(seeds, "golden seeds (centered)", HasteInit::centered));
                shapes_name = seq.name;
                shapes_gt = gt;
            }
            if (!o.quiet)
                fmt::print(stderr, "eval: {}: tracking against {} ({} trackers x {} seedings)\n", seq.name, gt.string(),
                           trackers.size(), these.size());
            const auto rows = pipeline::evaluate_trackers(f, trackers, these, {}, [&](const pipeline::TrackEvalRow& r) {
                if (!o.quiet)
                    fmt::print(stderr, "eval: {}: {} / {}: FA {:.3f}, {} tracks counted ({:.1f} s)\n", r.sequence,
                               r.tracker, r.seeding, r.fa, r.counted_tracks, r.track_s);
            });
            for (const auto& r : rows) {
                if (r.gt_rate_hz > 0) rates.insert(std::round(r.gt_rate_hz * 1000) / 1000);
                track_rows.push_back(r);
            }
        }
        if (!o.tracks_golden.empty()) {
            if (shapes_name.empty()) {
                golden_note = "--tracks-golden " + o.tracks_golden +
                              ": no `shapes` scene with GT tracks among the inputs, so the authors' outputs are not scored";
                fmt::print(stderr, "eval: {}\n", golden_note);
            } else {
                const std::string seeds = (fs::path(o.tracks_golden) / "seeds.txt").string();
                for (const GoldenRun& g : golden_runs(o.tracks_golden)) {
                    pipeline::TrackEvalRow r = pipeline::evaluate_track_file(g.file.string(), shapes_gt.string(), seeds);
                    r.sequence = shapes_name;
                    r.tracker = "authors' " + g.tracker;
                    r.seeding = "golden seeds (" + g.init + ")";
                    golden_rows.push_back(std::move(r));
                }
                if (golden_rows.empty())
                    golden_note = "--tracks-golden " + o.tracks_golden + ": no <tracker>.<init>.txt.gz output inside";
            }
        }
        for (const double r : rates) gt_rate += (gt_rate.empty() ? "" : ", ") + fmt::format("{:g}", r);
        if (gt_rate.empty()) gt_rate = "?";
    }
    const eval::Table1 t1 = eval::make_table1(runs);
    const eval::Table2 t2 = eval::make_table2(runs);
    fmt::print("Table 1: reduction rate (Red.) and corners on feature tracks (FT), %\n{}\n", table1_text(t1, false, ft_notes));
    fmt::print("Table 2: detection time per event (median of {} runs) and max. event rate\n{}", o.repeat,
               table2_text(t2, false));
    const std::string match_rule = fmt::format(
        "a corner event (pixel centre) is true when a visible truth corner lies within {} px of it at its time "
        "(truth interpolated: {}); recall: visible truth samples with a matching corner event within {} us; "
        "an event near several corners credits {} (docs/evaluation.md)",
        o.match.radius, eval::to_string(o.match.interpolation), o.match.tolerance_us,
        o.match.credit == eval::Credit::all ? "all of them" : "the nearest");
    if (!truth_rows.empty()) {
        fmt::print("\nAgainst ground truth: {}\n{}", match_rule, truth_table_text(truth_rows, false, ft_notes));
        fmt::print("\nMean over the sequences (AP: average precision of the score's PR curve, docs/evaluation.md; "
                   "smear: true corner events per visible truth corner per ms)\n{}",
                   truth_summary_text(truth_rows, false));
    }
    std::map<std::string, std::size_t> unseeded_by_sequence;  // the GT t0 rows of a sequence all say the same
    for (const auto& r : track_rows)
        if (r.kind == pipeline::SeedingKind::gt && r.unseeded_tracks > 0) unseeded_by_sequence[r.sequence] = r.unseeded_tracks;
    std::string unseeded_text;
    for (const auto& [name, n] : unseeded_by_sequence)
        unseeded_text += fmt::format("{}{} {}", unseeded_text.empty() ? "" : ", ", name, n);
    unseeded_text = unseeded_text.empty() ? " (none here)" : " (not seeded: " + unseeded_text + ")";
    std::vector<pipeline::TrackEvalRow> all_track_rows = track_rows;
    all_track_rows.insert(all_track_rows.end(), golden_rows.begin(), golden_rows.end());
    std::string no_gt_text;
    for (const auto& n : without_gt_tracks) no_gt_text += (no_gt_text.empty() ? "" : ", ") + n;
    const std::vector<std::string> protocol =
        o.tracks ? tracking_protocol(detectors, gt_rate, !golden_rows.empty(), unseeded_text) : std::vector<std::string>();
    if (o.tracks) {
        fmt::print("\nTracking against GT tracks\n");
        for (const auto& line : protocol) fmt::print("  {}\n", line);
        if (!all_track_rows.empty())
            fmt::print("{}\nMean over the sequences\n{}", tracking_table_text(all_track_rows, false),
                       tracking_mean_text(all_track_rows, false));
        if (!without_gt_tracks.empty()) fmt::print("Without GT tracks (not tracked): {}\n", no_gt_text);
        if (!golden_note.empty()) fmt::print("{}\n", golden_note);
    }
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
    if (!truth_rows.empty()) {
        write_file(dir / "truth_table.csv", truth_table_csv(truth_rows));
        write_file(dir / "truth_speed.csv", truth_speed_csv(truth_rows));
        write_file(dir / "pr_curve.csv", pr_curve_csv(truth_rows));
        nlohmann::json edges = o.match.speed_edges;
        j["truth_match"] = {{"radius_px", o.match.radius},
                            {"tolerance_us", o.match.tolerance_us},
                            {"credit", std::string(eval::to_string(o.match.credit))},
                            {"interpolation", std::string(eval::to_string(o.match.interpolation))},
                            {"speed_edges", edges}};
    }
    if (nms) {
        j["nms"] = {{"rule", nms_rule_name(nms->rule)},
                    {"radius", nms->radius},
                    {"time_us", nms->time_us},
                    {"compare", o.compare_nms}};
    }
    if (o.tracks) {
        nlohmann::json rows = nlohmann::json::array();
        for (const auto& r : track_rows) rows.push_back(tracking_row_json(r, false));
        for (const auto& r : golden_rows) rows.push_back(tracking_row_json(r, true));
        j["tracking"] = {{"mode", "synchronous"},
                         {"thresholds_px", 31},
                         {"association_radius_px", 3},
                         {"seeds_radius_px", 1},
                         {"protocol", protocol},
                         {"trackers", trackers},
                         {"golden", o.tracks_golden.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.tracks_golden)},
                         {"rows", rows},
                         {"without_gt_tracks", without_gt_tracks}};
        if (!golden_note.empty()) j["tracking"]["golden_note"] = golden_note;
    }
    write_file(dir / "results.json", j.dump(2) + "\n");
    std::string md = "# evcorner evaluation\n\n";
    md += fmt::format(
        "Feature tracks: inner {} px, outer {} px, at least {} inner corner events, outer/inner at most {}, "
        "pairs at most {} us and {} px apart, {}, overlap '{}' (docs/evaluation.md).\n"
        "Detection time: {} fresh detectors of each kind are fed the same batches of {} events as the "
        "sequence is read; a run's time is the sum of its detector's batch calls (detection only, no reading), "
        "the median of the {} runs is reported.\n\n",
        o.params.inner_radius, o.params.outer_radius, o.params.min_inner, o.params.max_outer_ratio,
        o.params.max_duration_us, o.params.max_length, o.params.same_polarity ? "per polarity" : "both polarities",
        eval::to_string(o.params.overlap), o.repeat, kBatch, o.repeat);
    if (nms)
        md += fmt::format("Non-maximum suppression (docs/nms.md): rule {}, radius {} px, {} {} us, after the detectors "
                          "named NAME+nms{}.\n\n",
                          nms_rule_name(nms->rule), nms->radius, nms->rule == NmsRule::window ? "window" : "decay",
                          nms->time_us, o.compare_nms ? " (beside each detector without it)" : "");
    md += "## Table 1: reduction rate and FT (%)\n\n" + table1_text(t1, true, ft_notes) + "\n";
    std::map<std::string, std::string> base;
    for (const auto& q : seqs) base[q.name] = q.base;
    const std::string paper = paper_comparison_md(t1, base);
    md += "### Beside the paper's Table 1 (whole one-minute sequences)\n\n";
    md += paper.empty() ? "None of these sequences is one of the twelve Event-Camera-Dataset sequences of the "
                          "paper's Table 1 (shapes, dynamic, poster, boxes x rotation, translation, 6dof, found by "
                          "the name of the folder holding events.txt), so there is nothing to set beside it.\n\n"
                        : paper + "\n";
    md += "## Table 2: time per event\n\n" + table2_text(t2, true) + "\n";
    if (!truth_rows.empty()) {
        md += "## Against ground truth (simulated scenes)\n\nMatching: " + match_rule +
              ". Precision and FT side by side: FT counts corner events on feature tracks found in the detector's "
              "own output, precision those within the radius of a true corner.\n\n" +
              truth_table_text(truth_rows, true, ft_notes) + "\n### Mean over the sequences\n\n" +
              truth_summary_text(truth_rows, true) +
              "\nAP: the average precision of the detector's score threshold swept over its corner events "
              "(precision-recall curve; pr_curve.csv); smear: true corner events per visible truth corner per "
              "millisecond (docs/evaluation.md).\n\n";
        if (!pr_figures_md.empty())
            md += "### Precision-recall curves\n\nThe score threshold swept from the largest score down; precision "
                  "interpolated (the largest at a recall at least the level), absent beyond the detector's full "
                  "recall.\n\n| sequence | precision against recall |\n|---|---|\n" + pr_figures_md + "\n";
        if (!speed_figures_md.empty())
            md += "### Precision and recall against image speed\n\nAn event counts in the speed bin of the nearest "
                  "visible corner at its time, a truth sample in its own (truth_speed.csv has the counts).\n\n"
                  "| sequence | precision | recall |\n|---|---|---|\n" + speed_figures_md + "\n";
        if (!truth_figures_md.empty())
            md += "### Localisation error and corner events over the truth\n\nHistogram of the true positives' "
                  "distance to the nearest corner; space-time: visible truth corners every millisecond grey, corner "
                  "events green when true, red when not.\n\n| sequence | detector | localisation error | "
                  "space-time |\n|---|---|---|---|\n" + truth_figures_md + "\n";
    }
    md += "Paper (one core of an i7-3720QM, 2.6 GHz): Harris 11.6 us / 86,230 e/s; eFAST 0.78 us / 1,275,000 e/s.\n\n";
    if (o.tracks) {
        md += "## Tracking\n\nFeature trackers against ground-truth (GT) tracks, every tracker under every seeding "
              "on every sequence with GT tracks (docs/tracking.md).\n\n";
        for (const auto& line : protocol) md += "- " + line + "\n";
        md += "\n";
        if (!golden_rows.empty())
            md += "Authors' HASTE rows: the outputs of the authors' app (" + o.tracks_golden +
                  ", run on the golden input of the shapes scene from its seeds.txt) scored against this run's `" +
                  golden_rows.front().sequence + "` GT by the same metric, through those seeds.\n\n";
        if (!all_track_rows.empty())
            md += tracking_table_text(all_track_rows, true) + "\n### Mean over the sequences\n\n" +
                  tracking_mean_text(all_track_rows, true) + "\n";
        if (!without_gt_tracks.empty())
            md += "Without GT tracks (no NAME.gt-tracks.txt beside the events; not tracked): " + no_gt_text + ".\n\n";
        if (!golden_note.empty()) md += golden_note + ".\n\n";
    }
    if (!figures_md.empty()) {
        md += "## Figures\n\nCorners of the last 33 ms (bright) and 100 ms (dark), green ON, red OFF (Fig. 6); "
              "corner events in space-time over the whole sequence, green on a feature track, red off it "
              "(Fig. 5b). Per sequence also `figures/<sequence>.sae" + ext + "` (Fig. 2b) and "
              "`figures/<sequence>.space_time" + ext + "` (Fig. 1b, the first detector's corners). The grey events of the "
              "space-time views are all of a sequence's events up to " + std::to_string(StreamFigures::kSample) +
              ", else a uniform sample of that many.\n\n"
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
                    "Sequence files, or folders: a folder with events.txt, or a rosbag2 folder (metadata.yaml), "
                    "is one sequence; any other gives its <sequence>/events.txt folders, its rosbag2 folders and "
                    "its event files (" + event_extensions_text() + "), other files skipped with a note")
        ->required();
    cmd->add_option("-d,--detectors", o->detectors,
                    "Comma-separated detectors, or all; repeatable (-d efast -d arcstar) [default: all, each with its "
                    "defaults (the paper's for efast, harris and harris-global)]:" +
                        detectors_help())
        ->delimiter(',')
        ->multi_option_policy(CLI::MultiOptionPolicy::Join)
        ->check([](const std::string& list) {
            try {
                (void)parse_detector_list(list);
                return std::string();
            } catch (const std::invalid_argument& e) {
                return std::string(e.what());
            }
        });
    add_param_options(*cmd, o->detector_params);
    cmd->add_option("--repeat", o->repeat, "Timed runs per detector and sequence (median)")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000));
    cmd->add_option("--report", o->report, "Write table1.csv, table2.csv, results.json, report.md and figures/ here");
    cmd->add_flag("--no-figures", o->no_figures, "No figures in the report");
    cmd->add_option("--figure-format", o->figure_format,
                    "The report's figures as png, or as svg or pdf (vector: titles, axes, legends and "
                    "charts; the event views inside are rasters)")
        ->capture_default_str()
        ->check(CLI::IsMember({"png", "svg", "pdf"}));
    cmd->add_flag("-q,--quiet", o->quiet, "No progress lines or bars");
    cmd->add_flag("--no-progress", o->no_progress, "No progress bars (shown only when stderr is a terminal)");
    add_load_options(*cmd, o->in);
    add_feature_track_options(*cmd, o->params, o->overlap);
    const auto tg = "Against ground truth (docs/evaluation.md)";
    cmd->add_option("--truth", o->truth,
                    "Ground-truth CSV of the one input (evcorner simulate --truth) [default: NAME.truth.csv beside "
                    "NAME.events.EXT or NAME.EXT, as simulate --suite writes them]")
        ->check(CLI::ExistingFile)
        ->group(tg);
    cmd->add_option("--match-radius", o->match.radius, "A corner event is true within this distance of a corner, px")
        ->capture_default_str()
        ->check(CLI::PositiveNumber)
        ->group(tg);
    cmd->add_option("--match-tolerance", o->match.tolerance_us,
                    "Recall: a truth sample is found by a matching corner event this close in time, us")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber)
        ->group(tg);
    cmd->add_option("--match-credit", o->credit,
                    "An event near several corners credits all of them, or only the nearest, for recall")
        ->capture_default_str()
        ->check(CLI::IsMember({"all", "nearest"}))
        ->group(tg);
    cmd->add_option("--match-interpolation", o->interpolation,
                    "Truth between samples: linear, or the nearest sample")
        ->capture_default_str()
        ->check(CLI::IsMember({"linear", "nearest"}))
        ->group(tg);
    CLI::Option* compare_nms =
        cmd->add_flag("--compare-nms", o->compare_nms,
                      "Run every detector twice: without NMS and with it (as NAME+nms), with the --nms-* options")
            ->group("Non-maximum suppression");
    add_nms_options(*cmd, o->nms, o->nms_params, o->nms_rule, compare_nms);
    cmd->add_option("--speed-bins", o->speed_edges,
                    "Image-speed bin edges, px/s, from 0, increasing [default: 0,50,100,200,400,700]")
        ->delimiter(',')
        ->group(tg);
    const auto trg = "Tracking against GT tracks (docs/tracking.md)";
    CLI::Option* tracks =
        cmd->add_flag("--tracks", o->tracks,
                      "Also evaluate the trackers on every sequence with GT tracks beside it (NAME.gt-tracks.txt "
                      "for NAME.events.EXT or NAME.EXT, as simulate --suite writes them): each tracker seeded at "
                      "the GT's first samples (GT t0, scored by id) and by each -d detector as a front end (scored "
                      "by association within 3 px), by the feature-track benchmark's FA, EFA, FA@5, TE@5 "
                      "(synchronous) and the asynchronous FA; sequences without GT tracks are listed as such")
            ->group(trg);
    cmd->add_option("--trackers", o->trackers, "With --tracks: comma-separated trackers, or all:" + [] {
        std::string h;
        for (const TrackerEntry& t : tracker_registry()) h += fmt::format("\n  {:<24}{}", t.name, t.summary);
        return h;
    }())
        ->capture_default_str()
        ->needs(tracks)
        ->group(trg);
    cmd->add_option("--tracks-golden", o->tracks_golden,
                    "With --tracks: a folder of the authors' HASTE app outputs on the shapes scene (seeds.txt and "
                    "<tracker>.<init>.txt.gz, e.g. ../shared/data/golden/haste/sim-shapes): each is scored against "
                    "the `shapes` scene's GT through those seeds, beside our trackers run from the same seeds")
        ->check(CLI::ExistingDirectory)
        ->needs(tracks)
        ->group(trg);
    cmd->footer(
        "Examples:\n"
        "  evcorner eval ../shared/data/real/ecd-stppp --report eval-report\n"
        "  evcorner eval a/events.txt b.txt -d efast,harris --repeat 3\n"
        "  evcorner eval ../shared/data/real/ecd-stppp -d all --harris-window 7 --no-figures\n"
        "  evcorner eval scene.npy --truth scene.truth.csv --report r     (simulate -o scene.npy --truth ...)\n"
        "  evcorner eval suite/ --report r                                (simulate --suite suite/)\n"
        "  evcorner eval suite/ --compare-nms --nms-rule window --report r (each detector with and without NMS)\n"
        "  evcorner eval suite/ -d efast,arcstar --tracks --report r      (and the trackers against GT tracks)");
    cmd->callback([o] { run_eval(*o); });
}

}  // namespace evcorner::cli
