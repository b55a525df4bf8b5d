#pragma once
// The two Bresenham circles eFAST samples around an event (Mueggler et al., BMVC 2017,
// Fig. 3): radius 3 with 16 pixels and radius 4 with 20 pixels, in cyclic order.
// The order is the one of the authors' reference implementation (arcs are contiguous in
// it; docs/efast.md); tests check count, distinctness,
// distance from the centre and symmetry.

#include <array>
#include <cstddef>
#include <cstdint>

namespace evcorner {

struct Offset {
    int dx;
    int dy;
    friend constexpr bool operator==(const Offset&, const Offset&) = default;
};

inline constexpr std::array<Offset, 16> kCircle3{{
    {0, 3}, {1, 3}, {2, 2}, {3, 1}, {3, 0}, {3, -1}, {2, -2}, {1, -3},
    {0, -3}, {-1, -3}, {-2, -2}, {-3, -1}, {-3, 0}, {-3, 1}, {-2, 2}, {-1, 3},
}};

inline constexpr std::array<Offset, 20> kCircle4{{
    {0, 4}, {1, 4}, {2, 3}, {3, 2}, {4, 1}, {4, 0}, {4, -1}, {3, -2}, {2, -3}, {1, -4},
    {0, -4}, {-1, -4}, {-2, -3}, {-3, -2}, {-4, -1}, {-4, 0}, {-4, 1}, {-3, 2}, {-2, 3}, {-1, 4},
}};

/// Distance from the centre beyond which no circle pixel lies; events closer than
/// this to the sensor border are never corners.
inline constexpr int kCircleMargin = 4;

/// The events of a sensor whose circles lie on it: kCircleMargin <= x < kCircleMargin +
/// width, and so for y (empty on a side too small for any). holds() is two unsigned
/// compares: a coordinate below the margin wraps to a large value.
struct InnerRegion {
    std::uint32_t width = 0, height = 0;
    [[nodiscard]] static constexpr InnerRegion of(int sensor_width, int sensor_height) noexcept {
        return {side(sensor_width), side(sensor_height)};
    }
    [[nodiscard]] constexpr bool holds(int x, int y) const noexcept {
        return (static_cast<std::uint32_t>(x - kCircleMargin) < width) &
               (static_cast<std::uint32_t>(y - kCircleMargin) < height);
    }

private:
    static constexpr std::uint32_t side(int n) noexcept {
        return static_cast<std::uint32_t>(n > 2 * kCircleMargin ? n - 2 * kCircleMargin : 0);
    }
};

}  // namespace evcorner
