#include "stablepush/planning.hpp"

#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include "stablepush/internal/checker_validator.hpp"
#include "stablepush/internal/grasp_space.hpp"
#include "stablepush/internal/trrt_star.hpp"

namespace stablepush {

namespace ob = ompl::base;

namespace {

/// How far x and z can be from 0 with some pad still on the object: a pad centre p in G lies in the
/// cross-section, so |p - c| <= circumradius and each of x, z is within circumradius + |p| of 0.
double pad_reach(const StablePushModel& model) {
  double reach = 0.0;
  for (const Pad& pad : model.gripper().pads()) reach = std::max(reach, pad.center.norm());
  return reach + model.section().circumradius();
}

/// The region the planner samples: the box spanned by the start and the goal, grown by
/// settings.sampling_margin unit steps on every side, and cut to |x|, |z| <= reach.
ob::RealVectorBounds sampling_region(const PlannerSettings& settings, double reach) {
  const Pose& a = settings.start;
  const Pose& b = settings.goal;
  const double grow = settings.sampling_margin * settings.step.length;
  const double turn = settings.sampling_margin * settings.step.angle;
  ob::RealVectorBounds bounds(3);
  // The start and the goal always lie inside (a re-plan may start where no pad holds the object;
  // the validity checker then refuses it, rather than OMPL dropping it as out of bounds).
  bounds.setLow(0, std::min({std::max(-reach, std::min(a.x, b.x) - grow), a.x, b.x}));
  bounds.setHigh(0, std::max({std::min(reach, std::max(a.x, b.x) + grow), a.x, b.x}));
  bounds.setLow(1, std::min({std::max(-reach, std::min(a.z, b.z) - grow), a.z, b.z}));
  bounds.setHigh(1, std::max({std::min(reach, std::max(a.z, b.z) + grow), a.z, b.z}));
  bounds.setLow(2, std::min(a.theta, b.theta) - turn);
  bounds.setHigh(2, std::max(a.theta, b.theta) + turn);
  return bounds;
}

void apply_parameters(ob::Planner& planner, const std::map<std::string, std::string>& parameters) {
  ob::ParamSet& declared = planner.params();
  for (const auto& [name, value] : parameters) {
    if (!declared.hasParam(name)) {
      std::vector<std::string> names;
      declared.getParamNames(names);
      std::string known;
      for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("unknown planner parameter '" + name + "' (TRRTstar declares " + known + ")");
    }
    bool taken = false;
    try {
      taken = declared.setParam(name, value);
    } catch (const std::invalid_argument&) {
      throw;  // a setter's range check, which names the parameter
    } catch (const std::exception&) {
      taken = false;  // OMPL's number conversion ("nan", "1e", ...)
    }
    if (!taken) throw std::invalid_argument("planner parameter '" + name + "' cannot take the value '" + value + "'");
  }
}

void check_settings(const PlannerSettings& s) {
  auto finite = [](const Pose& q) { return std::isfinite(q.x) && std::isfinite(q.z) && std::isfinite(q.theta); };
  if (!finite(s.start) || !finite(s.goal)) throw std::invalid_argument("start and goal must be finite");
  if (!(s.time_limit > 0.0 && s.time_limit <= kMaxTimeLimit))
    throw std::invalid_argument("time_limit must be > 0 and at most 1e6 s (kMaxTimeLimit)");
  for (const StepSize& size : {s.step, s.tolerance})
    if (!(std::isfinite(size.length) && std::isfinite(size.angle)))
      throw std::invalid_argument("step and tolerance must be finite");
  // PoseGoal's threshold and offset divide by the tolerance; a zero tolerance is a goal no pose meets.
  if (!(s.tolerance.length > 0.0 && s.tolerance.angle > 0.0))
    throw std::invalid_argument("tolerance must be > 0 in length and angle");
  // GraspPoseSpace::kShortestPush holds for unit steps of at least 0.001 mm and 0.001 deg.
  if (!(s.step.length >= 1e-6 && s.step.angle >= 1e-3 * M_PI / 180.0))
    throw std::invalid_argument("step must be at least 0.001 mm and 0.001 deg");
  if (!(std::isfinite(s.min_margin) && s.min_margin >= 0.0)) throw std::invalid_argument("min_margin must be >= 0");
  if (!(std::isfinite(s.sampling_margin) && s.sampling_margin >= 0.0))
    throw std::invalid_argument("sampling_margin must be >= 0");
  if (!(std::isfinite(s.min_hold_ratio) && s.min_hold_ratio >= 0.0))
    throw std::invalid_argument("min_hold_ratio must be >= 0");
  if (!(std::isfinite(s.min_transit_hold) && s.min_transit_hold >= 0.0))
    throw std::invalid_argument("min_transit_hold must be >= 0");
  if (s.start_pusher < kNoPusher) throw std::invalid_argument("start_pusher must be a pusher index or -1");
}

/// The OMPL problem TRRTstar solves: the pose space, its space information and the problem
/// definition (start and goal).
struct Problem {
  std::shared_ptr<GraspPoseSpace> space;
  ob::SpaceInformationPtr si;
  ob::ProblemDefinitionPtr pdef;
};

/// The problem of planning from settings.start to settings.goal: samples from the start-goal box
/// grown by settings.sampling_margin unit steps and cut to |x|, |z| <= reach [m]; poses, motions
/// and the goal judged by what the three factories make for the space information.
template <class PoseValidity, class MotionValidity, class Goal>
Problem make_problem(const PlannerSettings& settings, double reach, PoseValidity pose_validity,
                     MotionValidity motion_validity, Goal goal) {
  // OMPL's warnings are of cases the plan's outcome reports itself (a start the pads do not hold:
  // invalid_start); printed, they cluttered every closed-loop run that lost its grasp.
  ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
  Problem problem;
  problem.space = std::make_shared<GraspPoseSpace>(settings.step, sampling_region(settings, reach));
  problem.si = std::make_shared<ob::SpaceInformation>(problem.space);
  problem.si->setStateValidityChecker(pose_validity(problem.si));
  problem.si->setMotionValidator(motion_validity(problem.si));
  problem.si->setup();
  problem.pdef = std::make_shared<ob::ProblemDefinition>(problem.si);
  ob::ScopedState<GraspPoseSpace> start(problem.space);
  GraspPoseSpace::set_pose(start.get(), settings.start);
  problem.pdef->addStartState(start);
  problem.pdef->setGoal(goal(problem.si));
  return problem;
}

/// TRRTstar's solve of `problem` with the settings' declared parameters, until settings.time_limit.
ob::PlannerStatus solve(TRRTstar& planner, const Problem& problem, const PlannerSettings& settings) {
  apply_parameters(planner, settings.parameters);
  planner.setProblemDefinition(problem.pdef);
  planner.setup();
  ob::PlannerTerminationCondition ptc = ob::timedPlannerTerminationCondition(settings.time_limit);
  if (settings.stop) {
    const std::shared_ptr<StopFlag> stop = settings.stop;
    ptc = ob::plannerOrTerminationCondition(ptc, ob::PlannerTerminationCondition([stop] { return stop->is_set(); }));
  }
  return planner.solve(ptc);
}

/// Append the motion from the plan's last waypoint to `to` by `pusher`, cut into unit pushes as
/// the validator cut it (GraspPoseSpace::unit_pushes), so that each waypoint is a checked push;
/// each carries the test's verdict, the least over the models.
void append_pushes(Plan& plan, const GraspPoseSpace& space, const ModelSet& models, const Pose& to, int pusher) {
  const std::vector<Pose> poses = space.unit_pushes(plan.waypoints.back().pose, to);
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const PushResult r = worst_case(models, poses[k - 1], poses[k] - poses[k - 1], pusher);
    plan.waypoints.push_back({poses[k], pusher, r.margin, r.contact_case});
  }
}

/// Where the straight push from the plan's end q0 to the goal pose g is not stable for its last
/// pusher, a point pusher (whose stable pushes form a surface, docs/model.md section 2, that
/// rarely passes through g), or does not end held: two pushes, each on a point pusher's surface,
/// the first by the last pusher and the second by one of `seconds`, tried in their order. The
/// first goes a unit step (the longest one push may be) from q0 at heading phi onto the surface at
/// q0 (onto_wedge_surface), to q1(phi); the second, straight from q1 to g, is on the surface of
/// pusher s at q1 where
///     m_s(phi) = e_s . w_motion(q1, g - q1) / scale = 0        (wedge_plane_offset).
/// q1 is found once at the last pusher's wedge_step_headings (48 evenly spaced, and closely about
/// its translation headings) in order round; m_s's sign changes between them are refined to rounding in
/// phi, and a root counts where |m_s| is within the certification band (not across a jump). Of
/// the pairs whose two pushes are stable in every model and keep the grasp (and, for s other
/// than the last pusher, where `planner.pads_hold_transit` allows the switch-over at q1), the shortest
/// is appended. Returns s, or kNoPusher when none was appended. On the generated pin tasks (docs/planner.md)
/// shorter first pushes found fewer finishes, 24 headings half as many, and most finishes switch
/// pins: one surface moves the object in only two of its three coordinates, and two pushes by one
/// pin lie on nearly the same surface.
int finish_on_wedges(Plan& plan, const GraspPoseSpace& space, const StablePushValidator& validator, const Pose& target,
                     const ModelSet& models, const std::vector<int>& seconds, const TRRTstar& planner) {
  const int pusher = plan.waypoints.back().pusher;
  const Pose end = plan.waypoints.back().pose;
  const Eigen::Vector3d way = space.in_unit_steps(target - end);
  const auto onto_first = [&](double phi) -> std::optional<Pose> {
    const std::optional<Pose> q1 =
        validator.onto_wedge_surface(end, Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0), 1.0, pusher);
    if (!q1 || space.distance(*q1, target) < GraspPoseSpace::kShortestPush) return std::nullopt;
    return q1;
  };
  constexpr int kHeadings = 48;
  const double heading = std::atan2(way[1], way[0]);
  // In order round from the way's heading, the last the first again, a turn on.
  std::vector<double> phis = wedge_step_headings(validator, end, pusher, heading, kHeadings);
  for (double& phi : phis) phi = heading + std::fmod(std::fmod(phi - heading, 2.0 * M_PI) + 2.0 * M_PI, 2.0 * M_PI);
  std::sort(phis.begin(), phis.end());
  const std::size_t n = phis.size();
  phis.push_back(phis.front() + 2.0 * M_PI);
  std::vector<std::optional<Pose>> firsts(n + 1);
  for (std::size_t k = 0; k < n; ++k) firsts[k] = onto_first(phis[k]);
  firsts[n] = firsts[0];
  struct Leg {
    double phi;   ///< the first push's heading in unit steps' (x, z) [rad]
    double miss;  ///< m_s(phi)
    Pose q1;
  };
  for (const int second : seconds) {
    const auto leg = [&](double phi, const std::optional<Pose>& q1) -> std::optional<Leg> {
      if (!q1) return std::nullopt;
      return Leg{phi, validator.wedge_plane_offset(*q1, target - *q1, second), *q1};
    };
    std::vector<std::optional<Leg>> ring(n + 1);
    for (std::size_t k = 0; k <= n; ++k) ring[k] = leg(phis[k], firsts[k]);
    std::vector<std::pair<double, Pose>> found;  // (both pushes' length [unit steps], q1)
    for (std::size_t k = 0; k < n; ++k) {
      if (!ring[k] || !ring[k + 1] || (ring[k]->miss < 0.0) == (ring[k + 1]->miss < 0.0)) continue;
      const Leg root = refine_sign_change(*ring[k], *ring[k + 1], &Leg::phi, &Leg::miss,
                                          [&](double phi) { return leg(phi, onto_first(phi)); });
      if (std::abs(root.miss) <= kCertificationBand)
        found.emplace_back(space.distance(end, root.q1) + space.distance(root.q1, target), root.q1);
    }
    std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [length, q1] : found) {
      if ((second != pusher && !planner.pads_hold_transit(q1, pusher)) ||
          validator.stable_pushers(end, q1, PusherSet{1} << pusher) == 0 ||
          validator.stable_pushers(q1, target, PusherSet{1} << second) == 0)
        continue;
      append_pushes(plan, space, models, q1, pusher);
      append_pushes(plan, space, models, target, second);
      return second;
    }
  }
  return kNoPusher;
}

