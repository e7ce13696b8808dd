#include "stablepush/internal/grasp_space.hpp"

#include <ompl/base/SpaceInformation.h>
#include <ompl/util/Exception.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>

namespace stablepush {

namespace ob = ompl::base;

GraspPoseSpace::GraspPoseSpace(StepSize step, const ob::RealVectorBounds& bounds)
    : ob::RealVectorStateSpace(3), step_(step) {
  if (!(step_.length > 0.0) || !(step_.angle > 0.0)) throw std::invalid_argument("unit steps must be > 0");
  setName("GraspPose");
  setDimensionName(0, "x");
  setDimensionName(1, "z");
  setDimensionName(2, "theta");
  setBounds(bounds);
}

double GraspPoseSpace::distance(const ob::State* a, const ob::State* b) const { return distance(pose(a), pose(b)); }

double steps_between(const Pose& a, const Pose& b, const StepSize& step) {
  const Motion d = b - a;
  const double dx = d.dx / step.length, dz = d.dz / step.length, dt = d.dtheta / step.angle;
  return std::sqrt(dx * dx + dz * dz + dt * dt);
}

double GraspPoseSpace::distance(const Pose& a, const Pose& b) const { return steps_between(a, b, step_); }

double GraspPoseSpace::getMaximumExtent() const {
  const double dx = (bounds_.high[0] - bounds_.low[0]) / step_.length;
  const double dz = (bounds_.high[1] - bounds_.low[1]) / step_.length;
  const double dt = (bounds_.high[2] - bounds_.low[2]) / step_.angle;
  return std::sqrt(dx * dx + dz * dz + dt * dt);
}

Pose GraspPoseSpace::pose(const ob::State* s) {
  const double* v = s->as<StateType>()->values;
  return Pose{v[0], v[1], v[2]};
}

void GraspPoseSpace::set_pose(ob::State* s, const Pose& q) {
  double* v = s->as<StateType>()->values;
  v[0] = q.x;
  v[1] = q.z;
  v[2] = q.theta;
}

std::vector<Pose> GraspPoseSpace::unit_pushes(const Pose& a, const Pose& b) const {
  const double steps = distance(a, b);
  // A hair of slack so that a motion of exactly k unit steps is k pushes, not k + 1.
  const int n = std::max(1, static_cast<int>(std::ceil(steps - 1e-9)));
  std::vector<Pose> poses;
  poses.reserve(n + 1);
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / n;
    poses.push_back(a + t * (b - a));
  }
  poses.push_back(b);
  return poses;
}

SeededPoseSampler::SeededPoseSampler(const ob::StateSpace* space, std::uint_fast32_t seed)
    : ob::RealVectorStateSampler(space) {
  rng_ = ompl::RNG(seed);
}

GraspValidityChecker::GraspValidityChecker(const ob::SpaceInformationPtr& si, const StablePushModel& model)
    : ob::StateValidityChecker(si), model_(model) {}

bool GraspValidityChecker::isValid(const ob::State* s) const {
  return model_.grasp_maintained(GraspPoseSpace::pose(s));
}

StablePushValidator::StablePushValidator(const ob::SpaceInformationPtr& si, ModelSet models, double min_margin)
    : ob::MotionValidator(si),
      models_(std::move(models)),
      space_(*si->getStateSpace()->as<GraspPoseSpace>()),
      min_margin_(min_margin) {
  if (models_.empty() || static_cast<int>(models_.size()) > kMaxModels)
    throw std::invalid_argument("a push is checked in 1 to 4 models");
  const int n = static_cast<int>(models_.front()->pushers().size());
  if (n < 1 || n > kMaxPushers) throw std::invalid_argument("a task has between 1 and 32 pushers");
  all_ = n == kMaxPushers ? ~PusherSet{0} : ((PusherSet{1} << n) - 1u);
  for (int p = 0; p < n; ++p)
    if (models_.front()->pusher_cones()[p].dimension() == 2) wedges_ |= PusherSet{1} << p;
}

std::optional<Pose> PushChecker::onto_wedge_surface(const Pose&, const Eigen::Vector3d&, double, int) const {
  return std::nullopt;
}

std::vector<double> PushChecker::wedge_translation_headings(const Pose&, int) const { return {}; }

