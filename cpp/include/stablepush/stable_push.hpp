// The stable prehensile push test (paper section IV, docs/model.md section 2).
//
// Quasi-dynamic balance over one step from rest (paper eq. 5, rearranged as eqs. 8 and 9):
//     w_pusher = M xi / dt - w_sliding fingers - w_gravity - w_sticking fingers,
// all in O about O's origin. The push is stable for a pusher when some w_sticking in the
// sticking points' friction polytope puts w_pusher in the relative interior of that pusher's
// generalized friction cone.
//
// Fast and exact together: the decision is made in double precision and accepted when it is
// more than a certification band (kCertificationBand times the sum of the magnitudes of the
// terms) away from the cone's boundary; otherwise it is re-made in exact arithmetic from the
// same doubles (CGAL Gmpzf sums and products, CGAL's exact LP solver for the sticking case).
#pragma once

#include <string>
#include <vector>

#include "stablepush/cross_section.hpp"
#include "stablepush/friction_cone.hpp"
#include "stablepush/gripper.hpp"
#include "stablepush/pusher.hpp"
#include "stablepush/rigid_body.hpp"
#include "stablepush/types.hpp"

namespace stablepush {

/// Relative width of the band around a cone boundary inside which a double answer is re-made exactly.
inline constexpr double kCertificationBand = 1e-9;
/// The least unit motion (largest of |dx|, |dz| [m], |dtheta| [rad]) the model evaluates.
inline constexpr double kSmallestMotion = 1e-12;
/// "No pusher": the start of a plan, or the object held by the pads alone.
inline constexpr int kNoPusher = -1;
/// A pad point sticks when its slip speed is below this fraction of |v| + |omega| r_pad (docs/model.md section 2).
inline constexpr double kStickingSpeedRatio = 1e-9;

enum class ContactCase { AllSliding, Sticking };

/// The frame in which gravity is fixed during a push (docs: docs/planner.md, "Gravity during a push").
/// Gripper: the pusher moves and the gripper stays (the paper's assumption): gravity is fixed in G.
/// Object: the pusher is a feature fixed in the world and sticks, so on pusher p's feature the
/// object keeps its world orientation phi_p and G turns by phi_p - theta: gravity is fixed in O,
/// and in G it is R(theta - phi_p) g, with g the gravity in G when G's axes are the world's.
enum class GravityFrame { Gripper, Object };

/// Pad points at one location that stick during the motion; their friction discs add up.
struct StickingGroup {
  Vec2 arm;               ///< from O's origin to the points, in G [m]
  double friction_limit;  ///< radius of the summed friction disc, sum of mu N / k [N]
};

/// The paper's net motion wrench: everything in eqs. 8-9 that the motion fixes.
struct MotionWrench {
  /// M xi / dt - w_sliding - w_gravity in O about O's origin [N, N, N m].
  Wrench required = Wrench::Zero();
  /// Sticking pad points, grouped by location; empty in the all-sliding case.
  std::vector<StickingGroup> sticking;
  int sticking_points = 0;
  /// Sum of the magnitudes of the terms [N] (torques divided by the model's torque length).
  double scale = 0.0;
  Rotation2 rotation;           ///< R(theta) at the pose
  Vec2 gravity = Vec2::Zero();  ///< the gravity in G used [m/s^2] (it depends on the pusher, see GravityFrame)
};

/// The answer of the stable-push test for one pusher.
struct PushResult {
  bool feasible = false;
  ContactCase contact_case = ContactCase::AllSliding;
  /// How deep inside the cone [N]: the largest t such that w_pusher has every facet row at most -t,
  /// over the admissible sticking forces (rows normalized as in WrenchCone). Positive iff feasible
  /// outside the certification band; off the cone's span it is minus the distance to the span.
  double margin = 0.0;
  /// The pusher wrench that realizes `margin` (in O about O's origin) [N, N, N m].
  Wrench witness = Wrench::Zero();
  /// True when the decision was made in exact arithmetic.
  bool exact = false;
  int sticking_points = 0;
};

class StablePushModel {
 public:
  /// gravity: acceleration in G's grasp plane when G's axes are the world's [m/s^2]; step_time:
  /// dt of one unit step [s]; friction_polygon_sides: facets of the polygon inscribed in a sticking
  /// point's friction disc; gravity_frame and feature_angles (phi_p per pusher [rad], the object's
  /// world orientation on its feature; default 0): see GravityFrame.
  StablePushModel(CrossSection section, RigidBody body, Gripper gripper, std::vector<Pusher> pushers,
                  const Vec2& gravity, double step_time, int friction_polygon_sides = 16,
                  GravityFrame gravity_frame = GravityFrame::Gripper, std::vector<double> feature_angles = {});

