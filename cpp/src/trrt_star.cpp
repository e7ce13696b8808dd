#include "stablepush/internal/trrt_star.hpp"

#include <ompl/base/PlannerData.h>
#include <ompl/base/goals/GoalSampleableRegion.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/util/Exception.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace stablepush {

namespace ob = ompl::base;

struct TRRTstar::Node {
  ob::State* state = nullptr;
  Pose pose;
  int pusher = kNoPusher;  ///< the pusher of the push into this node
  Node* parent = nullptr;
  std::vector<Node*> children;
  PathCost cost;
  double goal_distance = 0.0;     ///< T-RRT configuration cost [unit steps]
  bool extended_to_goal = false;  ///< a goal sample has already been extended from here
  int descent = -1;               ///< the descent that made this node or started from it (index into descent_ends_)
};

/// A way to connect a new pose: from `parent`, at `cost`, by any pusher of `pushers`.
struct TRRTstar::Candidate {
  Node* parent = nullptr;
  PathCost cost;
  PusherSet pushers = 0;
};

const std::map<std::string, ParameterRange>& trrt_star_parameter_ranges() {
  static const std::map<std::string, ParameterRange> ranges{
      {"goal_bias", {false, 0.0, 1.0}},           // probability of sampling the goal
      {"rewire_radius", {false, 0.0, 100.0}},     // [unit steps]
      {"init_temperature", {false, 1e-12, 1e6}},  // T-RRT's first temperature
      {"temp_change_factor", {false, 1.0, 1e3}}, {"max_transition_failures", {true, 1.0, 1e6}},
      {"max_switches", {true, 0.0, 100.0}},   // switch-overs a plan may make
      {"steer_angle", {false, 0.0, 90.0}},    // [deg]
      {"seed", {true, 0.0, 4294967295.0}},    // 0 .. 2^32 - 1
      {"improve_for", {false, 0.0, 1e6}},     // [s] after the first plan
      {"restart_checks", {true, 0.0, 1e12}},  // stable-push tests before a restart (0: never)
  };
  return ranges;
}

double TRRTstar::checked(const char* name, double value) {
  const ParameterRange& range = trrt_star_parameter_ranges().at(name);
  if (!(value >= range.lowest && value <= range.highest)) {  // also refuses NaN
    std::ostringstream msg;
    msg << "planner parameter '" << name << "' must be between " << range.lowest << " and " << range.highest << ", got "
        << value;
    throw std::invalid_argument(msg.str());
  }
  return value;
}

namespace {
/// OMPL's range suggestion "lowest:step:highest" for a declared parameter.
std::string range_text(const char* name) {
  const ParameterRange& r = trrt_star_parameter_ranges().at(name);
  std::ostringstream out;
  out << std::setprecision(10) << r.lowest << ':' << (r.integer ? 1.0 : (r.highest - r.lowest) / 20.0) << ':'
      << r.highest;
  return out.str();
}

/// Edges shorter than this [unit steps] are not pushes (co-located nodes differ only by pusher),
/// and a descent this near the goal is there.
constexpr double kMinEdge = GraspPoseSpace::kShortestPush;

PusherSet single(int pusher) { return pusher < 0 ? 0u : (1u << pusher); }
}  // namespace

/// The unit steps a descent tries from `from`: turn 0 goes straight toward the goal; turn
/// ring * 8 + k turns from it toward the k-th of eight directions square to the way to the goal,
/// by ring / kRings of steer_angle for rings 1..kRings, and on from steer_angle evenly to 90 deg
/// for the wide rings kRings + 1 .. 2 kRings (the start's first steps across, descend_across).
struct TRRTstar::Steering {
  static constexpr int kRings = 4;

  Steering(const GraspPoseSpace& space, double steer_angle_deg, const Pose& from, const Pose& goal)
      : space(space), steer_angle_deg(steer_angle_deg), from(from) {
    const Eigen::Vector3d to_goal = space.in_unit_steps(goal - from);
    distance = to_goal.norm();
    length = std::min(1.0, distance);
    if (distance < kMinEdge) return;
    u = to_goal / distance;
    // Two directions square to u, from the coordinate axis least aligned with it.
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    Eigen::Index least;
    u.cwiseAbs().minCoeff(&least);
    axis[least] = 1.0;
    e1 = u.cross(axis).normalized();
    e2 = u.cross(e1);
  }

  /// The last ring a descent tries: kRings (none when steer_angle is 0).
  int rings() const { return steer_angle_deg > 0.0 ? kRings : 0; }

  Pose step(int turn) const {
    const int ring = turn / 8;
    const double alpha_deg = ring <= kRings ? steer_angle_deg * ring / kRings
                                            : steer_angle_deg + (90.0 - steer_angle_deg) * (ring - kRings) / kRings;
    const double alpha = alpha_deg * M_PI / 180.0, phi = 2.0 * M_PI * (turn % 8) / 8.0;
    const Eigen::Vector3d dir = std::cos(alpha) * u + std::sin(alpha) * (std::cos(phi) * e1 + std::sin(phi) * e2);
    return from + space.from_unit_steps(length * dir);
  }

