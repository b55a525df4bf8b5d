// Micro-benchmark of eFAST's per-event path on the real Event-Camera-Dataset cuts.
// Each run processes a file's events with a fresh detector (construction untimed);
// "ns_per_event" is the figure to read. Use --benchmark_repetitions=N for medians.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/io/text_reader.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

std::vector<fs::path> ecd_files() {
    std::vector<fs::path> files;
    const fs::path shared = fs::path(EVCORNER_SHARED_DIR) / "data/real";
    if (fs::is_directory(shared / "ecd-stppp")) {
        for (const char* seq : {"boxes_rotation", "boxes_translation", "dynamic_rotation",
                                "dynamic_translation", "poster_rotation", "poster_translation",
                                "shapes_rotation", "shapes_translation"})
            files.push_back(shared / "ecd-stppp" / seq / "events.txt");
        files.push_back(shared / "ecd-slider-depth-eventsviz/slider_depth/events_chunk.txt");
    } else {
        files.push_back(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt");
    }
    return files;
}

template <class D>
void run_detector(benchmark::State& state, const std::vector<Event>& events) {
    std::vector<std::uint8_t> flags(events.size());
    std::size_t corners = 0;
    for (auto _ : state) {
        state.PauseTiming();
        D det(kDavis240);
        state.ResumeTiming();
        corners = detect(det, std::span<const Event>(events), flags);
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
    static std::vector<std::vector<Event>> loaded;
    const auto files = ecd_files();
    loaded.reserve(files.size());
    for (const auto& f : files) {
        loaded.push_back(io::read_text_file(f.string()));
        const std::string name = f.parent_path().filename().string();
        const std::vector<Event>* ev = &loaded.back();
        benchmark::RegisterBenchmark(("efast/" + name).c_str(),
                                     [ev](benchmark::State& s) { run_detector<EFast>(s, *ev); })
            ->Unit(benchmark::kMicrosecond);
    }
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
}
