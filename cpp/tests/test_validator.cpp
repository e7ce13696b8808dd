// StablePushValidator on the model itself: a point pusher's surface of stable pushes
// (docs/model.md section 3), found as a root in the motion's elevation.
#include <ompl/base/SpaceInformation.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "stablepush/internal/grasp_space.hpp"
#include "stablepush/internal/trrt_star.hpp"

using namespace stablepush;
namespace ob = ompl::base;

namespace {
/// The grid onto_wedge_surface brackets its roots on [deg], as in grasp_space.cpp (a copy: a
/// change there must be made here too).
constexpr double kGridDeg[] = {-89.95, -89.5, -88, -85, -80, -70, -60, -50, -40, -30, -20,  -10,  0,
                               10,     20,    30,  40,  50,  60,  70,  80,  85,  88,  89.5, 89.95};

/// The pegs' cube (data/tasks/more/cube-pegs.yaml): 40 mm, 100 g, pads at the centre, a peg on
/// the left face 6 mm above the centre and one under the bottom face 5 mm right of it.
StablePushModel cube_with_pegs() {
  const CrossSection cube = CrossSection::box(0.04, 0.04);
  const Gripper gripper({Pad{Vec2::Zero(), 0.005}, Pad{Vec2::Zero(), 0.005}}, 10.0, 0.5, 1);
  std::vector<Pusher> pegs = {Pusher::on_boundary(cube, "peg-left", Vec2(-0.02, 0.006), Vec2(-0.02, 0.006), 0.5, 1),
                              Pusher::on_boundary(cube, "peg-bottom", Vec2(0.005, -0.02), Vec2(0.005, -0.02), 0.5, 1)};
  return StablePushModel(cube, RigidBody::uniform(cube, 0.1), gripper, std::move(pegs), Vec2(0.0, -9.81), 0.1);
}

/// The pegs' model, its grasp poses (x, z within 20 mm, theta within 0.02 rad; unit steps of
/// 0.5 mm and 0.5 deg) and a validator on them.
struct Pegs {
  Pegs() { ompl::msg::setLogLevel(ompl::msg::LOG_WARN); }
  static std::shared_ptr<GraspPoseSpace> make_space() {
    ob::RealVectorBounds bounds(3);
    bounds.setLow(-0.02);
    bounds.setHigh(0.02);
    return std::make_shared<GraspPoseSpace>(StepSize{0.5e-3, 0.5 * M_PI / 180.0}, bounds);
  }
  const StablePushModel model = cube_with_pegs();
  const std::shared_ptr<GraspPoseSpace> space = make_space();
  // Kept here: the validator (an OMPL MotionValidator) holds a raw pointer to it.
  const ob::SpaceInformationPtr si = std::make_shared<ob::SpaceInformation>(space);
  const StablePushValidator validator{si, ModelSet{&model}, 0.0};
};

/// The grid bracket [deg] that holds `beta` [rad]: the index of its upper end.
std::size_t bracket_of(double beta) {
  std::size_t i = 1;
  while (i + 1 < std::size(kGridDeg) && beta > kGridDeg[i] * M_PI / 180.0) ++i;
  return i;
}

/// e . w(a, dq(beta)) and the motion wrench's scale, for a point pusher's plane normal e.
struct OffPlane {
  const StablePushModel& model;
  const GraspPoseSpace& space;
  Pose a;
  double hx, hz, length;
  int pusher;
  Eigen::Vector3d motion(double beta) const {
    return Eigen::Vector3d(std::cos(beta) * hx, std::cos(beta) * hz, std::sin(beta)) * length;
  }
  std::pair<double, double> operator()(double beta) const {
    const MotionWrench load = model.motion_wrench(a, space.from_unit_steps(motion(beta)), pusher);
    return {model.pusher_cones()[pusher].equality_rows().front().dot(load.required), load.scale};
  }
};

/// The root nearest `beta0` over every grid bracket, each bisected, the lower one on a tie: where
/// onto_wedge_surface's answer must lie, found plainly (every bracket, no regula falsi). A bracket
/// may hold several roots, which the two refinements need not agree on, so only the bracket is
/// compared (and in other cases than these that could make the two disagree on the bracket).
std::optional<double> nearest_root_by_scan(const OffPlane& off, double beta0) {
  std::optional<double> best;
  for (std::size_t i = 1; i < std::size(kGridDeg); ++i) {
    double lo = kGridDeg[i - 1] * M_PI / 180.0, hi = kGridDeg[i] * M_PI / 180.0;
    const bool lo_negative = off(lo).first < 0.0;
    if (lo_negative == (off(hi).first < 0.0)) continue;
    for (;;) {  // to adjacent doubles
      const double mid = 0.5 * (lo + hi);
      if (!(mid > lo && mid < hi)) break;
      (off(mid).first < 0.0) == lo_negative ? lo = mid : hi = mid;
    }
    const double root = std::abs(off(lo).first) <= std::abs(off(hi).first) ? lo : hi;
    const auto [value, scale] = off(root);
    if (std::abs(value) > kCertificationBand * scale) continue;  // a jump, not a root
    if (!best || std::abs(root - beta0) < std::abs(*best - beta0)) best = root;
  }
  return best;
}
}  // namespace

