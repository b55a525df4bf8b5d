#pragma once
// Seeded random event streams for the Arc* and FA-Harris oracle tests: events clustered
// around drifting filled squares (so that circles see corners and edges), 5 % uniform
// clutter with the borders, both polarities, time steps drawn so that the 50 ms filter
// both passes and rejects: many equal timestamps (ties), short steps, and now and then a
// long pause, so that pixels fire in bursts and again after the window.

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::test {

/// `step_us`: the largest ordinary time step; every 500 events or so a pause of 0..3 x
/// `pause_us`.
inline std::vector<Event> arcstar_stream(SensorSize s, std::size_t n, std::uint64_t seed, std::int64_t step_us,
                                         std::int64_t pause_us) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> spread(0.0, 3.0);
    struct Blob {
        double x, y, vx, vy;
    };
    std::vector<Blob> blobs(4);
    for (auto& b : blobs) b = {unit(rng) * s.width, unit(rng) * s.height, unit(rng) - 0.5, unit(rng) - 0.5};
    std::vector<Event> ev;
    ev.reserve(n);
    std::int64_t t = 1000 + static_cast<std::int64_t>(rng() % 100000);  // some start inside the first 50 ms
    for (std::size_t i = 0; i < n; ++i) {
        if (rng() % 3 != 0) t += static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(step_us + 1));
        if (rng() % 500 == 0) t += static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(3 * pause_us + 1));
        int x, y;
        if (unit(rng) < 0.05) {
            x = static_cast<int>(rng() % static_cast<unsigned>(s.width));
            y = static_cast<int>(rng() % static_cast<unsigned>(s.height));
        } else {
            Blob& b = blobs[rng() % blobs.size()];
            b.x += b.vx * 0.05;
            b.y += b.vy * 0.05;
            if (b.x < 0 || b.x >= s.width) b.vx = -b.vx;
            if (b.y < 0 || b.y >= s.height) b.vy = -b.vy;
            x = std::clamp(static_cast<int>(b.x + spread(rng)), 0, s.width - 1);
            y = std::clamp(static_cast<int>(b.y + spread(rng)), 0, s.height - 1);
        }
        ev.push_back({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                      static_cast<std::uint8_t>(rng() & 1)});
    }
    return ev;
}

}  // namespace evcorner::test
