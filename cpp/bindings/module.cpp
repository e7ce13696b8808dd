// PYBIND11_MODULE(_core): the core's public headers for Python, in SI units. No logic lives in
// the bindings beyond batching checks for the benchmarks.
#include "bindings.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() =
      "stablepush C++ core: contact models, generalized friction cones, the stable-push test and the "
      "T-RRT* planner (SI units: m, rad, kg, N, s)";
  using namespace stablepush::python;
  expose_types(m);
  expose_cross_section(m);
  expose_rigid_body(m);
  expose_gripper(m);
  expose_pusher(m);
  expose_friction_cone(m);
  expose_stable_push(m);
  expose_planning(m);
}
