// Bindings of cross_section.hpp.
#include "stablepush/cross_section.hpp"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace py = pybind11;

namespace stablepush::python {

void expose_cross_section(py::module_& m) {
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
}

}  // namespace stablepush::python
