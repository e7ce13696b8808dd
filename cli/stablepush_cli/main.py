"""`stablepush` commands. The CLI parses arguments and prints; every rule lives in the library."""
from __future__ import annotations

import contextlib
import json
import math
import os
import sys
import threading
import time
from pathlib import Path

import click

from stablepush.errors import ArmFault, OutputError, PlanError, RunnerError, StablepushError, TaskError
from stablepush.execution.protocol import DEFAULT_PORT
from stablepush.extras import MissingExtra
from stablepush.sim.engines import DEFAULT_ENGINE, ENGINES
from stablepush.task import HEADING_STEP_DEG, check_push, load_task, stable_directions
from stablepush.task.schema import LIMITS, PLANNER_PARAMETER_RANGES

EXIT_NOT_SOLVED = 1
EXIT_BAD_INPUT = 2
EXIT_ARM_FAULT = 3
EXIT_INTERNAL = 4
EXIT_MISSED = 5  # `execute`: the run completed and the object did not land within the tolerance
EXIT_PIPE_CLOSED = 141  # the output's reader went away (128 + SIGPIPE, as a shell reports such a process)
# Every error stablepush raises on purpose, and its exit status (the first class that matches).
EXIT_STATUS = (
    (TaskError, EXIT_BAD_INPUT),
    (PlanError, EXIT_BAD_INPUT),
    (OutputError, EXIT_BAD_INPUT),
    (RunnerError, EXIT_BAD_INPUT),
    (MissingExtra, EXIT_BAD_INPUT),  # an optional part of the package that the command needs
    (ArmFault, EXIT_ARM_FAULT),
)


def _exit_status(error: StablepushError) -> int:
    return next(status for kind, status in EXIT_STATUS if isinstance(error, kind))


def _fail(message: str) -> None:
    click.echo(f"error: {message}", err=True)
    sys.exit(EXIT_BAD_INPUT)


_OUTPUTS = "stablepush.outputs"  # click's shared Context.meta: the command's outputs, option -> path


def _check_outputs(outputs: dict, inputs: dict) -> None:
    """stablepush.outputs.check_outputs, remembering the outputs so that one that fails later, while
    written (a full disk, /dev/full), is reported naming its option as well (_Commands)."""
    from stablepush.outputs import check_outputs

    check_outputs(outputs, inputs)
    click.get_current_context().meta[_OUTPUTS] = {name: path for name, path in outputs.items() if path is not None}


def _error_text(ctx: click.Context, error: StablepushError) -> str:
    """The error's message, an output's prefixed with the option that named it (_check_outputs)."""
    if isinstance(error, OutputError) and error.output is not None:
        for name, path in ctx.meta.get(_OUTPUTS, {}).items():
            if Path(path) == Path(error.output):
                return f"{name} {error}"
    return str(error)


def _load(task_file: str, goal_in_grasp: bool = True):
    """The task, its warnings printed to stderr (legal, but probably not what was meant)."""
    task = load_task(task_file, goal_in_grasp)
    for warning in task.warnings:
        click.echo(f"warning: {task_file}: {warning}", err=True)
    return task


class Finite(click.FloatRange):
    """A number in a range that is also finite: click's FloatRange compares with < and >, which
    nan passes, and an unbounded side lets inf through."""

    name = "finite float range"

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number.", param, ctx)
        return number


# The planner's own ranges, so that a value out of them is refused naming the option, before any work.
SEED = click.IntRange(0, int(PLANNER_PARAMETER_RANGES["seed"][2]))
MAX_SWITCHES = click.IntRange(0, int(PLANNER_PARAMETER_RANGES["max_switches"][2]))
TIME_LIMIT = Finite(*LIMITS["time_limit"])


def _ray_address(_ctx, _param, value):
    """--ray [ADDRESS] checked before any work (stablepush.runners.check_ray_address)."""
    from stablepush.runners import check_ray_address

    try:
        return check_ray_address(value) if value else value
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None


def _say_beside(*outputs):
    """click.echo for a command's own lines, on stderr when one of its outputs is standard output
    itself (`--json /dev/stdout | jq .`), so that the stream holds that file alone."""
    from stablepush.outputs import same_file

    to_stderr = any(path and same_file(path, "/dev/stdout") for path in outputs)
    return lambda text="": click.echo(text, err=to_stderr)


def _progressbar(quiet: bool, **options):
    """A progress bar on stderr when it is a terminal, else None: in a pipe click would print each
    new label as a line of its own (a line per trial, per step)."""
    if quiet or not sys.stderr.isatty():
        return None
    return click.progressbar(file=sys.stderr, **options)


@contextlib.contextmanager
def _searching(label: str, seconds: float, quiet: bool):
    """While the block searches (with the GIL released in the core): from its first second on, a
    bar of the time spent against its limit, on a terminal."""
    done = threading.Event()

    def show() -> None:
        started = time.monotonic()
        if done.wait(1.0):
            return
        with click.progressbar(length=max(1, round(seconds * 10)), label=label, file=sys.stderr) as bar:
            while not done.wait(0.1):
                bar.update(min(round((time.monotonic() - started) * 10), bar.length) - bar.pos)

    watcher = None if quiet or not sys.stderr.isatty() else threading.Thread(target=show, daemon=True)
    if watcher is not None:
        watcher.start()
    try:
        yield
    finally:
        done.set()
        if watcher is not None:
            watcher.join()


