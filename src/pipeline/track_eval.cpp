#include "evcorner/pipeline/track_eval.hpp"

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include "evcorner/error.hpp"
#include "evcorner/eval/track_metrics.hpp"
#include "evcorner/io/memory_reader.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/pipeline/track.hpp"
#include "evcorner/track/track_file.hpp"
#include "evcorner/track/track_seed.hpp"

namespace evcorner::pipeline {

namespace {

std::vector<TrackPoint> seed_points(std::span<const TrackSeed> seeds) {
    std::vector<TrackPoint> v;
    v.reserve(seeds.size());
    for (const TrackSeed& s : seeds) v.push_back({s.id, static_cast<double>(s.t) / 1e6, s.x, s.y});
    return v;
}

double sampling_rate_hz(std::span<const TrackPoint> gt) {
    std::vector<TrackPoint> rows(gt.begin(), gt.end());
    std::stable_sort(rows.begin(), rows.end(), [](const TrackPoint& a, const TrackPoint& b) {
        return a.id != b.id ? a.id < b.id : a.t < b.t;
    });
    std::vector<double> steps;
    for (std::size_t i = 1; i < rows.size(); ++i)
        if (rows[i].id == rows[i - 1].id && rows[i].t > rows[i - 1].t) steps.push_back(rows[i].t - rows[i - 1].t);
    if (steps.empty()) return 0;
    const auto mid = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
    std::nth_element(steps.begin(), mid, steps.end());
    return 1.0 / *mid;
}

/// Scores `predicted` both ways into `row`.
void score(std::span<const TrackPoint> predicted, std::span<const TrackPoint> gt, eval::TrackMetricOptions m,
           TrackEvalRow& row) {
    m.asynchronous = false;
    const eval::TrackEvaluation r = eval::evaluate_tracks(predicted, gt, m);
    row.fa = r.fa;
    row.efa = r.efa;
    row.fa_5 = r.fa_5;
    row.te_5 = r.te_5;
    row.predicted_tracks = r.predicted_tracks;
    row.gt_tracks = r.gt_tracks;
    row.counted_tracks = r.counted_tracks;
    row.skipped_tracks = r.skipped_tracks;
    row.unmatched_tracks = r.unmatched_tracks;
    m.asynchronous = true;
    row.fa_async = eval::evaluate_tracks(predicted, gt, m).fa;
}

/// One seeding made ready to run: its tracker options (but the tracker's name) and its metric.
struct PreparedSeeding {
    const TrackSeeding* seeding;
    TrackOptions run;
    std::vector<TrackPoint> seeds;  ///< seeds: the matching points
    eval::TrackMetricOptions metric;
    bool empty = false;  ///< no seed to start (nothing to run; the row stays 0)
    std::size_t unseeded = 0;
};

/// Leaves out the seeds a tracker refuses, off [0, W) x [0, H): a GT corner within half a
/// pixel of the sensor's border, still in pixel 0 by the pixel-index convention. Returns how many.
std::size_t drop_off_sensor(std::vector<TrackSeed>& seeds, SensorSize size) {
    const auto off = [&](const TrackSeed& s) {
        return !(s.x >= 0 && s.y >= 0 && s.x < static_cast<float>(size.width) && s.y < static_cast<float>(size.height));
    };
    const auto n = seeds.size();
    seeds.erase(std::remove_if(seeds.begin(), seeds.end(), off), seeds.end());
    return n - seeds.size();
}

}  // namespace

TrackSeeding gt_seeding() {
    TrackSeeding s;
    s.kind = SeedingKind::gt;
    s.name = "GT t0";
    return s;
}

TrackSeeding detector_seeding(DetectorConfig detector) {
    TrackSeeding s;
    s.kind = SeedingKind::detector;
    s.name = detector.name;
    s.detector = std::move(detector);
    s.init = HasteInit::centered;  // evcorner track's default
    s.stop.max_idle_us = 200000;   // the front end's rules (docs/tracking.md)
    s.stop.min_separation = 3;
    return s;
}

TrackSeeding seeds_seeding(std::string seeds_file, std::string name, HasteInit init) {
    TrackSeeding s;
    s.kind = SeedingKind::seeds;
    s.name = std::move(name);
    s.seeds_file = std::move(seeds_file);
    s.init = init;
    return s;
}

std::vector<TrackEvalRow> evaluate_trackers(const TrackEvalFiles& files, std::span<const std::string> trackers,
                                            std::span<const TrackSeeding> seedings, const TrackEvalParams& params,
                                            const TrackEvalRowFn& on_row) {
    if (!(params.associate_px > 0)) throw std::invalid_argument("track evaluation: the association radius must be > 0");
    if (params.max_threshold_px < 1) throw std::invalid_argument("track evaluation: the largest threshold must be >= 1 px");
    for (const std::string& t : trackers) (void)tracker_entry(t);
    // Everything but the events first: a bad name or file fails before the long read.
    const std::unique_ptr<io::EventReader> reader = io::open_event_reader(files.events, files.reader, files.format);
    const std::optional<SensorSize> sensor = reader->sensor();
    const SensorSize size = sensor.value_or(kDavis240);  // as run_track takes it
    const std::vector<TrackPoint> gt = read_track_points(files.gt);
    std::vector<TrackSeed> gt_seeds;
    bool gt_seeds_read = false;
    std::vector<PreparedSeeding> prepared;
    for (const TrackSeeding& s : seedings) {
        PreparedSeeding p{&s, {}, {}, {}, false, 0};
        TrackerConfig& c = p.run.config;
        c.init = s.init;
        c.stop = s.stop;
        c.seed_radius = s.seed_radius;
        c.max_tracks = s.max_tracks;
        p.metric.max_threshold_px = params.max_threshold_px;
        switch (s.kind) {
            case SeedingKind::gt:
                if (!gt_seeds_read) {
                    gt_seeds = read_seeds_file(files.gt);
                    gt_seeds_read = true;
                }
                c.seeds = gt_seeds;
                p.unseeded = drop_off_sensor(c.seeds, size);
                p.empty = c.seeds.empty();
                p.metric.align_start = false;
                break;
            case SeedingKind::detector: {
                DetectOptions d;
                d.detector = s.detector;
                p.run.detect = std::move(d);
                p.metric.associate_px = params.associate_px;
                break;
            }
            case SeedingKind::seeds:
                c.seeds = read_seeds_file(s.seeds_file);
                if (c.seeds.empty()) throw InputError(s.seeds_file, "holds no seed");
                p.unseeded = drop_off_sensor(c.seeds, size);
                p.empty = c.seeds.empty();
                p.seeds = seed_points(c.seeds);
                break;
        }
        if (!p.empty)
            for (const std::string& t : trackers) {
                p.run.tracker = t;
                check_track_options(p.run);
            }
        prepared.push_back(std::move(p));
    }
    for (PreparedSeeding& p : prepared) p.metric.seeds = p.seeds;  // the vectors stay put from here

    const std::vector<Event> events = io::read_all_events(*reader);
    const double gt_rate_hz = sampling_rate_hz(gt);
    std::vector<TrackEvalRow> rows;
    std::vector<TrackPoint> predicted;
    for (const std::string& t : trackers) {
        for (PreparedSeeding& p : prepared) {
            TrackEvalRow row;
            row.sequence = files.sequence;
            row.tracker = t;
            row.seeding = p.seeding->name;
            row.kind = p.seeding->kind;
            row.gt_rate_hz = gt_rate_hz;
            row.unseeded_tracks = p.unseeded;
            row.ns_per_update = std::numeric_limits<double>::quiet_NaN();
            if (!p.empty) {
                p.run.tracker = t;
                predicted.clear();
                io::MemoryReader reader(events, sensor, files.events);
                const TrackSummary s = run_track(reader, p.run, [&](std::span<const TrackState> states) {
                    for (const TrackState& st : states)
                        predicted.push_back({st.id, static_cast<double>(st.t) / 1e6, st.x, st.y});
                });
                row.states = s.states;
                row.updates = s.stats.updates;
                row.ns_per_update = s.ns_per_update();
                row.track_s = s.track_s;
                score(predicted, gt, p.metric, row);
            }
            if (on_row) on_row(row);
            rows.push_back(std::move(row));
        }
    }
    return rows;
}

TrackEvalRow evaluate_track_file(const std::string& tracks, const std::string& gt, const std::string& seeds_file,
                                 const TrackEvalParams& params) {
    if (params.max_threshold_px < 1) throw std::invalid_argument("track evaluation: the largest threshold must be >= 1 px");
    const std::vector<TrackSeed> seeds = read_seeds_file(seeds_file);
    if (seeds.empty()) throw InputError(seeds_file, "holds no seed");
    const std::vector<TrackPoint> seed_pts = seed_points(seeds);
    const std::vector<TrackPoint> predicted = read_track_points(tracks);
    const std::vector<TrackPoint> truth = read_track_points(gt);
    TrackEvalRow row;
    row.kind = SeedingKind::seeds;
    row.ns_per_update = std::numeric_limits<double>::quiet_NaN();
    row.states = predicted.size();
    row.gt_rate_hz = sampling_rate_hz(truth);
    eval::TrackMetricOptions m;
    m.max_threshold_px = params.max_threshold_px;
    m.seeds = seed_pts;
    score(predicted, truth, m, row);
    return row;
}

}  // namespace evcorner::pipeline
