#pragma once
// The two timing helpers the stand-alone benchmark programs share: the calling thread's CPU
// time (so that on a shared machine the time spent waiting for a core does not count; page
// faults and other system time do), and the median of a set of timings.

#include <algorithm>
#include <ctime>
#include <vector>

namespace evcorner::bench {

/// The calling thread's CPU time in nanoseconds (CLOCK_THREAD_CPUTIME_ID).
inline double thread_cpu_ns() noexcept {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e9 + static_cast<double>(ts.tv_nsec);
}

/// The median of `v` (the mean of the middle two for an even count); 0 for none.
inline double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace evcorner::bench