TEST_CASE_METHOD(Pegs,
                 "onto a point pusher's surface: the root nearest the direction's elevation, as a full scan finds it",
                 "[validator]") {
  REQUIRE(validator.wedge_pushers() == 0b11);

  // Poses about the start, headings all round, elevations from none to near pure rotation:
  // onto_wedge_surface refines the brackets nearest the elevation first and stops early, and must
  // still answer a root on the plane from the bracket where a scan of every bracket finds the
  // nearest: stopping at the first root found (`if (best) break;` for the distance test) fails 10
  // of these checks. That the root is the old scan's bit for bit is checked by the plans
  // themselves (benchmarks/plan_fingerprint.py), not here.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> offset(-0.004, 0.004), turn(-0.3, 0.3), heading(-M_PI, M_PI),
      elevation(-1.5, 1.5), length(0.25, 1.0);
  int found = 0, cases = 0;
  for (int k = 0; k < 2000; ++k) {
    const Pose a{offset(rng), offset(rng), turn(rng)};
    const double psi = heading(rng), beta0 = k % 4 == 0 ? 0.0 : elevation(rng), l = length(rng);
    const Eigen::Vector3d direction(std::cos(beta0) * std::cos(psi), std::cos(beta0) * std::sin(psi), std::sin(beta0));
    for (int pusher = 0; pusher < 2; ++pusher) {
      ++cases;
      const std::optional<Pose> q = validator.onto_wedge_surface(a, direction, l, pusher);
      const OffPlane off{model, *space, a, std::cos(psi), std::sin(psi), l, pusher};
      const std::optional<double> expected = nearest_root_by_scan(off, beta0);
      REQUIRE(q.has_value() == expected.has_value());
      if (!q) continue;
      ++found;
      const Eigen::Vector3d dq = space->in_unit_steps(*q - a);
      const double beta = std::atan2(dq[2], std::hypot(dq[0], dq[1]));
      CHECK(bracket_of(beta) == bracket_of(*expected));
      const auto [value, scale] = off(beta);
      CHECK(std::abs(value) <= 1e-6 * scale);  // on the plane (beta recovered from q, to rounding)
      CHECK(std::abs(dq.norm() - l) < 1e-9);   // the length asked for
      CHECK(std::abs(std::remainder(std::atan2(dq[1], dq[0]) - psi, 2 * M_PI)) < 1e-9);  // and its heading
    }
  }
  CHECK(cases == 4000);
  CHECK(found > 2000);  // most headings meet the surface
}

TEST_CASE("refine_sign_change: a root to rounding where the function is continuous, a large value beside a jump",
          "[validator]") {
  struct Point {
    double x, f;
  };
  const auto at = [](const auto& function) {
    return [&function](double x) { return std::optional<Point>(Point{x, function(x)}); };
  };
  const auto smooth = [](double x) { return std::cos(x) - x; };  // one root, 0.739085133215160642 (Dottie)
  const Point root =
      refine_sign_change(Point{0.0, smooth(0.0)}, Point{1.0, smooth(1.0)}, &Point::x, &Point::f, at(smooth));
  CHECK(std::abs(root.x - 0.739085133215160642) <= 2e-16);
  CHECK(std::abs(root.f) <= 4e-16);
  const auto jump = [](double x) { return x < 0.3 ? -1.0 : 1.0; };
  const Point beside = refine_sign_change(Point{0.0, -1.0}, Point{1.0, 1.0}, &Point::x, &Point::f, at(jump));
  CHECK(std::abs(beside.x - 0.3) <= 1e-15);
  CHECK(std::abs(beside.f) == 1.0);  // not a root: callers refuse it by its size
  // `at` may end the search: the bracket's own ends come back, the smaller in magnitude.
  const Point stopped = refine_sign_change(Point{0.0, -2.0}, Point{1.0, 1.0}, &Point::x, &Point::f,
                                           [](double) { return std::optional<Point>(); });
  CHECK(stopped.x == 1.0);
}

