"""Point pushers (docs/model.md sections 2 and 3). A peg's cone is a wedge, so with the
pads sliding its stable pushes form a surface in motion space: random motions are never stable,
and the planner finds the surface as a root in the push's rotation."""
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
    model = cube_pegs.build_model()
    assert [c.dimension for c in model.pusher_cones] == [2, 2]
    rng = np.random.default_rng(7)
    for _ in range(2000):
        d = rng.normal(size=3)
        dq = (d[0] * MM, d[1] * MM, math.radians(d[2]))
        assert not any(model.check((0, 0, 0), dq, p).feasible for p in (0, 1))


def test_a_root_of_the_wedge_equation_found_here_is_stable_and_a_turn_off_it_is_not(cube_pegs):
    """The surface found independently of the planner's root finder: bisection on e . w_motion in
    Python, then the core and the independent LP agree the push is stable on it, not off it."""
    model, reference = cube_pegs.build_model(), IndependentModel(cube_pegs)
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