class _Commands(click.Group):
    """The command group: each StablepushError becomes one line on stderr and its exit status;
    anything else is a bug, reported in one line (STABLEPUSH_DEBUG=1 shows the traceback)."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except StablepushError as error:
            click.echo(f"error: {_error_text(ctx, error)}", err=True)
            ctx.exit(_exit_status(error))
        except BrokenPipeError:  # the reader went away (`| head`): stop quietly, as a process ended by SIGPIPE
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no second error as Python exits
            ctx.exit(EXIT_PIPE_CLOSED)
        except (click.exceptions.Exit, click.ClickException, click.Abort, KeyboardInterrupt, SystemExit):
            raise
        except Exception as error:  # noqa: BLE001 - the last line of defence, reported as a bug
            if os.environ.get("STABLEPUSH_DEBUG"):
                raise
            text = " ".join(str(error).split())[:300]
            click.echo(f"internal error: {type(error).__name__}: {text} (a bug; please report it with the input; "
                       f"STABLEPUSH_DEBUG=1 shows the traceback)", err=True)
            ctx.exit(EXIT_INTERNAL)


@click.group(cls=_Commands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="stablepush")
def cli() -> None:
    """In-hand manipulation planning by stable prehensile pushing.

    A task file (YAML; mm, degrees, grams, newtons) describes the object, the gripper pads, the
    pushers and the goal; see data/tasks/ for the paper's examples and docs/task-files.md for the format.
    """


@cli.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@click.option("--at", "at", nargs=3, type=float, default=None, metavar="X Z TH",
              help="Object pose in the grasp: x mm, z mm, theta deg. Default: the task's start.")
@click.option("--move", nargs=3, type=float, default=None, metavar="DX DZ DTH",
              help="Unit motion of the object over one step: dx mm, dz mm, dtheta deg.")
@click.option("--directions", is_flag=True,
              help="Instead of --move: every direction in which a pusher can push the object one unit step "
                   "(planner.step) from --at, and how far any of them moves it along +-x, +-z and +-theta.")
@click.option("--heading-step", type=Finite(min=HEADING_STEP_DEG[0], max=HEADING_STEP_DEG[1]), default=10.0,
              metavar="DEG", show_default=True,
              help=f"With --directions: degrees between the headings tried in the (x, z) plane "
                   f"({HEADING_STEP_DEG[0]:g}-{HEADING_STEP_DEG[1]:g}).")
@click.option("--pusher", default=None, metavar="NAME", help="Test only this pusher (default: every pusher).")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object keyed by pusher name.")
@click.pass_context
def check(ctx: click.Context, task_file: str, at, move, directions: bool, heading_step: float, pusher,
          as_json: bool) -> None:
    """Is moving the object by --move from --at a stable push, pusher by pusher?

    For each pusher: feasible or not, the contact case at the pads (all_sliding, or sticking when
    some pad points stick), and the margin in newtons (how deep the pusher wrench lies inside the
    pusher's generalized friction cone; negative outside). Decisions within rounding of the cone's
    boundary are re-made in exact arithmetic ("exact" in --json).

    With --directions instead: each pusher's stable unit pushes from --at, by heading h in the (x, z)
    plane and elevation toward +theta (a point pusher's lie on a surface: at each heading, the
    elevations where it meets that surface),
    then the largest component any of them has along each of +-x, +-z, +-theta in unit steps. A
    sense no push moves the object in (0 or less) cannot be corrected from there: an overshoot that
    way stays.

    \b
    Examples:
      stablepush check data/tasks/horizontal-offset-low-mu.yaml --at 0 0 0 --move 1 0 0
      stablepush check data/tasks/more/cube-pegs.yaml --at 7.24 -6.14 19.54 --directions
    """
    if (move is None) == (not directions):
        raise click.UsageError("give --move DX DZ DTH, or --directions (one of the two)")
    if not directions and ctx.get_parameter_source("heading_step") is click.core.ParameterSource.COMMANDLINE:
        raise click.UsageError("--heading-step: only with --directions")
    task = _load(task_file)
    at = at if at else task.start
    if directions:
        _print_directions(stable_directions(task, at, pusher, heading_step), as_json)
        return
    results = check_push(task, at, move, pusher)
    if as_json:
        click.echo(json.dumps(results))
        return
    width = max(len(name) for name in results)
    for name, r in results.items():
        verdict = "stable" if r["feasible"] else "not stable"
        click.echo(f"{name:<{width}}  {verdict:<10}  {r['case']:<11}  margin {r['margin']:+.4f} N")


def _print_directions(found: dict, as_json: bool) -> None:
    if as_json:
        click.echo(json.dumps(found))
        return
    step_mm, step_deg = found["unit_step"]
    click.echo(f"stable unit pushes (one unit step: {step_mm:g} mm, {step_deg:g} deg), by heading in the (x, z) plane "
               f"and elevation toward +theta:")
    for name, pushes in found["pushers"].items():
        click.echo(f"{name}: {len(pushes)}")
        by_heading: dict = {}
        for p in pushes:
            by_heading.setdefault(p["heading"], []).append(p["elevation"])
        for heading, elevations in by_heading.items():
            shown = (f"elevation {elevations[0]:+6.1f}" if len(elevations) == 1
                     else f"{len(elevations)} elevations from {min(elevations):+.1f} to {max(elevations):+.1f}")
            click.echo(f"  heading {heading:5.1f}  {shown}")
    click.echo("largest component of a stable unit push along each sense, in unit steps (none or <= 0: no push "
               "moves the object that way):")
    click.echo("  " + "  ".join(f"{sense} {'none' if v is None else f'{v:+.3f}'}"
                                for sense, v in found["largest"].items()))


@cli.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@click.option("-o", "--output", "json_path", type=click.Path(dir_okay=False), default=None,
              help="Plan file (JSON). Default: <TASK file name>.plan.json in the current directory.")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False), default=None,
              help="Also write the waypoints as CSV (step,x,z,theta,pusher,...).")
@click.option(
    "--seed", type=SEED, default=None, help="Random seed (default: the task's planner.seed)."
)
@click.option("--time-limit", type=TIME_LIMIT, default=None, metavar="S",
              help="Give up after S seconds (default: the task's planner.time_limit).")
@click.option("--max-switches", type=MAX_SWITCHES, default=None, metavar="K",
              help="Stop at the first plan reaching the goal with at most K pusher switch-overs "
                   "(default: the task's planner.max_switches).")
@click.option("--quiet", is_flag=True,
              help="Print nothing on stdout on success. A note that the pads do not hold the last pose "
                   "still goes to stderr.")
def plan(task_file: str, json_path, csv_path, seed, time_limit, max_switches, quiet: bool) -> None:
    """Plan stable pushes from the task's start to its goal.

    The planner is T-RRT* (paper section V): it grows a tree of grasp poses joined by stable
    pushes, counts pusher switch-overs first and path length second, and stops at the first plan
    that reaches the goal within tolerance with at most --max-switches switch-overs, or at the
    time limit. The same task and seed give the same plan.

    The plan file (docs/model.md section 5) lists the pose after each unit push (x mm, z mm, theta
    deg), the pusher that made it, its margin in N, and where the pusher touches the object in
    the gripper frame. It is written even when the goal is not reached ("solved": false, the
    best partial path).

    \b
    A goal that no plan can reach for a reason decided before the search (every pusher excluded by
    the uncertainty box, no stable push out of the start, none that ends within the goal's
    tolerance, a hold requirement the goal cannot meet within its tolerance, a pad that would have
    to leave the object on the way) returns at once, "unreachable: " and the reason.

    \b
    Exit status: 0 solved, 1 not solved (time limit, or unreachable), 2 bad input.

    \b
    Example:
      stablepush plan data/tasks/horizontal-offset-low-mu.yaml -o low-mu.plan.json --csv low-mu.csv
    """
    from stablepush.outputs import default_output
    from stablepush.plan import plan_task, write_plan
    from stablepush.plan.verify import release_note

    json_label = "-o" if json_path else "the default -o"
    json_path = json_path or default_output(task_file, ".plan.json")
    _check_outputs({json_label: json_path, "--csv": csv_path}, {"TASK.yaml": task_file})
    say = _say_beside(json_path, csv_path)
    task = _load(task_file)
    limit = time_limit if time_limit is not None else task.planner["time_limit"]
    with _searching(f"{task.name}: searching (time limit {limit:g} s)", limit, quiet):
        result = plan_task(task, seed=seed, time_limit=time_limit, max_switches=max_switches)
    write_plan(result, json_path, csv_path)
    s = result.stats
    if not result.solved:
        click.echo(f"{task.name}: {result.message}", err=True)
        click.echo(f"partial plan written to {json_path}" + (f" and {csv_path}" if csv_path else ""), err=True)
        sys.exit(EXIT_NOT_SOLVED)
    if not quiet:
        say(f"{task.name}: solved in {s['planning_time_s'] * 1e3:.1f} ms (seed {s['seed']}): "
            f"{s['pushes']} pushes, "
            f"{s['switches']} switch-over(s), pushers {' -> '.join(result.pusher_sequence) or '(none)'}; "
            f"{s['iterations']} iterations, {s['nodes']} nodes, {s['feasibility_checks']} checks")
        say("ends at the goal pose" if result.ends_at_goal else
            f"ends within tolerance, {s['goal_distance_steps']:.2f} unit steps from the goal (a last push to "
            f"the goal itself is not a stable push)")
        say(f"plan written to {json_path}" + (f" and {csv_path}" if csv_path else ""))
    note = release_note(task, result)
    if note:
        click.echo(f"note: {note}", err=True)


@cli.command()
@click.argument("task_files", metavar="TASK.yaml...", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option("--checks", "checks_only", is_flag=True, help="Benchmark the stable-push test instead of planning.")
@click.option(
    "--trials",
    default=10,
    show_default=True,
    type=click.IntRange(min=1),
    help="Planning runs per task (seeds seed, seed+1, ...).",
)
@click.option("--seed", default=1, show_default=True, type=SEED, help="First seed.")
@click.option("--time-limit", type=TIME_LIMIT, default=None, metavar="S",
              help="Per-trial time limit (default: each task's planner.time_limit).")
@click.option("--out", "out_path", type=click.Path(dir_okay=False), default=None,
              help="Also write every trial to this file: .csv (one row per trial) or .json (trials and summary).")
@click.option(
    "-n", "--count", default=200_000, show_default=True, type=click.IntRange(min=1, max=10**9),
    help="With --checks: checks per contact case and task (timed in batches of up to 2,000).",
)
@click.option("--improve-for", type=Finite(min=0), default=None, metavar="S",
              help="Anytime planning: keep improving S seconds after the first plan (planner.improve_for), "
                   "and report the first and the improved plans.")
@click.option("--workers", type=click.IntRange(min=1, max=1024), default=None, metavar="K",
              help="Run the planning trials on K local processes (default: one after the other, here). "
                   "Times are each search's own, so they compare across runners; parallel runs share the CPUs.")
@click.option("--ray", "ray_address", is_flag=False, flag_value="", default=None, metavar="[ADDRESS]",
              callback=_ray_address,
              help="Run the planning trials on Ray: a local instance, or the cluster at ADDRESS.")
def bench(task_files, checks_only: bool, trials: int, seed: int, time_limit, out_path, count: int,
          improve_for, workers, ray_address) -> None:
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
    from stablepush.plan import benchmark

    tasks = [_load(path) for path in task_files]
    if checks_only:
        _bench_checks(tasks, count, seed)
        return
    from stablepush.outputs import require_suffix

    require_suffix("--out", out_path, (".csv", ".json"))
    _check_outputs({"--out": out_path}, {f"TASK.yaml {path}": path for path in task_files})
    say = _say_beside(out_path)

    runner = _runner(workers, ray_address, default=1)
    every, rows = [], []
    with click.progressbar(length=trials * len(tasks), label="planning", file=sys.stderr) as bar:
        for task in tasks:
            if workers is None and ray_address is None:
                runs = benchmark.bench_planning(task, trials, seed=seed, time_limit=time_limit, progress=bar.update,
                                                improve_for=improve_for)
            else:
                runs = _bench_on_runner(benchmark.PlanningJob(task, seed, time_limit, improve_for), trials, runner,
                                        bar.update)
            every.extend(runs)
            rows.append(benchmark.summarize_planning(runs))

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
        _write_bench(out_path, every, rows)
        say(f"written: {out_path}")


def _runner(workers, ray_address, default: int):
    """--workers K | --ray [ADDRESS] as a stablepush.runners.Runner (`default` workers when neither
    is given); both at once exit 2."""
    from stablepush.runners import Runner

    if ray_address is not None and workers is not None:
        _fail("--workers and --ray: choose one")
    runner = Runner(workers=workers or default, ray=ray_address is not None, ray_address=ray_address or None)
    if runner.ray:
        from stablepush.runners import probe_ray_head

        probe_ray_head(runner.ray_address)  # before any work: a batch is planned and started only then
    return runner


def _bench_on_runner(job, trials: int, runner, progress) -> list:
    """A task's planning trials on local processes or Ray (stablepush.runners.run_all), in seed order."""
    from stablepush.plan.benchmark import run_planning_job
    from stablepush.runners import WorkerLost, run_all

    done = {}
    for k, trial in run_all(run_planning_job, job, range(trials), runner):
        if isinstance(trial, WorkerLost):
            raise click.ClickException(f"{job.task.name}: planning trial {k} lost its worker ({trial.why})")
        done[k] = trial
        progress(1)
    return [done[k] for k in sorted(done)]


def _bench_checks(tasks, count: int, seed: int) -> None:
    from stablepush.plan.benchmark import bench_checks

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

    from stablepush.outputs import write_atomically

    records = [dataclasses.asdict(t) for t in trials]
    if path.lower().endswith(".json"):
        write_atomically(path, json.dumps({"trials": records, "summary": rows}, indent=1) + "\n")
        return
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(records[0]), lineterminator="\n")
    writer.writeheader()
    # A list (pusher_sequence) as JSON in its cell: pusher names may hold any printable character.
    writer.writerows({k: json.dumps(v) if isinstance(v, list) else v for k, v in r.items()} for r in records)
    write_atomically(path, buffer.getvalue())


