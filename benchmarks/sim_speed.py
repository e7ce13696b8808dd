"""How fast the simulated arm runs a plan, one worker (docs/evaluate.md, "Speed"): each task's seed-1
plan streamed straight into the MuJoCo arm in this process (no socket, no executor), open loop, in
the task's own world. Per task: the robot time, the wall and CPU seconds, robot seconds per wall
second (x real time), the pads' scratch steps (stablepush.sim.mujoco.friction), the mj_step calls per time
step (a scratch step taken as the time step counts once), and a fingerprint of the final state, so
that a change meant to make the simulation cheaper can show it left every state as it was.

    python3 benchmarks/sim_speed.py [TASK.yaml ...] [--waypoints N] [--rate 100] [--timers]
                                    [--option NAME=VALUE ...]

`--timers` adds MuJoCo's own timers (mujoco.set_mjcb_time) of the real steps: microseconds per
`mj_step` and in its constraint solve (noslip included), and the mean contacts, constraint rows and
solver iterations at the waypoints. `--option` sets a field of the model's `opt` after the scene is
built (`--option tolerance=1e-6 --option noslip_iterations=0`): a what-if of the solver's settings,
which changes the physics, so the fingerprint tells whether a state moved.

CPU seconds hold better than wall seconds on a loaded machine; compare builds on the same machine.
"""
import argparse
import hashlib
import time
from pathlib import Path

import mujoco
import numpy as np
from shipped import TASKS

from stablepush.execution.stream import arm_trajectory
from stablepush.execution.world import place_features, scene_description
from stablepush.plan import plan_task
from stablepush.sim.mujoco.arm import SimArm
from stablepush.task import load_task


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path, help="task files (default: the pivot and the T)")
    parser.add_argument("--waypoints", type=int, default=None, metavar="N",
                        help="stream only the first N waypoints of each plan (default: all)")
    parser.add_argument("--rate", type=float, default=100.0, help="waypoints per second (default 100)")
    parser.add_argument("--timers", action="store_true", help="MuJoCo's timers of the real steps, and the solver's load")
    parser.add_argument("--option", action="append", default=[], metavar="NAME=VALUE",
                        help="set model.opt.NAME after the scene is built (repeatable)")
    args = parser.parse_args()
    tasks = args.tasks or [TASKS / "pivoting.yaml", TASKS / "t-shaped.yaml"]
    options = [_option(text) for text in args.option]
    if args.timers:
        mujoco.set_mjcb_time(time.perf_counter)
    extra = " mj_step us | constraint us | contacts | rows | iterations |" if args.timers else ""
    print("| task | waypoints | robot s | wall s | CPU s | x real time | scratch steps / step | mj_step calls / step "
          "| final state |" + extra)
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|" + "---:|" * (5 if args.timers else 0))
    for path in tasks:
        task = load_task(path)
        steps = list(plan_task(task).waypoints)
        features = place_features(task, steps)
        scene = scene_description(task, features, steps[0].pose)
        arm = SimArm(scene)
        for name, value in options:
            setattr(arm.model.opt, name, type(getattr(arm.model.opt, name))(value))
        timed = {k: _timer(arm.data, k) for k in ("STEP", "CONSTRAINT")}
        load = []
        points = arm_trajectory(task, steps, features, args.rate, scene.gripper_pose)[:args.waypoints]
        period = 1.0 / args.rate
        friction = arm.pad_friction
        steps_before = round(float(arm.data.time) / arm.timestep)
        scratch_before = friction.trial_steps + friction.solver_steps
        copied_before = friction.copied_steps
        wall, cpu = time.perf_counter(), time.process_time()
        for point in points:
            arm.move_to(point.pose, period)
            if args.timers:
                load.append((arm.data.ncon, arm.data.nefc, arm.data.solver_niter[0]))
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        robot = len(points) * period
        real_steps = round(float(arm.data.time) / arm.timestep) - steps_before
        scratch_steps = friction.trial_steps + friction.solver_steps - scratch_before
        calls = real_steps - (friction.copied_steps - copied_before) + scratch_steps
        state = hashlib.sha1(np.concatenate([arm.data.qpos, arm.data.qvel]).tobytes()).hexdigest()[:12]
        print(f"| {task.name} | {len(points)} | {robot:.2f} | {wall:.2f} | {cpu:.2f} | {robot / wall:.2f} "
              f"| {scratch_steps / max(real_steps, 1):.2f} | {calls / max(real_steps, 1):.2f} | {state} |"
              + (_timers_cells(arm.data, timed, load) if args.timers else ""), flush=True)


def _option(text: str):
    name, _, value = text.partition("=")
    try:
        if isinstance(getattr(mujoco.MjOption(), name), (int, float)):
            return name, float(value)
    except (AttributeError, ValueError):
        pass
    raise SystemExit(f"--option {text}: expected NAME=VALUE with NAME a number field of mujoco.MjOption")


def _timer(data, name: str):
    """(seconds, count) of MuJoCo's timer mjTIMER_<name> on `data` so far."""
    stat = data.timer[int(getattr(mujoco.mjtTimer, "mjTIMER_" + name))]
    return stat.duration, stat.number


def _timers_cells(data, before: dict, load: list) -> str:
    """The mean microseconds of the real steps and of their constraint solves since `before`, and the
    mean contacts, constraint rows and solver iterations at the waypoints. A step the pads' friction
    took from its scratch copy (stablepush.sim.mujoco.friction) ran on that copy and is not among them."""
    cells = []
    for name, (seconds, count) in before.items():
        now_seconds, now_count = _timer(data, name)
        cells.append(f"{1e6 * (now_seconds - seconds) / max(now_count - count, 1):.1f}")
    cells += [f"{v:.1f}" for v in np.mean(load, axis=0)]
    return " " + " | ".join(cells) + " |"


if __name__ == "__main__":
    main()