/// Append the last, shorter push from the plan's end (within tolerance) to the goal pose itself,
/// cut into unit pushes as every motion is, with the last pusher, when each is a stable push in
/// every model and the goal's hold requirement holds there (Plan::ends_at_goal); for a point
/// pusher, where it does not, two pushes on point pushers' surfaces (finish_on_wedges), by the
/// last pusher alone or else, with `switch_left` and where `planner.pads_hold_transit` allows, with a
/// switch-over to another point pusher. Returns the switch-overs it added (0 or 1).
int finish_at_goal(Plan& plan, const GraspPoseSpace& space, const StablePushValidator& validator, const PoseGoal& goal,
                   const Pose& target, const ModelSet& models, bool switch_left, const TRRTstar& planner) {
  const Waypoint last = plan.waypoints.back();
  const Pose& end = last.pose;
  if (space.distance(end, target) < GraspPoseSpace::kShortestPush) {  // there: no push is that short
    plan.waypoints.back().pose = target;
    plan.ends_at_goal = true;
    return 0;
  }
  if (last.pusher == kNoPusher) return 0;
  if (goal.held(target, last.pusher) && validator.stable_pushers(end, target, PusherSet{1} << last.pusher) != 0) {
    append_pushes(plan, space, models, target, last.pusher);
    plan.ends_at_goal = true;
    return 0;
  }
  const PusherSet wedges = validator.wedge_pushers();
  if (!contains(wedges, last.pusher)) return 0;
  // The last pusher first: a switch-over is a transit between features.
  std::vector<int> seconds;
  if (goal.held(target, last.pusher)) seconds.push_back(last.pusher);
  for (int p = 0; switch_left && p < kMaxPushers; ++p)
    if (p != last.pusher && contains(wedges, p) && goal.held(target, p)) seconds.push_back(p);
  if (seconds.empty()) return 0;
  const int second = finish_on_wedges(plan, space, validator, target, models, seconds, planner);
  if (second == kNoPusher) return 0;
  plan.ends_at_goal = true;
  return second == last.pusher ? 0 : 1;
}

}  // namespace

