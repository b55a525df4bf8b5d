#pragma once
// Seeded random event streams for the oracle and parallel tests: events clustered around
// drifting filled squares ("blobs": circles and windows see their edges and corners),
// a share of uniform clutter with the borders, and time steps that often repeat a
// timestamp. Each test picks the shape, the time steps and the polarities.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::test {

struct BlobStreamShape {
    int blobs = 4;
    /// Blob velocities are drawn in speed * [-0.5, 0.5) per axis.
    double speed = 1.0;
    /// Standard deviation of an event's position around its blob, in pixels.
    double spread = 3.0;
    /// How far a blob moves per event of its own, in units of its velocity.
    double drift = 0.05;
    /// The share of events placed uniformly over the sensor.
    double clutter = 0.05;
    /// Round (not truncate) a position around a blob to its pixel.
    bool round = false;
    /// The time before the first step; plus a draw in [0, start_jitter) when it is not 0.
    std::int64_t start_t = 1000;
    std::uint64_t start_jitter = 0;
};

/// A step of 0, 1 or 2 us (0: the same timestamp as the event before).
inline std::int64_t tie_steps(std::mt19937_64& rng) { return static_cast<std::int64_t>(rng() % 3); }
/// Either polarity, evenly.
inline int either_polarity(std::mt19937_64& rng) { return static_cast<int>(rng() & 1); }

/// `n` events; `step(rng)` gives the time step before each event, `polarity(rng)` its
/// polarity (drawn last).
template <class Step = decltype(&tie_steps), class Polarity = decltype(&either_polarity)>
std::vector<Event> blob_stream(SensorSize s, std::size_t n, std::uint64_t seed, const BlobStreamShape& shape,
                               Step step = tie_steps, Polarity polarity = either_polarity) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> spread(0.0, shape.spread);
    struct Blob {
        double x, y, vx, vy;
    };
    std::vector<Blob> blobs(static_cast<std::size_t>(shape.blobs));
    for (auto& b : blobs)
        b = {unit(rng) * s.width, unit(rng) * s.height, shape.speed * (unit(rng) - 0.5),
             shape.speed * (unit(rng) - 0.5)};
    std::vector<Event> ev;
    ev.reserve(n);
    std::int64_t t = shape.start_t;
    if (shape.start_jitter != 0) t += static_cast<std::int64_t>(rng() % shape.start_jitter);
    auto place = [&](double v) {
        return shape.round ? static_cast<int>(std::lround(v)) : static_cast<int>(v);
    };
    for (std::size_t i = 0; i < n; ++i) {
        t += step(rng);
        int x, y;
        if (unit(rng) < shape.clutter) {
            x = static_cast<int>(rng() % static_cast<unsigned>(s.width));
            y = static_cast<int>(rng() % static_cast<unsigned>(s.height));
        } else {
            Blob& b = blobs[rng() % blobs.size()];
            b.x += b.vx * shape.drift;
            b.y += b.vy * shape.drift;
            if (b.x < 0 || b.x >= s.width) b.vx = -b.vx;
            if (b.y < 0 || b.y >= s.height) b.vy = -b.vy;
            x = std::clamp(place(b.x + spread(rng)), 0, s.width - 1);
            y = std::clamp(place(b.y + spread(rng)), 0, s.height - 1);
        }
        const int p = polarity(rng);
        ev.push_back({t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), static_cast<std::uint8_t>(p)});
    }
    return ev;
}

}  // namespace evcorner::test
