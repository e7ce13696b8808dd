"""Does the model's ranking of fixture layouts predict how often they land? `stablepush design` on
the shipped tasks with their pushers taken away (as design_shipped.py), then the best K designs by
the model's ranking and the task's own layout, each run through `evaluate`: N trials in the same
worlds, drawn wider than any plan's box (evaluate_tasks.SPREADS: pad and pusher mu +-15%, grip
+-10%, mass +-5%, features off by up to 0.5 mm and 0.5 deg), open loop on MuJoCo. Per task, one row
per layout: its place by the model (the task's own layout: "own"), its margin, and its measured
success with the Wilson 95% interval; then the order `design --evaluate` gives them.

    python3 benchmarks/design_odds.py [TASK.yaml ...] [--trials 20] [--top 3] [--time-limit 2] [--workers 2]
"""
import argparse
import time
from pathlib import Path

from design_shipped import DEFAULT_TASKS, design_of
from evaluate_tasks import SPREADS, add_runner_options, runner_of
from shipped import TASKS

from stablepush.design import DEFAULT_RANK, design, evaluate_designs, measure_layout


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path)
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--top", type=int, default=3)
    parser.add_argument("--time-limit", type=float, default=2.0)
    parser.add_argument("--max-fixtures", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1)
    add_runner_options(parser, workers=2)
    args = parser.parse_args()
    runner = runner_of(args)
    paths = args.tasks or [TASKS / f"{name}.yaml" for name in DEFAULT_TASKS]
    print(f"time limit {args.time_limit:g} s a layout, up to {args.max_fixtures} fixtures, ranked by "
          f"{','.join(DEFAULT_RANK)}; the best {args.top} and the task's own layout, {args.trials} trials each in "
          f"the same worlds ({SPREADS.describe()}; seed {args.seed}), open loop on mujoco, on {runner.describe()}")
    print("| task | layout | by the model | margin N | pushes | landed | 95% interval | by the odds | trials s |")
    print("|---|---|---:|---:|---:|---:|---|---:|---:|")
    for path in paths:
        task, candidates, own_pushers = design_of(path)
        study = design(task, candidates, source=str(path), max_fixtures=args.max_fixtures,
                       time_limit=args.time_limit, reach_top=0, runner=runner)
        model = {id(d): k for k, d in enumerate(study.designs, start=1)}
        own = measure_layout(task, own_pushers, str(path), time_limit=args.time_limit)
        study.designs = study.designs[:args.top] + ([own] if own.solved else [])
        model[id(own)] = "own"
        started = time.perf_counter()
        evaluate_designs(study, args.trials, SPREADS, top=len(study.designs), seed=args.seed, runner=runner)
        print(f"<!-- {path.stem}: {time.perf_counter() - started:.0f} s of trials -->", flush=True)
        for k, d in enumerate(study.designs, start=1):
            s = d.success
            if "refused" in s:
                landed, interval = f"refused: {s['refused']}", ""
            else:
                landed = f"{s['successes']}/{s['judged']}"
                interval = f"{s['ci95'][0]:.0%}-{s['ci95'][1]:.0%}" if s["ci95"] else ""
            print(f"| {path.stem} | {' + '.join(d.pushers)} | {model[id(d)]} | {d.margin_n:.3f} | {d.pushes} "
                  f"| {landed} | {interval} | {k} | {s.get('wall_s', 0):.0f} |", flush=True)


if __name__ == "__main__":
    main()
