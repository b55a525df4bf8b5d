// Reader throughput (events/s) on the real recordings, read from the page cache in
// 64 Ki-event batches. Targets: ECD text >= 20 M events/s, EVT 3.0 >= 100 M.

#include <benchmark/benchmark.h>

#include <string>

#include "read_throughput.hpp"

namespace {

void read_file(benchmark::State& state, const std::string& rel) {
    evcorner::bench::read_throughput(state, evcorner::bench::real_data_file(rel));
}

BENCHMARK_CAPTURE(read_file, ecd_text, std::string("ecd-stppp/shapes_rotation/events.txt"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, aedat2_davis, std::string("davis240c-imu-pyaedattools/IMU_rotDisk.aedat"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, evt2, std::string("expelliarmus/evt2_sample.raw"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, evt3, std::string("expelliarmus/evt3_sample.raw"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, dat, std::string("tonic-testdata/sample_ncars.dat"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
