"""The closed loop's aim before the first push (`closed_loop.aim`): a plan may stop anywhere
within the task's tolerance, but the loop lands within its final tolerance, so a plan that ends
outside that is planned again to it while every push is still ahead."""
import dataclasses

from stablepush.execution.closed_loop import ClosedLoop, aim
from stablepush.plan.search import plan_task

from conftest import shipped


def _within(pose, goal, tolerance):
    position, angle = tolerance
    return max(abs(pose[0] - goal[0]), abs(pose[1] - goal[1])) <= position and abs(pose[2] - goal[2]) <= angle


def test_a_plan_that_ends_short_of_the_final_tolerance_is_planned_again_to_it():
    # The large manipulation's plan (seed 1) stops 1.28 unit steps from the goal, inside its 1 mm /
    # 1 deg but not the loop's 0.2 / 0.2; its left pusher alone cannot push the rest from there.
    task = shipped("large-manipulation")
    plan = plan_task(task, seed=1)
    loop = ClosedLoop.for_task(task)
    assert not _within(plan.waypoints[-1].pose, task.goal, loop.final_tolerance)
    record, steps = aim(task, plan.waypoints, loop)
    assert record.solved and record.trigger == "plan_short" and record.after_step == 0
    assert record.planned == plan.waypoints[-1].pose and record.measured == plan.waypoints[0].pose
    assert steps[0].pose == plan.waypoints[0].pose and record.pushes == len(steps) - 1
    assert _within(steps[-1].pose, task.goal, loop.final_tolerance), steps[-1].pose
    assert record.pushers == ["left"]  # the task's switch-over budget (0) is kept


def test_a_plan_that_ends_within_the_final_tolerance_is_run_as_it_is():
    task = shipped("pivoting")  # its plan ends at the goal pose
    plan = plan_task(task, seed=1)
    assert aim(task, plan.waypoints, ClosedLoop.for_task(task)) is None


def test_when_no_plan_reaches_the_final_tolerance_the_plan_runs_and_the_record_says_why():
    # The pegs' plan ends short of 0.2 mm / 0.2 deg; in 2,000,000 tests (AIM_CHECKS) no plan of the two pegs
    # reaches it.
    task = shipped("more/cube-pegs")
    plan = plan_task(task, seed=1)
    record, steps = aim(task, plan.waypoints, ClosedLoop.for_task(task))
    assert not record.solved and steps == [] and record.pushes == 0 and record.pushers == []
    # The plan ends 0.245 mm past the goal in x, where neither peg moves the cube back along -x.
    # One line sums the searches up (what `execute` prints); each is in `tried` (what --json keeps).
    way_back = "from the plan's end no stable push moves the object toward the goal along -x (at most 0.05 of a unit step)"
    assert record.failure == f"3 search(es) failed (out of tests 3); {way_back}", record.failure
    assert record.tried == [f"{k} switch-over(s) in 2,000,000 tests: out of tests" for k in range(3)] + [way_back]
    assert not record.guard_fired
    assert record.as_dict()["tried"] == record.tried


def test_no_way_back_names_the_senses_no_pusher_moves_the_object_in():
    """closed_loop.no_way_back: the senses of x, z, theta toward the goal, beyond the tolerance, in
    which no stable push moves the object by more than a tenth of a unit step; None where the
    pushers can move it every way the goal lies (the T at its start), or off the grasp."""
    from stablepush.execution.closed_loop import no_way_back

    pegs = shipped("more/cube-pegs")
    edge = dataclasses.replace(pegs, planner=pegs.planner.replace(end_within=1.0))  # the plan to the tolerance's edge
    end = plan_task(edge, seed=1).waypoints[-1].pose
    assert no_way_back(pegs, end, (0.2, 0.2)) == "-x (at most 0.05 of a unit step)"
    assert no_way_back(pegs, end, (0.3, 0.5)) is None  # the x gap (0.245 mm) is within 0.3 mm
    t = shipped("t-shaped")
    assert no_way_back(t, t.start, (0.2, 0.2)) is None
    assert no_way_back(t, (500.0, 0.0, 0.0), (0.2, 0.2)) is None  # no grasp there


def test_aimed_plans_switch_over_only_where_corrections_may_and_no_more_than_needed():
    # The wedge's plan uses its heel stop alone and ends short; no plan of the heel stop alone
    # reaches 0.2 mm / 0.2 deg in 2 s, so the aimed plan switches once (its budget is 2), by the
    # rule of every correction: only where the pads hold 1.5 times the weight.
    from stablepush.execution.closed_loop import TRANSIT_HOLD_RATIO
    from stablepush.units import pose_to_si

    task = shipped("more/wedge-heel")
    plan = plan_task(task, seed=1)
    record, steps = aim(task, plan.waypoints, ClosedLoop.for_task(task))
    assert plan.pusher_sequence == ["heel-stop"] and task.planner.max_switches == 2
    assert record.solved and record.pushers == ["heel-stop", "floor-block"], record
    model = task.model
    holds = [model.hold_ratio(pose_to_si(before.pose), task.pusher_index(before.pusher))
             for before, after in zip(steps[1:], steps[2:]) if after.pusher != before.pusher]
    assert len(holds) == 1 and holds[0] >= TRANSIT_HOLD_RATIO, holds
    # The L bracket's plan (its left pusher alone) is aimed with the left pusher alone.
    task = shipped("more/l-bracket-mesh")
    record, steps = aim(task, plan_task(task, seed=1).waypoints, ClosedLoop.for_task(task))
    assert record.solved and record.pushers == ["left"], record


def test_the_same_plan_is_aimed_once_per_process(monkeypatch):
    # evaluate runs one plan in many worlds: the pegs' failed aim (its whole time limit) is made once.
    from stablepush.execution import closed_loop

    calls = []
    real = closed_loop._aim
    monkeypatch.setattr(closed_loop, "_aim", lambda *args: calls.append(args) or real(*args))
    monkeypatch.setattr(closed_loop, "_AIMED", type(closed_loop._AIMED)())
    task = shipped("large-manipulation")
    plan = plan_task(task, seed=1)
    loop = ClosedLoop.for_task(task)
    first = aim(task, plan.waypoints, loop)
    assert aim(task, plan.waypoints, loop) == first and len(calls) == 1
    tighter = ClosedLoop.for_task(task, final_tolerance=(0.1, 0.1))  # another tolerance: aimed anew
    assert aim(task, plan.waypoints, tighter)[0].solved and len(calls) == 2
    other = plan_task(task, seed=2)  # another plan: aimed anew
    aim(task, other.waypoints, loop)
    assert len(calls) == 3
