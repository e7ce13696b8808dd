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

#include "trrt_star_parts.hpp"

namespace stablepush {

namespace ob = ompl::base;

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
      {"pivot_steps", {true, 0.0, 1.0}},      // 1: descents turn about the pads' centres
      {"finish_steps", {true, 0.0, 1.0}},     // 1: the last pusher goes on toward the goal pose
      {"check_limit", {true, 0.0, 1e15}},     // stable-push tests a solve may make (0: no bound)
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

}  // namespace

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
  declareParam<long long>("pivot_steps", this, &TRRTstar::setPivotSteps, &TRRTstar::getPivotSteps,
                          range_text("pivot_steps"));
  declareParam<long long>("finish_steps", this, &TRRTstar::setFinishSteps, &TRRTstar::getFinishSteps,
                          range_text("finish_steps"));
  declareParam<double>("improve_for", this, &TRRTstar::setImproveFor, &TRRTstar::getImproveFor,
                       range_text("improve_for"));
  declareParam<long long>("restart_checks", this, &TRRTstar::setRestartChecks, &TRRTstar::getRestartChecks,
                          range_text("restart_checks"));
  declareParam<long long>("check_limit", this, &TRRTstar::setCheckLimit, &TRRTstar::getCheckLimit,
                          range_text("check_limit"));
  // What OMPL's benchmarking and planner-data tools read while a solve runs.
  addPlannerProgressProperty("iterations INTEGER", [this] { return std::to_string(iterations_); });
  addPlannerProgressProperty("nodes INTEGER", [this] { return std::to_string(nodes_.size()); });
  addPlannerProgressProperty("restarts INTEGER", [this] { return std::to_string(restarts_); });
  addPlannerProgressProperty("best switch-overs INTEGER", [this] {
    const Node* goal = best_goal();
    return goal ? std::to_string(goal->cost.switches) : std::string("inf");
  });
  addPlannerProgressProperty("best length REAL", [this] {
    const Node* goal = best_goal();
    return goal ? std::to_string(goal->cost.length) : std::string("inf");
  });
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
  goal_rays_.clear();
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

void TRRTstar::set_transit_hold(ModelSet models, double min_ratio, int start_pusher) {
  transit_models_ = std::move(models);
  min_transit_hold_ = min_ratio;
  start_pusher_ = start_pusher;
}

bool TRRTstar::pads_hold_transit(const Pose& q, int leaving) const {
  if (min_transit_hold_ <= 0.0) return true;
  return std::all_of(transit_models_.begin(), transit_models_.end(),
                     [&](const StablePushModel* model) { return model->hold_ratio(q, leaving) >= min_transit_hold_; });
}

PusherSet TRRTstar::transit_allowed(const Node* from, PusherSet pushers) const {
  if (min_transit_hold_ <= 0.0) return pushers;
  // The pusher in contact at `from`: the one that pushed into it, or at the root the start's.
  const int leaving = from->parent != nullptr ? from->pusher : start_pusher_;
  if (leaving == kNoPusher || (pushers & ~single(leaving)) == 0) return pushers;
  if (from->transit_held < 0) from->transit_held = pads_hold_transit(from->pose, leaving) ? 1 : 0;
  return from->transit_held ? pushers : pushers & single(leaving);
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
    stable = transit_allowed(m, stable);
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
    if (!(via < m->cost) || transit_allowed(node, single(m->pusher)) == 0) continue;
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
  while (!ptc) {
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
    const PusherSet allowed = transit_allowed(from, validator_->all_pushers());
    PusherSet stable = validator_->stable_pushers(from->pose, q_new, allowed);
    if (stable == 0 && (stable = onto_wedge(from->pose, q_new, allowed, step_state)) != 0 &&
        !transition_test(from->goal_distance, goal->distanceGoal(step_state), step))
      break;
    if (stable == 0) break;
    Node* next = connect(from, q_new, stable);
    if (last || next->cost.switches > max_switches_) break;
    from = next;
  }
  si_->freeState(step_state);
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
    goal_rays_.clear();
    begin_attempt(start_pose);
  }

  // The search stops when the caller's condition fires, the anytime phase is over or the search has
  // made check_limit stable-push tests. The count is a function of the search alone, so a search that
  // check_limit ends gives the same answer on any machine under any load; the caller's (wall time)
  // is then a guard, and check_limit_reached() tells which of them ended it.
  check_limit_reached_ = false;
  const std::uint64_t checks_began = validator_->feasibility_checks();
  const ob::PlannerTerminationCondition counted([this, checks_began] {
    if (check_limit_ == 0 || validator_->feasibility_checks() - checks_began < check_limit_) return false;
    check_limit_reached_ = true;
    return true;
  });
  const ob::PlannerTerminationCondition stop =
      ob::plannerOrTerminationCondition(ob::plannerOrTerminationCondition(counted, ptc), anytime_over());

  // Restarts against the long tail (restart_checks): a search that has made that many stable-push
  // tests without a plan starts again from the start with fresh streams and twice the budget, so
  // a seed whose first descents die where the chosen pusher cannot go on does not search there
  // for long; doubling keeps it complete. Counted in tests, not seconds, so a seed's plan is the
  // same on any machine. The attempt's condition is read between iterations, never inside one.
  std::uint64_t budget = restart_checks_, attempt_began = validator_->feasibility_checks();
  const ob::PlannerTerminationCondition attempt_over([&] {
    return budget > 0 && outcome_ != PlanOutcome::GoalReached &&
           validator_->feasibility_checks() - attempt_began >= budget;
  });

  ob::State* sample = si_->allocState();
  while (!stop) {
    if (attempt_over) {
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
      extend_toward_goal(from, stop);
      if (from->parent == nullptr && !stop) descend_across(from, stop);
    } else {
      sampler_->sampleUniform(sample);
      extend(nearest_extendable(GraspPoseSpace::pose(sample)), sample, stop);
    }
  }
  si_->freeState(sample);

  if (outcome_ != PlanOutcome::GoalReached)
    outcome_ = best_goal() != nullptr ? PlanOutcome::GoalOverSwitchLimit : PlanOutcome::TimeLimit;
  else if (improve_for_ > 0.0)
    choose_improved_path();
  if (outcome_ == PlanOutcome::GoalReached && finish_steps_) finish_toward_goal();
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

ob::PlannerTerminationCondition TRRTstar::anytime_over() const {
  return ob::PlannerTerminationCondition([this] {
    if (outcome_ != PlanOutcome::GoalReached) return false;
    return improve_for_ <= 0.0 ||
           std::chrono::duration<double>(std::chrono::steady_clock::now() - solve_started_).count() - first_time_ >=
               improve_for_;
  });
}

double TRRTstar::edge_margin(const Pose& a, const Pose& b, int pusher) const {
  double margin = std::numeric_limits<double>::infinity();
  const std::vector<Pose> poses = space_->unit_pushes(a, b);
  for (std::size_t i = 0; i + 1 < poses.size(); ++i)
    margin = std::min(margin, validator_->push_margin(poses[i], poses[i + 1], pusher));
  return margin;
}

double TRRTstar::path_margin(const Node* node) const {
  double margin = std::numeric_limits<double>::infinity();
  for (; node != nullptr && node->parent != nullptr; node = node->parent)
    margin = std::min(margin, edge_margin(node->parent->pose, node->pose, node->pusher));
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
