"""How fast the simulated arm runs a plan, one worker (docs/evaluate.md, "Speed"): each task's seed-1
plan streamed straight into the MuJoCo arm in this process (no socket, no executor), open loop, in
the task's own world. Per task: the robot time, the wall and CPU seconds, robot seconds per wall
second (x real time), the pads' scratch steps (stablepush.sim.friction), the mj_step calls per time
step (a scratch step taken as the time step counts once), and a fingerprint of the final state, so
that a change meant to make the simulation cheaper can show it left every state as it was.

    python3 benchmarks/sim_speed.py [TASK.yaml ...] [--waypoints N] [--rate 100]

CPU seconds hold better than wall seconds on a loaded machine; compare builds on the same machine.
"""
import argparse
import hashlib
import time
from pathlib import Path

import numpy as np
from shipped import TASKS

from stablepush.execution.stream import arm_trajectory
from stablepush.execution.world import place_features, scene_description
from stablepush.plan import plan_task
from stablepush.sim.arm import SimArm
from stablepush.task import load_task


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path, help="task files (default: the pivot and the T)")
    parser.add_argument("--waypoints", type=int, default=None, metavar="N",
                        help="stream only the first N waypoints of each plan (default: all)")
    parser.add_argument("--rate", type=float, default=100.0, help="waypoints per second (default 100)")
    args = parser.parse_args()
    tasks = args.tasks or [TASKS / "pivoting.yaml", TASKS / "t-shaped.yaml"]
    print("| task | waypoints | robot s | wall s | CPU s | x real time | scratch steps / step | mj_step calls / step "
          "| final state |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|")
    for path in tasks:
        task = load_task(path)
        steps = list(plan_task(task).waypoints)
        features = place_features(task, steps)
        scene = scene_description(task, features, steps[0].pose)
        arm = SimArm(scene)
        points = arm_trajectory(task, steps, features, args.rate, scene["gripper_pose"])[:args.waypoints]
        period = 1.0 / args.rate
        friction = arm.pad_friction
        steps_before = round(float(arm.data.time) / arm.timestep)
        scratch_before = friction.trial_steps + friction.solver_steps
        copied_before = friction.copied_steps
        wall, cpu = time.perf_counter(), time.process_time()
        for point in points:
            arm.move_to(point.pose, period)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        robot = len(points) * period
        real_steps = round(float(arm.data.time) / arm.timestep) - steps_before
        scratch_steps = friction.trial_steps + friction.solver_steps - scratch_before
        calls = real_steps - (friction.copied_steps - copied_before) + scratch_steps
        state = hashlib.sha1(np.concatenate([arm.data.qpos, arm.data.qvel]).tobytes()).hexdigest()[:12]
        print(f"| {task.name} | {len(points)} | {robot:.2f} | {wall:.2f} | {cpu:.2f} | {robot / wall:.2f} "
              f"| {scratch_steps / max(real_steps, 1):.2f} | {calls / max(real_steps, 1):.2f} | {state} |", flush=True)


if __name__ == "__main__":
    main()
