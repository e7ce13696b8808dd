// pybind11 binding: a thin layer that names the core's types for Python. No logic lives here
// beyond converting poses (3-sequences) and batching checks for the benchmarks.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>

#include "stablepush/cross_section.hpp"
#include "stablepush/friction_cone.hpp"
#include "stablepush/gripper.hpp"
#include "stablepush/planning.hpp"
#include "stablepush/pusher.hpp"
#include "stablepush/rigid_body.hpp"
#include "stablepush/stable_push.hpp"

namespace py = pybind11;
using namespace stablepush;

namespace {
Pose to_pose(const std::array<double, 3>& q) { return Pose{q[0], q[1], q[2]}; }
Motion to_motion(const std::array<double, 3>& dq) { return Motion{dq[0], dq[1], dq[2]}; }
StepSize to_step(const std::array<double, 2>& s) { return StepSize{s[0], s[1]}; }

py::tuple to_tuple(const Pose& q) { return py::make_tuple(q.x, q.z, q.theta); }

/// A PushChecker written in Python (the toy checkers of the search's tests): subclass
/// _core.PushChecker and define all_pushers(), stable_pushers(a, b, candidates) and
/// push_margin(a, b, pusher); poses are (x m, z m, theta rad) tuples, pusher sets int bit masks.
class PyPushChecker : public PushChecker {
 public:
  PusherSet all_pushers() const override { return call("all_pushers").cast<PusherSet>(); }
  PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const override {
    ++checks_;
    return call("stable_pushers", to_tuple(a), to_tuple(b), candidates).cast<PusherSet>();
  }
  double push_margin(const Pose& a, const Pose& b, int pusher) const override {
    return call("push_margin", to_tuple(a), to_tuple(b), pusher).cast<double>();
  }
  std::uint64_t feasibility_checks() const override { return checks_; }
  void reset_feasibility_checks() override { checks_ = 0; }

 private:
  template <class... Args>
  py::object call(const char* name, Args&&... args) const {
    py::gil_scoped_acquire gil;
    const py::function f = py::get_override(static_cast<const PushChecker*>(this), name);
    if (!f) throw std::runtime_error(std::string("PushChecker.") + name + " is not defined");
    return f(std::forward<Args>(args)...);
  }
  mutable std::uint64_t checks_ = 0;
};

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "stablepush C++ core: contact models, generalized friction cones and the stable-push test (SI units)";
  m.attr("CERTIFICATION_BAND") = kCertificationBand;
  m.attr("STICKING_SPEED_RATIO") = kStickingSpeedRatio;

  py::class_<CrossSection>(m, "CrossSection", "The object's cross-section in O: a simple polygon [m].")
      .def(py::init<std::vector<Vec2>>(), py::arg("vertices"))
      .def_static("box", &CrossSection::box, py::arg("length_x"), py::arg("height_z"))
      .def_static("defect", &CrossSection::defect, py::arg("vertices"),
                  "Why the vertices are not a usable cross-section ('' when they are).")
      .def_property_readonly("vertices", &CrossSection::vertices)
      .def_property_readonly("area", &CrossSection::area)
      .def_property_readonly("centroid", &CrossSection::centroid)
      .def_property_readonly("polar_moment_about_centroid", &CrossSection::polar_moment_about_centroid)
      .def_property_readonly("circumradius", &CrossSection::circumradius)
      .def_property_readonly("convex", &CrossSection::convex)
      .def("contains_disc", &CrossSection::contains_disc, py::arg("center"), py::arg("radius"))
      .def("contains_capsule", &CrossSection::contains_capsule, py::arg("a"), py::arg("b"), py::arg("radius"),
           "Whether the disc of `radius` swept along the segment a-b lies inside the polygon.")
      .def("distance_to_boundary", &CrossSection::distance_to_boundary, py::arg("point"))
      .def("edges_holding", &CrossSection::edges_holding, py::arg("a"), py::arg("b"), py::arg("tolerance"))
      .def("nearest_edge", &CrossSection::nearest_edge, py::arg("a"), py::arg("b"),
           "(edge index, distance m): the edge nearest to the segment a-b as a whole")
      .def("inward_normal", &CrossSection::inward_normal, py::arg("edge"));

  py::class_<RigidBody>(m, "RigidBody", "Mass [kg], centre of mass in O [m], inertia about it [kg m^2].")
      .def(py::init([](double mass, const Vec2& com, double inertia) { return RigidBody{mass, com, inertia}; }),
           py::arg("mass"), py::arg("com"), py::arg("inertia"))
      .def_static("uniform", &RigidBody::uniform, py::arg("section"), py::arg("mass"))
      .def_readonly("mass", &RigidBody::mass)
      .def_readonly("com", &RigidBody::com)
      .def_readonly("inertia", &RigidBody::inertia);

