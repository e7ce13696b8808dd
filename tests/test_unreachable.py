"""Goals decided unreachable before the search (`stablepush.plan.unreachable`): hand-made cases that
are, the bounds' soundness as properties over random poses (never below what the core computes),
the certificate's weak duality, and grids on which every goal called unreachable is also planned,
with the verdict switched off, and never reached."""
import dataclasses
import itertools
import math
import zlib
from fractions import Fraction

import numpy as np
import pytest
import yaml
from scipy.optimize import linprog

from stablepush import _core
from stablepush.frames import direction_in_gripper
from stablepush.plan import search
from stablepush.plan import unreachable as U
from stablepush.plan.search import plan_task
from stablepush.task import parse_task
from stablepush.units import pose_to_si

from conftest import shipped, task_with
from independent_lp import IndependentModel

SHIPPED = ["horizontal-offset-high-mu", "horizontal-offset-low-mu", "large-manipulation", "pivoting", "t-shaped",
           "more/cube-pegs", "more/hexagon-offset", "more/l-bracket-mesh", "more/tilted-gravity", "more/wedge-heel"]

# A 1 kg block held by pads of mu 0.1 at 2 N (0.4 N of friction against 9.8 N of weight), with one
# pusher on its top face: the pusher can only press down, so nothing carries the weight.
UNHELD = """
name: unheld-block
object: {shape: box, size: [40, 20, 40], mass: 1000}
gripper: {grip_force: 2, mu: 0.1, pad_rings: 1}
gravity: [0, -9.81]
pushers:
  - {name: top, from: [-20, 20], to: [20, 20], mu: 0.5}
start: [0, 0, 0]
goal: [0, -5, 0]
planner: {time_limit: 5}
"""

# A 1 kg bar held by pads that carry about half its weight (mu 0.5 at 5 N), over a ledge under its
# right end (x 20 to 45 mm in O). Only pads left of the centre of mass by at least the ledge's
# nearest reach can balance the weight's moment: from the pads at -x in O, the ledge carries the
# bar where x >= about 20 mm, and no push of it ends near x = 0.
LEDGE = """
name: bar-on-a-ledge
object: {shape: box, size: [100, 20, 20], mass: 1000}
gripper: {grip_force: 5, mu: 0.5, pad_rings: 1}
gravity: [0, -9.81]
pushers:
  - {name: ledge, from: [20, -10], to: [45, -10], mu: 0.5}
start: [30, 0, 0]
goal: [0, -4, 0]
planner: {time_limit: 5}
"""


def test_a_goal_no_push_can_end_at_is_unreachable_and_one_beside_the_ledge_is_planned():
    task = parse_task(LEDGE)
    assert task.model.hold_ratio(pose_to_si(task.goal), 0) < 1.0  # the pads alone do not hold it there
    plan = plan_task(task)
    assert plan.outcome == "unreachable" and len(plan.waypoints) == 1, plan.message
    assert "no pusher has a stable push that ends within planner.tolerance of the goal (ledge)" in plan.message
    assert plan.stats["planning_time_s"] < 2.0
    # The start is no dead end: with the ledge under the pads' side of the bar it pushes, and a
    # goal there is reached.
    assert plan_task(dataclasses.replace(task, goal=(30.0, -4.0, 0.0))).solved


def test_verdicts_past_their_deadline_stop_undecided(monkeypatch):
    """The verdicts stop, undecided, once the time they are given (the search's limit) is over: on
    a task of many pushers each test can take seconds. Here the clock passes the deadline after the
    first test, so the ledge's goal, unreachable by verdict 4, is left undecided; given the search's
    0.2 s, the verdicts decide it as before."""
    task = parse_task(LEDGE)
    assert U.why_unreachable(task) is not None
    clock = iter(itertools.count(0.0, 10.0))
    monkeypatch.setattr(U.time, "perf_counter", lambda: next(clock))
    assert U.why_unreachable(task, deadline=5.0) is None
    monkeypatch.undo()
    plan = plan_task(dataclasses.replace(task, planner=task.planner.replace(time_limit=0.2)))
    assert plan.outcome == "unreachable"  # within its time the verdict decides as before


