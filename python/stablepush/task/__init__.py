"""The task and its model: task files and their validation (schema.py; the field checks in
fields.py, the robot section in robot_section.py), design files (design_file.py), meshes, and the
stable-push test in file units. The layer every other one builds on; it imports nothing of
planning or execution."""
from stablepush.task.design_file import load_design
from stablepush.task.fields import LIMITS, PLANNER_PARAMETER_RANGES
from stablepush.task.mechanics import HEADING_STEP_DEG, check_push, stable_directions
from stablepush.task.model import Cell, PlannerSettings, PusherSpec, Robot, Task
from stablepush.task.parts import ANGLE, COORDINATE, DynamicsSpec, GripperSpec, PartSpec
from stablepush.task.robot_section import robot_with, with_robot
from stablepush.task.schema import load_task, parse_task

__all__ = ["Task", "PartSpec", "GripperSpec", "DynamicsSpec", "PlannerSettings", "PusherSpec", "Cell", "Robot",
           "with_robot", "robot_with",
           "load_task", "parse_task", "check_push", "stable_directions",
           "HEADING_STEP_DEG", "load_design", "LIMITS", "PLANNER_PARAMETER_RANGES", "ANGLE", "COORDINATE"]
