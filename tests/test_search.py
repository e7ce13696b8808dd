"""TRRTstar tested apart from the mechanics: the search asks a PushChecker
which pushers make a motion stable, so a toy rule can stand in for the model, OMPL-style.

The toy: two pushers, each able to move the object only within a narrow cone of directions in
unit steps, pusher 0 along +x and pusher 1 along +z. A goal up and to the right needs both, so
one switch-over; with no switch-over allowed it is out of reach."""
import math

import pytest

from stablepush import _core

MM, DEG = 1e-3, math.radians(1)
STEP = (1 * MM, DEG)


def unit(a, b):
    """b - a in unit steps."""
    return ((b[0] - a[0]) / STEP[0], (b[1] - a[1]) / STEP[0], (b[2] - a[2]) / STEP[1])


class ConeChecker(_core.PushChecker):
    AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))  # pusher 0: +x, pusher 1: +z
    COS = (0.9, 0.9)  # a motion is stable for pusher p when within acos(COS[p]) (26 deg) of its axis

    def __init__(self):
        super().__init__()
        self.calls = 0
        self.asked = []  # the candidate set of each call
        self.stable = set()  # (a, b, pusher) of every motion this checker answered stable

    def alignment(self, a, b, pusher):
        d = unit(a, b)
        n = math.sqrt(sum(c * c for c in d))
        return sum(c * e for c, e in zip(d, self.AXES[pusher])) / n if n > 0 else -1.0

    def all_pushers(self):
        return 0b11

    def stable_pushers(self, a, b, candidates):
        self.calls += 1
        self.asked.append(candidates)
        stable = [p for p in (0, 1) if candidates >> p & 1 and self.alignment(a, b, p) >= self.COS[p]]
        self.stable.update((tuple(a), tuple(b), p) for p in stable)
        return sum(1 << p for p in stable)

    def push_margin(self, a, b, pusher):
        return self.alignment(a, b, pusher) - self.COS[pusher]


def path_of(out):
    """The path of a CheckedPlan as ((x, z, theta), pusher) pairs, start first."""
    return [(tuple(node.pose), node.pusher) for node in out.path]


def plan(checker, goal, time_limit=5.0, **parameters):
    settings = _core.PlannerSettings(start=(0.0, 0.0, 0.0), goal=goal, step=STEP, tolerance=(0.5 * MM, 0.5 * DEG),
                                     time_limit=time_limit, parameters={k: str(v) for k, v in parameters.items()})
    return _core.plan_with_checker(checker, settings)


def test_a_goal_that_needs_both_toy_pushers_takes_one_switch_over_and_every_edge_obeys_the_toy():
    checker = ConeChecker()
    out = plan(checker, (6 * MM, 6 * MM, 0.0), max_switches=1, seed=3)
    assert out.outcome == _core.PlanOutcome.goal_reached
    path = path_of(out)
    assert path[0] == ((0.0, 0.0, 0.0), -1)
    pushers = [p for _, p in path[1:]]
    switches = sum(1 for p, q in zip(pushers, pushers[1:]) if p != q)
    assert switches == out.cost.switches == 1 and set(pushers) == {0, 1}
    for (a, _), (b, pusher) in zip(path, path[1:]):
        assert ConeChecker().alignment(a, b, pusher) >= ConeChecker.COS[pusher]  # the rule the search was given
    end = path[-1][0]
    assert abs(end[0] - 6 * MM) <= 0.5 * MM and abs(end[1] - 6 * MM) <= 0.5 * MM
    # every edge of the path is a motion this checker itself answered stable for that pusher
    assert all((tuple(a), tuple(b), pusher) in checker.stable for (a, _), (b, pusher) in zip(path, path[1:]))


def test_with_no_switch_over_allowed_the_toy_goal_is_out_of_reach():
    out = plan(ConeChecker(), (6 * MM, 6 * MM, 0.0), time_limit=1.0, max_switches=0, seed=3)
    assert out.outcome in (_core.PlanOutcome.goal_over_switch_limit, _core.PlanOutcome.time_limit)
    assert out.outcome != _core.PlanOutcome.goal_reached


def test_a_goal_along_one_toy_pusher_takes_no_switch_over_and_the_same_seed_the_same_path():
    first = plan(ConeChecker(), (8 * MM, 1 * MM, 0.0), seed=5)
    again = plan(ConeChecker(), (8 * MM, 1 * MM, 0.0), seed=5)
    assert first.outcome == _core.PlanOutcome.goal_reached and first.cost.switches == 0
    assert {p for _, p in path_of(first)[1:]} == {0}
    assert path_of(first) == path_of(again)