def dumbbell(neck_mm: float, neck_half_length: float = 15.0, start=(30, 0, 0), goal=(-30, 0, 0), pads=None) -> str:
    """Two squares (30 mm for the default neck) joined by a bar `neck_mm` tall and 2
    `neck_half_length` long, held by 5 mm pads (10 mm wide; `pads` as in a task file) in the right
    square, with a goal that puts them in the left one."""
    h, a, e = neck_mm / 2, neck_half_length, neck_half_length + 30
    outline = [[-e, -15], [-a, -15], [-a, -h], [a, -h], [a, -15], [e, -15], [e, 15], [a, 15], [a, h],
               [-a, h], [-a, 15], [-e, 15]]
    gripper = {"grip_force": 10, "mu": 0.5, "pad_rings": 1, **({"pads": pads} if pads else {})}
    return yaml.safe_dump({
        "name": "dumbbell", "object": {"shape": "polygon", "polygon": outline, "thickness": 20, "mass": 100},
        "gripper": gripper, "gravity": [0, -9.81],
        "pushers": [{"name": "left", "from": [-e, -15], "to": [-e, 15], "mu": 0.6},
                    {"name": "right", "from": [e, -15], "to": [e, 15], "mu": 0.6}],
        "start": list(start), "goal": list(goal), "planner": {"time_limit": 5}})


def test_a_goal_the_pads_cannot_slide_to_without_leaving_the_object_is_unreachable(monkeypatch):
    # A 9.9 mm neck: the 10 mm pads cannot pass it. A goal in the same square is planned.
    task = parse_task(dumbbell(9.9))
    plan = plan_task(task)
    assert plan.outcome == "unreachable" and len(plan.waypoints) == 1, plan.message
    assert "gripper.pads[0] (radius 5 mm) would have to leave the object" in plan.message
    assert plan_task(dataclasses.replace(task, goal=(20.0, 0.0, 0.0))).solved
    # A 10.1 mm neck lets them through: no verdict, and the plan crosses.
    assert plan_task(parse_task(dumbbell(10.1))).solved
    # Pads away from G's origin, the part turned at the start and at the goal: the same verdict.
    # A pad centre c in O sits, at theta, where o = p - R(theta) c.
    p, c_start, c_goal = np.array([4.0, 3.0]), (-30.0, 2.0), (30.0, -2.0)
    start = (*(p - direction_in_gripper(25.0, c_start)).tolist(), 25.0)
    goal = (*(p - direction_in_gripper(-20.0, c_goal)).tolist(), -20.0)
    pads = [{"center": p.tolist(), "radius": 5}, {"center": p.tolist(), "radius": 5}]
    turned = parse_task(dumbbell(9.9, start=start, goal=goal, pads=pads))
    assert "would have to leave the object" in U.why_unreachable(turned)
    same_square = (*(p - direction_in_gripper(-20.0, (-25.0, 0.0))).tolist(), -20.0)
    assert U.why_unreachable(dataclasses.replace(turned, goal=same_square)) is None
    # With the verdict off, the search does not cross the 9.9 mm neck either.
    monkeypatch.setattr(search, "why_unreachable", lambda task, deadline=None: None)
    for t in (task, turned):
        for seed in (1, 2):
            assert not plan_task(t, seed=seed, time_limit=1.5).solved


def test_a_goal_whose_tolerance_reaches_back_across_a_short_neck_is_not_called_cut_off():
    # A 9.99 mm neck 0.2 mm long: the goal's own pose puts the pads' centre across it, but a pose
    # within the 1 mm tolerance keeps it in the start's square, and the planner ends there.
    task = parse_task(dumbbell(9.99, neck_half_length=0.1, start=(20, 0, 0), goal=(-0.4, 0, 0)))
    assert U.why_unreachable(task) is None
    assert plan_task(task).solved
    # 5 mm farther, no pose within the tolerance is in the start's square.
    assert "would have to leave" in U.why_unreachable(dataclasses.replace(task, goal=(-5.4, 0.0, 0.0)))


@pytest.mark.parametrize("turn", [200.0, 300.0, 360.0, 720.0])
def test_a_turn_tolerance_past_half_a_turn_never_cuts_a_pad_off(turn):
    """Turned half a turn the dumbbell's pads sit in their start square again, so a tolerance in
    theta past 180 deg lets them end where they start: no turn moves a pad's centre farther than
    twice its distance from the object's origin."""
    task = parse_task(dumbbell(9.9))
    assert U.why_unreachable(task) is not None  # the default tolerance: cut off
    wide = dataclasses.replace(task, planner=task.planner.replace(tolerance=[1.0, turn]))
    assert U.why_unreachable(wide) is None