Plan plan_stable_pushes(const StablePushModel& model, const PlannerSettings& settings) {
  return plan_stable_pushes(ModelSet{&model}, settings);
}

Plan plan_stable_pushes(const ModelSet& models, const PlannerSettings& settings) {
  const auto started = std::chrono::steady_clock::now();
  check_settings(settings);
  if (models.empty()) throw std::invalid_argument("no model to plan in");
  for (const StablePushModel* m : models)
    if (m == nullptr) throw std::invalid_argument("a model to plan in is None");
  const StablePushModel& model = *models.front();  // the geometry, which every model shares

  std::shared_ptr<StablePushValidator> validator;
  std::shared_ptr<PoseGoal> goal;
  const Problem problem = make_problem(
      settings, pad_reach(model),
      [&](const ob::SpaceInformationPtr& si) { return std::make_shared<GraspValidityChecker>(si, model); },
      [&](const ob::SpaceInformationPtr& si) {
        return validator = std::make_shared<StablePushValidator>(si, models, settings.min_margin);
      },
      [&](const ob::SpaceInformationPtr& si) {
        return goal =
                   std::make_shared<PoseGoal>(si, settings.goal, settings.tolerance, models, settings.min_hold_ratio);
      });
  const auto& space = problem.space;
  if (settings.start_pusher >= static_cast<int>(model.pushers().size()))
    throw std::invalid_argument("start_pusher must be a pusher index or -1");
  TRRTstar planner(problem.si);
  planner.set_transit_hold(models, settings.min_transit_hold, settings.start_pusher);
  // The plan's end (finish_at_goal) after `switches` switch-overs; finish_steps ask it first.
  const auto end_at_goal = [&](Plan& plan, int switches) {
    return finish_at_goal(plan, *space, *validator, *goal, settings.goal, models, switches < planner.getMaxSwitches(),
                          planner);
  };
  // The last end the test tried, kept so that the plan's end is not searched (nor its tests
  // counted) twice where finish_toward_goal stops there: at an end that passed, or at the last
  // one tried when no step is left.
  struct Probe {
    Waypoint from;  ///< the end tried (pose, pusher)
    Plan plan;      ///< finish_at_goal on `from` alone
    int switches;
  };
  std::optional<Probe> probed;
  planner.set_end_test([&](const Pose& end, int pusher, int switches) {
    const Waypoint from{end, pusher, std::numeric_limits<double>::quiet_NaN(), ContactCase::AllSliding};
    Plan plan;
    plan.waypoints.push_back(from);
    const int added = end_at_goal(plan, switches);
    probed = Probe{from, std::move(plan), added};
    return probed->plan.ends_at_goal;
  });
  const ob::PlannerStatus status = solve(planner, problem, settings);
  planner.set_end_test(nullptr);  // it refers to this scope

  Plan plan;
  plan.outcome = planner.outcome();
  if (status == ob::PlannerStatus::INVALID_START) {  // the pads do not hold the object there: the start alone
    plan.waypoints.push_back(
        {settings.start, kNoPusher, std::numeric_limits<double>::quiet_NaN(), ContactCase::AllSliding});
    plan.goal_distance = space->distance(settings.start, settings.goal);
    plan.stats.planning_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return plan;
  }
  const std::vector<PathNode> nodes = planner.solution();
  plan.waypoints.push_back(
      {nodes.front().pose, kNoPusher, std::numeric_limits<double>::quiet_NaN(), ContactCase::AllSliding});
  for (std::size_t i = 1; i < nodes.size(); ++i) append_pushes(plan, *space, models, nodes[i].pose, nodes[i].pusher);
  const PathCost cost = planner.solution_cost();
  int finish_switches = 0;
  if (plan.outcome == PlanOutcome::GoalReached) {
    const Waypoint& last = plan.waypoints.back();
    if (!probed || probed->from.pusher != last.pusher || probed->from.pose.x != last.pose.x ||
        probed->from.pose.z != last.pose.z || probed->from.pose.theta != last.pose.theta) {
      finish_switches = end_at_goal(plan, cost.switches);
    } else if (probed->plan.ends_at_goal) {  // finish_toward_goal stopped where the test passed
      const std::vector<Waypoint>& tail = probed->plan.waypoints;
      plan.waypoints.back().pose = tail.front().pose;  // the goal pose, where the end was that near
      plan.waypoints.insert(plan.waypoints.end(), tail.begin() + 1, tail.end());
      plan.ends_at_goal = true;
      finish_switches = probed->switches;
    }
  }
  plan.stats.iterations = planner.iterations();
  plan.stats.nodes = planner.node_count();
  plan.stats.feasibility_checks = validator->feasibility_checks();
  plan.stats.switches = cost.switches + finish_switches;
  plan.stats.restarts = planner.restarts();
  plan.stats.check_limit_reached = planner.check_limit_reached();
  plan.stats.first_time_s =
      planner.first_solution_time() >= 0.0 ? planner.first_solution_time() : std::numeric_limits<double>::quiet_NaN();
  plan.stats.first_switches = planner.first_solution_cost().switches;
  plan.stats.first_length = planner.first_solution_cost().length;
  plan.stats.first_min_margin = planner.first_solution_margin();
  plan.stats.path_min_margin =
      planner.getImproveFor() > 0.0 ? planner.solution_margin() : std::numeric_limits<double>::quiet_NaN();
  plan.stats.length = 0.0;  // along the waypoints, the last push to the goal included
  for (std::size_t i = 1; i < plan.waypoints.size(); ++i)
    plan.stats.length += space->distance(plan.waypoints[i - 1].pose, plan.waypoints[i].pose);
  plan.goal_distance = space->distance(plan.waypoints.back().pose, settings.goal);
  plan.stats.planning_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return plan;
}