def test_a_descent_asks_for_its_own_pusher_first_and_for_no_other_while_it_works():
    """Toward a goal along +x every descent goes on with pusher 0; only pushes from the start,
    where no pusher is the descent's own yet, ask for both."""
    checker = ConeChecker()
    out = plan(checker, (12 * MM, 0.0, 0.0), goal_bias=1.0, seed=2)
    assert out.outcome == _core.PlanOutcome.goal_reached and {p for _, p in path_of(out)[1:]} == {0}
    assert checker.asked.count(0b01) >= 11  # each push after the first asks for pusher 0 alone
    assert 0b10 not in checker.asked and checker.asked.count(0b11) <= 3


class LiftDragChecker(ConeChecker):
    """The low-friction offset in miniature: pusher 0 is a ledge that lifts (+z within 26 deg);
    pusher 1 drags along x only while sliding down, 2-18 deg below the horizontal, so a drag of
    20 mm alone ends 0.7-6.5 mm low. A goal 20 mm along x within 0.5 mm needs the lift."""

    AXES = ((0.0, 1.0, 0.0), (math.cos(math.radians(-10)), math.sin(math.radians(-10)), 0.0))
    COS = (0.9, 0.99)


def test_a_pusher_that_can_only_push_across_the_way_to_the_goal_gets_a_run_across_from_the_start():
    """No descent tries the ledge (every step it makes turns more than steer_angle, 45 deg, from
    the goal), so before the start's run across, random extensions found the lift only by chance:
    569-5,961 checker calls on seeds 2-10. Now the start's first push is the ledge's, turned 67.5
    deg, and the plan takes a few hundred calls."""
    for seed in range(1, 6):
        checker = LiftDragChecker()
        out = plan(checker, (20 * MM, 0.0, 0.0), max_switches=1, seed=seed)
        assert out.outcome == _core.PlanOutcome.goal_reached
        (start, _), (first, pusher) = path_of(out)[:2]
        d = unit(start, first)
        turned = math.degrees(math.acos(d[0] / math.sqrt(sum(c * c for c in d))))
        assert pusher == 0 and 45.0 < turned <= 90.0
        assert checker.calls < 1000
        for (a, _), (b, p) in zip(path_of(out), path_of(out)[1:]):
            assert checker.alignment(a, b, p) >= checker.COS[p]


class AskewChecker(ConeChecker):
    """Pusher 0 makes a motion stable only 5-30 deg off the straight way to the goal, so each step
    that ends a descent lands a fifth as far from the goal as it started (a ring-1 turn)."""

    GOAL = (3 * MM, 0.0, 0.0)

    def __init__(self):
        super().__init__()
        self.shortest = math.inf  # the shortest motion asked about [unit steps]

    def all_pushers(self):
        return 0b01

    def stable_pushers(self, a, b, candidates):
        d, g = unit(a, b), unit(a, self.GOAL)
        n, m = math.sqrt(sum(c * c for c in d)), math.sqrt(sum(c * c for c in g))
        self.shortest = min(self.shortest, n)
        if not (candidates & 1 and n > 0 and m > 0):
            return 0
        off = math.degrees(math.acos(max(-1.0, min(1.0, sum(x * y for x, y in zip(d, g)) / (n * m)))))
        return 1 if 5.0 <= off <= 30.0 else 0


def test_descents_near_the_goal_stop_short_of_pushes_too_short_to_model():
    """Searching on after the first plan (improve_for), descents went on from nodes ever nearer the
    goal, a fifth as far each time, until their steps were under the model's smallest motion
    (1e-12 m) and the T-shaped task's seed 17 raised "the motion dq is zero". Now a pose within
    SHORTEST_PUSH unit steps of the goal is at it."""
    checker = AskewChecker()
    out = plan(checker, AskewChecker.GOAL, time_limit=2.0, improve_for=0.2, seed=1)
    assert out.outcome == _core.PlanOutcome.goal_reached
    assert checker.shortest >= _core.SHORTEST_PUSH


def test_a_checker_that_leaves_out_a_method_is_a_clear_error():
    class Incomplete(_core.PushChecker):
        def all_pushers(self):
            return 1

    with pytest.raises(RuntimeError, match="stable_pushers"):
        plan(Incomplete(), (3 * MM, 0.0, 0.0))