@pytest.mark.parametrize("name", ["t-shaped", "more/l-bracket-mesh", "dumbbell"])
def test_a_pad_called_off_near_a_goal_is_off_at_every_pose_within_its_tolerance(name):
    """Verdict 6 as a property: goals about the outline's edges (where pads are off, on or across
    it), each with random poses in its tolerance box (its corners among them); a pad the verdict
    calls off is off the object (the core's own test) at every one of them. Some goals must be
    called off and some not, so the test decides both."""
    task = parse_task(dumbbell(9.9)) if name == "dumbbell" else shipped(name)
    task = dataclasses.replace(task, planner=task.planner.replace(tolerance=[2.0, 5.0]))
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    section = task.object.section()
    model = task.corner_models[0]
    called, spared = 0, 0
    scale = np.array([2.0, 2.0, 5.0])  # the tolerance box's half-widths
    corners = np.array(list(itertools.product((-1.0, 1.0), repeat=3)))
    for _ in range(150):
        goal = tuple(rng.uniform(-40.0, 40.0, 2)) + (float(rng.uniform(-30.0, 30.0)),)
        off = U.pads_off_near(task, goal, section)
        called += bool(off)
        spared += len(off) < len(task.gripper.pads)
        if not off:
            continue
        for q in [*(corners * scale), *rng.uniform(-1.0, 1.0, (40, 3)) * scale]:
            pose = np.array(goal) + q
            inside = model.gripper.pads_inside(section, pose_to_si(pose))
            assert not any(inside[k] for k in off), (goal, tuple(pose), off)
    assert called > 10 and spared > 10, (called, spared)


@pytest.mark.parametrize("name", ["t-shaped", "more/l-bracket-mesh", "more/wedge-heel", "dumbbell"])
def test_a_start_and_goal_a_chain_of_grasps_joins_are_never_called_cut_off(name):
    """A property against the core's own grasp test: start and goal at random grasps; wherever a
    chain of grasps 0.25 mm apart (pad centres in O on a grid, the core's grasp_maintained at each)
    joins them, verdict 5 says nothing; on the dumbbell's 9.9 mm neck some pairs are cut off."""
    task = parse_task(dumbbell(9.9)) if name == "dumbbell" else shipped(name)
    model = task.model
    xs = np.array([v[0] for v in task.object.vertices])
    zs = np.array([v[1] for v in task.object.vertices])
    step = 0.25
    gx = np.arange(xs.min(), xs.max() + step, step)
    gz = np.arange(zs.min(), zs.max() + step, step)
    # A pad centre c in O at theta 0 is the pose (-c) for a pad at G's origin (the default pads).
    assert all(tuple(p[0]) == (0.0, 0.0) for p in task.gripper.pads)
    ok = np.array([[model.grasp_maintained(pose_to_si((-x, -z, 0.0))) for z in gz] for x in gx])
    label = np.zeros(ok.shape, int)
    n = 0
    for i, j in zip(*np.nonzero(ok)):  # flood fill, 4-neighbours
        if label[i, j]:
            continue
        n += 1
        stack = [(i, j)]
        label[i, j] = n
        while stack:
            a, b = stack.pop()
            for c, d in ((a + 1, b), (a - 1, b), (a, b + 1), (a, b - 1)):
                if 0 <= c < ok.shape[0] and 0 <= d < ok.shape[1] and ok[c, d] and not label[c, d]:
                    label[c, d] = n
                    stack.append((c, d))
    rng = np.random.default_rng(len(name))
    cells = list(zip(*np.nonzero(ok)))
    cut = 0
    for _ in range(40):
        (i, j), (k, m) = (cells[r] for r in rng.choice(len(cells), 2))
        t = dataclasses.replace(task, start=(-gx[i], -gz[j], 0.0), goal=(-gx[k], -gz[m], 0.0))
        why = U._pad_cut_off(t, model)
        if label[i, j] == label[k, m]:
            assert why is None, (name, t.start, t.goal, why)
        cut += why is not None
    assert (cut > 0) == (name == "dumbbell")