TEST_CASE_METHOD(Pegs, "wedge_plane_offset: within the certification band on a point pusher's surface, outside off it",
                 "[validator]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> offset(-0.004, 0.004), turn(-0.3, 0.3), heading(-M_PI, M_PI);
  int on = 0;
  for (int k = 0; k < 500; ++k) {
    const Pose a{offset(rng), offset(rng), turn(rng)};
    const double psi = heading(rng);
    for (int pusher = 0; pusher < 2; ++pusher) {
      const std::optional<Pose> q =
          validator.onto_wedge_surface(a, Eigen::Vector3d(std::cos(psi), std::sin(psi), 0.0), 1.0, pusher);
      if (!q) continue;
      ++on;
      const Motion dq = *q - a;
      CHECK(std::abs(validator.wedge_plane_offset(a, dq, pusher)) <= kCertificationBand);
      // A turn of 0.001 deg off the surface leaves the band.
      const Motion off{dq.dx, dq.dz, dq.dtheta + 1e-3 * M_PI / 180.0};
      CHECK(std::abs(validator.wedge_plane_offset(a, off, pusher)) > kCertificationBand);
    }
  }
  CHECK(on > 500);
  CHECK(std::isnan(validator.wedge_plane_offset(Pose{0.0, 0.0, 0.0}, Motion{1e-3, 0.0, 0.0}, 2)));  // not a wedge
}

TEST_CASE_METHOD(
    Pegs, "wedge_translation_headings: the pure translations on a point pusher's surface, as a fine scan finds them",
    "[validator]") {
  // Every sign change of e . w over a fine ring of pure translations that is a root (not a jump,
  // bisected to adjacent doubles) must be answered within half the ring's spacing, and nothing
  // else; at each heading answered a translation is on the surface, where onto_wedge_surface finds
  // its root with no turn.
  constexpr int kRing = 720;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> offset(-0.004, 0.004), turn(-0.3, 0.3);
  int answered = 0;
  for (int k = 0; k < 60; ++k) {
    const Pose a{offset(rng), offset(rng), turn(rng)};
    for (int pusher = 0; pusher < 2; ++pusher) {
      const auto off = [&](double psi) {
        return validator.wedge_plane_offset(
            a, space->from_unit_steps(Eigen::Vector3d(std::cos(psi), std::sin(psi), 0.0)), pusher);
      };
      std::vector<double> scanned;
      for (int i = 0; i < kRing; ++i) {
        double lo = 2.0 * M_PI * i / kRing, hi = 2.0 * M_PI * (i + 1) / kRing;
        const bool lo_negative = off(lo) < 0.0;
        if (lo_negative == (off(hi) < 0.0)) continue;
        for (;;) {
          const double mid = 0.5 * (lo + hi);
          if (!(mid > lo && mid < hi)) break;
          (off(mid) < 0.0) == lo_negative ? lo = mid : hi = mid;
        }
        if (std::min(std::abs(off(lo)), std::abs(off(hi))) <= kCertificationBand) scanned.push_back(lo);
      }
      const std::vector<double> headings = validator.wedge_translation_headings(a, pusher);
      INFO("case " << k << ", pusher " << pusher);
      REQUIRE(headings.size() == scanned.size());
      for (std::size_t i = 0; i < headings.size(); ++i) {
        ++answered;
        const double h = headings[i];
        CHECK(std::abs(std::remainder(h - scanned[i], 2.0 * M_PI)) < M_PI / kRing);
        CHECK(std::abs(off(h)) <= kCertificationBand);
        const std::optional<Pose> q =
            validator.onto_wedge_surface(a, Eigen::Vector3d(std::cos(h), std::sin(h), 0.0), 1.0, pusher);
        REQUIRE(q.has_value());
        CHECK(std::abs((*q - a).dtheta) < 1e-6 * space->step().angle);
      }
    }
  }
  CHECK(answered >= 200);  // two opposite headings per surface, nearly always
  CHECK(validator.wedge_translation_headings(Pose{0.0, 0.0, 0.0}, 2).empty());  // not a wedge
}