  const GraspPoseSpace& space;
  double steer_angle_deg;
  Pose from;
  double distance = 0.0;  ///< to the goal [unit steps]
  double length = 0.0;    ///< of a step [unit steps]: 1, or what is left
  Eigen::Vector3d u = Eigen::Vector3d::Zero(), e1 = Eigen::Vector3d::Zero(), e2 = Eigen::Vector3d::Zero();
};

TRRTstar::TRRTstar(const ob::SpaceInformationPtr& si) : ob::Planner(si, "TRRTstar") {
  specs_.approximateSolutions = true;
  specs_.optimizingPaths = true;
  specs_.directed = true;
  declareParam<double>("goal_bias", this, &TRRTstar::setGoalBias, &TRRTstar::getGoalBias, range_text("goal_bias"));
  declareParam<double>("rewire_radius", this, &TRRTstar::setRewireRadius, &TRRTstar::getRewireRadius,
                       range_text("rewire_radius"));
  declareParam<double>("init_temperature", this, &TRRTstar::setInitTemperature, &TRRTstar::getInitTemperature,
                       range_text("init_temperature"));
  declareParam<double>("temp_change_factor", this, &TRRTstar::setTempChangeFactor, &TRRTstar::getTempChangeFactor,
                       range_text("temp_change_factor"));
  declareParam<long long>("max_transition_failures", this, &TRRTstar::setMaxTransitionFailures,
                          &TRRTstar::getMaxTransitionFailures, range_text("max_transition_failures"));
  declareParam<long long>("max_switches", this, &TRRTstar::setMaxSwitches, &TRRTstar::getMaxSwitches,
                          range_text("max_switches"));
  declareParam<double>("steer_angle", this, &TRRTstar::setSteerAngle, &TRRTstar::getSteerAngle,
                       range_text("steer_angle"));
  declareParam<long long>("seed", this, &TRRTstar::setSeed, &TRRTstar::getSeed, range_text("seed"));
  declareParam<double>("improve_for", this, &TRRTstar::setImproveFor, &TRRTstar::getImproveFor,
                       range_text("improve_for"));
  declareParam<long long>("restart_checks", this, &TRRTstar::setRestartChecks, &TRRTstar::getRestartChecks,
                          range_text("restart_checks"));
}

TRRTstar::~TRRTstar() { free_tree(); }

void TRRTstar::setup() {
  ob::Planner::setup();
  space_ = dynamic_cast<const GraspPoseSpace*>(si_->getStateSpace().get());
  validator_ = dynamic_cast<PushChecker*>(si_->getMotionValidator().get());
  if (space_ == nullptr || validator_ == nullptr)
    throw ompl::Exception(getName(), "needs a GraspPoseSpace and a motion validator that is a PushChecker");
}

void TRRTstar::free_tree() {
  for (Node* n : nodes_) {
    si_->freeState(n->state);
    delete n;
  }
  nodes_.clear();
  goal_nodes_.clear();
  closest_ = nullptr;
  kept_paths_.clear();
  improved_.reset();
  unit_coords_.clear();
  descent_ends_.clear();
}

void TRRTstar::clear() {
  ob::Planner::clear();
  free_tree();
  iterations_ = 0;
  solve_started_ = std::chrono::steady_clock::now();
  first_time_ = -1.0;
  first_cost_ = PathCost{};
  first_margin_ = std::numeric_limits<double>::quiet_NaN();
  outcome_ = PlanOutcome::TimeLimit;
}

TRRTstar::Node* TRRTstar::add_node(const Pose& q, int pusher, Node* parent, const PathCost& cost) {
  auto* node = new Node;
  node->state = si_->allocState();
  GraspPoseSpace::set_pose(node->state, q);
  node->pose = q;
  node->pusher = pusher;
  node->parent = parent;
  node->cost = cost;
  const auto* goal = pdef_->getGoal()->as<ob::GoalRegion>();
  node->goal_distance = goal->distanceGoal(node->state);
  if (parent != nullptr) parent->children.push_back(node);
  nodes_.push_back(node);
  unit_coords_.push_back(space_->in_unit_steps(q));
  if (nodes_.size() == 1) min_goal_distance_ = max_goal_distance_ = node->goal_distance;
  min_goal_distance_ = std::min(min_goal_distance_, node->goal_distance);
  max_goal_distance_ = std::max(max_goal_distance_, node->goal_distance);
  return node;
}

bool TRRTstar::transition_test(double cost_from, double cost_to, double step) {
  if (cost_to <= cost_from) return true;  // downhill toward the goal: always
  const double slope = (cost_to - cost_from) / step;
  if (rng_->uniform01() < std::exp(-slope / temperature_)) {
    temperature_ /= temp_change_factor_;  // an accepted climb cools the search
    transition_failures_ = 0;
    return true;
  }
  if (++transition_failures_ >= max_transition_failures_) {  // stuck below climbs: heat up
    temperature_ *= temp_change_factor_;
    transition_failures_ = 0;
  }
  return false;
}

