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
#include "evcorner/io/open.hpp"
#include "evcorner/parallel_detect.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

std::vector<fs::path> real_files() {
    std::vector<fs::path> files;
    const fs::path shared = fs::path(EVCORNER_SHARED_DIR) / "data/real";
    if (fs::is_directory(shared / "ecd-stppp")) {
        for (const char* seq : {"boxes_rotation", "boxes_translation", "dynamic_rotation",
                                "dynamic_translation", "poster_rotation", "poster_translation",
                                "shapes_rotation", "shapes_translation"})
            files.push_back(shared / "ecd-stppp" / seq / "events.txt");
        files.push_back(shared / "ecd-slider-depth-eventsviz/slider_depth/events_chunk.txt");
        files.push_back(shared / "davis240c-imu-pyaedattools/IMU_rotDisk.aedat");
        files.push_back(shared / "davis240c-imu-pyaedattools/IMU_translBoxes.aedat");
    } else {
        files.push_back(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt");
    }
    return files;
}

std::vector<Event> load(const fs::path& f) {
    auto reader = io::open_event_reader(f.string());
    std::vector<Event> events, batch(1 << 16);
    for (std::size_t n; (n = reader->read(batch)) > 0;) events.insert(events.end(), batch.begin(), batch.begin() + n);
    return events;
}

std::string short_name(const fs::path& f) {
    return f.extension() == ".aedat" ? f.stem().string() : f.parent_path().filename().string();
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
    static std::vector<std::vector<Event>> loaded;
    const auto files = real_files();
    loaded.reserve(files.size());
    for (const auto& f : files) loaded.push_back(load(f));
    for (std::size_t i = 0; i < files.size(); ++i) {
        const std::string name = short_name(files[i]);
        const std::vector<Event>* ev = &loaded[i];
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
