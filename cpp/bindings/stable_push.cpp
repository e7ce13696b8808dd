// Bindings of stable_push.hpp: the model and its test (paper section IV), in SI units. Poses and
// motions are Pose and Motion (a Python 3-sequence converts to either).
#include "stablepush/stable_push.hpp"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace py = pybind11;

namespace stablepush::python {

void expose_stable_push(py::module_& m) {
  m.attr("CERTIFICATION_BAND") = kCertificationBand;
  m.attr("STICKING_SPEED_RATIO") = kStickingSpeedRatio;

  py::enum_<ContactCase>(m, "ContactCase", "How the pads move against the object during a push")
      .value("all_sliding", ContactCase::AllSliding)
      .value("sticking", ContactCase::Sticking);

  py::class_<PushResult>(m, "PushResult", "The stable-push test's verdict on one push by one pusher.")
      .def_readonly("feasible", &PushResult::feasible)
      .def_readonly("contact_case", &PushResult::contact_case)
      .def_readonly("margin", &PushResult::margin, "How deep inside the cone [N]")
      .def_readonly("witness", &PushResult::witness, "Pusher wrench in O [N, N, N m]")
      .def_readonly("exact", &PushResult::exact, "Decided in exact arithmetic")
      .def_readonly("sticking_points", &PushResult::sticking_points)
      .def("__repr__", [](const PushResult& r) {
        return std::string("<PushResult feasible=") + (r.feasible ? "True" : "False") +
               " case=" + (r.contact_case == ContactCase::Sticking ? "sticking" : "all_sliding") +
               " margin=" + std::to_string(r.margin) + ">";
      });

  py::class_<MotionWrench>(m, "MotionWrench", "What a push asks of the pusher, before the cone test.")
      .def_readonly("required", &MotionWrench::required, "M xi/dt - w_sliding - w_gravity in O [N, N, N m]")
      .def_property_readonly(
          "sticking",
          [](const MotionWrench& w) {
            std::vector<std::pair<Vec2, double>> out;
            for (const StickingGroup& g : w.sticking) out.emplace_back(g.arm, g.friction_limit);
            return out;
          },
          "(arm in G from O's origin [m], friction disc radius [N]) per sticking location")
      .def_readonly("sticking_points", &MotionWrench::sticking_points)
      .def_readonly("scale", &MotionWrench::scale);

  py::enum_<GravityFrame>(m, "GravityFrame", "The frame in which gravity is fixed during a push")
      .value("gripper", GravityFrame::Gripper)
      .value("object", GravityFrame::Object);

  py::class_<StablePushModel>(m, "StablePushModel")
      .def(py::init<CrossSection, RigidBody, Gripper, std::vector<Pusher>, const Vec2&, double, int, GravityFrame,
                    std::vector<double>>(),
           py::kw_only(), py::arg("section"), py::arg("body"), py::arg("gripper"), py::arg("pushers"),
           py::arg("gravity"), py::arg("step_time"), py::arg("friction_polygon_sides") = 16,
           py::arg_v("gravity_frame", GravityFrame::Gripper, "GravityFrame.gripper"),
           py::arg("feature_angles") = std::vector<double>{},
           "gravity: in G's plane when G's axes are the world's [m/s^2]; gravity_frame, feature_angles (the\n"
           "object's world orientation on each pusher's feature [rad]): how gravity turns during a push.")
      .def_property_readonly("gravity_frame", &StablePushModel::gravity_frame)
      .def(
          "gravity_in_gripper",
          [](const StablePushModel& m, const Pose& q, int pusher) { return m.gravity_in_gripper(q, pusher); },
          py::arg("q"), py::arg("pusher"),
          "gravity in G [m/s^2] at q during a push by `pusher` (-1: G's axes the world's)")
      .def_property_readonly("section", &StablePushModel::section)
      .def_property_readonly("body", &StablePushModel::body)
      .def_property_readonly("gripper", &StablePushModel::gripper)
      .def_property_readonly("pushers", &StablePushModel::pushers)
      .def_property_readonly("pusher_cones", &StablePushModel::pusher_cones)
      .def_property_readonly("torque_length", &StablePushModel::torque_length)
      .def("motion_wrench",
           py::overload_cast<const Pose&, const Motion&, int>(&StablePushModel::motion_wrench, py::const_),
           py::arg("q"), py::arg("dq"), py::arg("pusher") = kNoPusher)
      .def(
          "check",
          [](const StablePushModel& m, const Pose& q, const Motion& dq, int pusher) { return m.check(q, dq, pusher); },
          py::arg("q"), py::arg("dq"), py::arg("pusher"))
      .def("check_all", &StablePushModel::check_all, py::arg("q"), py::arg("dq"))
      .def("hold_ratio", &StablePushModel::hold_ratio, py::arg("q"), py::arg("pusher") = kNoPusher,
           "The largest multiple of the weight the pads alone hold at rest at q, gravity as during a push by\n"
           "`pusher` (-1: G's axes the world's); >= 1: held; inf: no gravity.")
      .def("grasp_maintained", &StablePushModel::grasp_maintained, py::arg("q"))
      .def("in_world", &StablePushModel::in_world, py::arg("pad_mu_scale"), py::arg("grip_force_scale"),
           py::arg("mass_scale"),
           "This model with the pads' mu, the grip force and the object's mass and inertia scaled (the pushers'\n"
           "cones shared): a world of the same part, grasp and pushers.")
      .def(
          "check_batch",
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
                const PushResult r =
                    m.check(Pose{Q(i, 0), Q(i, 1), Q(i, 2)}, Motion{D(i, 0), D(i, 1), D(i, 2)}, pusher);
                F(i) = r.feasible;
                M(i) = r.margin;
                E(i) = r.exact;
              }
            }
            return py::make_tuple(feasible, margin, exact);
          },
          py::arg("q"), py::arg("dq"), py::arg("pusher"),
          "Check many (q, dq) rows for one pusher without Python overhead per row: (feasible, margin, exact).");
}

}  // namespace stablepush::python
