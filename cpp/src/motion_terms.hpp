// The terms of the motion wrench (paper eqs. 8-9), walked once for the double evaluation and again,
// on the rare exact path, for the exact one. Private to the core.
#pragma once

#include <cmath>

#include "stablepush/stable_push.hpp"

namespace stablepush {

template <class Loads>
void StablePushModel::visit_motion_terms(const Pose& q, const Rotation2& rotation, const Motion& dq,
                                         const Vec2& gravity, Loads& loads) const {
  const double dt = step_time_;
  const Vec2 origin(q.x, q.z);
  const Vec2 v(dq.dx / dt, dq.dz / dt);  // velocity of O's origin in G [m/s]
  const double omega = dq.dtheta / dt;   // [rad/s]
  const double speed_v = v.norm();

  // Momentum gained over the step from rest, M xi / dt, and the weight, both at the centre of
  // mass: the force m (v_cm / dt - g) at r_cm plus the pure torque I omega / dt.
  const Vec2 r_cm = rotation.apply(body_.com);
  const Vec2 v_cm = v + omega_cross(omega, r_cm);
  loads.force(body_.mass * (v_cm / dt - gravity), r_cm);
  loads.torque(body_.inertia * omega / dt);

  // Fingers, coincident pad points merged (Gripper::sites): a sliding point exerts
  // -mu N/k v_j/|v_j| (maximum dissipation), so -w_sliding adds +mu N/k v_j/|v_j|; a sticking
  // point contributes its friction disc instead.
  for (const PadPoint& point : gripper_.sites()) {
    const Vec2 arm = point.position - origin;
    const Vec2 slip = v + omega_cross(omega, arm);
    const double slip_speed = slip.norm();
    if (slip_speed < kStickingSpeedRatio * (speed_v + std::abs(omega) * point.pad_radius)) {
      loads.sticking(arm, point.friction_limit, point.count);
    } else {
      loads.force((point.friction_limit / slip_speed) * slip, arm);
    }
  }
}

/// Groups sticking points by location (bit-identical arms, as the two pads of a parallel-jaw
/// grasp give) so each location becomes one friction disc.
template <class Groups>
inline void add_sticking_point(Groups& groups, const Vec2& arm, double friction_limit) {
  for (auto& group : groups)
    if (group.arm == arm) {
      group.friction_limit += friction_limit;
      return;
    }
  groups.push_back(StickingGroup{arm, friction_limit});
}

/// The wrench on the object in O about O's origin of a sticking group's force f (in G [N]):
/// L_g f = (R^T f, arm x f).
inline Wrench sticking_wrench(const Rotation2& R, const Vec2& arm, const Vec2& f) {
  return Wrench(R.c * f.x() - R.s * f.y(), R.s * f.x() + R.c * f.y(), cross_y(arm, f));
}

}  // namespace stablepush
