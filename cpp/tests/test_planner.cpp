// TRRTstar against a toy PushChecker (OMPL's PlannerTest way: the search apart from the mechanics).
// Two pushers: pusher 0 moves the object only within ~26 deg of +x, pusher 1 of +z (in unit steps).
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/ScopedState.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/util/Console.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "stablepush/internal/checker_validator.hpp"
#include "stablepush/internal/grasp_space.hpp"
#include "stablepush/internal/trrt_star.hpp"
#include "stablepush/planning.hpp"

using namespace stablepush;
namespace ob = ompl::base;

namespace {
const StepSize kStep{1e-3, M_PI / 180.0};

/// cos of the angle between the motion a -> b (in unit steps) and pusher p's axis.
double alignment(const Pose& a, const Pose& b, int p) {
  const Eigen::Vector3d d((b.x - a.x) / kStep.length, (b.z - a.z) / kStep.length, (b.theta - a.theta) / kStep.angle);
  const double n = d.norm();
  return n > 0 ? (p == 0 ? d.x() : d.y()) / n : -1.0;
}

class ConeChecker : public PushChecker {
 public:
  PusherSet all_pushers() const override { return 0b11; }
  PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const override {
    ++checks_;
    PusherSet out = 0;
    for (int p = 0; p < 2; ++p)
      if (contains(candidates, p) && alignment(a, b, p) >= 0.9) out |= PusherSet{1} << p;
    return out;
  }
  double push_margin(const Pose& a, const Pose& b, int p) const override { return alignment(a, b, p) - 0.9; }
  std::uint64_t feasibility_checks() const override { return checks_; }
  void reset_feasibility_checks() override { checks_ = 0; }

 private:
  mutable std::uint64_t checks_ = 0;
};

/// OMPL's motion validator asking a toy checker: plan_with_checker's own adapter.
template <class Checker, class... Args>
std::shared_ptr<CheckerMotionValidator> validator_of(const ob::SpaceInformationPtr& si, Args&&... args) {
  return std::make_shared<CheckerMotionValidator>(si, std::make_shared<Checker>(std::forward<Args>(args)...));
}

PlannerSettings settings_to(const Pose& goal) {
  PlannerSettings s;
  s.goal = goal;
  s.step = kStep;
  s.tolerance = StepSize{0.5e-3, 0.5 * M_PI / 180.0};
  s.time_limit = 5.0;
  s.parameters = {{"seed", "3"}, {"max_switches", "1"}};
  return s;
}
}  // namespace

/// The toy problem of planning from the origin to `goal` with TRRTstar, as plan_with_checker
/// sets it up, in a box of +-20 unit steps.
struct ToyProblem {
  ob::SpaceInformationPtr si;
  ob::ProblemDefinitionPtr pdef;
  explicit ToyProblem(
      const Pose& goal, std::function<bool(const Pose&)> valid = [](const Pose&) { return true; }) {
    ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
    ob::RealVectorBounds bounds(3);
    bounds.setLow(-0.02);
    bounds.setHigh(0.02);
    auto space = std::make_shared<GraspPoseSpace>(kStep, bounds);
    si = std::make_shared<ob::SpaceInformation>(space);
    si->setStateValidityChecker([valid](const ob::State* s) { return valid(GraspPoseSpace::pose(s)); });
    si->setMotionValidator(validator_of<ConeChecker>(si));
    si->setup();
    pdef = std::make_shared<ob::ProblemDefinition>(si);
    ob::ScopedState<GraspPoseSpace> start(space);
    GraspPoseSpace::set_pose(start.get(), Pose{});
    pdef->addStartState(start);
    pdef->setGoal(std::make_shared<PoseGoal>(si, goal, StepSize{0.5e-3, 0.5 * M_PI / 180.0}));
  }
};