CheckerMotionValidator::CheckerMotionValidator(const ob::SpaceInformationPtr& si, std::shared_ptr<PushChecker> checker)
    : ob::MotionValidator(si), checker_(std::move(checker)) {}

bool CheckerMotionValidator::checkMotion(const ob::State* a, const ob::State* b) const {
  return stable_pushers(GraspPoseSpace::pose(a), GraspPoseSpace::pose(b), all_pushers()) != 0;
}

bool CheckerMotionValidator::checkMotion(const ob::State* a, const ob::State* b,
                                         std::pair<ob::State*, double>& last_valid) const {
  const bool ok = checkMotion(a, b);
  if (!ok) last_valid.second = 0.0;
  return ok;
}

PusherSet CheckerMotionValidator::all_pushers() const { return checker_->all_pushers(); }

PusherSet CheckerMotionValidator::stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const {
  return checker_->stable_pushers(a, b, candidates);
}

PusherSet CheckerMotionValidator::stable_pushers_preferring(const Pose& a, const Pose& b, PusherSet candidates,
                                                            PusherSet preferred) const {
  return checker_->stable_pushers_preferring(a, b, candidates, preferred);
}

double CheckerMotionValidator::push_margin(const Pose& a, const Pose& b, int pusher) const {
  return checker_->push_margin(a, b, pusher);
}

