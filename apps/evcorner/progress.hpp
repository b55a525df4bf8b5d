#pragma once
// A progress bar on standard error, drawn only when standard error is a terminal and
// the run lasts long enough to need one.

#include <chrono>
#include <cstdint>
#include <optional>

namespace evcorner::cli {

class Progress {
public:
    /// total_bytes: the input's size when known (a percentage is shown then).
    Progress(bool enabled, std::optional<std::uint64_t> total_bytes);
    ~Progress() { finish(); }

    /// Cheap to call often: redraws at most ten times a second.
    void update(std::uint64_t bytes_done, std::uint64_t events_done);
    /// Erases the bar.
    void finish();

private:
    bool enabled_;
    bool drawn_ = false;
    std::optional<std::uint64_t> total_;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_;
};

}  // namespace evcorner::cli
