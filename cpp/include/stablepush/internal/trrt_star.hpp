// T-RRT* over grasp poses with the pusher in the search state (paper section V-B, Algorithm 1).
//
// Each tree node is a grasp pose q together with the pusher that made the push into it, so that
// the path cost (switch-overs first, then length in unit steps) is a sum over edges and RRT*'s
// choose-parent (the paper's optimEdge) and rewiring count switch-overs exactly.
//
// One iteration: sample q_rand (the goal with probability goal_bias); from the nearest node that
// needs at most max_switches switch-overs (a node beyond the budget cannot start a plan that
// meets it unless a rewiring lowers its count, so it is kept but not extended), step
// toward q_rand one unit step at a time while
//   1. the T-RRT transition test accepts the step on the configuration cost c(q) = distance to
//      the goal [unit steps] (Jaillet, Cortes and Simeon, T-RRT, 2008):
//        c_new <= c_parent: accept; otherwise accept with probability exp(-(dc / d) / T), where
//        the temperature T falls by temp_change_factor after an accepted climb and rises by it
//        after max_transition_failures refused climbs in a row;
//   2. the grasp is maintained at the new pose (the space's validity checker);
//   3. some pusher makes the step a stable push (StablePushValidator), or, for a point pusher,
//      the step of the same length and heading turned onto its surface of stable pushes;
// then connect the new pose to the cheapest near node whose push to it is stable, and rewire
// the near nodes through it when that is cheaper (Karaman and Frazzoli, RRT*, 2011). A descent
// toward the goal on point pushers' surfaces that stalls, or would switch pushers, first walks to
// where the next pusher's surface through the goal meets its own (walk_after_stall).
//
// The planner stops when a node within the goal tolerance costs at most max_switches
// switch-overs, or when the termination condition (time) fires; outcome() says which. With
// improve_for > 0 it goes on for that long after the first such node (the paper's anytime stop
// rule), and the plan is the goal node's path with the fewest switch-overs, then the largest least
// margin of its unit pushes (worst over the models), then the shortest.
#pragma once

#ifndef STABLEPUSH_INTERNAL_ALLOWED
#error "an internal header of the stablepush core: include stablepush/planning.hpp or stablepush/search.hpp"
#endif

#include <ompl/base/Planner.h>
#include <ompl/util/RandomNumbers.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "stablepush/internal/grasp_space.hpp"
#include "stablepush/search.hpp"

namespace stablepush {

/// A step onto a point pusher's surface of stable pushes and where it ends.
struct WedgeStep {
  double goal_distance;  ///< [unit steps]
  Pose pose;
  int pusher;
  bool ends_plan;  ///< within the goal's tolerance (and held there, PoseGoal::held)
};

/// The steps of each of `lengths` [unit steps] from `from` onto the surfaces of the point pushers
/// in `wedges` (PushChecker::onto_wedge_surface) at each pusher's wedge_step_headings (24 evenly
/// spaced from the goal's, and closely about its translation headings), one at a
/// time: those that end the plan (in `region`, from outside it) first, since from outside the box
/// entering it is what counts, then nearest `goal` first, ties in the order (pusher, length,
/// heading). Each surface's root is found only when no step whose root is not yet found can come
/// before it: a step of length L at heading h ends on the half circle
/// from + L (cos b h + sin b e_theta), |b| <= 90 deg, in unit steps, so the half circle's point
/// nearest the goal bounds the step's distance from below. A descent mostly takes one of the first
/// few steps, and the roots of the rest are never found.
class WedgeStepQueue {
 public:
  WedgeStepQueue(const PushChecker& checker, const GraspPoseSpace& space, const PoseGoal& region, const Pose& from,
                 const Pose& goal, const std::vector<double>& lengths, PusherSet wedges);
  /// The next step, or nullopt after the last.
  std::optional<WedgeStep> next();

 private:
  struct Pending {
    double bound;       ///< at most the step's goal distance [unit steps]
    std::size_t index;  ///< its place in the order (pusher, length, heading)
    Eigen::Vector3d direction;
    double length;
    int pusher;
  };
  struct Found {
    WedgeStep step;
    std::size_t index;
  };
  std::optional<WedgeStep> find(const Pending& pending) const;
  static bool after(const Found& a, const Found& b);  ///< a comes after b (the heap's order)

