#include "stablepush/stable_push.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "motion_terms.hpp"
#include "stablepush/internal/small_lp.hpp"

namespace stablepush {
namespace {

/// Accumulates the motion wrench in double, with the magnitude sum that sizes the certification band.
struct DoubleLoads {
  double inverse_length;
  Vec2 force_sum = Vec2::Zero();
  double torque_sum = 0.0;
  double scale = 0.0;
  MotionWrench* out;

  void force(const Vec2& f, const Vec2& arm) {
    force_sum += f;
    torque_sum += cross_y(arm, f);
    scale += (std::abs(f.x()) + std::abs(f.y())) * (1.0 + (std::abs(arm.x()) + std::abs(arm.y())) * inverse_length);
  }
  void torque(double t) {
    torque_sum += t;
    scale += std::abs(t) * inverse_length;
  }
  void sticking(const Vec2& arm, double friction_limit, int points) {
    add_sticking_point(out->sticking, arm, friction_limit);
    out->sticking_points += points;
    scale += 2.0 * friction_limit * (1.0 + (std::abs(arm.x()) + std::abs(arm.y())) * inverse_length);
  }
};

/// The map from a sticking group's force f (in G) to its wrench on the object in O about O's
/// origin: (R^T f, arm x f). Row r of the 3x2 matrix.
inline Vec2 sticking_map_row(const Rotation2& R, const Vec2& arm, int r) {
  switch (r) {
    case 0:
      return Vec2(R.c, -R.s);
    case 1:
      return Vec2(R.s, R.c);
    default:
      return Vec2(arm.y(), -arm.x());
  }
}

/// w^T L for a row w (a covector on wrenches): the covector it induces on the group's force.
inline Vec2 pull_back(const Wrench& w, const Rotation2& R, const Vec2& arm) {
  return w.x() * sticking_map_row(R, arm, 0) + w.y() * sticking_map_row(R, arm, 1) +
         w.z() * sticking_map_row(R, arm, 2);
}

}  // namespace

StablePushModel::StablePushModel(CrossSection section, RigidBody body, Gripper gripper, std::vector<Pusher> pushers,
                                 const Vec2& gravity, double step_time, int friction_polygon_sides,
                                 GravityFrame gravity_frame, std::vector<double> feature_angles)
    : section_(std::move(section)),
      body_(body),
      gripper_(std::move(gripper)),
      pushers_(std::move(pushers)),
      gravity_(gravity),
      gravity_frame_(gravity_frame),
      feature_angles_(std::move(feature_angles)),
      step_time_(step_time),
      torque_length_(section_.circumradius()),
      polygon_sides_(friction_polygon_sides) {
  if (!(body_.mass > 0.0)) throw std::invalid_argument("mass must be > 0");
  if (!(body_.inertia > 0.0)) throw std::invalid_argument("inertia must be > 0");
  if (!(step_time_ > 0.0)) throw std::invalid_argument("step_time must be > 0");
  if (!gravity_.allFinite()) throw std::invalid_argument("gravity must be finite");
  if (polygon_sides_ < 3) throw std::invalid_argument("friction_polygon_sides must be >= 3");
  if (pushers_.empty()) throw std::invalid_argument("at least one pusher is needed");
  if (feature_angles_.empty()) feature_angles_.assign(pushers_.size(), 0.0);
  if (feature_angles_.size() != pushers_.size()) throw std::invalid_argument("one feature angle per pusher is needed");
  for (double a : feature_angles_) {
    if (!std::isfinite(a)) throw std::invalid_argument("feature angles must be finite");
    gravity_in_object_.push_back(Rotation2(a).apply_inverse(gravity_));  // R(phi_p)^T g
  }
  for (const Pusher& pusher : pushers_) cones_.emplace_back(pusher.cone_generators(), torque_length_);
  // The polygon inscribed in the friction disc has its vertices at angles 2 pi k / sides (the
  // first on +x of G); edge k then has its outward normal at angle pi (2k + 1) / sides.
  for (int k = 0; k < polygon_sides_; ++k) polygon_normals_.push_back(unit_circle_point(2 * k + 1, 2 * polygon_sides_));
  polygon_inradius_ = std::cos(M_PI / polygon_sides_);
}

StablePushModel StablePushModel::in_world(double pad_mu_scale, double grip_force_scale, double mass_scale) const {
  for (double scale : {pad_mu_scale, grip_force_scale, mass_scale})
    if (!(std::isfinite(scale) && scale > 0.0)) throw std::invalid_argument("a world's scales must be finite and > 0");
  StablePushModel world = *this;
  world.gripper_ = Gripper(gripper_.pads(), gripper_.grip_force() * grip_force_scale, gripper_.mu() * pad_mu_scale,
                           gripper_.pad_rings());
  world.body_.mass *= mass_scale;
  world.body_.inertia *= mass_scale;
  return world;
}

Vec2 StablePushModel::gravity_in_gripper(const Pose& q, int pusher) const {
  return gravity_in_gripper(Rotation2(q.theta), pusher);
}

Vec2 StablePushModel::gravity_in_gripper(const Rotation2& R, int pusher) const {
  if (gravity_frame_ == GravityFrame::Gripper || pusher == kNoPusher) return gravity_;
  if (pusher < 0 || pusher >= static_cast<int>(pushers_.size())) throw std::out_of_range("pusher index");
  return R.apply(gravity_in_object_[pusher]);  // R(theta) R(phi_p)^T g = R(theta - phi_p) g
}

MotionWrench StablePushModel::motion_wrench(const Pose& q, const Motion& dq, int pusher) const {
  return motion_wrench(PoseAndRotation(q), dq, pusher);
}

MotionWrench StablePushModel::motion_wrench(const PoseAndRotation& at, const Motion& dq, int pusher) const {
  const Pose& q = at.pose();
  if (!(std::isfinite(q.x) && std::isfinite(q.z) && std::isfinite(q.theta)))
    throw std::invalid_argument("the pose q is not finite");
  if (!(std::isfinite(dq.dx) && std::isfinite(dq.dz) && std::isfinite(dq.dtheta)))
    throw std::invalid_argument("the motion dq is not finite");
  // Below this the motion's velocity and acceleration terms underflow to (sub)normal noise.
  if (std::max({std::abs(dq.dx), std::abs(dq.dz), std::abs(dq.dtheta)}) < kSmallestMotion)
    throw std::invalid_argument("the motion dq is zero (or under 1e-12 m and rad)");
  MotionWrench load;
  load.rotation = at.rotation();
  load.gravity = gravity_in_gripper(load.rotation, pusher);
  DoubleLoads loads{1.0 / torque_length_};
  loads.out = &load;
  visit_motion_terms(q, load.rotation, dq, load.gravity, loads);
  const Vec2 force_in_O = load.rotation.apply_inverse(loads.force_sum);
  load.required = Wrench(force_in_O.x(), force_in_O.y(), loads.torque_sum);
  load.scale = loads.scale;
  if (!load.required.allFinite() || !std::isfinite(load.scale))
    throw std::domain_error("the motion wrench overflows (a mass, inertia, com, mu or step time far out of range?)");
  return load;
}

double StablePushModel::hold_ratio(const Pose& q, int pusher) const {
  const Vec2 weight = body_.mass * gravity_in_gripper(q, pusher);  // in G [N]
  if (weight.isZero()) return std::numeric_limits<double>::infinity();
  const Vec2 origin(q.x, q.z);
  const Vec2 r_cm = Rotation2(q.theta).apply(body_.com);
  std::vector<StickingGroup> groups;
  for (const PadPoint& site : gripper_.sites()) add_sticking_point(groups, site.position - origin, site.friction_limit);

  // Unknowns x = (f_1, ..., f_G, lambda), forces in G. Balance in G about O's origin:
  //   sum f_g + lambda W = 0,   sum arm_g x f_g + lambda (r_cm x W) = 0   (E x = 0),
  // solved on E's null space x = N y (y = 0 is feasible), with every f_g in its polygon.
  const int n = 2 * static_cast<int>(groups.size()) + 1;
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(3, n);
  for (int g = 0; g < static_cast<int>(groups.size()); ++g) {
    E(0, 2 * g) = 1.0;
    E(1, 2 * g + 1) = 1.0;
    E(2, 2 * g) = groups[g].arm.y();  // cross_y(arm, f) = arm_z f_x - arm_x f_z
    E(2, 2 * g + 1) = -groups[g].arm.x();
  }
  E(0, n - 1) = weight.x();
  E(1, n - 1) = weight.y();
  E(2, n - 1) = cross_y(r_cm, weight);
  const Eigen::MatrixXd N = Eigen::FullPivLU<Eigen::MatrixXd>(E).kernel();

  constexpr double kCap = 1e3;  // lambda beyond this is reported as this: held a thousand times over
  const int rows = static_cast<int>(groups.size()) * polygon_sides_ + 1;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, n);
  Eigen::VectorXd b(rows);
  int r = 0;
  for (int g = 0; g < static_cast<int>(groups.size()); ++g)
    for (int k = 0; k < polygon_sides_; ++k, ++r) {
      A.block<1, 2>(r, 2 * g) = polygon_normals_[k].transpose();
      b[r] = groups[g].friction_limit * polygon_inradius_;
    }
  A(r, n - 1) = 1.0;
  b[r] = kCap;
  Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
  c[n - 1] = 1.0;
  const SmallLpResult lp = maximize_from_feasible(A * N, b, N.transpose() * c, Eigen::VectorXd::Zero(N.cols()), 1000);
  // The fast solver can stall at a degenerate vertex (symmetric pads, the centre of mass on a
  // pad's axis); the exact solver answers every instance.
  if (lp.status != SmallLpResult::Status::Optimal) return exact_hold_ratio(groups, weight, r_cm, kCap);
  return (N * lp.x)[n - 1];
}

