"""The same seed gives the same outcomes on a quiet machine and on one starved of CPU: every search
inside a run or a study is bounded by a count of stable-push tests (planner.check_limit), wall
time only a guard that is reported when it fires."""
from __future__ import annotations

import multiprocessing
import os
from contextlib import contextmanager

import pytest

from stablepush.evaluation import Batch, Spreads, evaluate
from stablepush.plan import check_plan, plan_task
from stablepush.plan.reach import ReachGrid, reach_map
from stablepush.runners import Runner

from conftest import shipped


def _spin(stop) -> None:
    while not stop.is_set():
        pass


@contextmanager
def cpu_hog(processes: int = 2 * (os.cpu_count() or 2)):
    """Busy loops on every core (twice over) while the block runs."""
    stop = multiprocessing.Event()
    hogs = [multiprocessing.Process(target=_spin, args=(stop,), daemon=True) for _ in range(processes)]
    for p in hogs:
        p.start()
    try:
        yield
    finally:
        stop.set()
        for p in hogs:
            p.join(5)
            if p.is_alive():
                p.kill()


def _cells(result):
    return [(c["goal"], c["verdict"], c["solved"], c["outcome"], c["switches"], c["pushes"], c["guard_fired"])
            for c in result.cells]


@pytest.mark.slow
def test_a_reach_map_bounded_by_tests_is_the_same_under_load():
    """Not-found cells included: their partial paths end where the count stopped the search."""
    task = shipped("large-manipulation")
    grid = ReachGrid(x=(5.0, 15.0, 3), z=(-13.0, -3.0, 3), theta=(45.0, 45.0, 1))
    quiet = reach_map(task, grid, seed=1, time_limit=1000.0, check_limit=2_000)
    with cpu_hog():
        loaded = reach_map(task, grid, seed=1, time_limit=1000.0, check_limit=2_000)
    assert _cells(quiet) == _cells(loaded)
    assert any(c["verdict"] == "not found" for c in quiet.cells) and not quiet.guard_fired()


def _trial(record: dict) -> tuple:
    return (record["trial"], record["success"], record["cause"], record["replans"], record["final_error"],
            record.get("wall_guard"))


@pytest.mark.slow
def test_a_closed_loop_study_is_the_same_under_load():
    """The closed loop's corrections are searches bounded by tests: a study of worlds that need them
    (the low-mu offset, pads' and pushers' mu +-35%) gives the same records on a machine busy with
    twice as many spinning processes as it has cores."""
    task = shipped("horizontal-offset-low-mu")
    plan = check_plan(task, plan_task(task, seed=1))
    spreads = Spreads(vary={"pad_mu": 0.35, "pusher_mu": 0.35}, feature_error=(0.5, 0.5))
    batch = Batch(task=task, plan=plan, spreads=spreads, seed=3, closed_loop=True)
    quiet = evaluate(batch, 2, Runner())
    with cpu_hog():
        loaded = evaluate(batch, 2, Runner())
    assert [_trial(t) for t in quiet.trials] == [_trial(t) for t in loaded.trials]
    assert sum(t["replans"] for t in quiet.trials) > 0  # the corrections were searched for
    assert not quiet.summary()["wall_guard_trials"]


def test_the_closed_loops_searches_are_bounded_by_tests_with_time_as_a_guard(monkeypatch):
    """Every correction's search (the aim before the first push, each re-plan's attempts) carries a
    check_limit, and its time limit is the guard, far past it."""
    from stablepush.execution import closed_loop

    task = shipped("horizontal-offset-low-mu")
    seen = []
    real = closed_loop.plan_task

    def spy(t, **kwargs):
        seen.append((t.planner.tuning.get("check_limit"), t.planner.time_limit))
        return real(t, **kwargs)

    monkeypatch.setattr(closed_loop, "plan_task", spy)
    loop = closed_loop.ClosedLoop.for_task(task)
    closed_loop.replan(task, (3.0, 0.4, 0.5), "bottom", loop, after_step=2, planned=(3.0, 0.0, 0.0))
    assert seen and all(limit in (closed_loop.KEEP_PUSHER_CHECKS, closed_loop.REPLAN_CHECKS) for limit, _ in seen)
    assert all(guard == closed_loop.GUARD_TIME_LIMIT for _, guard in seen)
