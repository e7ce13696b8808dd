"""How fast `stablepush evaluate` decides (docs/evaluate.md, "Speed"): trials per core-minute of a
study's trials, with settings A and B side by side in one run, in turn, on the same worlds.

Each task's seed-1 plan (robust to the table's spreads unless `--plans nominal`) runs trials 0..N-1
of the worlds of docs/evaluate.md's tables (evaluate_tasks.SPREADS), closed loop unless `--loop
open`, judged at 0.5 mm / 0.5 deg, on MuJoCo, in this process (one core). Trial k runs under each
setting in turn (the order alternates with k, so that a machine's drift falls on both), each
timed whole: world built, home found, run, judged. The settings are simulator time steps
(`--timestep-ms A B`; the contract's step is kinematics.cell_model.TIMESTEP). Per task and setting:

- trials per core-minute (60 s / the mean wall time of a trial) and x real time;
- the time a `--target 0.99` decision takes at best on 2 workers: it needs 296 landings in a row
  (docs/evaluate.md, "A decision"), so 296 trials / (2 x trials per core-minute);
- whether the outcomes agree: trials that land under one setting and not the other, and the
  largest difference of the goal error between them.

    python3 benchmarks/evaluate_speed.py [TASK.yaml ...] [--trials 8] [--timestep-ms 0.25 0.5]
                                         [--plans robust|nominal] [--loop closed|open] [--json OUT.json]

Wall seconds vary with the machine's load: the A/B ratio in one run is the figure to trust.
"""
import argparse
import json
import sys
import time
from pathlib import Path

from evaluate_tasks import SPREADS
from shipped import TASKS

from stablepush.evaluation import Batch, robust_task
from stablepush.evaluation.batch import run_trial
from stablepush.kinematics import cell_model
from stablepush.plan import check_plan, plan_task
from stablepush.task import load_task

DECISION_TRIALS = 296  # the fewest trials in which --target 0.99 --confidence 0.95 can say `above`
WORKERS = 2


def timed_trials(batch: Batch, trials: int, steps_s) -> dict:
    """step -> the records of trials 0..trials-1 run with that time step, each with its `wall_s`."""
    out = {step: [] for step in steps_s}
    for k in range(trials):
        for step in (steps_s if k % 2 == 0 else tuple(reversed(steps_s))):
            cell_model.TIMESTEP = step
            started = time.perf_counter()
            record = run_trial(batch, k)
            out[step].append({**record, "wall_s": time.perf_counter() - started})
            print(f"\r{batch.task.name}: trial {k + 1}/{trials}", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    return out


def figures(records: list) -> dict:
    wall = sum(r["wall_s"] for r in records) / len(records)
    robot = sum(r.get("sim_time_s") or 0.0 for r in records) / len(records)
    per_minute = 60.0 / wall
    return {"trials": len(records), "landed": sum(1 for r in records if r["success"]), "wall_s_per_trial": wall,
            "trials_per_core_minute": per_minute, "real_time_factor": robot / wall,
            "decision_minutes_2_workers": DECISION_TRIALS / (WORKERS * per_minute)}


def agreement(a: list, b: list) -> dict:
    """How the outcomes of the same worlds compare between two settings."""
    differ = [ra["trial"] for ra, rb in zip(a, b) if ra["success"] != rb["success"]]
    gaps = [abs(ra["goal_error"][key] - rb["goal_error"][key]) for ra, rb in zip(a, b)
            if ra.get("goal_error") and rb.get("goal_error") for key in ("distance",)]
    turns = [abs(ra["goal_error"]["theta"] - rb["goal_error"]["theta"]) for ra, rb in zip(a, b)
             if ra.get("goal_error") and rb.get("goal_error")]
    return {"outcomes_differ": differ, "max_goal_error_gap_mm": max(gaps, default=None),
            "max_goal_error_gap_deg": max(turns, default=None)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path, help="task files (default: the pivot and the T)")
    parser.add_argument("--trials", type=int, default=8)
    parser.add_argument("--timestep-ms", nargs=2, type=float, default=(cell_model.TIMESTEP * 1e3, 0.5),
                        metavar=("A", "B"), help="the two time steps compared, ms (default: the contract's, 0.5)")
    parser.add_argument("--plans", choices=("robust", "nominal"), default="robust")
    parser.add_argument("--loop", choices=("open", "closed"), default="closed")
    parser.add_argument("--json", type=Path, default=None, help="every figure, and each trial's record, as JSON")
    args = parser.parse_args()
    steps = tuple(ms / 1e3 for ms in args.timestep_ms)
    tasks = args.tasks or [TASKS / "pivoting.yaml", TASKS / "t-shaped.yaml"]
    print(f"{args.trials} trials per task and step, {args.plans} plans, {args.loop} loop, MuJoCo, one core",
          file=sys.stderr)
    print("| task | step ms | landed | s per trial | trials per core-minute | x real time "
          "| --target 0.99 at best, 2 workers |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    results = []
    for path in tasks:
        task = load_task(path)
        task = robust_task(task, SPREADS) if args.plans == "robust" else task
        batch = Batch(task=task, plan=check_plan(task, plan_task(task, seed=1)), spreads=SPREADS, seed=1,
                      closed_loop=args.loop == "closed", tolerance=(0.5, 0.5))
        runs = timed_trials(batch, args.trials, steps)
        row = {"task": task.name, "settings": {}, "agreement": agreement(runs[steps[0]], runs[steps[1]])}
        for step in steps:
            f = figures(runs[step])
            row["settings"][f"{step * 1e3:g} ms"] = {**f, "records": runs[step]}
            print(f"| {task.name} | {step * 1e3:g} | {f['landed']}/{f['trials']} | {f['wall_s_per_trial']:.2f} "
                  f"| {f['trials_per_core_minute']:.1f} | {f['real_time_factor']:.2f} "
                  f"| {f['decision_minutes_2_workers']:.1f} min |", flush=True)
        a = row["agreement"]
        print(f"| {task.name}: same worlds | | outcomes differ in trials {a['outcomes_differ'] or 'none'} | "
              f"goal error gap at most {a['max_goal_error_gap_mm'] or 0:.3f} mm, "
              f"{a['max_goal_error_gap_deg'] or 0:.3f} deg | | | |", flush=True)
        results.append(row)
    cell_model.TIMESTEP = steps[0]
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, default=str) + "\n")


if __name__ == "__main__":
    main()
