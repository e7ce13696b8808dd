"""The low-μ offset varied in ways nothing was tuned for (docs/results/planning.md, "Planning"): other goals, other
friction and grip, an extra ledge. Seeds 1-N, 3 s limit; median and p95 of time and of stable-push
tests (the machine-independent count).

    python3 benchmarks/low_mu_variants.py [--seeds 30]

Run it with PYTHONPATH pointing at a `pip install --target DIR .` of another commit to compare.
"""
import argparse
import copy
from pathlib import Path

import numpy as np
import yaml

from stablepush.plan import plan_task
from stablepush.task import parse_task

TASK = Path(__file__).resolve().parent.parent / "data" / "tasks" / "horizontal-offset-low-mu.yaml"


def _pushers_mu(mu):
    return lambda d: [p.update(mu=mu) for p in d["pushers"]]


VARIANTS = {
    "goal 15 mm": lambda d: d.update(goal=[15, 0, 0]),
    "goal 30 mm": lambda d: d.update(goal=[30, 0, 0]),
    "goal -20 mm (right pusher)": lambda d: d.update(goal=[-20, 0, 0]),
    "goal 20 mm, 5 deg": lambda d: d.update(goal=[20, 0, 5]),
    "pusher mu 0.15": _pushers_mu(0.15),
    "pusher mu 0.25": _pushers_mu(0.25),
    "grip 8 N": lambda d: d["gripper"].update(grip_force=8),
    "a top ledge too": lambda d: d["pushers"].append({"name": "top", "from": [-10, 12.5], "to": [10, 12.5], "mu": 0.2}),
    "robust ±15% μ": lambda d: d.update(uncertainty={"pad_mu": 0.15, "pusher_mu": 0.15}),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=30, help="seeds 1..N (default 30)")
    args = parser.parse_args()
    base = yaml.safe_load(TASK.read_text())
    print("| variant | solved | median ms | p95 ms | tests median | tests p95 |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, edit in VARIANTS.items():
        data = copy.deepcopy(base)
        edit(data)
        data["planner"]["time_limit"] = 3
        task = parse_task(yaml.safe_dump(data), f"{TASK.name} ({name})")
        plans = [plan_task(task, seed=s) for s in range(1, args.seeds + 1)]
        ms = np.array([p.stats["planning_time_s"] * 1e3 for p in plans])
        tests = np.array([p.stats["feasibility_checks"] for p in plans])
        print(f"| {name} | {sum(p.solved for p in plans)}/{args.seeds} | {np.median(ms):.2f} | "
              f"{np.percentile(ms, 95):.2f} | {np.median(tests):.0f} | {np.percentile(tests, 95):.0f} |", flush=True)


if __name__ == "__main__":
    main()
