"""`stablepush calibrate`."""
from __future__ import annotations

import json

import click

from stablepush.calibration import LIMITS, NEIGHBOURHOOD, PAD_PRODUCT, CalibrationSettings
from stablepush.execution import DEFAULT_PORT
from stablepush_cli.common import check_named_outputs, fail, help_with, load_task_file, say_beside
from stablepush_cli.groups import (
    ArmChoice,
    RobotChoice,
    SimWorld,
    arm_connection,
    option_group,
    robot_choice,
    sim_world,
)
from stablepush_cli.options import Finite, Whole

DEFAULTS = CalibrationSettings()


def _settings(max_probes, spread, target, error_rate, rate_hz, return_to_start, estimate):
    return CalibrationSettings(max_probes=max_probes, spread=spread, target=target, error_rate=error_rate,
                               rate_hz=rate_hz, return_to_start=return_to_start,
                               estimate=tuple(estimate) or DEFAULTS.estimate)


@click.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@arm_connection("Calibrate on a simulated arm started here (see --engine, and --world for a world that hides its "
                "friction).")
@sim_world()
@click.option("--from", "runs", multiple=True, metavar="RUN.json", type=click.Path(dir_okay=False),
              help="Instead of probing: learn from runs already made, the JSON reports of `stablepush execute --json` "
                   "(each contact's pushes and its measured slip). Repeatable.")
@option_group(
    "settings", _settings,
    click.option("--max-probes", default=DEFAULTS.max_probes, show_default=True, metavar="N",
                 type=Whole(*LIMITS["max_probes"]), help="Run at most N probes."),
    click.option("--spread", default=DEFAULTS.spread, show_default=True, metavar="F", type=Finite(*LIMITS["spread"]),
                 help="What the world's mu may be: each from the task's times 1 - F to 1 + F."),
    click.option("--target", nargs=2, default=DEFAULTS.target, show_default=True, metavar="PADS PUSHERS",
                 type=Finite(min=0, max=1, min_open=True, max_open=True),
                 help="Stop once each interval's half-width is within this share of its estimate (the pads', a "
                      "pusher's)."),
    click.option("--error-rate", default=DEFAULTS.error_rate, show_default=True, metavar="P",
                 type=Finite(*LIMITS["error_rate"]),
                 help="How often an observed stick or slip is taken to be wrong (near the boundary of stability the "
                      "simulator and a tracker can be)."),
    click.option("--rate", "rate_hz", default=DEFAULTS.rate_hz, show_default=True, metavar="HZ",
                 type=Finite(min=1, max=1000), help="Waypoints per second of the probes' runs (as `execute --rate`)."),
    click.option("--return/--no-return", "return_to_start", default=True, show_default=True,
                 help="End by pushing the object back to the task's start, by a plan of the calibrated task."),
    click.option("--estimate", multiple=True, metavar="FIELD", type=click.Choice(PAD_PRODUCT),
                 help="Which of the pads' quantities is unknown (default gripper.mu; the others are taken as the "
                      "task gives them). They enter the model only as the product mu x grip force / mass, so the "
                      "probes measure that product: one FIELD named is estimated from it; two or more, the product "
                      "alone is reported. Repeatable."))
@option_group(
    "outputs", lambda output, json_path: (output, json_path),
    click.option("-o", "--output", "output", default=None, metavar="CALIBRATED.yaml", type=click.Path(dir_okay=False),
                 help="Write the task with each estimated mu replaced by its estimate and an uncertainty box (pad_mu, "
                      "pusher_mu) that covers the intervals: `stablepush plan` takes it unchanged."),
    click.option("--json", "json_path", default=None, metavar="PATH", type=click.Path(dir_okay=False),
                 help="Write the estimates (task field -> value, low, high), every probe with its outcome and what "
                      "could not be identified and why, as JSON (/dev/stdout: on standard output, the lines on "
                      "stderr)."))
