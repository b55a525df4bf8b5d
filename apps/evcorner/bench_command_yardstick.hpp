#pragma once
// The yardstick of `evcorner bench --yardstick`: a plain, exhaustive eFAST (int64 SAE per
// polarity; every start and every length of each circle's arcs checked from scratch), the
// same computation as ../shared/tools/plain-efast.cpp that speed-ratio.py times, built into
// the tool so that it is compiled by the same compiler with the same flags as the
// detectors and runs on any input and sensor size. Speed is judged as a ratio to it, timed
// in the same run, because absolute times differ several-fold between CPUs.

#include <cstdint>
#include <span>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::cli {

/// Now in ns for timing a pass: the wall clock (steady_clock), or with `cpu_time` the calling
/// thread's CPU time (CLOCK_THREAD_CPUTIME_ID), which leaves out the time other processes
/// hold the core on a loaded machine.
double bench_clock_ns(bool cpu_time) noexcept;

struct YardstickPass {
    std::uint64_t corners = 0;
    double ns_per_event = 0;  ///< bench_clock_ns around the event loop (state allocation outside)
};

/// One cold pass of the plain eFAST over `events` (a fresh, never-fired SAE).
YardstickPass plain_efast_pass(std::span<const Event> events, SensorSize sensor, bool cpu_time);

}  // namespace evcorner::cli
