"""Issue 20's speed target, measured as `stablepush evaluate` runs (docs/evaluate.md, "Speed"):
evaluate should simulate at least TARGET times faster than the robot would run the plans, on
this machine with 2 workers, for the pivot and the T. Speed is robot time over wall time: trials x
each trial's trajectory duration (s) / the batch's wall seconds.

Each task's seed-1 plan runs N trials in the worlds of docs/evaluate.md's tables (pad and pusher mu
+-15%, grip force +-10%, mass +-5%, features off by up to 0.5 mm / 0.5 deg; evaluate_tasks.SPREADS),
open loop unless `--loop closed`, on MuJoCo. One table row per task, then a line a script can read:

    speed target (20x real time, 2 local processes): not met: pivoting <x>x, t-shaped <x>x

    python3 benchmarks/evaluate_speed.py [TASK.yaml ...] [--trials 20] [--workers 2 | --ray [ADDRESS]]
                                         [--loop open|closed] [--target 20] [--json OUT.json]

Wall seconds vary with the machine's load; compare builds on the same machine, in turn.
"""
import argparse
import json
import sys
from pathlib import Path

from evaluate_tasks import SPREADS, add_runner_options, runner_of
from shipped import TASKS

from stablepush.evaluation import Batch, evaluate
from stablepush.plan import plan_task
from stablepush.task import load_task

TARGET = 20.0  # x real time with 2 workers (issue 20)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path, help="task files (default: the pivot and the T)")
    parser.add_argument("--trials", type=int, default=20)
    add_runner_options(parser, workers=2)
    parser.add_argument("--loop", choices=("open", "closed"), default="open")
    parser.add_argument("--target", type=float, default=TARGET, help="x real time asked for (default 20)")
    parser.add_argument("--json", type=Path, default=None, help="each task's speed figures, as JSON")
    args = parser.parse_args()
    runner = runner_of(args)
    tasks = args.tasks or [TASKS / "pivoting.yaml", TASKS / "t-shaped.yaml"]
    print(f"{args.trials} trials per task, {args.loop} loop, on {runner.describe()}", file=sys.stderr)
    print("| task | trials | landed | robot s | wall s | x real time |")
    print("|---|---:|---:|---:|---:|---:|")
    results = []
    for path in tasks:
        task = load_task(path)
        batch = Batch(task=task, plan=plan_task(task, seed=1), spreads=SPREADS, closed_loop=args.loop == "closed")
        s = evaluate(batch, args.trials, runner).summary()
        results.append({"task": task.name, "trials": s["trials"], "successes": s["successes"],
                        "robot_time_s": s["robot_time_s"], "wall_s": s["wall_s"],
                        "real_time_factor": s["real_time_factor"]})
        print(f"| {task.name} | {s['trials']} | {s['successes']} | {s['robot_time_s']:.1f} | {s['wall_s']:.1f} "
              f"| {s['real_time_factor']:.2f} |", flush=True)
    met = all(r["real_time_factor"] >= args.target for r in results)
    figures = ", ".join(f"{r['task']} {r['real_time_factor']:.2f}x" for r in results)
    print(f"speed target ({args.target:g}x real time, {runner.describe()}): {'met' if met else 'not met'}: {figures}")
    if args.json:
        args.json.write_text(json.dumps({"target": args.target, "runner": runner.describe(), "met": met,
                                         "tasks": results}, indent=1) + "\n")


if __name__ == "__main__":
    main()