// Neighbour queries scan the nodes' coordinates in unit steps, kept contiguous: exact, and
// deterministic (ties go to the older node). Tree sizes here are thousands of nodes, where a
// tight linear scan beats tree structures; OMPL's GNAT would also draw its pivots from OMPL's
// global seed and make plans depend on the process's history.
void TRRTstar::near(const Pose& q, double radius, std::vector<Node*>& out) const {
  const Eigen::Vector3d u = space_->in_unit_steps(q);
  const double r2 = radius * radius;
  std::vector<std::pair<double, std::size_t>> hits;
  for (std::size_t i = 0; i < unit_coords_.size(); ++i) {
    const double d2 = (unit_coords_[i] - u).squaredNorm();
    if (d2 <= r2) hits.emplace_back(d2, i);
  }
  std::stable_sort(hits.begin(), hits.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  out.clear();
  for (const auto& hit : hits) out.push_back(nodes_[hit.second]);
}

TRRTstar::Node* TRRTstar::nearest_extendable(const Pose& q) const {
  const Eigen::Vector3d u = space_->in_unit_steps(q);
  Node* best = nullptr;
  double best_d2 = 0.0;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const double d2 = (unit_coords_[i] - u).squaredNorm();
    // The coordinates are contiguous, the nodes are not: look at a node only when it would be nearer.
    if (best != nullptr && !(d2 < best_d2)) continue;
    if (nodes_[i]->cost.switches > max_switches_) continue;
    best = nodes_[i];
    best_d2 = d2;
  }
  return best;
}

TRRTstar::Node* TRRTstar::most_promising_toward_goal() const {
  Node* best = nullptr;
  PathCost best_estimate;
  for (Node* n : nodes_) {
    if (n->extended_to_goal || n->cost.switches > max_switches_) continue;
    const PathCost estimate = n->cost + PathCost{0, n->goal_distance};
    if (best == nullptr || estimate < best_estimate) {
      best = n;
      best_estimate = estimate;
    }
  }
  return best;
}

TRRTstar::Candidate TRRTstar::choose_parent(const Pose& q_new, const std::vector<Node*>& near, Node* via,
                                            PusherSet via_pushers) const {
  // Near nodes in order of their cost if no switch-over were needed: a candidate cannot do
  // better than that, so the scan stops at the first one that cannot beat the best found.
  struct Option {
    Node* node;
    double distance;
    PathCost optimistic;
  };
  std::vector<Option> options;
  options.reserve(near.size() + 1);
  bool via_listed = false;
  for (Node* m : near) {
    const double d = space_->distance(m->pose, q_new);
    if (d < kMinEdge) continue;
    options.push_back({m, d, m->cost + PathCost{0, d}});
    via_listed = via_listed || m == via;
  }
  if (!via_listed) {
    const double d = space_->distance(via->pose, q_new);
    options.push_back({via, d, via->cost + PathCost{0, d}});
  }
  std::stable_sort(options.begin(), options.end(),
                   [](const Option& a, const Option& b) { return a.optimistic < b.optimistic; });

  Candidate best;
  for (const Option& o : options) {
    if (best.parent != nullptr && !(o.optimistic < best.cost)) break;
    Node* m = o.node;
    const PusherSet all = validator_->all_pushers();
    PusherSet stable;
    if (m == via) {
      stable = via_pushers;
    } else if (m->pusher != kNoPusher) {
      // The parent's own pusher first: if it works there is no switch-over to pay.
      stable = validator_->stable_pushers(m->pose, q_new, single(m->pusher));
      if (stable == 0 && (best.parent == nullptr || m->cost + PathCost{1, o.distance} < best.cost))
        stable = validator_->stable_pushers(m->pose, q_new, all & ~single(m->pusher));
    } else {
      stable = validator_->stable_pushers(m->pose, q_new, all);
    }
    if (stable == 0) continue;
    Candidate c;
    c.parent = m;
    if (m->pusher == kNoPusher) {  // the first push is not a switch-over
      c.cost = o.optimistic;
      c.pushers = stable;
    } else if (contains(stable, m->pusher)) {
      c.cost = o.optimistic;
      c.pushers = single(m->pusher);
    } else {
      c.cost = m->cost + PathCost{1, o.distance};
      c.pushers = stable;
    }
    if (best.parent == nullptr || c.cost < best.cost) best = c;
  }
  return best;
}

void TRRTstar::shift_subtree_cost(Node* node, const PathCost& delta) {
  std::vector<Node*> stack{node};
  while (!stack.empty()) {
    Node* n = stack.back();
    stack.pop_back();
    n->cost = n->cost + delta;
    stack.insert(stack.end(), n->children.begin(), n->children.end());
  }
}