def _load_plan_and_task(plan_file: str, task_file: str, require_solved: bool = True):
    """The task and the plan, once the plan is shown to belong to the task as it is now (check_plan;
    exit 2 if not)."""
    from stablepush.plan import check_plan, load_plan

    task = _load(task_file)
    return task, check_plan(task, load_plan(plan_file), source=plan_file, require_solved=require_solved)


@cli.command()
@click.argument("plan_file", metavar="PLAN.json", type=click.Path(dir_okay=False))
@click.option("--task", "task_file", required=True, metavar="TASK.yaml", type=click.Path(dir_okay=False),
              help="The task the plan was made for (checked against the plan).")
@click.option("-o", "--output", "png_path", type=click.Path(dir_okay=False), default=None,
              help="Figure to write: PNG, PDF or SVG, as the name ends. Default: PLAN.png beside the plan file "
                   "(t.plan.json: t.png; run.2.json: run.2.png).")
@click.option("--gif", "gif_path", type=click.Path(dir_okay=False), default=None, help="Also write an animated GIF.")
def show(plan_file: str, task_file: str, png_path, gif_path) -> None:
    """Draw a plan: snapshots of the object in the grasp and x, z, theta against step.

    The snapshots (as in the paper's fig. 1) show the object's outline in the gripper frame G with
    an arrow along its x axis (its orientation), the pads (dashed), every pusher (grey; a dot for a
    point pusher) and the active one (thick, coloured); switch-overs are named above the snapshot
    where they happen and dashed in the lower plot. An unsolved (partial) plan is drawn too, its
    title saying so.

    \b
    Example:
      stablepush plan data/tasks/t-shaped.yaml -o t.plan.json
      stablepush show t.plan.json --task data/tasks/t-shaped.yaml -o t.png --gif t.gif
    """
    from stablepush.outputs import FIGURE_SUFFIXES, require_suffix
    from stablepush.viz import figures

    png_label = "-o" if png_path else "the default -o"
    png_path = png_path or _beside(plan_file, (".json", ".plan"), ".png")
    require_suffix(png_label, png_path, FIGURE_SUFFIXES)
    require_suffix("--gif", gif_path, (".gif",))
    _check_outputs({png_label: png_path, "--gif": gif_path}, {"PLAN.json": plan_file, "--task": task_file})
    task, plan = _load_plan_and_task(plan_file, task_file, require_solved=False)
    figures.save_figure(figures.plan_figure(task, plan), png_path)
    click.echo(f"figure written to {png_path}")
    if gif_path:
        figures.save_plan_gif(task, plan, gif_path)
        click.echo(f"animation written to {gif_path}")


