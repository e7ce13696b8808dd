// The planning problem as OMPL sees it (paper section V, docs/model.md section 3), kept apart from
// the search: the space of grasp poses q = (x, z, theta), its metric in unit steps, the state
// validity (grasp maintained), the motion validity (a stable push by some pusher, the grasp kept
// throughout) and the goal region.
#pragma once

#ifndef STABLEPUSH_INTERNAL_ALLOWED
#error "an internal header of the stablepush core: include stablepush/planning.hpp or stablepush/search.hpp"
#endif

#include <ompl/base/MotionValidator.h>
#include <ompl/base/StateValidityChecker.h>
#include <ompl/base/goals/GoalSampleableRegion.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "stablepush/search.hpp"
#include "stablepush/stable_push.hpp"
#include "stablepush/types.hpp"

namespace stablepush {

/// The grasp poses (x [m], z [m], theta [rad]) with the metric
///     d(q1, q2) = sqrt((dx^2 + dz^2) / length^2 + dtheta^2 / angle^2)   [unit steps],
/// so that a unit step is a step of length 1. theta is not wrapped: a plan turns the object
/// through the angles it passes, and the bounds decide how far it may turn.
class GraspPoseSpace : public ompl::base::RealVectorStateSpace {
 public:
  GraspPoseSpace(StepSize step, const ompl::base::RealVectorBounds& bounds);

  const StepSize& step() const { return step_; }
  double distance(const ompl::base::State* a, const ompl::base::State* b) const override;
  double distance(const Pose& a, const Pose& b) const;
  /// Motions shorter than this [unit steps] are no push (co-located poses; a pose at the goal).
  /// With unit steps of at least 0.001 mm and 0.001 deg (the task's range), a longer motion has a
  /// component above the model's kSmallestMotion (1e-12 m or rad), where its wrenches are defined;
  /// at 1e-9, a descent's ever shorter steps toward the goal (improve_for) reached motions below it.
  static constexpr double kShortestPush = 1e-5;
  /// A motion in unit steps: (dx, dz) / length, dtheta / angle.
  Eigen::Vector3d in_unit_steps(const Motion& d) const {
    return Eigen::Vector3d(d.dx / step_.length, d.dz / step_.length, d.dtheta / step_.angle);
  }
  /// A pose's coordinates in unit steps: (x, z) / length, theta / angle (where the metric is Euclidean).
  Eigen::Vector3d in_unit_steps(const Pose& q) const {
    return Eigen::Vector3d(q.x / step_.length, q.z / step_.length, q.theta / step_.angle);
  }
  /// The inverse of in_unit_steps for a motion.
  Motion from_unit_steps(const Eigen::Vector3d& u) const {
    return Motion{u[0] * step_.length, u[1] * step_.length, u[2] * step_.angle};
  }
  double getMaximumExtent() const override;

  static Pose pose(const ompl::base::State* s);
  static void set_pose(ompl::base::State* s, const Pose& q);

  /// The motion a -> b cut into n equal pushes of at most one unit step each (n >= 1);
  /// returns the n + 1 poses, a first and b last. Planning and the plan's waypoints share it.
  std::vector<Pose> unit_pushes(const Pose& a, const Pose& b) const;

 private:
  StepSize step_;
};

/// Uniform samples of the pose space from a generator seeded by the planner, so that a seed
/// gives the same samples in any process (OMPL's default samplers draw from a global seed).
class SeededPoseSampler : public ompl::base::RealVectorStateSampler {
 public:
  SeededPoseSampler(const ompl::base::StateSpace* space, std::uint_fast32_t seed);
};

/// A pose is valid when the grasp is maintained: every pad disc inside the cross-section.
class GraspValidityChecker : public ompl::base::StateValidityChecker {
 public:
  GraspValidityChecker(const ompl::base::SpaceInformationPtr& si, const StablePushModel& model);
  bool isValid(const ompl::base::State* s) const override;