TEST_CASE("choose-parent and rewire keep every node's cost its parent's plus its edge's", "[trrt_star]") {
  int deep_trees = 0;
  for (long long seed = 1; seed <= 10; ++seed) {
    ToyProblem problem(Pose{12e-3, 12e-3, 0.0});
    TRRTstar planner(problem.si);
    planner.setSeed(seed);
    planner.setImproveFor(0.05);  // keeps growing (and rewiring) after the first plan
    planner.setProblemDefinition(problem.pdef);
    planner.setup();
    planner.solve(ob::timedPlannerTerminationCondition(5.0));
    const std::vector<TRRTstar::TreeNode> tree = planner.tree();
    REQUIRE(tree.size() > 10);
    CHECK(tree[0].parent == -1);
    CHECK(tree[0].cost.switches == 0);
    CHECK(tree[0].cost.length == 0.0);
    bool deep = false;
    for (const TRRTstar::TreeNode& n : tree) {
      if (n.parent < 0) continue;
      const TRRTstar::TreeNode& p = tree[static_cast<std::size_t>(n.parent)];
      const int switch_over = p.pusher != kNoPusher && p.pusher != n.pusher ? 1 : 0;
      CHECK(n.cost.switches == p.cost.switches + switch_over);
      CHECK_THAT(n.cost.length, Catch::Matchers::WithinAbs(p.cost.length + steps_between(p.pose, n.pose, kStep), 1e-9));
      CHECK(alignment(p.pose, n.pose, n.pusher) >= 0.9);  // every edge a push the checker allowed
      deep = deep || p.parent >= 0;
    }
    deep_trees += deep;
  }
  CHECK(deep_trees > 0);
}

TEST_CASE("the cost of the returned path is the cost of its pushes", "[trrt_star]") {
  for (const char* seed : {"1", "2", "3", "4", "5"}) {
    PlannerSettings settings = settings_to(Pose{6e-3, 6e-3, 0.0});
    settings.parameters["seed"] = seed;
    const CheckedPlan plan = plan_with_checker(std::make_shared<ConeChecker>(), settings);
    REQUIRE(plan.outcome == PlanOutcome::GoalReached);
    int switches = 0;
    double length = 0.0;
    for (std::size_t i = 1; i < plan.path.size(); ++i) {
      length += steps_between(plan.path[i - 1].pose, plan.path[i].pose, kStep);
      if (i > 1 && plan.path[i].pusher != plan.path[i - 1].pusher) ++switches;
    }
    CHECK(plan.cost.switches == switches);
    CHECK_THAT(plan.cost.length, Catch::Matchers::WithinRel(length, 1e-9));
    CHECK(switches == 1);  // the goal up and to the right needs both toy pushers
  }
}

TEST_CASE("solve, clear, solve: a cleared planner plans again as a new one (OMPL's contract)", "[trrt_star]") {
  ToyProblem problem(Pose{6e-3, 6e-3, 0.0});
  TRRTstar planner(problem.si);
  planner.setSeed(3);
  planner.setProblemDefinition(problem.pdef);
  planner.setup();
  const ob::PlannerStatus first = planner.solve(ob::timedPlannerTerminationCondition(5.0));
  REQUIRE(first == ob::PlannerStatus::EXACT_SOLUTION);
  REQUIRE(planner.outcome() == PlanOutcome::GoalReached);
  const std::vector<PathNode> path = planner.solution();

  planner.clear();
  CHECK(planner.node_count() == 0);
  problem.pdef->clearSolutionPaths();
  const ob::PlannerStatus again = planner.solve(ob::timedPlannerTerminationCondition(5.0));
  REQUIRE(again == ob::PlannerStatus::EXACT_SOLUTION);
  const std::vector<PathNode> replanned = planner.solution();
  REQUIRE(replanned.size() == path.size());
  for (std::size_t i = 0; i < path.size(); ++i) {
    CHECK(replanned[i].pusher == path[i].pusher);
    CHECK(replanned[i].pose.x == path[i].pose.x);
    CHECK(replanned[i].pose.z == path[i].pose.z);
    CHECK(replanned[i].pose.theta == path[i].pose.theta);
  }
}

TEST_CASE("a start where the grasp is not maintained ends the solve at once as INVALID_START", "[trrt_star]") {
  ToyProblem problem(Pose{6e-3, 6e-3, 0.0}, [](const Pose& q) { return q.x > 1e-3; });  // the start x = 0 is not
  TRRTstar planner(problem.si);
  planner.setProblemDefinition(problem.pdef);
  planner.setup();
  CHECK(planner.solve(ob::timedPlannerTerminationCondition(5.0)) == ob::PlannerStatus::INVALID_START);
  CHECK(planner.outcome() == PlanOutcome::InvalidStart);
  CHECK(planner.solution().empty());
}