  py::class_<Pad>(m, "Pad", "A finger pad: a disc in G (centre [m], radius [m]).")
      .def(py::init([](const Vec2& center, double radius) { return Pad{center, radius}; }), py::arg("center"),
           py::arg("radius"))
      .def_readonly("center", &Pad::center)
      .def_readonly("radius", &Pad::radius);

  py::class_<Gripper>(m, "Gripper")
      .def(py::init<std::vector<Pad>, double, double, int>(), py::arg("pads"), py::arg("grip_force"), py::arg("mu"),
           py::arg("pad_rings"))
      .def_property_readonly("pads", &Gripper::pads)
      .def_property_readonly("point_positions", [](const Gripper& g) {
        std::vector<Vec2> out;
        for (const PadPoint& p : g.points()) out.push_back(p.position);
        return out;
      })
      .def_property_readonly("point_friction_limits", [](const Gripper& g) {
        std::vector<double> out;
        for (const PadPoint& p : g.points()) out.push_back(p.friction_limit);
        return out;
      })
      .def("pads_inside", [](const Gripper& g, const CrossSection& s, const std::array<double, 3>& q) {
        return g.pads_inside(s, to_pose(q));
      }, py::arg("section"), py::arg("pose"))
      .def("grasp_maintained_along", [](const Gripper& g, const CrossSection& s, const std::array<double, 3>& a,
                                        const std::array<double, 3>& b) {
        return g.grasp_maintained_along(s, to_pose(a), to_pose(b));
      }, py::arg("section"), py::arg("start"), py::arg("end"),
      "Every pad disc inside the cross-section throughout the linear motion start -> end.");

  py::class_<Pusher>(m, "Pusher")
      .def_static("on_boundary", &Pusher::on_boundary, py::arg("section"), py::arg("name"), py::arg("a"),
                  py::arg("b"), py::arg("mu"), py::arg("n_points"))
      .def_readonly("name", &Pusher::name)
      .def_readonly("points", &Pusher::points)
      .def_readonly("inward_normal", &Pusher::inward_normal)
      .def_readonly("mu", &Pusher::mu)
      .def("cone_generators", &Pusher::cone_generators);

  py::class_<WrenchCone>(m, "WrenchCone", "A pointed polyhedral wrench cone with its exact H-representation.")
      .def(py::init<std::vector<Wrench>, double>(), py::arg("generators"), py::arg("torque_length"))
      .def_property_readonly("dimension", &WrenchCone::dimension)
      .def_property_readonly("generators", &WrenchCone::generators)
      .def_property_readonly("facet_rows", &WrenchCone::facet_rows)
      .def_property_readonly("equality_rows", &WrenchCone::equality_rows)
      .def_property_readonly("torque_length", &WrenchCone::torque_length);

  py::enum_<ContactCase>(m, "ContactCase")
      .value("all_sliding", ContactCase::AllSliding)
      .value("sticking", ContactCase::Sticking);

  py::class_<PushResult>(m, "PushResult")
      .def_readonly("feasible", &PushResult::feasible)
      .def_readonly("contact_case", &PushResult::contact_case)
      .def_readonly("margin", &PushResult::margin, "How deep inside the cone [N]")
      .def_readonly("witness", &PushResult::witness, "Pusher wrench in O [N, N, N m]")
      .def_readonly("exact", &PushResult::exact, "Decided in exact arithmetic")
      .def_readonly("sticking_points", &PushResult::sticking_points)
      .def("__repr__", [](const PushResult& r) {
        return std::string("<PushResult feasible=") + (r.feasible ? "True" : "False") + " case=" +
               (r.contact_case == ContactCase::Sticking ? "sticking" : "all_sliding") +
               " margin=" + std::to_string(r.margin) + ">";
      });

  py::class_<MotionWrench>(m, "MotionWrench")
      .def_readonly("required", &MotionWrench::required, "M xi/dt - w_sliding - w_gravity in O [N, N, N m]")
      .def_property_readonly("sticking", [](const MotionWrench& w) {
        std::vector<std::pair<Vec2, double>> out;
        for (const StickingGroup& g : w.sticking) out.emplace_back(g.arm, g.friction_limit);
        return out;
      }, "(arm in G from O's origin [m], friction disc radius [N]) per sticking location")
      .def_readonly("sticking_points", &MotionWrench::sticking_points)
      .def_readonly("scale", &MotionWrench::scale);

