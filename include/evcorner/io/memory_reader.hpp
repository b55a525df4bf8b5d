#pragma once
// Events already in memory, handed out as a file reader hands them: in batches, nothing
// skipped. For replaying one loaded sequence to several runs (benchmarks, evaluations).

#include <optional>
#include <span>
#include <string>

#include "evcorner/event.hpp"
#include "evcorner/io/event_reader.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::io {

class MemoryReader final : public EventReader {
public:
    /// `events` must outlive the reader; `name` is what errors and summaries call it.
    MemoryReader(std::span<const Event> events, std::optional<SensorSize> sensor, std::string name);

    std::size_t read(std::span<Event> out) override;
    [[nodiscard]] std::span<const SkipRun> skipped_in_batch() const noexcept override { return {}; }
    [[nodiscard]] std::uint64_t skipped() const noexcept override { return 0; }
    [[nodiscard]] std::optional<SensorSize> sensor() const noexcept override { return sensor_; }
    [[nodiscard]] std::string_view format() const noexcept override { return "memory"; }
    [[nodiscard]] const std::string& name() const noexcept override { return name_; }
    [[nodiscard]] std::uint64_t bytes_consumed() const noexcept override { return next_ * sizeof(Event); }
    [[nodiscard]] std::optional<std::uint64_t> bytes_total() const noexcept override {
        return events_.size() * sizeof(Event);
    }

private:
    std::span<const Event> events_;
    std::size_t next_ = 0;
    std::optional<SensorSize> sensor_;
    std::string name_;
};

}  // namespace evcorner::io
