"""What every command shares: the exit statuses, failing with one line, loading a task or a plan
with its task, outputs checked before any work, progress on a terminal and batch runners."""
from __future__ import annotations

import contextlib
import sys
import threading
import time
from pathlib import Path

import click

from stablepush.errors import ArmFault, OutputError, PlanError, RunnerError, SettingError, TaskError
from stablepush.extras import MissingExtra
from stablepush.task import load_task

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
    (SettingError, EXIT_BAD_INPUT),
    (MissingExtra, EXIT_BAD_INPUT),  # an optional part of the package that the command needs
    (ArmFault, EXIT_ARM_FAULT),
)


def fail(message: str) -> None:
    click.echo(f"error: {message}", err=True)
    sys.exit(EXIT_BAD_INPUT)


def help_with(**values):
    """Fill the command's docstring's {name} fields before click reads it as the help: what the
    library defines (the causes of a miss, a probe's bounds) is then written once."""
    def fill(command):
        command.__doc__ = command.__doc__.format(**values)
        return command
    return fill


def given(name: str) -> bool:
    """Whether the running command's option `name` was given on the command line (not defaulted)."""
    return click.get_current_context().get_parameter_source(name) is click.core.ParameterSource.COMMANDLINE


OUTPUTS = "stablepush.outputs"  # click's shared Context.meta: the command's outputs, option -> path


def check_named_outputs(outputs: dict, inputs: dict) -> None:
    """stablepush.outputs.check_outputs, remembering the outputs so that one that fails later, while
    written (a full disk, /dev/full), is reported naming its option as well (_Commands)."""
    from stablepush.outputs import check_outputs

    check_outputs(outputs, inputs)
    click.get_current_context().meta[OUTPUTS] = {name: path for name, path in outputs.items() if path is not None}


def load_task_file(task_file: str, goal_in_grasp: bool = True):
    """The task, its warnings printed to stderr (legal, but probably not what was meant)."""
    task = load_task(task_file, goal_in_grasp)
    for warning in task.warnings:
        click.echo(f"warning: {task_file}: {warning}", err=True)
    return task


def say_beside(*outputs):
    """click.echo for a command's own lines, on stderr when one of its outputs is standard output
    itself (`--json /dev/stdout | jq .`), so that the stream holds that file alone."""
    from stablepush.outputs import same_file

    to_stderr = any(path and same_file(path, "/dev/stdout") for path in outputs)
    return lambda text="": click.echo(text, err=to_stderr)


def progressbar(quiet: bool, **options):
    """A progress bar on stderr when it is a terminal, else None: in a pipe click would print each
    new label as a line of its own (a line per trial, per step)."""
    if quiet or not sys.stderr.isatty():
        return None
    return click.progressbar(file=sys.stderr, **options)


def study_spreads(task, vary, feature_error, tracker_noise=(0.0, 0.0)):
    """The worlds a study draws (evaluation.Spreads.for_task), a bad --vary, --feature-error or
    --tracker-noise refused naming the option."""
    from stablepush.evaluation import Spreads

    try:
        return Spreads.for_task(task, vary, feature_error, tracker_noise)
    except SettingError as exc:  # --vary, --feature-error or --tracker-noise past its bound
        fail(f"--{exc.field.replace('_', '-')}: {exc.reason}")


@contextlib.contextmanager
def landings_bar(quiet: bool, trials: int):
    """A progress bar over `trials` simulated trials, labelled with the landings so far; yields
    `landed(done, prefix="", suffix="")`, to call after each trial with the trial records done so
    far (and words before and after the count), or None without a terminal."""
    bar = progressbar(quiet, length=trials, label="trials", show_pos=True)
    if bar is None:
        yield None
        return

    def landed(done, prefix: str = "", suffix: str = "") -> None:
        n = sum(1 for r in done if r["success"])
        bar.label = f"{prefix}landed {n}/{len(done)} ({n / len(done):.0%}){suffix}"
        bar.update(1)

    try:
        yield landed
    finally:
        bar.render_finish()


@contextlib.contextmanager
def searching(label: str, seconds: float, quiet: bool):
    """While the block searches (with the GIL released in the core): from its first second on, a
    bar of the time spent against its limit, on a terminal."""
    done = threading.Event()

    def show() -> None:
        started = time.monotonic()
        if done.wait(1.0):
            return
        length = max(1, round(seconds * 10))
        with click.progressbar(length=length, label=label, file=sys.stderr) as bar:
            while not done.wait(0.1):
                bar.update(min(round((time.monotonic() - started) * 10), length) - bar.pos)

    watcher = None if quiet or not sys.stderr.isatty() else threading.Thread(target=show, daemon=True)
    if watcher is not None:
        watcher.start()
    try:
        yield
    finally:
        done.set()
        if watcher is not None:
            watcher.join()


def runner_for(workers, ray_address, default: int):
    """--workers K | --ray [ADDRESS] as a stablepush.runners.Runner (`default` workers when neither
    is given); both at once exit 2."""
    from stablepush.runners import Runner

    if ray_address is not None and workers is not None:
        fail("--workers and --ray: choose one")
    runner = Runner(workers=workers or default, ray=ray_address is not None, ray_address=ray_address or None,
                    on_wait=lambda line: click.echo(f"\n{line}", err=True))
    if runner.ray:
        from stablepush.runners import probe_ray_head

        probe_ray_head(runner.ray_address)  # before any work: a batch is planned and started only then
    return runner


def load_plan_and_task(plan_file: str, task_file: str, require_solved: bool = True):
    """The task and the plan, once the plan is shown to belong to the task as it is now (check_plan;
    exit 2 if not)."""
    from stablepush.plan import check_plan, load_plan

    task = load_task_file(task_file)
    return task, check_plan(task, load_plan(plan_file), source=plan_file, require_solved=require_solved)


def beside(path: str, endings, suffix: str) -> str:
    """`path` with each of `endings` it ends in taken off, in turn, and `suffix` put on. A path
    that names no file (empty, `.`, `/`) has nothing to put an output beside: exit 2."""
    name = Path(path).name
    if not name:
        fail(f"{path!r:.80} names no file (an output is named after it)")
    for ending in endings:
        if name.lower().endswith(ending) and len(name) > len(ending):
            name = name[: -len(ending)]
    return str(Path(path).with_name(name + suffix))
