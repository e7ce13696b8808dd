// The mechanics against cases derived by hand: a point pusher's friction cone, the motion wrench
// of a pure translation, and the swept grasp test (docs/model.md sections 1-2; paper section IV).
#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>

#include "stablepush/cross_section.hpp"
#include "stablepush/friction_cone.hpp"
#include "stablepush/gripper.hpp"
#include "stablepush/pusher.hpp"
#include "stablepush/rigid_body.hpp"
#include "stablepush/stable_push.hpp"

using namespace stablepush;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {
constexpr double kLength = 0.1;   // box along x [m]
constexpr double kHeight = 0.05;  // box along z [m]

/// Whether w is a positive multiple of `ray` (both wrenches).
bool along(const Wrench& w, const Wrench& ray) {
  return w.cross(ray).norm() <= 1e-12 * w.norm() * ray.norm() && w.dot(ray) > 0;
}
}  // namespace

TEST_CASE("a point pusher's cone is the wedge of its friction-cone edges n +- mu t", "[friction_cone]") {
  const CrossSection box = CrossSection::box(kLength, kHeight);
  const double mu = 0.3;
  const double h = kHeight / 2;
  // A point at the middle of the bottom edge, r = (0, -h): inward normal n = +z, tangent t = +x.
  const Pusher pin = Pusher::on_boundary(box, "pin", Vec2(0, -h), Vec2(0, -h), mu, 1);
  REQUIRE(pin.inward_normal.isApprox(Vec2(0, 1)));
  // Force f = (f_x, f_z) at r has the torque tau_y = r_z f_x - r_x f_z = -h f_x.
  const Wrench edge_plus(mu, 1.0, -h * mu);
  const Wrench edge_minus(-mu, 1.0, h * mu);
  const std::vector<Wrench> generators = pin.cone_generators();
  REQUIRE(generators.size() == 2);
  CHECK(((along(generators[0], edge_plus) && along(generators[1], edge_minus)) ||
         (along(generators[0], edge_minus) && along(generators[1], edge_plus))));

  const WrenchCone cone(generators, box.circumradius());
  CHECK(cone.dimension() == 2);
  // A pure normal push lies in the wedge's plane; a pure torque does not.
  CHECK_THAT(cone.distance_to_span(Wrench(0.0, 1.0, 0.0)), WithinAbs(0.0, 1e-12));
  CHECK(cone.distance_to_span(Wrench(0.0, 0.0, 1.0)) > 0.1);
  // In the plane, inside the wedge iff |f_x| < mu f_z: every facet row is negative only inside.
  const auto inside = [&](const Wrench& w) {
    for (const Wrench& row : cone.facet_rows())
      if (row.dot(w) >= 0) return false;
    return true;
  };
  CHECK(inside(Wrench(0.5 * mu, 1.0, -h * 0.5 * mu)));
  CHECK_FALSE(inside(Wrench(2.0 * mu, 1.0, -h * 2.0 * mu)));
}

TEST_CASE("a pure translation's motion wrench is the inertia plus all the pads' sliding friction", "[motion_wrench]") {
  // No gravity, pads centred at O's origin: every pad point slides against the motion, so the
  // pads' friction is mu N per pad along -dx and has no torque about O (the points are
  // symmetric). Paper eq. 5: w_required = M xi / dt - w_sliding, xi = dq / dt.
  const double mass = 0.2, grip_force = 10.0, mu = 0.5, dt = 0.1, dx = 1e-3;
  const CrossSection box = CrossSection::box(kLength, kHeight);
  const Gripper gripper({Pad{Vec2(0, 0), 0.005}, Pad{Vec2(0, 0), 0.005}}, grip_force, mu, 2);
  const std::vector<Pusher> pushers = {
      Pusher::on_boundary(box, "left", Vec2(-kLength / 2, -0.01), Vec2(-kLength / 2, 0.01), 0.5, 3)};
  const StablePushModel model(box, RigidBody::uniform(box, mass), gripper, pushers, Vec2(0, 0), dt);

  const MotionWrench load = model.motion_wrench(Pose{0, 0, 0}, Motion{dx, 0, 0}, 0);
  CHECK(load.sticking.empty());
  CHECK_THAT(load.required.x(), WithinRel(mass * dx / (dt * dt) + 2 * mu * grip_force, 1e-9));
  CHECK_THAT(load.required.y(), WithinAbs(0.0, 1e-9));
  CHECK_THAT(load.required.z(), WithinAbs(0.0, 1e-9));

  // The left pusher touches the -x face with normal +x: pushing along +x is inside its cone when
  // nothing else loads the object.
  CHECK(model.check(Pose{0, 0, 0}, Motion{dx, 0, 0}, 0).feasible);
  // It cannot pull the object along -x.
  CHECK_FALSE(model.check(Pose{0, 0, 0}, Motion{-dx, 0, 0}, 0).feasible);
}

TEST_CASE("the swept grasp test: a pad disc swept along a motion stays inside the section", "[grasp]") {
  const CrossSection box = CrossSection::box(kLength, kHeight);
  // Capsule of radius 10 mm along x: inside while its ends' discs stay within x = +-50 mm.
  CHECK(box.contains_capsule(Vec2(-0.02, 0), Vec2(0.02, 0), 0.01));
  CHECK(box.contains_capsule(Vec2(-0.039, 0), Vec2(0.039, 0), 0.01));
  CHECK_FALSE(box.contains_capsule(Vec2(-0.02, 0), Vec2(0.045, 0), 0.01));
  // ...and within z = +-25 mm.
  CHECK_FALSE(box.contains_capsule(Vec2(0, 0), Vec2(0, 0.02), 0.01));

  // A pad of radius 5 mm at G's origin: the object moving by x in G moves the pad by -x in O.
  const Gripper gripper({Pad{Vec2(0, 0), 0.005}}, 10.0, 0.5, 1);
  CHECK(gripper.grasp_maintained_along(box, Pose{0, 0, 0}, Pose{0.044, 0, 0}));
  CHECK_FALSE(gripper.grasp_maintained_along(box, Pose{0, 0, 0}, Pose{0.046, 0, 0}));
  // Turning by 90 deg about the centre keeps the pad at the centre.
  CHECK(gripper.grasp_maintained_along(box, Pose{0, 0, 0}, Pose{0, 0, M_PI / 2}));
  // Through the whole motion, not only at its ends: a pad 30 mm off G's origin is inside the box
  // at theta 0 and 180 deg (on the long axis) but not at 90 deg, which a half turn passes.
  const Gripper off_centre({Pad{Vec2(0.03, 0), 0.005}}, 10.0, 0.5, 1);
  CHECK(off_centre.pads_inside(box, Pose{0, 0, 0})[0]);
  CHECK(off_centre.pads_inside(box, Pose{0, 0, M_PI})[0]);
  CHECK_FALSE(off_centre.grasp_maintained_along(box, Pose{0, 0, 0}, Pose{0, 0, M_PI}));
}
