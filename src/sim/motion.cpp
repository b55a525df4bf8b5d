#include "evcorner/sim/motion.hpp"

#include <cmath>
#include <numbers>

namespace evcorner::sim {

double motion_time(const SpeedProfile& p, double t, double d) noexcept {
    if (!p.ramp) return t;
    return p.from * t + (p.to - p.from) * t * t / (2.0 * d);
}

double speed_factor(const SpeedProfile& p, double t, double d) noexcept {
    if (!p.ramp) return 1.0;
    return p.from + (p.to - p.from) * t / d;
}

Pose::Pose(const Motion& m, double t, double d) noexcept : c0_(m.center) {
    const double tau = motion_time(m.profile, t, d);
    const double f = speed_factor(m.profile, t, d);
    const double w = m.rotation_deg_s * std::numbers::pi / 180.0;  // rad per second of motion time
    const double s = 1.0 + m.scaling_per_s * tau;
    const double c = std::cos(w * tau), sn = std::sin(w * tau);
    a_ = s * c;
    b_ = s * sn;
    // d/dt (s cos) = f (s' cos - s w sin), d/dt (s sin) = f (s' sin + s w cos)
    da_ = f * (m.scaling_per_s * c - s * w * sn);
    db_ = f * (m.scaling_per_s * sn + s * w * c);
    c_ = {m.center.x + m.velocity.x * tau, m.center.y + m.velocity.y * tau};
    vc_ = {m.velocity.x * f, m.velocity.y * f};
}

}  // namespace evcorner::sim