PushResult StablePushModel::check(const Pose& q, const Motion& dq, int pusher) const {
  return check(motion_wrench(q, dq, pusher), q, dq, pusher);
}

std::vector<PushResult> StablePushModel::check_all(const Pose& q, const Motion& dq) const {
  MotionWrench load = motion_wrench(q, dq, 0);
  std::vector<PushResult> results;
  results.reserve(cones_.size());
  for (int p = 0, loaded_for = 0; p < static_cast<int>(cones_.size()); ++p) {
    if (!same_gravity(loaded_for, p)) {
      load = motion_wrench(q, dq, p);
      loaded_for = p;
    }
    results.push_back(check(load, q, dq, p));
  }
  return results;
}

PushResult StablePushModel::check(const MotionWrench& load, const Pose& q, const Motion& dq, int pusher) const {
  if (pusher < 0 || pusher >= static_cast<int>(cones_.size())) throw std::out_of_range("pusher index");
  const WrenchCone& cone = cones_[pusher];
  return load.sticking.empty() ? all_sliding(cone, load, q, dq) : with_sticking(cone, load, q, dq);
}

// All pad points slide: w_pusher = w_motion is fixed; project it on the face normals (paper IV-D).
PushResult StablePushModel::all_sliding(const WrenchCone& cone, const MotionWrench& load, const Pose& q,
                                        const Motion& dq) const {
  PushResult result;
  result.contact_case = ContactCase::AllSliding;
  result.witness = load.required;
  const double band = kCertificationBand * load.scale;
  const double off_span = cone.distance_to_span(load.required);
  if (off_span > band) {  // certainly off a lower-dimensional cone's span
    result.margin = -off_span;
    return result;
  }
  // Within the band of a lower-dimensional cone's span (a point pusher's wedge plane) the wrench
  // counts as on it: a point pusher's stable motions form a surface (the planner finds them by a
  // root in the rotation, StablePushValidator::onto_wedge_surface), and a motion on it, given in
  // doubles, misses the plane by rounding; what it leaves is 1e-9 of the push's loads. The facet
  // rows of such a cone lie in its span, so they measure the wrench's projection onto it.
  double margin = std::numeric_limits<double>::infinity();
  for (const Wrench& row : cone.facet_rows()) margin = std::min(margin, -row.dot(load.required));
  result.margin = margin;
  result.feasible = margin > 0.0;
  if (std::abs(margin) > band) return result;
  return exact_all_sliding(cone, load, q, dq, result);
}