  const PushChecker& checker_;
  const GraspPoseSpace& space_;
  const PoseGoal& region_;
  Pose from_, goal_;
  bool outside_;                  ///< from outside the tolerance box: a step may end the plan
  std::vector<Pending> pending_;  ///< roots not yet found, the least bound first
  std::size_t next_pending_ = 0;
  std::vector<Found> ending_;  ///< the steps that end the plan, in order (all found at once)
  std::size_t next_ending_ = 0;
  std::vector<Found> found_;  ///< the other steps found, a heap with the next on top
};

class TRRTstar : public ompl::base::Planner {
 public:
  explicit TRRTstar(const ompl::base::SpaceInformationPtr& si);
  ~TRRTstar() override;

  void setup() override;
  /// Grows the tree until `ptc` fires or the search is over (outcome()): EXACT_SOLUTION for
  /// GoalReached, APPROXIMATE_SOLUTION otherwise, INVALID_START (outcome InvalidStart) when no start
  /// is valid. A second call goes on growing the same tree; clear() starts anew.
  ompl::base::PlannerStatus solve(const ompl::base::PlannerTerminationCondition& ptc) override;
  /// Frees the tree and the last solve's results.
  void clear() override;
  /// Switch pushers only where the pads alone hold the object with `min_ratio` times its weight in
  /// every one of `models` (0: anywhere; PlannerSettings::min_transit_hold), `start_pusher` being
  /// the pusher in contact at the start (kNoPusher: none). Not a declared parameter: it needs the models.
  void set_transit_hold(ModelSet models, double min_ratio, int start_pusher);
  /// Whether a switch-over from pusher `leaving` may happen at q: the pads alone hold the object
  /// there with set_transit_hold's ratio in every one of its models (always, with ratio 0).
  bool pads_hold_transit(const Pose& q, int leaving) const;
  /// Whether the plan can end at the goal pose from `end`, pushed into by `pusher`, after
  /// `switches` switch-overs (planning.cpp's end of a plan: the straight push, a point pusher's two).
  using EndTest = std::function<bool(const Pose& end, int pusher, int switches)>;
  /// finish_toward_goal stops where `can_end` holds, the search's end included: a plan that ends at
  /// the goal pose without finish_steps is unchanged by them. Unset: where the straight push is stable.
  void set_end_test(EndTest can_end) { end_test_ = std::move(can_end); }
  void getPlannerData(ompl::base::PlannerData& data) const override;

