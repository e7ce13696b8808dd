"""How planning time grows with the number of pushers, the pad discretization and the distance
to the goal. Prints markdown tables (median / max planning time over seeds, success rate).

    python3 benchmarks/scaling.py [--trials 10] [--time-limit 2]

Variants are built from the shipped tasks by editing their YAML as a user would:
- pushers: large-manipulation (solvable by the left pusher alone) with 1..8 pushers (left,
  right, bottom, top, then four shorter segments near the corners of the bottom and top faces);
- pad_rings: 1, 2, 3 on the low-mu offset and the large manipulation (7, 19, 37 points per pad);
- goal distance: the high-mu offset to x = 5..40 mm, and the large manipulation scaled to
  25..100 % of its goal (15, -13, 45).
"""
from __future__ import annotations

import argparse
import copy
import statistics

import yaml
from shipped import TASKS

from stablepush.plan.benchmark import bench_planning
from stablepush.task import parse_task

EXTRA_PUSHERS = [  # on the large manipulation's 80 x 38 mm section, after its left pusher
    {"name": "right", "from": [40, -19], "to": [40, 19], "mu": 0.6},
    {"name": "bottom", "from": [-20, -19], "to": [20, -19], "mu": 0.6},
    {"name": "top", "from": [-20, 19], "to": [20, 19], "mu": 0.6},
    {"name": "bottom-left", "from": [-38, -19], "to": [-24, -19], "mu": 0.6},
    {"name": "bottom-right", "from": [24, -19], "to": [38, -19], "mu": 0.6},
    {"name": "top-left", "from": [-38, 19], "to": [-24, 19], "mu": 0.6},
    {"name": "top-right", "from": [24, 19], "to": [38, 19], "mu": 0.6},
]


def load(name):
    return yaml.safe_load((TASKS / f"{name}.yaml").read_text())


def row(label, data, trials, time_limit):
    task = parse_task(yaml.safe_dump(data), source=label)
    runs = bench_planning(task, trials, seed=1, time_limit=time_limit)
    times = [r.planning_time_s * 1e3 for r in runs]
    checks = statistics.median(r.feasibility_checks for r in runs)
    ok = sum(r.solved for r in runs) / len(runs)
    return f"| {label} | {statistics.median(times):.2f} | {max(times):.1f} | {ok:.0%} | {checks:.0f} |"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--trials", type=int, default=10)
    ap.add_argument("--time-limit", type=float, default=2.0)
    args = ap.parse_args()
    header = "| variant | median ms | max ms | solved | median checks |\n|---|---:|---:|---:|---:|"

    print("### Number of pushers (large-manipulation)\n\n" + header)
    base = load("large-manipulation")
    left = [p for p in base["pushers"] if p["name"] == "left"]
    for n in range(1, 9):
        data = copy.deepcopy(base)
        data["pushers"] = left + EXTRA_PUSHERS[: n - 1]
        print(row(f"{n} pusher{'s' if n > 1 else ''}", data, args.trials, args.time_limit), flush=True)

    print("\n### Pad discretization\n\n" + header)
    for name in ("horizontal-offset-low-mu", "large-manipulation"):
        for rings in (1, 2, 3):
            data = load(name)
            data["gripper"]["pad_rings"] = rings
            print(row(f"{name}, pad_rings {rings}", data, args.trials, args.time_limit), flush=True)

    print("\n### Distance to the goal\n\n" + header)
    for x in (5, 10, 20, 30, 40):
        data = load("horizontal-offset-high-mu")
        data["goal"] = [x, 0, 0]
        print(row(f"high-mu offset, goal x = {x} mm", data, args.trials, args.time_limit), flush=True)
    for f in (0.25, 0.5, 0.75, 1.0):
        data = load("large-manipulation")
        data["goal"] = [round(f * v, 3) for v in (15, -13, 45)]
        print(row(f"large manipulation, {f:.0%} of the goal", data, args.trials, args.time_limit), flush=True)


if __name__ == "__main__":
    main()
