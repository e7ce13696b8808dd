"""`stablepush design` on the shipped tasks with their pushers taken away (docs/design.md): every
edge of the part and the points beside its convex corners are candidates, with the task's least
pusher mu; its features are left to the design. Per task: the layouts planned and pruned, the
designs found, layouts planned per second, the time to the first verified design, the best
design, and where the task's own layout (measured the same way) ranks among them.

    python3 benchmarks/design_shipped.py [TASK.yaml ...] [--time-limit 2] [--workers 2] [--max-fixtures 2]
"""
import argparse
import time
from pathlib import Path

import yaml
from evaluate_tasks import add_runner_options, runner_of
from shipped import TASKS

from stablepush.design import DEFAULT_RANK, LayoutSearch, design, measure_layout
from stablepush.task.design_file import candidate_pushers

DEFAULT_TASKS = ("horizontal-offset-low-mu", "horizontal-offset-high-mu", "pivoting", "t-shaped", "large-manipulation")


def design_of(path: Path):
    """The task as a design: pushers out, candidates {mu: the least pusher mu} in, features left open."""
    data = yaml.safe_load(path.read_text())
    own = data.pop("pushers")
    environment = dict(data.get("environment") or {})
    environment.pop("features", None)
    data["environment"] = environment
    return data, candidate_pushers({"mu": min(p["mu"] for p in own)}, data, str(path)), own


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("tasks", nargs="*", type=Path)
    parser.add_argument("--time-limit", type=float, default=2.0)
    parser.add_argument("--max-fixtures", type=int, default=2)
    add_runner_options(parser, workers=2)
    args = parser.parse_args()
    runner = runner_of(args)
    paths = args.tasks or [TASKS / f"{name}.yaml" for name in DEFAULT_TASKS]
    print(f"time limit {args.time_limit:g} s a layout, up to {args.max_fixtures} fixtures, on {runner.describe()}, "
          f"ranked by {','.join(DEFAULT_RANK)}")
    print("| task | candidates | planned | pruned | designs | layouts/s | first design s | best design "
          "| the task's own layout |")
    print("|---|---:|---:|---:|---:|---:|---:|---|---|")
    for path in paths:
        task, candidates, own_pushers = design_of(path)
        started = time.perf_counter()
        first = []

        def seen(d, first=first, started=started):
            if d.solved and not first:
                first.append(time.perf_counter() - started)

        study = design(task, candidates, source=str(path),
                       search=LayoutSearch(max_fixtures=args.max_fixtures, time_limit=args.time_limit, reach_top=0),
                       runner=runner, progress=seen)
        wall = time.perf_counter() - started
        own = measure_layout(task, own_pushers, str(path), time_limit=args.time_limit)
        if not own.solved:
            standing = f"not solved in {args.time_limit:g} s"
        else:
            better = sum(1 for d in study.designs if d.key(DEFAULT_RANK) < own.key(DEFAULT_RANK))
            standing = (f"{' + '.join(own.pushers)}: {own.pushes} pushes, {own.switches} switch-overs, margin "
                        f"{own.margin_n:.3f} N; {better} designs rank above it")
        best = study.designs[0] if study.designs else None
        best_text = (f"{' + '.join(best.pushers)}: {best.pushes} pushes, {best.switches} switch-overs, margin "
                     f"{best.margin_n:.3f} N" if best else study.verdict)
        print(f"| {path.stem} | {len(candidates)} | {study.layouts_searched} | {study.layouts_pruned} "
              f"| {len(study.designs)} | {study.layouts_searched / wall:.2f} | "
              f"{first[0] if first else float('nan'):.1f} | {best_text} | {standing} |", flush=True)


if __name__ == "__main__":
    main()
