// Bindings of rigid_body.hpp.
#include "stablepush/rigid_body.hpp"

#include <pybind11/eigen.h>

#include "bindings.hpp"

namespace py = pybind11;

namespace stablepush::python {

void expose_rigid_body(py::module_& m) {
  py::class_<RigidBody>(m, "RigidBody", "Mass [kg], centre of mass in O [m], inertia about it [kg m^2].")
      .def(py::init([](double mass, const Vec2& com, double inertia) {
             return RigidBody{mass, com, inertia};
           }),
           py::arg("mass"), py::arg("com"), py::arg("inertia"))
      .def_static("uniform", &RigidBody::uniform, py::arg("section"), py::arg("mass"))
      .def_readonly("mass", &RigidBody::mass)
      .def_readonly("com", &RigidBody::com)
      .def_readonly("inertia", &RigidBody::inertia);
}

}  // namespace stablepush::python
