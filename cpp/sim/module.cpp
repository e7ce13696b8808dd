// PYBIND11_MODULE(_pad_friction): coulomb_pad_friction.hpp for python/stablepush/sim/mujoco/friction.py,
// which owns the MuJoCo model and data and hands their addresses over (MjModel._address).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <cstring>
#include <memory>

#include "coulomb_pad_friction.hpp"

namespace py = pybind11;
using stablepush::sim::CoulombPadFriction;
using stablepush::sim::PadFrictionParameters;

namespace {

py::array_t<bool> as_array(const std::vector<char>& flags) {
  py::array_t<bool> out(static_cast<py::ssize_t>(flags.size()));
  std::memcpy(out.mutable_data(), flags.data(), flags.size());
  return out;
}

}  // namespace

PYBIND11_MODULE(_pad_friction, m) {
  m.doc() = "The simulated arm's pad friction in C++ (stablepush.sim.mujoco.friction explains it; SI units)";
  m.attr("MUJOCO_VERSION") = mjVERSION_HEADER;  // the headers built against: must equal mujoco.mj_version()

  py::class_<PadFrictionParameters>(m, "PadFrictionParameters", "The pad friction's thresholds (friction.py).")
      .def(py::init([](double slide_speed, double stick_speed, int slide_steps, double on_cone, double directions_agree,
                       int max_trials, double frictionless_mu) {
             return PadFrictionParameters{slide_speed,      stick_speed, slide_steps,    on_cone,
                                          directions_agree, max_trials,  frictionless_mu};
           }),
           py::kw_only(), py::arg("slide_speed"), py::arg("stick_speed"), py::arg("slide_steps"), py::arg("on_cone"),
           py::arg("directions_agree"), py::arg("max_trials"), py::arg("frictionless_mu"));

  py::class_<CoulombPadFriction>(m, "CoulombPadFriction",
                                 "Per pad point, stick by the solver or slide with Coulomb friction (friction.py).")
      .def(py::init([](std::uintptr_t model_address, const std::vector<int>& pad_geoms,
                       const PadFrictionParameters& parameters) {
             return std::make_unique<CoulombPadFriction>(reinterpret_cast<mjModel*>(model_address), pad_geoms,
                                                         parameters);
           }),
           py::arg("model_address"), py::arg("pad_geoms"), py::arg("parameters"),
           "model_address: MjModel._address; the model must outlive this object.")
      .def(
          "step",
          [](CoulombPadFriction& self, std::uintptr_t data_address) {
            self.step(reinterpret_cast<mjData*>(data_address));
          },
          py::arg("data_address"),
          "One time step (update, then mj_step or the scratch's copy): data_address is MjData._address.")
      .def(
          "update",
          [](CoulombPadFriction& self, std::uintptr_t data_address) {
            self.update(reinterpret_cast<mjData*>(data_address));
          },
          py::arg("data_address"),
          "The next step's friction only: mj_step after it takes the step `step` takes. data_address is "
          "MjData._address of the model's data.")
      .def_property_readonly("slipping", [](const CoulombPadFriction& f) { return as_array(f.slipping()); })
      .def_property_readonly("sliding", [](const CoulombPadFriction& f) { return as_array(f.sliding()); })
      .def_property_readonly("solver_steps", &CoulombPadFriction::solver_steps)
      .def_property_readonly("trial_steps", &CoulombPadFriction::trial_steps)
      .def_property_readonly("copied_steps", &CoulombPadFriction::copied_steps);
}
