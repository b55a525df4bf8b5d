// ns per event and per update of EVERY registered tracker (track/tracker.hpp: nothing here
// names one) on a simulated checkerboard, seeded at 10, 100 and 1000 ground-truth corners,
// beside eFAST detect on the same stream for the ratio.
//
// The stream: kScene, a 640x480 sensor with a 36x27 checkerboard of 16 px squares (37 x 28 =
// 1036 grid corners, all on the sensor) translating at (40, 20) px/s, simulated once
// (sim/simulator.hpp) for 0.2 s ("full", about 0.9 M events); "short" is its first 50 ms
// (about 0.2 M events). Seeds are the GT tracks' first samples (sim/gt_tracks.hpp over
// corners_at at t = 0, as `evcorner simulate --gt-tracks` writes them): the first N ids,
// HASTE's uncentered start.
//
// - track/<tracker>/seeds:<N>/stream:short: every tracker;
// - track/<tracker>/seeds:<N>/stream:full: the trackers whose full pass at 1000 seeds fits
//   kPassBudgetS, judged before registering from one pass at 100 seeds over the short stream
//   (printed to stderr): the slow ones (the plain correlation and haste-difference today)
//   stay on the short stream so that the binary runs in a few minutes;
// - detect/efast/stream:<s>: eFAST over the same stream, for the ratio.
// One iteration: a fresh tracker (construction not timed) over every event of the stream,
// process(e, false) as pipeline::run_track feeds it. Counters: time_per_event (seconds per
// event of the stream, "575n" = 575 ns), time_per_update (per in-range (event, track) pair,
// TrackerStats::updates; absent for a tracker that reports none), live (tracks running at
// the end), updates, events. Google Benchmark's rates are per CPU time of the thread. Run
// with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// --benchmark_enable_random_interleaving=true for interleaved medians (about 3 minutes on
// a shared 2-core EPYC).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/sim/gt_tracks.hpp"
#include "evcorner/sim/scene.hpp"
#include "evcorner/sim/simulator.hpp"
#include "evcorner/sim/truth.hpp"
#include "evcorner/track/tracker.hpp"
#include "timing.hpp"

using namespace evcorner;

namespace {

// docs/simulate.md, "Scene file". Intensities 0.2 / 0.8 on the default 0.5 background.
constexpr const char* kScene = R"({
  "sensor": [640, 480], "duration_s": 0.2, "seed": 1,
  "objects": [{"checkerboard": {"origin": [32, 24], "square": 16, "cols": 36, "rows": 27},
               "intensity": [0.2, 0.8], "motion": {"velocity": [40, 20]}}]
})";
constexpr std::int64_t kShortUs = 50'000;
constexpr double kPassBudgetS = 5.0;  // longest single pass (1000 seeds, full stream) worth timing
constexpr std::size_t kSeedCounts[] = {10, 100, 1000};

struct Stream {
    std::string name;
    std::span<const Event> events;
};

// The GT tracks' first samples, by id: what `evcorner track --seeds gt.txt` starts from.
std::vector<TrackSeed> gt_seeds(const sim::Scene& scene) {
    std::vector<sim::TruthCorner> corners;
    sim::corners_at(scene, 0, corners);
    sim::GtTrackSampler sampler;
    std::vector<TrackState> states;
    sampler.sample(corners, states);
    sampler.finish(states);  // the pending first samples, one per visible corner
    std::vector<TrackSeed> seeds;
    for (const TrackState& s : states) seeds.push_back({s.t, s.x, s.y, 0.0f, s.id});
    std::sort(seeds.begin(), seeds.end(), [](const TrackSeed& a, const TrackSeed& b) { return a.id < b.id; });
    return seeds;
}

TrackerConfig config_for(const std::vector<TrackSeed>& seeds, std::size_t n) {
    TrackerConfig c;
    c.seeds.assign(seeds.begin(), seeds.begin() + static_cast<std::ptrdiff_t>(std::min(n, seeds.size())));
    c.init = HasteInit::uncentered;
    return c;
}

// One pass of a fresh tracker over the stream; returns its stats.
TrackerStats pass(const TrackerEntry& entry, SensorSize sensor, const TrackerConfig& config,
                  std::span<const Event> events, benchmark::State* state) {
    if (state) state->PauseTiming();
    const std::unique_ptr<Tracker> tracker = entry.make(sensor, config);
    if (state) state->ResumeTiming();
    std::size_t states = 0;
    for (const Event& e : events) states += tracker->process(e, false).size();
    benchmark::DoNotOptimize(states);
    return tracker->stats();
}