void TRRTstar::rewire(Node* node, const std::vector<Node*>& near) {
  for (Node* m : near) {
    if (m == node->parent || m->parent == nullptr) continue;
    const double d = si_->distance(node->state, m->state);
    if (d < kMinEdge) continue;
    const int switches = node->pusher != m->pusher ? 1 : 0;
    const PathCost via = node->cost + PathCost{switches, d};
    if (!(via < m->cost)) continue;
    // m keeps its pusher, so the costs below m stay exact; only the push into m is new.
    if (validator_->stable_pushers(node->pose, m->pose, single(m->pusher)) == 0) continue;
    auto& siblings = m->parent->children;
    siblings.erase(std::find(siblings.begin(), siblings.end(), m));
    m->parent = node;
    node->children.push_back(m);
    shift_subtree_cost(m, via - m->cost);
  }
}

void TRRTstar::note_goal_candidate(Node* node) {
  const auto* goal = pdef_->getGoal()->as<PoseGoal>();
  if (goal->isSatisfied(node->state) && goal->held(node->pose, node->pusher)) {
    goal_nodes_.push_back(node);
    // While improving, keep the path as it is now: a later rewiring may trade its margin for length.
    if (outcome_ == PlanOutcome::GoalReached && improve_for_ > 0.0 && node->cost.switches <= max_switches_ &&
        node->cost.switches <= best_goal()->cost.switches)
      kept_paths_.push_back(goal_path(node));
  }
  if (closest_ == nullptr || node->goal_distance < closest_->goal_distance ||
      (node->goal_distance == closest_->goal_distance && node->cost < closest_->cost))
    closest_ = node;
}

TRRTstar::Node* TRRTstar::best_goal() const {
  Node* best = nullptr;
  for (Node* g : goal_nodes_)
    if (best == nullptr || g->cost < best->cost) best = g;
  return best;
}

PusherSet TRRTstar::onto_wedge(const Pose& from, Pose& q, PusherSet allowed, ob::State* scratch) const {
  const PusherSet wedges = allowed & validator_->wedge_pushers();
  if (wedges == 0) return 0;
  const Eigen::Vector3d step = space_->in_unit_steps(q - from);
  const double length = step.norm();
  if (!(length > 0.0)) return 0;
  for (int p = 0; p < kMaxPushers; ++p) {
    if (!contains(wedges, p)) continue;
    const std::optional<Pose> on_surface = validator_->onto_wedge_surface(from, step / length, length, p);
    if (on_surface && wedge_step_valid(from, WedgeStep{0.0, *on_surface, p}, scratch)) {
      q = *on_surface;
      return PusherSet{1} << p;
    }
  }
  GraspPoseSpace::set_pose(scratch, q);
  return 0;
}

std::vector<TRRTstar::WedgeStep> TRRTstar::wedge_steps(const Pose& from, const Pose& goal, double length,
                                                       PusherSet wedges) const {
  const Eigen::Vector3d to_goal = space_->in_unit_steps(goal - from);
  const double heading = std::atan2(to_goal[1], to_goal[0]);
  const double translation = std::max(std::hypot(to_goal[0], to_goal[1]), 1e-3);
  std::vector<WedgeStep> steps;
  constexpr int kHeadings = 24;
  for (int p = 0; p < kMaxPushers; ++p) {
    if (!contains(wedges, p)) continue;
    for (int k = 0; k < kHeadings; ++k) {
      const double psi = heading + 2.0 * M_PI * k / kHeadings;
      // The goal's elevation picks the root nearest to it.
      const Eigen::Vector3d direction(std::cos(psi) * translation, std::sin(psi) * translation, to_goal[2]);
      const std::optional<Pose> on_surface = validator_->onto_wedge_surface(from, direction.normalized(), length, p);
      if (on_surface) steps.push_back({space_->distance(*on_surface, goal), *on_surface, p});
    }
  }
  std::sort(steps.begin(), steps.end(),
            [](const WedgeStep& a, const WedgeStep& b) { return a.goal_distance < b.goal_distance; });
  return steps;
}

bool TRRTstar::wedge_step_valid(const Pose& from, const WedgeStep& step, ob::State* scratch) const {
  GraspPoseSpace::set_pose(scratch, step.pose);
  return si_->isValid(scratch) && validator_->stable_pushers(from, step.pose, PusherSet{1} << step.pusher) != 0;
}

