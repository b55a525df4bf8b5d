// luvHarris: the per-event cost and the table refresh cost, separately, for 240x180 and
// 1280x720, and the share of the wall time the refreshes take at the real files' rates.
// Inputs: the eight Event-Camera-Dataset cuts (240x180) and expelliarmus/evt3_sample.raw
// (Prophesee Gen4.1 EVT 3.0, 1280x720) under ../shared/data; without it, the bundled
// shapes_translation sample only.
// - refresh/<W>x<H>: one refresh point over a surface the file's events built, with no event
//   since the last (the incremental refresh then has nothing to copy: its fixed cost);
// - events_only/<file>: every event with the table refreshed once before timing and never
//   again (TOS update, look-up, adaptive threshold);
// - full/<file>: the detector with its defaults (a refresh every 1000 us of event time),
//   a fresh detector per pass; counters: refreshes per pass, the file's event rate.
// share of the wall time the refreshes take = refreshes x refresh / full (printed by
// scripts or by hand from the medians; the counters give the numbers).
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/io/open.hpp"
#include "evcorner/luvharris.hpp"
#include "evcorner/scored_detector.hpp"
#include "real_files.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

struct Input {
    std::string name;
    SensorSize size;
    std::vector<Event> events;
};

std::vector<Input> load_inputs() {
    std::vector<Input> inputs;
    const fs::path data = fs::path(EVCORNER_SHARED_DIR) / "data";
    for (const auto& f : bench::real_240x180_files(data))
        if (f.ecd && f.name != "slider_depth") inputs.push_back({f.name, kDavis240, bench::load_events(f.events)});
    const fs::path hd = data / "real/expelliarmus/evt3_sample.raw";
    if (fs::exists(hd)) {
        const auto reader = io::open_event_reader(hd.string());
        auto events = io::read_all_events(*reader);
        inputs.push_back({"evt3_1280x720", reader->sensor().value_or(SensorSize{1280, 720}), std::move(events)});
    }
    if (inputs.empty())
        inputs.push_back({"bundled_shapes_translation", kDavis240,
                          bench::load_events(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt")});
    return inputs;
}

void per_event(benchmark::State& state, const Input& in) {
    state.counters["time_per_event"] =
        benchmark::Counter(static_cast<double>(in.events.size()) * static_cast<double>(state.iterations()),
                           benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    const double span_s = static_cast<double>(in.events.back().t - in.events.front().t) * 1e-6;
    state.counters["events_per_s_in_file"] = static_cast<double>(in.events.size()) / span_s;
}

LuvHarrisParams never_again() {
    LuvHarrisParams p;
    p.refresh_us = LuvHarris::kMaxRefreshUs;
    return p;
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<Input> inputs = load_inputs();
    // One refresh per sensor size, over the surface of its first file.
    std::vector<SensorSize> sizes_done;
    for (const Input& in : inputs) {
        bool seen = false;
        for (const SensorSize& s : sizes_done) seen |= s == in.size;
        if (seen) continue;
        sizes_done.push_back(in.size);
        const std::string name = "refresh/" + std::to_string(in.size.width) + "x" + std::to_string(in.size.height);
        benchmark::RegisterBenchmark(name.c_str(), [&in](benchmark::State& state) {
            LuvHarris det(in.size, never_again());
            for (const Event& e : in.events) det.process_unchecked(e);
            for (auto _ : state) {
                det.refresh();
                benchmark::DoNotOptimize(det.table(in.size.width / 2, in.size.height / 2));
            }
            state.counters["pixels"] = static_cast<double>(in.size.pixels());
            state.counters["time_per_pixel"] = benchmark::Counter(
                static_cast<double>(in.size.pixels()) * static_cast<double>(state.iterations()),
                benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
        })->Unit(benchmark::kMicrosecond);
    }
    for (const Input& in : inputs) {
        benchmark::RegisterBenchmark(("events_only/" + in.name).c_str(), [&in](benchmark::State& state) {
            std::vector<std::uint8_t> flags(in.events.size());
            std::size_t corners = 0;
            for (auto _ : state) {
                state.PauseTiming();
                LuvHarris det(in.size, never_again());
                det.refresh();  // a (zero) table from the start: every event looks up
                state.ResumeTiming();
                corners = detect_unchecked(det, in.events, flags);
                benchmark::DoNotOptimize(corners);
            }
            per_event(state, in);
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("full/" + in.name).c_str(), [&in](benchmark::State& state) {
            std::vector<std::uint8_t> flags(in.events.size());
            std::size_t corners = 0;
            std::uint64_t refreshes = 0;
            for (auto _ : state) {
                state.PauseTiming();
                LuvHarris det(in.size);
                state.ResumeTiming();
                corners = detect_unchecked(det, in.events, flags);
                refreshes = det.refreshes();
                benchmark::DoNotOptimize(corners);
            }
            per_event(state, in);
            state.counters["refreshes"] = static_cast<double>(refreshes);
            state.counters["corners"] = static_cast<double>(corners);
        })->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
