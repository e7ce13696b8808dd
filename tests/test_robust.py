"""Robust stable pushes (task `uncertainty:`, docs/model.md section 7): the core decides at the 4
corners of (pad mu x grip force, mass) at the smallest pusher mu; checked here against the
independent HiGHS LP (tests/independent_lp.py) sampled over the whole box of pad mu, grip force,
mass and pusher mu, separately (all 16 corners and interior points)."""
import dataclasses
import itertools
import math
import zlib

import numpy as np
import pytest
from test_cross_check import BAND_N, random_queries

from stablepush import _core
from stablepush.errors import TaskError
from stablepush.plan import plan_task
from stablepush.units import pose_to_si

from conftest import task_with
from independent_lp import IndependentModel

UNCERTAINTY = {"pad_mu": 0.1, "pusher_mu": 0.15, "grip_force": 0.1, "mass": 0.05}


def uncertain(name, uncertainty=UNCERTAINTY, **planner):
    def edit(d):
        d["uncertainty"] = dict(uncertainty)
        d.setdefault("planner", {}).update(planner)

    return task_with(name, edit)


def box_samples(task, rng, interior=2):
    """Independent models over the box: the 16 corners of (pad mu, grip force, mass, pusher mu),
    the hardest first, then random interior points."""
    u = task.uncertainty
    span = {k: (1 - u.get(k, 0.0), 1 + u.get(k, 0.0)) for k in ("pad_mu", "grip_force", "mass", "pusher_mu")}
    corners = sorted(itertools.product(*span.values()), key=lambda c: (c[0] * c[1], -c[2], c[3]))
    points = corners + [tuple(rng.uniform(lo, hi) for lo, hi in span.values()) for _ in range(interior)]
    for pad_mu, grip, mass, pusher_mu in points:
        yield IndependentModel(dataclasses.replace(task, uncertainty={}).with_values({
            "gripper.mu": task.gripper.mu * pad_mu, "gripper.grip_force": task.gripper.grip_force * grip,
            "object.mass": task.object.mass * mass, **{f"pushers.{p.name}.mu": p.mu * pusher_mu for p in task.pushers}}))


@pytest.mark.parametrize("name, n", [("horizontal-offset-low-mu", 1000), ("pivoting", 1000)])
def test_corners_agree_with_the_independent_lp_over_the_whole_box(name, n):
    task = uncertain(name)
    corners = task.corner_models
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    references = list(box_samples(task, rng))
    compared = robust = 0
    disagreements = []
    for q, dq, p in random_queries(task, rng, n):
        core = _core.worst_case(corners, q, dq, p)
        if abs(core.margin) <= BAND_N:
            continue
        compared += 1
        robust += core.feasible
        # Stable for every value in the box iff the LP finds it stable at every sample.
        everywhere = all(ref.stable(q, dq, p)[0] for ref in references)
        if core.feasible != everywhere:
            disagreements.append((q, dq, p, core.margin))
    assert not disagreements, disagreements[:5]
    assert compared > 0.95 * n and 0 < robust < compared


def test_the_corners_are_the_box_extremes_by_hand():
    """hold_ratio = 2 mu N / (m g) for the prism held at its centre (docs/model.md section 2): at
    the corners it scales by (1 +- 0.1)^2 / (1 -+ 0.05)."""
    task = uncertain("horizontal-offset-low-mu")
    nominal = task.model.hold_ratio(pose_to_si(task.start), -1)
    ratios = sorted(m.hold_ratio(pose_to_si(task.start), -1) / nominal for m in task.corner_models)
    expected = sorted(f / m for f in (0.9 * 0.9, 1.1 * 1.1) for m in (0.95, 1.05))
    assert ratios == pytest.approx(expected, rel=1e-9)
    assert [p.mu for p in task.corner_models[0].pushers] == pytest.approx([0.2 * 0.85] * 3)


@pytest.mark.parametrize("name", ["horizontal-offset-low-mu", "pivoting", "t-shaped"])
def test_every_push_of_a_robust_plan_is_stable_everywhere_in_the_box(name):
    task = uncertain(name, max_switches=3, time_limit=20)
    plan = plan_task(task, seed=1)
    assert plan.solved, plan.message
    references = list(box_samples(task, np.random.default_rng(7)))
    nominal = task.model
    for a, b in zip(plan.waypoints, plan.waypoints[1:]):
        q0, q1 = pose_to_si((a.x, a.z, a.theta)), pose_to_si((b.x, b.z, b.theta))
        dq = tuple(y - x for x, y in zip(q0, q1))
        p = task.pusher_index(b.pusher)
        assert all(ref.stable(q0, dq, p)[0] for ref in references), (b, p)
        # The reported margin is the least over the corners, never more than the nominal one.
        assert b.margin <= nominal.check(q0, dq, p).margin + 1e-12
        assert b.margin_per_normal is not None and b.margin_per_normal > 0


def test_uncertainty_is_validated():
    with pytest.raises(TaskError, match="uncertainty.pad_mu: must be between 0 and 0.9"):
        uncertain("pivoting", {"pad_mu": 1.5})
    with pytest.raises(TaskError, match="uncertainty.friction: unknown key"):
        uncertain("pivoting", {"friction": 0.1})
    assert len(uncertain("pivoting", {}).corner_models) == 1
    assert math.isclose(uncertain("pivoting", {"mass": 0.2}).corner_models[1].body.mass, 1.2 * 0.202)


def test_a_point_pusher_is_robust_to_its_own_mu_only_and_the_loader_says_so():
    """docs/model.md, "Point pushers and the box": a peg's stable pushes are a surface that moves
    with pad mu x grip force and with mass, so with any width in those no push is stable at every
    corner; a width in pusher mu only narrows the wedge."""
    own = uncertain("more/cube-pegs", {"pusher_mu": 0.15}, time_limit=5)
    assert not any("point pusher" in w for w in own.warnings)
    assert plan_task(own, seed=1).solved
    for key in ("pad_mu", "grip_force", "mass"):
        task = uncertain("more/cube-pegs", {key: 0.01}, time_limit=0.3)
        says = [w for w in task.warnings if f"a point pusher makes no push robust to uncertainty.{key}" in w]
        assert [w.split(" ")[0] for w in says] == ["pushers[0]", "pushers[1]"]
        plan = plan_task(task, seed=1)  # not one push, even at 1%: decided before the search
        assert plan.outcome == "unreachable" and plan.stats["nodes"] == 0 and len(plan.waypoints) == 1
