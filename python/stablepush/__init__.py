"""stablepush: in-hand manipulation planning by stable prehensile pushing.

    import stablepush as sp
    task = sp.load_task("data/tasks/t-shaped.yaml")
    plan = sp.plan_task(task, seed=1, time_limit=2.0)  # a Plan (plain data)
    sp.save_plan(plan, "t.plan.json"); plan = sp.load_plan("t.plan.json")
    sp.check_plan(task, plan)                          # every push re-checked against the task
    traj = sp.trajectory(task, plan, rate_hz=100)      # timed gripper poses and velocities
    sp.check(task, at=(0, 0, 0), move=(1, 0, 0))       # the stable-push test, per pusher
    fig = sp.plan_figure(task, plan)                   # a matplotlib Figure (loads matplotlib)

Units at this level are the task file's: mm, degrees, grams, newtons; a Trajectory's are the arm's,
SI in the world frame. `stablepush.plan` is the planning subpackage (search, plan files, checks,
reach maps). Every error raised on purpose is a `StablepushError` (TaskError, PlanError,
OutputError, ArmFault, RunnerError, SettingError).

The package's layers, each importing only those below it (docs/architecture.md):
`sim`, `viz` > `kinematics` > `execution` > `plan` > `task` > `units`, `frames`, `errors`, `outputs`, `_core`.
"""
from stablepush._core import ContactCase, PushResult
from stablepush.errors import ArmFault, OutputError, PlanError, RunnerError, SettingError, StablepushError, TaskError
from stablepush.plan import Plan, PlanOutcome, PusherContact, Waypoint, check_plan, load_plan, plan_task
from stablepush.plan import write_plan as save_plan
from stablepush.task import (
    Cell,
    DynamicsSpec,
    GripperSpec,
    PartSpec,
    PlannerSettings,
    PusherSpec,
    Robot,
    Task,
    load_task,
    parse_task,
)
from stablepush.task import check_push as check

__version__ = "0.1.0"
__all__ = ["load_task", "parse_task", "plan_task", "check", "check_plan", "save_plan", "load_plan", "trajectory",
           "plan_figure", "Plan", "Waypoint", "PusherContact", "Task", "PartSpec", "GripperSpec", "DynamicsSpec",
           "PlannerSettings", "PusherSpec", "Cell", "Robot",
           "Trajectory", "StablepushError", "TaskError", "PlanError", "OutputError", "ArmFault", "RunnerError",
           "SettingError", "ContactCase", "PlanOutcome", "PushResult", "joint_path"]


# Loaded when first used, so that `import stablepush` (and the CLI's start-up) does not pay for
# matplotlib or the executor: name -> (module, attribute).
_LAZY = {
    "plan_figure": ("stablepush.viz.figures", "plan_figure"),
    "trajectory": ("stablepush.execution.trajectory", "plan_trajectory"),
    "Trajectory": ("stablepush.execution.trajectory", "Trajectory"),
    "joint_path": ("stablepush.kinematics", "joint_path"),
}


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module 'stablepush' has no attribute {name!r}")
    import importlib

    module, attribute = _LAZY[name]
    return getattr(importlib.import_module(module), attribute)
