// ROS bag reader throughput (events/s) on the real bags of ../shared/data/real, read from
// the page cache in 64 Ki-event batches, each run opening the bag afresh (topics, counts,
// the first message) as a command does. The EVT 3.0 RAW file is read in the same run: the
// bags' evt3 payloads go through the same word decoder.

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