  py::enum_<GravityFrame>(m, "GravityFrame", "The frame in which gravity is fixed during a push")
      .value("gripper", GravityFrame::Gripper)
      .value("object", GravityFrame::Object);

  py::class_<StablePushModel>(m, "StablePushModel")
      .def(py::init<CrossSection, RigidBody, Gripper, std::vector<Pusher>, const Vec2&, double, int, GravityFrame,
                    std::vector<double>>(),
           py::arg("section"), py::arg("body"), py::arg("gripper"), py::arg("pushers"), py::arg("gravity"),
           py::arg("step_time"), py::arg("friction_polygon_sides") = 16, py::arg("gravity_frame") = GravityFrame::Gripper,
           py::arg("feature_angles") = std::vector<double>{},
           "gravity: in G's plane when G's axes are the world's [m/s^2]; gravity_frame, feature_angles (the\n"
           "object's world orientation on each pusher's feature [rad]): how gravity turns during a push.")
      .def_property_readonly("gravity_frame", &StablePushModel::gravity_frame)
      .def("gravity_in_gripper", [](const StablePushModel& m, const std::array<double, 3>& q, int pusher) {
        return m.gravity_in_gripper(to_pose(q), pusher);
      }, py::arg("q"), py::arg("pusher"), "gravity in G [m/s^2] at q during a push by `pusher` (-1: G's axes the world's)")
      .def_property_readonly("section", &StablePushModel::section)
      .def_property_readonly("body", &StablePushModel::body)
      .def_property_readonly("gripper", &StablePushModel::gripper)
      .def_property_readonly("pushers", &StablePushModel::pushers)
      .def_property_readonly("pusher_cones", &StablePushModel::pusher_cones)
      .def_property_readonly("torque_length", &StablePushModel::torque_length)
      .def("motion_wrench", [](const StablePushModel& m, const std::array<double, 3>& q, const std::array<double, 3>& dq,
                               int pusher) { return m.motion_wrench(to_pose(q), to_motion(dq), pusher); },
           py::arg("q"), py::arg("dq"), py::arg("pusher") = kNoPusher)
      .def("check", [](const StablePushModel& m, const std::array<double, 3>& q, const std::array<double, 3>& dq,
                       int pusher) { return m.check(to_pose(q), to_motion(dq), pusher); },
           py::arg("q"), py::arg("dq"), py::arg("pusher"))
      .def("check_all", [](const StablePushModel& m, const std::array<double, 3>& q, const std::array<double, 3>& dq) {
        return m.check_all(to_pose(q), to_motion(dq));
      }, py::arg("q"), py::arg("dq"))
      .def("hold_ratio", [](const StablePushModel& m, const std::array<double, 3>& q, int pusher) {
        return m.hold_ratio(to_pose(q), pusher);
      }, py::arg("q"), py::arg("pusher") = kNoPusher,
           "The largest multiple of the weight the pads alone hold at rest at q, gravity as during a push by\n"
           "`pusher` (-1: G's axes the world's); >= 1: held; inf: no gravity.")
      .def("grasp_maintained", [](const StablePushModel& m, const std::array<double, 3>& q) {
        return m.grasp_maintained(to_pose(q));
      }, py::arg("q"))
      .def("check_batch",
           [](const StablePushModel& m, py::array_t<double, py::array::c_style | py::array::forcecast> q,
              py::array_t<double, py::array::c_style | py::array::forcecast> dq, int pusher) {
             if (q.ndim() != 2 || q.shape(1) != 3 || dq.ndim() != 2 || dq.shape(1) != 3 || q.shape(0) != dq.shape(0))
               throw std::invalid_argument("q and dq must be arrays of shape (n, 3)");
             const py::ssize_t n = q.shape(0);
             py::array_t<bool> feasible(n);
             py::array_t<double> margin(n);
             py::array_t<bool> exact(n);
             auto Q = q.unchecked<2>();
             auto D = dq.unchecked<2>();
             auto F = feasible.mutable_unchecked<1>();
             auto M = margin.mutable_unchecked<1>();
             auto E = exact.mutable_unchecked<1>();
             {
               py::gil_scoped_release release;
               for (py::ssize_t i = 0; i < n; ++i) {
                 const PushResult r = m.check(Pose{Q(i, 0), Q(i, 1), Q(i, 2)}, Motion{D(i, 0), D(i, 1), D(i, 2)}, pusher);
                 F(i) = r.feasible;
                 M(i) = r.margin;
                 E(i) = r.exact;
               }
             }
             return py::make_tuple(feasible, margin, exact);
           },
           py::arg("q"), py::arg("dq"), py::arg("pusher"),
           "Check many (q, dq) rows for one pusher without Python overhead per row: (feasible, margin, exact).");