namespace {
/// The pegs' validator, counting the roots asked of it.
struct CountingChecker : PushChecker {
  explicit CountingChecker(const StablePushValidator& v) : validator(v) {}
  PusherSet all_pushers() const override { return validator.all_pushers(); }
  PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const override {
    return validator.stable_pushers(a, b, candidates);
  }
  double push_margin(const Pose& a, const Pose& b, int pusher) const override {
    return validator.push_margin(a, b, pusher);
  }
  PusherSet wedge_pushers() const override { return validator.wedge_pushers(); }
  std::optional<Pose> onto_wedge_surface(const Pose& a, const Eigen::Vector3d& direction, double length,
                                         int pusher) const override {
    ++roots;
    return validator.onto_wedge_surface(a, direction, length, pusher);
  }
  std::vector<double> wedge_translation_headings(const Pose& a, int pusher) const override {
    return validator.wedge_translation_headings(a, pusher);
  }
  std::uint64_t feasibility_checks() const override { return validator.feasibility_checks(); }
  void reset_feasibility_checks() override {}
  const StablePushValidator& validator;
  mutable long roots = 0;
};
}  // namespace

TEST_CASE_METHOD(Pegs, "WedgeStepQueue: the steps of a full sort, in its order, the first found with fewer roots",
                 "[trrt_star]") {
  // From poses about the start toward goals a few unit steps away (some within a step, so that
  // steps end the plan, some from inside the box, half of them with the pads to hold the goal, some
  // straight up in theta, some ranked against a pose other than the box's centre), the queue must
  // give every step onto the pegs' surfaces that a full sort of all of them gives, bit for bit and
  // in the same order: those that end the plan first, then nearest the goal, ties in the order
  // (pusher, length, heading). A bound above a step's distance fails this (one with 1e-3 unit
  // steps of slack added fails some 2,700 of its checks).
  const CountingChecker checker(validator);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> offset(-0.004, 0.004), turn(-0.3, 0.3), away(-3.0, 3.0);
  const StepSize unit{0.5e-3, 0.5 * M_PI / 180.0};
  const std::vector<std::vector<double>> length_sets = {{1.0}, {0.5, 0.25}, {0.7}};
  long candidates = 0, first_roots = 0, steps = 0, ending = 0, inside = 0, not_held = 0;
  for (int k = 0; k < 300; ++k) {
    const Pose from{offset(rng), offset(rng), turn(rng)};
    const double reach = k % 3 == 0 ? 0.4 : 1.0;  // a third within a step or so of the goal
    const double up = k % 10 == 5 ? 0.0 : 1.0;    // a tenth with no translation to the goal
    const Pose centre = from + Motion{up * reach * away(rng) * unit.length, up * reach * away(rng) * unit.length,
                                      reach * away(rng) * unit.angle};
    const bool hold = k % 2 == 1;
    // The pads hold the cube some 8-10 times over about the start: a ratio some steps miss.
    constexpr double kHoldRatio = 9.0;
    const PoseGoal region(si, centre, unit, hold ? ModelSet{&model} : ModelSet{}, hold ? kHoldRatio : 0.0);
    // A seventh ranked against a pose half a step off the box's centre.
    const Pose goal = k % 7 == 3 ? centre + Motion{0.5 * unit.length, -0.3 * unit.length, 0.2 * unit.angle} : centre;
    const bool outside = !region.contains(from);
    inside += outside ? 0 : 1;
    const std::vector<double>& lengths = length_sets[k % length_sets.size()];

    // Every step, as the queue asks for them: its headings (wedge_step_headings) and, copied, its
    // direction at each (a change there must be made here).
    std::vector<WedgeStep> expected;
    const Eigen::Vector3d to_goal = space->in_unit_steps(goal - from);
    const double heading = std::atan2(to_goal[1], to_goal[0]);
    const double translation = std::max(std::hypot(to_goal[0], to_goal[1]), 1e-3);
    for (int p = 0; p < 2; ++p) {
      const std::vector<double> headings = wedge_step_headings(validator, from, p, heading, 24);
      for (const double length : lengths)
        for (const double psi : headings) {
          const Eigen::Vector3d direction =
              Eigen::Vector3d(std::cos(psi) * translation, std::sin(psi) * translation, to_goal[2]).normalized();
          ++candidates;
          if (const std::optional<Pose> q = validator.onto_wedge_surface(from, direction, length, p)) {
            const bool in_box = outside && region.contains(*q);
            expected.push_back({space->distance(*q, goal), *q, p, in_box && region.held(*q, p)});
            if (in_box && !expected.back().ends_plan) ++not_held;
          }
        }
    }
    std::stable_sort(expected.begin(), expected.end(), [](const WedgeStep& a, const WedgeStep& b) {
      return a.ends_plan != b.ends_plan ? a.ends_plan : a.goal_distance < b.goal_distance;
    });

    checker.roots = 0;
    WedgeStepQueue queue(checker, *space, region, from, goal, lengths, 0b11);
    std::vector<WedgeStep> given;
    while (const std::optional<WedgeStep> step = queue.next()) {
      given.push_back(*step);
      if (given.size() == 1) first_roots += checker.roots;
    }
    REQUIRE(given.size() == expected.size());
    for (std::size_t i = 0; i < given.size(); ++i) {
      INFO("case " << k << ", step " << i);
      CHECK(given[i].pusher == expected[i].pusher);
      CHECK(given[i].pose.x == expected[i].pose.x);
      CHECK(given[i].pose.z == expected[i].pose.z);
      CHECK(given[i].pose.theta == expected[i].pose.theta);
      CHECK(given[i].goal_distance == expected[i].goal_distance);
      CHECK(given[i].ends_plan == expected[i].ends_plan);
    }
    steps += static_cast<long>(given.size());
    ending += std::count_if(given.begin(), given.end(), [](const WedgeStep& s) { return s.ends_plan; });
  }
  CHECK(steps > candidates / 2);        // most headings meet a surface
  CHECK(ending > 100);                  // the steps that end the plan were among them
  CHECK(inside > 10);                   // and starts within the tolerance box
  CHECK(not_held > 10);                 // and steps into the box where the pads do not hold the object
  CHECK(first_roots < candidates / 2);  // the first step needs few of the roots
}

