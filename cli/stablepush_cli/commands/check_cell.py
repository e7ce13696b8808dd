"""`stablepush check-cell`."""
from __future__ import annotations

import json

import click

from stablepush_cli.common import (
    check_named_outputs,
)
from stablepush_cli.groups import PlanFiles, RobotChoice, plan_and_task, robot_choice
from stablepush_cli.options import (
    Finite,
)


@click.command("check-cell")
@plan_and_task("The task the plan was made for (checked against the plan); its environment places the features "
               "and names the arm (environment.robot).")
@click.option("--rate", "rate_hz", default=100.0, show_default=True, type=Finite(min=1, max=1000), metavar="HZ",
              help="Samples per second of the timed trajectory checked (execute's --rate).")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None,
              help="Write the verdict as JSON: follows true with the figures printed, or follows false with the "
                   "sample, t, plan step, phase and reason.")
@robot_choice
def check_cell(files: PlanFiles, rate_hz: float, json_path, robot: RobotChoice) -> None:
    """Say whether the arm can follow a plan in its cell, before any motion.

    Every sample of the timed trajectory (as `trajectory` writes it and `execute` streams it) is
    solved for the arm's joints, each from the one before: within the joints' limits and reach,
    each joint under its speed limit (a URDF's limit velocity, else environment.robot's
    max_joint_speed), every link clear of the features and the floor. Exit 0 with the figures, or
    exit 2 naming the first sample it cannot follow: the joint at its limit, or the link and the
    fixture that collide and by how much. `execute` runs the same check on the simulated arm, and
    on an arm server given --robot. Needs the [sim] extra (MuJoCo's kinematics).

    \b
    Examples:
      stablepush check-cell t.plan.json --task data/tasks/t-shaped.yaml
      stablepush check-cell t.plan.json --task data/tasks/t-shaped.yaml \\
          --robot my_arm.urdf --flange tool0 --tcp 0 0 110 0 180 0 --base 0 0 0 0
    """
    from stablepush.extras import require
    from stablepush.outputs import write_atomically

    require("mujoco", "check-cell (the arm's kinematics)")
    from stablepush.kinematics import CellError, joint_path

    check_named_outputs({"--json": json_path}, files.inputs())
    task, plan = files.load()
    task = robot.on(task)
    arm = task.environment.robot.model or "the shipped arm"
    try:
        path = joint_path(task, plan, rate_hz)
    except CellError as refusal:
        if json_path:
            write_atomically(json_path, json.dumps({"arm": arm, **refusal.verdict()}, indent=1) + "\n")
        raise
    if json_path:
        write_atomically(json_path, json.dumps({"arm": arm, **path.verdict()}, indent=1) + "\n")
    click.echo(f"{task.name} on {arm}: the arm follows the plan: {path.describe()}")
