// AEDAT 4.0 reader throughput (events/s), target >= 100 M events/s: the real
// DVXplorer recording (LZ4, 59 event packets among IMU packets) and a synthetic 4 M-event
// file written by Aedat4Writer (LZ4 and uncompressed, 8192-event packets, random pixels
// with slowly rising time, so LZ4 finds little to compress in x/y). Page cache, 64 Ki batches.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "evcorner/io/aedat4_reader.hpp"
#include "evcorner/io/aedat4_writer.hpp"

namespace {

using evcorner::io::Aedat4Reader;
using evcorner::io::Aedat4Writer;

void read_all(benchmark::State& state, const std::string& path) {
    std::vector<evcorner::Event> buf(1 << 16);
    std::uint64_t events = 0;
    for (auto _ : state) {
        Aedat4Reader r(path);
        while (const std::size_t n = r.read(buf)) {
            events += n;
            benchmark::DoNotOptimize(buf.data());
        }
    }
    state.counters["events/s"] = benchmark::Counter(static_cast<double>(events), benchmark::Counter::kIsRate);
}

std::string synthetic(Aedat4Writer::Compression c) {
    const std::string path = (std::filesystem::temp_directory_path() /
                              (c == Aedat4Writer::Compression::lz4 ? "evcorner-bench-lz4.aedat4" : "evcorner-bench-raw.aedat4"))
                                 .string();
    std::mt19937 rng(1);
    Aedat4Writer w(path, {evcorner::SensorSize{640, 480}, c, 8192});
    std::vector<evcorner::Event> ev(1 << 16);
    std::int64_t t = 0;
    for (int b = 0; b < 64; ++b) {
        for (auto& e : ev) {
            t += rng() % 3;
            e = {t, static_cast<std::uint16_t>(rng() % 640), static_cast<std::uint16_t>(rng() % 480),
                 static_cast<std::uint8_t>(rng() & 1)};
        }
        w.write(ev);
    }
    w.close();
    return path;
}

void BM_real_dvxplorer(benchmark::State& state) {
    const std::string path = std::string(EVCORNER_SHARED_DIR) + "/data/real/tonic-testdata/sample.aedat4";
    if (!std::filesystem::exists(path)) {
        state.SkipWithError(("missing " + path).c_str());
        return;
    }
    read_all(state, path);
}
BENCHMARK(BM_real_dvxplorer)->Unit(benchmark::kMillisecond);

void BM_synthetic_lz4(benchmark::State& state) {
    static const std::string path = synthetic(Aedat4Writer::Compression::lz4);
    read_all(state, path);
}
BENCHMARK(BM_synthetic_lz4)->Unit(benchmark::kMillisecond);

void BM_synthetic_uncompressed(benchmark::State& state) {
    static const std::string path = synthetic(Aedat4Writer::Compression::none);
    read_all(state, path);
}
BENCHMARK(BM_synthetic_uncompressed)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
