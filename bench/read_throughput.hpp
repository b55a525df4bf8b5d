#pragma once
// Reader throughput for the reader benchmarks: a file read whole on every iteration, from
// the page cache in 64 Ki-event batches, each iteration opening it afresh as a command
// does; the rate is reported as the counter events/s.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/io/open.hpp"

namespace evcorner::bench {

/// A recording under ../shared/data/real, by its path there.
inline std::string real_data_file(const std::string& rel) {
    return std::string(EVCORNER_SHARED_DIR) + "/data/real/" + rel;
}

/// Reads `path` (as `format`; no fallback sensor size) on every iteration; skips the
/// benchmark with "missing PATH" when the file is not there.
inline void read_throughput(benchmark::State& state, const std::string& path, std::string_view format = "auto") {
    if (!std::filesystem::exists(path)) {
        state.SkipWithError(("missing " + path).c_str());
        return;
    }
    std::vector<Event> buf(1 << 16);
    std::uint64_t events = 0;
    for (auto _ : state) {
        io::ReaderOptions o;
        o.fallback_sensor = std::nullopt;
        auto r = io::open_event_reader(path, o, format);
        while (const std::size_t n = r->read(buf)) {
            events += n;
            benchmark::DoNotOptimize(buf.data());
        }
    }
    state.counters["events/s"] = benchmark::Counter(static_cast<double>(events), benchmark::Counter::kIsRate);
}

}  // namespace evcorner::bench
