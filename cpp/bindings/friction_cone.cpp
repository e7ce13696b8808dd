// Bindings of friction_cone.hpp.
#include "stablepush/friction_cone.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace py = pybind11;

namespace stablepush::python {

void expose_friction_cone(py::module_& m) {
  py::class_<WrenchCone>(m, "WrenchCone", "A pointed polyhedral wrench cone with its exact H-representation.")
      .def(py::init<std::vector<Wrench>, double>(), py::arg("generators"), py::arg("torque_length"))
      .def_property_readonly("dimension", &WrenchCone::dimension)
      .def_property_readonly("generators", &WrenchCone::generators)
      .def_property_readonly("facet_rows", &WrenchCone::facet_rows)
      .def_property_readonly("equality_rows", &WrenchCone::equality_rows)
      .def_property_readonly("torque_length", &WrenchCone::torque_length);
}

}  // namespace stablepush::python