std::vector<double> StablePushValidator::wedge_translation_headings(const Pose& a, int pusher) const {
  if (!contains(wedges_, pusher)) return {};
  const StablePushModel& model = *models_.front();
  const Wrench& plane_normal = model.pusher_cones()[pusher].equality_rows().front();
  const PoseAndRotation from(a);
  struct Off {
    double heading;
    double off;    ///< e . w(a, dq(heading)) [N]
    double scale;  ///< MotionWrench::scale
  };
  const auto off_plane = [&](double heading) {
    const MotionWrench load = model.motion_wrench(
        from, space_.from_unit_steps(Eigen::Vector3d(std::cos(heading), std::sin(heading), 0.0)), pusher);
    return Off{heading, plane_normal.dot(load.required), load.scale};
  };
  // A plane's translations are two opposite headings; 24 samples resolve a few more.
  constexpr int kTranslationScan = 24;
  std::array<Off, kTranslationScan + 1> scan;
  for (int k = 0; k < kTranslationScan; ++k) scan[k] = off_plane(2.0 * M_PI * k / kTranslationScan);
  scan[kTranslationScan] = scan[0];
  scan[kTranslationScan].heading += 2.0 * M_PI;
  std::vector<double> headings;
  for (int k = 0; k < kTranslationScan; ++k) {
    if ((scan[k].off < 0.0) == (scan[k + 1].off < 0.0)) continue;
    const Off root = refine_sign_change(scan[k], scan[k + 1], &Off::heading, &Off::off,
                                        [&](double heading) { return std::optional<Off>(off_plane(heading)); });
    if (std::abs(root.off) <= kCertificationBand * root.scale) headings.push_back(root.heading);
  }
  return headings;
}

std::vector<double> wedge_step_headings(const PushChecker& checker, const Pose& at, int pusher, double first,
                                        int count) {
  static constexpr double kTranslationOffsetsDeg[] = {0.0, -0.25, 0.25, -0.5, 0.5, -1.0, 1.0, -2.0, 2.0, -4.0, 4.0};
  std::vector<double> headings;
  for (int k = 0; k < count; ++k) headings.push_back(first + 2.0 * M_PI * k / count);
  for (const double translation : checker.wedge_translation_headings(at, pusher))
    for (const double offset_deg : kTranslationOffsetsDeg) headings.push_back(translation + offset_deg * M_PI / 180.0);
  return headings;
}

std::vector<Vec2> StablePushValidator::pivot_points() const {
  std::vector<Vec2> points;
  for (const Pad& pad : models_.front()->gripper().pads())
    if (std::none_of(points.begin(), points.end(), [&](const Vec2& p) { return p == pad.center; }))
      points.push_back(pad.center);
  return points;
}

double StablePushValidator::push_margin(const Pose& a, const Pose& b, int pusher) const {
  return worst_case(models_, a, b - a, pusher).margin;
}

