#pragma once
// The two Bresenham circles eFAST samples around an event (Mueggler et al., BMVC 2017,
// Fig. 3): radius 3 with 16 pixels and radius 4 with 20 pixels, in cyclic order.
// The order is the one of the authors' reference implementation (arcs are contiguous in
// it; docs/efast.md); tests check count, distinctness,
// distance from the centre and symmetry.

#include <array>
#include <cstddef>

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

}  // namespace evcorner
