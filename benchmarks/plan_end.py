"""Where plans end: the share of the goal's tolerance each plan's end uses (the largest of |dx|, |dz|
over the length tolerance and |dtheta| over the angle's; 0: at the goal pose, 1: at the tolerance's
edge), with the deeper search (planner.end_within, docs/planner.md) and without it (end_within: 1),
on the shipped tasks and on generated ones nothing was tuned for: line-pusher tasks
(generated_task_odds.py's, robust, tolerance 0.5 mm / 0.5 deg) and point-pusher tasks
(point_pusher_tasks.py's).

    python3 benchmarks/plan_end.py [--seeds 3] [--generated 10] [--set 1] [--out results/plan_end.md]

For each task and seed: whether it was solved, the end's share without and with the deeper search,
the plan's pushes and its stable-push tests both ways. The summary counts the plans whose end lies
within end_within (0.5) of the tolerance, and those whose deeper search found none (the first plan
stands, its stats say how deep it got).
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np
from generated_task_odds import generate_task as edge_task
from generated_task_odds import goal_for as edge_goal
from point_pusher_tasks import generated_tasks as pin_tasks
from shipped import shipped_tasks

from stablepush.plan import plan_task
from stablepush.task import load_task

HERE = Path(__file__).resolve().parent


def _tasks(args):
    for path in shipped_tasks():
        yield "shipped", load_task(path)
    for i in range(args.generated):
        data = edge_task(args.set, i)
        found = edge_goal(data, args.set, i)
        if found is not None:
            yield "edges", found[1]
    for task, _ in pin_tasks(args.set, args.generated):
        yield "pins", task


def _row(kind: str, task, seed: int) -> dict:
    out = {"kind": kind, "task": task.name, "seed": seed}
    for label, share in (("edge", 1.0), ("deeper", task.planner.end_within)):
        t = dataclasses.replace(task, planner=task.planner.replace(end_within=share))
        began = time.perf_counter()
        plan = plan_task(t, seed=seed)
        out[label] = {"solved": plan.solved, "ms": (time.perf_counter() - began) * 1e3,
                      "used": task.tolerance.used(plan.waypoints[-1].pose, task.goal)
                      if plan.solved else None,
                      "pushes": plan.stats["pushes"], "checks": plan.stats["feasibility_checks"],
                      "deeper_found": (plan.stats.get("deeper") or {}).get("solved")}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--generated", type=int, default=10, help="tasks of each generated kind")
    parser.add_argument("--set", type=int, default=1, help="the generated tasks' set (seed)")
    parser.add_argument("--out", type=Path, default=HERE / "results" / "plan_end.md")
    args = parser.parse_args()
    rows = []
    lines = ["| kind | task | seed | end used, to the edge | end used, deeper | pushes | tests | deeper search |",
             "|---|---|---:|---:|---:|---:|---:|---|"]
    for kind, task in _tasks(args):
        for seed in range(1, args.seeds + 1):
            r = _row(kind, task, seed)
            rows.append(r)
            e, d = r["edge"], r["deeper"]
            fmt = lambda v: "-" if v is None else f"{v:.2f}"  # noqa: E731
            found = {None: "not needed", True: "found", False: "none: first plan kept"}[d["deeper_found"]]
            line = (f"| {kind} | {task.name} | {seed} | {fmt(e['used'])} | {fmt(d['used'])} | "
                    f"{e['pushes']} -> {d['pushes']} | {e['checks']:,} -> {d['checks']:,} | {found} |")
            lines.append(line)
            print(line, file=sys.stderr, flush=True)
    solved = [r for r in rows if r["deeper"]["solved"]]
    within = [r for r in solved if r["deeper"]["used"] <= 0.5 + 1e-9]
    before = [r for r in rows if r["edge"]["solved"] and r["edge"]["used"] <= 0.5 + 1e-9]
    ms = lambda k: np.median([r[k]["ms"] for r in solved])  # noqa: E731
    summary = [
        f"Plans solved: {len(solved)} of {len(rows)} (task and seed). Ending within half the tolerance: "
        f"{len(within)} of {len(solved)} with the deeper search, {len(before)} without it. Deeper search found "
        f"none: {sum(r['deeper']['deeper_found'] is False for r in rows)}. Median planning time "
        f"{ms('edge'):.1f} ms to the edge, {ms('deeper'):.1f} ms deeper.",
        "", "Plans whose end lies beyond half the tolerance with the deeper search:",
        *[f"- {r['task']} seed {r['seed']}: {r['deeper']['used']:.2f}" for r in solved if r not in within]]
    text = ("# Where plans end (benchmarks/plan_end.py)\n\n"
            f"`python3 benchmarks/plan_end.py --seeds {args.seeds} --generated {args.generated} --set {args.set}`\n\n"
            + "\n".join(summary) + "\n\n" + "\n".join(lines) + "\n")
    args.out.write_text(text)
    print("\n".join(summary))


if __name__ == "__main__":
    main()