PusherSet TRRTstar::descend_on_wedges(const Pose& from, const Pose& goal, double length, PusherSet allowed,
                                      ob::State* scratch, Pose& q) const {
  const PusherSet wedges = allowed & validator_->wedge_pushers();
  if (wedges == 0) return 0;
  const double now = space_->distance(from, goal);
  const std::vector<WedgeStep> steps = wedge_steps(from, goal, length, wedges);
  const auto take = [&](const WedgeStep& step) {
    q = step.pose;
    GraspPoseSpace::set_pose(scratch, q);
    return PusherSet{1} << step.pusher;
  };
  std::vector<const WedgeStep*> valid;
  for (const WedgeStep& step : steps) {
    if (!wedge_step_valid(from, step, scratch)) continue;
    if (step.goal_distance < now) return take(step);
    valid.push_back(&step);
  }
  // A local minimum of one step: one surface alone moves q in two of its three coordinates, so
  // look two steps ahead (the second on any point pusher's surface) from the best first steps.
  constexpr std::size_t kFirstSteps = 8;
  for (std::size_t i = 0; i < std::min(valid.size(), kFirstSteps); ++i) {
    const double next_length = std::min(1.0, valid[i]->goal_distance);
    for (const WedgeStep& second : wedge_steps(valid[i]->pose, goal, next_length, validator_->wedge_pushers())) {
      if (second.goal_distance >= now) break;
      if (wedge_step_valid(valid[i]->pose, second, scratch)) return take(*valid[i]);
    }
  }
  GraspPoseSpace::set_pose(scratch, q);
  return 0;
}

TRRTstar::Node* TRRTstar::connect(Node* from, const Pose& q_new, PusherSet stable, int prefer) {
  near(q_new, rewire_radius_, near_);
  const Candidate best = choose_parent(q_new, near_, from, stable);
  // One node per pusher that can make the push when it starts a new contact (or is the first
  // push), so that any of them can be continued without a further switch-over.
  Node* first = nullptr;
  for (int p = 0; p < kMaxPushers; ++p) {
    if (!contains(best.pushers, p)) continue;
    Node* node = add_node(q_new, p, best.parent, best.cost);
    rewire(node, near_);
    note_goal_candidate(node);
    if (first == nullptr || p == prefer) first = node;
  }
  const Node* reached = best_goal();
  if (reached != nullptr && reached->cost.switches <= max_switches_ && outcome_ != PlanOutcome::GoalReached) {
    outcome_ = PlanOutcome::GoalReached;
    first_time_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_started_).count();
    first_cost_ = reached->cost;
    if (improve_for_ > 0.0) {  // margins cost a test per push: only an improvement needs them
      first_margin_ = path_margin(reached);
      for (const Node* g : goal_nodes_)  // the goal paths as they are now, the first plan's among them
        if (g->cost.switches <= max_switches_) kept_paths_.push_back(goal_path(g));
    }
  }
  return first;
}

void TRRTstar::extend(Node* from, const ob::State* target, const ob::PlannerTerminationCondition& ptc) {
  // Algorithm 1's inner loop: unit steps toward the target while each is accepted.
  const auto* goal = pdef_->getGoal()->as<ob::GoalRegion>();
  ob::State* step_state = si_->allocState();
  while (!finished(ptc)) {
    const double d = si_->distance(from->state, target);
    if (d < kMinEdge) break;
    const bool last = d <= 1.0;
    if (last)
      si_->copyState(step_state, target);
    else
      si_->getStateSpace()->interpolate(from->state, target, 1.0 / d, step_state);
    const double step = last ? d : si_->distance(from->state, step_state);
    if (!transition_test(from->goal_distance, goal->distanceGoal(step_state), step)) break;
    if (!si_->isValid(step_state)) break;  // the grasp is lost at the new pose
    Pose q_new = GraspPoseSpace::pose(step_state);
    PusherSet stable = validator_->stable_pushers(from->pose, q_new, validator_->all_pushers());
    if (stable == 0 && (stable = onto_wedge(from->pose, q_new, validator_->all_pushers(), step_state)) != 0 &&
        !transition_test(from->goal_distance, goal->distanceGoal(step_state), step))
      break;
    if (stable == 0) break;
    Node* next = connect(from, q_new, stable);
    if (last || next->cost.switches > max_switches_) break;
    from = next;
  }
  si_->freeState(step_state);
}

