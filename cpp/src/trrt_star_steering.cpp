// TRRTstar: steering toward the goal, point pushers' wedge steps, descents and runs across (extend_toward_goal,
// descend_across).
#include <ompl/base/goals/GoalSampleableRegion.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "stablepush/internal/trrt_star.hpp"
#include "trrt_star_parts.hpp"

namespace stablepush {

PusherSet TRRTstar::onto_wedge(const Pose& from, Pose& q, PusherSet allowed, ob::State* scratch) const {
  const PusherSet wedges = allowed & validator_->wedge_pushers();
  if (wedges == 0) return 0;
  const Eigen::Vector3d step = space_->in_unit_steps(q - from);
  const double length = step.norm();
  if (!(length > 0.0)) return 0;
  for (int p = 0; p < kMaxPushers; ++p) {
    if (!contains(wedges, p)) continue;
    const std::optional<Pose> on_surface = validator_->onto_wedge_surface(from, step / length, length, p);
    if (on_surface && wedge_step_valid(from, WedgeStep{0.0, *on_surface, p, false}, scratch)) {
      q = *on_surface;
      return PusherSet{1} << p;
    }
  }
  GraspPoseSpace::set_pose(scratch, q);
  return 0;
}

namespace {
/// The least distance [unit steps] from d to the half circle length (cos b h + sin b e_theta),
/// |b| <= 90 deg, h = (hx, hz, 0) a unit heading; a little less, so that rounding cannot put a
/// step on that circle nearer than it.
double half_circle_distance(const Eigen::Vector3d& d, double hx, double hz, double length) {
  const double along = d[0] * hx + d[1] * hz;   // in the circle's plane, along h
  const double across = d[1] * hx - d[0] * hz;  // off the circle's plane
  // Behind the heading (along < 0) the nearest point is an end of the half circle, b = +-90 deg.
  const double in_plane = along >= 0.0 ? std::hypot(along, d[2]) - length : std::hypot(along, std::abs(d[2]) - length);
  return std::max(0.0, std::hypot(across, in_plane) * (1.0 - 1e-9) - 1e-9);
}
}  // namespace

WedgeStepQueue::WedgeStepQueue(const PushChecker& checker, const GraspPoseSpace& space, const PoseGoal& region,
                               const Pose& from, const Pose& goal, const std::vector<double>& lengths, PusherSet wedges)
    : checker_(checker), space_(space), region_(region), from_(from), goal_(goal) {
  outside_ = !region.contains(from);  // from within the box, nearer is what counts
  const Eigen::Vector3d to_goal = space.in_unit_steps(goal - from);
  const Eigen::Vector3d to_region = space.in_unit_steps(region.pose() - from);
  const double box_radius = region.getThreshold();  // no pose farther from the goal pose is in the box
  const double heading = std::atan2(to_goal[1], to_goal[0]);
  const double translation = std::max(std::hypot(to_goal[0], to_goal[1]), 1e-3);
  constexpr int kHeadings = 24;
  std::size_t index = 0;
  for (int p = 0; p < kMaxPushers; ++p) {
    if (!contains(wedges, p)) continue;
    const std::vector<double> headings = wedge_step_headings(checker, from, p, heading, kHeadings);
    for (const double length : lengths) {
      for (std::size_t k = 0; k < headings.size(); ++k, ++index) {
        const double psi = headings[k];
        // The goal's elevation picks the root nearest to it.
        const Eigen::Vector3d direction =
            Eigen::Vector3d(std::cos(psi) * translation, std::sin(psi) * translation, to_goal[2]).normalized();
        const double heading_norm = std::hypot(direction[0], direction[1]);
        const double hx = direction[0] / heading_norm, hz = direction[1] / heading_norm;
        const Pending pending{half_circle_distance(to_goal, hx, hz, length), index, direction, length, p};
        // A step that may end in the tolerance box is found now: those that end the plan come first.
        if (!(outside_ && half_circle_distance(to_region, hx, hz, length) <= box_radius)) {
          pending_.push_back(pending);
        } else if (std::optional<WedgeStep> step = find(pending)) {
          (step->ends_plan ? ending_ : found_).push_back({*step, index});
        }
      }
    }
  }
  std::sort(pending_.begin(), pending_.end(), [](const Pending& a, const Pending& b) {
    return a.bound != b.bound ? a.bound < b.bound : a.index < b.index;
  });
  std::sort(ending_.begin(), ending_.end(), [](const Found& a, const Found& b) { return after(b, a); });
  std::make_heap(found_.begin(), found_.end(), after);
}

bool WedgeStepQueue::after(const Found& a, const Found& b) {
  return a.step.goal_distance != b.step.goal_distance ? a.step.goal_distance > b.step.goal_distance : a.index > b.index;
}

std::optional<WedgeStep> WedgeStepQueue::find(const Pending& pending) const {
  const std::optional<Pose> on_surface =
      checker_.onto_wedge_surface(from_, pending.direction, pending.length, pending.pusher);
  if (!on_surface) return std::nullopt;
  const WedgeStep step{space_.distance(*on_surface, goal_), *on_surface, pending.pusher,
                       outside_ && region_.contains(*on_surface) && region_.held(*on_surface, pending.pusher)};
  assert(step.goal_distance >= pending.bound);  // a checker's steps as PushChecker::onto_wedge_surface says
  return step;
}

std::optional<WedgeStep> WedgeStepQueue::next() {
  if (next_ending_ < ending_.size()) return ending_[next_ending_++].step;
  for (;;) {
    const bool pending_left = next_pending_ < pending_.size();
    // A found step goes out once every root not yet found lies farther from the goal than it.
    if (!found_.empty() && (!pending_left || found_.front().step.goal_distance < pending_[next_pending_].bound)) {
      std::pop_heap(found_.begin(), found_.end(), after);
      const WedgeStep step = found_.back().step;
      found_.pop_back();
      return step;
    }
    if (!pending_left) return std::nullopt;
    const Pending& pending = pending_[next_pending_++];
    if (std::optional<WedgeStep> step = find(pending)) {
      found_.push_back({*step, pending.index});
      std::push_heap(found_.begin(), found_.end(), after);
    }
  }
}

std::vector<WedgeStep> TRRTstar::wedge_steps(const Pose& from, const Pose& goal, const std::vector<double>& lengths,
                                             PusherSet wedges) const {
  WedgeStepQueue queue = wedge_step_queue(from, goal, lengths, wedges);
  std::vector<WedgeStep> steps;
  while (std::optional<WedgeStep> step = queue.next()) steps.push_back(*step);
  return steps;
}

WedgeStepQueue TRRTstar::wedge_step_queue(const Pose& from, const Pose& goal, const std::vector<double>& lengths,
                                          PusherSet wedges) const {
  return WedgeStepQueue(*validator_, *space_, *pdef_->getGoal()->as<PoseGoal>(), from, goal, lengths, wedges);
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
  const auto take = [&](const WedgeStep& step) {
    q = step.pose;
    GraspPoseSpace::set_pose(scratch, q);
    return PusherSet{1} << step.pusher;
  };
  WedgeStepQueue steps = wedge_step_queue(from, goal, {length}, wedges);
  std::vector<WedgeStep> valid;
  while (const std::optional<WedgeStep> step = steps.next()) {
    if (!wedge_step_valid(from, *step, scratch)) continue;
    if (step->ends_plan || step->goal_distance < now) return take(*step);
    valid.push_back(*step);
  }
  // Stalled near the goal: shorter steps, since a surface may cross the tolerance box (a unit step
  // or two across) only where a full step from here overshoots it.
  if (now < 2.0 * pdef_->getGoal()->as<ob::GoalRegion>()->getThreshold()) {
    WedgeStepQueue shorter = wedge_step_queue(from, goal, {0.5 * length, 0.25 * length}, wedges);
    while (const std::optional<WedgeStep> step = shorter.next()) {
      if (!step->ends_plan && step->goal_distance >= now) break;
      if (wedge_step_valid(from, *step, scratch)) return take(*step);
    }
  }
  // A local minimum of one step: one surface alone moves q in two of its three coordinates, so
  // look two steps ahead (the second on any point pusher's surface) from the best first steps.
  constexpr std::size_t kFirstSteps = 8;
  for (std::size_t i = 0; i < std::min(valid.size(), kFirstSteps); ++i) {
    const double next_length = std::min(1.0, valid[i].goal_distance);
    WedgeStepQueue seconds = wedge_step_queue(valid[i].pose, goal, {next_length}, validator_->wedge_pushers());
    while (const std::optional<WedgeStep> second = seconds.next()) {
      if (!second->ends_plan && second->goal_distance >= now) break;
      if (wedge_step_valid(valid[i].pose, *second, scratch)) return take(valid[i]);
    }
  }
  GraspPoseSpace::set_pose(scratch, q);
  return 0;
}

namespace {
constexpr int kRayHeadings = 24;
constexpr int kSplitRefinements = 2;
// At most this many times the straight way (long ways round leave the first-order model): for a
// way left square to the first surface a split is cot(phi / 2) times as long, phi the angle
// between the two surfaces, so this admits surfaces at least 37 deg apart. After an odd number of
// restarts an attempt admits twice as long, surfaces at least 19 deg apart: on some parts two pins'
// surfaces meet only at such angles, on others the long ways round lead descents astray
// (docs/planner.md), so the attempts take turns.
constexpr double kLongestSplit = 3.0;
constexpr double kLongestSplitOddAttempt = 6.0;
}  // namespace

std::vector<std::optional<Eigen::Vector3d>> TRRTstar::wedge_rays(const Pose& at, int pusher, ob::State* scratch) const {
  // In the order of their headings: a cone of the split is spanned by two neighbours.
  std::vector<double> headings = wedge_step_headings(*validator_, at, pusher, 0.0, kRayHeadings);
  for (double& psi : headings) psi -= 2.0 * M_PI * std::floor(psi / (2.0 * M_PI));
  std::sort(headings.begin(), headings.end());
  std::vector<std::optional<Eigen::Vector3d>> rays(headings.size());
  for (std::size_t k = 0; k < headings.size(); ++k) {
    const double psi = headings[k];
    const std::optional<Pose> end =
        validator_->onto_wedge_surface(at, Eigen::Vector3d(std::cos(psi), std::sin(psi), 0.0), 1.0, pusher);
    if (end && wedge_step_valid(at, WedgeStep{0.0, *end, pusher, false}, scratch))
      rays[k] = space_->in_unit_steps(*end - at);
  }
  return rays;
}

namespace {
using Rays = std::vector<std::optional<Eigen::Vector3d>>;

/// The shortest d = a + b with a in the cone of `first` (two adjacent rays) and b in that of
/// `second` (or the other way round), |a| + |b| at most `longest` |d|: (a, |a| + |b|).
std::optional<std::pair<Eigen::Vector3d, double>> decompose(const Eigen::Vector3d& d, const Rays& first,
                                                            const Rays& second, double longest) {
  std::optional<std::pair<Eigen::Vector3d, double>> best;
  const auto consider = [&](const Eigen::Vector3d& u, const Eigen::Vector3d& v, const Eigen::Vector3d& w,
                            bool two_of_first) {
    Eigen::Matrix3d m;
    m << u, v, w;
    if (!(std::abs(m.determinant()) > 1e-6)) return;
    Eigen::Vector3d x = m.partialPivLu().solve(d);
    if (!(x.minCoeff() >= -1e-12)) return;  // d on a cone's edge may solve a rounding below 0
    x = x.cwiseMax(0.0);
    const Eigen::Vector3d leg = two_of_first ? Eigen::Vector3d(x[0] * u + x[1] * v) : Eigen::Vector3d(x[2] * w);
    const double length = leg.norm() + (d - leg).norm();
    // A long way round (surfaces at a shallow angle) leaves the first-order model.
    if (length <= longest * d.norm() && (!best || length < best->second)) best = std::make_pair(leg, length);
  };
  // Each cone of one set's neighbouring rays with each ray of the other set.
  const auto cones = [&](const Rays& pairs, const Rays& singles, bool two_of_first) {
    const std::size_t n = pairs.size();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t next = (i + 1) % n;
      if (!pairs[i] || !pairs[next]) continue;
      for (const std::optional<Eigen::Vector3d>& single : singles)
        if (single) consider(*pairs[i], *pairs[next], *single, two_of_first);
    }
  };
  cones(first, second, true);
  cones(second, first, false);
  return best;
}
}  // namespace

