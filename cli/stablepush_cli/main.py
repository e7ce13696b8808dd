"""`stablepush` commands. The CLI parses arguments and prints; the mechanics live in the core."""
from __future__ import annotations

import json
import sys

import click

from stablepush.mechanics import check_push
from stablepush.task import TaskError, load_task

EXIT_BAD_INPUT = 2


def _fail(message: str) -> None:
    click.echo(f"error: {message}", err=True)
    sys.exit(EXIT_BAD_INPUT)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="stablepush")
def cli() -> None:
    """In-hand manipulation planning by stable prehensile pushing.

    A task file (YAML; mm, degrees, grams, newtons) describes the object, the gripper pads, the
    pushers and the goal; see data/tasks/ for the paper's examples and README.md for the format.
    """


@cli.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@click.option("--at", "at", nargs=3, type=float, default=None, metavar="X Z TH",
              help="Object pose in the grasp: x mm, z mm, theta deg. Default: the task's start.")
@click.option("--move", nargs=3, type=float, required=True, metavar="DX DZ DTH",
              help="Unit motion of the object over one step: dx mm, dz mm, dtheta deg.")
@click.option("--pusher", default=None, metavar="NAME", help="Test only this pusher (default: every pusher).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object keyed by pusher name.")
def check(task_file: str, at, move, pusher, as_json: bool) -> None:
    """Is moving the object by --move from --at a stable push, pusher by pusher?

    For each pusher: feasible or not, the contact case at the pads (all_sliding, or sticking when
    some pad points stick), and the margin in newtons (how deep the pusher wrench lies inside the
    pusher's generalized friction cone; negative outside). Decisions within rounding of the cone's
    boundary are re-made in exact arithmetic ("exact" in --json).

    \b
    Example:
      stablepush check data/tasks/horizontal-offset-low-mu.yaml --at 0 0 0 --move 1 0 0
    """
    try:
        task = load_task(task_file)
        results = check_push(task, at if at else task.start, move, pusher)
    except TaskError as exc:
        _fail(str(exc))
    if as_json:
        click.echo(json.dumps(results))
        return
    width = max(len(name) for name in results)
    for name, r in results.items():
        verdict = "stable" if r["feasible"] else "not stable"
        click.echo(f"{name:<{width}}  {verdict:<10}  {r['case']:<11}  margin {r['margin']:+.4f} N")


@cli.command()
@click.argument("task_files", metavar="TASK.yaml...", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option("--checks", "checks_only", is_flag=True, help="Benchmark the stable-push test (median time per check).")
@click.option("-n", "--count", default=200_000, show_default=True, help="Checks per contact case and task.")
@click.option("--seed", default=0, show_default=True, help="Seed of the random queries.")
def bench(task_files, checks_only: bool, count: int, seed: int) -> None:
    """Benchmark stablepush on task files.

    --checks times the stable-push test itself: random poses and unit motions, all-sliding
    (generic motions) and sticking (rotations about a pad centre), single thread, the median
    over batches of 2,000 checks.

    \b
    Example:
      stablepush bench --checks data/tasks/horizontal-offset-low-mu.yaml
    """
    from stablepush.benchmark import bench_checks

    if not checks_only:
        _fail("choose what to benchmark: --checks (planning benchmarks come with the planner)")
    try:
        tasks = [load_task(path) for path in task_files]
    except TaskError as exc:
        _fail(str(exc))
    click.echo(f"{'task':<28} {'case':<12} {'median us':>10} {'min us':>8} {'checks':>8} {'feasible':>9} {'exact':>7}")
    for task in tasks:
        with click.progressbar(length=2 * count, label=f"{task.name}", file=sys.stderr) as bar:
            timings = bench_checks(task, checks=count, seed=seed, progress=bar.update)
        for t in timings.values():
            click.echo(f"{task.name:<28} {t.case:<12} {t.median_us:>10.3f} {t.min_us:>8.3f} {t.checks:>8d} "
                       f"{t.feasible_fraction:>8.1%} {t.exact_fraction:>7.3%}")


def main() -> None:  # pragma: no cover - console entry
    cli()


if __name__ == "__main__":  # pragma: no cover
    main()