void TRRTstar::extend_toward_goal(Node* from, const ob::PlannerTerminationCondition& ptc) {
  const Pose goal = pdef_->getGoal()->as<PoseGoal>()->pose();
  ob::State* step_state = si_->allocState();
  int turn = 0;  // the last step's deviation (Steering; 0: none)
  const int descent = static_cast<int>(descent_ends_.size());
  descent_ends_.push_back(-1.0);
  if (from->descent < 0) from->descent = descent;
  // Where this descent meets one that ended in a dead end well away from the goal (a node of it
  // within half a step, with the same pusher and no more switch-overs), the rest would retrace
  // it. Descents that ended near the goal are not cut short: there the last steps decide, and
  // descents from nearby starts end differently.
  const double far = 2.0 * pdef_->getGoal()->as<ob::GoalRegion>()->getThreshold();
  const auto retraces = [&](const Node* m, const Node* next) {
    return m != next && m->descent >= 0 && descent_ends_[m->descent] > far && m->pusher == next->pusher &&
           m->cost.switches <= next->cost.switches && space_->distance(m->pose, next->pose) < 0.5;
  };
  while (!finished(ptc)) {
    const Steering steering(*space_, steer_angle_, from->pose, goal);
    if (steering.distance < kMinEdge) break;
    const double length = steering.length;
    // Pushers this node may use without exceeding the switch-over budget.
    const PusherSet allowed = from->pusher == kNoPusher || from->cost.switches < max_switches_
                                  ? validator_->all_pushers()
                                  : single(from->pusher);
    // The step toward the goal, or a deviation from it within steer_angle (Steering) that an
    // allowed pusher makes stable, the descent's own pusher tested first (it costs no switch-over,
    // and when it works the others need no test). After the straight step (and a point pusher's
    // surface), the last step's deviation comes first, since a steered descent tends to keep its
    // turn; then the rings, nearest first.
    const PusherSet own = from->pusher == kNoPusher ? 0 : single(from->pusher);
    const auto try_direction = [&](int turn, Pose& q) -> PusherSet {
      q = steering.step(turn);
      GraspPoseSpace::set_pose(step_state, q);
      return si_->isValid(step_state) ? validator_->stable_pushers_preferring(from->pose, q, allowed, own) : 0;
    };
    Pose q_new;
    int turn_taken = 0;  // ring * 8 + k of the step taken (0: straight, or onto a surface)
    PusherSet stable = try_direction(0, q_new);
    // A point pusher's stable pushes are a surface: the step on it that brings q nearest the goal.
    if (stable == 0) stable = descend_on_wedges(from->pose, goal, length, allowed, step_state, q_new);
    if (stable == 0 && turn > 0 && (stable = try_direction(turn, q_new)) != 0) turn_taken = turn;
    for (int t = 8; t < 8 * (steering.rings() + 1) && stable == 0; ++t)
      if (t != turn && (stable = try_direction(t, q_new)) != 0) turn_taken = t;
    if (stable == 0) break;
    if (!transition_test(from->goal_distance, pdef_->getGoal()->as<ob::GoalRegion>()->distanceGoal(step_state), length))
      break;
    // Go on with the same pusher where it can (no switch-over); the nodes of the other pushers at
    // q_new stay candidates for descents of their own, which start each pusher's straight way in.
    Node* next = connect(from, q_new, stable, from->pusher);
    next->extended_to_goal = true;  // this descent goes on from it
    next->descent = descent;
    if (next->cost.switches > max_switches_) break;
    from = next;
    // connect left q_new's near nodes in near_.
    if (std::any_of(near_.begin(), near_.end(), [&](const Node* m) { return retraces(m, next); })) break;
    turn = turn_taken;
  }
  descent_ends_[descent] = from->goal_distance;
  si_->freeState(step_state);
}

void TRRTstar::descend_across(Node* root, const ob::PlannerTerminationCondition& ptc) {
  const auto* goal = pdef_->getGoal()->as<PoseGoal>();
  const Steering steering(*space_, steer_angle_, root->pose, goal->pose());
  if (steering.distance < kMinEdge || steering.rings() == 0) return;
  // A point pusher's stable pushes are a surface that no ring meets (descend_on_wedges steers
  // onto it instead).
  PusherSet across = validator_->all_pushers() & ~validator_->wedge_pushers();
  for (const Node* child : root->children) across &= ~single(child->pusher);
  // The candidates are tested together at each direction, sharing its motion wrench.
  ob::State* scratch = si_->allocState();
  const auto stable_at = [&](int turn, PusherSet candidates) -> PusherSet {
    const Pose q = steering.step(turn);
    GraspPoseSpace::set_pose(scratch, q);
    return si_->isValid(scratch) ? validator_->stable_pushers(root->pose, q, candidates) : 0;
  };
  const int within = 8 * (steering.rings() + 1), wide = 8 * (2 * Steering::kRings + 1);
  for (int turn = 0; turn < within && across != 0; turn = turn == 0 ? 8 : turn + 1) across &= ~stable_at(turn, across);
  // Each such pusher's first steps: every stable direction of the nearest wide ring where it has
  // one. All of them, since they tie (at 90 deg, lifting and turning the object are equally far
  // from the goal) and only the descents after them tell which leads there.
  std::array<std::vector<int>, kMaxPushers> first_turns;
  for (int ring = within; ring < wide && across != 0; ring += 8) {
    PusherSet in_ring = 0;
    for (int turn = ring; turn < ring + 8; ++turn) {
      const PusherSet stable = stable_at(turn, across);
      for (int p = 0; p < kMaxPushers; ++p)
        if (contains(stable, p)) first_turns[p].push_back(turn);
      in_ring |= stable;
    }
    across &= ~in_ring;
  }
  // Each first step is repeated (a run across, no longer than the way to the goal), with a
  // descent from every node of the run, while the descents end nearer the goal than the one
  // before. The run is a deliberate climb, so the transition test does not judge it; its pusher
  // and the grasp bound it.
  const int longest_run = static_cast<int>(std::ceil(steering.distance));
  for (int p = 0; p < kMaxPushers; ++p) {
    for (const int first_turn : first_turns[p]) {
      if (finished(ptc)) break;
      const Pose first = steering.step(first_turn);
      const Motion dq = first - root->pose;
      Node* node = root;
      double previous_end = std::numeric_limits<double>::infinity();  // [unit steps from the goal]
      for (int k = 0; k < longest_run && !finished(ptc); ++k) {
        const Pose q = node->pose + dq;
        GraspPoseSpace::set_pose(scratch, q);
        // The first step is the probe's, already tested.
        if (k > 0 && !(si_->isValid(scratch) && validator_->stable_pushers(node->pose, q, single(p)) != 0)) break;
        node = connect(node, q, single(p), p);
        node->extended_to_goal = true;  // its descent is made here
        extend_toward_goal(node, ptc);
        if (!(descent_ends_.back() < previous_end)) break;
        previous_end = descent_ends_.back();
      }
    }
  }
  si_->freeState(scratch);
}

