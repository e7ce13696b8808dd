"""Cross-check of the core's stable-push test against an independent HiGHS LP (tests/independent_lp.py)
on 11,500 random queries over the paper's tasks, a point-pusher task and one whose pads are apart.

Agreement is required outside a band around the cone boundary: |core margin| > BAND_N.
"""
import math
import zlib

import numpy as np
import pytest

from conftest import shipped, task_with
from independent_lp import IndependentModel

MM = 1e-3
BAND_N = 1e-6  # newtons; decisions closer than this to the cone boundary are not compared


def point_pusher_task():
    def edit(d):
        d["gravity"] = [0, 0]
        d["pushers"] = [{"name": "tip-left", "at": [-50, 0], "mu": 0.6}, {"name": "tip-bottom", "at": [0, -12.5], "mu": 0.6}]

    return task_with("horizontal-offset-low-mu", edit)


def offset_pads_task():
    """Pads at different places with different radii: no pad points coincide (Gripper::sites merges
    only coincident ones)."""
    def edit(d):
        d["gripper"]["pads"] = [{"center": [-8, 0], "radius": 5}, {"center": [6, 2], "radius": 4}]

    return task_with("horizontal-offset-low-mu", edit)


def random_queries(task, rng, n):
    pads = [np.array(c) * MM for c, _ in task.gripper.pads]
    for _ in range(n):
        q = np.array([rng.uniform(-4, 4) * MM, rng.uniform(-4, 4) * MM, math.radians(rng.uniform(-30, 30))])
        kind = rng.random()
        if kind < 0.35:  # rotation about a pad centre: that centre sticks
            w = math.radians(rng.uniform(0.2, 1.5)) * rng.choice([-1, 1])
            arm = pads[rng.integers(len(pads))] - q[:2]
            dq = np.array([-w * arm[1], w * arm[0], w])  # v = -omega x arm
        elif kind < 0.5:  # pure translation
            a = rng.uniform(0, 2 * math.pi)
            dq = np.array([math.cos(a) * MM, math.sin(a) * MM, 0.0])
        else:
            dq = np.array([rng.uniform(-1, 1) * MM, rng.uniform(-1, 1) * MM, math.radians(rng.uniform(-1, 1))])
        yield tuple(q), tuple(dq), int(rng.integers(len(task.pushers)))


CASES = [
    ("horizontal-offset-low-mu", 2000),
    ("horizontal-offset-high-mu", 1500),
    ("pivoting", 2000),
    ("large-manipulation", 1500),
    ("t-shaped", 1500),
    ("point-pushers", 1500),
    ("offset-pads", 1500),
]


@pytest.mark.parametrize("name,n", CASES)
def test_core_agrees_with_independent_lp(name, n):
    built = {"point-pushers": point_pusher_task, "offset-pads": offset_pads_task}
    task = built[name]() if name in built else shipped(name)
    model, reference = task.model, IndependentModel(task)
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    compared = near = sticking = feasible = 0
    disagreements = []
    queries = list(random_queries(task, rng, n))
    if name == "point-pushers":
        # A point pusher's stable pushes are measure-zero among generic motions: add pushes along
        # the left tip's line of action (pad centre on the line), exactly in its wedge's plane.
        for _ in range(100):
            q = (rng.uniform(-4, 4) * MM, 0.0, 0.0)
            queries.append((q, (rng.uniform(0.2, 1.0) * MM, 0.0, 0.0), 0))
    for q, dq, p in queries:
        core = model.check(q, dq, p)
        ref_feasible, ref_s = reference.stable(q, dq, p)
        sticking += core.contact_case.name == "sticking"
        if abs(core.margin) <= BAND_N:
            near += 1
            continue
        compared += 1
        feasible += core.feasible
        if core.feasible != ref_feasible:
            disagreements.append((q, dq, p, core.margin, ref_s))
    assert not disagreements, disagreements[:5]
    # The sample must exercise both cases and both answers.
    assert sticking > 0.2 * n and 0 < feasible < compared
    assert near < 0.01 * n
