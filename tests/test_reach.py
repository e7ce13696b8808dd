"""`stablepush reach` (stablepush.plan.reach): a map of the goals the pushers can reach from the
start. The same seed gives the same map on every runner; an `unreachable` verdict is never given
to a goal that a plan reaches (each one is planned again with a long limit), and every `reached`
cell's plan passes the task's own check."""
import dataclasses
import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from stablepush.errors import TaskError
from stablepush.plan import check_plan, plan_task, search
from stablepush.plan.reach import ReachGrid, ReachJob, axis_values, reach_cell, reach_map
from stablepush.runners import Runner
from stablepush_cli.main import cli

from conftest import TASKS, shipped, task_with

GRID = ReachGrid(x=(-30.0, 30.0, 5), z=(-15.0, 15.0, 3), theta=(-20.0, 20.0, 2))


def _verdicts(result):
    """Each cell's verdict and plan; for a `not found` cell not its partial path, which is where the
    time limit stopped the search (reach's docstring)."""
    return [(c["goal"], c["verdict"], c["solved"], c["outcome"],
             *((c["switches"], c["pushes"]) if c["verdict"] != "not found" else ())) for c in result.cells]


def test_the_same_seed_gives_the_same_map_here_and_on_workers():
    task = shipped("t-shaped")
    here = reach_map(task, GRID, seed=3, time_limit=0.3)
    workers = reach_map(task, GRID, seed=3, time_limit=0.3, runner=Runner(workers=2))
    assert _verdicts(here) == _verdicts(workers)
    assert len(here.cells) == 30 and {c["verdict"] for c in here.cells} >= {"reached", "unreachable"}


def test_unreachable_verdicts_are_sound_and_reached_plans_check(monkeypatch):
    """Each cell called unreachable is planned again for 1 s with the planner's verdicts switched
    off (else they would only repeat themselves) and not reached."""
    task = shipped("t-shaped")
    result = reach_map(task, GRID, seed=1, time_limit=0.3)
    monkeypatch.setattr(search, "why_unreachable", lambda task, deadline=None: None)
    for cell in result.cells:
        cell_task = dataclasses.replace(task, goal=tuple(cell["goal"]))
        if cell["verdict"] == "unreachable":
            assert "no grasp" in cell["reason"]
            long = plan_task(cell_task, seed=1, time_limit=1.0)
            assert not long.solved, cell
        elif cell["verdict"] == "reached" and cell["pushes"]:
            check_plan(cell_task, plan_task(cell_task, seed=1, time_limit=0.3))


def test_a_goal_whose_pose_has_no_grasp_but_whose_tolerance_has_one_is_planned():
    """On the T, the goal (5.5, 5, 0) puts the pads across the stem's edge, but (4.9, 5, 0), within
    its 1 mm tolerance, holds them: a plan can reach it, so its cell is planned, not called
    unreachable; (8, 5, 0) is farther off than the tolerance reaches."""
    task = shipped("t-shaped")
    job = ReachJob(task=task, goals=[(5.5, 5.0, 0.0), (8.0, 5.0, 0.0)], seed=1, time_limit=2.0)
    near, far = reach_cell(job, 0), reach_cell(job, 1)
    assert near["verdict"] == "reached", near
    check_plan(dataclasses.replace(task, goal=(5.5, 5.0, 0.0)),
               plan_task(dataclasses.replace(task, goal=(5.5, 5.0, 0.0)), seed=1, time_limit=2.0))
    assert far["verdict"] == "unreachable" and "no grasp there" in far["reason"], far


def test_a_goal_at_the_start_is_reached_with_no_push():
    task = shipped("pivoting")
    job = ReachJob(task=task, goals=(tuple(task.start),), seed=1, time_limit=0.1)
    cell = reach_cell(job, 0)
    assert cell["verdict"] == "reached" and cell["pushes"] == 0 and cell["outcome"] == "at_start"


