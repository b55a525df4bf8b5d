// The eFAST -> Harris cascade against eFAST (and Harris) in the same run, on the real
// 240x180 recordings (the nine Event-Camera-Dataset cuts and the two DAVIS240C AEDAT 2.0
// files; without ../shared, the bundled shapes_translation sample):
// - cold/<detector>: one iteration runs every file once, in turn, each with a fresh
//   detector (so no file's data or branch history is warm from its own previous pass),
//   the way a user runs a file;
// - replay/<detector>/<file>: the same file again and again, a fresh detector per pass.
// Detector construction is outside the timing. Counter time_per_event = seconds per event.
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/efast_harris.hpp"
#include "evcorner/harris.hpp"
#include "real_files.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

struct Input {
    std::string name;
    std::vector<Event> events;
};

std::vector<Input> load_inputs() {
    std::vector<Input> inputs;
    for (const auto& f : bench::real_240x180_files(fs::path(EVCORNER_SHARED_DIR) / "data"))
        inputs.push_back({f.name, bench::load_events(f.events)});
    if (inputs.empty())
        inputs.push_back({"bundled_shapes_translation",
                          bench::load_events(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt")});
    return inputs;
}

void per_event(benchmark::State& state, std::size_t events_per_iteration, std::size_t corners) {
    const double n = static_cast<double>(events_per_iteration);
    state.counters["time_per_event"] = benchmark::Counter(
        n * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["corners"] = static_cast<double>(corners);
}

template <class Make>
void replay(benchmark::State& state, const Input* in, Make make) {
    std::vector<std::uint8_t> flags(in->events.size());
    std::size_t corners = 0;
    for (auto _ : state) {
        state.PauseTiming();
        auto det = make();
        state.ResumeTiming();
        corners = detect_unchecked(det, in->events, flags);
        benchmark::DoNotOptimize(corners);
    }
    per_event(state, in->events.size(), corners);
}

template <class Make>
void cold(benchmark::State& state, const std::vector<Input>* inputs, Make make) {
    std::size_t longest = 0, total = 0;
    for (const Input& in : *inputs) {
        longest = std::max(longest, in.events.size());
        total += in.events.size();
    }
    std::vector<std::uint8_t> flags(longest);
    std::size_t corners = 0;
    for (auto _ : state) {
        corners = 0;
        for (const Input& in : *inputs) {
            state.PauseTiming();
            auto det = make();
            state.ResumeTiming();
            corners += detect_unchecked(det, in.events, flags);
        }
        benchmark::DoNotOptimize(corners);
    }
    per_event(state, total, corners);
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<Input> inputs = load_inputs();
    const auto efast = [] { return EFast(kDavis240); };
    const auto cascade = [] { return EFastHarris(kDavis240); };
    const auto harris = [] { return Harris(kDavis240); };
    benchmark::RegisterBenchmark("cold/efast", [=](benchmark::State& s) { cold(s, &inputs, efast); })
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("cold/efast_harris", [=](benchmark::State& s) { cold(s, &inputs, cascade); })
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("cold/harris", [=](benchmark::State& s) { cold(s, &inputs, harris); })
        ->Unit(benchmark::kMillisecond);
    for (const Input& in : inputs) {
        benchmark::RegisterBenchmark(("replay/efast/" + in.name).c_str(),
                                     [&in, efast](benchmark::State& s) { replay(s, &in, efast); })
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("replay/efast_harris/" + in.name).c_str(),
                                     [&in, cascade](benchmark::State& s) { replay(s, &in, cascade); })
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
