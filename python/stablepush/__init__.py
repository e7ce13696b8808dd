"""stablepush: in-hand manipulation planning by stable prehensile pushing.

    import stablepush as sp
    task = sp.load_task("data/tasks/t-shaped.yaml")
    plan = sp.plan(task, seed=1, time_limit=2.0)       # a Plan
    plan.save("t.plan.json"); plan = sp.Plan.load("t.plan.json")
    plan.check(task)                                   # every push re-checked against the task
    traj = plan.trajectory(task, rate_hz=100)          # timed gripper poses and velocities
    sp.check(task, at=(0, 0, 0), move=(1, 0, 0))       # the stable-push test, per pusher

Units at this level are the task file's: mm, degrees, grams, newtons. Every error raised on
purpose is a `StablepushError` (TaskError, PlanError, OutputError, ArmFault).
"""
from stablepush._core import ContactCase, PushResult  # noqa: F401
from stablepush.errors import ArmFault, OutputError, PlanError, StablepushError, TaskError  # noqa: F401
from stablepush.mechanics import check_push as check  # noqa: F401
from stablepush.planning import Plan, Waypoint  # noqa: F401
from stablepush.planning import plan_task as plan  # noqa: F401
from stablepush.task import Task, load_task  # noqa: F401

__version__ = "0.1.0"
__all__ = ["load_task", "plan", "check", "Plan", "Waypoint", "Task", "StablepushError", "TaskError", "PlanError",
           "OutputError", "ArmFault", "ContactCase", "PushResult"]
