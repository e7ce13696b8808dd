// Bindings of gripper.hpp.
#include "stablepush/gripper.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace py = pybind11;

namespace stablepush::python {

void expose_gripper(py::module_& m) {
  py::class_<Pad>(m, "Pad", "A finger pad: a disc in G (centre [m], radius [m]).")
      .def(py::init([](const Vec2& center, double radius) {
             return Pad{center, radius};
           }),
           py::arg("center"), py::arg("radius"))
      .def_readonly("center", &Pad::center)
      .def_readonly("radius", &Pad::radius);

  py::class_<Gripper>(m, "Gripper", "The pads of a parallel-jaw grasp, their grip force [N] and friction.")
      .def(py::init<std::vector<Pad>, double, double, int>(), py::arg("pads"), py::arg("grip_force"), py::arg("mu"),
           py::arg("pad_rings"))
      .def_property_readonly("pads", &Gripper::pads)
      .def_property_readonly("point_positions",
                             [](const Gripper& g) {
                               std::vector<Vec2> out;
                               for (const PadPoint& p : g.points()) out.push_back(p.position);
                               return out;
                             })
      .def_property_readonly("point_friction_limits",
                             [](const Gripper& g) {
                               std::vector<double> out;
                               for (const PadPoint& p : g.points()) out.push_back(p.friction_limit);
                               return out;
                             })
      .def("pads_inside", &Gripper::pads_inside, py::arg("section"), py::arg("pose"))
      .def("grasp_maintained_along", &Gripper::grasp_maintained_along, py::arg("section"), py::arg("start"),
           py::arg("end"), "Every pad disc inside the cross-section throughout the linear motion start -> end.");
}

}  // namespace stablepush::python
