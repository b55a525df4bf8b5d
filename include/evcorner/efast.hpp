#pragma once
// eFAST: the event-based FAST corner detector of
//   E. Mueggler, C. Bartolozzi, D. Scaramuzza, "Fast Event-based Corner Detection",
//   BMVC 2017.
// Per event: write its timestamp into the SAE of its polarity; away from the border,
// it is a corner iff on that SAE the radius-3 circle has a contiguous arc of 3..6
// pixels all strictly newer than the rest of the circle, and the radius-4 circle one
// of 4..8 pixels (docs/algorithms.md fixes every detail).

#include <array>
#include <cstddef>
#include <cstdint>

#include "evcorner/arc_test.hpp"
#include "evcorner/circle.hpp"
#include "evcorner/detector.hpp"
#include "evcorner/event.hpp"
#include "evcorner/sae.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner {

class EFast {
public:
    static constexpr int kArc3Min = 3, kArc3Max = 6;
    static constexpr int kArc4Min = 4, kArc4Max = 8;

    explicit EFast(SensorSize size) : sae_(size) {}

    /// Updates the SAE with `e` and answers whether `e` is a corner event.
    /// `e` must lie on the sensor (readers validate).
    bool process(const Event& e) noexcept {
        sae_.update(e);
        const SensorSize s = sae_.size();
        if (e.x < kCircleMargin || e.x >= s.width - kCircleMargin || e.y < kCircleMargin ||
            e.y >= s.height - kCircleMargin)
            return false;
        const std::int64_t* centre =
            sae_.plane(e.p) + static_cast<std::ptrdiff_t>(e.y) * s.width + e.x;
        // Offsets from compile-time circle coordinates: the loads address rows
        // centre + dy * width with constant column offsets.
        const std::ptrdiff_t w = s.width;
        return circle_fires<kCircle3.size(), kArc3Min, kArc3Max>(
                   centre, [w](int k) { return kCircle3[k].dy * w + kCircle3[k].dx; }) &&
               circle_fires<kCircle4.size(), kArc4Min, kArc4Max>(
                   centre, [w](int k) { return kCircle4[k].dy * w + kCircle4[k].dx; });
    }

    /// Updates the SAE with `e` without classifying it (the halo of a parallel part).
    void observe(const Event& e) noexcept { sae_.update(e); }

    [[nodiscard]] const Sae& sae() const noexcept { return sae_; }
    [[nodiscard]] SensorSize size() const noexcept { return sae_.size(); }
    [[nodiscard]] std::size_t memory_bytes() const noexcept { return sae_.memory_bytes(); }

private:
    Sae sae_;
};
static_assert(Detector<EFast>);

}  // namespace evcorner
