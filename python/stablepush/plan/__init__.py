"""Plans: the `Plan` value type, the search that makes one, plan files, and the check that a plan
belongs to a task. Builds on `stablepush.task`; knows nothing of arms or figures."""
from stablepush.lazy import lazy_exports
from stablepush.plan.files import load_plan, read_plan, write_plan
from stablepush.plan.plan import Plan, PlanOutcome, PusherContact, Waypoint
from stablepush.plan.search import SearchRules, end_text, plan_task
from stablepush.plan.verify import check_plan, release_note

__all__ = ["Plan", "PlanOutcome", "Waypoint", "PusherContact", "plan_task", "SearchRules", "end_text", "check_plan",
           "load_plan", "read_plan", "write_plan", "release_note"]
# Loaded when first used: the reach map and the benchmark bring in the batch runners.
_EXPORTS = {"MAX_AXIS": "stablepush.plan.reach", "grid_axis": "stablepush.plan.reach",
            "ReachGrid": "stablepush.plan.reach", "reach_map": "stablepush.plan.reach",
            "bench_checks": "stablepush.plan.benchmark", "bench_planning": "stablepush.plan.benchmark",
            "summarize_planning": "stablepush.plan.benchmark", "write_planning_trials": "stablepush.plan.benchmark"}
__all__ += list(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