 private:
  const StablePushModel& model_;
};

/// A root of a function of one variable between two points where it changes sign, refined to
/// rounding by regula falsi with the Illinois rule. `lo` and `hi` are points with lo.*x < hi.*x
/// and values lo.*f, hi.*f of opposite signs; `at(x)` gives the point at x, or nullopt to stop
/// there. Returns the one of the last two kept whose value is the smaller in magnitude: a root
/// where the function is continuous; beside a jump, a point whose value is not small, which
/// callers refuse by its size.
template <class Point, class At>
Point refine_sign_change(Point lo, Point hi, double Point::*x, double Point::*f, const At& at) {
  double f_lo = lo.*f, f_hi = hi.*f;  // the Illinois-weighted values
  int kept = 0;                       // which end was kept last: -1 lo, +1 hi
  for (int k = 0; k < 60; ++k) {
    double mid = (lo.*x * f_hi - hi.*x * f_lo) / (f_hi - f_lo);
    if (!(mid > lo.*x && mid < hi.*x)) mid = 0.5 * (lo.*x + hi.*x);
    if (!(mid > lo.*x && mid < hi.*x)) break;  // lo and hi are adjacent doubles
    const std::optional<Point> point = at(mid);
    if (!point) break;
    if ((*point).*f == 0.0) return *point;
    if (((*point).*f < 0.0) == (f_lo < 0.0)) {
      lo = *point;
      f_lo = lo.*f;
      if (kept == -1) f_hi *= 0.5;
      kept = -1;
    } else {
      hi = *point;
      f_hi = hi.*f;
      if (kept == 1) f_lo *= 0.5;
      kept = 1;
    }
    if (hi.*x - lo.*x <= 1e-15) break;
  }
  return std::abs(lo.*f) <= std::abs(hi.*f) ? lo : hi;
}

/// A motion a -> b is valid when, for one same pusher, each of its unit pushes
/// (GraspPoseSpace::unit_pushes) is a stable push with a margin of at least `min_margin` [N] in
/// every model of the set, and the grasp is maintained throughout (swept pads,
/// Gripper::grasp_maintained_along).
class StablePushValidator : public ompl::base::MotionValidator, public PushChecker {
 public:
  /// At most kMaxModels models (the 4 corners of an uncertainty box).
  StablePushValidator(const ompl::base::SpaceInformationPtr& si, ModelSet models, double min_margin);
  static constexpr int kMaxModels = 4;

  /// The pushers among `candidates` that make every unit push of a -> b stable; 0 when the
  /// grasp is lost on the way.
  PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const override;
  /// One unit push is tested once for the grasp and its motion wrench, the preferred pushers first.
  PusherSet stable_pushers_preferring(const Pose& a, const Pose& b, PusherSet candidates,
                                      PusherSet preferred) const override;
  PusherSet all_pushers() const override { return all_; }
  double push_margin(const Pose& a, const Pose& b, int pusher) const override;
  /// The pushers whose cone is a wedge (a point pusher with mu > 0): their stable all-sliding
  /// motions form a surface in motion space, which onto_wedge_surface finds.
  PusherSet wedge_pushers() const override { return wedges_; }
  const ModelSet& models() const { return models_; }

  /// A point pusher's stable pushes (docs/model.md section 3): the motion from `a` of `length` unit
  /// steps whose translation keeps the heading of `direction` (in unit steps) and whose rotation
  /// puts the required pusher wrench in the plane of wedge pusher `pusher`'s cone, in the first
  /// model. Writing the motion's elevation above the translation plane as beta, the motion is
  /// length (cos beta h, sin beta) with h the unit heading, and e . w(a, dq(beta)) = 0 for the
  /// wedge's plane normal e is a root in beta: bracketed on a grid over |beta| < 90 deg (10 deg,
  /// finer toward pure rotation) and refined to rounding (regula falsi, Illinois), the root nearest
  /// the direction's own elevation, the lower on a tie (brackets nearest it first; a bracket
  /// farther from it than the best root so far is not evaluated). Empty when `pusher`'s cone is
  /// not a wedge, the direction has no translation, or no root exists. The motion still has to
  /// pass stable_pushers (the wedge's facets, every model, the grasp).
  std::optional<Pose> onto_wedge_surface(const Pose& a, const Eigen::Vector3d& direction, double length,
                                         int pusher) const override;
  /// The headings h at which a unit step of pure translation, h in unit steps, puts the required
  /// pusher wrench in the wedge's plane, e . w(a, dq(h)) = 0, in the first model: the sign changes
  /// over 24 evenly spaced headings, each refined to rounding (regula falsi); a sign
  /// change across a jump is not a root. Empty when `pusher`'s cone is not a wedge.
  std::vector<double> wedge_translation_headings(const Pose& a, int pusher) const override;
  /// How far the motion dq from `a` misses wedge pusher `pusher`'s plane, in the first model:
  ///     e . w_motion(a, dq) / scale   (signed, dimensionless; e the wedge's plane normal, scale
  /// the sum of the motion wrench's magnitudes, MotionWrench::scale), so that the span counts as
  /// met where its magnitude is within kCertificationBand (docs/model.md section 2). NaN when
  /// `pusher`'s cone is not a wedge.
  double wedge_plane_offset(const Pose& a, const Motion& dq, int pusher) const;
  /// The centres of the first model's pads, each once.
  std::vector<Vec2> pivot_points() const override;

