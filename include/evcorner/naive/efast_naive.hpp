#pragma once
// eFAST written plainly from its definition, as an oracle for the fast path:
// a full SAE per polarity indexed (x, y), and every arc start and length tried.

#include <array>
#include <cstdint>
#include <vector>

#include "evcorner/arc_test.hpp"
#include "evcorner/circle.hpp"
#include "evcorner/event.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::naive {

class EFastNaive {
public:
    explicit EFastNaive(SensorSize size)
        : size_(size),
          sae_{std::vector<std::int64_t>(static_cast<std::size_t>(size.pixels()), INT64_MIN),
               std::vector<std::int64_t>(static_cast<std::size_t>(size.pixels()), INT64_MIN)} {}

    bool process(const Event& e) noexcept {
        cell(e.p, e.x, e.y) = e.t;
        if (e.x < 4 || e.x >= size_.width - 4 || e.y < 4 || e.y >= size_.height - 4) return false;
        std::array<std::int64_t, 16> c3;
        for (int k = 0; k < 16; ++k) c3[k] = cell(e.p, e.x + kCircle3[k].dx, e.y + kCircle3[k].dy);
        std::array<std::int64_t, 20> c4;
        for (int k = 0; k < 20; ++k) c4[k] = cell(e.p, e.x + kCircle4[k].dx, e.y + kCircle4[k].dy);
        return arc_fires_naive<16, 3, 6>(c3) && arc_fires_naive<20, 4, 8>(c4);
    }

private:
    std::int64_t& cell(int p, int x, int y) {
        return sae_[p][static_cast<std::size_t>(x) * size_.height + y];
    }
    SensorSize size_;
    std::array<std::vector<std::int64_t>, 2> sae_;
};

}  // namespace evcorner::naive