  // Declared parameters (Planner::params()), settable by name from the task's planner section.
  // Each setter refuses a value outside its range in trrt_star_parameter_ranges()
  // (std::invalid_argument naming the parameter); integers arrive as 64-bit so that no value
  // wraps on its way in.
  void setGoalBias(double p) { goal_bias_ = checked("goal_bias", p); }
  double getGoalBias() const { return goal_bias_; }
  void setRewireRadius(double steps) { rewire_radius_ = checked("rewire_radius", steps); }
  double getRewireRadius() const { return rewire_radius_; }
  void setInitTemperature(double t) { init_temperature_ = checked("init_temperature", t); }
  double getInitTemperature() const { return init_temperature_; }
  void setTempChangeFactor(double f) { temp_change_factor_ = checked("temp_change_factor", f); }
  double getTempChangeFactor() const { return temp_change_factor_; }
  void setMaxTransitionFailures(long long n) {
    max_transition_failures_ = static_cast<unsigned>(checked("max_transition_failures", n));
  }
  long long getMaxTransitionFailures() const { return max_transition_failures_; }
  void setMaxSwitches(long long k) { max_switches_ = static_cast<int>(checked("max_switches", k)); }
  long long getMaxSwitches() const { return max_switches_; }
  /// Largest deviation from the straight step toward the goal tried when that step is not a
  /// stable push [deg]; 0 keeps to straight steps.
  void setSteerAngle(double degrees) { steer_angle_ = checked("steer_angle", degrees); }
  double getSteerAngle() const { return steer_angle_; }
  void setSeed(long long seed) { seed_ = static_cast<std::uint32_t>(checked("seed", seed)); }
  long long getSeed() const { return seed_; }
  /// 1: a descent whose straight step is not stable tries a turn about a pad's centre before the
  /// steered steps (pivot_toward_goal); 0 (the default): never.
  void setPivotSteps(long long on) { pivot_steps_ = checked("pivot_steps", static_cast<double>(on)) > 0.0; }
  long long getPivotSteps() const { return pivot_steps_ ? 1 : 0; }
  /// 1: once the goal is reached, the plan's last pusher goes on toward the goal pose itself
  /// (finish_toward_goal); 0 (the default): the plan ends at the first pose within the tolerance
  /// unless one straight push from there to the goal pose is stable.
  void setFinishSteps(long long on) { finish_steps_ = checked("finish_steps", static_cast<double>(on)) > 0.0; }
  long long getFinishSteps() const { return finish_steps_ ? 1 : 0; }
  /// How long to keep improving after the first plan [s] (0: stop at the first).
  void setImproveFor(double seconds) { improve_for_ = checked("improve_for", seconds); }
  double getImproveFor() const { return improve_for_; }
  /// Stable-push tests without a plan before the search starts again with fresh streams and twice
  /// the budget (0: never restart).
  void setRestartChecks(long long checks) {
    restart_checks_ = static_cast<std::uint64_t>(checked("restart_checks", static_cast<double>(checks)));
  }
  long long getRestartChecks() const { return static_cast<long long>(restart_checks_); }
  /// The stable-push tests a solve may make before it stops as at its time limit (0: no bound). A
  /// search bounded so answers the same on any machine: wall time is then only a guard.
  void setCheckLimit(long long checks) {
    check_limit_ = static_cast<std::uint64_t>(checked("check_limit", static_cast<double>(checks)));
  }
  long long getCheckLimit() const { return static_cast<long long>(check_limit_); }
  /// Whether the last solve stopped at check_limit (rather than at the caller's condition).
  bool check_limit_reached() const { return check_limit_reached_; }
  /// Restarts in the last solve.
  unsigned restarts() const { return restarts_; }

  // The last solve.
  PlanOutcome outcome() const { return outcome_; }
  /// The best path of the last solve, start first: to the cheapest goal node (after an
  /// improvement, the path choose_improved_path took), or, when the goal was not reached, to the
  /// node closest to the goal.
  std::vector<PathNode> solution() const;
  PathCost solution_cost() const;
  std::uint64_t iterations() const { return iterations_; }
  /// The first plan found: when [s since the solve began], its cost and its least margin [N];
  /// time < 0 when none was found. The margin is computed only with improve_for > 0 (else NaN).
  double first_solution_time() const { return first_time_; }
  PathCost first_solution_cost() const { return first_cost_; }
  double first_solution_margin() const { return first_margin_; }
  /// The least margin [N] over the unit pushes of the returned path (worst over the models).
  double solution_margin() const;
  std::size_t node_count() const { return nodes_.size(); }
  /// A node of the search tree as the planner holds it: its pose, the pusher of the push into it,
  /// its parent (an index into tree(); -1 at the root) and its cost from the root.
  struct TreeNode {
    Pose pose;
    int pusher = kNoPusher;
    int parent = -1;
    PathCost cost;
  };
  /// The tree of the last solve, the root first. Choose-parent and rewire keep each node's cost
  /// equal to its parent's plus its edge's: the edge's length in unit steps, and a switch-over when
  /// the pusher changes after the first push.
  std::vector<TreeNode> tree() const;
  double temperature() const { return temperature_; }

 private:
  struct Node;
  struct Candidate;
  struct Steering;

