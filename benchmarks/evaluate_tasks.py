"""Success rates at scale (docs/evaluate.md): every task (default: the shipped ones and
data/tasks/more), its seed-1 plan, N trials in worlds with the issue's spreads (pad and pusher mu
+-15%, grip force +-10%, mass +-5%, features off by up to 0.5 mm / 0.5 deg), open and closed loop,
judged as `stablepush evaluate` judges a trial: where the object comes to rest after the release,
within the task's planner.tolerance of the goal, or `--tolerance MM DEG` (docs/results/evaluate-1000-trials.md's
tables of 1,000 trials were measured with `--tolerance 0.5 0.5`). One table row per task, plan,
loop and approach. The
plan is the task's own (`nominal`) or robust to those spreads (`robust`: `stablepush evaluate
--robust`); a task with no robust plan gets a row that says why. The approaches find each feature
by touch (`guarded`, the default) or end where the plan puts it (`plain`: `evaluate --no-guard`).

    python3 benchmarks/evaluate_tasks.py [TASK.yaml ...] [--trials 100] [--seed 1] [--workers 2 | --ray [ADDRESS]]
                                         [--plans nominal robust] [--loop open closed]
                                         [--approach guarded plain] [--engine mujoco]
                                         [--tolerance MM DEG] [--target RATE [--confidence C]] [--json OUT.json]

`--json` keeps each row's missed trials, to look into why they missed.
"""
import argparse
import json
import sys
from pathlib import Path
from typing import Optional

from shipped import shipped_tasks

from stablepush.evaluation import Batch, SequentialTest, Spreads, evaluate, robust_task
from stablepush.plan import check_plan, plan_task
from stablepush.runners import Runner, default_workers
from stablepush.sim.engines import ENGINES
from stablepush.task import load_task

SPREADS = Spreads(vary={"pad_mu": 0.15, "pusher_mu": 0.15, "grip_force": 0.1, "mass": 0.05}, feature_error=(0.5, 0.5))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path)
    parser.add_argument("--trials", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1)
    add_runner_options(parser)
    parser.add_argument("--plans", nargs="+", choices=("nominal", "robust"), default=["nominal"])
    parser.add_argument("--loop", nargs="+", choices=("open", "closed"), default=["open", "closed"])
    parser.add_argument("--approach", nargs="+", choices=("guarded", "plain"), default=["guarded"])
    parser.add_argument("--engine", choices=ENGINES, default="mujoco")
    parser.add_argument("--tolerance", nargs=2, type=float, default=None, metavar=("MM", "DEG"),
                        help="judge the trials by this tolerance (default: each task's planner.tolerance)")
    parser.add_argument("--target", type=float, default=None, metavar="RATE",
                        help="decide whether each row lands at least RATE of the time and stop it when decided "
                             "(evaluate --target); --trials is then the cap")
    parser.add_argument("--confidence", type=float, default=0.95, help="with --target (default 0.95)")
    parser.add_argument("--predict", type=int, default=None, metavar="N",
                        help="N model-only worlds joined to the trials; with --target the decision uses them "
                             "(evaluate --predict)")
    parser.add_argument("--json", type=Path, default=None,
                        help="every row's summary, with its missed trials' records under `missed` (trial, world, "
                             "verdict, replans: enough to run one again), as JSON")
    args = parser.parse_args()
    runner = runner_of(args)
    print(f"{args.trials} trials per row, seed {args.seed}, {args.engine}, on {runner.describe()}", file=sys.stderr)
    paths = args.tasks or shipped_tasks()
    print("| task | plan | loop | approach | tolerance | landed | success rate (95% CI) | goal error p50 / p95 mm "
          "| p50 / p95 deg | misses | wall s | x real time |")
    print("|---|---|---|---|---|---:|---|---|---|---|---:|---:|")
    summaries = []
    for path in paths:
        nominal = load_task(path)
        for kind in args.plans:
            task = robust_task(nominal, SPREADS) if kind == "robust" else nominal
            plan = plan_task(task, seed=1)
            if not plan.solved:
                print(f"| {task.name} | {kind} | - | no plan: {plan.message} |", flush=True)
                summaries.append({"task": task.name, "plan": kind, "no_plan": plan.message})
                continue
            plan = check_plan(task, plan)
            for loop, approach in ((loop, approach) for loop in args.loop for approach in args.approach):
                batch = Batch(task=task, plan=plan, spreads=SPREADS, seed=args.seed, closed_loop=loop == "closed",
                              guarded=approach == "guarded", engine=args.engine, tolerance=args.tolerance)
                progress = progress_line(f"{task.name} {kind}", f"{loop} {approach}", args.trials)
                test = SequentialTest(args.target, args.confidence) if args.target is not None else None
                evaluation = evaluate(batch, args.trials, runner, progress=progress, test=test,
                                      predictions=args.predict)
                s = evaluation.summary()
                missed = [t for t in evaluation.trials if not t["success"]]
                summaries.append({**s, "plan": kind, "approach": approach, "missed": missed})
                mm, deg = s["goal_error_mm"] or {}, s["goal_error_deg"] or {}
                misses = ", ".join(f"{k} {v}" for k, v in sorted(s["causes"].items())) or "-"
                if s["decision"] is not None:
                    misses += (f"; decision {s['decision']['decision']} after {s['decision']['trials']} trials "
                               f"({s['decision']['method']})")
                tol = s["tolerance"]
                print(f"| {task.name} | {kind} | {loop} | {approach} | {tol[0]:g} mm, {tol[1]:g} deg "
                      f"| {s['successes']}/{s['trials']} "
                      f"| {s['success_rate']:.1%} ({s['ci95'][0]:.1%}-{s['ci95'][1]:.1%}) | {mm.get('p50', float('nan')):.2f} / "
                      f"{mm.get('p95', float('nan')):.2f} | {deg.get('p50', float('nan')):.2f} / "
                      f"{deg.get('p95', float('nan')):.2f} | {misses} | {s['wall_s']:.0f} | "
                      f"{s['real_time_factor']:.2f} |", flush=True)
    if args.json:
        args.json.write_text(json.dumps(summaries, indent=1) + "\n")


def add_runner_options(parser: argparse.ArgumentParser, workers: Optional[int] = None) -> None:
    """`--workers K` (default `workers`, else the CPU count) and `--ray [ADDRESS]`, as `stablepush
    evaluate` takes them; `runner_of` reads them."""
    parser.add_argument("--workers", type=int, default=workers or default_workers())
    parser.add_argument("--ray", nargs="?", const="", default=None, metavar="ADDRESS")


def runner_of(args: argparse.Namespace) -> Runner:
    return Runner(workers=args.workers, ray=args.ray is not None, ray_address=args.ray or None)


def progress_line(name: str, loop: str, trials: int):
    """A line on stderr, rewritten after each trial: trials done and landed so far (the table row
    comes at the end of the batch, which at 1,000 trials takes the better part of an hour)."""
    def show(record: dict, done: list) -> None:
        landed = sum(1 for r in done if r["success"])
        end = "\n" if len(done) == trials else ""
        print(f"\r{name} {loop}: {len(done)}/{trials} trials, {landed} landed", end=end, file=sys.stderr, flush=True)
    return show


if __name__ == "__main__":
    main()