ob::PlannerStatus TRRTstar::solve(const ob::PlannerTerminationCondition& ptc) {
  checkValidity();
  auto* goal = dynamic_cast<PoseGoal*>(pdef_->getGoal().get());
  if (goal == nullptr) throw ompl::Exception(getName(), "needs a PoseGoal");
  // OMPL hands each start state out once: a second solve finds none and goes on growing the tree of
  // the first (OMPL's contract; clear() starts anew). No start and no tree: the start is invalid.
  const ob::State* start = pis_.nextStart();
  if (start == nullptr && nodes_.empty()) {  // the pads do not hold the object at the start
    outcome_ = PlanOutcome::InvalidStart;
    return ob::PlannerStatus::INVALID_START;
  }
  const bool resume = start == nullptr;
  const Pose start_pose = resume ? nodes_.front()->pose : GraspPoseSpace::pose(start);
  solve_started_ = std::chrono::steady_clock::now();
  if (!resume) {
    iterations_ = 0;
    restarts_ = 0;
    first_time_ = -1.0;
    first_cost_ = PathCost{};
    first_margin_ = std::numeric_limits<double>::quiet_NaN();
    validator_->reset_feasibility_checks();
    begin_attempt(start_pose);
  }

  // Restarts against the long tail (restart_checks): a search that has made that many stable-push
  // tests without a plan starts again from the start with fresh streams and twice the budget, so
  // a seed whose first descents die where the chosen pusher cannot go on does not search there
  // for long; doubling keeps it complete. Counted in tests, not seconds, so a seed's plan is the
  // same on any machine.
  std::uint64_t budget = restart_checks_, attempt_began = validator_->feasibility_checks();

  ob::State* sample = si_->allocState();
  while (!finished(ptc)) {
    if (budget > 0 && outcome_ != PlanOutcome::GoalReached &&
        validator_->feasibility_checks() - attempt_began >= budget) {
      ++restarts_;
      begin_attempt(start_pose);
      attempt_began = validator_->feasibility_checks();
      budget = budget > (std::numeric_limits<std::uint64_t>::max() >> 1) ? budget : 2 * budget;
    }
    ++iterations_;
    // A goal sample extends from the node that promises the cheapest plan, cost so far plus
    // the straight distance left (an A* estimate), among those not yet extended toward the
    // goal: the steps of such an extension all go downhill, so the transition test passes them
    // and the mechanics alone decide how far it gets; a second try would repeat the first.
    Node* from = nullptr;
    if (rng_->uniform01() < goal_bias_ && (from = most_promising_toward_goal()) != nullptr) {
      from->extended_to_goal = true;
      extend_toward_goal(from, ptc);
      if (from->parent == nullptr && !finished(ptc)) descend_across(from, ptc);
    } else {
      sampler_->sampleUniform(sample);
      extend(nearest_extendable(GraspPoseSpace::pose(sample)), sample, ptc);
    }
  }
  si_->freeState(sample);

  if (outcome_ != PlanOutcome::GoalReached)
    outcome_ = best_goal() != nullptr ? PlanOutcome::GoalOverSwitchLimit : PlanOutcome::TimeLimit;
  else if (improve_for_ > 0.0)
    choose_improved_path();
  auto path = std::make_shared<ompl::geometric::PathGeometric>(si_);
  for (const PathNode& n : solution()) {
    ob::State* s = si_->allocState();
    GraspPoseSpace::set_pose(s, n.pose);
    path->append(s);
    si_->freeState(s);
  }
  const bool exact = outcome_ == PlanOutcome::GoalReached;
  const Node* end = path_end();
  pdef_->addSolutionPath(path, !exact, exact ? 0.0 : end->goal_distance, getName());
  return {true, !exact};
}

