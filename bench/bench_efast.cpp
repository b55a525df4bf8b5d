// Micro-benchmark of eFAST's per-event path on the real 240x180 recordings: the nine
// Event-Camera-Dataset cuts and the two DAVIS240C AEDAT 2.0 files. Each run processes a
// file's events with a fresh detector (construction untimed); "ns_per_event" is the
// figure to read. Variants: efast (detect(), the path chosen for this CPU), efast_<path>
// for every code path this CPU runs (avx512, avx2, portable: the loop every x86-64
// runs), efast_x2 (two threads, parallel_detect.hpp; its first batch plans the parts and
// builds their detectors, which weighs on files this short).
// Use --benchmark_repetitions=N --benchmark_report_aggregates_only=true for medians.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "real_files.hpp"
#include "evcorner/parallel_detect.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

// The 11 real files, else the bundled cut: (name, events).
std::vector<std::pair<std::string, std::vector<Event>>> load_inputs() {
    std::vector<std::pair<std::string, std::vector<Event>>> inputs;
    for (const auto& f : bench::real_240x180_files(fs::path(EVCORNER_SHARED_DIR) / "data"))
        inputs.emplace_back(f.name, bench::load_events(f.events));
    if (inputs.empty())
        inputs.emplace_back("shapes_translation",
                            bench::load_events(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt"));
    return inputs;
}

// run(det, events, flags) once per iteration on a fresh detector from make().
template <class Make, class Run>
void per_file(benchmark::State& state, const std::vector<Event>& events, Make make, Run run) {
    std::vector<std::uint8_t> flags(events.size());
    std::size_t corners = 0;
    for (auto _ : state) {
        state.PauseTiming();
        auto det = make();
        state.ResumeTiming();
        corners = run(*det, events, flags);
        benchmark::DoNotOptimize(flags.data());
    }
    state.counters["corners"] = static_cast<double>(corners);
    // time / (events * 1e-9) = nanoseconds per event
    state.counters["ns_per_event"] = benchmark::Counter(
        static_cast<double>(events.size()) * 1e-9,
        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

int main(int argc, char** argv) {
    static const auto loaded = load_inputs();
    for (const auto& [name, events] : loaded) {
        const std::vector<Event>* ev = &events;
        benchmark::RegisterBenchmark(("efast/" + name).c_str(), [ev](benchmark::State& s) {
            per_file(s, *ev, [] { return std::make_unique<EFast>(kDavis240); },
                     [](EFast& d, const std::vector<Event>& e, std::vector<std::uint8_t>& f) {
                         return detect(d, std::span<const Event>(e), f);
                     });
        })->Unit(benchmark::kMicrosecond);
        for (const std::string& path : efast_code_paths())
            benchmark::RegisterBenchmark(("efast_" + path + "/" + name).c_str(), [ev, path](benchmark::State& s) {
                per_file(s, *ev, [] { return std::make_unique<EFast>(kDavis240); },
                         [&path](EFast& d, const std::vector<Event>& e, std::vector<std::uint8_t>& f) {
                             return detect_on_path(path, d, std::span<const Event>(e), f);
                         });
            })->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark(("efast_x2/" + name).c_str(), [ev](benchmark::State& s) {
            per_file(s, *ev,
                     [] {
                         return std::make_unique<ParallelDetector<EFast>>(kDavis240, 2, kCircleMargin,
                                                                          [](SensorSize s, int planes) { return EFast(s, planes); });
                     },
                     [](ParallelDetector<EFast>& d, const std::vector<Event>& e, std::vector<std::uint8_t>& f) {
                         return d.detect(e, f);
                     });
        })->Unit(benchmark::kMicrosecond)->UseRealTime();
    }
    benchmark::AddCustomContext("efast_code_path", efast_code_path());
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