void rate(benchmark::State& s, const char* name, double per_iteration) {
    s.counters[name] = benchmark::Counter(per_iteration * static_cast<double>(s.iterations()),
                                          benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
    static const sim::Scene scene = sim::parse_scene(kScene, "bench_track scene");
    static const std::vector<Event> all = sim::simulate(scene);
    static const std::vector<TrackSeed> seeds = gt_seeds(scene);
    const SensorSize sensor = scene.sensor;
    const auto short_end =
        std::upper_bound(all.begin(), all.end(), kShortUs, [](std::int64_t t, const Event& e) { return t < e.t; });
    const Stream short_stream{"short", std::span<const Event>(all.begin(), short_end)};
    const Stream full_stream{"full", std::span<const Event>(all)};
    std::fprintf(stderr, "bench_track: %dx%d checkerboard, %zu GT corners at t = 0; full %zu events (%.2f s), "
                 "short %zu (first %.2f s)\n",
                 sensor.width, sensor.height, seeds.size(), full_stream.events.size(), scene.duration_s,
                 short_stream.events.size(), static_cast<double>(kShortUs) * 1e-6);

    auto add_tracker = [&](const TrackerEntry& entry, const Stream& stream, std::size_t n) {
        if (n > seeds.size()) return;  // the scene has too few corners
        const std::string name = "track/" + std::string(entry.name) + "/seeds:" + std::to_string(n) + "/stream:" +
                                 stream.name;
        benchmark::RegisterBenchmark(name.c_str(), [&entry, sensor, stream, n](benchmark::State& s) {
            const TrackerConfig config = config_for(seeds, n);
            TrackerStats stats;
            for (auto _ : s) stats = pass(entry, sensor, config, stream.events, &s);
            const double events = static_cast<double>(stream.events.size());
            rate(s, "time_per_event", events);
            if (stats.updates > 0) rate(s, "time_per_update", static_cast<double>(stats.updates));
            s.counters["live"] = static_cast<double>(stats.live);
            s.counters["updates"] = static_cast<double>(stats.updates);
            s.counters["events"] = events;
            s.SetItemsProcessed(static_cast<std::int64_t>(events * static_cast<double>(s.iterations())));
        })->Unit(benchmark::kMillisecond);
    };
    for (const Stream& stream : {short_stream, full_stream})
        benchmark::RegisterBenchmark(("detect/efast/stream:" + stream.name).c_str(), [sensor, stream](benchmark::State& s) {
            std::vector<std::uint8_t> flags(stream.events.size());
            std::size_t corners = 0;
            for (auto _ : s) {
                s.PauseTiming();
                EFast det(sensor);
                s.ResumeTiming();
                corners = detect(det, stream.events, flags);
                benchmark::DoNotOptimize(flags.data());
            }
            rate(s, "time_per_event", static_cast<double>(stream.events.size()));
            s.counters["corners"] = static_cast<double>(corners);
            s.counters["events"] = static_cast<double>(stream.events.size());
        })->Unit(benchmark::kMillisecond);
    for (const TrackerEntry& entry : tracker_registry()) {
        // Whether a full pass at 1000 seeds fits the budget: from one at 100 over the short
        // stream, scaled by the seeds (updates grow with the tracks in range) and the events.
        const double t0 = bench::thread_cpu_ns();
        (void)pass(entry, sensor, config_for(seeds, 100), short_stream.events, nullptr);
        const double s100 = (bench::thread_cpu_ns() - t0) * 1e-9;
        const double estimate = s100 * 10.0 * static_cast<double>(full_stream.events.size()) /
                                static_cast<double>(short_stream.events.size());
        const bool full = estimate <= kPassBudgetS;
        std::fprintf(stderr, "  %-24s 100 seeds, short stream: %.3f s CPU; full pass at 1000 estimated %.1f s -> %s\n",
                     std::string(entry.name).c_str(), s100, estimate, full ? "short and full" : "short only");
        for (const std::size_t n : kSeedCounts) {
            add_tracker(entry, short_stream, n);
            if (full) add_tracker(entry, full_stream, n);
        }
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