std::optional<Pose> StablePushValidator::onto_wedge_surface(const Pose& a, const Eigen::Vector3d& direction,
                                                            double length, int pusher) const {
  if (!contains(wedges_, pusher)) return std::nullopt;
  const double heading_norm = std::hypot(direction[0], direction[1]);
  if (!(heading_norm > 1e-9 * direction.norm())) return std::nullopt;
  const double hx = direction[0] / heading_norm, hz = direction[1] / heading_norm;
  const StablePushModel& model = *models_.front();
  const Wrench& plane_normal = model.pusher_cones()[pusher].equality_rows().front();
  // Every evaluation is from a, so its R(theta) is taken once, and the grid's sines and cosines
  // once per process: sines and cosines were a large part of each evaluation (docs/measured.md).
  const PoseAndRotation from(a);
  const auto motion = [&](double cos_beta, double sin_beta) {
    return space_.from_unit_steps(length * Eigen::Vector3d(cos_beta * hx, cos_beta * hz, sin_beta));
  };
  struct Off {
    double beta;
    double off;    ///< e . w(a, dq(beta)) [N]
    double scale;  ///< the motion wrench's scale there (MotionWrench::scale)
  };
  const auto off_plane = [&](double beta, double cos_beta, double sin_beta) {
    const MotionWrench load = model.motion_wrench(from, motion(cos_beta, sin_beta), pusher);
    return Off{beta, plane_normal.dot(load.required), load.scale};
  };
  // The grid in beta [deg], finer toward pure rotation, where a peg's roots crowd (a motion whose
  // translation is small against its rotation in unit steps); in radians with its cosines and sines.
  static constexpr double kGridDeg[] = {-89.95, -89.5, -88, -85, -80, -70, -60, -50, -40, -30, -20,  -10,  0,
                                        10,     20,    30,  40,  50,  60,  70,  80,  85,  88,  89.5, 89.95};
  constexpr std::size_t kGrid = std::size(kGridDeg);
  struct GridAngle {
    double beta, cos_beta, sin_beta;
  };
  static const std::array<GridAngle, kGrid> kGridAngles = [] {
    std::array<GridAngle, kGrid> angles;
    for (std::size_t i = 0; i < kGrid; ++i) {
      const double beta = kGridDeg[i] * M_PI / 180.0;
      angles[i] = {beta, std::cos(beta), std::sin(beta)};
    }
    return angles;
  }();
  const double beta0 = std::atan2(direction[2], heading_norm);
  // The brackets between neighbouring grid angles, nearest beta0 first, each evaluated when its
  // turn comes: once one is farther from beta0 than the root found, no root in it or beyond can be
  // nearer, so neither it nor they are evaluated. The answer is a scan's over every bracket (the
  // root nearest beta0, the lower one on a tie), bit for bit, with a fifth fewer evaluations of
  // the motion wrench on the generated pin tasks (docs/measured.md).
  std::array<std::pair<double, std::size_t>, kGrid - 1> brackets;  // (distance from beta0, upper index)
  for (std::size_t i = 1; i < kGrid; ++i)
    brackets[i - 1] = {std::max({0.0, kGridAngles[i - 1].beta - beta0, beta0 - kGridAngles[i].beta}), i};
  std::sort(brackets.begin(), brackets.end());
  std::array<std::optional<Off>, kGrid> grid;
  const auto at_grid = [&](std::size_t i) -> const Off& {
    if (!grid[i]) grid[i] = off_plane(kGridAngles[i].beta, kGridAngles[i].cos_beta, kGridAngles[i].sin_beta);
    return *grid[i];
  };
  std::optional<double> best;
  for (const auto& [distance, upper] : brackets) {
    if (best && distance > std::abs(*best - beta0)) break;
    if ((at_grid(upper - 1).off < 0.0) == (at_grid(upper).off < 0.0)) continue;
    const Off root = refine_sign_change(*grid[upper - 1], *grid[upper], &Off::beta, &Off::off, [&](double beta) {
      return std::optional<Off>(off_plane(beta, std::cos(beta), std::sin(beta)));
    });
    // A sign change across a jump (a pad point's slip reversing) is not a root.
    const bool on_plane = std::abs(root.off) <= kCertificationBand * root.scale;
    const double d = std::abs(root.beta - beta0);
    if (on_plane && (!best || d < std::abs(*best - beta0) || (d == std::abs(*best - beta0) && root.beta < *best)))
      best = root.beta;
  }
  if (!best) return std::nullopt;
  return a + motion(std::cos(*best), std::sin(*best));
}

double StablePushValidator::wedge_plane_offset(const Pose& a, const Motion& dq, int pusher) const {
  if (!contains(wedges_, pusher)) return std::numeric_limits<double>::quiet_NaN();
  const StablePushModel& model = *models_.front();
  const MotionWrench load = model.motion_wrench(a, dq, pusher);
  return model.pusher_cones()[pusher].equality_rows().front().dot(load.required) / load.scale;
}

PusherSet PushChecker::stable_pushers_preferring(const Pose& a, const Pose& b, PusherSet candidates,
                                                 PusherSet preferred) const {
  if ((candidates & preferred) == 0 || (candidates & ~preferred) == 0) return stable_pushers(a, b, candidates);
  const PusherSet first = stable_pushers(a, b, candidates & preferred);
  return first != 0 ? first : stable_pushers(a, b, candidates & ~preferred);
}

PusherSet StablePushValidator::stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const {
  const std::vector<Pose> poses = space_.unit_pushes(a, b);
  for (std::size_t i = 0; i + 1 < poses.size() && candidates != 0; ++i)
    candidates = stable_in_unit_push(poses[i], poses[i + 1], candidates, 0);
  return candidates;
}

PusherSet StablePushValidator::stable_pushers_preferring(const Pose& a, const Pose& b, PusherSet candidates,
                                                         PusherSet preferred) const {
  const std::vector<Pose> poses = space_.unit_pushes(a, b);
  if (poses.size() != 2) return PushChecker::stable_pushers_preferring(a, b, candidates, preferred);
  return stable_in_unit_push(poses[0], poses[1], candidates, preferred);
}

