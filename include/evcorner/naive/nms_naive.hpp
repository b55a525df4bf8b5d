#pragma once
// AsyncNms (nms.hpp) written plainly from its definition, as an oracle: every corner
// event kept in a list; for a new corner, the latest earlier corner at each pixel of the
// neighbourhood is found by scanning the list backwards, and the rule applied to it.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

#include "evcorner/event.hpp"
#include "evcorner/nms.hpp"

namespace evcorner::naive {

class NmsNaive {
public:
    explicit NmsNaive(const NmsParams& p) : p_(p) {}

    bool keep(const Event& e, double score) {
        const double s = std::isnan(score) ? -std::numeric_limits<double>::infinity() : score;
        bool suppressed = false;
        for (int dy = -p_.radius; dy <= p_.radius; ++dy)
            for (int dx = -p_.radius; dx <= p_.radius; ++dx) {
                const int x = e.x + dx, y = e.y + dy;
                for (auto it = past_.rbegin(); it != past_.rend(); ++it) {
                    if (it->e.x != x || it->e.y != y || it->e.p != e.p) continue;
                    // The latest earlier corner at (x, y): the only one looked at.
                    const double dt = static_cast<double>(e.t - it->e.t);
                    if (p_.rule == NmsRule::window) {
                        if (dt <= static_cast<double>(p_.time_us) && it->s >= s) suppressed = true;
                    } else {
                        const double x = std::max(dt, 0.0) / static_cast<double>(p_.time_us);
                        const double w = x > 700.0 ? 0.0 : std::exp(-x);  // weight 0 beyond 700 time constants
                        const double d = w == 0.0 ? (it->s >= 0 ? 0.0 : -std::numeric_limits<double>::infinity())
                                                  : (it->s >= 0 ? it->s * w : it->s / w);
                        if (d >= s) suppressed = true;
                    }
                    break;
                }
            }
        past_.push_back({e, s});
        return !suppressed;
    }

private:
    struct Past {
        Event e;
        double s;
    };
    NmsParams p_;
    std::vector<Past> past_;
};

}  // namespace evcorner::naive
