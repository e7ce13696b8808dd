"""`stablepush bench`."""
from __future__ import annotations

import sys
from dataclasses import dataclass
from typing import Optional

import click

from stablepush_cli.common import (
    check_named_outputs,
    load_task_file,
    say_beside,
)
from stablepush_cli.groups import RunnerChoice, option_group, runner_choice
from stablepush_cli.options import (
    SEED,
    TIME_LIMIT,
    Finite,
    Whole,
)


@dataclass(frozen=True)
class BenchTrials:
    """--trials, --seed, --time-limit: the planning runs of each task, seeds seed, seed+1, ..."""

    trials: int
    seed: int
    time_limit: Optional[float]


@click.command()
@click.argument("task_files", metavar="TASK.yaml...", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option("--checks", "checks_only", is_flag=True, help="Benchmark the stable-push test instead of planning.")
@option_group(
    "runs", BenchTrials,
    click.option("--trials", default=10, show_default=True, type=Whole(min=1),
                 help="Planning runs per task (seeds seed, seed+1, ...)."),
    click.option("--seed", default=1, show_default=True, type=SEED, help="First seed."),
    click.option("--time-limit", type=TIME_LIMIT, default=None, metavar="S",
                 help="Per-trial time limit (default: each task's planner.time_limit)."))
@click.option("--out", "out_path", type=click.Path(dir_okay=False), default=None,
              help="Also write every trial to this file: .csv (one row per trial) or .json (trials and summary).")
@click.option(
    "-n", "--count", default=200_000, show_default=True, type=Whole(min=1, max=10**9),
    help="With --checks: checks per contact case and task (timed in batches of up to 2,000).",
)
@click.option("--improve-for", type=Finite(min=0), default=None, metavar="S",
              help="Anytime planning: keep improving S seconds after the first plan (planner.improve_for), "
                   "and report the first and the improved plans.")
@runner_choice("the planning trials", "one after the other, here",
               " Times are each search's own, so they compare across runners; parallel runs share the CPUs.")
def bench(task_files, checks_only: bool, runs: BenchTrials, out_path, count: int, improve_for,
          where: RunnerChoice) -> None:
    """Benchmark planning over seeds, in the shape of the paper's Table II.

    For each task: success rate, median / p95 / min / max planning time, median switch-overs and path
    length of the solved trials, and stable-push checks per second, with the paper's published
    median times beside ours (MATLAB, i7 2.8 GHz; and the earlier complementarity planner).
    A trial that does not solve counts with the time it took (its time limit).

    With --improve-for S each trial keeps improving S seconds after its first plan (fewer
    switch-overs, then a larger least margin, then shorter); a second table gives the medians of
    the first and the improved plans.

    --checks instead times the stable-push test itself: random poses and unit motions,
    all-sliding (generic motions) and sticking (rotations about a pad centre), single thread,
    the median over batches of 2,000 checks.

    \b
    Examples:
      stablepush bench data/tasks/*.yaml --trials 10 --out results.csv
      stablepush bench --checks data/tasks/horizontal-offset-low-mu.yaml
    """
    from stablepush.plan import bench_planning, summarize_planning, write_planning_trials

    tasks = [load_task_file(path) for path in task_files]
    if checks_only:
        _bench_checks(tasks, count, runs.seed)
        return
    from stablepush.outputs import require_suffix

    require_suffix("--out", out_path, (".csv", ".json"))
    check_named_outputs({"--out": out_path}, {f"TASK.yaml {path}": path for path in task_files})
    say = say_beside(out_path)

    runner = None if where.workers is None and where.ray_address is None else where.runner(default=1)
    every, rows = [], []
    with click.progressbar(length=runs.trials * len(tasks), label="planning", file=sys.stderr) as bar:
        for task in tasks:
            trials = bench_planning(task, runs.trials, seed=runs.seed, time_limit=runs.time_limit,
                                    progress=bar.update, improve_for=improve_for, runner=runner)
            every.extend(trials)
            rows.append(summarize_planning(trials))

    def num(v, fmt):
        return "-" if v is None else format(v, fmt)

    say(f"{'task':<26} {'success':>7} {'median ms':>10} {'p95 ms':>8} {'min ms':>8} {'max ms':>9} "
        f"{'switches':>8} "
        f"{'length':>7} {'checks/s':>10} {'paper s':>8} {'earlier s':>9}")
    for r in rows:
        say(f"{r['task']:<26} {r['success_rate']:>7.0%} {r['median_time_s'] * 1e3:>10.2f} "
            f"{r['p95_time_s'] * 1e3:>8.2f} "
            f"{r['min_time_s'] * 1e3:>8.2f} {r['max_time_s'] * 1e3:>9.2f} {num(r['median_switches'], '.0f'):>8} "
            f"{num(r['median_path_length_steps'], '.1f'):>7} {r['checks_per_s']:>10.3g} "
            f"{num(r['paper_time_s'], 'g'):>8} {num(r['earlier_planner_time_s'], 'g'):>9}")
    if improve_for is not None:
        say(f"\nfirst plan -> improved after {improve_for:g} s (medians of the solved trials)")
        say(f"{'task':<26} {'first ms':>9} {'switches':>13} {'length':>15} {'least margin N':>17}")
        for r in rows:
            if "first_median_time_s" not in r:
                say(f"{r['task']:<26} {'-':>9}")
                continue
            say(f"{r['task']:<26} {r['first_median_time_s'] * 1e3:>9.2f} "
                f"{r['first_median_switches']:>5.0f} -> {r['improved_median_switches']:<5.0f} "
                f"{r['first_median_path_length_steps']:>6.1f} -> {r['improved_median_path_length_steps']:<6.1f} "
                f"{r['first_median_min_margin']:>7.3f} -> {r['improved_median_min_margin']:<7.3f}")
    if out_path:
        write_planning_trials(out_path, every, rows)
        say(f"written: {out_path}")


def _bench_checks(tasks, count: int, seed: int) -> None:
    from stablepush.plan import bench_checks

    click.echo(f"{'task':<28} {'case':<12} {'median us':>10} {'min us':>8} {'checks':>8} {'feasible':>9} {'exact':>7}")
    for task in tasks:
        with click.progressbar(length=2 * count, label=f"{task.name}", file=sys.stderr) as bar:
            timings = bench_checks(task, checks=count, seed=seed, progress=bar.update)
        for t in timings.values():
            click.echo(f"{task.name:<28} {t.case:<12} {t.median_us:>10.3f} {t.min_us:>8.3f} {t.checks:>8d} "
                       f"{t.feasible_fraction:>8.1%} {t.exact_fraction:>7.3%}")
