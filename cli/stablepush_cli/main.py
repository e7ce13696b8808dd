"""`stablepush`: the command group, which turns each StablepushError into one line and its exit
status, and its commands (one module each under commands/). The CLI parses arguments and prints;
every rule lives in the library."""
from __future__ import annotations

import os
import sys
from pathlib import Path

import click

from stablepush.errors import OutputError, StablepushError
from stablepush_cli.commands import (
    bench,
    calibrate,
    check,
    check_cell,
    cone,
    design,
    evaluate,
    execute,
    plan,
    reach,
    show,
    sim_arm,
    trajectory,
)
from stablepush_cli.common import (
    EXIT_INTERNAL,
    EXIT_PIPE_CLOSED,
    EXIT_STATUS,
    OUTPUTS,
)


def _exit_status(error: StablepushError) -> int:
    return next(status for kind, status in EXIT_STATUS if isinstance(error, kind))


def _error_text(ctx: click.Context, error: StablepushError) -> str:
    """The error's message, an output's prefixed with the option that named it (check_named_outputs)."""
    if isinstance(error, OutputError) and error.output is not None:
        for name, path in ctx.meta.get(OUTPUTS, {}).items():
            if Path(path) == Path(error.output) and not str(error).startswith(f"{name} "):
                return f"{name} {error}"
    return str(error)


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
        finally:
            from stablepush.outputs import forget_outputs

            forget_outputs()


@click.group(cls=_Commands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="stablepush")
def cli() -> None:
    """In-hand manipulation planning by stable prehensile pushing.

    A task file (YAML; mm, degrees, grams, newtons) describes the object, the gripper pads, the
    pushers and the goal; see data/tasks/ for the paper's examples and docs/task-files.md for the format.
    """


for command in (bench.bench, calibrate.calibrate, check.check, check_cell.check_cell, cone.cone, design.design,
                evaluate.evaluate, execute.execute, plan.plan, reach.reach, show.show, sim_arm.sim_arm,
                trajectory.trajectory):
    cli.add_command(command)


def main() -> None:  # pragma: no cover - console entry
    cli()


if __name__ == "__main__":  # pragma: no cover
    main()
