// Bindings of planning.hpp: PlannerSettings in, Plan out (SI units), and the search run with a
// PushChecker written in Python (the toy checkers of the search's tests).
#include "stablepush/planning.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/typing.h>

#include <atomic>
#include <csignal>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "stablepush/internal/grasp_space.hpp"

namespace py = pybind11;

namespace stablepush::python {
namespace {

// Ctrl-C during a search: the core plans with the GIL released, so Python's own SIGINT handler
// cannot run until it returns; for the search's length a C handler sets its stop flag instead, and
// the KeyboardInterrupt is raised once the search has returned. Only one search at a time (the main
// thread's, where Python delivers signals) installs it.
std::atomic<StopFlag*> interrupted_search{nullptr};

extern "C" void stop_search_on_sigint(int) {
  if (StopFlag* flag = interrupted_search.load()) flag->set();
}

/// Installs stop_search_on_sigint for `flag` while it lives; restores the previous handler after.
class SigintStopsSearch {
 public:
  explicit SigintStopsSearch(StopFlag* flag) {
    interrupted_search.store(flag);
    struct sigaction action {};
    action.sa_handler = stop_search_on_sigint;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, &previous_);
  }
  ~SigintStopsSearch() {
    sigaction(SIGINT, &previous_, nullptr);
    interrupted_search.store(nullptr);
  }
  SigintStopsSearch(const SigintStopsSearch&) = delete;
  SigintStopsSearch& operator=(const SigintStopsSearch&) = delete;

 private:
  struct sigaction previous_ {};
};

/// A PushChecker written in Python: subclass _core.PushChecker and define all_pushers(),
/// stable_pushers(a, b, candidates) and push_margin(a, b, pusher); a and b are Poses, pusher sets
/// int bit masks.
class PyPushChecker : public PushChecker {
 public:
  PusherSet all_pushers() const override { return call("all_pushers").cast<PusherSet>(); }
  PusherSet stable_pushers(const Pose& a, const Pose& b, PusherSet candidates) const override {
    ++checks_;
    return call("stable_pushers", a, b, candidates).cast<PusherSet>();
  }
  double push_margin(const Pose& a, const Pose& b, int pusher) const override {
    return call("push_margin", a, b, pusher).cast<double>();
  }
  std::uint64_t feasibility_checks() const override { return checks_; }
  void reset_feasibility_checks() override { checks_ = 0; }

 private:
  template <class... Args>
  py::object call(const char* name, Args&&... args) const {
    py::gil_scoped_acquire gil;
    const py::function f = py::get_override(static_cast<const PushChecker*>(this), name);
    if (!f) throw std::runtime_error(std::string("PushChecker.") + name + " is not defined");
    return f(std::forward<Args>(args)...);
  }
  mutable std::uint64_t checks_ = 0;
};

}  // namespace

