// Compiled without STABLEPUSH_INTERNAL_ALLOWED: every public header builds on its own, and none of
// them brings in CGAL, Boost or OMPL (the public API's types are the core's and Eigen's only).
#include "stablepush/cross_section.hpp"
#include "stablepush/friction_cone.hpp"
#include "stablepush/gripper.hpp"
#include "stablepush/planning.hpp"
#include "stablepush/pusher.hpp"
#include "stablepush/rigid_body.hpp"
#include "stablepush/search.hpp"
#include "stablepush/stable_push.hpp"
#include "stablepush/types.hpp"

#ifdef CGAL_VERSION_NR
#error "a public header includes CGAL"
#endif
#ifdef BOOST_VERSION
#error "a public header includes Boost"
#endif
#ifdef OMPL_VERSION
#error "a public header includes OMPL"
#endif
