"""Plans: the `Plan` value type, the search that makes one, plan files, and the check that a plan
belongs to a task. Builds on `stablepush.task`; knows nothing of arms or figures."""
from stablepush.plan.files import load_plan, read_plan, write_plan
from stablepush.plan.plan import Plan, PlanOutcome, PusherContact, Waypoint
from stablepush.plan.search import end_text, plan_task
from stablepush.plan.verify import check_plan

__all__ = ["Plan", "PlanOutcome", "Waypoint", "PusherContact", "plan_task", "end_text", "check_plan", "load_plan",
           "read_plan", "write_plan"]
