"""`stablepush trajectory`."""
from __future__ import annotations

import click

from stablepush_cli.common import (
    check_named_outputs,
    fail,
)
from stablepush_cli.groups import PlanFiles, RobotChoice, plan_and_task, robot_choice
from stablepush_cli.options import (
    Finite,
    stamp_option,
)


@click.command()
@plan_and_task()
@click.option("-o", "--output", "out_path", required=True, type=click.Path(dir_okay=False),
              metavar="TRAJ.csv|.json|.mcap",
              help="Where to write the trajectory: CSV (a header, one row per sample), JSON (columns and rows), or a "
                   "ROS 2 bag in one MCAP file (/tf, /tf_static, the gripper's pose and twist, phase, step and the "
                   "scene as markers; docs/execution.md, 'ROS 2 bags').")
@click.option("--rate", "rate_hz", default=100.0, show_default=True, type=Finite(min=1, max=1000),
              metavar="HZ", help="Samples per second (the executor streams at this rate). Each push takes the "
                                 "fewest whole samples that last the task's dynamics.step_time: a rate that does not "
                                 "divide it pushes slower than the stability test assumed. The last push of each "
                                 "contact eases to rest, up to 4/3 of the planned speed on the way "
                                 "(docs/execution.md).")
@click.option("--quat", type=click.Choice(["xyzw", "wxyz"]), default=None,
              help="Quaternion order in a .csv or .json: xyzw as ROS writes it (the default), wxyz as the arm "
                   "protocol and MuJoCo do. A .mcap's messages are ROS's own, xyzw.")
@click.option("--joints", is_flag=True,
              help="The arm's joint positions (rad: the shipped arm, or --robot, or the task's environment.robot), "
                   "once every sample is checked: within the joints' limits and reach, each joint under its speed "
                   "limit, every link clear of the features and the floor; a plan the arm cannot follow exits 2 "
                   "naming the first sample, the joint or the link. A "
                   ".csv or .json holds them instead of G's poses (a column per joint for the positions, the "
                   "velocities and the accelerations); a .mcap adds /joint_states, a trajectory_msgs/JointTrajectory "
                   "(/stablepush/joint_trajectory, in the arm's base link, with velocities and accelerations) and, "
                   "for a URDF arm, /robot_description. Needs the [sim] extra.")
@stamp_option("a .mcap", "now")
@robot_choice
def trajectory(files: PlanFiles, out_path: str, rate_hz: float, quat: str, joints: bool, stamp_ns,
               robot: RobotChoice) -> None:
    """Write the gripper's timed trajectory for a plan: what the executor streams, for your robot.

    One sample per 1/HZ s: time (s), G's position in the world (m) and orientation (a unit
    quaternion), its linear (m/s) and angular (rad/s) velocity in the world over the period that
    ends there, the phase (push, settle, retract, move, approach) and the plan step. The world
    is the executor's: G starts at the task's environment.home (1 mm back from the first feature
    when the object starts on it, as the guarded approach starts), each pusher a fixed feature
    placed as `execute` places it.

    \b
    Example:
      stablepush plan data/tasks/t-shaped.yaml -o t.plan.json
      stablepush trajectory t.plan.json --task data/tasks/t-shaped.yaml -o t.traj.csv
      stablepush trajectory t.plan.json --task data/tasks/t-shaped.yaml -o t.mcap   # ros2 bag play, Foxglove
    """
    from stablepush.execution import execution_warnings, timed_trajectory
    from stablepush.outputs import require_suffix, write_atomically

    require_suffix("-o", out_path, (".csv", ".json", ".mcap"))
    if quat is not None and out_path.lower().endswith(".mcap"):
        fail(f"--quat {quat}: a ROS 2 bag's quaternions are its message types' own (x, y, z, w); --quat is for "
              f".csv and .json")
    if stamp_ns is not None and not out_path.lower().endswith(".mcap"):
        fail("--stamp: only with a .mcap (a ROS 2 bag; a .csv or .json counts t from 0)")
    if not joints and robot != RobotChoice():
        fail("--robot, --flange, --tcp and --base: only with --joints (G's poses are the same for every arm)")
    if joints and quat is not None:
        fail("--joints: joint positions have no quaternions; --quat is for the gripper's poses")
    quat = quat or "xyzw"
    check_named_outputs({"-o": out_path}, files.inputs())
    task, plan = files.load()
    task = robot.on(task)
    for warning in execution_warnings(task):  # the stream is the executor's, so is its cell
        click.echo(f"warning: {warning}", err=True)
    traj = timed_trajectory(task, plan, rate_hz)
    path = None
    if joints:
        from stablepush.kinematics import joint_path

        path = joint_path(task, plan, rate_hz, traj)
        if not out_path.lower().endswith(".mcap"):
            write_atomically(out_path, path.to_json() if out_path.lower().endswith(".json") else path.to_csv())
            click.echo(f"{task.name}: {path.describe()}; written to {out_path}")
            return
    if out_path.lower().endswith(".mcap"):
        from stablepush.execution import write_bag

        write_bag(out_path, task, plan, traj, start_ns=stamp_ns,
                  joints=None if path is None else path.samples())
        if path is not None:
            click.echo(f"{task.name}: {path.describe()}")
    else:
        write_atomically(out_path, traj.to_json(quat) if out_path.lower().endswith(".json") else traj.to_csv(quat))
    click.echo(f"{task.name}: {len(traj)} samples at {rate_hz:g} Hz, {traj.t[-1]:.2f} s, "
               f"{len(plan.waypoints) - 1} pushes; written to {out_path}")
