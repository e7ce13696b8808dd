"""`stablepush` commands. The CLI parses arguments and prints; the mechanics live in the core."""
from __future__ import annotations

import json
import sys

import click

from stablepush.mechanics import check_push
from stablepush.task import TaskError, load_task

EXIT_NOT_SOLVED = 1
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
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@click.option("-o", "--output", "json_path", type=click.Path(dir_okay=False), default=None,
              help="Plan file (JSON). Default: <task name>.plan.json in the current directory.")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False), default=None,
              help="Also write the waypoints as CSV (step,x,z,theta,pusher,...).")
@click.option("--seed", type=click.IntRange(min=0), default=None, help="Random seed (default: the task's planner.seed).")
@click.option("--time-limit", type=click.FloatRange(min=0, min_open=True), default=None, metavar="S",
              help="Give up after S seconds (default: the task's planner.time_limit).")
@click.option("--max-switches", type=click.IntRange(min=0), default=None, metavar="K",
              help="Stop at the first plan reaching the goal with at most K pusher switch-overs "
                   "(default: the task's planner.max_switches).")
@click.option("--quiet", is_flag=True, help="Print nothing on success.")
def plan(task_file: str, json_path, csv_path, seed, time_limit, max_switches, quiet: bool) -> None:
    """Plan stable pushes from the task's start to its goal.

    The planner is T-RRT* (paper section VI): it grows a tree of grasp poses joined by stable
    pushes, counts pusher switch-overs first and path length second, and stops at the first plan
    that reaches the goal within tolerance with at most --max-switches switch-overs, or at the
    time limit. The same task and seed give the same plan.

    The plan file (MODEL.md section 5) lists the pose after each unit push (x mm, z mm, theta
    deg), the pusher that made it, its margin in N, and where the pusher touches the object in
    the gripper frame. It is written even when the goal is not reached ("solved": false, the
    best partial path).

    \b
    Exit status: 0 solved, 1 not solved (time limit), 2 bad input.

    \b
    Example:
      stablepush plan data/tasks/horizontal-offset-low-mu.yaml -o low-mu.plan.json --csv low-mu.csv
    """
    from stablepush.plan_io import write_plan_csv, write_plan_json
    from stablepush.planning import plan_task

    try:
        task = load_task(task_file)
        result = plan_task(task, seed=seed, time_limit=time_limit, max_switches=max_switches)
    except TaskError as exc:
        _fail(str(exc))
    json_path = json_path or f"{task.name}.plan.json"
    try:
        write_plan_json(result, json_path)
        if csv_path:
            write_plan_csv(result, csv_path)
    except OSError as exc:
        _fail(f"cannot write the plan: {exc}")
    s = result.stats
    if not result.solved:
        click.echo(f"{task.name}: {result.message}", err=True)
        click.echo(f"partial plan written to {json_path}", err=True)
        sys.exit(EXIT_NOT_SOLVED)
    if not quiet:
        click.echo(f"{task.name}: solved in {s['planning_time_s'] * 1e3:.1f} ms (seed {s['seed']}): {s['pushes']} pushes, "
                   f"{s['switches']} switch-over(s), pushers {' -> '.join(result.pusher_sequence) or '(none)'}; "
                   f"{s['iterations']} iterations, {s['nodes']} nodes, {s['feasibility_checks']} checks")
        click.echo(f"plan written to {json_path}" + (f" and {csv_path}" if csv_path else ""))