  py::enum_<PlanOutcome>(m, "PlanOutcome")
      .value("goal_reached", PlanOutcome::GoalReached)
      .value("goal_over_switch_limit", PlanOutcome::GoalOverSwitchLimit)
      .value("time_limit", PlanOutcome::TimeLimit)
      .value("invalid_start", PlanOutcome::InvalidStart);

  py::class_<PlanStats>(m, "PlanStats")
      .def_readonly("planning_time_s", &PlanStats::planning_time_s)
      .def_readonly("iterations", &PlanStats::iterations)
      .def_readonly("nodes", &PlanStats::nodes)
      .def_readonly("feasibility_checks", &PlanStats::feasibility_checks)
      .def_readonly("switches", &PlanStats::switches)
      .def_readonly("length", &PlanStats::length, "[unit steps]")
      .def_readonly("restarts", &PlanStats::restarts)
      .def_readonly("first_time_s", &PlanStats::first_time_s, "when the first plan was found [s]; NaN: none")
      .def_readonly("first_switches", &PlanStats::first_switches)
      .def_readonly("first_length", &PlanStats::first_length, "[unit steps]")
      .def_readonly("first_min_margin", &PlanStats::first_min_margin, "[N]")
      .def_readonly("path_min_margin", &PlanStats::path_min_margin, "[N], the search's path (no last push to the goal)");

