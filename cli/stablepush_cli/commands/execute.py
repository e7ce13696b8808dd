"""`stablepush execute`."""
from __future__ import annotations

import contextlib
import sys
from dataclasses import dataclass
from typing import Optional, Tuple

import click

from stablepush.errors import SettingError
from stablepush.execution import CAUSES, DEFAULT_PORT
from stablepush.sim import DEFAULT_ENGINE, VIDEO_VIEWS
from stablepush_cli.common import (
    EXIT_ARM_FAULT,
    EXIT_MISSED,
    check_named_outputs,
    fail,
    given,
    help_with,
    progressbar,
    say_beside,
)
from stablepush_cli.groups import (
    ArmChoice,
    LoopChoice,
    PlanFiles,
    RobotChoice,
    SimWorld,
    StreamChoice,
    VideoRequest,
    arm_connection,
    option_group,
    plan_and_task,
    robot_choice,
    sim_world,
    video_request,
)
from stablepush_cli.options import (
    Finite,
    Whole,
    stamp_option,
    video_output,
    video_settings_need,
)


@dataclass(frozen=True)
class RunReport:
    """--json, --success-tolerance, --record, --stamp, --video: the run's report and the tolerance
    its verdict is judged by (None: the task's), and the bag and the video recorded of it."""

    json_path: Optional[str]
    success_tolerance: Optional[Tuple[float, float]]
    record_path: Optional[str]
    stamp_ns: Optional[int]
    video: VideoRequest


@dataclass(frozen=True)
class Verbosity:
    """--quiet, -v: no progress bar; a line per correction and per contact."""

    quiet: bool
    verbose: bool


@click.command()
@plan_and_task("The task the plan was made for (checked against the plan before anything moves).")
@arm_connection("Start a simulated arm here and run the plan on it (see --engine).")
@option_group("stream", StreamChoice,
              click.option("--rate", "rate_hz", default=100.0, show_default=True, type=Finite(min=1, max=1000),
                           metavar="HZ", help="Waypoints per second of motion. Each push takes the fewest whole "
                                              "periods that last the task's dynamics.step_time (slower than the "
                                              "model when HZ does not divide it); the last push of each contact "
                                              "eases to rest, up to 4/3 of the planned speed on the way "
                                              "(docs/execution.md)."),
              click.option("--resume-from", "resume_from", default=0, type=Whole(min=0), metavar="STEP",
                           help="Continue after plan step STEP (the last confirmed step a fault reported). A "
                                "`stablepush sim-arm` server then keeps the world it has; --sim starts a fresh one, "
                                "the object where step STEP leaves it."),
              click.option("--pace/--no-pace", default=None,
                           help="Hold the stream to --rate in wall-clock time (default: on for a real arm, off "
                                "with --sim)."))
@option_group(
    "report", RunReport,
    click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None,
                 help="Write the run's report as JSON: success, tolerance, cause of a miss, engine, final pose in the "
                      "grasp, slip per contact, corrections, features (on an arm fault: the verdict and where to "
                      "resume)."),
    click.option("--success-tolerance", "success_tolerance", nargs=2, type=Finite(min=0, min_open=True),
                 default=None, metavar="MM DEG",
                 help="The run lands when the object ends within MM (x and z) and DEG of the goal in the grasp "
                      "(default: the task's planner.tolerance)."),
    click.option("--record", "record_path", type=click.Path(dir_okay=False), default=None, metavar="RUN.mcap",
                 help="Record the run as a ROS 2 bag (one MCAP file): the commanded and measured gripper pose, the "
                      "object in the world and in the grasp, /tf and /tf_static, the pusher in contact, each "
                      "correction and the verdict; with the arm's model (--sim, --robot or environment.robot) its "
                      "/joint_states and, for a URDF, /robot_description (docs/execution.md, 'ROS 2 bags'); written "
                      "on a fault too."),
    stamp_option("--record", "when the run starts"),
    video_request(
        "--video",
        click.option("--video", "video_path", type=click.Path(dir_okay=False), default=None, metavar="RUN.mp4",
                     help="Draw the run as a video (H.264 MP4, headless): seen along the gripping axis as the plan "
                          "figures are, the object, the pads, the features (the pusher in contact highlighted) and "
                          "the plan's pose at each step as a green ghost (docs/execution.md, 'Video of a run'); "
                          "needs the object's pose, which a simulated arm reports; drawn on a fault too."),
        click.option("--video-view", "video_view", type=click.Choice(VIDEO_VIEWS), default="schematic",
                     show_default=True,
                     help="With --video: schematic, along the gripping axis as the plan figures are; 3d, the whole "
                          "cell in perspective, the arm posed from the joints it reported (its model: --sim, --robot "
                          "or the task's environment.robot), the part in its jaws and the features; both, the two "
                          "side by side, the video twice as wide.")))