def test_a_goal_the_pads_cannot_hold_within_its_tolerance_is_unreachable_at_once():
    # The high-mu offset's goal: the pads hold 0.908 of the prism's weight there; in the whole
    # 0.5 mm / 0.5 deg box around it, at most 0.942 (the bound). It searched its full time limit.
    task = task_with("horizontal-offset-high-mu", lambda d: d["planner"].update(min_hold_ratio=1.0))
    plan = plan_task(task, time_limit=5)
    assert plan.outcome == "unreachable" and not plan.solved and len(plan.waypoints) == 1
    assert "at most 0.942 times" in plan.message and "min_hold_ratio asks for 1" in plan.message
    assert plan.stats["planning_time_s"] < 1.0 and plan.waypoints[0].pose == task.start
    # Asking for 0.9 leaves it reachable, and the search finds it.
    task = task_with("horizontal-offset-high-mu", lambda d: d["planner"].update(min_hold_ratio=0.9))
    assert plan_task(task).solved


def test_a_start_no_pusher_can_carry_is_unreachable():
    task = parse_task(UNHELD)
    plan = plan_task(task)
    assert plan.outcome == "unreachable", plan.message
    assert "no pusher has a stable push out of the start" in plan.message and "(top)" in plan.message
    # With a pusher under the block, which lifts, the start is no dead end.
    data = yaml.safe_load(UNHELD)
    data["pushers"].append({"name": "floor", "from": [-20, -20], "to": [20, -20], "mu": 0.5})
    assert U.why_unreachable(parse_task(yaml.safe_dump(data))) is None


def test_point_pushers_all_excluded_by_the_box_are_unreachable_and_a_width_in_pusher_mu_is_not():
    task = task_with("more/cube-pegs", lambda d: d.update(uncertainty={"pad_mu": 0.1}))
    plan = plan_task(task)
    assert plan.outcome == "unreachable" and "uncertainty box's pad_mu" in plan.message
    assert U.why_unreachable(task_with("more/cube-pegs", lambda d: d.update(uncertainty={"pusher_mu": 0.1}))) is None


@pytest.mark.parametrize("name", SHIPPED)
def test_the_shipped_tasks_are_not_called_unreachable(name):
    assert U.why_unreachable(shipped(name)) is None


def _random_in_box(rng, goal, tol, n):
    g = np.array(goal, float)
    offsets = rng.uniform(-1.0, 1.0, size=(n, 3)) * np.array([tol[0], tol[0], tol[1]])
    corners = np.array([[sx * tol[0], sz * tol[0], st * tol[1]] for sx in (-1, 1) for sz in (-1, 1) for st in (-1, 1)])
    return g + np.vstack([offsets, corners])


@pytest.mark.parametrize("name", SHIPPED)
def test_the_hold_bound_is_never_below_the_cores_hold_ratio_in_the_box(name):
    """A property over random goals near the task's and random poses in their boxes, every pusher's
    gravity, every corner model: the bound is an upper bound of the core's own hold_ratio."""
    rng = np.random.default_rng(zlib.crc32(name.encode()))  # hash() differs per process
    task = shipped(name)
    for trial in range(4):
        tol = (float(rng.uniform(0.1, 3.0)), float(rng.uniform(0.1, 5.0)))
        goal = tuple(np.array(task.goal) + rng.normal(0.0, [2.0, 2.0, 10.0]))
        t = dataclasses.replace(task, goal=goal, planner=task.planner.replace(tolerance=list(tol)))
        for model in t.corner_models:
            for pusher in range(len(t.pushers)):
                bound = U._hold_bound(t, model, pusher)
                worst = max(model.hold_ratio(pose_to_si(q), pusher) for q in _random_in_box(rng, goal, tol, 40))
                assert bound >= worst, (name, trial, pusher, float(bound), worst)  # exact: Fraction vs float
        # And above the independent LP's (tests/independent_lp.py, HiGHS on polygon vertices).
        independent = IndependentModel(t)
        for pusher in range(len(t.pushers)):
            bound = U._hold_bound(t, t.model, pusher)
            for q in _random_in_box(rng, goal, tol, 5):
                assert bound >= independent.hold_ratio(pose_to_si(q), pusher) - 1e-9, (name, trial, pusher, q)


