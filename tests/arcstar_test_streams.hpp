#pragma once
// Seeded random event streams for the Arc* and FA-Harris oracle tests: events clustered
// around drifting filled squares (so that circles see corners and edges), 5 % uniform
// clutter with the borders, both polarities, time steps drawn so that the 50 ms filter
// both passes and rejects: many equal timestamps (ties), short steps, and now and then a
// long pause, so that pixels fire in bursts and again after the window.

#include <cstdint>
#include <random>
#include <vector>

#include "blob_stream.hpp"

namespace evcorner::test {

/// `step_us`: the largest ordinary time step; every 500 events or so a pause of 0..3 x
/// `pause_us`.
inline std::vector<Event> arcstar_stream(SensorSize s, std::size_t n, std::uint64_t seed, std::int64_t step_us,
                                         std::int64_t pause_us) {
    // Some start inside the first 50 ms.
    return blob_stream(s, n, seed, {.start_jitter = 100000}, [=](std::mt19937_64& rng) {
        std::int64_t dt = 0;
        if (rng() % 3 != 0) dt += static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(step_us + 1));
        if (rng() % 500 == 0) dt += static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(3 * pause_us + 1));
        return dt;
    });
}

}  // namespace evcorner::test