std::optional<TRRTstar::Split> TRRTstar::split_point(const Pose& q, PusherSet first, PusherSet second,
                                                     ob::State* scratch) {
  const Pose goal = pdef_->getGoal()->as<PoseGoal>()->pose();
  const Eigen::Vector3d d = space_->in_unit_steps(goal - q);
  const PusherSet wedges = validator_->wedge_pushers();
  if (goal_rays_.size() != kMaxPushers) goal_rays_.assign(kMaxPushers, std::nullopt);
  const double longest = restarts_ % 2 == 1 ? kLongestSplitOddAttempt : kLongestSplit;
  std::optional<Split> best;
  for (int a = 0; a < kMaxPushers; ++a) {
    if (!contains(first & wedges, a)) continue;
    const Rays rays_a = wedge_rays(q, a, scratch);
    for (int b = 0; b < kMaxPushers; ++b) {
      if (b == a || !contains(second & wedges, b)) continue;
      if (!goal_rays_[b]) goal_rays_[b] = wedge_rays(goal, b, scratch);
      auto found = decompose(d, rays_a, *goal_rays_[b], longest);
      // The second surface turns with the object between the switch-over and the goal: its rays
      // again where the first leg ends, twice.
      for (int again = 0; again < kSplitRefinements && found; ++again) {
        auto refined = decompose(d, rays_a, wedge_rays(q + space_->from_unit_steps(found->first), b, scratch), longest);
        if (!refined) break;
        found = refined;
      }
      if (found && (!best || found->second < best->length)) best = Split{a, b, found->first, found->second};
    }
  }
  return best;
}

