// Google Benchmark of Arc* and FA-Harris beside eFAST on the 8 real Event-Camera-Dataset
// cuts that have Arc* goldens (replayed: every iteration runs the file with a fresh
// detector, constructed outside the timing). Read "time_per_event". For medians:
//   build/bin/bench_arcstar --benchmark_repetitions=9 --benchmark_report_aggregates_only=true
// Variants per file: efast, arcstar (detect(): the path chosen for this CPU), arcstar_portable
// (the loop every x86-64 runs), arcstar_nofilter, arcstar_minority, fa_harris.
// Cold figures (one pass per file, files rotating): bench_arcstar_files.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/arcstar.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/fa_harris.hpp"
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
        if (f.ecd && f.name != "slider_depth") inputs.push_back({f.name, bench::load_events(f.events)});
    if (inputs.empty())
        inputs.push_back({"bundled_shapes_translation",
                          bench::load_events(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt")});
    return inputs;
}

template <class Make, class Run>
void run(benchmark::State& state, const Input* in, Make make, Run detect_with) {
    std::vector<std::uint8_t> flags(in->events.size());
    std::size_t corners = 0;
    for (auto _ : state) {
        state.PauseTiming();
        auto det = make();
        state.ResumeTiming();
        corners = detect_with(det, in->events, flags);
        benchmark::DoNotOptimize(corners);
    }
    const double n = static_cast<double>(in->events.size());
    state.counters["time_per_event"] = benchmark::Counter(
        n * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["corners"] = static_cast<double>(corners);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * in->events.size()));
}

const auto kDetect = [](auto& det, const std::vector<Event>& ev, std::vector<std::uint8_t>& flags) {
    return detect(det, std::span<const Event>(ev), flags);
};

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<Input> inputs = load_inputs();
    for (const Input& in : inputs) {
        const Input* p = &in;
        benchmark::RegisterBenchmark(("efast/" + in.name).c_str(), [p](benchmark::State& s) {
            run(s, p, [] { return EFast(kDavis240); }, kDetect);
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("arcstar/" + in.name).c_str(), [p](benchmark::State& s) {
            run(s, p, [] { return ArcStar(kDavis240); }, kDetect);
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("arcstar_portable/" + in.name).c_str(), [p](benchmark::State& s) {
            run(s, p, [] { return ArcStar(kDavis240); },
                [](ArcStar& det, const std::vector<Event>& ev, std::vector<std::uint8_t>& flags) {
                    return det.run_unchecked<ScalarSearch>(ev, flags);
                });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("arcstar_nofilter/" + in.name).c_str(), [p](benchmark::State& s) {
            run(s, p, [] { return ArcStar(kDavis240, {.filter = false}); }, kDetect);
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("arcstar_minority/" + in.name).c_str(), [p](benchmark::State& s) {
            run(s, p, [] { return ArcStar(kDavis240, {.minority_only = true}); }, kDetect);
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("fa_harris/" + in.name).c_str(), [p](benchmark::State& s) {
            run(s, p, [] { return FaHarris(kDavis240); }, kDetect);
        })->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
