// Bindings of types.hpp: Pose and Motion as value classes that a Python 3-sequence converts to,
// and iterate as (x, z, theta) / (dx, dz, dtheta) so that `tuple(pose)` and `pose[0]` work.
#include "stablepush/types.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/typing.h>

#include <array>
#include <sstream>

#include "bindings.hpp"
#include "stablepush/search.hpp"

namespace py = pybind11;

namespace stablepush::python {
namespace {

/// A three-coordinate value class: constructible from three numbers or one 3-sequence, indexable,
/// iterable and comparable like the tuple it stands for.
template <class T>
void bind_triple(py::module_& m, const char* name, const char* doc, const char* a, const char* b, const char* c,
                 double T::*pa, double T::*pb, double T::*pc) {
  auto as_tuple = [pa, pb, pc](const T& v) { return py::make_tuple(v.*pa, v.*pb, v.*pc); };
  py::class_<T>(m, name, doc)
      .def(py::init<>())
      .def(py::init([](double x, double y, double z) {
             return T{x, y, z};
           }),
           py::arg(a), py::arg(b), py::arg(c))
      .def(py::init([](const std::array<double, 3>& v) {
             return T{v[0], v[1], v[2]};
           }),
           py::arg("values"))
      .def_readwrite(a, pa)
      .def_readwrite(b, pb)
      .def_readwrite(c, pc)
      .def("__len__", [](const T&) { return 3; })
      .def("__getitem__",
           [as_tuple](const T& v, py::ssize_t i) -> py::float_ {
             if (i < 0) i += 3;
             if (i < 0 || i >= 3) throw py::index_error("index out of range (3 coordinates)");
             const py::tuple values = as_tuple(v);
             return values[static_cast<std::size_t>(i)].cast<py::float_>();
           })
      .def("__iter__", [as_tuple](const T& v) -> py::typing::Iterator<py::float_> { return py::iter(as_tuple(v)); })
      .def("__eq__",
           [as_tuple](const T& v, const py::object& other) {
             if (py::isinstance<T>(other)) return as_tuple(v).equal(as_tuple(other.cast<const T&>()));
             return py::isinstance<py::sequence>(other) && as_tuple(v).equal(py::tuple(other));
           })
      .def("__repr__", [name, a, b, c, pa, pb, pc](const T& v) {
        std::ostringstream out;
        out.precision(17);
        out << name << "(" << a << "=" << v.*pa << ", " << b << "=" << v.*pb << ", " << c << "=" << v.*pc << ")";
        return out.str();
      });
  py::implicitly_convertible<py::tuple, T>();
  py::implicitly_convertible<py::list, T>();
  py::implicitly_convertible<py::array, T>();
}

}  // namespace

void expose_types(py::module_& m) {
  bind_triple<Pose>(m, "Pose", "The object's pose O seen from the gripper frame G: x [m], z [m], theta [rad].", "x",
                    "z", "theta", &Pose::x, &Pose::z, &Pose::theta);
  bind_triple<Motion>(m, "Motion", "A displacement of the object in the grasp: dx [m], dz [m], dtheta [rad], in G.",
                      "dx", "dz", "dtheta", &Motion::dx, &Motion::dz, &Motion::dtheta);
  py::class_<StepSize>(m, "StepSize", "One unit step of the planner: length [m] and angle [rad].")
      .def(py::init([](double length, double angle) {
             return StepSize{length, angle};
           }),
           py::arg("length"), py::arg("angle"))
      .def(py::init([](const std::array<double, 2>& s) {
             return StepSize{s[0], s[1]};
           }),
           py::arg("values"))
      .def_readwrite("length", &StepSize::length)
      .def_readwrite("angle", &StepSize::angle)
      .def("__iter__", [](const StepSize& s) -> py::typing::Iterator<py::float_> {
        return py::iter(py::make_tuple(s.length, s.angle));
      });
  py::implicitly_convertible<py::tuple, StepSize>();
  py::implicitly_convertible<py::list, StepSize>();
}

}  // namespace stablepush::python