@click.option("--quiet", is_flag=True, help="No line per probe.")
@robot_choice
@help_with(pushes=DEFAULTS.pushes, near_mm=NEIGHBOURHOOD[0], near_deg=NEIGHBOURHOOD[1])
def calibrate(task_file: str, connection: ArmChoice, world: SimWorld, runs, settings, outputs, quiet: bool,
              robot: RobotChoice) -> None:
    """Measure the friction the arm will push with: the pads' mu (or grip force, or mass) and each feature's.

    The model chooses short probing pushes ({pushes} unit pushes by one feature) whose outcome, the part
    following its pusher or slipping, flips at a known value of the unknown mu: the stable-push
    test as a function of mu is the instrument. Each probe is the one whose outcome is least
    certain given what earlier ones showed, and every probe is safe in every world considered
    (the pads stay on the part and hold it, within 10 mm and 10 deg of the start). Probes run on
    the arm as `execute` runs a plan (the same arm port and tracker: --sim, or --arm for a lab's
    bridge); the tracker's pose in the grasp says whether a probe stuck. Grip force and mass are
    taken as the task gives them, unless --estimate names one (then the pads' mu is taken as given).

    It stops when every mu a probe can reach is within --target, or after --max-probes; Ctrl-C
    stops after the probe running and keeps what was measured. Then, unless --no-return, a plan of
    the calibrated task pushes the part back to the start. docs/calibrate.md says how the
    intervals are made and what calibration cannot see.

    \b
    Examples:
      stablepush calibrate data/tasks/t-shaped.yaml --sim --world gripper.mu=0.2 -o t-cal.yaml
      stablepush calibrate data/tasks/t-shaped.yaml --arm 10.0.0.7:47100 --json cal.json
      stablepush calibrate data/tasks/t-shaped.yaml --from run1.json --from run2.json
      stablepush calibrate data/tasks/t-shaped.yaml --sim --world gripper.grip_force=8 --estimate gripper.grip_force
    """
    from stablepush.outputs import write_atomically

    output, json_path = outputs
    check_named_outputs({"-o": output, "--json": json_path}, {"TASK.yaml": task_file})
    task = robot.on(load_task_file(task_file))
    if runs and (connection.sim or connection.arm is not None):
        fail("--from and --sim/--arm: choose one (learn from runs made, or probe on an arm)")
    if not connection.sim and (world.world or world.mu_scale != 1.0 or any(world.tracker_noise)):
        fail("--world, --sim-mu-scale and --tracker-noise: only with --sim (a simulated arm started here)")
    say = say_beside(json_path)
    if runs:
        calibration = _from_runs(task, runs, settings)
    else:
        world.deviation().world_task(task)  # each field one the task has (TaskError naming it)
        calibration = _probe(task, connection, world, settings, quiet, say)
    for line in calibration.describe():
        say(line)
    if output:
        from stablepush.calibration import calibrated_task_text

        write_atomically(output, calibrated_task_text(calibration))
        say(f"calibrated task written to {output}")
    if json_path:
        write_atomically(json_path, json.dumps(calibration.as_dict(), indent=1) + "\n")
        say(f"estimates written to {json_path}")


def _from_runs(task, runs, settings):
    from stablepush.calibration import calibrate_from_runs, read_run_report

    return calibrate_from_runs(task, [(path, read_run_report(path)) for path in runs], settings)


def _probe(task, connection: ArmChoice, world: SimWorld, settings, quiet: bool, say):
    from stablepush.calibration import calibrate

    if connection.sim and connection.arm is not None:
        fail("--sim and --arm: choose one (a simulated arm started here, or the arm server at HOST:PORT)")

    def arm_for():
        if connection.sim:
            from stablepush.sim import SimulatedArm

            return SimulatedArm(connection.engine, world.deviation().fixed_to(task), robot=task.environment.robot)
        from stablepush.execution import TcpArm
        from stablepush.kinematics import modelled

        host, port = connection.arm or ("127.0.0.1", DEFAULT_PORT)
        return modelled(TcpArm(host, port, connection.ack_timeout), task.environment.robot)

    def progress(record, done):
        if not quiet:
            move = ", ".join(f"{v:+.2f}" for v in record.move)
            slip = (f"slip {record.slip_mm:.3f} mm, {record.slip_deg:.3f} deg" if record.slip_mm is not None
                    else record.error)
            say(f"probe {done}: {record.pusher} x{record.pushes} by ({move}) from "
                f"{[round(v, 2) for v in record.start]}: {record.outcome} ({slip}; expected to stick "
                f"{record.p_stuck:.0%})")

    return calibrate(task, arm_for, settings, progress)
