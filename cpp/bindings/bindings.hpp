// The pybind11 module `stablepush._core`, one binding file per public header (pinocchio's way):
// each expose_* function binds the types and functions of its header. Value types are bound as
// classes (Pose, Motion, StepSize, PlannerSettings, Waypoint, ...), and a Python 3-sequence
// converts to a Pose or a Motion implicitly, so no binding flattens a type into arguments.
#pragma once

#include <pybind11/pybind11.h>

namespace stablepush::python {

void expose_types(pybind11::module_& m);          // types.hpp: Pose, Motion; StepSize
void expose_cross_section(pybind11::module_& m);  // cross_section.hpp
void expose_rigid_body(pybind11::module_& m);     // rigid_body.hpp
void expose_gripper(pybind11::module_& m);        // gripper.hpp
void expose_pusher(pybind11::module_& m);         // pusher.hpp
void expose_friction_cone(pybind11::module_& m);  // friction_cone.hpp
void expose_stable_push(pybind11::module_& m);    // stable_push.hpp
void expose_planning(pybind11::module_& m);       // planning.hpp

}  // namespace stablepush::python