TRRTstar::Node* TRRTstar::connect_descent(Node* from, const Pose& q_new, PusherSet stable, int prefer, int descent) {
  Node* next = connect(from, q_new, stable, prefer);
  next->extended_to_goal = true;
  next->descent = descent;
  return next;
}

TRRTstar::Node* TRRTstar::walk_to_split(Node* from, Split split, int descent,
                                        const ob::PlannerTerminationCondition& ptc) {
  ob::State* scratch = si_->allocState();
  // Each step is the first leg's heading on the first pusher's surface; the leg is found again
  // from where the step ends, since the surface turns with the object.
  const int most = static_cast<int>(std::ceil(split.length)) + 2;
  for (int k = 0; k < most && !ptc && split.first_leg.norm() >= 0.5; ++k) {
    const double length = std::min(1.0, split.first_leg.norm());
    const std::optional<Pose> q =
        validator_->onto_wedge_surface(from->pose, split.first_leg.normalized(), length, split.first);
    if (!q || !wedge_step_valid(from->pose, WedgeStep{0.0, *q, split.first, false}, scratch)) break;
    Node* next = connect_descent(from, *q, single(split.first), split.first, descent);
    if (next->cost.switches > max_switches_) break;
    from = next;
    if (outcome_ == PlanOutcome::GoalReached) break;
    const std::optional<Split> again = split_point(from->pose, single(split.first), single(split.second), scratch);
    if (!again) break;
    split = *again;
  }
  si_->freeState(scratch);
  return from;
}

