#include "evcorner/efast.hpp"

#include "evcorner/arc_test.hpp"

namespace evcorner {

EFast::EFast(SensorSize size) : sae_(size) {
    for (std::size_t k = 0; k < kCircle3.size(); ++k)
        off3_[k] = static_cast<std::ptrdiff_t>(kCircle3[k].dy) * size.width + kCircle3[k].dx;
    for (std::size_t k = 0; k < kCircle4.size(); ++k)
        off4_[k] = static_cast<std::ptrdiff_t>(kCircle4[k].dy) * size.width + kCircle4[k].dx;
}

bool EFast::process(const Event& e) noexcept {
    sae_.update(e);
    const SensorSize s = sae_.size();
    if (e.x < kCircleMargin || e.x >= s.width - kCircleMargin || e.y < kCircleMargin ||
        e.y >= s.height - kCircleMargin)
        return false;

    const std::int64_t* centre =
        sae_.plane(e.p) + static_cast<std::ptrdiff_t>(e.y) * s.width + e.x;
    constexpr int n3 = kCircle3.size();
    constexpr int n4 = kCircle4.size();
    std::array<std::int64_t, 2 * n3> t3;  // the circle twice: arcs never wrap
    for (int k = 0; k < n3; ++k) t3[k] = t3[k + n3] = centre[off3_[k]];
    if (!arc_fires<n3, kArc3Min, kArc3Max>(t3.data())) return false;

    std::array<std::int64_t, 2 * n4> t4;
    for (int k = 0; k < n4; ++k) t4[k] = t4[k + n4] = centre[off4_[k]];
    return arc_fires<n4, kArc4Min, kArc4Max>(t4.data());
}

}  // namespace evcorner
