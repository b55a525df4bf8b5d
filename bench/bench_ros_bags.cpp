// ROS bag reader throughput (events/s) on the real bags of ../shared/data/real, read from
// the page cache in 64 Ki-event batches, each run opening the bag afresh (topics, counts,
// the first message) as a command does. The EVT 3.0 RAW file is read in the same run: the
// bags' evt3 payloads go through the same word decoder.

#include <benchmark/benchmark.h>

#include <string>

#include "read_throughput.hpp"

namespace {

void read_file(benchmark::State& state, const std::string& rel) {
    evcorner::bench::read_throughput(state, evcorner::bench::real_data_file(rel));
}

BENCHMARK_CAPTURE(read_file, evt3_raw, std::string("expelliarmus/evt3_sample.raw"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, rosbag2_evt3, std::string("ros2-event-camera-py/test_events_1/test_events_1.db3"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, rosbag2_evt3_trigger,
                  std::string("ros2-event-camera-codecs/test_data_evt3_trigger/test_data_evt3_trigger_0.db3"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, rosbag2_libcaer,
                  std::string("ros2-event-camera-codecs/test_data_libcaer_rollover/libcaer_rollover_0.db3"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, mcap_libcaer_cmp, std::string("ros2-event-camera-py/test_events_2/test_events_2_0.mcap"))
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(read_file, rosbag1_evt3, std::string("ros2-event-camera-py/ros1/test_events_1.bag"))
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