def _stamp(_ctx, _param, value):
    """--stamp as Unix ns (None: the bag's default), by the library's rule (bags.parse_stamp)."""
    if value is None:
        return None
    from stablepush.execution.bags import parse_stamp

    try:
        return parse_stamp(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None


def _stamp_option(which: str, default: str):
    """--stamp: the start time of the ROS 2 bag that `which` writes."""
    return click.option(
        "--stamp", "stamp_ns", default=None, callback=_stamp, metavar="TIME",
        help=f"With {which}: the bag's start time, Unix seconds (1764600000.5) or ISO-8601 with its zone "
             f"(2026-12-01T15:00:00Z); each message is stamped with it plus its time in the stream, so that the "
             f"bag plays beside live data (default: {default}).")


@cli.command()
@click.argument("plan_file", metavar="PLAN.json", type=click.Path(dir_okay=False))
@click.option("--task", "task_file", required=True, metavar="TASK.yaml", type=click.Path(dir_okay=False),
              help="The task the plan was made for (checked against the plan).")
@click.option("-o", "--output", "out_path", required=True, type=click.Path(dir_okay=False),
              metavar="TRAJ.csv|.json|.mcap",
              help="Where to write the trajectory: CSV (a header, one row per sample), JSON (columns and rows), or a "
                   "ROS 2 bag in one MCAP file (/tf, /tf_static, the gripper's pose and twist, phase, step and the "
                   "scene as markers; docs/execution.md, 'ROS 2 bags').")
@click.option("--rate", "rate_hz", default=100.0, show_default=True, type=Finite(min=1, max=1000),
              metavar="HZ", help="Samples per second (the executor streams at this rate). Each push takes the "
                                 "fewest whole samples that last the task's dynamics.step_time: a rate that does not "
                                 "divide it pushes slower than the stability test assumed. The last push of each "
                                 "contact eases to rest, up to 4/3 of the planned speed on the way "
                                 "(docs/execution.md).")
@click.option("--quat", type=click.Choice(["xyzw", "wxyz"]), default=None,
              help="Quaternion order in a .csv or .json: xyzw as ROS writes it (the default), wxyz as the arm "
                   "protocol and MuJoCo do. A .mcap's messages are ROS's own, xyzw.")
@_stamp_option("a .mcap", "now")
def trajectory(plan_file: str, task_file: str, out_path: str, rate_hz: float, quat: str, stamp_ns) -> None:
    """Write the gripper's timed trajectory for a plan: what the executor streams, for your robot.

    One sample per 1/HZ s: time (s), G's position in the world (m) and orientation (a unit
    quaternion), its linear (m/s) and angular (rad/s) velocity in the world over the period that
    ends there, the phase (push, settle, retract, move, approach) and the plan step. The world
    is the executor's: G starts at the task's environment.home (1 mm back from the first feature
    when the object starts on it, as the guarded approach starts), each pusher a fixed feature
    placed as `execute` places it.

    \b
    Example:
      stablepush plan data/tasks/t-shaped.yaml -o t.plan.json
      stablepush trajectory t.plan.json --task data/tasks/t-shaped.yaml -o t.traj.csv
      stablepush trajectory t.plan.json --task data/tasks/t-shaped.yaml -o t.mcap   # ros2 bag play, Foxglove
    """
    from stablepush.execution import execution_warnings, timed_trajectory
    from stablepush.outputs import require_suffix, write_atomically

    require_suffix("-o", out_path, (".csv", ".json", ".mcap"))
    if quat is not None and out_path.lower().endswith(".mcap"):
        _fail(f"--quat {quat}: a ROS 2 bag's quaternions are its message types' own (x, y, z, w); --quat is for "
              f".csv and .json")
    if stamp_ns is not None and not out_path.lower().endswith(".mcap"):
        _fail("--stamp: only with a .mcap (a ROS 2 bag; a .csv or .json counts t from 0)")
    quat = quat or "xyzw"
    _check_outputs({"-o": out_path}, {"PLAN.json": plan_file, "--task": task_file})
    task, plan = _load_plan_and_task(plan_file, task_file)
    for warning in execution_warnings(task):  # the stream is the executor's, so is its cell
        click.echo(f"warning: {warning}", err=True)
    traj = timed_trajectory(task, plan, rate_hz)
    if out_path.lower().endswith(".mcap"):
        from stablepush.execution.bags import write_bag

        write_bag(out_path, task, plan, traj, start_ns=stamp_ns)
    else:
        write_atomically(out_path, traj.to_json(quat) if out_path.lower().endswith(".json") else traj.to_csv(quat))
    click.echo(f"{task.name}: {len(traj)} samples at {rate_hz:g} Hz, {traj.t[-1]:.2f} s, "
               f"{len(plan.waypoints) - 1} pushes; written to {out_path}")


@cli.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@click.option("--pusher", required=True, metavar="NAME", help="The pusher whose cone to draw.")
@click.option("-o", "--output", "png_path", type=click.Path(dir_okay=False), default=None,
              help="Figure to write: PNG, PDF or SVG, as the name ends. Default: <TASK file name>.<pusher>.cone.png "
                   "in the current directory.")
def cone(task_file: str, pusher: str, png_path) -> None:
    """Draw a pusher's generalized friction cone in wrench space (paper figs. 4-5).

    The cone is the conic hull of the wrenches of the edges n +- mu t of each of the pusher's contact
    points, in the object frame O; axes f_x, f_z (N) and tau_y / l (N), with l the torque length that
    the stable-push margin uses. A point pusher's cone is a flat wedge (dimension 2).

    \b
    Example:
      stablepush cone data/tasks/pivoting.yaml --pusher left -o left-cone.png
    """
    from stablepush.outputs import FIGURE_SUFFIXES, default_output, require_suffix
    from stablepush.viz import figures

    task = _load(task_file)
    task.pusher_index(pusher)
    png_label = "-o" if png_path else "the default -o"
    png_path = png_path or default_output(task_file, f".{pusher}.cone.png")
    require_suffix(png_label, png_path, FIGURE_SUFFIXES)
    _check_outputs({png_label: png_path}, {"TASK.yaml": task_file})
    figures.save_figure(figures.cone_figure(task, pusher), png_path)
    click.echo(f"figure written to {png_path}")


def _video_size(_ctx, _param, value: str):
    """--video-size WxH as (width, height) pixels (the library checks the numbers)."""
    width, sep, height = value.lower().partition("x")
    if not sep or not width.strip().isdigit() or not height.strip().isdigit():
        raise click.BadParameter(f"expected WIDTHxHEIGHT in pixels (e.g. 640x480), got {value!r}")
    return int(width), int(height)


def _video_options(which: str):
    """--video-fps and --video-size, for the videos that `which` asks for."""
    def decorate(command):
        command = click.option(
            "--video-size", "video_size", default="640x480", show_default=True, callback=_video_size,
            metavar="WxH", help=f"With {which}: the video's width and height in pixels (even).")(command)
        return click.option(
            "--video-fps", "video_fps", default=25.0, show_default=True, type=Finite(min=0, min_open=True),
            metavar="FPS", help=f"With {which}: frames per second of the run's time, played at that rate (real "
                                f"time); at most 100, a frame per waypoint at 100 Hz.")(command)
    return decorate


def _video_settings_need(option: str) -> None:
    """Exit 2 when --video-fps or --video-size is given without `option` (they would do nothing)."""
    ctx = click.get_current_context()
    given = [f"--video-{name}" for name in ("fps", "size")
             if ctx.get_parameter_source(f"video_{name}") is click.core.ParameterSource.COMMANDLINE]
    if given:
        _fail(f"{' and '.join(given)}: only with {option}")


def _check_video(option: str, path: str, fps: float, size) -> None:
    """Refuse, before anything runs, a video that could not be written (exit 2 naming the option).
    Loads MuJoCo for headless rendering (MUJOCO_GL=osmesa), so call it before the simulated arm
    starts."""
    from stablepush.sim.video import check_fps, check_size, check_video_path

    for name, check, value in (("--video-fps", check_fps, fps), ("--video-size", check_size, size)):
        try:
            check(value)
        except ValueError as exc:
            _fail(f"{name}: {exc}")
    try:
        check_video_path(path)
    except OutputError as exc:
        _fail(f"{option} {exc}")
    except MissingExtra as exc:
        _fail(f"{option}: {exc}")


def _video_output(option: str, path: str, fps: float, size, quiet: bool):
    """The run's video as an output (stablepush.sim.video.RunVideo), with a progress bar on stderr;
    exit 2 naming `option` for one that could not be written. Loads MuJoCo for headless rendering
    (MUJOCO_GL=osmesa), so call it before the simulated arm starts."""
    _check_video(option, path, fps, size)
    from stablepush.sim.video import RunVideo

    bar = None

    def progress(done: int, frames: int) -> None:
        nonlocal bar
        if bar is None:
            bar = click.progressbar(length=frames, label=f"video {path}", file=sys.stderr, show_pos=True)
            bar.__enter__()
        bar.update(1)
        if done == frames:
            bar.__exit__(None, None, None)

    return RunVideo(path, fps, size, progress=None if quiet else progress)


def _host_port(_ctx, _param, value):
    """--arm HOST:PORT as (host, port); a HOST left out is this machine."""
    if value is None:
        return None
    host, sep, port = value.rpartition(":")
    if not sep or not port.isdigit() or not 0 < int(port) < 65536:
        raise click.BadParameter(f"expected HOST:PORT with a port from 1 to 65535, got {value!r}")
    return host or "127.0.0.1", int(port)


@cli.command()
@click.argument("plan_file", metavar="PLAN.json", type=click.Path(dir_okay=False))
@click.option("--task", "task_file", required=True, metavar="TASK.yaml", type=click.Path(dir_okay=False),
              help="The task the plan was made for (checked against the plan before anything moves).")
@click.option("--arm", "arm", default=None, metavar="HOST:PORT", callback=_host_port,
              help=f"The arm server (stablepush.arm/2 protocol, see docs/execution.md). Default: with --sim a "
                   f"simulated arm started in this process, else 127.0.0.1:{DEFAULT_PORT}.")
@click.option("--sim", is_flag=True, help="Start a simulated arm here and run the plan on it (see --engine).")
@click.option("--engine", default=DEFAULT_ENGINE, show_default=True, type=click.Choice(ENGINES),
              help="With --sim: the physics engine of the simulated arm. mujoco: pads slide with stablepush's own "
                   "Coulomb friction; drake: Drake's contact solver alone decides stick and slip.")
@click.option("--rate", "rate_hz", default=100.0, show_default=True, type=Finite(min=1, max=1000),
              metavar="HZ", help="Waypoints per second of motion. Each push takes the fewest whole periods that "
                                 "last the task's dynamics.step_time (slower than the model when HZ does not divide "
                                 "it); the last push of each contact eases to rest, up to 4/3 of the planned "
                                 "speed on the way (docs/execution.md).")
@click.option("--resume-from", "resume_from", default=0, type=click.IntRange(min=0), metavar="STEP",
              help="Continue after plan step STEP (the last confirmed step a fault reported); a simulated arm then "
                   "keeps the world it has, where every other run starts from a fresh one.")
@click.option("--pace/--no-pace", default=None,
              help="Hold the stream to --rate in wall-clock time (default: on for a real arm, off with --sim).")
@click.option("--ack-timeout", default=5.0, show_default=True, type=Finite(min=0.01), metavar="S",
              help="Give up when the arm server does not reply within S seconds (not with --sim: the simulated "
                   "arm runs in this process, and a waypoint takes as long as it takes).")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None,
              help="Write the run's report as JSON: success, tolerance, cause of a miss, engine, final pose in the "
                   "grasp, slip per contact, corrections, features (on an arm fault: the verdict and where to resume).")
