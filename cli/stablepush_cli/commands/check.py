"""`stablepush check`."""
from __future__ import annotations

import json

import click

from stablepush.task import HEADING_STEP_DEG, check_push, stable_directions
from stablepush_cli.common import (
    given,
    load_task_file,
)
from stablepush_cli.options import (
    Finite,
    Real,
)


@click.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@click.option("--at", "at", nargs=3, type=Real(), default=None, metavar="X Z TH",
              help="Object pose in the grasp: x mm, z mm, theta deg. Default: the task's start.")
@click.option("--move", nargs=3, type=Real(), default=None, metavar="DX DZ DTH",
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
def check(task_file: str, at, move, directions: bool, heading_step: float, pusher,
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
    if not directions and given("heading_step"):
        raise click.UsageError("--heading-step: only with --directions")
    task = load_task_file(task_file)
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