TEST_CASE_METHOD(Pegs, "WedgeStepQueue: a peg's translating push comes first where the goal lies off its heading",
                 "[trrt_star]") {
  // Toward a goal 3 unit steps away at 37 deg from a peg's translation heading, the unit step of
  // pure translation ends sqrt(10 - 6 cos 37 deg) = 2.28 steps from it; the steps at the evenly
  // spaced headings (from the goal's, every 15 deg: the nearest 7 deg off) are near-pure turns,
  // which end farther than the start. The queue's first step must be at least as near as the
  // translation.
  const CountingChecker checker(validator);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> offset(-0.004, 0.004), turn(-0.3, 0.3);
  int cases = 0;
  for (int k = 0; k < 40; ++k) {
    const Pose from{offset(rng), offset(rng), turn(rng)};
    for (int pusher = 0; pusher < 2; ++pusher) {
      for (const double t : validator.wedge_translation_headings(from, pusher)) {
        const double side = k % 2 == 0 ? 1.0 : -1.0;
        const double psi = t + side * 37.0 * M_PI / 180.0;
        const Pose goal = from + space->from_unit_steps(Eigen::Vector3d(3.0 * std::cos(psi), 3.0 * std::sin(psi), 0.0));
        const PoseGoal region(si, goal, StepSize{0.1e-3, 0.1 * M_PI / 180.0});
        const std::optional<Pose> translated =
            validator.onto_wedge_surface(from, Eigen::Vector3d(std::cos(t), std::sin(t), 0.0), 1.0, pusher);
        // Where the surface meets pure translation at a jump the root is not that translation.
        if (!translated || std::abs((*translated - from).dtheta) > 1e-6 * space->step().angle) continue;
        const double by_translation = space->distance(*translated, goal);
        REQUIRE(std::abs(by_translation - std::sqrt(10.0 - 6.0 * std::cos(37.0 * M_PI / 180.0))) < 1e-9);
        WedgeStepQueue queue(checker, *space, region, from, goal, {1.0}, PusherSet{1} << pusher);
        const std::optional<WedgeStep> first = queue.next();
        REQUIRE(first.has_value());
        CHECK(first->goal_distance <= by_translation + 1e-12);
        ++cases;
      }
    }
  }
  CHECK(cases >= 100);
}