@click.option("--success-tolerance", "success_tolerance", nargs=2, type=Finite(min=0, min_open=True),
              default=None, metavar="MM DEG",
              help="The run lands when the object ends within MM (x and z) and DEG of the goal in the grasp "
                   "(default: the task's planner.tolerance).")
@click.option("--record", "record_path", type=click.Path(dir_okay=False), default=None, metavar="RUN.mcap",
              help="Record the run as a ROS 2 bag (one MCAP file): the commanded and measured gripper pose, the "
                   "object in the world and in the grasp, /tf and /tf_static, the pusher in contact, each correction "
                   "and the verdict (docs/execution.md, 'ROS 2 bags'); written on a fault too.")
@_stamp_option("--record", "when the run starts")
@click.option("--video", "video_path", type=click.Path(dir_okay=False), default=None, metavar="RUN.mp4",
              help="Draw the run as a video (H.264 MP4, headless): seen along the gripping axis as the plan figures "
                   "are, the object, the pads, the features (the pusher in contact highlighted) and the plan's pose "
                   "at each step as a green ghost (docs/execution.md, 'Video of a run'); needs the object's pose, "
                   "which a simulated arm reports; drawn on a fault too.")
@_video_options("--video")
@click.option("--quiet", is_flag=True, help="No progress bar.")
@click.option("-v", "--verbose", is_flag=True,
              help="A line per correction of the closed loop and per contact (slip, carry, where the guard found "
                   "its feature); without, one line sums each up.")
@click.option("--sim-mu-scale", "mu_scale", default=1.0, show_default=True, type=Finite(min=0.1, max=10),
              metavar="S", help="With --sim: the simulated pads' and features' mu are S times the task's, to test "
                                "the plan against a world whose friction differs from its model.")
@click.option("--tracker-noise", "tracker_noise", nargs=2, type=Finite(min=0), default=(0.0, 0.0),
              metavar="MM DEG", help="With --sim: standard deviations of the simulated tracker's noise on the "
                                     "object's pose in the grasp (x and z in mm, theta in deg).")
@click.option("--closed-loop", "closed_loop", is_flag=True,
              help="As the object comes onto each feature and after each push compare the arm's tracked "
                   "pose in the grasp with the plan's; past --replan-threshold (on the last contact's "
                   "feature, --final-tolerance) re-plan from the measured pose and continue with the new plan. "
                   "An arm that reports no tracked pose runs open loop (and says so).")
@click.option("--guard/--no-guard", "guarded", default=True, show_default=True,
              help="End each approach slowly and find the feature by touch (the arm's contact force, else its "
                   "tracked pose in the grasp), then push from where it was found: a feature off its place is "
                   "found, not pushed into or missed. After a contact's first push, a feature the object rests "
                   "on turned (past 0.15 deg) is taken as turned for the contact's other pushes. An arm that "
                   "reports no tracked pose approaches as planned (and says so).")
@click.option("--replan-threshold", nargs=2, type=Finite(min=0, min_open=True), default=None,
              metavar="MM DEG", help="With --closed-loop: deviation from the plan that triggers a re-plan "
                                     "(default: half the task's goal tolerance).")
@click.option("--final-tolerance", nargs=2, type=Finite(min=0, min_open=True), default=None,
              metavar="MM DEG", help="With --closed-loop: after the last push, correct until the object is "
                                     "this close to the goal, and re-plan on the last contact's feature past it "
                                     "(default: a fifth of the task's goal tolerance).")
def execute(plan_file: str, task_file: str, arm, sim: bool, engine: str, rate_hz: float, resume_from: int, pace,
            ack_timeout: float, json_path, success_tolerance, record_path, stamp_ns, video_path, video_fps: float,
            video_size, quiet: bool, verbose: bool, mu_scale: float, tracker_noise, closed_loop: bool, guarded: bool,
            replan_threshold, final_tolerance) -> None:
    """Run a plan on an arm: stream end-effector waypoints and report what the arm confirmed.

    Each pusher the plan uses is a fixed feature of the world (the task's `environment:` section
    places them, else one station per pusher along y, 150 mm apart and alternating about home).
    During a push the object rests on its feature while the gripper moves; between pushes the
    gripper retracts, moves and approaches, and the approach finds the feature by touch (--guard).
    Waypoints (G's pose in the world, m and a quaternion) go out at --rate as JSON lines over TCP and
    each is acknowledged with the arm's state.

    The run ends with a verdict: it landed when the object's pose in the grasp is within the task's
    goal tolerance (or --success-tolerance), exit 0; a completed run that missed exits 5 and names
    its cause (grasp_lost, correction_not_found, corrections_exhausted, feature_off,
    pusher_slipped, plan_short, drift). An arm that reports no pose in the grasp gets no verdict (exit 0).

    On a fault (the arm server gone, a malformed or out-of-order reply, an error from the arm) the arm
    is told to stop, the last confirmed plan step is printed, and the exit status is 3; run again with
    --resume-from STEP to continue. A plan that does not belong to the task exits 2 before anything moves.

    \b
    Examples:
      stablepush execute low-mu.plan.json --task data/tasks/horizontal-offset-low-mu.yaml --sim
      stablepush execute low-mu.plan.json --task data/tasks/horizontal-offset-low-mu.yaml --sim --video low-mu.mp4
      stablepush sim-arm --port 47100 &     # or your robot's bridge
      stablepush execute low-mu.plan.json --task data/tasks/horizontal-offset-low-mu.yaml --arm 127.0.0.1:47100
    """
    from stablepush.execution import ClosedLoop, GuardedApproach, RunOptions, execution_warnings
    from stablepush.execution.run import BagRecording, JsonReport, run_plan
    from stablepush.execution.stream import check_resume_from
    from stablepush.outputs import require_suffix

    require_suffix("--record", record_path, (".mcap",))
    if stamp_ns is not None and not record_path:
        _fail("--stamp: only with --record (it is the recording's start time)")
    _check_outputs({"--json": json_path, "--record": record_path, "--video": video_path},
                  {"PLAN.json": plan_file, "--task": task_file})
    task, plan = _load_plan_and_task(plan_file, task_file)
    for warning in execution_warnings(task):
        click.echo(f"warning: {warning}", err=True)
    check_resume_from(plan.waypoints, resume_from, field="--resume-from")
    _only_with("--closed-loop", closed_loop, ("--replan-threshold", replan_threshold),
               ("--final-tolerance", final_tolerance))
    _only_with("--sim (a simulated arm started here)", sim and arm is None, ("--engine", engine != DEFAULT_ENGINE),
               ("--sim-mu-scale", mu_scale != 1.0), ("--tracker-noise", any(tracker_noise)))
    # The video is made first: the renderer needs MUJOCO_GL=osmesa before the simulated arm loads MuJoCo.
    video = [_video_output("--video", video_path, video_fps, video_size, quiet)] if video_path else []
    if not video_path:
        _video_settings_need("--video")
    outputs = ([JsonReport(json_path)] if json_path else []) + (
        [BagRecording(record_path, stamp_ns)] if record_path else []) + video
    options = RunOptions(rate_hz=rate_hz, resume_from=resume_from, pace=(not sim) if pace is None else pace,
                         closed_loop=ClosedLoop.for_task(task, replan_threshold, final_tolerance) if closed_loop
                         else None,
                         guard=GuardedApproach.for_tracker_noise(*tracker_noise) if guarded else None,
                         success_tolerance=success_tolerance)
    target = _arm_for(arm, sim, engine, mu_scale, tracker_noise, ack_timeout, quiet)
    with _run_progress(task, plan, resume_from, quiet) as progress:
        run = run_plan(task, plan, target, options, outputs, progress=progress)
    say = _say_beside(json_path, record_path, video_path)
    if run.fault is not None:
        _report_fault(run.fault, plan_file, len(plan.waypoints) - 1, run.written)
    for line in run.report.describe(verbose) + run.written:
        say(line)
    if run.report.success is False:
        sys.exit(EXIT_MISSED)


def _only_with(option: str, given: bool, *others) -> None:
    """Exit 2 when any of `others` ((name, given) pairs) is given without `option`."""
    named = [name for name, value in others if value]
    if named and not given:
        _fail(f"{' and '.join(named)}: only with {option}")


