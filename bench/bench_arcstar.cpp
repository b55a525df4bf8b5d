// Google Benchmark of Arc* and FA-Harris beside eFAST on the 8 real Event-Camera-Dataset
// cuts that have Arc* goldens (replayed: every iteration runs the file with a fresh
// detector, constructed outside the timing). Read "time_per_event". For medians:
//   build/bin/bench_arcstar --benchmark_repetitions=9 --benchmark_report_aggregates_only=true
// Variants per file: efast, arcstar (detect(): the path chosen for this CPU), arcstar_portable
// (the loop every x86-64 runs), arcstar_nofilter, arcstar_minority, fa_harris.
// Cold figures (one pass per file, files rotating): bench_arcstar_files.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <string>
#include <vector>

#include "evcorner/arcstar.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/fa_harris.hpp"
#include "detector_runs.hpp"
#include "real_files.hpp"

using namespace evcorner;

namespace {

// The 8 cuts with Arc* goldens: no slider_depth, no AEDAT recording.
bool arcstar_cut(const bench::RealFile& f) { return f.ecd && f.name != "slider_depth"; }

// Arc*'s portable loop (every x86-64 runs it), timed as bench::replay times detect().
void replay_portable(benchmark::State& state, const bench::Input* in) {
    std::vector<std::uint8_t> flags(in->events.size());
    std::size_t corners = 0;
    for (auto _ : state) {
        state.PauseTiming();
        ArcStar det(kDavis240);
        state.ResumeTiming();
        corners = det.run_unchecked<ScalarSearch>(in->events, flags);
        benchmark::DoNotOptimize(corners);
    }
    bench::per_event(state, in->events.size(), corners);
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<bench::Input> inputs = bench::load_real_inputs(arcstar_cut);
    for (const bench::Input& in : inputs) {
        const bench::Input* p = &in;
        benchmark::RegisterBenchmark(("efast/" + in.name).c_str(), [p](benchmark::State& s) {
            bench::replay<true>(s, p, [] { return EFast(kDavis240); });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("arcstar/" + in.name).c_str(), [p](benchmark::State& s) {
            bench::replay<true>(s, p, [] { return ArcStar(kDavis240); });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("arcstar_portable/" + in.name).c_str(), [p](benchmark::State& s) {
            replay_portable(s, p);
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("arcstar_nofilter/" + in.name).c_str(), [p](benchmark::State& s) {
            bench::replay<true>(s, p, [] { return ArcStar(kDavis240, {.filter = false}); });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("arcstar_minority/" + in.name).c_str(), [p](benchmark::State& s) {
            bench::replay<true>(s, p, [] { return ArcStar(kDavis240, {.minority_only = true}); });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("fa_harris/" + in.name).c_str(), [p](benchmark::State& s) {
            bench::replay<true>(s, p, [] { return FaHarris(kDavis240); });
        })->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
