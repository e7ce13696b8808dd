"""The task and its model: task files, their validation, meshes, and the stable-push test in file
units. The layer every other one builds on; it imports nothing of planning or execution."""
from stablepush.task.mechanics import HEADING_STEP_DEG, check_push, stable_directions
from stablepush.task.model import Cell, PlannerSettings, PusherSpec, Robot, Task
from stablepush.task.parts import DynamicsSpec, GripperSpec, PartSpec
from stablepush.task.schema import (
    ANGLE,
    COORDINATE,
    LIMITS,
    PLANNER_PARAMETER_RANGES,
    load_design,
    load_task,
    parse_task,
    robot_with,
    with_robot,
)

__all__ = ["Task", "PartSpec", "GripperSpec", "DynamicsSpec", "PlannerSettings", "PusherSpec", "Cell", "Robot",
           "with_robot", "robot_with",
           "load_task", "parse_task", "check_push", "stable_directions",
           "HEADING_STEP_DEG", "load_design", "LIMITS", "PLANNER_PARAMETER_RANGES", "ANGLE", "COORDINATE"]
