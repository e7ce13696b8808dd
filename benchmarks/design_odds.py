"""Does the model's ranking of fixture layouts predict how often they land? `stablepush design` on
tasks with their pushers taken away (every edge and the points beside every convex corner are
candidates, as design_shipped.py makes them), then each layout among the best K by the ranking
rule, by the rule without its `end` and `points` keys (NO_END_OR_POINTS), and the task's own
layout, run through `evaluate`: N trials in the same worlds, drawn wider than any plan's box
(evaluate_tasks.SPREADS: pad and pusher mu +-15%, grip +-10%, mass +-5%, features off by up to
0.5 mm and 0.5 deg), open loop on MuJoCo, judged by each task's tolerance.

The tasks: the five shipped ones, or with --generated K tasks nothing was tuned for
(generated_task_odds.generate_task: boxes and convex polygons, other masses, grips and friction,
each with a goal its own line pushers reach robustly).

One row per layout: its place by each rule (the task's own layout: "own"), the plan's end over its
tolerance (1: at the edge), the point pushers it uses, its margin, and its measured success with
the Wilson 95% interval. The lines under the table sum, over the tasks, the landings of each rule's
first design and of the best measured one.

    python3 benchmarks/design_odds.py [TASK.yaml ...] [--generated K] [--trials 20] [--top 3]
                                      [--time-limit 2] [--workers 2]
"""
import argparse
from pathlib import Path

import yaml
from design_shipped import DEFAULT_TASKS, design_of
from evaluate_tasks import SPREADS, add_runner_options, runner_of
from generated_task_odds import generate_task, goal_for
from shipped import TASKS

from stablepush.design import DEFAULT_RANK, DesignOdds, LayoutSearch, design, evaluate_designs, measure_layout
from stablepush.task.design_file import candidate_pushers

NO_END_OR_POINTS = tuple(k for k in DEFAULT_RANK if k not in ("end", "points"))


def generated_designs(count: int, seed: int):
    """(name, design mapping, candidates, own pushers, source) for generated tasks with a goal."""
    for i in range(count):
        data = generate_task(seed, i)
        found = goal_for(data, seed, i)
        if found is None:
            print(f"<!-- {data['name']}: no goal its pushers reach; left out -->", flush=True)
            continue
        data["goal"] = found[0]
        own = data.pop("pushers")
        yield data["name"], data, candidate_pushers({"mu": min(p["mu"] for p in own)}, data, None), own, None


def shipped_designs(paths):
    for path in paths:
        yield (path.stem, *design_of(path), str(path))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path)
    parser.add_argument("--generated", type=int, default=0, metavar="K")
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--top", type=int, default=3)
    parser.add_argument("--time-limit", type=float, default=2.0)
    parser.add_argument("--max-fixtures", type=int, default=2)
    parser.add_argument("--seed", type=int, default=1)
    add_runner_options(parser, workers=2)
    args = parser.parse_args()
    runner = runner_of(args)
    tasks = (generated_designs(args.generated, args.seed) if args.generated else
             shipped_designs(args.tasks or [TASKS / f"{name}.yaml" for name in DEFAULT_TASKS]))
    print(f"time limit {args.time_limit:g} s a layout, up to {args.max_fixtures} fixtures; the best {args.top} by "
          f"{','.join(DEFAULT_RANK)} and by {','.join(NO_END_OR_POINTS)}, and the task's own layout, {args.trials} "
          f"trials each in the same worlds ({SPREADS.describe()}; seed {args.seed}), open loop on mujoco, on "
          f"{runner.describe()}")
    print("| task | layout | by the rule | without end, points | end / tolerance | points | margin N | landed "
          "| 95% interval |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---|")
    firsts = {"the rule's first": 0, "the first without end, points": 0, "the best measured": 0}
    for name, task, candidates, own_pushers, source in tasks:
        study = design(task, candidates, source=source,
                       search=LayoutSearch(max_fixtures=args.max_fixtures, time_limit=args.time_limit, reach_top=0),
                       runner=runner)
        if not study.designs:
            print(f"<!-- {name}: {study.verdict} -->", flush=True)
            continue
        ranked = list(study.designs)
        without = sorted(ranked, key=lambda d: d.key(NO_END_OR_POINTS))
        chosen = list(dict.fromkeys(ranked[:args.top] + without[:args.top]))
        own = measure_layout(task, own_pushers, source, time_limit=args.time_limit)
        study.designs = chosen + ([own] if own.solved else [])
        evaluate_designs(study, DesignOdds(args.trials, SPREADS, top=len(study.designs), seed=args.seed), runner=runner)

        def place(d, order):
            return "own" if d is own else order.index(d) + 1

        for d in sorted(study.designs, key=lambda d: (d is own, ranked.index(d) if d is not own else 0)):
            s = d.success
            interval = f"{s['ci95'][0]:.0%}-{s['ci95'][1]:.0%}" if s.get("ci95") else ""
            landed = f"{s['successes']}/{s['judged']}" if "refused" not in s else f"refused: {s['refused']}"
            print(f"| {name} | {' + '.join(d.pushers)} | {place(d, ranked)} | {place(d, without)} | "
                  f"{d.end_used:.2f} | {d.points} | {d.margin_n:.3f} | {landed} | {interval} |", flush=True)
        firsts["the rule's first"] += ranked[0].success.get("successes", 0)
        firsts["the first without end, points"] += without[0].success.get("successes", 0)
        firsts["the best measured"] += max(d.success.get("successes", 0) for d in chosen)
        print(f"<!-- {name}: {yaml.safe_dump(firsts, default_flow_style=True).strip()} -->", flush=True)
    print()
    for label, landed in firsts.items():
        print(f"- {label}: {landed} landings")


if __name__ == "__main__":
    main()
