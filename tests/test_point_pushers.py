"""Point pushers (docs/model.md sections 2 and 3). A peg's cone is a wedge, so with the
pads sliding its stable pushes form a surface in motion space: random motions are never stable,
and the planner finds the surface as a root in the push's rotation."""
import dataclasses
import math

import numpy as np
import pytest

from stablepush.plan import plan_task
from stablepush.task import load_task

from conftest import TASKS
from independent_lp import IndependentModel
from test_planner import reaches_goal, recheck, unit_steps

MM = 1e-3


@pytest.fixture(scope="module")
def cube_pegs():
    return load_task(TASKS / "more" / "cube-pegs.yaml")


def test_random_motions_are_never_stable_for_a_peg(cube_pegs):
    model = cube_pegs.model
    assert [c.dimension for c in model.pusher_cones] == [2, 2]
    rng = np.random.default_rng(7)
    for _ in range(2000):
        d = rng.normal(size=3)
        dq = (d[0] * MM, d[1] * MM, math.radians(d[2]))
        assert not any(model.check((0, 0, 0), dq, p).feasible for p in (0, 1))


def test_a_root_of_the_wedge_equation_found_here_is_stable_and_a_turn_off_it_is_not(cube_pegs):
    """The surface found independently of the planner's root finder: bisection on e . w_motion in
    Python, then the core and the independent LP agree the push is stable on it, not off it."""
    model, reference = cube_pegs.model, IndependentModel(cube_pegs)
    e = np.array(model.pusher_cones[0].equality_rows[0])
    heading = math.radians(340)

    def motion(beta):
        return (math.cos(beta) * math.cos(heading) * MM, math.cos(beta) * math.sin(heading) * MM,
                math.sin(beta) * math.radians(1))

    def off_plane(beta):
        return float(e @ np.array(model.motion_wrench((0, 0, 0), motion(beta), 0).required))

    lo, hi = math.radians(76), math.radians(78)
    assert off_plane(lo) > 0 > off_plane(hi)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if off_plane(mid) > 0 else (lo, mid)
    on = motion(lo)
    assert model.check((0, 0, 0), on, 0).feasible
    assert reference.stable(np.zeros(3), np.array(on), 0)[0]
    off = (on[0], on[1], on[2] + math.radians(1e-3))
    assert not model.check((0, 0, 0), off, 0).feasible
    assert not reference.stable(np.zeros(3), np.array(off), 0)[0]


def test_a_cube_with_two_pegs_is_solved_on_every_seed_and_every_push_passes_the_independent_lp(cube_pegs):
    for seed in range(1, 11):
        plan = plan_task(cube_pegs, seed=seed)
        assert plan.solved and reaches_goal(cube_pegs, plan), (seed, plan.message)
        unit_steps(cube_pegs, plan)
        recheck(cube_pegs, plan)
        assert {w.pusher for w in plan.waypoints[1:]} <= {"peg-left", "peg-bottom"}


