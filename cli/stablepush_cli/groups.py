"""Options that reach a command as one value: the plan and its task, the arm a run moves, the
world a simulated run departs into, the closed loop, a video. Each group is declared once here and
taken by every command that has it, so a command's function takes a few values, not every option.

`option_group(target, build, *decorators)` adds the options of `decorators` to a command and hands
it `target` = build(**their values); a group among `decorators` hands `build` its value as its own
target. The options keep their names in click's context (`ctx.params`), where `--help`, `given()`
and a resume command read them.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, Callable, Dict, Optional, Tuple

import click

from stablepush_cli.options import robot_options as _robot_options


def option_group(target: str, build: Callable[..., Any], *decorators: Callable) -> Callable:
    """A decorator: the options `decorators` add, handed to the command as `target` = build(**values)."""
    names = [name for decorator in decorators for name in _handed(decorator)]

    def decorate(command: Callable) -> Callable:
        @functools.wraps(command)
        def grouped(*args, **kwargs):
            kwargs[target] = build(**{name: kwargs.pop(name) for name in names})
            return command(*args, **kwargs)

        for decorator in reversed(decorators):
            grouped = decorator(grouped)
        return grouped

    decorate.group_target = target  # type: ignore[attr-defined]  # what an enclosing group's build is handed
    return decorate


def _handed(decorator: Callable) -> list:
    """The names of the values `decorator` hands a command: a group's target, else its options'."""
    if hasattr(decorator, "group_target"):
        return [decorator.group_target]
    return [param.name for param in click.command()(decorator(lambda **_: None)).params]


@dataclass(frozen=True)
class PlanFiles:
    """PLAN.json and --task: a plan and the task it was made for, as paths until `load`."""

    plan_file: str
    task_file: str

    def inputs(self) -> Dict[str, str]:
        """The files as check_named_outputs names its inputs."""
        return {"PLAN.json": self.plan_file, "--task": self.task_file}

    def load(self, require_solved: bool = True):
        """(task, plan), once the plan is shown to belong to the task (exit 2 if not)."""
        from stablepush_cli.common import load_plan_and_task

        return load_plan_and_task(self.plan_file, self.task_file, require_solved)


def plan_and_task(task_help: str = "The task the plan was made for (checked against the plan).") -> Callable:
    """PLAN.json and --task TASK.yaml, as `files` (PlanFiles)."""
    return option_group(
        "files", PlanFiles,
        click.argument("plan_file", metavar="PLAN.json", type=click.Path(dir_okay=False)),
        click.option("--task", "task_file", required=True, metavar="TASK.yaml", type=click.Path(dir_okay=False),
                     help=task_help))


@dataclass(frozen=True)
class RobotChoice:
    """--robot, --flange, --tcp, --base: the arm over the task's environment.robot (None: the task's)."""

    robot_model: Optional[str] = None
    flange: Optional[str] = None
    tcp: Optional[Tuple[float, ...]] = None
    base: Optional[Tuple[float, ...]] = None

    def on(self, task):
        """`task` on this arm (stablepush.task.with_robot checks the fields)."""
        from stablepush.task import with_robot

        return with_robot(task, self.robot_model, self.flange, self.tcp, self.base)

    def arm(self):
        """This arm over the shipped one, for a command that takes no task (stablepush.task.robot_with)."""
        from stablepush.task import Robot, robot_with

        return robot_with(Robot(), self.robot_model, self.flange, self.tcp, self.base)


robot_choice = option_group("robot", RobotChoice, _robot_options)


@dataclass(frozen=True)
class ArmChoice:
    """--arm, --sim, --engine, --ack-timeout: where a run goes, a simulated arm started here or an
    arm server at HOST:PORT."""

    arm: Optional[Tuple[str, int]]
    sim: bool
    engine: str
    ack_timeout: float


@dataclass(frozen=True)
class SimWorld:
    """--sim-mu-scale, --tracker-noise, --world: how a simulated world departs from the task
    (`seed`: of the tracker's noise)."""

    mu_scale: float
    tracker_noise: Tuple[float, float]
    world: Tuple[Tuple[str, float], ...] = ()
    seed: int = 0

    def deviation(self):
        from stablepush.sim import WorldDeviation

        return WorldDeviation(mu_scale=self.mu_scale, tracker_noise_mm=self.tracker_noise[0],
                              tracker_noise_deg=self.tracker_noise[1], seed=self.seed, world=self.world)


def world_option(scope: str) -> Callable:
    """--world FIELD=VALUE, repeatable: a task field's value in the simulated world whatever the
    task says; `scope` says which worlds ("With --sim: the", "The")."""
    from stablepush_cli.options import parse_world

    return click.option(
        "--world", "world", multiple=True, callback=parse_world, metavar="FIELD=VALUE",
        help=f"{scope} simulated world's value of a task field, whatever the task says (the real world does not "
             f"read the task file either): gripper.mu, gripper.grip_force (N), object.mass (g) or "
             f"pushers.NAME.mu. Repeatable; before --sim-mu-scale. A world to calibrate against "
             f"(`stablepush calibrate --sim --world ...`).")


def arm_connection(sim_help: str) -> Callable:
    """--arm, --sim, --engine, --ack-timeout as `connection` (ArmChoice); `sim_help`: what --sim does."""
    from stablepush.execution import ACK_TIMEOUT_RANGE, DEFAULT_ACK_TIMEOUT, DEFAULT_PORT
    from stablepush.sim import DEFAULT_ENGINE, ENGINES
    from stablepush_cli.options import Finite, parse_host_port

    return option_group(
        "connection", ArmChoice,
        click.option("--arm", "arm", default=None, metavar="HOST:PORT", callback=parse_host_port,
                     help=f"The arm server (stablepush.arm/2 protocol, see docs/execution.md). Default: with --sim a "
                          f"simulated arm started in this process, else 127.0.0.1:{DEFAULT_PORT}."),
        click.option("--sim", is_flag=True, help=sim_help),
        click.option("--engine", default=DEFAULT_ENGINE, show_default=True, type=click.Choice(ENGINES),
                     help="With --sim: the physics engine of the simulated arm. mujoco: pads slide with stablepush's "
                          "own Coulomb friction; drake: Drake's contact solver alone decides stick and slip."),
        click.option("--ack-timeout", default=DEFAULT_ACK_TIMEOUT, show_default=True, type=Finite(*ACK_TIMEOUT_RANGE),
                     metavar="S", help="Give up when the arm server does not reply within S seconds (not with --sim: "
                                       "the simulated arm runs in this process, and a waypoint takes as long as it "
                                       "takes)."))


def sim_world(tracker_noise_help: str = "") -> Callable:
    """--sim-mu-scale, --tracker-noise and --world as `world` (SimWorld)."""
    from stablepush_cli.options import Finite

    return option_group(
        "world", SimWorld,
        click.option("--sim-mu-scale", "mu_scale", default=1.0, show_default=True, type=Finite(min=0.1, max=10),
                     metavar="S", help="With --sim: the simulated pads' and features' mu are S times the task's, to "
                                       "test the plan against a world whose friction differs from its model."),
        click.option("--tracker-noise", "tracker_noise", nargs=2, type=Finite(min=0), default=(0.0, 0.0),
                     metavar="MM DEG", help="With --sim: standard deviations of the simulated tracker's noise on the "
                                            "object's pose in the grasp (x and z in mm, theta in deg)."
                                            + tracker_noise_help),
        world_option("With --sim: the"))


@dataclass(frozen=True)
class LoopChoice:
    """--closed-loop, --guard, --replan-threshold, --final-tolerance: how a run corrects itself."""

    closed_loop: bool
    guarded: bool
    replan_threshold: Optional[Tuple[float, float]]
    final_tolerance: Optional[Tuple[float, float]]

    def loop_for(self, task):
        """The task's ClosedLoop with these thresholds, or None open loop."""
        from stablepush.execution import ClosedLoop

        return ClosedLoop.for_task(task, self.replan_threshold, self.final_tolerance) if self.closed_loop else None


@dataclass(frozen=True)
class StreamChoice:
    """--rate, --resume-from, --pace: how the waypoints go out."""

    rate_hz: float
    resume_from: int
    pace: Optional[bool]


@dataclass(frozen=True)
class VideoRequest:
    """--video and its settings (fps, WxH, view); `path` None: no video."""

    path: Optional[str]
    fps: float
    size: Tuple[int, int]
    view: str = "schematic"


def video_request(option: str, path_option: Callable, view_option: Optional[Callable] = None) -> Callable:
    """`option` (a path, declared by `path_option`), its --video-fps and --video-size, and, when
    given, its view (`view_option`), as `video` (VideoRequest)."""
    from stablepush_cli.options import video_options

    def build(video_path, video_fps, video_size, video_view="schematic"):
        return VideoRequest(video_path, video_fps, video_size, video_view)

    decorators = [path_option, video_options(option)] + ([view_option] if view_option else [])
    return option_group("video", build, *decorators)


@dataclass(frozen=True)
class RunnerChoice:
    """--workers K | --ray [ADDRESS]: where a batch runs (stablepush.runners.Runner)."""

    workers: Optional[int]
    ray_address: Optional[str]

    def runner(self, default: int):
        """The Runner (`default` workers when neither is given; both at once exit 2), a Ray head
        checked before any work."""
        from stablepush_cli.common import runner_for

        return runner_for(self.workers, self.ray_address, default)


def runner_choice(what: str, default: str = "the number of CPUs", where_help: str = "") -> Callable:
    """--workers and --ray for the jobs `what` names ("the trials"), as `where` (RunnerChoice);
    `default` says where they run without either."""
    from stablepush_cli.options import Whole, parse_ray_address

    return option_group(
        "where", RunnerChoice,
        click.option("--workers", type=Whole(min=1, max=1024), default=None, metavar="K",
                     help=f"Run {what} on K local processes (default: {default}).{where_help}"),
        click.option("--ray", "ray_address", is_flag=False, flag_value="", default=None, metavar="[ADDRESS]",
                     callback=parse_ray_address,
                     help=f"Run {what} on Ray: a local instance, or the cluster at ADDRESS (e.g. 10.0.0.5:6379; see "
                          f"docs/evaluate.md, 'Where the trials run')."))


@dataclass(frozen=True)
class StudyOutputs:
    """--json, --csv, --plot and the failed trials' videos: where a study's records, figure and
    videos go."""

    json_path: Optional[str]
    csv_path: Optional[str]
    png_path: Optional[str]
    video: VideoRequest

    def named(self) -> Dict[str, Optional[str]]:
        return {"--json": self.json_path, "--csv": self.csv_path, "--plot": self.png_path}

    def given(self) -> list:
        return [path for path in (self.json_path, self.csv_path, self.png_path) if path]


@dataclass(frozen=True)
class TrialRun:
    """--closed-loop, --engine, and evaluate's --guard and --success-tolerance: how each trial of a
    study runs and what counts as landing (None: the task's tolerance)."""

    closed_loop: bool
    engine: str
    guarded: bool = True
    success_tolerance: Optional[Tuple[float, float]] = None


@dataclass(frozen=True)
class WorldSpreads:
    """--vary, --feature-error, --tracker-noise: how a study's worlds differ from the task."""

    vary: Optional[Dict[str, float]]
    feature_error: Optional[Tuple[float, float]]
    tracker_noise: Tuple[float, float] = (0.0, 0.0)

    def spreads(self, task):
        """The study's Spreads for `task` (exit 2 naming the option for one out of range)."""
        from stablepush_cli.common import study_spreads

        return study_spreads(task, self.vary, self.feature_error, self.tracker_noise)
