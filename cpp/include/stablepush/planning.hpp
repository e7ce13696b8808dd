// From a stable-push model, a start and a goal to a plan: the OMPL problem set up around
// TRRTstar, solved, and the tree path cut into the unit pushes a robot executes.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "stablepush/search.hpp"
#include "stablepush/stable_push.hpp"

namespace stablepush {

/// The longest time limit a plan accepts [s] (OMPL's timed termination counts in integer ns).
inline constexpr double kMaxTimeLimit = 1e6;

/// Set from another thread to end a search early (Ctrl-C): the plan returns as at its time limit.
class StopFlag {
 public:
  void set() { set_.store(true); }
  bool is_set() const { return set_.load(); }

 private:
  std::atomic<bool> set_{false};
};

struct PlannerSettings {
  Pose start;                ///< [m, m, rad]
  Pose goal;                 ///< [m, m, rad]
  StepSize step;             ///< one unit step
  StepSize tolerance;        ///< per coordinate, around the goal
  double time_limit = 10.0;  ///< [s]
  double min_margin = 1e-3;  ///< least depth inside the pusher's cone for a push to count [N]
  /// Samples are drawn from the box spanned by start and goal, grown by this many unit steps.
  double sampling_margin = 5.0;
  /// The plan must end where the pads alone hold the object with this factor of its weight
  /// (StablePushModel::hold_ratio); 0: no such requirement.
  double min_hold_ratio = 0.0;
  /// TRRTstar's declared parameters by name (seed, max_switches, goal_bias, ...); values as text.
  std::map<std::string, std::string> parameters;
  /// Switch-overs only where the pads alone hold the object with this factor of its weight in every
  /// model (StablePushModel::hold_ratio at the pose where the pusher changes, with the gravity of
  /// the feature being left): between two features the object is carried by the pads alone. 0: anywhere.
  double min_transit_hold = 0.0;
  /// The pusher in contact at the start (a re-plan from a pose on a feature), else kNoPusher. With
  /// min_transit_hold, a plan that starts with another pusher makes a transit at the start.
  int start_pusher = kNoPusher;
  /// When given and set, the search stops at once (checked as often as the time limit).
  std::shared_ptr<StopFlag> stop;
};

/// One waypoint: the pose after a unit push, the pusher that made it, and the test's verdict
/// on that push. The first waypoint is the start: pusher kNoPusher, margin NaN.
struct Waypoint {
  Pose pose;
  int pusher = kNoPusher;
  double margin = 0.0;  ///< [N]
  ContactCase contact_case = ContactCase::AllSliding;
};

struct PlanStats {
  double planning_time_s = 0.0;
  std::uint64_t iterations = 0;
  std::size_t nodes = 0;
  std::uint64_t feasibility_checks = 0;  ///< stable-push tests, one per pusher and unit push
  int switches = 0;
  double length = 0.0;    ///< [unit steps]
  unsigned restarts = 0;  ///< times the search started again (TRRTstar's restart_checks)
  /// The search stopped at TRRTstar's check_limit: a count, so the same on any machine. An
  /// unsolved plan without it stopped at the time limit (or a StopFlag), which depends on the
  /// machine's speed and load.
  bool check_limit_reached = false;
  /// The first path the search found (TRRTstar's improve_for; the search's own path without it),
  /// before the plan's end (Plan::ends_at_goal, finish_steps): when [s into the search, NaN when
  /// none], its switch-overs, length [unit steps] and least margin [N].
  double first_time_s = 0.0;
  int first_switches = 0;
  double first_length = 0.0;
  double first_min_margin = 0.0;
  /// The least margin over the pushes of the search's path [N] (the last push to the goal pose,
  /// Plan::ends_at_goal, not counted): what an improvement compares with first_min_margin. Both
  /// margins are computed only with improve_for > 0 (NaN otherwise: a test per push).
  double path_min_margin = 0.0;
};

struct Plan {
  PlanOutcome outcome = PlanOutcome::TimeLimit;
  std::vector<Waypoint> waypoints;
  PlanStats stats;
  double goal_distance = 0.0;  ///< from the last waypoint [unit steps]
  /// A solved plan ends exactly at the goal when a last, shorter push by the last pusher from the
  /// node within tolerance to the goal pose is stable (in every model; and held, when a hold
  /// ratio is required), or, for a point pusher, two pushes on point pushers' surfaces are (a
  /// switch-over among them where the budget and min_transit_hold allow; counted in
  /// stats.switches); else it ends where the search reached the tolerance.
  bool ends_at_goal = false;
};

/// Plan stable pushes from settings.start to settings.goal. Throws std::invalid_argument for a
/// parameter that TRRTstar does not declare or cannot take.
Plan plan_stable_pushes(const StablePushModel& model, const PlannerSettings& settings);
/// The same, with every push stable in every model of `models` (the corners of an uncertainty
/// box, docs/model.md section 7); each waypoint's margin is the least over them.
Plan plan_stable_pushes(const ModelSet& models, const PlannerSettings& settings);

/// A search's outcome with a PushChecker of one's own: the path (start first) and its cost.
struct CheckedPlan {
  PlanOutcome outcome = PlanOutcome::TimeLimit;
  std::vector<PathNode> path;
  PathCost cost;
  unsigned restarts = 0;
};

/// TRRTstar from settings.start to settings.goal with `checker` deciding which pushers make a
/// motion stable (grasp_space.hpp, PushChecker): every pose valid, no hold requirement, samples
/// from the start-goal box grown by sampling_margin unit steps. Tests the search apart from the
/// mechanics with a toy checker; min_margin and min_hold_ratio are not used.
CheckedPlan plan_with_checker(std::shared_ptr<PushChecker> checker, const PlannerSettings& settings);

/// TRRTstar's declared parameters and their default values (as text).
std::map<std::string, std::string> trrt_star_parameters();

}  // namespace stablepush