  bool checkMotion(const ompl::base::State* a, const ompl::base::State* b) const override;
  bool checkMotion(const ompl::base::State* a, const ompl::base::State* b,
                   std::pair<ompl::base::State*, double>& last_valid) const override;

  /// Stable-push tests made so far (one per pusher and unit push).
  std::uint64_t feasibility_checks() const override { return checks_; }
  void reset_feasibility_checks() override { checks_ = 0; }

 private:
  /// The pushers of `candidates` that make the unit push from -> to stable, those of `preferred`
  /// first: when some of them are, the others are not tested. 0 when the grasp is lost on the way.
  PusherSet stable_in_unit_push(const Pose& from, const Pose& to, PusherSet candidates, PusherSet preferred) const;

  ModelSet models_;
  const GraspPoseSpace& space_;
  double min_margin_;
  PusherSet all_;
  PusherSet wedges_ = 0;
  mutable std::uint64_t checks_ = 0;
};

/// Headings [rad] of steps onto point pusher `pusher`'s surface from `at`
/// (PushChecker::onto_wedge_surface): `count` evenly spaced from `first`, then, about each of its
/// translation headings (PushChecker::wedge_translation_headings), offsets of 0, +-0.25, +-0.5,
/// +-1, +-2 and +-4 deg. The evenly spaced ones find the roots near pure rotation, where they crowd
/// (the surface is nearly a plane through it); the pushes that translate the part lie within a few
/// degrees of a translation heading, where the root's elevation turns through 180 deg, faster on
/// some parts than others (hence offsets growing twofold).
std::vector<double> wedge_step_headings(const PushChecker& checker, const Pose& at, int pusher, double first,
                                        int count);

/// The goal: every coordinate within its tolerance of the goal pose (|dx|, |dz| <= tolerance.length,
/// |dtheta| <= tolerance.angle). distanceGoal is the distance in unit steps.
class PoseGoal : public ompl::base::GoalSampleableRegion {
 public:
  /// With `hold` (a model and min_hold_ratio > 0), a node within tolerance ends a plan only when
  /// the pads alone hold the object there with that factor (`held`, StablePushModel::hold_ratio).
  PoseGoal(const ompl::base::SpaceInformationPtr& si, const Pose& goal, StepSize tolerance, ModelSet hold = {},
           double min_hold_ratio = 0.0);

  const Pose& pose() const { return goal_; }
  /// q within the tolerance of the goal pose, in each of x, z and theta.
  bool contains(const Pose& q) const;
  /// The largest of q's offsets from the goal pose in x, z and theta, each over its tolerance
  /// (at most 1 within the tolerance; 0 at the goal pose).
  double offset(const Pose& q) const;
  bool isSatisfied(const ompl::base::State* s) const override { return contains(GraspPoseSpace::pose(s)); }
  bool isSatisfied(const ompl::base::State* s, double* distance) const override;
  /// Whether a plan may end at q after a push by `last_pusher` (always, without a hold requirement).
  bool held(const Pose& q, int last_pusher) const;
  double distanceGoal(const ompl::base::State* s) const override;
  void sampleGoal(ompl::base::State* s) const override;
  unsigned int maxSampleCount() const override { return 1; }

 private:
  const GraspPoseSpace& space_;
  Pose goal_;
  StepSize tolerance_;
  ModelSet hold_;  ///< empty: no hold requirement; else the pads must hold in every model
  double min_hold_ratio_;
};

}  // namespace stablepush
