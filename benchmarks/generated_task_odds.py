"""Success rates on tasks nothing was tuned for: a generator of line-pusher tasks (boxes and convex
polygons of other sizes and masses, two or three flat features along their edges at other places
and friction, with and without gravity in the grasp plane), each planned robustly to a goal its
features reach, and run N times in the worlds of docs/evaluate.md's tables (pad and pusher mu +-15%,
grip +-10%, mass +-5%, features off by up to 0.5 mm / 0.5 deg), judged within 0.5 mm / 0.5 deg.

    python3 benchmarks/generated_task_odds.py [--tasks 10] [--trials 50] [--seed 1] [--loop closed]
                                              [--only NAME ...] [--finish-steps] [--workers 2 | --ray [ADDRESS]]
                                              [--json OUT.json]

Task i depends only on (--seed, i). Its goal is a random pose within GOAL_SPAN of the start that
the task's robust plan (seed 1, `uncertainty:` the spreads' box, as `evaluate --robust`) reaches in
PLAN_LIMIT s, planned to the tolerance the trials are judged by; a task none of whose tries gives
one is left out and listed. One row per task and loop; the line under the table sums the trials
over all tasks (the closed-loop target: >= 99%). The column "ends at" is the plan's end's largest
offset from the goal, each coordinate over the tolerance (1: at its edge). With --finish-steps the
plans are made with `planner.finish_steps: 1` (the same goals and pushes, then the last pusher's
steps deeper into the tolerance).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path

import numpy as np
import yaml
from evaluate_tasks import SPREADS, add_runner_options, progress_line, runner_of
from point_pusher_tasks import random_task

from stablepush.errors import TaskError
from stablepush.evaluation import Batch, evaluate, robust_task, wilson_interval
from stablepush.plan import check_plan, plan_task
from stablepush.pose import Tolerance
from stablepush.task import parse_task

GOAL_SPAN = (20.0, 15.0, 20.0)  # mm, mm, deg either side of the start
MIN_GOAL_MM = 5.0  # a goal at least this far from the start in x and z together
PLAN_LIMIT = 5.0  # s a goal's robust plan may take
FEATURE_SHARE = (0.4, 1.0)  # of its edge's length, a feature's length
TOLERANCE = (0.5, 0.5)  # mm, deg: the plans end within what a trial is judged by (a user who wants 0.5 mm asks for it)


def _features(rng: np.random.Generator, polygon: list, count: int) -> list:
    """`count` flat features on distinct edges, each FEATURE_SHARE of its edge's length, placed at
    random along it."""
    edges = rng.choice(len(polygon), size=count, replace=False)
    features = []
    for k, e in enumerate(sorted(int(i) for i in edges)):
        a, b = np.array(polygon[e]), np.array(polygon[(e + 1) % len(polygon)])
        share = rng.uniform(*FEATURE_SHARE)
        begin = rng.uniform(0.0, 1.0 - share)
        ends = [a + t * (b - a) for t in (begin, begin + share)]
        features.append({"name": f"edge-{k}", "from": [round(float(v), 3) for v in ends[0]],
                         "to": [round(float(v), 3) for v in ends[1]], "mu": round(float(rng.uniform(0.3, 0.8)), 2)})
    return features


def generate_task(seed: int, index: int) -> dict:
    """Task `index` of the set `seed`, as a task file's mapping (its goal: `goal_for`)."""
    return random_task(np.random.default_rng([seed, index]), f"edges-{seed}-{index}",
                       lambda rng, polygon: _features(rng, polygon, int(rng.integers(2, 4))),
                       {"time_limit": PLAN_LIMIT, "seed": 1, "max_switches": 2, "tolerance": list(TOLERANCE)})


def goal_for(data: dict, seed: int, index: int, tries: int = 8):
    """(goal, the robust task, its plan) for the first random goal within GOAL_SPAN that the robust
    plan reaches; None when no try gives one."""
    rng = np.random.default_rng([seed, index, 1])
    for _ in range(tries):
        goal = [round(float(v), 2) for v in rng.uniform(-1.0, 1.0, 3) * GOAL_SPAN]
        if math.hypot(goal[0], goal[1]) < MIN_GOAL_MM:
            continue
        try:
            task = robust_task(parse_task(yaml.safe_dump({**data, "goal": goal}), source=data["name"]), SPREADS)
        except TaskError:  # no grasp at the goal (a pad off the object)
            continue
        plan = plan_task(task, seed=1)
        if plan.solved:
            return goal, task, check_plan(task, plan)
    return None