  void free_tree();
  /// A fresh tree at the start, the streams seeded from (seed, restarts_).
  void begin_attempt(const Pose& start);
  /// Connect q_new (stable from `from` by `stable`) through the cheapest near parent, rewire,
  /// and note a goal; returns the node added for pusher `prefer` if there is one, else the first.
  Node* connect(Node* from, const Pose& q_new, PusherSet stable, int prefer = kNoPusher);
  /// connect, for a step of descent `descent`, which goes on from the node returned (so no other
  /// descent starts there).
  Node* connect_descent(Node* from, const Pose& q_new, PusherSet stable, int prefer, int descent);
  /// Unit steps from `from` straight toward `target` while each is accepted (Algorithm 1).
  void extend(Node* from, const ompl::base::State* target, const ompl::base::PlannerTerminationCondition& ptc);
  /// A descent: unit steps from `from` toward the goal, each the straight step, else the last
  /// step's deviation, else the nearest deviation within steer_angle that a pusher allowed by the
  /// switch-over budget makes stable (the descent's own pusher tested first). It stops at a dead
  /// end, or where it meets a descent that ended in a dead end far from the goal.
  void extend_toward_goal(Node* from, const ompl::base::PlannerTerminationCondition& ptc);
  /// After the start's descent, for each pusher (not a point pusher) that its first step did not
  /// use and that cannot push within steer_angle of the way to the goal (a ledge that can only
  /// lift): the nearest stable step turned further, up to 90 deg (Steering's wide rings),
  /// repeated as a run with a descent from each of its nodes while those descents end nearer the
  /// goal. The first push costs no switch-over, so such a pusher may well start the plan, but
  /// descents never try it and random extensions find it only by chance.
  void descend_across(Node* root, const ompl::base::PlannerTerminationCondition& ptc);
  /// When no pusher makes the step from -> q stable: the step of the same length and heading onto
  /// the stable surface of a point pusher in `allowed` (StablePushValidator::onto_wedge_surface)
  /// that the grasp survives and that pusher makes stable. Sets q (and `scratch`) to it and returns
  /// that pusher; 0, q unchanged, when there is none.
  PusherSet onto_wedge(const Pose& from, Pose& q, PusherSet allowed, ompl::base::State* scratch) const;
  /// WedgeStepQueue's steps toward this problem's goal region (not yet checked for the grasp and
  /// facets). Those that end the plan come first: a surface rarely passes through the goal pose
  /// itself, and where its point nearest the goal pose is outside the tolerance box, a descent
  /// ranked by that distance alone stops there though the surface crosses the box.
  WedgeStepQueue wedge_step_queue(const Pose& from, const Pose& goal, const std::vector<double>& lengths,
                                  PusherSet wedges) const;
  /// All of wedge_step_queue's steps, in its order.
  std::vector<WedgeStep> wedge_steps(const Pose& from, const Pose& goal, const std::vector<double>& lengths,
                                     PusherSet wedges) const;
  /// The grasp survives `step` and its pusher makes it stable.
  bool wedge_step_valid(const Pose& from, const WedgeStep& step, ompl::base::State* scratch) const;
  /// Toward the goal when no straight or steered step is stable: the valid wedge step (wedge_step_queue)
  /// that ends the plan, or else ends nearest the goal if closer than `from`; where none does
  /// within two goal thresholds of the goal, the same among half and quarter steps; else, since
  /// one surface moves q in only two of three coordinates, the first of the best 8 valid steps
  /// from which a second valid wedge step ends the plan or ends closer. Sets q (and `scratch`) and
  /// returns that pusher; 0, q unchanged, when none.
  PusherSet descend_on_wedges(const Pose& from, const Pose& goal, double length, PusherSet allowed,
                              ompl::base::State* scratch, Pose& q) const;
  /// A point pusher's stable pushes from `at` as rays [unit steps]: the unit steps onto its surface
  /// (onto_wedge_surface, the root nearest no turn) at its wedge_step_headings (24 evenly spaced,
  /// and closely about its translation headings) that keep the grasp and are stable, in the order
  /// of their headings round the circle (nullopt where there is none).
  std::vector<std::optional<Eigen::Vector3d>> wedge_rays(const Pose& at, int pusher, ompl::base::State* scratch) const;
  /// A two-push way to the goal: the first pusher's push by `first_leg` [unit steps], then the
  /// second's to the goal; `length` is the two legs' [unit steps].
  struct Split {
    int first = kNoPusher;
    int second = kNoPusher;
    Eigen::Vector3d first_leg = Eigen::Vector3d::Zero();
    double length = 0.0;
  };
  /// Where a descent on point pushers' surfaces switches over. Two pushes reach the
  /// goal g from q when g - q = a + b, a in the cone of the first pusher's stable pushes at q and
  /// b in the second's (each cone spanned by two adjacent rays, wedge_rays; the surfaces taken as
  /// planes, which they are to first order; the second's rays first at g, then twice again where
  /// a ends). A greedy descent goes to the point of the
  /// first surface nearest g, which the second surface through g rarely passes through; q + a is
  /// on both. The shortest such pair (|a| + |b|, at most three times |g - q|, six after an odd
  /// number of restarts) with the first pusher in `first` and the second in `second`; nullopt when there is none.
  std::optional<Split> split_point(const Pose& q, PusherSet first, PusherSet second, ompl::base::State* scratch);
  /// From `from`, `split`'s first pusher steps along its first leg (found again after each step,
  /// as the surface turns with the object) until that leg is under half a step, a step is not
  /// stable, no split is found again, the budget is exceeded or the goal is reached; returns the
  /// last node. Steps of descent `descent`; no transition test, since the way to the switch-over
  /// may climb. Only before the first plan: walk_after_stall is not called once the goal is reached.
  Node* walk_to_split(Node* from, Split split, int descent, const ompl::base::PlannerTerminationCondition& ptc);
  /// Where a descent on point pushers' surfaces stalls, or is about to switch pushers because its
  /// own goes no nearer (extend_toward_goal), with a switch-over left: the split_point walk from
  /// `from` (walk_to_split), the first leg by its own pusher when `own_first` or when one
  /// switch-over is left, and at least one unit step long; `from` when there is none.
  Node* walk_after_stall(Node* from, bool own_first, int descent, const ompl::base::PlannerTerminationCondition& ptc);
  /// Toward the goal when no straight, steered or wedge step is stable: a turn about a pad's centre
  /// (PushChecker::pivot_points), the sticking case, by the rest of the goal's theta or as much of
  /// it as a unit step holds, its translation dq = -omega_cross(dtheta, P - o) so that the pad point
  /// at P does not slip. Sets q (and `scratch`) and returns the pushers that make it stable, the
  /// descent's own first; 0, q unchanged, when none does. A plan made to turn about a pad centre
  /// (the pivot) needs it once the object is off that centre: 0.01 mm off, no plan was found.
  /// Only with pivot_steps: tried before the steered steps, it changes plans that do not need it.
  PusherSet pivot_toward_goal(const Pose& from, const Pose& goal, PusherSet allowed, PusherSet own,
                              ompl::base::State* scratch, Pose& q) const;
  Node* add_node(const Pose& q, int pusher, Node* parent, const PathCost& cost);
  /// optimEdge: the cheapest stable connection to q_new among the near nodes; `via` is the node
  /// the extension came from, `via_pushers` the pushers stable along via -> q_new.
  Candidate choose_parent(const Pose& q_new, const std::vector<Node*>& near, Node* via, PusherSet via_pushers) const;
  void rewire(Node* node, const std::vector<Node*>& near);
  void shift_subtree_cost(Node* node, const PathCost& delta);
  bool transition_test(double cost_from, double cost_to, double step);
  /// The nodes within `radius` unit steps of q, nearest first.
  void near(const Pose& q, double radius, std::vector<Node*>& out) const;
  /// The node nearest to q among those within the switch-over budget (max_switches).
  Node* nearest_extendable(const Pose& q) const;
  /// Among the nodes within the budget not yet extended toward the goal, the one with the least
  /// cost plus distance to the goal; nullptr when there is none.
  Node* most_promising_toward_goal() const;
  void note_goal_candidate(Node* node);
  /// The goal node with the least cost (switch-overs, then length).
  Node* best_goal() const;
  /// Where the returned path ends: the best goal node, else the node closest to the goal (nullptr
  /// before the first solve).
  const Node* path_end() const;
  /// A goal node's path as it was when noted (rewiring may shorten a path later and lower its
  /// margin, so an improvement keeps the paths it saw), its cost and least margin [N].
  struct GoalPath {
    std::vector<PathNode> nodes;
    PathCost cost;
    double margin = 0.0;
  };
  GoalPath goal_path(const Node* node) const;
  /// The least margin over the unit pushes of a -> b by `pusher` [N].
  double edge_margin(const Pose& a, const Pose& b, int pusher) const;
  /// The least margin over the unit pushes of the path to `node` [N] (+inf at the root).
  double path_margin(const Node* node) const;
  /// After an improvement: improved_ = among the goal paths kept while improving and those of the
  /// goal nodes now, within the budget, the one with the fewest switch-overs, then the largest
  /// least margin, then the shortest.
  void choose_improved_path();
  /// With finish_steps, after the goal is reached: from the plan's end its last pusher takes, while
  /// one is found and the plan cannot end at the goal pose from there (set_end_test), the step that
  /// ends deepest in the tolerance box (PoseGoal::offset, by at least 0.001 of it), held there,
  /// in the grasp and a stable push, among full, half and quarter steps toward the goal turned up
  /// to 90 deg (for a point pusher, its wedge steps). No switch-over; the plan's length grows and
  /// its least margin may drop. A plan that ends at the edge of the tolerance leaves an open-loop
  /// run no room for the drift of a real push (docs/evaluate.md). Bounded in steps, not time.
  void finish_toward_goal();
  /// The anytime phase's end: true once a plan exists and improve_for [s] has passed since the first
  /// (at once when improve_for is 0). solve() ORs it with the caller's condition; the helpers that
  /// grow the tree take that combined condition as their `ptc`.
  ompl::base::PlannerTerminationCondition anytime_over() const;

