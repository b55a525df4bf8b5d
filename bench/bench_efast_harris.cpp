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

#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/efast_harris.hpp"
#include "evcorner/harris.hpp"
#include "detector_runs.hpp"

using namespace evcorner;
using evcorner::bench::Input;

int main(int argc, char** argv) {
    static const std::vector<Input> inputs = bench::load_real_inputs();
    const auto efast = [] { return EFast(kDavis240); };
    const auto cascade = [] { return EFastHarris(kDavis240); };
    const auto harris = [] { return Harris(kDavis240); };
    benchmark::RegisterBenchmark("cold/efast", [=](benchmark::State& s) { bench::cold<false>(s, &inputs, efast); })
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("cold/efast_harris", [=](benchmark::State& s) { bench::cold<false>(s, &inputs, cascade); })
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("cold/harris", [=](benchmark::State& s) { bench::cold<false>(s, &inputs, harris); })
        ->Unit(benchmark::kMillisecond);
    for (const Input& in : inputs) {
        benchmark::RegisterBenchmark(("replay/efast/" + in.name).c_str(),
                                     [&in, efast](benchmark::State& s) { bench::replay<false>(s, &in, efast); })
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("replay/efast_harris/" + in.name).c_str(),
                                     [&in, cascade](benchmark::State& s) { bench::replay<false>(s, &in, cascade); })
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