TEST_CASE("solve, solve: a second solve goes on growing the first one's tree (OMPL's contract)", "[trrt_star]") {
  ToyProblem problem(Pose{12e-3, 12e-3, 0.0});
  TRRTstar planner(problem.si);
  planner.setSeed(2);
  planner.setProblemDefinition(problem.pdef);
  planner.setup();
  int polls = 0;
  const ob::PlannerTerminationCondition soon([&polls] { return ++polls > 40; });
  planner.solve(soon);
  const std::vector<TRRTstar::TreeNode> before = planner.tree();
  REQUIRE(before.size() > 1);
  REQUIRE(planner.outcome() != PlanOutcome::GoalReached);  // stopped early

  CHECK(planner.solve(ob::timedPlannerTerminationCondition(5.0)) == ob::PlannerStatus::EXACT_SOLUTION);
  const std::vector<TRRTstar::TreeNode> after = planner.tree();
  REQUIRE(after.size() > before.size());
  for (std::size_t i = 0; i < before.size(); ++i) {  // the first tree is still there, node for node
    CHECK(after[i].pose.x == before[i].pose.x);
    CHECK(after[i].pose.z == before[i].pose.z);
    CHECK(after[i].pose.theta == before[i].pose.theta);
  }
}

TEST_CASE("statistics are OMPL progress properties", "[trrt_star]") {
  ToyProblem problem(Pose{6e-3, 6e-3, 0.0});
  TRRTstar planner(problem.si);
  planner.setProblemDefinition(problem.pdef);
  planner.setup();
  REQUIRE(planner.solve(ob::timedPlannerTerminationCondition(5.0)) == ob::PlannerStatus::EXACT_SOLUTION);
  const auto& properties = planner.getPlannerProgressProperties();
  CHECK(properties.at("iterations INTEGER")() == std::to_string(planner.iterations()));
  CHECK(properties.at("nodes INTEGER")() == std::to_string(planner.node_count()));
  CHECK(properties.at("best switch-overs INTEGER")() == std::to_string(planner.solution_cost().switches));
  CHECK(properties.count("restarts INTEGER") == 1);
}

namespace {
/// Stable only as a turn toward +theta about kPivot (fixed in G), the sticking case: the point of the
/// object at kPivot does not slip, v + omega_cross(omega, kPivot - o) = 0.
const Vec2 kPivot(2e-3, 0.0);

class PivotChecker : public PushChecker {
 public:
  PusherSet all_pushers() const override { return 0b1; }
  PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const override {
    ++checks_;
    const Vec2 v(b.x - a.x, b.z - a.z);
    const double omega = b.theta - a.theta;
    const Vec2 slip = v + omega_cross(omega, kPivot - Vec2(a.x, a.z));
    const bool turns = omega > 0.0 && slip.norm() <= 1e-9 * (v.norm() + omega * (kPivot - Vec2(a.x, a.z)).norm());
    return turns ? (candidates & 0b1) : 0;
  }
  double push_margin(const Pose&, const Pose&, int) const override { return 1.0; }
  std::vector<Vec2> pivot_points() const override { return {kPivot}; }
  std::uint64_t feasibility_checks() const override { return checks_; }
  void reset_feasibility_checks() override { checks_ = 0; }

 private:
  mutable std::uint64_t checks_ = 0;
};

/// From the origin, 2 mm off the pivot, to the origin turned 30 deg about it.
ob::PlannerStatus solve_pivot(long long pivot_steps, std::vector<PathNode>* path) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  ob::RealVectorBounds bounds(3);
  bounds.setLow(-0.02);
  bounds.setHigh(0.02);
  bounds.setHigh(2, 1.0);
  auto space = std::make_shared<GraspPoseSpace>(kStep, bounds);
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([](const ob::State*) { return true; });
  si->setMotionValidator(validator_of<PivotChecker>(si));
  si->setup();
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  ob::ScopedState<GraspPoseSpace> start(space);
  GraspPoseSpace::set_pose(start.get(), Pose{});
  pdef->addStartState(start);
  const double turn = 30.0 * M_PI / 180.0;
  const Vec2 end = kPivot + Rotation2(turn).apply(-kPivot);
  pdef->setGoal(std::make_shared<PoseGoal>(si, Pose{end.x(), end.y(), turn}, StepSize{0.5e-3, 0.5 * M_PI / 180.0}));
  TRRTstar planner(si);
  planner.params().setParam("pivot_steps", std::to_string(pivot_steps));
  planner.params().setParam("seed", "1");
  planner.setProblemDefinition(pdef);
  planner.setup();
  const ob::PlannerStatus status = planner.solve(ob::timedPlannerTerminationCondition(1.0));
  *path = planner.solution();
  return status;
}
}  // namespace

