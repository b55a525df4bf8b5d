#pragma once
// Exact area coverage of polygons on the pixel grid (anti-aliased, no staircase).
//
// For each pixel the integral of the polygon's winding number over the pixel square, which
// for a simple polygon with positive signed_area() is the covered fraction of the pixel.
// Each edge is cut at the row and column lines into pieces lying in one cell; a piece with
// signed height h (the edge's y-extent in the cell, positive upwards) and mean x xm in cell
// column k adds h (k + 1 - xm) to its own cell and h (xm - k) to the next one; the running
// sum along each row then gives every pixel the area between the edges to its left, exactly
// (x is linear in y along a piece, so its mean is the midpoint). Work: one cell per piece,
// plus one addition per pixel of the rows and columns a polygon spans. The edge walk itself
// is walk_coverage() (coverage_walk.hpp).

#include <cstddef>
#include <span>
#include <vector>

#include "evcorner/sensor.hpp"
#include "evcorner/sim/scene.hpp"

namespace evcorner::sim {

/// Adds `weight` times the edges of `poly` into `acc`, rows [0, height) of `stride` doubles
/// each (stride >= width + 2); parts left of x = 0 add to column 0, parts right of x = width
/// and outside the rows add nothing. The running sum of a row over columns [0, x] is then
/// weight times the coverage of pixel x.
void accumulate_polygon(std::span<const Vec2> poly, double weight, double* acc, std::size_t stride, int width,
                        int height) noexcept;

/// accumulate_polygon into acc with weight and into acc2 with weight2 in one walk of the
/// edges; each array gets exactly the values two separate calls would give.
void accumulate_polygon2(std::span<const Vec2> poly, double weight, double* acc, double weight2, double* acc2,
                         std::size_t stride, int width, int height) noexcept;

/// The coverage of the one pixel (x, y) (any integers, on the sensor or not): the same area as
/// the running sums give, computed from the edges alone (each edge's part in the row band
/// [y, y + 1] adds its height times the mean fraction of the pixel to its right). Work: one
/// pass over the edges; the simulator uses it to sample single pixels between steps.
double pixel_coverage(std::span<const Vec2> poly, int x, int y) noexcept;

/// The coverage of every pixel (row-major, width x height), each in [0, 1].
std::vector<double> polygon_coverage(std::span<const Vec2> poly, SensorSize size);

}  // namespace evcorner::sim