def ends_at(task, plan) -> float:
    """The plan's end's largest offset from the goal, each coordinate over TOLERANCE (1: its edge)."""
    end = plan.waypoints[-1]
    return Tolerance.of(TOLERANCE).used(end.pose, task.goal)


def _row(task, data: dict, loop: str, plan, s: dict) -> str:
    shape = "box" if len(data["object"]["polygon"]) == 4 else f"{len(data['object']['polygon'])}-gon"
    misses = ", ".join(f"{k} {v}" for k, v in sorted(s["causes"].items())) or "-"
    mm = (s["goal_error_mm"] or {}).get("p95", float("nan"))
    return (f"| {task.name} | {shape} | {len(task.pushers)} | {'yes' if any(task.gravity) else 'no'} | {data['goal']} "
            f"| {len(plan.waypoints) - 1} | {ends_at(task, plan):.2f} | {loop} | {s['successes']}/{s['trials']} "
            f"| {s['success_rate']:.1%} ({s['ci95'][0]:.1%}-{s['ci95'][1]:.1%}) | {mm:.2f} | {misses} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tasks", type=int, default=10)
    parser.add_argument("--trials", type=int, default=50, help="per task and loop")
    parser.add_argument("--seed", type=int, default=1, help="the task set's seed (the worlds use seed 1)")
    parser.add_argument("--loop", nargs="+", choices=("open", "closed"), default=["closed"])
    parser.add_argument("--only", nargs="+", metavar="NAME", default=None,
                        help="run only these tasks of the set (e.g. edges-2-4), the others generated and skipped")
    parser.add_argument("--finish-steps", action="store_true",
                        help="plan with planner.finish_steps: 1 (the last pusher goes on deeper into the tolerance)")
    add_runner_options(parser)
    parser.add_argument("--json", type=Path, default=None, help="every row's summary and task, with its missed trials")
    args = parser.parse_args()
    names = {generate_task(args.seed, i)["name"] for i in range(args.tasks)}
    if args.only is not None and not set(args.only) <= names:
        parser.error(f"--only: no task {', '.join(sorted(set(args.only) - names))} in set {args.seed} "
                     f"(its tasks: {', '.join(sorted(names))})")
    runner = runner_of(args)
    print(f"{args.trials} trials per task and loop, task set {args.seed}, on {runner.describe()}", file=sys.stderr)
    print("| task | shape | features | gravity | goal | pushes | ends at | loop | landed | success rate (95% CI) "
          "| goal error p95 mm | misses |")
    print("|---|---|---:|---|---|---:|---:|---|---:|---|---:|---|")
    rows, left_out, totals = [], [], {}
    for index in range(args.tasks):
        data = generate_task(args.seed, index)
        if args.only is not None and data["name"] not in args.only:
            continue
        found = goal_for(data, args.seed, index)
        if found is None:
            left_out.append(data["name"])
            continue
        data["goal"], task, plan = found
        if args.finish_steps:
            task = dataclasses.replace(task, planner=task.planner.replace(finish_steps=1))
            data["planner"] = {**data["planner"], "finish_steps": 1}
            plan = check_plan(task, plan_task(task, seed=1))
            if not plan.solved:  # the same search as goal_for's, under its time limit on a busy machine
                raise SystemExit(f"{task.name}: with finish_steps, no plan in {PLAN_LIMIT:g} s: {plan.message}")
        for loop in args.loop:
            batch = Batch(task=task, plan=plan, spreads=SPREADS, seed=1, closed_loop=loop == "closed")
            evaluation = evaluate(batch, args.trials, runner, progress=progress_line(task.name, loop, args.trials))
            s = evaluation.summary()
            print(_row(task, data, loop, plan, s), flush=True)
            landed, trials = totals.get(loop, (0, 0))
            totals[loop] = (landed + s["successes"], trials + s["trials"])
            rows.append({**s, "task_file": {**data, "uncertainty": task.uncertainty}, "loop": loop,
                         "missed": [t for t in evaluation.trials if not t["success"]]})
    print()
    for loop, (landed, trials) in totals.items():
        low, high = wilson_interval(landed, trials)
        print(f"{loop} loop, all tasks: {landed}/{trials} landed ({landed / trials:.1%}, {low:.1%}-{high:.1%})")
    if left_out:
        print(f"left out (no robust plan to any of its goals in {PLAN_LIMIT:g} s): {', '.join(left_out)}")
    if args.json:
        args.json.write_text(json.dumps({"rows": rows, "left_out": left_out, "args": {**vars(args), "json": str(args.json)}},
                                        indent=1) + "\n")


if __name__ == "__main__":
    main()