@option_group(
    "talk", Verbosity,
    click.option("--quiet", is_flag=True, help="No progress bar."),
    click.option("-v", "--verbose", is_flag=True,
                 help="A line per correction of the closed loop and per contact (slip, carry, where the guard found "
                      "its feature); without, one line sums each up."))
@sim_world()
@option_group("loop", LoopChoice,
              click.option("--closed-loop", "closed_loop", is_flag=True,
                           help="As the object comes onto each feature and after each push compare the arm's "
                                "tracked pose in the grasp with the plan's; past --replan-threshold (on the last "
                                "contact's feature, --final-tolerance) re-plan from the measured pose and continue "
                                "with the new plan. An arm that reports no tracked pose runs open loop (and says "
                                "so)."),
              click.option("--guard/--no-guard", "guarded", default=True, show_default=True,
                           help="End each approach slowly and find the feature by touch (the arm's contact force, "
                                "else its tracked pose in the grasp), then push from where it was found: a feature "
                                "off its place is found, not pushed into or missed. After a contact's first push, a "
                                "feature the object rests on turned (past 0.15 deg) is taken as turned for the "
                                "contact's other pushes. An arm that reports no tracked pose approaches as planned "
                                "(and says so)."),
              click.option("--replan-threshold", nargs=2, type=Finite(min=0, min_open=True), default=None,
                           metavar="MM DEG", help="With --closed-loop: deviation from the plan that triggers a "
                                                  "re-plan (default: half the task's goal tolerance)."),
              click.option("--final-tolerance", nargs=2, type=Finite(min=0, min_open=True), default=None,
                           metavar="MM DEG", help="With --closed-loop: after the last push, correct until the object "
                                                  "is this close to the goal, and re-plan on the last contact's "
                                                  "feature past it (default: a fifth of the task's goal "
                                                  "tolerance)."))