TRRTstar::Node* TRRTstar::walk_after_stall(Node* from, bool own_first, int descent,
                                           const ob::PlannerTerminationCondition& ptc) {
  if (outcome_ == PlanOutcome::GoalReached || validator_->wedge_pushers() == 0) return from;
  const int spare = max_switches_ - from->cost.switches;
  if (spare < 1) return from;  // the second leg is a switch-over
  // The first leg by the descent's own pusher costs no switch-over, another's one more.
  const PusherSet first = own_first || (from->pusher != kNoPusher && spare < 2)
                              ? single(from->pusher)
                              : transit_allowed(from, validator_->all_pushers());
  ob::State* scratch = si_->allocState();
  const std::optional<Split> split = split_point(from->pose, first, validator_->wedge_pushers(), scratch);
  si_->freeState(scratch);
  return split && split->first_leg.norm() >= 1.0 ? walk_to_split(from, *split, descent, ptc) : from;
}

PusherSet TRRTstar::pivot_toward_goal(const Pose& from, const Pose& goal, PusherSet allowed, PusherSet own,
                                      ob::State* scratch, Pose& q) const {
  const double turn = goal.theta - from.theta;
  if (!(std::abs(turn) > kMinEdge * space_->step().angle)) return 0;
  const Vec2 origin(from.x, from.z);
  for (const Vec2& pivot : validator_->pivot_points()) {
    // At most one unit step: (dtheta |P - o| / length)^2 + (dtheta / angle)^2 <= 1.
    const double radius = (pivot - origin).norm() / space_->step().length;
    const double largest = 1.0 / std::hypot(radius, 1.0 / space_->step().angle);
    const double dtheta = std::copysign(std::min(std::abs(turn), largest), turn);
    const Vec2 d = -omega_cross(dtheta, pivot - origin);
    const Pose candidate = from + Motion{d.x(), d.y(), dtheta};
    GraspPoseSpace::set_pose(scratch, candidate);
    if (!si_->isValid(scratch)) continue;
    const PusherSet stable = validator_->stable_pushers_preferring(from, candidate, allowed, own);
    if (stable != 0) {
      q = candidate;
      return stable;
    }
  }
  GraspPoseSpace::set_pose(scratch, q);
  return 0;
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
  int splits_left = max_switches_;
  bool walked = false;  // the last node was reached by a walk (walk_after_stall)
  for (;;) {
    while (!ptc) {
      const Steering steering(*space_, steer_angle_, from->pose, goal);
      if (steering.distance < kMinEdge) break;
      const double length = steering.length;
      // Pushers this node may use without exceeding the switch-over budget.
      const PusherSet allowed = transit_allowed(from, from->pusher == kNoPusher || from->cost.switches < max_switches_
                                                          ? validator_->all_pushers()
                                                          : single(from->pusher));
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
      // A turn about a pad's centre before the steered steps: they drift the object across the grasp.
      if (stable == 0 && pivot_steps_) stable = pivot_toward_goal(from->pose, goal, allowed, own, step_state, q_new);
      if (stable == 0 && turn > 0 && (stable = try_direction(turn, q_new)) != 0) turn_taken = turn;
      for (int t = 8; t < 8 * (steering.rings() + 1) && stable == 0; ++t)
        if (t != turn && (stable = try_direction(t, q_new)) != 0) turn_taken = t;
      if (stable == 0) break;
      // The step found is not by the descent's own point pusher (its own goes no nearer, or another's
      // step ends nearer), and a greedy switch-over would leave the goal off the next surface: first
      // walk to where the next surface through the goal meets this one.
      // Not right after a walk: from where it ended the split is the one just walked, or none.
      if (own != 0 && (stable & own) == 0 && (own & validator_->wedge_pushers()) != 0 && splits_left > 0 && !walked) {
        --splits_left;
        Node* end = walk_after_stall(from, true, descent, ptc);
        if (end != from) {
          from = end;
          turn = 0;
          walked = true;
          continue;
        }
      }
      // A step into the goal's tolerance may climb (a point pusher's surface may cross the box only
      // farther from the goal pose than the descent's last node): it ends the plan, so it is taken.
      const auto* goal_region = pdef_->getGoal()->as<PoseGoal>();
      const bool enters = !goal_region->isSatisfied(from->state) && goal_region->isSatisfied(step_state);
      if (!enters && !transition_test(from->goal_distance, goal_region->distanceGoal(step_state), length)) break;
      // Go on with the same pusher where it can (no switch-over); the nodes of the other pushers at
      // q_new stay candidates for descents of their own, which start each pusher's straight way in.
      Node* next = connect_descent(from, q_new, stable, from->pusher, descent);
      if (next->cost.switches > max_switches_) break;
      from = next;
      walked = false;
      // connect left q_new's near nodes in near_.
      if (std::any_of(near_.begin(), near_.end(), [&](const Node* m) { return retraces(m, next); })) break;
      turn = turn_taken;
    }
    // Stalled on point pushers' surfaces: on from where another pusher's surface through the
    // goal meets this one's (walk_after_stall), at most once per switch-over.
    if (ptc || splits_left == 0) break;
    --splits_left;
    Node* end = walk_after_stall(from, false, descent, ptc);
    if (end == from) break;
    from = end;
    turn = 0;
    walked = true;
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
  PusherSet across = transit_allowed(root, validator_->all_pushers() & ~validator_->wedge_pushers());
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
      if (ptc) break;
      const Pose first = steering.step(first_turn);
      const Motion dq = first - root->pose;
      Node* node = root;
      double previous_end = std::numeric_limits<double>::infinity();  // [unit steps from the goal]
      for (int k = 0; k < longest_run && !ptc; ++k) {
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

void TRRTstar::finish_toward_goal() {
  if (!improved_) improved_ = goal_path(best_goal());
  GoalPath& path = *improved_;
  const int pusher = path.nodes.back().pusher;
  if (pusher == kNoPusher) return;  // the start is within the tolerance: no push to go on with
  const auto* goal = pdef_->getGoal()->as<PoseGoal>();
  ob::State* scratch = si_->allocState();
  // Deeper into the tolerance box (PoseGoal::offset), not nearer the goal pose in unit steps: an
  // open-loop run misses by its worst coordinate. Each step gains kDeeper of the tolerance, so at
  // most 1/kDeeper steps: the loop needs no time limit, and a plan does not depend on the machine.
  constexpr double kDeeper = 1e-3;
  for (;;) {
    const Pose from = path.nodes.back().pose;
    const Steering steering(*space_, steer_angle_, from, goal->pose());
    if (steering.distance < kMinEdge) break;
    // From where the plan can end at the goal pose (planning.cpp's finish_at_goal), a step aside
    // would only lose it.
    if (end_test_
            ? end_test_(from, pusher, path.cost.switches)
            : validator_->stable_pushers(from, goal->pose(), single(pusher)) != 0 && goal->held(goal->pose(), pusher))
      break;
    std::vector<std::pair<double, Pose>> candidates;  // (offset, end), deepest first
    const auto consider = [&](const Pose& q) {
      if (goal->offset(q) < goal->offset(from) - kDeeper) candidates.emplace_back(goal->offset(q), q);
    };
    const double l = steering.length;
    if (contains(validator_->wedge_pushers(), pusher)) {
      for (const WedgeStep& step : wedge_steps(from, goal->pose(), {l, 0.5 * l, 0.25 * l}, single(pusher)))
        consider(step.pose);
    } else {  // every ring out to 90 deg (whatever steer_angle), full and shorter steps
      const Steering wide(*space_, 45.0, from, goal->pose());  // its rings: 11.25 deg apart out to 90
      for (int turn = 0; turn < 8 * (2 * Steering::kRings + 1); turn = turn == 0 ? 8 : turn + 1)
        for (const double fraction : {1.0, 0.5, 0.25}) consider(from + fraction * (wide.step(turn) - from));
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    const auto taken = std::find_if(candidates.begin(), candidates.end(), [&](const auto& c) {
      GraspPoseSpace::set_pose(scratch, c.second);
      return goal->held(c.second, pusher) && si_->isValid(scratch) &&
             validator_->stable_pushers(from, c.second, single(pusher)) != 0;
    });
    if (taken == candidates.end()) break;
    const Pose next = taken->second;
    path.nodes.push_back({next, pusher});
    path.cost.length += space_->distance(from, next);
    path.margin = std::min(path.margin, edge_margin(from, next, pusher));
  }
  si_->freeState(scratch);
}

}  // namespace stablepush
