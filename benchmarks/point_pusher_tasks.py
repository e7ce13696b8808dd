"""Point pushers on parts nothing was tuned for: a generator of tasks (boxes and convex polygons of
other sizes and masses, two or three pins at other places and friction, with and without gravity
in the grasp plane), goals the pins can reach, and the planning time over seeds.

    python3 benchmarks/point_pusher_tasks.py [--tasks 10] [--seeds 30] [--seed 1] [--time-limit 5]
                                             [--goals random|paths] [--goals-from RUN.json]
                                             [--planner KEY=VALUE ...] [--shift MM] [--json OUT.json]

Task i depends only on (--seed, i). Its goal (`goal_for`) is reachable: a random pose near the
start that a long search with other seeds reaches (as a user picks a goal), or the end of a
partial path toward a random target (spread over the part of the grasp the pins reach, as
`stablepush reach` finds it, without a grid). Each task is then planned from its start to that goal
with every seed 1..--seeds; the table gives the solved count and the planning time's median and
95th percentile per task, and the line under it the same over all runs (issue 21's target:
median <= 100 ms, p95 <= 500 ms).

With --shift MM each goal is also planned moved by +-MM in x and in z (the same seeds, so a run
takes about five times as long; the line under the table is the goals' own runs): where a move of
a tenth of the tolerance or so turns a goal's runs from solved to unsolved, or the other way, the
goal may lie near the edge of the poses the pins reach within the switch-over budget, and its
slow runs come from where it lies rather than from the rest of the search.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Optional

import numpy as np
import yaml

from stablepush import _core
from stablepush.errors import TaskError
from stablepush.plan import plan_task
from stablepush.task import parse_task
from stablepush.units import MM, pose_to_si

# The far targets the goals are drawn toward, and how far (unit steps) a goal must be from the start.
TARGET_SPAN = (12.0, 12.0, 25.0)  # mm, mm, deg
MIN_GOAL_STEPS = 3.0
VERIFY_SEED = 10_000  # seeds that find goals, never used to time them
VERIFY_LIMIT = 3.0  # s a random goal's search may take to show it is reachable


def _convex_polygon(rng: np.random.Generator) -> list:
    """5 to 7 vertices on an ellipse of semi-axes 15-40 mm, counterclockwise (convex)."""
    n = int(rng.integers(5, 8))
    # Keep the vertices apart, so that no edge is too short to hold a pin away from its ends.
    angles = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False) + rng.uniform(-0.25, 0.25, n) * (2 * math.pi / n)
    a, b = rng.uniform(15.0, 40.0, 2)
    return [[round(float(a * math.cos(t)), 2), round(float(b * math.sin(t)), 2)] for t in angles]


def outline(rng: np.random.Generator) -> list:
    """A box of 25-80 x 20-60 mm or, as often, a convex polygon (`_convex_polygon`), in mm."""
    if rng.uniform() < 0.5:
        w, h = rng.uniform(25.0, 80.0), rng.uniform(20.0, 60.0)
        polygon = [[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]]
        return [[round(float(x), 2), round(float(z), 2)] for x, z in polygon]
    return _convex_polygon(rng)


def _pins(rng: np.random.Generator, polygon: list, count: int) -> list:
    """`count` pins on distinct edges, each between 20% and 80% along its edge."""
    edges = rng.choice(len(polygon), size=count, replace=False)
    pins = []
    for k, e in enumerate(sorted(int(i) for i in edges)):
        a, b = np.array(polygon[e]), np.array(polygon[(e + 1) % len(polygon)])
        at = a + rng.uniform(0.2, 0.8) * (b - a)
        pins.append({"name": f"pin-{k}", "at": [round(float(at[0]), 3), round(float(at[1]), 3)],
                     "mu": round(float(rng.uniform(0.3, 0.8)), 2)})
    return pins


def random_task(rng: np.random.Generator, name: str, place_pushers, planner: dict) -> dict:
    """A task file's mapping with a random outline (`outline`), mass, thickness, grip, pad mu and
    gravity (in the grasp plane for 70% of the tasks), its pushers from `place_pushers(rng,
    polygon)`, start and goal at the origin (the goal: `goal_for`)."""
    polygon = outline(rng)
    gravity = [0.0, -9.81] if rng.uniform() < 0.7 else [0.0, 0.0]
    return {
        "name": name,
        "object": {"shape": "polygon", "polygon": polygon, "thickness": round(float(rng.uniform(10.0, 40.0)), 1),
                   "mass": round(float(rng.uniform(30.0, 300.0)), 1)},
        "gripper": {"grip_force": round(float(rng.uniform(5.0, 20.0)), 1),
                    "mu": round(float(rng.uniform(0.3, 0.7)), 2), "pad_rings": 1},
        "gravity": gravity,
        "pushers": place_pushers(rng, polygon),
        "start": [0.0, 0.0, 0.0],
        "goal": [0.0, 0.0, 0.0],
        "planner": planner,
    }


SMALLEST_SHIFT = 1e-4  # mm: goals are rounded to 4 decimals


def shifted_goals(goal: list, shift_mm: float) -> list:
    """The goal moved by +-shift_mm (at least SMALLEST_SHIFT) in x and in z, as (label, goal)."""
    x, z, theta = goal
    return [(f"{label}{shift_mm:g}", [round(x + dx, 4), round(z + dz, 4), theta])
            for label, dx, dz in (("x+", shift_mm, 0.0), ("x-", -shift_mm, 0.0),
                                  ("z+", 0.0, shift_mm), ("z-", 0.0, -shift_mm))]


def generate_task(seed: int, index: int, planner: Optional[dict] = None) -> dict:
    """Task `index` of the set `seed`, as a task file's mapping (no goal yet: `goal_for`), its
    planner section updated with `planner`."""
    return random_task(np.random.default_rng([seed, index]), f"pins-{seed}-{index}",
                       lambda rng, polygon: _pins(rng, polygon, int(rng.integers(2, 4))),
                       {"time_limit": 5.0, "seed": 1, "max_switches": 2, **(planner or {})})


def goal_for(data: dict, seed: int, index: int, kind: str = "random", tries: int = 8) -> Optional[list]:
    """A reachable goal for the task, None when no try gives one. `kind`:
    - "random": a random pose within TARGET_SPAN of the start (as a user picks one) that a search of
      VERIFY_LIMIT s with seed VERIFY_SEED or VERIFY_SEED + 1 reaches (seeds the timing never uses);
    - "paths": the end of the best partial path toward a random far target (0.5 s, seed VERIFY_SEED),
      a pose some sequence of stable pushes reaches, spread over the part of the grasp the pins reach.
    Either is at least MIN_GOAL_STEPS unit steps from the start."""
    rng = np.random.default_rng([seed, index, 1])
    for _ in range(tries):
        target = [round(float(v), 3) for v in rng.uniform(-1.0, 1.0, 3) * TARGET_SPAN]
        try:
            task = parse_task(yaml.safe_dump({**data, "goal": target}), source=data["name"])
        except TaskError:  # no grasp at the target (a pad off the object)
            continue
        unit = (task.planner.step[0] * MM, math.radians(task.planner.step[1]))
        far = lambda pose: _core.steps_between(pose_to_si(task.start), pose_to_si(pose), unit) >= MIN_GOAL_STEPS  # noqa: E731
        if kind == "paths":
            end = plan_task(task, seed=VERIFY_SEED, time_limit=0.5).waypoints[-1].pose
            if far(end):
                return [round(v, 4) for v in end]
        elif far(target) and any(plan_task(task, seed=s, time_limit=VERIFY_LIMIT).solved
                                 for s in (VERIFY_SEED, VERIFY_SEED + 1)):
            return target
    return None


def generated_tasks(seed: int, count: int, kind: str = "random", goals: Optional[dict] = None,
                    planner: Optional[dict] = None):
    """(task, its mapping) for tasks 0..count-1 of the set `seed` that have a reachable goal; with
    `goals` (task name -> goal), those goals instead of goal_for's; `planner` as generate_task's."""
    for index in range(count):
        data = generate_task(seed, index, planner)
        goal = goal_for(data, seed, index, kind) if goals is None else goals.get(data["name"])
        if goal is None:
            continue
        data = {**data, "goal": goal}
        yield parse_task(yaml.safe_dump(data), source=data["name"]), data


def _runs(task, args: argparse.Namespace, runs: list, **tags) -> list:
    """Plan `task` with every seed 1..--seeds, a record of each run (with `tags`) appended to
    `runs`; the new records."""
    new = []
    for s in range(1, args.seeds + 1):
        plan = plan_task(task, seed=s, time_limit=args.time_limit)
        new.append({"task": task.name, **tags, "seed": s, "solved": plan.solved,
                    "ms": plan.stats["planning_time_s"] * 1e3, "ends_at_goal": plan.ends_at_goal,
                    "checks": plan.stats["feasibility_checks"], "restarts": plan.stats["restarts"],
                    "pushes": plan.stats["pushes"], "switches": plan.stats["switches"]})
    runs += new
    return new


def _shifted_runs(data: dict, label: str, goal: list, args: argparse.Namespace, runs: list) -> str:
    """The task planned to `goal` (a shifted goal) with every seed, each run appended to `runs`;
    the table's entry."""
    try:
        task = parse_task(yaml.safe_dump({**data, "goal": goal}), source=data["name"])
    except TaskError:  # no grasp there
        return f"{label}: no grasp"
    new = _runs(task, args, runs, shifted=label, goal=goal)
    return f"{label}: {sum(r['solved'] for r in new)}/{args.seeds} {np.median([r['ms'] for r in new]):.1f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tasks", type=int, default=10)
    parser.add_argument("--seeds", type=int, default=30)
    parser.add_argument("--seed", type=int, default=1, help="the task set's seed")
    parser.add_argument("--time-limit", type=float, default=5.0, help="s per plan")
    parser.add_argument("--goals", choices=("random", "paths"), default="random",
                        help="random poses a long search reaches, or ends of partial paths (goal_for)")
    parser.add_argument("--goals-from", default=None, metavar="JSON",
                        help="the goals of an earlier run's --json: a random goal is one a time-limited search "
                             "reached, so it depends on the planner and the machine; two planners compared "
                             "on the same goals")
    parser.add_argument("--planner", nargs="+", default=[], metavar="KEY=VALUE",
                        help="planner settings of every task (YAML values), e.g. restart_checks=2000; the goals "
                             "are found with them too, so compare planners with --goals-from")
    parser.add_argument("--shift", type=float, default=None, metavar="MM",
                        help="also plan each goal moved by +-MM in x and in z (a run about five times as long): "
                             "a goal where a small move (say 0.1 mm) flips solved and unsolved may lie near "
                             "the edge of what the pins reach")
    parser.add_argument("--json", default=None,
                        help="write every run, the shifted goals' under shifted_runs, and each task's goal here")
    args = parser.parse_args()
    planner = {}
    for item in args.planner:
        key, sep, value = item.partition("=")
        if not sep or not key:
            parser.error(f"--planner {item}: expected KEY=VALUE")
        planner[key] = yaml.safe_load(value)
    given = None
    if args.goals_from:
        given = json.loads(Path(args.goals_from).read_text()).get("goals")
        names = {generate_task(args.seed, i)["name"] for i in range(args.tasks)}
        if not given or not names & set(given):
            parser.error(f"--goals-from {args.goals_from}: no goal of a task of set {args.seed} (its 'goals' "
                         f"must name some of {', '.join(sorted(names))}); --goals is not used with it")
    if args.shift is not None and not (math.isfinite(args.shift) and args.shift >= SMALLEST_SHIFT):
        parser.error(f"--shift {args.shift}: expected a finite distance of at least {SMALLEST_SHIFT} (mm)")
    shifted_columns = "" if args.shift is None else f" solved, median ms at the goal moved ±{args.shift:g} mm |"
    print("| task | shape | pins | gravity | goal | solved | median ms | p95 ms |" + shifted_columns)
    print("|---|---|---:|---|---|---:|---:|---:|" + ("---|" if args.shift is not None else ""))
    runs, shifted_runs, everything, goals = [], [], [], {}
    for task, data in generated_tasks(args.seed, args.tasks, args.goals, given, planner):
        goals[task.name] = data["goal"]
        new = _runs(task, args, runs)
        times = [r["ms"] for r in new]
        solved = sum(r["solved"] for r in new)
        everything += times
        shifted = ""
        if args.shift is not None:
            entries = [_shifted_runs(data, label, goal, args, shifted_runs)
                       for label, goal in shifted_goals(data["goal"], args.shift)]
            shifted = " " + " · ".join(entries) + " |"
        shape = "box" if len(data["object"]["polygon"]) == 4 else f"{len(data['object']['polygon'])}-gon"
        print(f"| {task.name} | {shape} | {len(task.pushers)} | {'yes' if any(task.gravity) else 'no'} "
              f"| {data['goal']} | {solved}/{args.seeds} | {np.median(times):.1f} | {np.percentile(times, 95):.1f} |"
              + shifted, flush=True)
    t = np.array(everything)
    solved = sum(r["solved"] for r in runs)
    print(f"\nall {len(runs)} runs: solved {solved}, median {np.median(t):.1f} ms, p95 {np.percentile(t, 95):.1f} ms, "
          f"max {t.max():.1f} ms (target: median <= 100 ms, p95 <= 500 ms); "
          f"{sum(r['checks'] for r in runs) / 1e6:.1f} M stable-push tests, {t.sum() / 1e3:.1f} s in all")
    if shifted_runs:
        print(f"the shifted goals: {len(shifted_runs)} runs, solved {sum(r['solved'] for r in shifted_runs)}, "
              f"{sum(r['ms'] for r in shifted_runs) / 1e3:.1f} s in all")
    if args.json:
        record = {"runs": runs, "shifted_runs": shifted_runs, "goals": goals, "args": vars(args)}
        Path(args.json).write_text(json.dumps(record, indent=1) + "\n")
    sys.exit(0)


if __name__ == "__main__":
    main()
