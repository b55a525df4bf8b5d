#include "evcorner/pipeline/track.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "evcorner/io/open.hpp"
#include "evcorner/io/output_paths.hpp"

namespace evcorner::pipeline {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// The tracker fed by the detection pipeline: every event with its corner flag.
class TrackingSink final : public DetectSink {
public:
    TrackingSink(Tracker& tracker, const TrackStatesFn& sink, TrackSummary& s) : tracker_(tracker), sink_(sink), s_(s) {}
    void write(const DetectedBatch& b) override {
        // The states are handed on after the batch: the time measured is the tracker's alone.
        const auto t0 = Clock::now();
        states_.clear();
        for (std::size_t i = 0; i < b.events.size(); ++i) {
            const auto states = tracker_.process(b.events[i], b.is_corner[i] != 0);
            s_.corners += b.is_corner[i];
            states_.insert(states_.end(), states.begin(), states.end());
        }
        s_.track_s += since(t0);
        s_.events += b.events.size();
        s_.states += states_.size();
        if (!states_.empty()) sink_(states_);
    }

private:
    Tracker& tracker_;
    const TrackStatesFn& sink_;
    TrackSummary& s_;
    std::vector<TrackState> states_;
};

}  // namespace

double TrackSummary::ns_per_update() const noexcept {
    return stats.updates ? track_s * 1e9 / static_cast<double>(stats.updates) : std::numeric_limits<double>::quiet_NaN();
}
double TrackSummary::ns_per_event() const noexcept {
    return events ? track_s * 1e9 / static_cast<double>(events) : std::numeric_limits<double>::quiet_NaN();
}

void check_track_options(const TrackOptions& o) {
    (void)tracker_entry(o.tracker);
    if (o.config.seeds.empty() && !o.detect)
        throw std::invalid_argument("tracking needs seeds or a detector to seed from (--seeds FILE or -d DETECTOR)");
    if (o.detect) {
        check_detect_options(*o.detect);
        if (o.detect->threads != 1) throw std::invalid_argument("tracking runs on one thread (--threads 1)");
    }
}

TrackSummary run_track(io::EventReader& reader, const TrackOptions& o, const TrackStatesFn& sink, SensorSize fallback) {
    const auto wall_start = Clock::now();
    check_track_options(o);
    TrackSummary s;
    s.tracker = o.tracker;
    s.sensor = reader.sensor().value_or(fallback);
    TrackerConfig config = o.config;
    config.seed_from_corners = o.detect.has_value();
    const std::unique_ptr<Tracker> tracker = tracker_entry(o.tracker).make(s.sensor, config);
    if (o.detect) {
        s.detector = o.detect->detector.name;
        TrackingSink ts(*tracker, sink, s);
        DetectSink* sinks[] = {&ts};
        run_detect(reader, *o.detect, sinks, {}, s.sensor);
    } else {
        std::vector<Event> batch(std::size_t{1} << 16);
        std::vector<TrackState> states;  // handed on after each batch: the time is the tracker's
        for (;;) {
            const std::size_t n = reader.read(batch);
            if (n == 0 && reader.skipped_in_batch().empty()) break;
            const auto t0 = Clock::now();
            states.clear();
            for (std::size_t i = 0; i < n; ++i) {
                const auto out = tracker->process(batch[i], false);
                states.insert(states.end(), out.begin(), out.end());
            }
            s.track_s += since(t0);
            s.events += n;
            s.states += states.size();
            if (!states.empty()) sink(states);
        }
    }
    s.stats = tracker->stats();
    s.wall_s = since(wall_start);
    return s;
}

TrackSummary track_file(const TrackFiles& f, const TrackOptions& o) {
    const auto wall_start = Clock::now();
    io::check_output_paths({{"input", f.input}}, {{"output", f.output}});
    io::check_outputs_creatable({{"output", f.output}});
    check_track_options(o);
    const std::unique_ptr<io::EventReader> reader = io::open_event_reader(f.input, f.reader, f.format);
    TrackWriter out(f.output, f.tracks_format.value_or(track_format_for(f.output)));
    TrackSummary s = run_track(*reader, o, [&](std::span<const TrackState> states) { out.write(states); });
    out.close();
    s.wall_s = since(wall_start);
    return s;
}

}  // namespace evcorner::pipeline