@robot_choice
@help_with(causes=", ".join(CAUSES))
def execute(files: PlanFiles, connection: ArmChoice, stream: StreamChoice, report: RunReport, talk: Verbosity,
            world: SimWorld, loop: LoopChoice, robot: RobotChoice) -> None:
    """Run a plan on an arm: stream end-effector waypoints and report what the arm confirmed.

    Each pusher the plan uses is a fixed feature of the world (the task's `environment:` section
    places them, else one station per pusher along y, 150 mm apart and alternating about home).
    During a push the object rests on its feature while the gripper moves; between pushes the
    gripper retracts, moves and approaches, and the approach finds the feature by touch (--guard).
    Waypoints (G's pose in the world, m and a quaternion) go out at --rate, each acknowledged with
    the arm's state: to a simulated arm in this process (--sim), or as JSON lines over TCP to an arm
    server (--arm: a real arm's bridge, or `stablepush sim-arm`).

    The run ends with a verdict: it landed when the object's pose in the grasp is within the task's
    goal tolerance (or --success-tolerance), exit 0; a completed run that missed exits 5 and names
    its cause. The report's `cause` is one of {causes} (docs/execution.md): the first that
    applies to a miss; not_measured where the arm reports no pose in the grasp, which gets no
    verdict (exit 0); arm_fault on a fault (below).

    On a fault (the arm server gone, a malformed or out-of-order reply, an error from the arm) the arm
    is told to stop, the last confirmed plan step is printed, and the exit status is 3; run again with
    --resume-from STEP to continue. A plan that does not belong to the task exits 2 before anything moves,
    and so does one the arm cannot follow in its cell: the simulated arm, or an arm server with --robot
    (or the task's environment.robot), is checked for reach, joint limits and speeds, and links clear of
    the features and the floor at every sample first (as `stablepush check-cell` checks).

    \b
    Examples:
      stablepush execute low-mu.plan.json --task data/tasks/horizontal-offset-low-mu.yaml --sim
      stablepush execute low-mu.plan.json --task data/tasks/horizontal-offset-low-mu.yaml --sim --video low-mu.mp4
      stablepush sim-arm --port 47100 &     # or your robot's bridge
      stablepush execute low-mu.plan.json --task data/tasks/horizontal-offset-low-mu.yaml --arm 127.0.0.1:47100
    """
    from stablepush.execution import (
        BagRecording,
        GuardedApproach,
        JsonReport,
        RunOptions,
        check_resume_from,
        execution_warnings,
        recording_for,
        run_plan,
    )
    from stablepush.outputs import require_suffix

    json_path, record_path, stamp_ns, video = report.json_path, report.record_path, report.stamp_ns, report.video
    quiet = talk.quiet
    require_suffix("--record", record_path, (".mcap",))
    if stamp_ns is not None and not record_path:
        fail("--stamp: only with --record (it is the recording's start time)")
    check_named_outputs({"--json": json_path, "--record": record_path, "--video": video.path}, files.inputs())
    task, plan = files.load()
    task = robot.on(task)
    for warning in execution_warnings(task):
        click.echo(f"warning: {warning}", err=True)
    check_resume_from(plan.waypoints, stream.resume_from, field="--resume-from")
    _only_with("--closed-loop", loop.closed_loop, ("--replan-threshold", loop.replan_threshold),
               ("--final-tolerance", loop.final_tolerance))
    if connection.sim and connection.arm is not None:
        fail("--sim and --arm: choose one (a simulated arm started here, or the arm server at HOST:PORT)")
    _only_with("--sim (a simulated arm started here)", connection.sim,
               ("--engine", connection.engine != DEFAULT_ENGINE), ("--sim-mu-scale", world.mu_scale != 1.0),
               ("--tracker-noise", any(world.tracker_noise)), ("--world", bool(world.world)))
    world.deviation().world_task(task)  # each field one the task has (TaskError naming it)
    _only_with("an arm server (--arm, or no --sim)", not connection.sim, ("--ack-timeout", given("ack_timeout")))
    # The video is made first: the renderer needs MUJOCO_GL=osmesa before the simulated arm loads MuJoCo.
    videos = ([video_output("--video", video.path, video.fps, video.size, quiet, video.view)] if video.path
              else [])
    if not video.path:
        video_settings_need("--video")
    named = ([("--json", JsonReport(json_path))] if json_path else []) + (
        [("--record", BagRecording(record_path, stamp_ns))] if record_path else []) + [("--video", v) for v in videos]
    outputs = [output for _, output in named]
    try:
        guard = GuardedApproach.for_tracker_noise(*world.tracker_noise) if loop.guarded else None
    except SettingError as exc:  # a noise the guard cannot tell a touch from
        fail(f"--tracker-noise: {exc.reason}")
    options = RunOptions(rate_hz=stream.rate_hz, resume_from=stream.resume_from, pace=stream.pace,
                         closed_loop=loop.loop_for(task), guard=guard, success_tolerance=report.success_tolerance)
    target = _arm_for(connection, world, quiet, task.environment.robot)
    with _run_progress(task, plan, stream.resume_from, quiet) as progress:
        run = run_plan(task, plan, target, options, progress=progress,
                       recording=recording_for(task, plan, options, outputs))
    try:  # after the run's bar has ended: the video draws its own
        run.write(outputs)
    finally:
        for output in videos:
            if output.progress is not None:
                output.progress.close()
    say = say_beside(json_path, record_path, video.path)
    lines = run.written if run.fault is not None else run.report.describe(talk.verbose) + run.written
    for line in lines:
        say(line)
    for output, error in run.failed:  # as each would have been refused before the run, named by its option
        fail(f"{next(name for name, o in named if o is output)} {error}")
    if run.fault is not None:
        _report_fault(run.fault, files.plan_file, len(plan.waypoints) - 1, connection.sim)
    if run.report.success is False:
        sys.exit(EXIT_MISSED)


def _only_with(option: str, given: bool, *others) -> None:
    """Exit 2 when any of `others` ((name, given) pairs) is given without `option`."""
    named = [name for name, value in others if value]
    if named and not given:
        fail(f"{' and '.join(named)}: only with {option}")


