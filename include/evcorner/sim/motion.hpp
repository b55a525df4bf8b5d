#pragma once
// Where an object's points are at time t: the similarity motion of scene.hpp evaluated at
// the motion time of its speed profile.

#include "evcorner/sim/scene.hpp"

namespace evcorner::sim {

/// tau(t) = integral over [0, t] of the profile's speed factor; duration_s is the ramp's length.
double motion_time(const SpeedProfile& p, double t_s, double duration_s) noexcept;
/// The speed factor d tau / dt at t.
double speed_factor(const SpeedProfile& p, double t_s, double duration_s) noexcept;

/// The similarity transform of a motion at one time: p -> center + offset + a (p - center0)
/// with a = s R, and its time derivative for velocities.
class Pose {
public:
    Pose() = default;  ///< the identity
    Pose(const Motion& m, double t_s, double duration_s) noexcept;
    [[nodiscard]] Vec2 apply(Vec2 p0) const noexcept {
        const double dx = p0.x - c0_.x, dy = p0.y - c0_.y;
        return {c_.x + a_ * dx - b_ * dy, c_.y + b_ * dx + a_ * dy};
    }
    /// Image velocity (px/s) at time t of the point that was at p0.
    [[nodiscard]] Vec2 velocity(Vec2 p0) const noexcept {
        const double dx = p0.x - c0_.x, dy = p0.y - c0_.y;
        return {vc_.x + da_ * dx - db_ * dy, vc_.y + db_ * dx + da_ * dy};
    }

private:
    Vec2 c0_, c_, vc_;
    double a_ = 1, b_ = 0, da_ = 0, db_ = 0;
};

}  // namespace evcorner::sim
