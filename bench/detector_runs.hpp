#pragma once
// The timing loops the detector benchmarks share (bench_detectors, bench_efast_harris):
// the real 240x180 inputs loaded once, a replayed file and a cold pass over all files,
// each with a fresh detector per pass built outside the timing, and the per-event counter.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "real_files.hpp"

namespace evcorner::bench {

struct Input {
    std::string name;
    std::vector<Event> events;
};

/// The 11 real 240x180 files (real_files.hpp), or those of them `keep` accepts, else the
/// bundled shapes_translation sample.
inline std::vector<Input> load_real_inputs(bool (*keep)(const RealFile&) = nullptr) {
    namespace fs = std::filesystem;
    std::vector<Input> inputs;
    for (const auto& f : real_240x180_files(fs::path(EVCORNER_SHARED_DIR) / "data"))
        if (keep == nullptr || keep(f)) inputs.push_back({f.name, load_events(f.events)});
    if (inputs.empty())
        inputs.push_back({"bundled_shapes_translation",
                          load_events(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt")});
    return inputs;
}

/// Counters: time_per_event (seconds per event, "25n" = 25 ns), corners, items.
inline void per_event(benchmark::State& state, std::size_t events_per_iteration, std::size_t corners) {
    const double n = static_cast<double>(events_per_iteration);
    state.counters["time_per_event"] = benchmark::Counter(
        n * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["corners"] = static_cast<double>(corners);
    state.SetItemsProcessed(static_cast<std::int64_t>(static_cast<double>(state.iterations()) * n));
}

/// One file again and again, a fresh detector (make()) per pass; detect() when Checked,
/// else detect_unchecked().
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

/// Every file once per iteration, in turn, a fresh detector each (as a user runs a file).
template <bool Checked, class Make>
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
            const std::span<std::uint8_t> f(flags.data(), in.events.size());
            if constexpr (Checked)
                corners += detect(det, in.events, f);
            else
                corners += detect_unchecked(det, in.events, f);
        }
        benchmark::DoNotOptimize(corners);
    }
    per_event(state, total, corners);
}

}  // namespace evcorner::bench
