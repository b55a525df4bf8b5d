// ns/event of each detector on each real Event-Camera-Dataset cut (files loaded once,
// before timing). Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// for medians. Without ../shared, falls back to the bundled shapes_translation sample.
//
// The cost of checking the events at the boundary: <detector>/<file> is detect() (checks
// the span in one pass, then runs), <detector>_unchecked/<file> is detect_unchecked(),
// and check_events/<file> is the checking pass alone.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/event_check.hpp"
#include "evcorner/harris.hpp"
#include "evcorner/harris_global.hpp"
#include "real_files.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

struct Input {
    std::string name;
    std::vector<Event> events;
};

// The nine Event-Camera-Dataset cuts, else the bundled one.
std::vector<Input> load_inputs() {
    std::vector<Input> inputs;
    for (const auto& f : bench::real_240x180_files(fs::path(EVCORNER_SHARED_DIR) / "data"))
        if (f.ecd) inputs.push_back({f.name, bench::load_events(f.events)});
    if (inputs.empty())
        inputs.push_back({"bundled_shapes_translation",
                          bench::load_events(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt")});
    return inputs;
}

void set_counters(benchmark::State& state, const Input* in);

// A fresh detector per pass, so that every pass sees the same stream from the start;
// its construction is outside the timing.
template <bool Checked, class Make>
void run(benchmark::State& state, const Input* in, Make make) {
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
    set_counters(state, in);
    state.counters["corners"] = static_cast<double>(corners);
}

void set_counters(benchmark::State& state, const Input* in) {
    const double n = static_cast<double>(in->events.size());
    // Seconds per event (printed with an SI prefix: "250n" = 250 ns/event).
    state.counters["time_per_event"] = benchmark::Counter(
        n * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * in->events.size()));
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<Input> inputs = load_inputs();
    for (const Input& in : inputs) {
        benchmark::RegisterBenchmark(("check_events/" + in.name).c_str(), [&in](benchmark::State& s) {
            const EventLimits limits = EFast(kDavis240).limits();
            for (auto _ : s) benchmark::DoNotOptimize(first_invalid_event(in.events, limits));
            set_counters(s, &in);
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("efast/" + in.name).c_str(), [&in](benchmark::State& s) {
            run<true>(s, &in, [] { return EFast(kDavis240); });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("efast_unchecked/" + in.name).c_str(), [&in](benchmark::State& s) {
            run<false>(s, &in, [] { return EFast(kDavis240); });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("harris/" + in.name).c_str(), [&in](benchmark::State& s) {
            run<true>(s, &in, [] { return Harris(kDavis240); });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("harris_unchecked/" + in.name).c_str(), [&in](benchmark::State& s) {
            run<false>(s, &in, [] { return Harris(kDavis240); });
        })->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("harris_global/" + in.name).c_str(), [&in](benchmark::State& s) {
            run<true>(s, &in, [] { return HarrisGlobal(kDavis240); });
        })->Unit(benchmark::kMillisecond);
    }
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