void TRRTstar::begin_attempt(const Pose& start) {
  free_tree();
  // Two 32-bit streams per seed, one-to-one over all 2^32 seeds (the generators keep 32 bits):
  // the sampler's is 2 seed for seed < 2^31 (as it always was) and odd above; the search's the
  // other parity. A restart draws its seed from (seed, restart) by SplitMix64.
  std::uint32_t seed = seed_;
  if (restarts_ > 0) {
    std::uint64_t z = (static_cast<std::uint64_t>(seed_) << 32 | restarts_) + 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    seed = static_cast<std::uint32_t>((z ^ (z >> 31)) >> 32);
  }
  const std::uint32_t sampler_seed = seed < 0x80000000u ? 2u * seed : 2u * (seed - 0x80000000u) + 1u;
  rng_ = std::make_unique<ompl::RNG>(sampler_seed ^ 1u);
  sampler_ = std::make_shared<SeededPoseSampler>(si_->getStateSpace().get(), sampler_seed);
  temperature_ = init_temperature_;
  transition_failures_ = 0;
  outcome_ = PlanOutcome::TimeLimit;
  Node* root = add_node(start, kNoPusher, nullptr, PathCost{});
  note_goal_candidate(root);
  if (best_goal() != nullptr) {  // already there
    outcome_ = PlanOutcome::GoalReached;
    first_time_ = 0.0;
    first_margin_ = path_margin(root);  // no push: +inf
  }
}

bool TRRTstar::finished(const ob::PlannerTerminationCondition& ptc) const {
  if (ptc) return true;
  if (outcome_ != PlanOutcome::GoalReached) return false;
  return improve_for_ <= 0.0 ||
         std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_started_).count() - first_time_ >=
             improve_for_;
}

double TRRTstar::path_margin(const Node* node) const {
  double margin = std::numeric_limits<double>::infinity();
  for (; node != nullptr && node->parent != nullptr; node = node->parent) {
    const std::vector<Pose> poses = space_->unit_pushes(node->parent->pose, node->pose);
    for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
      margin = std::min(margin, validator_->push_margin(poses[i], poses[i + 1], node->pusher));
    }
  }
  return margin;
}

TRRTstar::GoalPath TRRTstar::goal_path(const Node* node) const {
  GoalPath out;
  out.cost = node->cost;
  out.margin = path_margin(node);
  for (const Node* n = node; n != nullptr; n = n->parent) out.nodes.push_back({n->pose, n->pusher});
  std::reverse(out.nodes.begin(), out.nodes.end());
  return out;
}

void TRRTstar::choose_improved_path() {
  for (const Node* g : goal_nodes_)
    if (g->cost.switches <= max_switches_) kept_paths_.push_back(goal_path(g));
  const auto better = [](const GoalPath& a, const GoalPath& b) {  // fewer switch-overs, larger margin, shorter
    if (a.cost.switches != b.cost.switches) return a.cost.switches < b.cost.switches;
    if (a.margin != b.margin) return a.margin > b.margin;
    return a.cost.length < b.cost.length;
  };
  for (GoalPath& p : kept_paths_)
    if (!improved_ || better(p, *improved_)) improved_ = std::move(p);
  kept_paths_.clear();
}

double TRRTstar::solution_margin() const {
  if (improved_) return improved_->margin;
  return path_margin(path_end());
}

const TRRTstar::Node* TRRTstar::path_end() const {
  const Node* goal = best_goal();
  return goal != nullptr ? goal : closest_;
}

std::vector<PathNode> TRRTstar::solution() const {
  if (improved_) return improved_->nodes;
  std::vector<PathNode> path;
  for (const Node* n = path_end(); n != nullptr; n = n->parent) path.push_back({n->pose, n->pusher});
  std::reverse(path.begin(), path.end());
  return path;
}

PathCost TRRTstar::solution_cost() const {
  if (improved_) return improved_->cost;
  const Node* end = path_end();
  return end ? end->cost : PathCost{};
}

std::vector<TRRTstar::TreeNode> TRRTstar::tree() const {
  std::unordered_map<const Node*, int> index;
  for (std::size_t i = 0; i < nodes_.size(); ++i) index[nodes_[i]] = static_cast<int>(i);
  std::vector<TreeNode> out;
  out.reserve(nodes_.size());
  for (const Node* n : nodes_) out.push_back({n->pose, n->pusher, n->parent ? index.at(n->parent) : -1, n->cost});
  return out;
}

void TRRTstar::getPlannerData(ob::PlannerData& data) const {
  ob::Planner::getPlannerData(data);
  // Vertex tags carry the pusher of the push into the vertex (kNoPusher at the start).
  for (const Node* n : nodes_) {
    if (n->parent == nullptr)
      data.addStartVertex(ob::PlannerDataVertex(n->state, n->pusher));
    else
      data.addEdge(ob::PlannerDataVertex(n->parent->state, n->parent->pusher),
                   ob::PlannerDataVertex(n->state, n->pusher));
  }
  if (const Node* g = best_goal()) data.addGoalVertex(ob::PlannerDataVertex(g->state, g->pusher));
}

}  // namespace stablepush