def test_a_goal_at_the_start_the_pads_do_not_hold_as_asked_is_not_reached():
    # 2 N of grip hold the offset bar 0.86 times its weight at the start.
    def weak(d, need):
        d["gripper"]["grip_force"] = 2.0
        d["planner"]["min_hold_ratio"] = need
    task = task_with("horizontal-offset-high-mu", lambda d: weak(d, 1.0))
    job = ReachJob(task=task, goals=(tuple(task.start),), seed=1, time_limit=0.1)
    cell = reach_cell(job, 0)
    assert cell["verdict"] == "unreachable" and "min_hold_ratio" in cell["reason"] and not cell["solved"]
    # 0.86 asked: the start falls short, but somewhere within the tolerance the bound (0.865) does not.
    cell = reach_cell(dataclasses.replace(job, task=task_with("horizontal-offset-high-mu", lambda d: weak(d, 0.86))), 0)
    assert cell["verdict"] == "not found" and cell["outcome"] == "at_start" and not cell["solved"]
    held = reach_cell(dataclasses.replace(job, task=task_with("horizontal-offset-high-mu", lambda d: weak(d, 0.85))), 0)
    assert held["verdict"] == "reached" and held["pushes"] == 0


def test_reach_cli_writes_the_map_and_refuses_a_bad_axis(tmp_path):
    out, png = tmp_path / "r.json", tmp_path / "r.png"
    task = str(TASKS / "pivoting.yaml")
    result = CliRunner().invoke(cli, ["reach", task, "--theta", "0:90:4", "--time-limit", "0.2", "--workers", "1",
                                      "--json", str(out), "--plot", str(png), "--quiet"])
    assert result.exit_code == 0, result.output
    data = json.loads(out.read_text())
    assert len(data["cells"]) == 4 and data["counts"]["reached"] >= 1
    assert png.read_bytes()[:4] == b"\x89PNG"
    bad = CliRunner().invoke(cli, ["reach", task, "--x", "1:2"])
    assert bad.exit_code == 2 and "FROM:TO:COUNT" in bad.output
    # The library's own checks of an axis, named as the option and with click's usage line.
    bad = CliRunner().invoke(cli, ["reach", task, "--x", "5:5:3"])
    assert bad.exit_code == 2 and "Invalid value for '--x'" in bad.output and "from and to are both 5" in bad.output
    assert "x_axis[2]" not in bad.output