TEST_CASE("pivot_steps: a turn about a pad's centre reaches what straight and steered steps cannot", "[trrt_star]") {
  std::vector<PathNode> path;
  REQUIRE(solve_pivot(1, &path) == ob::PlannerStatus::EXACT_SOLUTION);
  CHECK(path.size() >= 31);  // one unit step of turn at most per push
  for (std::size_t i = 1; i < path.size(); ++i) CHECK(path[i].pose.theta > path[i - 1].pose.theta);
  CHECK(solve_pivot(0, &path) == ob::PlannerStatus::APPROXIMATE_SOLUTION);  // the default: none found
}

namespace {
/// Point pushers whose stable pushes are planes: pusher k's are n_k . dq = 0 (dq in unit steps,
/// x z theta), a point pusher's surface, flat.
class PlaneChecker : public PushChecker {
 public:
  explicit PlaneChecker(std::vector<Eigen::Vector3d> normals) : n_(std::move(normals)) {
    for (Eigen::Vector3d& n : n_) n.normalize();
  }
  PusherSet all_pushers() const override { return (PusherSet{1} << n_.size()) - 1; }
  PusherSet wedge_pushers() const override { return all_pushers(); }
  PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const override {
    ++checks_;
    const Eigen::Vector3d d = in_steps(b - a);
    PusherSet stable = 0;
    for (std::size_t k = 0; k < n_.size(); ++k)
      if (d.norm() > 0.0 && std::abs(n_[k].dot(d)) <= 1e-9 * d.norm()) stable |= PusherSet{1} << k;
    return stable & candidates;
  }
  /// The same heading in (x, z), the theta that puts it on the plane, `length` unit steps long.
  std::optional<Pose> onto_wedge_surface(const Pose& a, const Eigen::Vector3d& direction, double length,
                                         int pusher) const override {
    const Eigen::Vector3d& n = n_[pusher];
    Eigen::Vector3d d(direction.x(), direction.y(), -(n.x() * direction.x() + n.y() * direction.y()) / n.z());
    d *= length / d.norm();
    return a + Motion{d.x() * kStep.length, d.y() * kStep.length, d.z() * kStep.angle};
  }
  double push_margin(const Pose&, const Pose&, int) const override { return 1.0; }
  std::uint64_t feasibility_checks() const override { return checks_; }
  void reset_feasibility_checks() override { checks_ = 0; }

 private:
  static Eigen::Vector3d in_steps(const Motion& m) {
    return {m.dx / kStep.length, m.dz / kStep.length, m.dtheta / kStep.angle};
  }
  std::vector<Eigen::Vector3d> n_;
  mutable std::uint64_t checks_ = 0;
};
}  // namespace

namespace {
/// Plans with descents only (goal_bias 1) from the origin to `goal` with PlaneChecker(normals);
/// returns the iterations the solve took, 0 when it found no plan in 1 s. With `restarts`, an
/// attempt ends after its first descent, and the attempts made are written there.
std::uint64_t descents_to(const std::vector<Eigen::Vector3d>& normals, const Pose& goal, int max_switches = 1,
                          unsigned* restarts = nullptr) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  ob::RealVectorBounds bounds(3);
  bounds.setLow(-0.02);
  bounds.setHigh(0.02);
  auto space = std::make_shared<GraspPoseSpace>(kStep, bounds);
  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([](const ob::State*) { return true; });
  si->setMotionValidator(validator_of<PlaneChecker>(si, normals));
  si->setup();
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  ob::ScopedState<GraspPoseSpace> start(space);
  GraspPoseSpace::set_pose(start.get(), Pose{});
  pdef->addStartState(start);
  pdef->setGoal(std::make_shared<PoseGoal>(si, goal, StepSize{0.5e-3, 0.5 * M_PI / 180.0}));
  TRRTstar planner(si);
  planner.params().setParam("seed", "1");
  planner.params().setParam("goal_bias", "1");  // descents, while a node is left to descend from
  planner.params().setParam("max_switches", std::to_string(max_switches));
  if (restarts != nullptr) planner.params().setParam("restart_checks", "1");
  planner.setProblemDefinition(pdef);
  planner.setup();
  const bool solved = planner.solve(ob::timedPlannerTerminationCondition(1.0)) == ob::PlannerStatus::EXACT_SOLUTION;
  if (restarts != nullptr) *restarts = planner.restarts();
  return solved ? planner.iterations() : 0;
}
}  // namespace

