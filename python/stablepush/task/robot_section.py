"""The environment.robot section of a task file (the arm a run uses: a lab's URDF or MJCF, its
flange, TCP and base), and the same changes made from a command line (--robot, --flange, --tcp,
--base), checked as the file's are.

Files use mm and degrees; TaskError names the field (or the option) it refuses.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, Dict, Optional, Sequence

from stablepush.errors import TaskError
from stablepush.task.fields import SUB_MM, _mapping, _name, _number, _reads_as_radians, _shown, _vector
from stablepush.task.model import JOINT_SPEED, ROBOT_MODEL_SUFFIXES, Robot, Task
from stablepush.task.parts import ANGLE, COORDINATE
from stablepush.task.robot_files import model_source


def robot_section(value: Any, source: Optional[str] = None, names: Optional[Dict[str, str]] = None) -> Robot:
    """The environment.robot section as a Robot: `model` a URDF or MJCF file (relative to the task
    file's folder), with the `flange` it mounts the jaws on and the `tcp` (both required with a
    model: no default fits another arm), `base` and `max_joint_speed` [rad/s] optional. A tcp or
    base that reads as metres and radians is refused, named as `names` says (a command line's
    --tcp, --base; default: the task file's field)."""
    robot = _mapping("environment.robot", value, [], ["model", "flange", "tcp", "base", "max_joint_speed"])
    out: Dict[str, Any] = {}
    if "model" in robot:
        out["model"] = robot_model_file("environment.robot.model", robot["model"], source)
        for key in ("flange", "tcp"):
            if key not in robot:
                raise TaskError(f"environment.robot.{key}", "is required with a robot model (the shipped arm's "
                                                            "does not fit another arm)")
    if "flange" in robot:
        out["flange"] = _name("environment.robot.flange", robot["flange"])
    if "tcp" in robot:
        tcp = _vector("environment.robot.tcp", robot["tcp"], 6)
        out["tcp"] = [_number(f"environment.robot.tcp[{i}]", v, COORDINATE if i < 3 else ANGLE)
                      for i, v in enumerate(tcp)]
    if "base" in robot:
        base = _vector("environment.robot.base", robot["base"], 4)
        out["base"] = [_number(f"environment.robot.base[{i}]", v, COORDINATE if i < 3 else ANGLE)
                       for i, v in enumerate(base)]
    for key in ("tcp", "base"):
        slip = _robot_unit_slip(out[key]) if key in out else ""
        if slip:
            name = (names or {}).get(key, f"environment.robot.{key}")
            raise TaskError(name, f"{' '.join(f'{v:g}' for v in out[key])}: {slip}; {name} takes mm and deg")
    if "max_joint_speed" in robot:
        out["max_joint_speed"] = _number("environment.robot.max_joint_speed", robot["max_joint_speed"], JOINT_SPEED)
    return Robot.from_mapping(out)


def _robot_unit_slip(pose: Sequence[float]) -> str:
    """Why a tcp or base (x, y, z mm, then angles deg) reads as written in metres and radians, as the
    task's own lengths and angles do (_sub_millimetre, _in_radians): a position off the origin by
    under SUB_MM, an angle that is a round one in radians; '' when neither."""
    position, angles = list(pose[:3]), [a for a in pose[3:] if _reads_as_radians(a)]
    slips = []
    if any(position) and max(map(abs, position)) < SUB_MM:
        slips.append("written in metres? (" + ", ".join(f"{v:g} m is {v * 1e3:g} mm" for v in position if v) + ")")
    if angles:
        slips.append("written in radians? (" + ", ".join(f"{a:g} rad is {math.degrees(a):.4g} deg" for a in angles)
                     + ")")
    return "; ".join(slips)


def with_robot(task: Task, model: Optional[str] = None, flange: Optional[str] = None,
               tcp: Optional[Sequence[float]] = None, base: Optional[Sequence[float]] = None) -> Task:
    """`task` on another arm: its environment.robot changed as `robot_with` changes it (a command
    line's --robot, --flange, --tcp and --base)."""
    if model is None and flange is None and tcp is None and base is None:
        return task
    cell = dataclasses.replace(task.environment, robot=robot_with(task.environment.robot, model, flange, tcp, base))
    return dataclasses.replace(task, environment=cell)


def robot_with(robot: Robot, model: Optional[str] = None, flange: Optional[str] = None,
               tcp: Optional[Sequence[float]] = None, base: Optional[Sequence[float]] = None) -> Robot:
    """`robot` with the fields given changed, checked as the task file's are: another model must
    come with its flange and tcp; a relative model file is taken from the working folder."""
    section = {k: v for k, v in robot.as_dict().items() if v is not None}
    if model is not None:
        section = {k: v for k, v in section.items() if k not in ("flange", "tcp")}
        section["model"] = model
    changes = {"flange": flange, "tcp": None if tcp is None else list(tcp),
               "base": None if base is None else list(base)}
    section.update({k: v for k, v in changes.items() if v is not None})
    return robot_section(section, names={k: f"--{k}" for k in ("tcp", "base") if changes[k] is not None})


def robot_model_file(field: str, value: Any, source: Optional[str] = None) -> str:
    """A robot model's file name, relative to the folder of `source` (a task file) when not
    absolute: an existing .urdf, .xml or .mjcf file."""
    if not isinstance(value, str) or not value.strip():
        raise TaskError(field, f"must name a URDF or MJCF file, got {_shown(value)}")
    path = Path(value).expanduser()
    if not path.is_absolute() and source:
        path = Path(source).parent / path
    if path.suffix.lower() not in ROBOT_MODEL_SUFFIXES:
        raise TaskError(field, f"{value!r:.80} is not a URDF or MJCF file (it ends {', '.join(ROBOT_MODEL_SUFFIXES)})")
    if not path.is_file():
        raise TaskError(field, f"no file {str(path)!r:.120}")
    model_source(path)  # read now, every file it names protected as an input: refused before any work
    return str(path.resolve())
