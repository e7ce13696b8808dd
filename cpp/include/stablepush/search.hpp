// What a search for stable pushes takes and gives, in plain types (no OMPL, CGAL or Boost): the
// unit step and its metric, sets of pushers, the models a push must be stable in, the question the
// search asks of the mechanics (PushChecker), and the path it returns with its cost (paper
// section V, docs/model.md section 3). planning.hpp plans with them.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "stablepush/stable_push.hpp"
#include "stablepush/types.hpp"

namespace stablepush {

/// One unit step of the planner: a translation of `length` [m] or a rotation of `angle` [rad]
/// (the task's planner.step). Distances in the planner are counted in these units.
struct StepSize {
  double length = 1e-3;
  double angle = M_PI / 180.0;
};

/// Pushers as a set: bit i stands for pusher i. At most kMaxPushers pushers per task.
using PusherSet = std::uint32_t;
inline constexpr int kMaxPushers = 32;
inline bool contains(PusherSet set, int pusher) { return pusher >= 0 && ((set >> pusher) & 1u); }

/// The distance from a to b in unit steps: |(dx / length, dz / length, dtheta / angle)|. A unit
/// push moves at most 1; the planner cuts longer motions into pushes by it (unit_pushes).
double steps_between(const Pose& a, const Pose& b, const StepSize& step);

/// The models a push must be stable in: the nominal model alone, or the corners of the task's
/// uncertainty box (docs/model.md section 7), which share the geometry (section, pads, pushers).
/// A push is stable when it is stable in every model; its margin is the least. Non-owning.
using ModelSet = std::vector<const StablePushModel*>;

/// The push q -> q + dq by `pusher` as the least stable model of the set sees it: the result with
/// the least margin (an infeasible one first).
PushResult worst_case(const ModelSet& models, const Pose& q, const Motion& dq, int pusher);

/// What the search asks of the mechanics: which pushers make a motion a stable push, and how
/// deep. TRRTstar is written against this alone (OMPL keeps validity apart from search the same
/// way), so it can be tested with a toy rule; StablePushValidator answers it for the model. The
/// search finds it as its SpaceInformation's motion validator, which must implement both.
class PushChecker {
 public:
  virtual ~PushChecker() = default;
  /// Every pusher of the task as a set.
  virtual PusherSet all_pushers() const = 0;
  /// The pushers among `candidates` that make every unit push of a -> b stable; 0 when none.
  virtual PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const = 0;
  /// The same, except that when some of the `preferred` candidates are stable only they are
  /// returned, and the others need not be tested (a descent going on with its own pusher).
  virtual PusherSet stable_pushers_preferring(const Pose& a, const Pose& b, PusherSet candidates,
                                              PusherSet preferred) const;
  /// The margin [N] of one unit push a -> b by `pusher` (the least over the models), for the
  /// anytime choice between plans (TRRTstar's improve_for).
  virtual double push_margin(const Pose& a, const Pose& b, int pusher) const = 0;
  /// Point pushers, whose stable pushes are a surface (StablePushValidator::onto_wedge_surface);
  /// by default there are none.
  virtual PusherSet wedge_pushers() const { return 0; }
  /// A step onto `pusher`'s surface from `a`, `length` unit steps long with the heading of
  /// `direction` [unit steps]: a + length (cos b h + sin b e_theta) in unit steps, h the unit
  /// heading of direction's first two coordinates, |b| <= 90 deg (the search bounds where such a
  /// step can end by it, WedgeStepQueue); nullopt when there is none. By default none.
  virtual std::optional<Pose> onto_wedge_surface(const Pose& a, const Eigen::Vector3d& direction, double length,
                                                 int pusher) const;
  /// The headings [rad] of the pure translations on `pusher`'s surface from `a` (b = 0 above).
  /// The surface is nearly a plane through pure rotation, so the roots at evenly spaced headings
  /// crowd near it and its translating pushes lie within a few degrees of these headings. By
  /// default none.
  virtual std::vector<double> wedge_translation_headings(const Pose& a, int pusher) const;
  /// Points fixed in G [m] about which a turn keeps a pad point sticking (the pads' centres): such a
  /// turn is the sticking case, one line of motions the straight and steered steps meet only by
  /// chance once the object is off the point it was planned to turn about. By default none.
  virtual std::vector<Vec2> pivot_points() const { return {}; }
  /// Stable-push tests made so far (what restarts count).
  virtual std::uint64_t feasibility_checks() const = 0;
  virtual void reset_feasibility_checks() = 0;
};

/// Path cost: switch-overs first, then length [unit steps]. The first push is not a switch-over.
struct PathCost {
  int switches = 0;
  double length = 0.0;

  /// Lexicographic; lengths within 1e-9 unit steps count as equal.
  bool operator<(const PathCost& other) const {
    if (switches != other.switches) return switches < other.switches;
    return length < other.length - 1e-9;
  }
  PathCost operator+(const PathCost& other) const { return {switches + other.switches, length + other.length}; }
  PathCost operator-(const PathCost& other) const { return {switches - other.switches, length - other.length}; }
};

/// How a solve ended.
enum class PlanOutcome {
  GoalReached,          ///< a node within the goal tolerance with at most max_switches switch-overs
  GoalOverSwitchLimit,  ///< time ran out; the goal was reached, but only with more switch-overs
  TimeLimit,            ///< time ran out before the goal was reached; the path ends closest to it
  InvalidStart,         ///< the pads do not hold the object at the start: nothing was planned
};

/// One node of a solution path: the pose and the pusher of the push into it (kNoPusher at the start).
struct PathNode {
  Pose pose;
  int pusher = kNoPusher;
};

/// A declared parameter's kind and the closed range its setter accepts.
struct ParameterRange {
  bool integer = false;
  double lowest = 0.0;
  double highest = 0.0;
};

/// TRRTstar's declared parameters and their ranges: the one table the setters enforce and the
/// task validation reads (Python: _core.TRRT_STAR_PARAMETER_RANGES).
const std::map<std::string, ParameterRange>& trrt_star_parameter_ranges();

}  // namespace stablepush