def _generator():
    """benchmarks/point_pusher_tasks.py, the generator of point-pusher tasks nothing was tuned on."""
    import importlib.util

    path = TASKS.parent.parent / "benchmarks" / "point_pusher_tasks.py"
    spec = importlib.util.spec_from_file_location("point_pusher_tasks", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_benchmarks_shifted_goals_move_the_goal_by_the_shift_in_x_and_in_z_alone():
    """point_pusher_tasks.py --shift: the four goals beside a goal, each moved in one of x and z."""
    assert _generator().shifted_goals([-4.534, 4.419, 18.024], 0.1) == [
        ("x+0.1", [-4.434, 4.419, 18.024]),
        ("x-0.1", [-4.634, 4.419, 18.024]),
        ("z+0.1", [-4.534, 4.519, 18.024]),
        ("z-0.1", [-4.534, 4.319, 18.024]),
    ]


@pytest.mark.parametrize("shift", ["0", "-0.1", "inf", "nan", "1e-6"])
def test_the_benchmark_refuses_a_shift_it_cannot_plan_and_names_it(shift):
    """--shift must be finite and at least the goals' rounding (1e-4 mm): below it the shifted goals
    would be the goal itself under another label."""
    import subprocess
    import sys

    script = TASKS.parent.parent / "benchmarks" / "point_pusher_tasks.py"
    done = subprocess.run([sys.executable, str(script), "--shift", shift], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "--shift" in done.stderr, done.stderr


def test_at_the_pegs_plan_end_no_stable_push_moves_the_cube_back_along_x(cube_pegs):
    """stable_directions (`stablepush check --directions`): every push it lists is stable by the
    independent LP, and at the end of the pegs' plan (seed 1, 0.245 unit steps past the goal in x)
    neither peg moves the cube along -x by more than a twentieth of a unit step, and only while
    turning it (+0.99 in theta): an overshoot in x there is beyond any correction (docs/results/engines-cross-engine.md)."""
    from stablepush.task import stable_directions

    reference = IndependentModel(cube_pegs)
    end = plan_task(cube_pegs, seed=1).waypoints[-1].pose
    assert end[0] > cube_pegs.goal[0]
    found = stable_directions(cube_pegs, end)
    q = np.array([end[0] * MM, end[1] * MM, math.radians(end[2])])
    assert found["unit_step"] == [1.0, 1.0] and all(found["pushers"].values())
    for pusher, pushes in enumerate(found["pushers"].values()):
        for push in pushes:
            dq = np.array([push["move"][0] * MM, push["move"][1] * MM, math.radians(push["move"][2])])
            assert reference.stable(q, dq, pusher)[0], (pusher, push)
    largest = found["largest"]
    assert largest["+x"] > 0.5 and largest["-x"] < 0.06
    back = min((p for pushes in found["pushers"].values() for p in pushes), key=lambda p: p["move"][0])
    assert back["move"][2] > 0.95  # the one push with -x turns the cube


def test_generated_point_pusher_tasks_are_solved_and_every_push_passes_the_independent_lp():
    """A small set of the benchmark's generated tasks (boxes and polygons, 2-3 pins, with and
    without gravity), each to a goal the pins reach, on 3 seeds: solved, and every push stable by
    the independent LP. The set is the same on every run (the generator's seed)."""
    generator = _generator()
    tasks = list(generator.generated_tasks(seed=5, count=4, kind="paths"))
    assert len(tasks) >= 3, [t.name for t, _ in tasks]
    assert {len(d["object"]["polygon"]) == 4 for _, d in tasks} == {True, False}  # boxes and polygons
    for task, _ in tasks:
        assert all(p.is_point for p in task.pushers)
        for seed in (1, 2, 3):
            plan = plan_task(task, seed=seed, time_limit=5.0)
            assert plan.solved and reaches_goal(task, plan), (task.name, seed, plan.message)
            unit_steps(task, plan)
            recheck(task, plan)


def test_a_pins_translating_pushes_are_found_between_evenly_spaced_headings():
    """At the start of generated task pins-4-2 (a 7-gon, three pins, goal 5.4 mm and 23 deg away)
    each pin's stable pushes that move the part lie within about 5 deg of one heading, where the
    root's elevation turns from -82 to +81 deg; at 24 evenly spaced headings only near-pure turns
    are found, and plans took 64 k-860 k stable-push tests over seeds 1-5, turning the part back
    and forth. With steps about each pin's translation headings every seed plans within 20 k,
    every push stable by the independent LP."""
    [(task, _)] = _generator().generated_tasks(seed=4, count=3, goals={"pins-4-2": [0.697, -5.389, -23.354]})
    for seed in range(1, 6):
        plan = plan_task(task, seed=seed, time_limit=5.0)
        assert plan.solved and reaches_goal(task, plan), (seed, plan.message)
        assert plan.stats["feasibility_checks"] < 20_000, (seed, plan.stats["feasibility_checks"])
        recheck(task, plan)


def test_a_pin_plan_ends_at_the_goal_pose_by_two_pushes_on_pin_surfaces():
    """No straight push by a pin ends a plan at the goal pose (a pin's stable pushes form a surface
    that rarely passes through it); two pushes on pins' surfaces may (finish_on_wedges in
    planning.cpp). Generated task pins-1-7, with the goal the random-goal benchmark drew for it:
    the plan ends at the goal pose itself, within its switch-over budget, and every push, the two
    last included, passes the independent LP. With planner.finish_steps the plan and its counts are the
    same: its last pin takes no step deeper into the tolerance from where the plan can end at the
    goal pose."""
    from stablepush.plan import check_plan

    generator = _generator()
    [(task, _)] = generator.generated_tasks(seed=1, count=8, goals={"pins-1-7": [7.943, -5.826, -3.109]})
    plan = plan_task(task, seed=1)
    assert plan.solved and plan.ends_at_goal, plan.message
    assert plan.waypoints[-1].pose == pytest.approx(task.goal, abs=1e-9)  # mm, deg (to m, rad and back)
    assert plan.stats["switches"] == sum(a.pusher != b.pusher for a, b in zip(plan.waypoints[1:], plan.waypoints[2:]))
    check_plan(task, plan)  # the switch-over budget, unit steps, each push in the task's own model
    recheck(task, plan)
    finishing = plan_task(dataclasses.replace(task, planner=task.planner.replace(finish_steps=1)), seed=1)
    assert [(w.pose, w.pusher) for w in finishing.waypoints] == [(w.pose, w.pusher) for w in plan.waypoints]
    same = ("switches", "feasibility_checks", "iterations")  # the plan's end is searched once
    assert {k: finishing.stats[k] for k in same} == {k: plan.stats[k] for k in same}


def test_finish_steps_walk_a_pin_plan_to_where_it_can_end_at_the_goal_pose():
    """A plan whose end admits no finish at the goal pose: with planner.finish_steps its last pin
    steps deeper into the tolerance and, at each step, the plan's end is tried again, so that it
    stops where two pushes on pins' surfaces reach the goal pose (generated pins-2-4, seed 3, with
    its benchmark goal). The search's pushes are kept; every push passes the independent LP."""
    from stablepush.plan import check_plan

    [(task, _)] = _generator().generated_tasks(seed=2, count=5, goals={"pins-2-4": [-6.167, -1.082, 8.373]})
    task = dataclasses.replace(task, planner=task.planner.replace(end_within=1.0))  # finish steps alone
    plain = plan_task(task, seed=3)
    assert plain.solved and not plain.ends_at_goal, plain.message
    finishing = dataclasses.replace(task, planner=task.planner.replace(finish_steps=1))
    plan = plan_task(finishing, seed=3)
    assert plan.solved and plan.ends_at_goal, plan.message
    assert plan.waypoints[-1].pose == pytest.approx(task.goal, abs=1e-9)
    head = [(w.pose, w.pusher) for w in plain.waypoints]
    assert [(w.pose, w.pusher) for w in plan.waypoints[:len(head)]] == head
    check_plan(finishing, plan)
    recheck(finishing, plan)


def test_the_generator_is_deterministic_and_its_tasks_are_valid():
    generator = _generator()
    a = [generator.generate_task(9, i) for i in range(6)]
    assert a == [generator.generate_task(9, i) for i in range(6)]
    for data in a:
        pins = data["pushers"]
        assert 2 <= len(pins) <= 3 and all("at" in p and 0.3 <= p["mu"] <= 0.8 for p in pins)