TEST_CASE("a descent on a point pusher's surface ends in the goal's box where the surface crosses it", "[trrt_star]") {
  // Planes through the start that cross the goal's box of +-0.5 unit steps, though their point
  // nearest the goal pose is outside it: a descent ranked by the distance to the goal pose alone
  // stops at that point: so ranked, the start's descent reaches the box in 25 of these 81.
  int first_descent = 0, cases = 0;
  for (const double nz : {0.96, 0.9, 0.8}) {
    const Eigen::Vector3d n(std::sqrt(1.0 - nz * nz), 0.0, nz);
    // The nearest point is off by |n.g| nz in theta, outside when |n.g| > 0.5 / nz; the plane
    // meets the box while |n.g| <= 0.5 (|n_x| + |n_theta|).
    const double outside = 0.5 / nz, crosses = 0.5 * (n.x() + n.z());
    for (const double f : {0.2, 0.5, 0.8}) {
      const double n_dot_goal = outside + f * (crosses - outside);
      for (const double gx : {3.0, 5.0, 8.0}) {
        for (const double gz : {0.0, 2.0, -3.0}) {
          const double gtheta = (-n_dot_goal - n.x() * gx) / nz;  // [unit steps]
          const std::uint64_t iterations =
              descents_to({n}, Pose{gx * kStep.length, gz * kStep.length, gtheta * kStep.angle});
          CHECK(iterations > 0);  // every goal planned
          first_descent += iterations == 1;
          ++cases;
        }
      }
    }
  }
  CHECK(cases == 81);
  CHECK(first_descent == cases);  // the start's own descent, every time
}

TEST_CASE("a descent on one point pusher's surface walks to where another's through the goal meets it", "[trrt_star]") {
  // Two planes of stable pushes whose normals meet at cos 0.64. Greedy descents project the way
  // left onto one plane and then the other, shrinking it by 0.64^2 per pair of switch-overs, so
  // with two allowed they end 1.2-3.3 unit steps off these goals (|n_a . g| from 3 to 8). The
  // walk to where the second plane through the goal meets the first (split_point) reaches it.
  const std::vector<Eigen::Vector3d> normals = {{0.6, 0.0, 0.8}, {0.0, 0.6, 0.8}};
  int first_descent = 0, cases = 0;
  for (const double na_g : {3.0, 5.0, 8.0}) {
    for (const double gx : {-4.0, 0.0, 4.0}) {
      for (const double gz : {-3.0, 0.0, 3.0}) {
        const double gtheta = (na_g - 0.6 * gx) / 0.8;  // [unit steps]: n_a . g = na_g
        const std::uint64_t iterations =
            descents_to(normals, Pose{gx * kStep.length, gz * kStep.length, gtheta * kStep.angle}, 2);
        CHECK(iterations > 0);
        first_descent += iterations == 1;
        ++cases;
      }
    }
  }
  CHECK(cases == 27);
  CHECK(first_descent == cases);  // the start's own descent, every time
}

TEST_CASE("after one restart a walk between point pushers' surfaces at a shallow angle takes the long way round",
          "[trrt_star]") {
  // Two planes of stable pushes 24.5 deg apart (normals meeting at cos 0.91): the shortest split
  // of the way to these goals, a on the first plane and b on the second, is 1.8 to 4.6 times as
  // long as the way itself (|a| + |b| over |g|), and greedy switch-overs shrink the way left only
  // by 0.91^2 per pair. Each attempt ends after its first descent: the first attempt's splits are
  // at most three times the way, the second's six, so the first attempt reaches none of these goals
  // and the second attempt's first descent every one (with three in both, none).
  const double nz = std::sqrt(0.91);
  const std::vector<Eigen::Vector3d> normals = {{0.3, 0.0, nz}, {0.0, 0.3, nz}};
  int second_attempt = 0, cases = 0;
  for (const double na_g : {3.0, 5.0, 8.0}) {
    for (const double gx : {-4.0, 0.0, 4.0}) {
      for (const double gz : {-3.0, 0.0, 3.0}) {
        const double gtheta = (na_g - 0.3 * gx) / nz;  // [unit steps]: n_a . g = na_g
        unsigned restarts = 0;
        const std::uint64_t iterations =
            descents_to(normals, Pose{gx * kStep.length, gz * kStep.length, gtheta * kStep.angle}, 2, &restarts);
        CHECK(iterations > 0);
        second_attempt += restarts == 1 && iterations == 2;
        ++cases;
      }
    }
  }
  CHECK(cases == 27);
  CHECK(second_attempt == cases);
}
