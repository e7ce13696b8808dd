"""Point pushers: the cube with two pegs (data/tasks/more/cube-pegs.yaml) over seeds,
then goals 10 mm from the start in 8 directions at +-20 degrees, to show where a peg's surface of
stable pushes reaches and where it does not.

    python3 benchmarks/point_pushers.py [--seeds 10] [--time-limit 1]
"""
import argparse
import dataclasses
import math
from pathlib import Path

import numpy as np

from stablepush.plan import plan_task
from stablepush.task import load_task

TASK = Path(__file__).resolve().parent.parent / "data" / "tasks" / "more" / "cube-pegs.yaml"


def _runs(task, seeds):
    plans = [plan_task(task, seed=seed) for seed in range(1, seeds + 1)]
    times = np.array([p.stats["planning_time_s"] * 1e3 for p in plans])
    return plans, times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--time-limit", type=float, default=1.0, help="s per plan in the sweep of goals")
    args = parser.parse_args()
    task = load_task(TASK)
    plans, times = _runs(task, args.seeds)
    print(f"{task.name}, goal {list(task.goal)}: solved {sum(p.solved for p in plans)}/{args.seeds}, "
          f"median {np.median(times):.1f} ms, p95 {np.percentile(times, 95):.1f} ms, max {times.max():.1f} ms, "
          f"switch-overs {sorted({p.stats['switches'] for p in plans})}\n")
    print("| goal heading deg | goal theta deg | solved | median ms | pushers used |")
    print("|---:|---:|---:|---:|---|")
    planner = task.planner.replace(time_limit=args.time_limit)
    for theta in (20, -20):
        for heading in range(0, 360, 45):
            goal = (10 * math.cos(math.radians(heading)), 10 * math.sin(math.radians(heading)), theta)
            variant = dataclasses.replace(task, goal=goal, planner=planner)
            plans, times = _runs(variant, args.seeds)
            used = sorted({w.pusher for p in plans if p.solved for w in p.waypoints[1:]})
            print(f"| {heading} | {theta:+d} | {sum(p.solved for p in plans)}/{args.seeds} | {np.median(times):.1f} "
                  f"| {', '.join(used) or '-'} |", flush=True)


if __name__ == "__main__":
    main()