void expose_planning(py::module_& m) {
  py::enum_<PlanOutcome>(m, "PlanOutcome", "How a solve ended")
      .value("goal_reached", PlanOutcome::GoalReached)
      .value("goal_over_switch_limit", PlanOutcome::GoalOverSwitchLimit)
      .value("time_limit", PlanOutcome::TimeLimit)
      .value("invalid_start", PlanOutcome::InvalidStart);

  py::class_<StopFlag, std::shared_ptr<StopFlag>>(m, "StopFlag", "Set from another thread to end a search early.")
      .def(py::init<>())
      .def("set", &StopFlag::set)
      .def_property_readonly("is_set", &StopFlag::is_set);

  py::class_<PlannerSettings>(m, "PlannerSettings", "What to plan: start and goal, the unit step, the limits.")
      .def(py::init([](const Pose& start, const Pose& goal, const StepSize& step, const StepSize& tolerance,
                       double time_limit, double min_margin, double sampling_margin, double min_hold_ratio,
                       std::map<std::string, std::string> parameters, double min_transit_hold, int start_pusher) {
             PlannerSettings s{start,           goal,           step,
                               tolerance,       time_limit,     min_margin,
                               sampling_margin, min_hold_ratio, std::move(parameters)};
             s.min_transit_hold = min_transit_hold;
             s.start_pusher = start_pusher;
             return s;
           }),
           py::kw_only(), py::arg("start"), py::arg("goal"), py::arg("step"), py::arg("tolerance"),
           py::arg("time_limit") = 10.0, py::arg("min_margin") = 1e-3, py::arg("sampling_margin") = 5.0,
           py::arg("min_hold_ratio") = 0.0, py::arg("parameters") = std::map<std::string, std::string>{},
           py::arg("min_transit_hold") = 0.0, py::arg("start_pusher") = kNoPusher)
      .def_readwrite("start", &PlannerSettings::start, "[m, m, rad]")
      .def_readwrite("goal", &PlannerSettings::goal, "[m, m, rad]")
      .def_readwrite("step", &PlannerSettings::step, "one unit step [m, rad]")
      .def_readwrite("tolerance", &PlannerSettings::tolerance, "per coordinate, around the goal [m, rad]")
      .def_readwrite("time_limit", &PlannerSettings::time_limit, "[s]")
      .def_readwrite("min_margin", &PlannerSettings::min_margin, "least depth inside the pusher's cone [N]")
      .def_readwrite("sampling_margin", &PlannerSettings::sampling_margin, "[unit steps] around the start-goal box")
      .def_readwrite("min_hold_ratio", &PlannerSettings::min_hold_ratio, "0: no hold requirement at the end")
      .def_readwrite("min_transit_hold", &PlannerSettings::min_transit_hold,
                     "switch pushers only where the pads hold this many times the weight (0: anywhere)")
      .def_readwrite("start_pusher", &PlannerSettings::start_pusher, "the pusher in contact at the start, or -1")
      .def_property(
          "stop", [](const PlannerSettings& s) -> py::typing::Optional<StopFlag> { return py::cast(s.stop); },
          [](PlannerSettings& s, std::optional<std::shared_ptr<StopFlag>> stop) { s.stop = stop.value_or(nullptr); },
          "a StopFlag that ends the search early when set, or None")
      .def_readwrite("parameters", &PlannerSettings::parameters, "TRRTstar's declared parameters by name, as text");

  py::class_<Waypoint>(m, "Waypoint", "The pose after a unit push, its pusher (-1 at the start) and the verdict.")
      .def_readonly("pose", &Waypoint::pose)
      .def_readonly("pusher", &Waypoint::pusher)
      .def_readonly("margin", &Waypoint::margin, "[N]; NaN at the start")
      .def_readonly("contact_case", &Waypoint::contact_case);

  py::class_<PlanStats>(m, "PlanStats")
      .def_readonly("planning_time_s", &PlanStats::planning_time_s)
      .def_readonly("iterations", &PlanStats::iterations)
      .def_readonly("nodes", &PlanStats::nodes)
      .def_readonly("feasibility_checks", &PlanStats::feasibility_checks)
      .def_readonly("switches", &PlanStats::switches)
      .def_readonly("length", &PlanStats::length, "[unit steps]")
      .def_readonly("restarts", &PlanStats::restarts)
      .def_readonly("check_limit_reached", &PlanStats::check_limit_reached,
                    "the search stopped at check_limit (a count), not at the time limit")
      .def_readonly("first_time_s", &PlanStats::first_time_s, "when the first plan was found [s]; NaN: none")
      .def_readonly("first_switches", &PlanStats::first_switches)
      .def_readonly("first_length", &PlanStats::first_length, "[unit steps]")
      .def_readonly("first_min_margin", &PlanStats::first_min_margin, "[N]")
      .def_readonly("path_min_margin", &PlanStats::path_min_margin,
                    "[N], the search's path (no last push to the goal)");

  py::class_<Plan>(m, "Plan", "Waypoints after each unit push, start first (SI units).")
      .def_readonly("outcome", &Plan::outcome)
      .def_readonly("waypoints", &Plan::waypoints)
      .def_readonly("stats", &Plan::stats)
      .def_readonly("goal_distance", &Plan::goal_distance, "from the last waypoint [unit steps]")
      .def_readonly("ends_at_goal", &Plan::ends_at_goal,
                    "a solved plan's last push reaches the goal pose itself (else it ends within tolerance)")
      .def_property_readonly(
          "poses",
          [](const Plan& p) {
            py::array_t<double> out({static_cast<py::ssize_t>(p.waypoints.size()), py::ssize_t{3}});
            auto o = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < p.waypoints.size(); ++i) {
              o(i, 0) = p.waypoints[i].pose.x;
              o(i, 1) = p.waypoints[i].pose.z;
              o(i, 2) = p.waypoints[i].pose.theta;
            }
            return out;
          },
          "(n, 3): x [m], z [m], theta [rad]");

  m.def(
      "plan",
      [](const ModelSet& models, PlannerSettings settings, bool interruptible) {
        if (!interruptible) {
          py::gil_scoped_release release;
          return plan_stable_pushes(models, settings);
        }
        if (!settings.stop) settings.stop = std::make_shared<StopFlag>();
        Plan plan;
        {
          SigintStopsSearch sigint(settings.stop.get());
          py::gil_scoped_release release;
          plan = plan_stable_pushes(models, settings);
        }
        if (settings.stop->is_set()) {
          PyErr_SetNone(PyExc_KeyboardInterrupt);
          throw py::error_already_set();
        }
        return plan;
      },
      py::arg("models"), py::arg("settings"), py::arg("interruptible") = false,
      "Plan stable pushes with TRRTstar. models: StablePushModels sharing the geometry (the corners of an\n"
      "uncertainty box, or the nominal model alone): a push counts when it is stable in all, its margin the\n"
      "least. Throws ValueError for a parameter TRRTstar does not declare or cannot take. interruptible (only from\n"
      "the main thread): SIGINT stops the search at once and raises KeyboardInterrupt.");

  py::class_<PathNode>(m, "PathNode", "A node of the search's path: the pose and the pusher of the push into it.")
      .def_readonly("pose", &PathNode::pose)
      .def_readonly("pusher", &PathNode::pusher);
  py::class_<PathCost>(m, "PathCost", "Switch-overs first, then length [unit steps].")
      .def_readonly("switches", &PathCost::switches)
      .def_readonly("length", &PathCost::length);
  py::class_<CheckedPlan>(m, "CheckedPlan", "A search's outcome with a PushChecker of one's own.")
      .def_readonly("outcome", &CheckedPlan::outcome)
      .def_readonly("path", &CheckedPlan::path, "start first (pusher -1 at the start)")
      .def_readonly("cost", &CheckedPlan::cost)
      .def_readonly("restarts", &CheckedPlan::restarts);

  py::class_<PushChecker, PyPushChecker, std::shared_ptr<PushChecker>>(
      m, "PushChecker",
      "What the search asks of the mechanics: subclass it and define all_pushers() -> int (a bit mask),\n"
      "stable_pushers(a, b, candidates) -> int (the pushers among candidates that make the motion a -> b\n"
      "stable; a and b Poses) and push_margin(a, b, pusher) -> float (N), then plan with plan_with_checker:\n"
      "the search tested apart from the mechanics.")
      .def(py::init<>());
  m.def("plan_with_checker", &plan_with_checker, py::arg("checker"), py::arg("settings"),
        "TRRTstar with `checker` deciding which pushers make a motion stable; every pose is valid, and\n"
        "settings.min_margin and min_hold_ratio are not used.");

  m.def("worst_case", &worst_case, py::arg("models"), py::arg("q"), py::arg("dq"), py::arg("pusher"),
        "The push q -> q + dq by `pusher` as the least stable of `models` sees it (the corners of an\n"
        "uncertainty box): the result with the least margin, an infeasible one first.");
  m.def("steps_between", &steps_between, py::arg("a"), py::arg("b"), py::arg("step"),
        "The distance from pose a to b in unit steps; a unit push moves at most 1.");
  m.attr("TRRT_STAR_PARAMETERS") = trrt_star_parameters();
  py::dict ranges;
  for (const auto& [name, r] : trrt_star_parameter_ranges())
    ranges[py::str(name)] = py::make_tuple(r.integer ? "integer" : "number", r.lowest, r.highest);
  m.attr("TRRT_STAR_PARAMETER_RANGES") = ranges;
  m.attr("MAX_TIME_LIMIT") = kMaxTimeLimit;
  m.attr("SHORTEST_PUSH") = GraspPoseSpace::kShortestPush;  // [unit steps]
}

}  // namespace stablepush::python