def test_reach_maps_a_task_whose_own_goal_has_no_grasp(tmp_path):
    """The grid replaces the goal, so a task whose goal lies off the grasp is mapped, its cells
    judged on their own; `plan` still refuses that task, naming the goal."""
    from conftest import task_text

    task = tmp_path / "far.yaml"
    task.write_text(task_text("horizontal-offset-low-mu").replace("goal: [20, 0, 0]", "goal: [500, 0, 0]"))
    assert "goal: [500, 0, 0]" in task.read_text()
    out = tmp_path / "r.json"
    result = CliRunner().invoke(cli, ["reach", str(task), "--x", "0:500:2", "--z", "0:0:1", "--theta", "0:0:1",
                                      "--time-limit", "0.2", "--workers", "1", "--json", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    near, far = json.loads(out.read_text())["cells"]
    assert near["verdict"] == "reached" and far["verdict"] == "unreachable" and "no grasp" in far["reason"]
    refused = CliRunner().invoke(cli, ["plan", str(task), "-o", str(tmp_path / "p.json")])
    assert refused.exit_code == 2 and "goal:" in refused.stderr


def test_an_axis_of_finite_ends_has_finite_values_and_its_ends_exact():
    """Evenly spaced from one end to the other, where the span itself overflows too (`reach --x
    1e308:-1e308:3` was an internal error, a goal of nan); the command now refuses an axis past
    the task file's pose bounds, naming the option."""
    assert axis_values((-30.0, 30.0, 7)) == [-30.0, -20.0, -10.0, 0.0, 10.0, 20.0, 30.0]
    assert axis_values((5.0, 9.0, 1)) == [5.0]
    for start, stop in ((1.7e308, -1.7e308), (-1.7e308, 1.7e308), (1e308, 1.5e308)):
        values = axis_values((start, stop, 5))
        assert values[0] == start and values[-1] == stop and all(map(math.isfinite, values))
        steps = [b - a for a, b in zip(values, values[1:])]
        assert all((s > 0) == (stop > start) for s in steps)
    huge = CliRunner().invoke(cli, ["reach", str(TASKS / "pivoting.yaml"), "--x", "1e308:-1e308:3", "--time-limit",
                                    "0.05", "--workers", "1", "--quiet"])
    assert huge.exit_code == 2 and "--x" in huge.output and "from -10000 to 10000" in huge.output, huge.output


def test_show_draws_a_plan_that_found_no_push_and_marks_the_goal(tmp_path):
    """An unsolved plan with the start alone (a goal no push leads toward) is drawn, not refused."""
    from stablepush import save_plan

    task = shipped("horizontal-offset-low-mu")
    plan = plan_task(task, seed=1)
    start_only = dataclasses.replace(plan, waypoints=plan.waypoints[:1], solved=False, outcome="time_limit")
    path, png = tmp_path / "none.plan.json", tmp_path / "none.png"
    save_plan(start_only, str(path))
    result = CliRunner().invoke(cli, ["show", str(path), "--task", str(TASKS / "horizontal-offset-low-mu.yaml"),
                                      "-o", str(png)])
    assert result.exit_code == 0, result.output
    assert png.read_bytes()[:4] == b"\x89PNG"
    # One panel (nothing moves, so no pose against step), the goal's outline on it, and the title
    # within the figure.
    from stablepush.viz.figures import plan_figure

    fig = plan_figure(task, start_only)
    [ax] = fig.axes
    assert ax.get_title().startswith("start, no push found") and any(
        line.get_color() == "tab:red" and line.get_linestyle() == "--" for line in ax.get_lines())
    fig.canvas.draw()
    box = fig._suptitle.get_window_extent()
    assert 0 <= box.x0 and box.x1 <= fig.bbox.x1, (box, fig.bbox)
    with_push = CliRunner().invoke(cli, ["execute", str(path), "--task", str(TASKS / "horizontal-offset-low-mu.yaml"),
                                         "--sim"])
    assert with_push.exit_code == 2 and "solved" in with_push.output  # running it is still refused


def test_the_library_refuses_a_bad_grid_naming_the_axis_before_any_cell():
    """ReachGrid checks its axes and reach_map its seed and time limit as the CLI does: a count that
    is not a whole number, a bound past the task file's pose bounds, a seed or time limit out of the
    planner's ranges, a count of 1 with two ends or equal ends with a larger count are refused with
    the argument named, and the map records the axes it planned."""
    task = shipped("pivoting")
    x, z = (0.0, 0.0, 1), (0.0, 0.0, 1)
    bad = {r"x\[1\]": dict(x=(0.0, math.nan, 2)), "x: must be \\(from, to, count\\)": dict(x=(0.0, 10.0)),
           "x: must be": dict(x=np.array(5.0)),
           r"x\[2\]": dict(x=(0.0, 10.0, 2.7)), r"theta\[0\]": dict(theta=(1e5, 1e5, 1)),
           r"z\[2\]": dict(z=(0.0, 1.0, 0)), "seed": dict(seed=-1), "time_limit": dict(time_limit=0.0),
           r"x\[2\]: a count of 1 takes from \(0\) alone": dict(x=(0.0, 10.0, 1)),
           r"z\[2\]: from and to are both 5": dict(z=(5.0, 5.0, 3))}
    for field, change in bad.items():
        arguments = {"x": x, "z": z, "theta": (0.0, 0.0, 1), "seed": 1, "time_limit": 0.1, **change}
        with pytest.raises(TaskError, match=field):
            grid = ReachGrid(arguments.pop("x"), arguments.pop("z"), arguments.pop("theta"))
            reach_map(task, grid, **arguments)
    with pytest.raises(TypeError, match="grid must be a ReachGrid"):
        reach_map(task, (x, z, (0.0, 0.0, 1)))
    result = reach_map(task, ReachGrid(x=np.array([0.0, 0.0, 1.0]), z=z, theta=(0.0, 90.0, np.int64(2))),
                       time_limit=0.1)
    assert result.axes["theta"] == [0.0, 90.0, 2] and type(result.axes["theta"][2]) is int
    assert result.axes["x"] == [0.0, 0.0, 1] and len(result.cells) == 2


def test_the_figure_draws_the_slice_of_the_start_and_says_how_many_it_leaves_out():
    from stablepush.viz.figures import reach_figure

    task = shipped("t-shaped")  # start theta 0
    cells = [{"goal": [0.0, 3.0, float(theta)], "verdict": "reached"} for theta in range(-3, 4)]
    reach = {"task": task.name, "start": list(task.start), "cells": cells, "seed": 1, "time_limit_s": 0.2,
             "counts": {"reached": 7, "not found": 0, "unreachable": 0}}
    fig = reach_figure(task, reach)
    titles = [ax.get_title() for ax in fig.axes[1:]]
    assert len(titles) == 6 and "goal theta 0 deg" in titles
    assert any("6 of 7 theta slices drawn" in text.get_text() for text in fig.texts)
    reach["cells"] = cells[:6]
    assert not any("slices drawn" in text.get_text() for text in reach_figure(task, reach).texts)
