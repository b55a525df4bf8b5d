#pragma once
// The static background image of a scene: uniform, or seeded value noise.

#include <cstdint>
#include <vector>

#include "evcorner/sensor.hpp"
#include "evcorner/sim/scene.hpp"

namespace evcorner::sim {

/// Intensity of every pixel (row-major), in [0, 1]. A texture is value noise: random levels
/// on a square lattice of spacing scale_px, smoothly interpolated (smoothstep in x and y) at
/// each pixel's centre, plus `octaves - 1` finer layers (half the spacing and half the weight
/// each), scaled so the layers' sum lies in [-1, 1]; mean + amplitude * that, clamped to [0, 1].
std::vector<double> background_image(const Background& b, SensorSize size, std::uint64_t seed);

}  // namespace evcorner::sim
