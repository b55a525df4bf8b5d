#pragma once
// How much memory a detector's state needs, how much the machine has, and the refusal
// when it does not fit (make_detector checks before allocating anything).

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "evcorner/sensor.hpp"

namespace evcorner {

/// A detector state that does not fit in the memory available. what() reads e.g. "a
/// 65536x65536 sensor needs 68.7 GB for efast's state (16 B per pixel); 21.3 GB is available".
class StateTooLarge : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Bytes the system can still give this process without swapping: MemAvailable of
/// /proc/meminfo, else free physical pages (sysconf); also bounded by a cgroup v2 memory
/// limit when there is one. 0 when none of these can be read (then nothing is refused).
std::uint64_t available_memory_bytes() noexcept;

/// "68.7 GB", "512 kB", "16 B": decimal units, three significant figures.
std::string format_bytes(std::uint64_t bytes);

/// Throws StateTooLarge when `need` bytes of `detector`'s state for `size` exceed
/// `available` (0: unknown, never refused). What every other allocation a user's number
/// decides (an image's size, a replay's length, a simulated sensor) is checked with too:
void require_state_fits(std::string_view detector, SensorSize size, std::uint64_t need, std::uint64_t available);

/// Throws StateTooLarge, reading "<what> needs 24.6 GB; 21.3 GB is available<hint>", when
/// `need` bytes exceed available_memory_bytes() (unknown: never refused). `hint` tells
/// the user what to lower, e.g. " (lower --scale)".
void require_memory_fits(std::string_view what, std::uint64_t need, std::string_view hint = {});

}  // namespace evcorner
