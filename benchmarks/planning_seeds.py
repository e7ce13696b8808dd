"""Planning time and stable-push tests over many seeds (docs/results/planning.md, "Planning"): each seed planned
twice and the faster time kept (this machine's timings are noisy; the tests are not).

    python3 benchmarks/planning_seeds.py [TASK.yaml ...] [--seeds 100]

To compare two builds, run it once with each installed (or with PYTHONPATH pointing at a
`pip install --target DIR .` of the other commit).
"""
import argparse
from pathlib import Path

import numpy as np
from shipped import shipped_tasks

from stablepush.plan import plan_task
from stablepush.task import load_task


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path, help="task files (default: data/tasks/*.yaml)")
    parser.add_argument("--seeds", type=int, default=100, help="seeds 1..N (default 100)")
    args = parser.parse_args()
    paths = args.tasks or shipped_tasks(more=False)
    print("| task | solved | median ms | p95 ms | max ms | tests median | tests p95 | switch-overs (mean) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for path in paths:
        task = load_task(path)
        times = np.full((2, args.seeds), np.inf)
        tests = np.zeros(args.seeds)
        switches = np.zeros(args.seeds)
        solved = 0
        for attempt in range(2):
            for k in range(args.seeds):
                plan = plan_task(task, seed=k + 1)
                times[attempt, k] = plan.stats["planning_time_s"] * 1e3
                tests[k] = plan.stats["feasibility_checks"]
                switches[k] = plan.stats["switches"]
                solved += attempt == 0 and plan.solved
        best = times.min(axis=0)
        print(f"| {task.name} | {solved}/{args.seeds} | {np.median(best):.2f} | {np.percentile(best, 95):.2f} | "
              f"{best.max():.1f} | {np.median(tests):.0f} | {np.percentile(tests, 95):.0f} | {switches.mean():.2f} |",
              flush=True)


if __name__ == "__main__":
    main()
