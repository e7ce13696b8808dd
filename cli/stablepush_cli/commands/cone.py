"""`stablepush cone`."""
from __future__ import annotations

import click

from stablepush_cli.common import (
    check_named_outputs,
    load_task_file,
)


@click.command()
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
    from stablepush.viz import cone_figure, save_figure

    task = load_task_file(task_file)
    task.pusher_index(pusher)
    png_label = "-o" if png_path is not None else "the default -o"
    png_path = png_path if png_path is not None else default_output(task_file, f".{pusher}.cone.png")
    require_suffix(png_label, png_path, FIGURE_SUFFIXES)
    check_named_outputs({png_label: png_path}, {"TASK.yaml": task_file})
    save_figure(cone_figure(task, pusher), png_path)
    click.echo(f"figure written to {png_path}")
