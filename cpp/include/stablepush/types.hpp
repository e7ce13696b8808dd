// Small value types shared by the whole core. Everything inside the core is SI:
// metres, radians, kilograms, newtons, seconds (docs/model.md section 1).
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace stablepush {

/// A vector in a grasp plane, (x, z). In G or in O as the name says.
using Vec2 = Eigen::Vector2d;

/// A planar wrench (f_x [N], f_z [N], tau_y [N m]) with tau_y = r_z f_x - r_x f_z.
using Wrench = Eigen::Vector3d;

/// Pose of the object frame O seen from the gripper frame G: (x [m], z [m], theta [rad]),
/// theta a right-handed rotation about +y (the paper's theta_y).
struct Pose {
  double x = 0.0;
  double z = 0.0;
  double theta = 0.0;
};

/// A displacement of the object in the grasp, Delta q = q_b - q_a: (dx [m], dz [m], dtheta [rad]),
/// all in G. The stable-push test takes one as the unit motion of a step: the twist xi = Delta q / dt,
/// constant over the step time dt from rest (the quasi-dynamic step of paper eq. 5). The planner
/// cuts longer motions into such steps.
struct Motion {
  double dx = 0.0;
  double dz = 0.0;
  double dtheta = 0.0;
};

/// The motion that takes pose a to pose b: b - a, coordinate by coordinate (theta is not wrapped).
inline Motion operator-(const Pose& b, const Pose& a) { return Motion{b.x - a.x, b.z - a.z, b.theta - a.theta}; }
/// The motion from a to b (b - a).
inline Motion between(const Pose& a, const Pose& b) { return b - a; }
/// The pose reached from q by the motion m.
inline Pose operator+(const Pose& q, const Motion& m) { return Pose{q.x + m.dx, q.z + m.dz, q.theta + m.dtheta}; }
/// The motion m scaled by s (a fraction of it, when 0 <= s <= 1).
inline Motion operator*(double s, const Motion& m) { return Motion{s * m.dx, s * m.dz, s * m.dtheta}; }

/// y-component of r x f for r, f in a grasp plane: tau_y = r_z f_x - r_x f_z.
inline double cross_y(const Vec2& r, const Vec2& f) { return r.y() * f.x() - r.x() * f.y(); }

/// omega x r for an angular velocity omega about +y and r in the grasp plane: (omega r_z, -omega r_x).
inline Vec2 omega_cross(double omega, const Vec2& r) { return Vec2(omega * r.y(), -omega * r.x()); }

/// The rotation R(theta) of docs/model.md section 1: p_G = c + R p_O, R = [[cos, sin], [-sin, cos]].
struct Rotation2 {
  double c = 1.0;
  double s = 0.0;
  Rotation2() = default;
  explicit Rotation2(double theta) : c(std::cos(theta)), s(std::sin(theta)) {}
  /// R p: a vector of O expressed in G.
  Vec2 apply(const Vec2& p) const { return Vec2(c * p.x() + s * p.y(), -s * p.x() + c * p.y()); }
  /// R^T v: a vector of G expressed in O.
  Vec2 apply_inverse(const Vec2& v) const { return Vec2(c * v.x() - s * v.y(), s * v.x() + c * v.y()); }
};

/// A pose q with its R(theta) evaluated once, for the many motions a root search tries from one pose
/// (StablePushModel::motion_wrench); the rotation is always the pose's own.
class PoseAndRotation {
 public:
  explicit PoseAndRotation(const Pose& q) : pose_(q), rotation_(q.theta) {}
  const Pose& pose() const { return pose_; }
  const Rotation2& rotation() const { return rotation_; }

 private:
  Pose pose_;
  Rotation2 rotation_;
};

/// The point at angle 2 pi j / n on the unit circle, with the eight symmetries of the square
/// holding bit for bit (mirror images are exact negations or swaps). Pad rings and friction
/// polygons are built from it, so a symmetric task gives sums that cancel exactly, which the
/// exact re-check of a lower-dimensional cone relies on.
Vec2 unit_circle_point(long j, long n);

}  // namespace stablepush