@pytest.mark.parametrize("name", SHIPPED)
def test_a_start_with_a_stable_push_is_never_called_stuck(name):
    """A property: at random poses (most of them not held by the pads alone), wherever the core
    finds a stable push of a pusher in some random direction, and at the start of every push of
    the task's plan (a point pusher's stable pushes are a surface random directions miss), the LP
    says the pusher may push."""
    rng = np.random.default_rng(7 + len(name))
    task = shipped(name)
    model = task.model
    step = task.planner.step
    sampled = 0  # random poses and directions where the core found a stable push
    for _ in range(30):
        q = pose_to_si(tuple(np.array(task.start) + rng.normal(0.0, [3.0, 3.0, 15.0])))
        if not model.grasp_maintained(q):
            continue
        for pusher in range(len(task.pushers)):
            for _ in range(20):
                d = rng.normal(size=3)
                d /= np.linalg.norm(d)
                dq = _core.Motion(d[0] * step[0] * 1e-3, d[1] * step[0] * 1e-3, math.radians(d[2] * step[1]))
                if model.check(q, dq, pusher).feasible:
                    sampled += 1
                    assert U._may_push(task, model, q, pusher), (name, q, pusher)
                    break
    plan = plan_task(task, seed=1)
    assert plan.solved and len(plan.waypoints) > 1, name  # every push of a plan is a case of the property
    for before, push in zip(plan.waypoints, plan.waypoints[1:]):
        assert U._may_push(task, model, pose_to_si(before.pose), task.pusher_index(push.pusher)), (name, before)
    # Random directions miss a point pusher's surface of stable pushes; every line pusher's cone is
    # met by some of them, so the random cases must have run too.
    assert (sampled > 0) == any(not p.is_point for p in task.pushers), (name, sampled)


# The bar over a ledge under its middle, pads that carry a tenth of its weight, pushed by a moving
# pusher: gravity is fixed in G and turns in O with theta, and past about 30 deg of turn the
# ledge's cone no longer carries it.
CENTRED_LEDGE = (LEDGE.replace("from: [20, -10], to: [45, -10]", "from: [-10, -10], to: [10, -10]")
                 .replace("start: [30, 0, 0]", "start: [0, 0, 0]").replace("grip_force: 5", "grip_force: 1")
                 + "dynamics: {pushes: by_moving_pusher}\n")


@pytest.mark.parametrize("name", SHIPPED + ["ledge", "centred ledge"])
def test_a_box_with_a_stable_push_anywhere_in_it_is_never_called_stuck(name):
    """A property (verdict 4's LP): boxes of random half-widths (up to 10 mm and 20 deg, so that
    some reach across the ledge's edge of support, where the slack decides) about random poses,
    most of them not held by the pads alone; wherever the core or the independent LP (tests/independent_lp.py) finds
    a stable push of a pusher in a random direction from a pose in the box (its corners included),
    the LP over the box says the pusher may push."""
    rng = np.random.default_rng(11 + len(name))
    task = parse_task({"ledge": LEDGE, "centred ledge": CENTRED_LEDGE}[name]) if "ledge" in name else shipped(name)
    model, independent = task.model, IndependentModel(task)
    step = task.planner.step
    found = 0
    for _ in range(12):
        centre = np.array(task.start) + rng.normal(0.0, [12.0, 3.0, 15.0])
        if name == "ledge":  # about the edge of the ledge's support (x about 17 mm)
            centre = np.array([rng.uniform(5.0, 25.0), rng.normal(0.0, 2.0), rng.normal(0.0, 5.0)])
        if name == "centred ledge":  # about the turns past which its cone no longer carries the bar
            centre = np.array([rng.normal(0.0, 3.0), rng.normal(0.0, 2.0), rng.uniform(-60.0, 60.0)])
        half = np.array([rng.uniform(0.2, 10.0), 0.0, rng.uniform(0.2, 20.0)])
        half[1] = half[0]  # the LP's box: the same half-width in x and z
        box = (half[0] * 1e-3, math.radians(half[2]))
        corners = [centre + half * np.array(signs) for signs in itertools.product((-1, 1), repeat=3)]
        poses = [pose_to_si(tuple(q)) for q in [centre, *(centre + rng.uniform(-1, 1, (6, 3)) * half), *corners]]
        for pusher in range(len(task.pushers)):
            stable_somewhere = False
            for q in poses:
                if not model.grasp_maintained(q):
                    continue
                for _ in range(16):
                    d = rng.normal(size=3)
                    d /= np.linalg.norm(d)
                    dq = (d[0] * step[0] * 1e-3, d[1] * step[0] * 1e-3, math.radians(d[2] * step[1]))
                    if model.check(q, _core.Motion(*dq), pusher).feasible or independent.stable(q, dq, pusher)[0]:
                        stable_somewhere = True
                        break
                if stable_somewhere:
                    break
            if stable_somewhere:
                found += 1
                assert U._may_push(task, model, pose_to_si(tuple(centre)), pusher, box), (name, centre, half, pusher)
    # A point pusher's stable pushes are a surface random directions miss: the plan's pushes, each
    # at a random place in a box about its start.
    plan = plan_task(task, seed=1)
    for before, push in zip(plan.waypoints[::4], plan.waypoints[1::4]):
        half = rng.uniform(0.2, 2.0, size=2)
        centre = np.array(before.pose) + rng.uniform(-1, 1, 3) * np.array([half[0], half[0], half[1]])
        box = (half[0] * 1e-3, math.radians(half[1]))
        found += 1
        assert U._may_push(task, model, pose_to_si(tuple(centre)), task.pusher_index(push.pusher), box), (name, before)
    assert found > 0