  const CrossSection& section() const { return section_; }
  const RigidBody& body() const { return body_; }
  const Gripper& gripper() const { return gripper_; }
  const std::vector<Pusher>& pushers() const { return pushers_; }
  const std::vector<WrenchCone>& pusher_cones() const { return cones_; }
  const Vec2& gravity() const { return gravity_; }
  GravityFrame gravity_frame() const { return gravity_frame_; }
  const std::vector<double>& feature_angles() const { return feature_angles_; }
  /// Gravity in G [m/s^2] at q during a push by `pusher` (kNoPusher: G's axes the world's).
  Vec2 gravity_in_gripper(const Pose& q, int pusher) const;
  /// The same, from R(theta) already at hand.
  Vec2 gravity_in_gripper(const Rotation2& R, int pusher) const;
  /// Whether pushers a and b see the same gravity at every pose (so they share a motion wrench).
  bool same_gravity(int a, int b) const {
    return gravity_frame_ == GravityFrame::Gripper || feature_angles_[a] == feature_angles_[b];
  }
  double step_time() const { return step_time_; }
  /// Length that converts torques to forces in margins and bands [m]: the cross-section's circumradius.
  double torque_length() const { return torque_length_; }
  int friction_polygon_sides() const { return polygon_sides_; }

  /// The motion wrench of a unit motion dq from pose q (twist xi = dq / dt, constant over the step)
  /// when `pusher` pushes (its index selects the gravity, see GravityFrame; kNoPusher: G's axes the
  /// world's).
  MotionWrench motion_wrench(const Pose& q, const Motion& dq, int pusher) const;
  /// The same, with R(theta) already at hand (bit for bit the same wrench).
  MotionWrench motion_wrench(const PoseAndRotation& q, const Motion& dq, int pusher) const;

  /// The stable-push test of dq from q for pusher `pusher` (an index into pushers()).
  PushResult check(const Pose& q, const Motion& dq, int pusher) const;
  /// The test for every pusher, one motion wrench shared by the pushers with the same gravity.
  std::vector<PushResult> check_all(const Pose& q, const Motion& dq) const;
  /// The test against a motion wrench already computed for (q, dq) and this pusher's gravity.
  PushResult check(const MotionWrench& load, const Pose& q, const Motion& dq, int pusher) const;

  /// Whether the pads alone hold the object at rest at q, with no pusher (the grasp at the end of a
  /// plan, or between two features): the largest factor lambda such that lambda times the weight
  /// (m g at the centre of mass) is balanced by friction forces of the pad points, all sticking
  /// at rest, each in its friction polygon (grouped by location as in the sticking case). The
  /// grasp holds the object when lambda >= 1; +infinity without gravity; capped at 1e3. Double
  /// precision (CGAL's exact LP on the same doubles where the fast solver does not converge): a
  /// report and a goal filter, not a certified decision.
  /// Gravity as during a push by `pusher` (the last one before the object is let go), or with G's
  /// axes the world's for kNoPusher.
  double hold_ratio(const Pose& q, int pusher) const;

  /// Every pad disc inside the cross-section at q.
  bool grasp_maintained(const Pose& q) const { return gripper_.grasp_maintained(section_, q); }

  /// This model in another world of the same part, grasp and pushers: the pads' mu and grip force
  /// times `pad_mu_scale` and `grip_force_scale`, the object's mass and inertia times `mass_scale`
  /// (its centre of mass where it was). The pushers' cones are shared, not rebuilt: their exact
  /// facets are most of what a model costs to make, and a world that changes a pusher's mu needs a
  /// model of its own. std::invalid_argument when a scale is not finite and positive.
  StablePushModel in_world(double pad_mu_scale, double grip_force_scale, double mass_scale) const;

 private:
  /// Walks the terms of the motion wrench in G: loads.force(f, arm) for a force f [N] at arm [m]
  /// from O's origin, loads.torque(t) for a pure torque [N m], loads.sticking(arm, limit, n) for a
  /// sticking site of n pad points (Gripper::sites); `rotation` R(q.theta), computed once by the
  /// caller; `gravity` in G [m/s^2]. Shared by the double and the exact evaluations so both see the
  /// same doubles. Defined in cpp/src/motion_terms.hpp, which the core's sources include.
  template <class Loads>
  void visit_motion_terms(const Pose& q, const Rotation2& rotation, const Motion& dq, const Vec2& gravity,
                          Loads& loads) const;
  PushResult all_sliding(const WrenchCone& cone, const MotionWrench& load, const Pose& q, const Motion& dq) const;
  PushResult with_sticking(const WrenchCone& cone, const MotionWrench& load, const Pose& q, const Motion& dq) const;
  PushResult exact_all_sliding(const WrenchCone& cone, const MotionWrench& load, const Pose& q, const Motion& dq,
                               PushResult double_answer) const;
  PushResult exact_sticking(const WrenchCone& cone, const MotionWrench& load, const Pose& q, const Motion& dq) const;
  double exact_hold_ratio(const std::vector<StickingGroup>& groups, const Vec2& weight, const Vec2& r_cm,
                          double cap) const;

  CrossSection section_;
  RigidBody body_;
  Gripper gripper_;
  std::vector<Pusher> pushers_;
  std::vector<WrenchCone> cones_;
  Vec2 gravity_;
  GravityFrame gravity_frame_;
  std::vector<double> feature_angles_;   ///< phi_p per pusher [rad]
  std::vector<Vec2> gravity_in_object_;  ///< R(phi_p)^T g per pusher: gravity in O on p's feature
  double step_time_;
  double torque_length_;
  int polygon_sides_;
  std::vector<Vec2> polygon_normals_;  ///< outward edge normals of the unit friction polygon (in G)
  double polygon_inradius_;            ///< cos(pi / sides): edge offset of the unit polygon
};

}  // namespace stablepush