@cli.command()
@click.argument("task_files", metavar="TASK.yaml...", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option("--checks", "checks_only", is_flag=True, help="Benchmark the stable-push test instead of planning.")
@click.option("--trials", default=10, show_default=True, type=click.IntRange(min=1), help="Planning runs per task (seeds seed, seed+1, ...).")
@click.option("--seed", default=1, show_default=True, type=click.IntRange(min=0), help="First seed.")
@click.option("--time-limit", type=click.FloatRange(min=0, min_open=True), default=None, metavar="S",
              help="Per-trial time limit (default: each task's planner.time_limit).")
@click.option("--out", "out_path", type=click.Path(dir_okay=False), default=None,
              help="Also write every trial to this file: .csv (one row per trial) or .json (trials and summary).")
@click.option("-n", "--count", default=200_000, show_default=True, help="With --checks: checks per contact case and task.")
def bench(task_files, checks_only: bool, trials: int, seed: int, time_limit, out_path, count: int) -> None:
    """Benchmark planning over seeds, in the shape of the paper's Table II.

    For each task: success rate, median / min / max planning time, median switch-overs and path
    length of the solved trials, and stable-push checks per second, with the paper's published
    median times beside ours (MATLAB, i7 2.8 GHz; and the earlier complementarity planner).
    A trial that does not solve counts with the time it took (its time limit).

    --checks instead times the stable-push test itself: random poses and unit motions,
    all-sliding (generic motions) and sticking (rotations about a pad centre), single thread,
    the median over batches of 2,000 checks.

    \b
    Examples:
      stablepush bench data/tasks/*.yaml --trials 10 --out results.csv
      stablepush bench --checks data/tasks/horizontal-offset-low-mu.yaml
    """
    from stablepush import benchmark

    try:
        tasks = [load_task(path) for path in task_files]
    except TaskError as exc:
        _fail(str(exc))
    if checks_only:
        _bench_checks(tasks, count, seed)
        return
    if out_path and not out_path.endswith((".csv", ".json")):
        _fail(f"--out {out_path}: the file name must end in .csv or .json")

    every, rows = [], []
    with click.progressbar(length=trials * len(tasks), label="planning", file=sys.stderr) as bar:
        for task in tasks:
            runs = benchmark.bench_planning(task, trials, seed=seed, time_limit=time_limit, progress=bar.update)
            every.extend(runs)
            rows.append(benchmark.summarize_planning(runs))

    def num(v, fmt):
        return "-" if v is None else format(v, fmt)

    click.echo(f"{'task':<26} {'success':>7} {'median ms':>10} {'min ms':>8} {'max ms':>9} {'switches':>8} "
               f"{'length':>7} {'checks/s':>10} {'paper s':>8} {'earlier s':>9}")
    for r in rows:
        click.echo(f"{r['task']:<26} {r['success_rate']:>7.0%} {r['median_time_s'] * 1e3:>10.2f} "
                   f"{r['min_time_s'] * 1e3:>8.2f} {r['max_time_s'] * 1e3:>9.2f} {num(r['median_switches'], '.0f'):>8} "
                   f"{num(r['median_path_length_steps'], '.1f'):>7} {r['checks_per_s']:>10.3g} "
                   f"{num(r['paper_time_s'], 'g'):>8} {num(r['earlier_planner_time_s'], 'g'):>9}")
    if out_path:
        _write_bench(out_path, every, rows)
        click.echo(f"trials written to {out_path}")


def _bench_checks(tasks, count: int, seed: int) -> None:
    from stablepush.benchmark import bench_checks

    click.echo(f"{'task':<28} {'case':<12} {'median us':>10} {'min us':>8} {'checks':>8} {'feasible':>9} {'exact':>7}")
    for task in tasks:
        with click.progressbar(length=2 * count, label=f"{task.name}", file=sys.stderr) as bar:
            timings = bench_checks(task, checks=count, seed=seed, progress=bar.update)
        for t in timings.values():
            click.echo(f"{task.name:<28} {t.case:<12} {t.median_us:>10.3f} {t.min_us:>8.3f} {t.checks:>8d} "
                       f"{t.feasible_fraction:>8.1%} {t.exact_fraction:>7.3%}")


def _write_bench(path: str, trials, rows) -> None:
    import csv
    import dataclasses
    import io

    from stablepush.plan_io import write_atomically

    records = [dataclasses.asdict(t) for t in trials]
    if path.endswith(".json"):
        write_atomically(path, json.dumps({"trials": records, "summary": rows}, indent=1) + "\n")
        return
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(records[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(records)
    write_atomically(path, buffer.getvalue())


def main() -> None:  # pragma: no cover - console entry
    cli()


if __name__ == "__main__":  # pragma: no cover
    main()