def _arm_for(arm, sim: bool, engine: str, mu_scale: float, tracker_noise, ack_timeout: float, quiet: bool):
    """The arm a run goes to: a simulated one in this process (--sim), else the arm server at
    --arm (or the default port here)."""
    if sim and arm is None:
        from stablepush.sim.deviation import WorldDeviation
        from stablepush.sim.local_arm import SimulatedArm

        deviation = WorldDeviation(mu_scale=mu_scale, tracker_noise_mm=tracker_noise[0],
                                   tracker_noise_deg=tracker_noise[1])
        return SimulatedArm(engine, deviation, log=None if quiet else lambda text: click.echo(f"sim-arm: {text}",
                                                                                             err=True))
    from stablepush.execution import TcpArm

    host, port = arm or ("127.0.0.1", DEFAULT_PORT)
    return TcpArm(host, port, ack_timeout)


@contextlib.contextmanager
def _run_progress(task, plan, resume_from: int, quiet: bool):
    """A progress bar over the plan's steps (a re-plan may change their number), as the progress
    callback of a run; None without a terminal."""
    bar = _progressbar(quiet, length=len(plan.waypoints) - 1 - resume_from, label=f"{task.name}: step {resume_from}",
                       show_pos=True)
    if bar is None:
        yield None
        return
    seen = [resume_from]

    def progress(waypoint, confirmed, total):
        if total - resume_from != bar.length:  # a re-plan changed the plan's length
            bar.length = total - resume_from
        if confirmed > seen[0]:
            bar.label = f"{task.name}: step {confirmed} ({waypoint.phase})"
            bar.update(confirmed - seen[0])
            seen[0] = confirmed

    with bar:
        yield progress


def _report_fault(fault, plan_file: str, last_step: int, written) -> None:
    """Print how a run ended in an arm fault, and where to resume, then exit 3."""
    for line in written:
        click.echo(line)
    if not fault.connected:
        click.echo(f"error: {fault.reason}; nothing was sent. Is the arm server running? "
                   f"(`stablepush sim-arm` serves a simulated arm, or run with --sim)", err=True)
        sys.exit(EXIT_ARM_FAULT)
    stopped = {True: "the arm was stopped", None: "the arm could not be reached to stop it"}[fault.arm_stopped]
    if fault.replanned:  # its steps are the closed loop's, numbered otherwise than the plan file's
        click.echo(f"error: {fault.reason}; {stopped}; the closed loop had re-planned the run, so no step of "
                   f"{plan_file} continues it: plan again from where the object is in the grasp (a task whose "
                   f"start: is the tracked pose)", err=True)
        sys.exit(EXIT_ARM_FAULT)
    click.echo(f"error: {fault.reason}; {stopped}; last confirmed step: {fault.last_confirmed_step} of "
               f"{last_step}", err=True)
    click.echo(f"continue with: {_resume_command(click.get_current_context(), fault.last_confirmed_step)}", err=True)
    sys.exit(EXIT_ARM_FAULT)


# The options of `execute` that say how a run runs, so a resume keeps them (outputs are left out:
# a resumed run writes its own).
RUN_OPTIONS = ("arm", "sim", "engine", "rate_hz", "pace", "ack_timeout", "success_tolerance", "mu_scale",
               "tracker_noise", "closed_loop", "replan_threshold", "final_tolerance", "guarded")


def _resume_command(ctx: click.Context, step: int) -> str:
    """The command that continues this `execute` from plan step `step`: its arguments and every
    option of RUN_OPTIONS given other than its default, as typed."""
    import shlex

    words = ["stablepush", "execute", ctx.params["plan_file"], "--task", ctx.params["task_file"]]
    for param in ctx.command.params:
        value = ctx.params.get(param.name)
        if param.name not in RUN_OPTIONS or value is None or value == param.get_default(ctx):
            continue
        if param.name == "arm":
            words += ["--arm", f"{value[0]}:{value[1]}"]
        elif param.is_flag and param.secondary_opts:  # --x/--no-x
            words.append(param.opts[0] if value else param.secondary_opts[0])
        elif param.is_flag:
            words.append(param.opts[0])
        else:
            words += [param.opts[0], *(f"{v:g}" if isinstance(v, float) else str(v)
                                       for v in (value if isinstance(value, tuple) else (value,)))]
    return shlex.join(words + ["--resume-from", str(step)])


def _vary(_ctx, _param, values):
    """--vary KEY=FRACTION, repeated, as a dict (the keys and ranges are checked by Spreads); None
    when not given, {} for `--vary none`."""
    if not values:
        return None
    if [v.strip().lower() for v in values] == ["none"]:
        return {}
    out = {}
    for value in values:
        key, sep, fraction = value.partition("=")
        try:
            out[key.strip()] = float(fraction)
        except ValueError:
            sep = ""
        if not sep:
            raise click.BadParameter(f"expected KEY=FRACTION (e.g. pad_mu=0.15), got {value!r}")
    return out


@cli.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@click.option("--plan", "plan_file", metavar="PLAN.json", type=click.Path(dir_okay=False), default=None,
              help="The plan to evaluate (checked against the task). Default: plan once from the task.")
@click.option("--robust", is_flag=True,
              help="Plan robust to the worlds: the task's uncertainty box widened to the --vary spreads, so every "
                   "push is stable for every multiplier they draw (docs/model.md section 7). Corrections keep "
                   "the box. Not with --plan.")
@click.option("--trials", default=100, show_default=True, type=click.IntRange(min=1, max=1_000_000),
              help="Number of trials (worlds).")
@click.option("--seed", default=1, show_default=True, type=click.IntRange(min=0, max=2**32 - 1),
              help="Trial i's world depends on (seed, i) alone: the same seed gives the same worlds and outcomes, "
                   "serially, on workers or on Ray.")
@click.option("--vary", "vary", multiple=True, callback=_vary, metavar="KEY=FRACTION",
              help="Multiply the task's KEY (pad_mu, pusher_mu, grip_force or mass) in each world by a factor drawn "
                   "uniformly within 1 +- FRACTION. Repeatable; `--vary none` varies nothing. Default: the task's "
                   "uncertainty box, else pad_mu and pusher_mu 0.1, grip_force 0.05, mass 0.02, with "
                   "--feature-error 0.2 0.2 (docs/evaluate.md, 'The worlds').")
@click.option("--feature-error", nargs=2, type=Finite(min=0), default=None, metavar="MM DEG",
              help="Place each feature off by up to MM in x and z and DEG about y (uniform). Default: 0.2 0.2 "
                   "without --vary, else 0 0.")
@click.option("--tracker-noise", nargs=2, type=Finite(min=0), default=(0.0, 0.0), metavar="MM DEG",
              help="Standard deviations of the tracker's noise on the pose in the grasp.")
@click.option("--closed-loop", is_flag=True, help="Run each trial closed loop (re-plan from the tracked pose).")
@click.option("--guard/--no-guard", "guarded", default=True, show_default=True,
              help="Find each feature by touch at the end of its approach (as `execute --guard`).")
@click.option("--engine", default=DEFAULT_ENGINE, show_default=True, type=click.Choice(ENGINES),
              help="The simulated arm's physics engine.")
@click.option("--success-tolerance", nargs=2, type=Finite(min=0, min_open=True), default=None, metavar="MM DEG",
              help="A trial lands when the object comes to rest within MM (x and z) and DEG of the goal in the "
                   "grasp, as `execute` judges a run (default: the task's planner.tolerance).")
@click.option("--workers", type=click.IntRange(min=1, max=1024), default=None, metavar="K",
              help="Run the trials on K local processes (default: the number of CPUs).")
@click.option("--ray", "ray_address", is_flag=False, flag_value="", default=None, metavar="[ADDRESS]",
              callback=_ray_address,
              help="Run the trials on Ray: a local instance, or the cluster at ADDRESS (e.g. 10.0.0.5:6379; see "
                   "docs/evaluate.md, 'Where the trials run').")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None,
              help="Write the summary and every trial as JSON.")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False), default=None, help="Write one trial a row.")
@click.option("--plot", "png_path", type=click.Path(dir_okay=False), default=None,
              help="Draw the goal error's CDF against the tolerance, and success over the varied parameters (PNG, "
                   "PDF or SVG, as the name ends).")
@click.option("--video-failed", "video_dir", type=click.Path(file_okay=False), default=None, metavar="DIR",
              help="Draw each failed trial's run as a video, DIR/trial-<i>.mp4 (made if missing; as `execute "
                   "--video` draws it, in the trial's own world), named in the trial's record (--json, --csv).")
