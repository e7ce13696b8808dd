"""`stablepush reach`."""
from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import click

from stablepush_cli.common import (
    check_named_outputs,
    load_task_file,
    progressbar,
    say_beside,
)
from stablepush_cli.groups import RunnerChoice, option_group, runner_choice
from stablepush_cli.options import (
    SEED,
    TIME_LIMIT,
    Whole,
    parse_axis,
)

Axis = Tuple[float, float, int]


@dataclass(frozen=True)
class GoalAxes:
    """--x, --z, --theta: the grid's axes (from, to, count), each None for the task's goal alone."""

    x_axis: Optional[Axis]
    z_axis: Optional[Axis]
    theta_axis: Optional[Axis]

    def grid(self, goal: Sequence[float]):
        """The grid (stablepush.plan.ReachGrid), an axis not given the goal's value alone."""
        from stablepush.plan import ReachGrid

        axes = (self.x_axis, self.z_axis, self.theta_axis)
        return ReachGrid(*(a if a is not None else (g, g, 1) for a, g in zip(axes, goal)))


@dataclass(frozen=True)
class CellSearch:
    """--checks, --time-limit, --seed: each cell's search, bounded by a count of tests, then a time."""

    check_limit: int
    time_limit: float
    seed: Optional[int]


@click.command()
@click.argument("task_file", metavar="TASK.yaml", type=click.Path(dir_okay=False))
@option_group(
    "axes", GoalAxes,
    click.option("--x", "x_axis", callback=parse_axis, default=None, metavar="A:B:N",
                 help="Goal x values, mm: N from A to B (default: the task's goal x alone)."),
    click.option("--z", "z_axis", callback=parse_axis, default=None, metavar="A:B:N",
                 help="Goal z values, mm (likewise)."),
    click.option("--theta", "theta_axis", callback=parse_axis, default=None, metavar="A:B:N",
                 help="Goal theta values, deg (likewise)."))
@option_group(
    "search", CellSearch,
    click.option("--checks", "check_limit", default=1_000_000, show_default=True, type=Whole(min=0, max=10**15),
                 metavar="N", help="Stable-push tests each cell's search may make: a count, so the map is the same "
                                   "on any machine under any load (0: --time-limit alone bounds it)."),
    click.option("--time-limit", default=10.0, show_default=True, type=TIME_LIMIT,
                 metavar="S", help="Each cell's search time, a guard past --checks: a cell it stops is counted in the "
                                   "summary (its verdict may differ on a less loaded machine)."),
    click.option("--seed", default=None, type=SEED, help="Planner seed (default: the task's)."))
@runner_choice("the cells' plans")
@click.option("--json", "json_path", type=click.Path(dir_okay=False), default=None,
              help="Write the map: its cells (goal, verdict, reason, solved, seed, planning time, switch-overs).")
@click.option("--plot", "png_path", type=click.Path(dir_okay=False), default=None,
              help="Draw the map in slices of theta, beside the grasp at the start (PNG, PDF or SVG, as the name "
                   "ends); at most six slices, evenly chosen, the one nearest the start's theta among them (the "
                   "title says how many of how many).")
@click.option("--quiet", is_flag=True, help="No progress bar.")
def reach(task_file: str, axes: GoalAxes, search: CellSearch, where: RunnerChoice, json_path, png_path,
          quiet: bool) -> None:
    """Map where the pushers can take the object: plan from the task's start to every goal of a grid.

    Each cell is the task with its goal replaced, planned on its own. Its verdict: `reached`,
    `unreachable` with the reason (decided exactly before any search: no grasp at the goal,
    every pusher excluded by the uncertainty box, no stable push out of the start or
    none into the goal's tolerance, a min_hold_ratio the goal cannot meet, or a pad that would
    have to leave the object on the way), or `not found` within --checks (or --time-limit). The
    same seed gives the same map, whichever runner plans it. The task's start must have a grasp; its goal need
    not, as the grid replaces it.

    \b
    Example:
      stablepush reach data/tasks/t-shaped.yaml --x -20:20:9 --z -10:10:5 --theta 0:0:1 \\
          --json t.reach.json --plot t.reach.png
    """
    from stablepush.outputs import FIGURE_SUFFIXES, require_suffix, write_atomically
    from stablepush.plan import reach_map
    from stablepush.runners import default_workers

    require_suffix("--plot", png_path, FIGURE_SUFFIXES)
    check_named_outputs({"--json": json_path, "--plot": png_path}, {"TASK.yaml": task_file})
    say = say_beside(json_path, png_path)
    runner = where.runner(default=default_workers())
    # The grid replaces the goal; its cells say where there is no grasp.
    task = load_task_file(task_file, goal_in_grasp=False)
    grid = axes.grid(task.goal)
    count = grid.cells
    bar = progressbar(quiet, length=count, label=f"{count} cells", show_pos=True)
    try:
        result = reach_map(task, grid, seed=task.planner.seed if search.seed is None else search.seed,
                           time_limit=search.time_limit, check_limit=search.check_limit, runner=runner,
                           progress=(lambda cell: bar.update(1)) if bar else None)
    finally:
        if bar is not None:
            bar.render_finish()
    data = result.as_dict()
    if json_path is not None:
        write_atomically(json_path, json.dumps(data, indent=1) + "\n")
    if png_path is not None:
        from stablepush.viz import reach_figure, save_figure

        save_figure(reach_figure(task, data), png_path)
    c = data["counts"]
    check_limit, time_limit = search.check_limit, search.time_limit
    bound = f"{check_limit:,} tests" if check_limit else f"{time_limit:g} s"
    say(f"{task.name}: {c['reached']} of {count} goals reached, {c['not found']} not found in {bound}, "
        f"{c['unreachable']} unreachable ({result.wall_s:.1f} s on {result.runner})")
    if data["guard_fired"]:
        click.echo(f"warning: {data['guard_fired']} cell(s) stopped at --time-limit {time_limit:g} s before their "
                   f"{check_limit:,} tests: their verdict may differ on a less loaded machine", err=True)
    written = [p for p in (json_path, png_path) if p]
    if written:
        say(f"written: {', '.join(written)}")
