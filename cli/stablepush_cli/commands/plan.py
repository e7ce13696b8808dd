"""`stablepush plan`."""
from __future__ import annotations

import sys

import click

from stablepush_cli.common import (
    EXIT_NOT_SOLVED,
    check_named_outputs,
    load_task_file,
    say_beside,
    searching,
)
from stablepush_cli.options import (
    MAX_SWITCHES,
    SEED,
    TIME_LIMIT,
)


@click.command()
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
    from stablepush.plan import end_text, plan_task, release_note, write_plan

    json_label = "-o" if json_path is not None else "the default -o"
    json_path = json_path if json_path is not None else default_output(task_file, ".plan.json")
    check_named_outputs({json_label: json_path, "--csv": csv_path}, {"TASK.yaml": task_file})
    say = say_beside(json_path, csv_path)
    task = load_task_file(task_file)
    limit = time_limit if time_limit is not None else task.planner.time_limit
    with searching(f"{task.name}: searching (time limit {limit:g} s)", limit, quiet):
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
        say("ends " + end_text(s, result.ends_at_goal, task.planner.end_within))
        say(f"plan written to {json_path}" + (f" and {csv_path}" if csv_path else ""))
    note = release_note(task, result)
    if note:
        click.echo(f"note: {note}", err=True)