@_video_options("--video-failed")
@click.option("--quiet", is_flag=True, help="No progress bar.")
def evaluate(task_file: str, plan_file, robust: bool, trials: int, seed: int, vary, feature_error, tracker_noise,
             closed_loop: bool, guarded: bool, engine: str, success_tolerance, workers, ray_address, json_path,
             csv_path, png_path, video_dir, video_fps: float, video_size, quiet: bool) -> None:
    """Measure how often a plan lands: run it in TRIALS simulated worlds that differ from its model.

    Each trial's world multiplies the task's parameters named by --vary by factors drawn within the
    given spreads (default: the task's uncertainty box, else a lab's: see --vary), moves each
    feature by up to --feature-error and adds --tracker-noise; the plan runs there on the simulated
    arm (open loop, or --closed-loop) and lands, as `execute` judges a run, when the object comes
    to rest after the release within the task's tolerance of the goal (or --success-tolerance).
    The summary gives the success rate with its Wilson 95% interval, the goal error's percentiles
    and the causes of the misses. Spreads that vary nothing make one world: one trial runs, and no
    interval is given. A trial that crashes is recorded (cause `crash`) and the batch goes on;
    Ctrl-C stops it and keeps the trials done.

    \b
    Exit status: 0 done (whatever the success rate), 1 no plan found, 2 bad input, 130 stopped by
    Ctrl-C (the trials done are summarized and written).

    \b
    Examples:
      stablepush evaluate data/tasks/t-shaped.yaml --trials 100   # a lab's spreads, judged by the task's tolerance
      stablepush evaluate data/tasks/pivoting.yaml --trials 200 --vary pad_mu=0.15 --vary pusher_mu=0.15 \\
          --vary grip_force=0.1 --vary mass=0.05 --feature-error 0.5 0.5 --json piv.eval.json --plot piv.png
      stablepush evaluate data/tasks/t-shaped.yaml --trials 1000 --closed-loop --vary pad_mu=0.15 --ray
      stablepush evaluate data/tasks/t-shaped.yaml --trials 100 --robust --vary pad_mu=0.15 --vary pusher_mu=0.15
      stablepush evaluate data/tasks/t-shaped.yaml --trials 20 --vary pad_mu=0.3 --video-failed t-failed
    """
    if video_dir:  # before the trials load MuJoCo: the renderer needs MUJOCO_GL=osmesa from the start
        _check_video("--video-failed", os.path.join(video_dir, "trial-0.mp4"), video_fps, video_size)
    else:
        _video_settings_need("--video-failed")
    from stablepush.evaluation import Batch, Spreads, robust_task, write_evaluation
    from stablepush.evaluation import evaluate as run_evaluation
    from stablepush.outputs import FIGURE_SUFFIXES, require_suffix
    from stablepush.plan import plan_task
    from stablepush.runners import default_workers

    require_suffix("--plot", png_path, FIGURE_SUFFIXES)
    _check_outputs({"--json": json_path, "--csv": csv_path, "--plot": png_path},
                  {"TASK.yaml": task_file, "--plan": plan_file})
    say = _say_beside(json_path, csv_path, png_path)

    runner = _runner(workers, ray_address, default=default_workers())
    if robust and plan_file:
        _fail("--robust plans from the task; a plan given with --plan is evaluated as it is")
    if plan_file:
        task, plan = _load_plan_and_task(plan_file, task_file)
    else:
        task = _load(task_file)
    try:
        spreads = Spreads.for_task(task, vary, feature_error, tracker_noise)
    except ValueError as exc:  # only --vary can be refused here, and Spreads names it `vary`
        _fail(f"--{exc}")
    if robust and not any(spreads.vary.values()):
        _fail("--robust needs spreads to widen the box to (--vary, or the defaults it takes without)")
    if not plan_file:
        if robust:
            task = robust_task(task, spreads)
        plan = plan_task(task)
        if not plan.solved:
            click.echo(f"{task.name}{' (robust)' if robust else ''}: {plan.message}", err=True)
            sys.exit(EXIT_NOT_SOLVED)
    if video_dir:
        from stablepush.sim.video import video_directory

        try:
            video_dir = video_directory(video_dir)
        except OutputError as exc:
            _fail(f"--video-failed {exc}")
    batch = Batch(task=task, plan=plan, spreads=spreads, seed=seed, closed_loop=closed_loop, guarded=guarded,
                  engine=engine, tolerance=success_tolerance, video_dir=video_dir, video_fps=video_fps,
                  video_size=tuple(video_size))
    for warning in batch.warnings():
        click.echo(f"warning: {warning}", err=True)
    trials = spreads.trials_to_run(trials)  # as evaluate() runs them: the bar and the header say so too
    if not quiet:
        box = ", ".join(f"{key} +-{fraction:.0%}" for key, fraction in task.uncertainty.items())
        worlds = ("one world, the model's own (nothing varies)" if spreads.one_world else
                  ", ".join([f"{key} +-{fraction:.0%}" for key, fraction in spreads.vary.items() if fraction]
                            + [f"features off by up to {spreads.feature_error[0]:g} mm, "
                               f"{spreads.feature_error[1]:g} deg"] * any(spreads.feature_error)
                            + [f"tracker noise {spreads.tracker_noise[0]:g} mm, {spreads.tracker_noise[1]:g} deg"]
                            * any(spreads.tracker_noise)))
        click.echo(f"{task.name}: {worlds}", err=True)
        click.echo(f"{task.name}: {trials} trials, {'closed' if closed_loop else 'open'} loop"
                   f"{'' if guarded else ', approaches not guarded'} on {engine}, "
                   f"on {runner.describe()}" + (f"; the plan is robust to {box}" if box else ""), err=True)
    bar = _progressbar(quiet, length=trials, label="trials", show_pos=True)

    def progress(record, done) -> None:
        if bar is not None:
            landed = sum(1 for r in done if r["success"])
            bar.label = f"landed {landed}/{len(done)} ({landed / len(done):.0%})"
            bar.update(1)

    try:
        result = run_evaluation(batch, trials, runner, progress)
    finally:
        if bar is not None:
            bar.render_finish()
    write_evaluation(result, json_path, csv_path, png_path)
    s = result.summary()
    if not s["trials"]:
        click.echo("interrupted before any trial finished" if s["interrupted"] else "no trial finished", err=True)
        sys.exit(130 if s["interrupted"] else EXIT_NOT_SOLVED)
    tol = s["tolerance"]
    within = f"within {tol[0]:g} mm (x and z) and {tol[1]:g} deg"
    if s["one_world"]:
        say(f"{task.name}: one world, the model's own (nothing varies): "
            f"{'landed' if s['successes'] else 'missed'} {within}; one trial, so no interval")
    else:
        low, high = s["ci95"]
        say(f"{task.name}: landed {s['successes']} of {s['trials']} trials {within}: {s['success_rate']:.1%} "
            f"(95% CI {low:.1%}-{high:.1%})" + (f"; interrupted after {s['trials']} of {trials}"
                                                if s["interrupted"] else ""))
    if s["goal_error_mm"]:
        say(f"goal error: median {s['goal_error_mm']['p50']:.3f} mm / {s['goal_error_deg']['p50']:.3f} deg, "
            f"p95 {s['goal_error_mm']['p95']:.3f} mm / {s['goal_error_deg']['p95']:.3f} deg")
    if s["causes"]:
        say("misses: " + ", ".join(f"{cause} {count}" for cause, count in sorted(s["causes"].items())))
    say(f"{s['wall_s']:.1f} s on {s['runner']}: {s['robot_time_s']:.0f} s of robot time, "
        f"{s['real_time_factor']:.2f}x real time")
    written = [p for p in (json_path, csv_path, png_path) if p]
    if written:
        say(f"written: {', '.join(written)}")
    if video_dir:
        videos = sum(1 for t in result.trials if t.get("video"))
        failed = sum(1 for t in result.trials if not t["success"])
        say(f"videos of {videos} of the {failed} failed trial(s) written to {video_dir}"
            + "".join(f"\n  trial {t['trial']}: no video ({t['video_error']})"
                      for t in result.trials if t.get("video_error")))
    if s["interrupted"]:
        sys.exit(130)


def _beside(path: str, endings, suffix: str) -> str:
    """`path` with each of `endings` it ends in taken off, in turn, and `suffix` put on."""
    name = Path(path).name
    for ending in endings:
        if name.lower().endswith(ending) and len(name) > len(ending):
            name = name[: -len(ending)]
    return str(Path(path).with_name(name + suffix))