  /// Of `pushers`, those that may push from `from`: all of them, unless using one other than the
  /// pusher in contact at `from` is a transit the pads do not hold there (set_transit_hold).
  PusherSet transit_allowed(const Node* from, PusherSet pushers) const;

  PushChecker* validator_ = nullptr;  ///< the motion validator, as what the search asks of it
  ModelSet transit_models_;           ///< set_transit_hold's models
  double min_transit_hold_ = 0.0;
  int start_pusher_ = kNoPusher;
  EndTest end_test_;  ///< set_end_test's
  const GraspPoseSpace* space_ = nullptr;
  std::vector<Node*> nodes_;
  std::vector<Eigen::Vector3d> unit_coords_;  ///< nodes_[i]'s pose in unit steps
  std::vector<Node*> goal_nodes_;
  std::vector<Node*> near_;  ///< scratch for near-node queries
  /// wedge_rays at the goal, per pusher (filled when first asked; cleared by a new solve).
  std::vector<std::optional<std::vector<std::optional<Eigen::Vector3d>>>> goal_rays_;
  /// Per descent (extend_toward_goal): the goal distance where it ended [unit steps]; -1 while it runs.
  std::vector<double> descent_ends_;
  /// `value` if it lies in `name`'s declared range, else std::invalid_argument.
  static double checked(const char* name, double value);