  py::class_<Plan>(m, "Plan", "Waypoints after each unit push, start first (SI units).")
      .def_readonly("outcome", &Plan::outcome)
      .def_readonly("stats", &Plan::stats)
      .def_readonly("goal_distance", &Plan::goal_distance, "from the last waypoint [unit steps]")
      .def_readonly("ends_at_goal", &Plan::ends_at_goal,
                    "a solved plan's last push reaches the goal pose itself (else it ends within tolerance)")
      .def_property_readonly("poses", [](const Plan& p) {
        py::array_t<double> out({static_cast<py::ssize_t>(p.waypoints.size()), py::ssize_t{3}});
        auto o = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < p.waypoints.size(); ++i) {
          o(i, 0) = p.waypoints[i].pose.x;
          o(i, 1) = p.waypoints[i].pose.z;
          o(i, 2) = p.waypoints[i].pose.theta;
        }
        return out;
      }, "(n, 3): x [m], z [m], theta [rad]")
      .def_property_readonly("pushers", [](const Plan& p) {
        std::vector<int> out;
        for (const PlanStep& s : p.waypoints) out.push_back(s.pusher);
        return out;
      }, "pusher index of the push into each waypoint (-1 at the start)")
      .def_property_readonly("margins", [](const Plan& p) {
        std::vector<double> out;
        for (const PlanStep& s : p.waypoints) out.push_back(s.margin);
        return out;
      }, "[N]; NaN at the start")
      .def_property_readonly("contact_cases", [](const Plan& p) {
        std::vector<ContactCase> out;
        for (const PlanStep& s : p.waypoints) out.push_back(s.contact_case);
        return out;
      });

  const char* plan_doc =
      "Plan stable pushes with TRRTstar. models: one StablePushModel, or a list of them (the corners of an\n"
      "uncertainty box, sharing the geometry; a push counts when it is stable in all, its margin the least).\n"
      "start, goal: (x m, z m, theta rad); step, tolerance: (m, rad); time_limit [s]; min_margin [N];\n"
      "sampling_margin [unit steps]; parameters: TRRTstar's declared parameters by name, as text;\n"
      "min_hold_ratio: the plan must end where the pads alone hold this multiple of the weight (0: none).";
  auto plan = [](const ModelSet& models, const std::array<double, 3>& start, const std::array<double, 3>& goal,
                 const std::array<double, 2>& step, const std::array<double, 2>& tolerance, double time_limit,
                 double min_margin, double sampling_margin, const std::map<std::string, std::string>& parameters,
                 double min_hold_ratio) {
    PlannerSettings settings{to_pose(start), to_pose(goal), to_step(step), to_step(tolerance), time_limit,
                             min_margin, sampling_margin, min_hold_ratio, parameters};
    py::gil_scoped_release release;
    return plan_stable_pushes(models, settings);
  };
  m.def("plan", [plan](const StablePushModel& model, const std::array<double, 3>& start,
                       const std::array<double, 3>& goal, const std::array<double, 2>& step,
                       const std::array<double, 2>& tolerance, double time_limit, double min_margin,
                       double sampling_margin, const std::map<std::string, std::string>& parameters,
                       double min_hold_ratio) {
          return plan(ModelSet{&model}, start, goal, step, tolerance, time_limit, min_margin, sampling_margin,
                      parameters, min_hold_ratio);
        },
        py::arg("model"), py::arg("start"), py::arg("goal"), py::arg("step"), py::arg("tolerance"),
        py::arg("time_limit"), py::arg("min_margin"), py::arg("sampling_margin"), py::arg("parameters"),
        py::arg("min_hold_ratio") = 0.0, plan_doc);
  m.def("plan", plan, py::arg("models"), py::arg("start"), py::arg("goal"), py::arg("step"), py::arg("tolerance"),
        py::arg("time_limit"), py::arg("min_margin"), py::arg("sampling_margin"), py::arg("parameters"),
        py::arg("min_hold_ratio") = 0.0, plan_doc);
  py::class_<PushChecker, PyPushChecker, std::shared_ptr<PushChecker>>(
      m, "PushChecker",
      "What the search asks of the mechanics: subclass it and define all_pushers() -> int (a bit mask),\n"
      "stable_pushers(a, b, candidates) -> int (the pushers among candidates that make the motion a -> b\n"
      "stable; poses (x m, z m, theta rad)) and push_margin(a, b, pusher) -> float (N), then plan with\n"
      "plan_with_checker: the search tested apart from the mechanics.")
      .def(py::init<>());
  m.def("plan_with_checker",
        [](std::shared_ptr<PushChecker> checker, const std::array<double, 3>& start, const std::array<double, 3>& goal,
           const std::array<double, 2>& step, const std::array<double, 2>& tolerance, double time_limit,
           double sampling_margin, const std::map<std::string, std::string>& parameters) {
          PlannerSettings settings{to_pose(start), to_pose(goal), to_step(step), to_step(tolerance), time_limit,
                                   0.0, sampling_margin, 0.0, parameters};
          const CheckedPlan plan = plan_with_checker(std::move(checker), settings);
          py::list path;
          for (const PathNode& n : plan.path) path.append(py::make_tuple(to_tuple(n.pose), n.pusher));
          py::dict out;
          out["outcome"] = plan.outcome;
          out["path"] = path;
          out["switches"] = plan.cost.switches;
          out["length"] = plan.cost.length;
          out["restarts"] = plan.restarts;
          return out;
        },
        py::arg("checker"), py::arg("start"), py::arg("goal"), py::arg("step"), py::arg("tolerance"),
        py::arg("time_limit"), py::arg("sampling_margin") = 5.0,
        py::arg("parameters") = std::map<std::string, std::string>{},
        "TRRTstar with `checker` (a PushChecker) deciding which pushers make a motion stable; every pose is\n"
        "valid. Poses (m, m, rad), step and tolerance (m, rad). Returns outcome, path [((x, z, theta), pusher)]\n"
        "start first (pusher -1 at the start), switches, length (unit steps) and restarts.");
  m.def("worst_case", [](const ModelSet& models, const std::array<double, 3>& q, const std::array<double, 3>& dq,
                         int pusher) { return worst_case(models, to_pose(q), to_motion(dq), pusher); },
        py::arg("models"), py::arg("q"), py::arg("dq"), py::arg("pusher"),
        "The push q -> q + dq (m, m, rad) by `pusher` as the least stable of `models` sees it (the corners of\n"
        "an uncertainty box): the result with the least margin, an infeasible one first.");
  m.def("steps_between", [](const std::array<double, 3>& a, const std::array<double, 3>& b,
                            const std::array<double, 2>& step) { return steps_between(to_pose(a), to_pose(b), to_step(step)); },
        py::arg("a"), py::arg("b"), py::arg("step"),
        "The distance from pose a to b in unit steps (poses (x m, z m, theta rad), step (m, rad)); a unit push "
        "moves at most 1.");
  m.attr("TRRT_STAR_PARAMETERS") = trrt_star_parameters();
  py::dict ranges;
  for (const auto& [name, r] : trrt_star_parameter_ranges())
    ranges[py::str(name)] = py::make_tuple(r.integer ? "integer" : "number", r.lowest, r.highest);
  m.attr("TRRT_STAR_PARAMETER_RANGES") = ranges;
  m.attr("MAX_TIME_LIMIT") = kMaxTimeLimit;
  m.attr("SHORTEST_PUSH") = GraspPoseSpace::kShortestPush;  // [unit steps]
}