def _axis(_ctx, param, value):
    """A grid axis A:B:N (N values from A to B; A:A:1 for A alone), within the task file's pose bounds;
    the library's own check (grid_axis) refuses a count of 1 with B other than A, and equal ends
    with a larger count, named as the option."""
    from stablepush.plan.reach import MAX_AXIS, grid_axis
    from stablepush.task.schema import ANGLE, COORDINATE

    if value is None:
        return None
    low, high = ANGLE if param.name == "theta_axis" else COORDINATE
    parts = value.split(":")
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3 or not 1 <= count <= MAX_AXIS or not (low <= start <= high and low <= stop <= high):
            raise ValueError
    except (ValueError, IndexError):
        raise click.BadParameter(f"expected FROM:TO:COUNT, FROM and TO from {low:g} to {high:g} and COUNT from 1 to "
                                 f"{MAX_AXIS} (e.g. -10:10:11), got {value!r}")
    try:
        return grid_axis(param.name, (start, stop, count), (low, high))
    except TaskError as exc:
        raise click.BadParameter(exc.reason) from None


@cli.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@click.option("--x", "x_axis", callback=_axis, default=None, metavar="A:B:N",
              help="Goal x values, mm: N from A to B (default: the task's goal x alone).")
@click.option("--z", "z_axis", callback=_axis, default=None, metavar="A:B:N", help="Goal z values, mm (likewise).")
@click.option("--theta", "theta_axis", callback=_axis, default=None, metavar="A:B:N",
              help="Goal theta values, deg (likewise).")
@click.option("--time-limit", default=1.0, show_default=True, type=TIME_LIMIT,
              metavar="S", help="Each cell's search time.")
@click.option("--seed", default=None, type=SEED, help="Planner seed (default: the task's).")
@click.option("--workers", type=click.IntRange(min=1, max=1024), default=None, metavar="K",
              help="Plan the cells on K local processes (default: the number of CPUs).")
@click.option("--ray", "ray_address", is_flag=False, flag_value="", default=None, metavar="[ADDRESS]",
              callback=_ray_address,
              help="Plan the cells on Ray: a local instance, or the cluster at ADDRESS.")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None,
              help="Write the map: its cells (goal, verdict, reason, solved, seed, planning time, switch-overs).")
@click.option("--plot", "png_path", type=click.Path(dir_okay=False), default=None,
              help="Draw the map in slices of theta, beside the grasp at the start (PNG, PDF or SVG, as the name "
                   "ends); at most six slices, evenly chosen, the one nearest the start's theta among them (the "
                   "title says how many of how many).")
@click.option("--quiet", is_flag=True, help="No progress bar.")
def reach(task_file: str, x_axis, z_axis, theta_axis, time_limit: float, seed, workers, ray_address, json_path,
          png_path, quiet: bool) -> None:
    """Map where the pushers can take the object: plan from the task's start to every goal of a grid.

    Each cell is the task with its goal replaced, planned on its own. Its verdict: `reached`,
    `unreachable` with the reason (decided exactly before any search: no grasp at the goal,
    every pusher excluded by the uncertainty box, no stable push out of the start or
    none into the goal's tolerance, a min_hold_ratio the goal cannot meet, or a pad that would
    have to leave the object on the way), or `not found` within --time-limit. The same seed gives
    the same map, whichever runner plans it. The task's start must have a grasp; its goal need
    not, as the grid replaces it.

    \b
    Example:
      stablepush reach data/tasks/t-shaped.yaml --x -20:20:9 --z -10:10:5 --theta 0:0:1 \\
          --json t.reach.json --plot t.reach.png
    """
    from stablepush.outputs import FIGURE_SUFFIXES, require_suffix, write_atomically
    from stablepush.plan.reach import reach_map
    from stablepush.runners import default_workers

    require_suffix("--plot", png_path, FIGURE_SUFFIXES)
    _check_outputs({"--json": json_path, "--plot": png_path}, {"TASK.yaml": task_file})
    say = _say_beside(json_path, png_path)
    runner = _runner(workers, ray_address, default=default_workers())
    task = _load(task_file, goal_in_grasp=False)  # the grid replaces the goal; its cells say where there is no grasp
    gx, gz, gth = task.goal
    axes = [a if a is not None else (g, g, 1) for a, g in ((x_axis, gx), (z_axis, gz), (theta_axis, gth))]
    count = axes[0][2] * axes[1][2] * axes[2][2]
    if count > 100_000:
        _fail(f"--x, --z, --theta: {count} cells; at most 100000")
    bar = _progressbar(quiet, length=count, label=f"{count} cells", show_pos=True)
    try:
        result = reach_map(task, *axes, seed=task.planner["seed"] if seed is None else seed, time_limit=time_limit,
                           runner=runner, progress=(lambda cell: bar.update(1)) if bar else None)
    finally:
        if bar is not None:
            bar.render_finish()
    data = result.as_dict()
    if json_path:
        write_atomically(json_path, json.dumps(data, indent=1) + "\n")
    if png_path:
        from stablepush.viz.figures import reach_figure, save_figure

        save_figure(reach_figure(task, data), png_path)
    c = data["counts"]
    say(f"{task.name}: {c['reached']} of {count} goals reached, {c['not found']} not found in {time_limit:g} s, "
        f"{c['unreachable']} unreachable ({result.wall_s:.1f} s on {result.runner})")
    written = [p for p in (json_path, png_path) if p]
    if written:
        say(f"written: {', '.join(written)}")


@cli.command("sim-arm")
@click.option("--host", default="127.0.0.1", show_default=True, help="Address to listen on.")
@click.option("--port", default=DEFAULT_PORT, show_default=True, type=click.IntRange(min=0, max=65535),
              help="Port to listen on (0: any free port, printed).")
@click.option("--exit-after", type=click.IntRange(min=1), default=None, metavar="N",
              help="Fault injection for testing executors: die abruptly after N waypoints.")
@click.option("--mu-scale", "mu_scale", default=1.0, show_default=True, type=Finite(min=0.1, max=10),
              metavar="S", help="The pads' and features' mu are S times each task's (a world unlike the model).")
@click.option(
    "--tracker-noise",
    "tracker_noise",
    nargs=2,
    type=Finite(min=0),
    default=(0.0, 0.0),
    metavar="MM DEG",
    help="Standard deviations of the tracker's noise on object_in_grasp (x, z mm; theta deg).",
)
@click.option("--seed", default=0, show_default=True, type=click.IntRange(min=0, max=2**32 - 1),
              help="Seed of the tracker's noise.")
@click.option("--idle-timeout", default=30.0, show_default=True, type=Finite(min=0.1, max=3600), metavar="S",
              help="Drop a client that sends no complete message for S seconds (the arm is stopped).")
@click.option("--engine", default=DEFAULT_ENGINE, show_default=True, type=click.Choice(ENGINES),
              help="The physics engine. mujoco: pads slide with stablepush's own Coulomb friction; drake: Drake's "
                   "contact solver alone decides stick and slip (about half MuJoCo's speed).")
def sim_arm(host: str, port: int, exit_after, mu_scale: float, tracker_noise, seed: int, idle_timeout: float,
            engine: str) -> None:
    """Serve a simulated arm (MuJoCo or Drake) over the arm protocol, until interrupted.

    A 7-joint arm of simple shapes (shipped MJCF) with a parallel-jaw gripper whose pads press with
    the task's grip force; the executor's hello carries the object, the features and the friction.
    One session at a time (a second client is told the arm is busy); each starts from a fresh
    world unless the executor resumes a run (--resume-from). An object outline of more than 64
    vertices is simplified for the simulated world only (the tolerance is logged).
    Joint servos track the streamed waypoints by IK; the simulation steps in lock-step with the stream
    (one waypoint period per waypoint), headless, and reports its steps/s. Each acknowledgement carries
    the object's pose in the grasp as a tracker would (`object_in_grasp`), with --tracker-noise.
    """
    from stablepush.sim.deviation import WorldDeviation
    from stablepush.sim.server import SimArmServer

    deviation = WorldDeviation(mu_scale=mu_scale, tracker_noise_mm=tracker_noise[0], tracker_noise_deg=tracker_noise[1],
                               seed=seed)
    server = SimArmServer(host, port, exit_after=exit_after, deviation=deviation, idle_timeout=idle_timeout,
                          engine=engine)
    click.echo(f"sim-arm: listening on {server.host}:{server.port} ({engine})", err=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.close()


def main() -> None:  # pragma: no cover - console entry
    cli()


if __name__ == "__main__":  # pragma: no cover
    main()
