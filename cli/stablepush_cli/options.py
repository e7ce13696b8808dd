"""The option types and callbacks more than one command takes: finite numbers in a range, seeds
and limits from the task file's own ranges, Ray addresses, stamps, videos, HOST:PORT, --vary and
grid axes."""
from __future__ import annotations

import math
import sys
from typing import TYPE_CHECKING, Optional

import click

from stablepush.errors import OutputError, SettingError, TaskError
from stablepush.extras import MissingExtra
from stablepush.task import LIMITS, PLANNER_PARAMETER_RANGES
from stablepush_cli.common import (
    fail,
    given,
)

if TYPE_CHECKING:
    from click._termui_impl import ProgressBar  # what click.progressbar returns


def ascii_number(text: str) -> bool:
    """Whether `text` is written in ASCII: Python's float() and int() read any script's digits
    ("٣" is 3, "３" too), which a command line should not take for a number."""
    return text.isascii()


class Finite(click.FloatRange):
    """A number in a range that is also finite: click's FloatRange compares with < and >, which
    nan passes, and an unbounded side lets inf through. Written in ASCII digits (ascii_number)."""

    name = "finite float range"

    def convert(self, value, param, ctx):
        if isinstance(value, str) and not ascii_number(value):
            self.fail(f"{value!r} is not a number written in ASCII digits.", param, ctx)
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return number


class Real(click.types.FloatParamType):
    """click's float, written in ASCII digits (ascii_number); nan and inf are the library's to refuse."""

    def convert(self, value, param, ctx):
        if isinstance(value, str) and not ascii_number(value):
            self.fail(f"{value!r} is not a number written in ASCII digits.", param, ctx)
        return super().convert(value, param, ctx)


class Whole(click.IntRange):
    """click's IntRange, written in ASCII digits (ascii_number)."""

    def convert(self, value, param, ctx):
        if isinstance(value, str) and not ascii_number(value):
            self.fail(f"{value!r} is not a whole number written in ASCII digits.", param, ctx)
        return super().convert(value, param, ctx)


# The planner's own ranges, so that a value out of them is refused naming the option, before any work.
SEED = Whole(0, int(PLANNER_PARAMETER_RANGES["seed"][2]))
MAX_SWITCHES = Whole(0, int(PLANNER_PARAMETER_RANGES["max_switches"][2]))
TIME_LIMIT = Finite(*LIMITS["time_limit"])


def parse_ray_address(_ctx, _param, value):
    """--ray [ADDRESS] checked before any work (stablepush.runners.check_ray_address)."""
    from stablepush.runners import check_ray_address

    try:
        return check_ray_address(value) if value else value
    except SettingError as exc:
        raise click.BadParameter(exc.reason) from None


def parse_stamp(_ctx, _param, value):
    """--stamp as Unix ns (None: the bag's default), by the library's rule (bags.parse_stamp)."""
    if value is None:
        return None
    from stablepush.execution import parse_stamp

    try:
        return parse_stamp(value)
    except SettingError as exc:
        raise click.BadParameter(exc.reason) from None


def stamp_option(which: str, default: str):
    """--stamp: the start time of the ROS 2 bag that `which` writes."""
    return click.option(
        "--stamp", "stamp_ns", default=None, callback=parse_stamp, metavar="TIME",
        help=f"With {which}: the bag's start time, Unix seconds (1764600000.5) or ISO-8601 with its zone "
             f"(2026-12-01T15:00:00Z); each message is stamped with it plus its time in the stream, so that the "
             f"bag plays beside live data (default: {default}).")


def parse_video_size(_ctx, _param, value: str):
    """--video-size WxH as (width, height) pixels (the library checks the numbers)."""
    width, sep, height = value.lower().partition("x")
    if not sep or not ascii_number(value) or not width.strip().isdigit() or not height.strip().isdigit():
        raise click.BadParameter(f"expected WIDTHxHEIGHT in pixels (e.g. 640x480), got {value!r}")
    return int(width), int(height)


def video_options(which: str):
    """--video-fps and --video-size, for the videos that `which` asks for."""
    def decorate(command):
        command = click.option(
            "--video-size", "video_size", default="640x480", show_default=True, callback=parse_video_size,
            metavar="WxH", help=f"With {which}: the video's width and height in pixels (even).")(command)
        return click.option(
            "--video-fps", "video_fps", default=25.0, show_default=True, type=Finite(min=0, min_open=True),
            metavar="FPS", help=f"With {which}: frames per second of the run's time, played at that rate (real "
                                f"time); at most 100, a frame per waypoint at 100 Hz.")(command)
    return decorate


def video_settings_need(option: str) -> None:
    """Exit 2 when --video-fps or --video-size is given without `option` (they would do nothing)."""
    named = [f"--video-{name}" for name in ("fps", "size", "view") if given(f"video_{name}")]
    if named:
        fail(f"{' and '.join(named)}: only with {option}")


def check_video(option: str, path: str, fps: float, size) -> None:
    """Refuse, before anything runs, a video that could not be written (exit 2 naming the option).
    Loads MuJoCo for headless rendering (MUJOCO_GL=osmesa), so call it before the simulated arm
    starts."""
    from stablepush.sim import check_fps, check_size, check_video_path

    for name, check, value in (("--video-fps", check_fps, fps), ("--video-size", check_size, size)):
        try:
            check(value)
        except SettingError as exc:
            fail(f"{name}: {exc.reason}")
    try:
        check_video_path(path)
    except OutputError as exc:
        fail(f"{option} {exc}")
    except MissingExtra as exc:
        fail(f"{option}: {exc}")


