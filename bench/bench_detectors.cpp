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

#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/registry.hpp"
#include "detector_runs.hpp"

using namespace evcorner;
using evcorner::bench::Input;

int main(int argc, char** argv) {
    static const std::vector<Input> inputs = bench::load_real_inputs();
    for_each_detector_entry([](const auto& entry) {
        const std::string name(entry.name);
        const auto make = [&entry] { return entry.make(kDavis240, {}); };
        benchmark::RegisterBenchmark(("cold/" + name).c_str(), [make](benchmark::State& s) { bench::cold<true>(s, &inputs, make); })
            ->Unit(benchmark::kMillisecond);
        for (const Input& in : inputs) {
            benchmark::RegisterBenchmark(("replay/" + name + "/" + in.name).c_str(),
                                         [&in, make](benchmark::State& s) { bench::replay<true>(s, &in, make); })
                ->Unit(benchmark::kMillisecond);
            benchmark::RegisterBenchmark(("unchecked/" + name + "/" + in.name).c_str(),
                                         [&in, make](benchmark::State& s) { bench::replay<false>(s, &in, make); })
                ->Unit(benchmark::kMillisecond);
        }
    });
    for (const Input& in : inputs)
        benchmark::RegisterBenchmark(("check_events/" + in.name).c_str(), [&in](benchmark::State& s) {
            const EventLimits limits = EFast(kDavis240).limits();
            for (auto _ : s) benchmark::DoNotOptimize(first_invalid_event(in.events, limits));
            bench::per_event(s, in.events.size(), 0);
        })->Unit(benchmark::kMillisecond);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