def test_the_certificate_is_an_upper_bound_for_any_dual_and_tight_for_highs_own():
    rng = np.random.default_rng(3)
    for _ in range(20):
        n, m = 6, 12
        A = rng.normal(size=(m, n))
        b = rng.uniform(0.5, 2.0, size=m)
        c = rng.normal(size=n)
        bounds = [(-3.0, 3.0)] * n
        res = linprog(-c, A_ub=A, b_ub=b, bounds=bounds, method="highs")
        optimum = -res.fun
        bound = U._certified_max(c, A, b, None, None, bounds)
        assert float(bound) >= optimum - 1e-12 and float(bound) <= optimum + 1e-6
        for _ in range(5):  # any y >= 0 bounds it, however poor
            y = rng.uniform(0.0, 1.0, size=m)
            assert U._weak_duality_bound(c, A, b, None, None, bounds, y, np.zeros(0)) >= Fraction(optimum) - Fraction(
                1, 10**9)


GRID_TASKS = [("horizontal-offset-high-mu", 1.0), ("horizontal-offset-low-mu", 1.0), ("more/hexagon-offset", 4.0),
              ("more/tilted-gravity", 1.5), ("t-shaped", 2.2)]


def test_no_goal_the_ledge_cannot_end_at_is_reached_by_a_long_search(monkeypatch):
    """Verdict 4 on a grid of goals along the bar: every goal it calls unreachable is planned again
    with the verdict switched off, 2 seeds x 1.5 s, and none is reached; some goals are called
    unreachable and some are reached."""
    task = parse_task(LEDGE)
    verdicts = {}
    for x in (0.0, 10.0, 20.0, 30.0, 40.0):
        for theta in (-10.0, 0.0, 10.0):
            goal = (x, -4.0, theta)
            verdicts[goal] = U.why_unreachable(dataclasses.replace(task, goal=goal))
    unreachable = [goal for goal, why in verdicts.items() if why is not None]
    assert unreachable and len(unreachable) < len(verdicts), verdicts
    assert plan_task(dataclasses.replace(task, goal=(30.0, -4.0, 0.0))).solved
    monkeypatch.setattr(search, "why_unreachable", lambda task, deadline=None: None)
    for goal in unreachable:
        for seed in (1, 2):
            plan = plan_task(dataclasses.replace(task, goal=goal), seed=seed, time_limit=1.5)
            assert not plan.solved, (goal, verdicts[goal], plan.message)


@pytest.mark.slow
@pytest.mark.parametrize("name, hold", GRID_TASKS)
def test_no_goal_called_unreachable_on_a_grid_is_reached_by_a_long_search(name, hold, monkeypatch):
    """Goals across a grid around the task's, with a hold requirement: each goal the verdict calls
    unreachable is planned again with the verdict switched off for 1.5 s and 2 seeds, and none is
    reached; some cells of each grid are unreachable and some are reached, so the test decides both."""
    task = task_with(name, lambda d: d["planner"].update(min_hold_ratio=hold))
    g = np.array(task.goal)
    verdicts = {}
    for dx in (-8.0, 0.0, 8.0):
        for dth in (-20.0, 0.0, 20.0):
            goal = (g[0] + dx, g[1], g[2] + dth)
            t = dataclasses.replace(task, goal=goal)
            if t.at_goal(t.start):
                continue
            verdicts[goal] = U.why_unreachable(t)
    unreachable = [goal for goal, why in verdicts.items() if why is not None]
    assert unreachable and len(unreachable) < len(verdicts), verdicts
    monkeypatch.setattr(search, "why_unreachable", lambda task, deadline=None: None)
    for goal in unreachable:
        t = dataclasses.replace(task, goal=goal)
        for seed in (1, 2):
            plan = plan_task(t, seed=seed, time_limit=1.5)
            assert not plan.solved, (goal, verdicts[goal], plan.message)