// Some pad points stick: search their friction polytope for a force that puts w_pusher strictly
// inside the cone (paper IV-E): maximize t s.t. facet_i . (w - sum_g L_g f_g) <= -t, f_g in P_g.
PushResult StablePushModel::with_sticking(const WrenchCone& cone, const MotionWrench& load, const Pose& q,
                                          const Motion& dq) const {
  const int groups = static_cast<int>(load.sticking.size());
  const int facets = static_cast<int>(cone.facet_rows().size());
  if (!cone.equality_rows().empty() || groups > 3) return exact_sticking(cone, load, q, dq);

  const int n = 2 * groups + 1;
  const int rows = facets + polygon_sides_ * groups;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, n);
  Eigen::VectorXd b(rows);
  for (int i = 0; i < facets; ++i) {
    const Wrench& row = cone.facet_rows()[i];
    for (int g = 0; g < groups; ++g)
      A.block<1, 2>(i, 2 * g) = -pull_back(row, load.rotation, load.sticking[g].arm).transpose();
    A(i, n - 1) = 1.0;
    b[i] = -row.dot(load.required);
  }
  for (int g = 0; g < groups; ++g)
    for (int k = 0; k < polygon_sides_; ++k) {
      const int r = facets + g * polygon_sides_ + k;
      A.block<1, 2>(r, 2 * g) = polygon_normals_[k].transpose();
      b[r] = load.sticking[g].friction_limit * polygon_inradius_;
    }
  Eigen::VectorXd objective = Eigen::VectorXd::Zero(n);
  objective[n - 1] = 1.0;
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(n);
  x0[n - 1] = b.head(facets).minCoeff() - (1.0 + load.scale);
  const SmallLpResult lp = maximize_from_feasible(A, b, objective, x0);
  if (lp.status != SmallLpResult::Status::Optimal) return exact_sticking(cone, load, q, dq);

  const double band = kCertificationBand * load.scale;
  PushResult result;
  result.contact_case = ContactCase::Sticking;
  result.sticking_points = load.sticking_points;
  auto witness_of = [&](const Eigen::VectorXd& x) {
    Wrench w = load.required;
    for (int g = 0; g < groups; ++g) w -= sticking_wrench(load.rotation, load.sticking[g].arm, x.segment<2>(2 * g));
    return w;
  };

  // Primal certificate: a sticking force pulled slightly inside its polygon whose margin,
  // evaluated directly, clears the band.
  if (lp.x[n - 1] > band) {
    Eigen::VectorXd x = lp.x;
    x.head(n - 1) *= (1.0 - 1e-12);
    bool inside = true;
    for (int r = facets; r < rows && inside; ++r) inside = A.row(r).head(n - 1).dot(x.head(n - 1)) <= b[r];
    double t = std::numeric_limits<double>::infinity();
    for (int i = 0; i < facets; ++i) t = std::min(t, b[i] - A.row(i).head(n - 1).dot(x.head(n - 1)));
    if (inside && t > band) {
      result.feasible = true;
      result.margin = t;
      result.witness = witness_of(x);
      return result;
    }
  }
  // Dual certificate: for lambda in the simplex and mu >= 0, every admissible f has
  // t <= lambda.b_F + mu.b_P + |P + E^T mu| R, with P the f-part of lambda^T A_F.
  if (lp.x[n - 1] < -band) {
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(facets), mu = Eigen::VectorXd::Zero(rows - facets);
    for (std::size_t a = 0; a < lp.active.size(); ++a) {
      const int r = lp.active[a];
      const double y = std::max(0.0, lp.multipliers[a]);
      if (r < facets)
        lambda[r] = y;
      else
        mu[r - facets] = y;
    }
    const double lambda_sum = lambda.sum();
    if (lambda_sum > 0.0) {
      lambda /= lambda_sum;
      mu /= lambda_sum;
      const Eigen::VectorXd residual = (lambda.transpose() * A.topLeftCorner(facets, n - 1)).transpose() +
                                       (mu.transpose() * A.bottomLeftCorner(rows - facets, n - 1)).transpose();
      double radius2 = 0.0;
      for (const StickingGroup& g : load.sticking) radius2 += g.friction_limit * g.friction_limit;
      const double bound = lambda.dot(b.head(facets)) + mu.dot(b.tail(rows - facets)) +
                           residual.norm() * std::sqrt(radius2) * (1.0 + 1e-9);
      if (bound < -band) {
        result.feasible = false;
        result.margin = lp.x[n - 1];
        result.witness = witness_of(lp.x);
        return result;
      }
    }
  }
  return exact_sticking(cone, load, q, dq);
}

}  // namespace stablepush