PusherSet CheckerMotionValidator::wedge_pushers() const { return checker_->wedge_pushers(); }

std::optional<Pose> CheckerMotionValidator::onto_wedge_surface(const Pose& a, const Eigen::Vector3d& direction,
                                                               double length, int pusher) const {
  return checker_->onto_wedge_surface(a, direction, length, pusher);
}

std::vector<double> CheckerMotionValidator::wedge_translation_headings(const Pose& a, int pusher) const {
  return checker_->wedge_translation_headings(a, pusher);
}

std::vector<Vec2> CheckerMotionValidator::pivot_points() const { return checker_->pivot_points(); }

std::uint64_t CheckerMotionValidator::feasibility_checks() const { return checker_->feasibility_checks(); }

void CheckerMotionValidator::reset_feasibility_checks() { checker_->reset_feasibility_checks(); }

CheckedPlan plan_with_checker(std::shared_ptr<PushChecker> checker, const PlannerSettings& settings) {
  check_settings(settings);
  if (!checker) throw std::invalid_argument("no push checker");
  const Problem problem = make_problem(
      settings, std::numeric_limits<double>::infinity(),
      [](const ob::SpaceInformationPtr& si) { return std::make_shared<ob::AllValidStateValidityChecker>(si); },
      [&](const ob::SpaceInformationPtr& si) {
        return std::make_shared<CheckerMotionValidator>(si, std::move(checker));
      },
      [&](const ob::SpaceInformationPtr& si) {
        return std::make_shared<PoseGoal>(si, settings.goal, settings.tolerance);
      });
  TRRTstar planner(problem.si);
  solve(planner, problem, settings);
  return {planner.outcome(), planner.solution(), planner.solution_cost(), planner.restarts()};
}

std::map<std::string, std::string> trrt_star_parameters() {
  ob::RealVectorBounds bounds(3);
  bounds.setLow(-1.0);
  bounds.setHigh(1.0);
  auto si = std::make_shared<ob::SpaceInformation>(std::make_shared<GraspPoseSpace>(StepSize{}, bounds));
  TRRTstar planner(si);
  std::map<std::string, std::string> out;
  planner.params().getParams(out);
  return out;
}

}  // namespace stablepush
