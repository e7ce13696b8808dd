"""Reliability, round three (issue 61): each class of fault found, at its root, with the input that
showed it. Fast: nothing here runs the simulated arm."""
import dataclasses
import time

import pytest

import stablepush as sp
from stablepush.errors import TaskError
from stablepush.plan.files import MAX_WAYPOINTS

from conftest import shipped


def _with_step(task, step):
    return dataclasses.replace(task, planner=task.planner.replace(step=step))


# -- 6. steps too small for a plan file, and the time limit ----------------------------------------

def test_a_step_no_plan_within_the_push_cap_can_take_is_refused_before_the_search():
    """It searched, made 18,001 pushes, spent 11 s past a 2 s limit and was refused by the writer."""
    task = _with_step(shipped("pivoting"), (0.002, 0.005))
    started = time.perf_counter()
    with pytest.raises(TaskError) as caught:
        sp.plan_task(task, time_limit=2)
    assert caught.value.field == "planner.step" and "17,800 pushes" in str(caught.value)
    assert time.perf_counter() - started < 1.0


def test_a_plan_found_longer_than_the_push_cap_is_refused_naming_the_step():
    """The pivot's 90 deg in steps of 0.009 deg: the bound lets it search (9,889 pushes at least),
    the straight plan it finds takes 10,000, one more than a plan file holds."""
    with pytest.raises(TaskError) as caught:
        sp.plan_task(_with_step(shipped("pivoting"), (0.009, 0.009)), time_limit=1)
    assert caught.value.field == "planner.step" and f"{MAX_WAYPOINTS:,} pushes" in str(caught.value)


def test_a_long_plan_is_made_within_its_time_limit_and_written(tmp_path):
    """Making the waypoints copied the core's whole path once per waypoint: quadratic, 7 s of the
    pivot's 18,001 pushes after a search of 0.3 s."""
    started = time.perf_counter()
    plan = sp.plan_task(_with_step(shipped("pivoting"), (0.0091, 0.0091)), time_limit=0.5)
    assert time.perf_counter() - started < 1.5
    assert plan.solved and len(plan.waypoints) > 9_800
    sp.save_plan(plan, str(tmp_path / "long.plan.json"))
    assert len(sp.load_plan(str(tmp_path / "long.plan.json")).waypoints) == len(plan.waypoints)
