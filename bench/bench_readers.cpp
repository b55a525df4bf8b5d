// Reader throughput (events/s) on the real recordings, read from the page cache in
// 64 Ki-event batches. Issue 5 targets: ECD text >= 20 M events/s, EVT 3.0 >= 100 M.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include "evcorner/io/open.hpp"

namespace {

void read_file(benchmark::State& state, const std::string& rel) {
    const std::string path = std::string(EVCORNER_SHARED_DIR) + "/data/real/" + rel;
    if (!std::filesystem::exists(path)) {
        state.SkipWithError(("missing " + path).c_str());
        return;
    }
    std::vector<evcorner::Event> buf(1 << 16);
    std::uint64_t events = 0;
    for (auto _ : state) {
        evcorner::io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        auto r = evcorner::io::open_event_reader(path, o);
        while (const std::size_t n = r->read(buf)) {
            events += n;
            benchmark::DoNotOptimize(buf.data());
        }
    }
    state.counters["events/s"] = benchmark::Counter(static_cast<double>(events), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(read_file, ecd_text, std::string("ecd-stppp/shapes_rotation/events.txt"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, aedat2_davis, std::string("davis240c-imu-pyaedattools/IMU_rotDisk.aedat"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, evt2, std::string("expelliarmus/evt2_sample.raw"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, evt3, std::string("expelliarmus/evt3_sample.raw"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, dat, std::string("tonic-testdata/sample_ncars.dat"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
