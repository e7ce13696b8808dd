"""`stablepush show`."""
from __future__ import annotations

import click

from stablepush_cli.common import (
    beside,
    check_named_outputs,
)
from stablepush_cli.groups import PlanFiles, plan_and_task


@click.command()
@plan_and_task()
@click.option("-o", "--output", "png_path", type=click.Path(dir_okay=False), default=None,
              help="Figure to write: PNG, PDF or SVG, as the name ends. Default: PLAN.png beside the plan file "
                   "(t.plan.json: t.png; run.2.json: run.2.png).")
@click.option("--gif", "gif_path", type=click.Path(dir_okay=False), default=None, help="Also write an animated GIF.")
def show(files: PlanFiles, png_path, gif_path) -> None:
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
    from stablepush.viz import plan_figure, save_figure, save_plan_gif

    png_label = "-o" if png_path is not None else "the default -o"
    png_path = png_path if png_path is not None else beside(files.plan_file, (".json", ".plan"), ".png")
    require_suffix(png_label, png_path, FIGURE_SUFFIXES)
    require_suffix("--gif", gif_path, (".gif",))
    check_named_outputs({png_label: png_path, "--gif": gif_path}, files.inputs())
    task, plan = files.load(require_solved=False)
    save_figure(plan_figure(task, plan), png_path)
    click.echo(f"figure written to {png_path}")
    if gif_path:
        save_plan_gif(task, plan, gif_path)
        click.echo(f"animation written to {gif_path}")
