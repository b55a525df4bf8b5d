// ns/event of EVERY registered detector (registry.hpp: nothing here names one) with its
// default parameters on the real 240x180 recordings: the nine Event-Camera-Dataset cuts
// and the two DAVIS240C AEDAT 2.0 files (real_files.hpp), loaded once before timing.
// Without ../shared, falls back to the bundled shapes_translation sample.
//
// - cold/<detector>: one iteration runs every file once, in turn, each with a fresh
//   detector, the way a user runs a file;
// - replay/<detector>/<file>: the same file again and again, a fresh detector per pass;
// - unchecked/<detector>/<file>: as replay, with detect_unchecked() instead of detect()
//   (detect() checks the span in one pass, then runs: the difference is that check);
// - check_events/<file>: the checking pass alone.
// Detector construction is outside the timing; the batch loop is the class's own
// detect() (statically dispatched, as the pipeline runs it). Counter time_per_event =
// seconds per event ("25n" = 25 ns/event). Run with --benchmark_repetitions=5
// --benchmark_report_aggregates_only=true --benchmark_enable_random_interleaving=true
// for interleaved medians.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/registry.hpp"
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
    state.SetItemsProcessed(static_cast<std::int64_t>(static_cast<double>(state.iterations()) * n));
}

template <bool Checked, class Make>
void replay(benchmark::State& state, const Input* in, Make make) {
    std::vector<std::uint8_t> flags(in->events.size());
    std::size_t corners = 0;
    for (auto _ : state) {
        state.PauseTiming();
        auto det = make();
        state.ResumeTiming();
        if constexpr (Checked)
            corners = detect(det, in->events, flags);
        else
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
            corners += detect(det, in.events, std::span<std::uint8_t>(flags.data(), in.events.size()));
        }
        benchmark::DoNotOptimize(corners);
    }
    per_event(state, total, corners);
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<Input> inputs = load_inputs();
    for_each_detector_entry([](const auto& entry) {
        const std::string name(entry.name);
        const auto make = [&entry] { return entry.make(kDavis240, {}); };
        benchmark::RegisterBenchmark(("cold/" + name).c_str(), [make](benchmark::State& s) { cold(s, &inputs, make); })
            ->Unit(benchmark::kMillisecond);
        for (const Input& in : inputs) {
            benchmark::RegisterBenchmark(("replay/" + name + "/" + in.name).c_str(),
                                         [&in, make](benchmark::State& s) { replay<true>(s, &in, make); })
                ->Unit(benchmark::kMillisecond);
            benchmark::RegisterBenchmark(("unchecked/" + name + "/" + in.name).c_str(),
                                         [&in, make](benchmark::State& s) { replay<false>(s, &in, make); })
                ->Unit(benchmark::kMillisecond);
        }
    });
    for (const Input& in : inputs)
        benchmark::RegisterBenchmark(("check_events/" + in.name).c_str(), [&in](benchmark::State& s) {
            const EventLimits limits = EFast(kDavis240).limits();
            for (auto _ : s) benchmark::DoNotOptimize(first_invalid_event(in.events, limits));
            per_event(s, in.events.size(), 0);
        })->Unit(benchmark::kMillisecond);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