  Node* closest_ = nullptr;
  std::unique_ptr<ompl::RNG> rng_;
  ompl::base::StateSamplerPtr sampler_;

  double goal_bias_ = 0.2;
  double rewire_radius_ = 2.0;
  double init_temperature_ = 0.1;
  double temp_change_factor_ = 2.0;
  double steer_angle_ = 45.0;
  unsigned max_transition_failures_ = 10;
  int max_switches_ = 1;
  std::uint32_t seed_ = 1;
  double improve_for_ = 0.0;
  bool pivot_steps_ = false;
  bool finish_steps_ = false;
  std::uint64_t restart_checks_ = 5000;
  std::uint64_t check_limit_ = 0;
  bool check_limit_reached_ = false;
  unsigned restarts_ = 0;

  double temperature_ = 0.0;
  unsigned transition_failures_ = 0;
  std::uint64_t iterations_ = 0;
  PlanOutcome outcome_ = PlanOutcome::TimeLimit;
  std::chrono::steady_clock::time_point solve_started_;
  double first_time_ = -1.0;
  PathCost first_cost_;
  double first_margin_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<GoalPath> kept_paths_;  ///< goal paths seen while improving
  std::optional<GoalPath> improved_;  ///< the path returned when not the best goal node's own
};

}  // namespace stablepush