class VideoBar:
    """A progress bar on stderr over a video's frames, as RunVideo's progress callback; `close()`
    ends it whether or not the video was finished."""

    def __init__(self, path: str):
        self.path = path
        self.bar: Optional[ProgressBar[int]] = None

    def __call__(self, done: int, frames: int) -> None:
        if self.bar is None:
            self.bar = click.progressbar(length=frames, label=f"video {self.path}", file=sys.stderr, show_pos=True)
            self.bar.__enter__()
        self.bar.update(1)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
            self.bar = None


def video_output(option: str, path: str, fps: float, size, quiet: bool, view: str = "schematic"):
    """The run's video in `view` as an output (stablepush.sim.mujoco.video.RunVideo), with a VideoBar
    unless `quiet`; exit 2 naming `option` for one that could not be written. Loads MuJoCo for
    headless rendering (MUJOCO_GL=osmesa), so call it before the simulated arm starts."""
    check_video(option, path, fps, size)
    from stablepush.sim import RunVideo

    return RunVideo(path, fps, size, progress=None if quiet else VideoBar(path), view=view)


def parse_host_port(_ctx, _param, value):
    """--arm HOST:PORT as (host, port); a HOST left out is this machine."""
    if value is None:
        return None
    host, sep, port = value.rpartition(":")
    if not sep or not ascii_number(port) or not port.isdigit() or not 0 < int(port) < 65536:
        raise click.BadParameter(f"expected HOST:PORT with a port from 1 to 65535, got {value!r}")
    return host or "127.0.0.1", int(port)


def parse_vary(_ctx, _param, values):
    """--vary KEY=FRACTION, repeated, as a dict (the keys and ranges are checked by Spreads); None
    when not given, {} for `--vary none`."""
    if not values:
        return None
    if [v.strip().lower() for v in values] == ["none"]:
        return {}
    out = {}
    for value in values:
        key, sep, fraction = value.partition("=")
        try:
            if not ascii_number(fraction):
                raise ValueError(fraction)
            out[key.strip()] = float(fraction)
        except ValueError:
            sep = ""
        if not sep:
            raise click.BadParameter(f"expected KEY=FRACTION (e.g. pad_mu=0.15), got {value!r}")
    return out


def parse_world(_ctx, _param, values):
    """--world FIELD=VALUE, repeated, as (field, value) pairs in order (the fields and ranges are
    checked by the library's WorldDeviation, and against the task where there is one)."""
    out = []
    for value in values:
        name, sep, number = value.partition("=")
        try:
            if not sep or not ascii_number(number):
                raise ValueError(number)
            out.append((name.strip(), float(number)))
        except ValueError:
            raise click.BadParameter(f"expected FIELD=VALUE (e.g. gripper.mu=0.3), got {value!r:.80}") from None
    return tuple(out)


def parse_axis(_ctx, param, value):
    """A grid axis A:B:N (N values from A to B; A:A:1 for A alone), within the task file's pose bounds;
    the library's own check (grid_axis) refuses a count of 1 with B other than A, and equal ends
    with a larger count, named as the option."""
    from stablepush.plan import MAX_AXIS, grid_axis
    from stablepush.task import ANGLE, COORDINATE

    if value is None:
        return None
    low, high = ANGLE if param.name == "theta_axis" else COORDINATE
    parts = value.split(":")
    try:
        if not ascii_number(value):
            raise ValueError(value)
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3 or not 1 <= count <= MAX_AXIS or not (low <= start <= high and low <= stop <= high):
            raise ValueError
    except (ValueError, IndexError):
        raise click.BadParameter(f"expected FROM:TO:COUNT, FROM and TO from {low:g} to {high:g} and COUNT from 1 to "
                                 f"{MAX_AXIS} (e.g. -10:10:11), got {value!r}")
    try:
        return grid_axis(param.name, (start, stop, count), (low, high))
    except TaskError as exc:
        raise click.BadParameter(exc.reason) from None


def robot_options(f):
    """--robot, --flange, --tcp and --base: the arm the command moves, over the task's
    environment.robot (stablepush.task.with_robot checks them)."""
    f = click.option("--base", nargs=4, type=float, default=None, metavar="X Y Z YAW",
                     help="The arm's base in the world: mm, and deg about the world's z (default: the task's "
                          "environment.robot.base, else 0 0 0 0).")(f)
    f = click.option("--tcp", nargs=6, type=float, default=None, metavar="X Y Z RX RY RZ",
                     help="G, the grasp frame midway between the pads, in the flange's frame: mm, and fixed-axis "
                          "roll, pitch, yaw in deg as a URDF rpy. Required with --robot.")(f)
    f = click.option("--flange", default=None, metavar="LINK",
                     help="The link (URDF) or body (MJCF) the project's jaws mount on. Required with --robot.")(f)
    return click.option("--robot", "robot_model", default=None, metavar="FILE.urdf|.xml",
                        type=click.Path(dir_okay=False),
                        help="The arm as a URDF or MJCF file (default: the task's environment.robot, else the "
                             "shipped 7-joint arm); docs/execution.md, 'Bring your own arm'.")(f)