PusherSet StablePushValidator::stable_in_unit_push(const Pose& from, const Pose& to, PusherSet candidates,
                                                   PusherSet preferred) const {
  if (candidates == 0) return 0;
  const StablePushModel& geometry = *models_.front();
  if (!geometry.gripper().grasp_maintained_along(geometry.section(), from, to)) return 0;
  const Motion dq = to - from;
  const int models = static_cast<int>(models_.size());
  // One motion wrench per model serves every pusher whose gravity is the same (all of them,
  // unless the features hold the object at different world orientations; see GravityFrame).
  std::array<int, kMaxModels> loaded_for;
  loaded_for.fill(-1);
  std::array<MotionWrench, kMaxModels> loads;
  PusherSet stable = 0;
  for (const PusherSet group : {candidates & preferred, candidates & ~preferred}) {
    for (int p = 0; p < kMaxPushers; ++p) {
      if (!contains(group, p)) continue;
      ++checks_;
      bool stable_in_every_model = true;
      for (int m = 0; m < models && stable_in_every_model; ++m) {
        const StablePushModel& model = *models_[m];
        if (loaded_for[m] < 0 || !model.same_gravity(loaded_for[m], p)) {
          loads[m] = model.motion_wrench(from, dq, p);
          loaded_for[m] = p;
        }
        const PushResult r = model.check(loads[m], from, dq, p);
        stable_in_every_model = r.feasible && r.margin >= min_margin_;
      }
      if (stable_in_every_model) stable |= PusherSet{1} << p;
    }
    if (stable != 0) break;  // the preferred pushers that work, or (none preferred) every one that does
  }
  return stable;
}

PushResult worst_case(const ModelSet& models, const Pose& q, const Motion& dq, int pusher) {
  if (models.empty()) throw std::invalid_argument("worst_case needs at least one model");
  PushResult worst = models.front()->check(q, dq, pusher);
  for (std::size_t m = 1; m < models.size(); ++m) {
    const PushResult r = models[m]->check(q, dq, pusher);
    if ((!r.feasible && worst.feasible) || (r.feasible == worst.feasible && r.margin < worst.margin)) worst = r;
  }
  return worst;
}

bool StablePushValidator::checkMotion(const ob::State* a, const ob::State* b) const {
  const bool ok = stable_pushers(GraspPoseSpace::pose(a), GraspPoseSpace::pose(b), all_) != 0;
  (ok ? valid_ : invalid_)++;
  return ok;
}

bool StablePushValidator::checkMotion(const ob::State* a, const ob::State* b,
                                      std::pair<ob::State*, double>& last_valid) const {
  // The longest prefix of whole unit pushes that one pusher makes stable.
  const std::vector<Pose> poses = space_.unit_pushes(GraspPoseSpace::pose(a), GraspPoseSpace::pose(b));
  const std::size_t n = poses.size() - 1;
  PusherSet alive = all_;
  std::size_t done = 0;
  for (; done < n; ++done) {
    const PusherSet next = stable_pushers(poses[done], poses[done + 1], alive);
    if (next == 0) break;
    alive = next;
  }
  if (done == n) {
    valid_++;
    return true;
  }
  if (last_valid.first != nullptr) GraspPoseSpace::set_pose(last_valid.first, poses[done]);
  last_valid.second = static_cast<double>(done) / n;
  invalid_++;
  return false;
}

PoseGoal::PoseGoal(const ob::SpaceInformationPtr& si, const Pose& goal, StepSize tolerance, ModelSet hold,
                   double min_hold_ratio)
    : ob::GoalSampleableRegion(si),
      space_(*si->getStateSpace()->as<GraspPoseSpace>()),
      goal_(goal),
      tolerance_(tolerance),
      hold_(min_hold_ratio > 0.0 ? std::move(hold) : ModelSet{}),
      min_hold_ratio_(min_hold_ratio) {
  // OMPL's threshold: no state farther than this (unit steps) from the goal pose satisfies it.
  const double x = tolerance_.length / space_.step().length;
  const double t = tolerance_.angle / space_.step().angle;
  setThreshold(std::sqrt(2.0 * x * x + t * t));
}

bool PoseGoal::contains(const Pose& q) const {
  return std::abs(q.x - goal_.x) <= tolerance_.length && std::abs(q.z - goal_.z) <= tolerance_.length &&
         std::abs(q.theta - goal_.theta) <= tolerance_.angle;
}

double PoseGoal::offset(const Pose& q) const {
  return std::max({std::abs(q.x - goal_.x) / tolerance_.length, std::abs(q.z - goal_.z) / tolerance_.length,
                   std::abs(q.theta - goal_.theta) / tolerance_.angle});
}

bool PoseGoal::held(const Pose& q, int last_pusher) const {
  for (const StablePushModel* model : hold_)
    if (model->hold_ratio(q, last_pusher) < min_hold_ratio_) return false;
  return true;
}

bool PoseGoal::isSatisfied(const ob::State* s, double* distance) const {
  if (distance != nullptr) *distance = distanceGoal(s);
  return isSatisfied(s);
}

double PoseGoal::distanceGoal(const ob::State* s) const { return space_.distance(GraspPoseSpace::pose(s), goal_); }

void PoseGoal::sampleGoal(ob::State* s) const { GraspPoseSpace::set_pose(s, goal_); }

}  // namespace stablepush
