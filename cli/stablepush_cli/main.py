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


def main() -> None:  # pragma: no cover - console entry
    cli()


if __name__ == "__main__":  # pragma: no cover
    main()
