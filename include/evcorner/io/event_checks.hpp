#pragma once
// What every reader does with a decoded event before handing it out, kept in one place:
// the record of events skipped as outside the sensor (--skip-invalid), and the messages
// for an event outside the sensor and for time going backwards.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "evcorner/io/event_reader.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::io {

/// Events skipped so far, and this batch's runs of them (EventReader::skipped_in_batch).
class SkipLog {
public:
    /// Starts a new batch: its runs are cleared, the total carries on.
    void new_batch() noexcept { runs_.clear(); }
    /// One event skipped just before out[before] of this batch. Consecutive skips share
    /// one run, so memory stays bounded.
    void skip(std::size_t before) {
        ++total_;
        if (!runs_.empty() && runs_.back().before == before)
            ++runs_.back().count;
        else
            runs_.push_back({before, 1});
    }
    [[nodiscard]] std::span<const SkipRun> batch() const noexcept { return runs_; }
    [[nodiscard]] std::uint64_t total() const noexcept { return total_; }

private:
    std::vector<SkipRun> runs_;
    std::uint64_t total_ = 0;
};

/// "event at x=.. y=.. lies outside the WxH sensor (set --size, or --skip-invalid ...)", or,
/// with no sensor known, that the event does not fit 16-bit coordinates.
/// `keyword_spelling`: name the options as Python's keywords (ReaderOptions::keyword_spelling).
std::string outside_sensor_message(std::int64_t x, std::int64_t y, const std::optional<SensorSize>& sensor,
                                   bool keyword_spelling = false);
/// "timestamp goes backwards (N us before the previous event)", exact for any two int64 times.
std::string backwards_message(std::int64_t previous, std::int64_t t);

}  // namespace evcorner::io
