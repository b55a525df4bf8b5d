// Feature-track labelling speed (target: 100 000 corner events under 10 s on
// one core). Two inputs of >= 100 000 corner events:
//  - synthetic: 100 straight tracks (60 events each, 1 px jitter) per 100 ms window plus
//    25 % uniform clutter, repeated along time;
//  - real: the eFAST corners of the Event-Camera-Dataset cuts, replayed end to end
//    (each copy shifted in time) until 100 000 corners.

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "evcorner/detector.hpp"
#include "evcorner/efast.hpp"
#include "evcorner/eval/feature_tracks.hpp"
#include "evcorner/io/text_reader.hpp"

namespace fs = std::filesystem;
using namespace evcorner;

namespace {

constexpr std::size_t kCorners = 100'000;

std::vector<Event> synthetic() {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> px(10, 230), py(10, 170), v(-0.5, 0.5);
    std::uniform_int_distribution<int> jit(-1, 1), cx(0, 239), cy(0, 179), pol(0, 1);
    std::vector<Event> out;
    for (std::int64_t window = 0; out.size() < kCorners; window += 100'000) {
        std::uniform_int_distribution<std::int64_t> ct(window, window + 99'999);
        for (int k = 0; k < 100; ++k) {
            const double x0 = px(rng), y0 = py(rng), vx = v(rng), vy = v(rng);
            const int p = pol(rng);
            for (int i = 0; i < 60; ++i) {
                const double ms = i * 1.5;
                const double x = std::clamp(x0 + vx * ms + jit(rng), 0.0, 239.0);
                const double y = std::clamp(y0 + vy * ms + jit(rng), 0.0, 179.0);
                out.push_back({window + static_cast<std::int64_t>(ms * 1000), static_cast<std::uint16_t>(x),
                               static_cast<std::uint16_t>(y), static_cast<std::uint8_t>(p)});
            }
        }
        for (int k = 0; k < 1500; ++k)
            out.push_back({ct(rng), static_cast<std::uint16_t>(cx(rng)), static_cast<std::uint16_t>(cy(rng)),
                           static_cast<std::uint8_t>(pol(rng))});
    }
    std::sort(out.begin(), out.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
    out.resize(kCorners);
    return out;
}

std::vector<Event> real_replayed() {
    const fs::path dir = fs::path(EVCORNER_SHARED_DIR) / "data/real/ecd-stppp";
    std::vector<fs::path> files;
    if (fs::is_directory(dir)) {
        for (const char* s : {"shapes_rotation", "shapes_translation", "dynamic_rotation", "dynamic_translation",
                              "poster_rotation", "poster_translation", "boxes_rotation", "boxes_translation"})
            files.push_back(dir / s / "events.txt");
    } else {
        files.push_back(fs::path(EVCORNER_SOURCE_DIR) / "data/ecd/shapes_translation/events.txt");
    }
    std::vector<std::vector<Event>> per_file;
    for (const auto& f : files) {
        const auto events = io::read_text_file(f.string());
        EFast det(kDavis240);
        std::vector<std::uint8_t> flags(events.size());
        detect(det, std::span<const Event>(events), flags);
        std::vector<Event> c;
        for (std::size_t i = 0; i < events.size(); ++i)
            if (flags[i]) c.push_back(events[i]);
        per_file.push_back(std::move(c));
    }
    std::vector<Event> out;
    std::int64_t offset = 0;
    while (out.size() < kCorners) {
        for (const auto& c : per_file) {
            if (c.empty()) continue;
            const std::int64_t shift = offset - c.front().t;
            for (const Event& e : c) out.push_back({e.t + shift, e.x, e.y, e.p});
            offset = out.back().t + 200'000;  // copies never share a hypothesis
        }
    }
    out.resize(kCorners);
    return out;
}

void run(benchmark::State& state, const std::vector<Event>& corners, const std::string& path = {}) {
    eval::FeatureTrackResult r;
    for (auto _ : state) {
        r = path.empty() ? eval::label_feature_tracks(corners) : eval::label_feature_tracks_on_path(path, corners);
        benchmark::DoNotOptimize(r.on_track.data());
    }
    state.counters["corners"] = static_cast<double>(corners.size());
    state.counters["ft_percent"] = r.ft_percent();
    state.counters["hypotheses"] = static_cast<double>(r.hypotheses);
}

}  // namespace

int main(int argc, char** argv) {
    static const std::vector<Event> syn = synthetic();
    static const std::vector<Event> real = real_replayed();
    benchmark::RegisterBenchmark("label/synthetic_100k", [](benchmark::State& s) { run(s, syn); })
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1);
    benchmark::RegisterBenchmark("label/ecd_efast_replayed_100k", [](benchmark::State& s) { run(s, real); })
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1);
    // Each code path this CPU runs (the unsuffixed ones above take the fastest).
    for (const std::string& path : eval::feature_track_code_paths()) {
        benchmark::RegisterBenchmark(("label/synthetic_100k/" + path).c_str(),
                                     [path](benchmark::State& s) { run(s, syn, path); })
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1);
        benchmark::RegisterBenchmark(("label/ecd_efast_replayed_100k/" + path).c_str(),
                                     [path](benchmark::State& s) { run(s, real, path); })
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1);
    }
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
