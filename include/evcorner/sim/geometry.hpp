#pragma once
// Plane geometry of the simulator's polygons: area, simplicity, angles, point inside.

#include <cstddef>
#include <optional>
#include <span>
#include <utility>

#include "evcorner/sim/scene.hpp"

namespace evcorner::sim {

/// Shoelace area: positive when the vertices run from +x towards +y (clockwise on screen).
double signed_area(std::span<const Vec2> poly) noexcept;

/// The first pair of non-adjacent edges (i, j), edge i from vertex i to i+1, that touch or
/// cross; nullopt for a simple polygon.
std::optional<std::pair<std::size_t, std::size_t>> first_self_intersection(std::span<const Vec2> poly) noexcept;

/// Interior angle in degrees, (0, 360), at vertex v between its neighbours prev and next, of a
/// polygon with positive signed_area().
double interior_angle_deg(Vec2 prev, Vec2 v, Vec2 next) noexcept;

/// Whether p lies strictly inside (even-odd rule; points on an edge may go either way).
bool inside(std::span<const Vec2> poly, Vec2 p) noexcept;

}  // namespace evcorner::sim