def _arm_for(connection: ArmChoice, world: SimWorld, quiet: bool, robot):
    """The arm a run goes to: a simulated `robot` in this process (--sim), else the arm server at
    --arm (or the default port here), checked against `robot` when one is named."""
    if connection.sim and connection.arm is None:
        from stablepush.sim import SimulatedArm

        log = None if quiet else lambda text: click.echo(f"sim-arm: {text}", err=True)
        return SimulatedArm(connection.engine, world.deviation(), log=log, robot=robot)
    from stablepush.execution import TcpArm
    from stablepush.kinematics import modelled

    host, port = connection.arm or ("127.0.0.1", DEFAULT_PORT)
    return modelled(TcpArm(host, port, connection.ack_timeout), robot)


@contextlib.contextmanager
def _run_progress(task, plan, resume_from: int, quiet: bool):
    """A progress bar over the plan's steps (a re-plan may change their number), as the progress
    callback of a run; None without a terminal."""
    bar = progressbar(quiet, length=len(plan.waypoints) - 1 - resume_from, label=f"{task.name}: step {resume_from}",
                       show_pos=True)
    if bar is None:
        yield None
        return
    seen = [resume_from]

    def progress(waypoint, confirmed, total):
        if total - resume_from != bar.length:  # a re-plan changed the plan's length
            bar.length = total - resume_from
        if confirmed > seen[0]:
            bar.label = f"{task.name}: step {confirmed} ({waypoint.phase})"
            bar.update(confirmed - seen[0])
            seen[0] = confirmed

    with bar:
        yield progress


def _report_fault(fault, plan_file: str, last_step: int, sim: bool) -> None:
    """Print how a run ended in an arm fault, and where to resume, then exit 3."""
    if not fault.connected and sim:
        click.echo(f"error: {fault.reason}; nothing moved", err=True)
        sys.exit(EXIT_ARM_FAULT)
    if not fault.connected:
        click.echo(f"error: {fault.reason}; nothing was sent. Is the arm server running? "
                   f"(`stablepush sim-arm` serves a simulated arm, or run with --sim)", err=True)
        sys.exit(EXIT_ARM_FAULT)
    stopped = {True: "the arm was stopped", None: "the arm could not be reached to stop it"}[fault.arm_stopped]
    if fault.replanned:  # its steps are the closed loop's, numbered otherwise than the plan file's
        click.echo(f"error: {fault.reason}; {stopped}; the closed loop had re-planned the run, so no step of "
                   f"{plan_file} continues it: plan again from where the object is in the grasp (a task whose "
                   f"start: is the tracked pose)", err=True)
        sys.exit(EXIT_ARM_FAULT)
    click.echo(f"error: {fault.reason}; {stopped}; last confirmed step: {fault.last_confirmed_step} of "
               f"{last_step}", err=True)
    click.echo(f"continue with: {_resume_command(click.get_current_context(), fault.last_confirmed_step)}", err=True)
    sys.exit(EXIT_ARM_FAULT)


# The options of `execute` that say how a run runs, so a resume keeps them (outputs are left out:
# a resumed run writes its own).
RUN_OPTIONS = ("arm", "sim", "engine", "rate_hz", "pace", "ack_timeout", "success_tolerance", "mu_scale",
               "tracker_noise", "world", "closed_loop", "replan_threshold", "final_tolerance", "guarded")


def _resume_command(ctx: click.Context, step: int) -> str:
    """The command that continues this `execute` from plan step `step`: its arguments and every
    option of RUN_OPTIONS given other than its default, as typed."""
    import shlex

    words = ["stablepush", "execute", ctx.params["plan_file"], "--task", ctx.params["task_file"]]
    for param in ctx.command.params:
        value = ctx.params.get(param.name)
        if param.name not in RUN_OPTIONS or value is None or value == param.get_default(ctx):
            continue
        if param.name == "arm":
            words += ["--arm", f"{value[0]}:{value[1]}"]
        elif param.name == "world":
            words += [word for name, number in value for word in ("--world", f"{name}={number!r}")]
        elif isinstance(param, click.Option) and param.is_flag and param.secondary_opts:  # --x/--no-x
            words.append(param.opts[0] if value else param.secondary_opts[0])
        elif isinstance(param, click.Option) and param.is_flag:
            words.append(param.opts[0])
        else:
            words += [param.opts[0], *(f"{v:g}" if isinstance(v, float) else str(v)
                                       for v in (value if isinstance(value, tuple) else (value,)))]
    return shlex.join(words + ["--resume-from", str(step)])
