// Bindings of pusher.hpp.
#include "stablepush/pusher.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace py = pybind11;

namespace stablepush::python {

void expose_pusher(py::module_& m) {
  py::class_<Pusher>(m, "Pusher", "A pusher fixed on the object's boundary in O: its contact points and friction.")
      .def_static("on_boundary", &Pusher::on_boundary, py::arg("section"), py::arg("name"), py::arg("a"), py::arg("b"),
                  py::arg("mu"), py::arg("n_points"))
      .def_readonly("name", &Pusher::name)
      .def_readonly("points", &Pusher::points)
      .def_readonly("inward_normal", &Pusher::inward_normal)
      .def_readonly("mu", &Pusher::mu)
      .def("cone_generators", &Pusher::cone_generators);
}

}  // namespace stablepush::python
