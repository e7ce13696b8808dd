"""Plan every shipped task (seed 1) and run it on the simulated arm over the socket: the final
pose in the grasp against the plan's, and the slip at the pusher per contact (docs/execution.md and docs/engines.md); then
the tasks of data/tasks/more, which nothing was tuned for.
`--mu-scale` runs each plan again in worlds whose pads' and features' mu differ from the task's.

    python3 benchmarks/execute_shipped.py [TASK.yaml ...] [--seed 1] [--mu-scale 1 0.85 1.15] [--closed-loop]
                                          [--success-tolerance MM DEG] [--engine mujoco drake] [--no-guard]

The verdict column is the run's (stablepush.execution.verdict): landed where the object came to
rest after the release (the goal error's pose), within the task's goal tolerance, or
--success-tolerance, or missed and why. Approaches are guarded (the executor's
default: each feature found by touch) unless --no-guard.
"""
import argparse
import math
from pathlib import Path

from shipped import shipped_tasks

from stablepush.execution.closed_loop import ClosedLoop
from stablepush.execution.guard import GuardedApproach
from stablepush.execution.run import RunOptions, run_plan
from stablepush.plan import check_plan, plan_task
from stablepush.sim.deviation import WorldDeviation
from stablepush.sim.engines import DEFAULT_ENGINE, ENGINES
from stablepush.sim.local_arm import SimulatedArm
from stablepush.task import load_task


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("tasks", nargs="*", type=Path, help="task files (default: every shipped task)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--mu-scale", type=float, nargs="+", default=[1.0], metavar="S",
                        help="world mu / task mu, one run per value (default 1)")
    parser.add_argument("--closed-loop", action="store_true", help="re-plan from the tracked pose (stablepush.closed_loop)")
    parser.add_argument("--success-tolerance", type=float, nargs=2, default=None, metavar=("MM", "DEG"),
                        help="judge each run with this tolerance (default: the task's goal tolerance)")
    parser.add_argument("--engine", nargs="+", choices=ENGINES, default=[DEFAULT_ENGINE],
                        help="the simulated arm's physics engine, one run per engine (default mujoco)")
    parser.add_argument("--no-guard", action="store_true", help="approaches end where the plan puts each feature")
    args = parser.parse_args()
    guard = None if args.no_guard else GuardedApproach()
    paths = args.tasks or shipped_tasks()
    print("| task | engine | world mu | loop | pushes | contacts | final error mm | final error deg | goal error mm / deg "
          "| re-plans | max slip at pusher mm (deg) | release moves it mm / deg | verdict | sim steps/s | wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for path in paths:
        task = load_task(path)
        plan = check_plan(task, plan_task(task, seed=args.seed))
        for scale in args.mu_scale:
            for engine in args.engine:
                _run(task, plan, scale, ClosedLoop.for_task(task) if args.closed_loop else None, args.success_tolerance,
                     engine, guard)


def _run(task, plan, mu_scale: float, loop, tolerance, engine: str, guard) -> None:
    arm = SimulatedArm(engine, WorldDeviation(mu_scale=mu_scale))
    report = run_plan(task, plan, arm, RunOptions(rate_hz=100.0, closed_loop=loop, guard=guard,
                                               success_tolerance=tolerance)).report_or_fault()
    err, goal = report.final_error, report.goal_error
    replans = f"{sum(r.solved for r in report.replans)}" + (f" (+{sum(not r.solved for r in report.replans)} failed)"
                                                            if any(not r.solved for r in report.replans) else "")
    slip = max(report.contacts, key=lambda c: c.slip_mm)
    release = report.release_change  # None: the run ends on its feature (environment.end_on_feature)
    released = "on its feature" if release is None else \
        f"{math.hypot(release['x'], release['z']):.2f} / {release['theta']:+.2f}"
    print(f"| {task.name} | {engine} | x{mu_scale:g} | {'closed' if loop else 'open'} | {report.total_steps} "
          f"| {' → '.join(c.pusher for c in report.contacts)} "
          f"| {err['distance']:.2f} | {err['theta']:+.2f} | {goal['distance']:.2f} / {goal['theta']:+.2f} | {replans} "
          f"| {slip.slip_mm:.2f} ({slip.slip_deg:.2f}) "
          f"| {released} "
          f"| {'landed' if report.success else 'missed: ' + str(report.verdict.cause)} "
          f"| {report.sim_steps_per_s:.0f} | {report.wall_time_s:.1f} |", flush=True)


if __name__ == "__main__":
    main()
