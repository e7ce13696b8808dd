"""The verdict on a run (`stablepush.execution.verdict`): hand-made reports, one per cause, and
the order in which causes are given."""
import dataclasses

import pytest

from stablepush.execution.closed_loop import Replan
from stablepush.execution.report import ContactRecord, ExecutionReport
from stablepush.execution.verdict import CAUSES, Verdict, judge, success_tolerance
from stablepush.pose import Tolerance

from conftest import shipped

TASK = shipped("horizontal-offset-high-mu")  # goal (20, 0, 0), tolerance 0.5 mm, 0.5 deg


def _report(final, released=None, contacts=(), replans=(), closed_loop="off", planned=(20.0, 0.0, 0.0)):
    pose = None if final is None else dict(zip(("x", "z", "theta"), final))
    after = None if released is None else dict(zip(("x", "z", "theta"), released))
    return ExecutionReport(task=TASK.name, resumed_from=0, last_confirmed_step=20, total_steps=20, waypoints=200,
                           planned_final=planned, goal=TASK.goal, final_in_grasp=pose, released_in_grasp=after,
                           contacts=list(contacts), closed_loop=closed_loop, replans=list(replans))


def _replan(solved, failure=None):
    return Replan(after_step=5, measured=(5.0, 0.3, 0.0), planned=(5.0, 0.0, 0.0), solved=solved, pushers=[],
                  pushes=0, kept_pusher=False, planning_ms=1.0, failure=failure)


def test_the_goal_tolerance_is_the_tasks_per_coordinate_unless_given():
    assert TASK.goal == (20.0, 0.0, 0.0) and success_tolerance(TASK) == Tolerance(0.5, 0.5)
    assert success_tolerance(TASK, [0.2, 0.3]) == Tolerance(0.2, 0.3)
    # Per coordinate, as Task.at_goal: 0.45 mm in x and 0.45 mm in z is 0.64 mm away, and within.
    assert Tolerance(0.5, 0.5).within({"x": 20.45, "z": 0.45, "theta": -0.45}, TASK.goal)
    assert not Tolerance(0.5, 0.5).within({"x": 20.0, "z": 0.0, "theta": 0.51}, TASK.goal)


@pytest.mark.parametrize("tolerance", [(float("nan"), 0.5), (0.5, float("inf")), (0.0, 0.5), (0.5, -1.0)])
def test_a_tolerance_that_is_not_finite_and_positive_is_refused_naming_it(tolerance):
    with pytest.raises(ValueError, match="success_tolerance: must be two finite numbers above 0"):
        success_tolerance(TASK, tolerance)
    with pytest.raises(ValueError, match="success_tolerance: must be two finite numbers above 0"):
        Verdict.for_fault(tolerance, "stopped")


def test_a_run_within_tolerance_landed_and_the_line_names_each_coordinate_and_its_tolerance():
    v = judge(TASK, _report((20.3, -0.2, 0.4)))
    assert v.success is True and v.cause is None
    # Per coordinate, as the tolerance is: no distance that could read as outside it.
    assert v.detail == "landed: x +0.30 mm, z -0.20 mm, theta +0.40 deg (tolerance 0.5 mm, 0.5 mm, 0.5 deg)"
    v = judge(TASK, _report((20.6, 0.0, 0.0)))
    assert v.detail.startswith("missed: x +0.60 mm, z +0.00 mm, theta +0.00 deg (tolerance 0.5 mm, 0.5 mm, 0.5 deg): ")


def test_a_part_that_moves_out_of_tolerance_on_release_did_not_land():
    # Within the tolerance on its last feature, 8 mm and 23 deg off once the pads alone hold it.
    report = _report((20.3, -0.2, 0.4), released=(28.0, -0.2, 23.0))
    v = judge(TASK, report)
    assert v.success is False and v.cause == "moved_on_release" and report.release_moved
    assert v.detail.startswith("missed: x +8.00 mm, z -0.20 mm, theta +23.00 deg")
    assert "on its last feature it was within the tolerance (x +0.30 mm, z -0.20 mm, theta +0.40 deg)" in v.detail
    # The pose before the release stays in the report; the goal error is where it came to rest.
    d = report.as_dict()
    assert d["final_in_grasp"]["x"] == 20.3 and d["landed_in_grasp"]["x"] == 28.0
    assert report.goal_error["x"] == pytest.approx(8.0)
    # A release that moves it a little, and it stays within: landed.
    assert judge(TASK, _report((20.3, -0.2, 0.4), released=(20.4, -0.3, 0.45))).success is True
    # A run that was off before the release keeps the cause it had there.
    assert judge(TASK, _report((21.6, 0.0, 0.0), released=(23.0, 0.0, 2.0))).cause == "drift"


def test_a_run_that_ends_on_its_feature_is_judged_there():
    report = dataclasses.replace(_report((20.3, -0.2, 0.4), released=(28.0, -0.2, 23.0)), ends_on_feature=True)
    assert judge(TASK, report).success is True and report.release_change is None
    assert report.landed_in_grasp == report.final_in_grasp


def test_a_tighter_tolerance_turns_the_same_run_into_a_miss():
    report = _report((20.3, -0.2, 0.4))
    v = judge(TASK, report, (0.2, 0.2))
    assert v.success is False and v.tolerance == Tolerance(0.2, 0.2) and v.cause == "drift"


def test_a_slipping_pusher_is_the_cause_and_named():
    slips = [ContactRecord("left", 1, 10, slip_mm=0.1, slip_deg=0.1), ContactRecord("left", 11, 20, slip_mm=1.4,
                                                                                    slip_deg=0.2)]
    v = judge(TASK, _report((21.6, 0.0, 0.0), contacts=slips))
    assert v.cause == "pusher_slipped" and "left slipped 1.40 mm" in v.detail and "steps 11-20" in v.detail
    # Slips below half the tolerance (0.25 mm, 0.25 deg) are not blamed.
    small = [dataclasses.replace(slips[1], slip_mm=0.24, slip_deg=0.24)]
    assert judge(TASK, _report((21.6, 0.0, 0.0), contacts=small)).cause == "drift"


def test_a_feature_met_beyond_its_place_is_blamed_before_a_slip():
    late = [ContactRecord("left", 1, 20, slip_mm=0.3, slip_deg=0.0, carried_mm=0.45)]
    v = judge(TASK, _report((19.4, 0.0, 0.0), contacts=late))
    assert v.cause == "feature_off" and "left's feature was met late: the object rode with the hand 0.45 mm into " \
        "step 1 before it stopped it (its feature beyond its place along the push, or the object moved" in v.detail
    # Where the guarded approach found that feature, the verdict says so rather than guess.
    v = judge(TASK, _report((19.4, 0.0, 0.0), contacts=[dataclasses.replace(late[0], found_mm=0.02)]))
    assert v.cause == "feature_off" and "(the guarded approach found the feature +0.02 mm from its place)" in v.detail
    # Carried no more than half the tolerance (0.25 mm): the slip is the cause again.
    v = judge(TASK, _report((19.4, 0.0, 0.0), contacts=[dataclasses.replace(late[0], carried_mm=0.24)]))
    assert v.cause == "pusher_slipped"
    # A feature that never stopped the object is not said to have been met.
    v = judge(TASK, _report((0.0, 0.0, 0.0), contacts=[dataclasses.replace(late[0], carried_mm=20.0,
                                                                           feature_met=False)]))
    assert v.cause == "feature_off" and "left's feature was not met" in v.detail and "steps 1-20" in v.detail


def test_a_plan_that_stops_short_is_its_own_cause():
    v = judge(TASK, _report((18.5, 0.0, 0.0), planned=(18.5, 0.0, 0.0)))
    assert v.cause == "plan_short" and "the plan itself ends at x -1.50 mm, z +0.00 mm, theta +0.00 deg" in v.detail


def test_a_short_plan_that_the_loop_could_not_aim_again_is_plan_short_and_says_why():
    # The aim before the first push is no correction: its failure leaves the cause to the plan.
    aimed = dataclasses.replace(_replan(False, failure="every pusher in 500 ms: time_limit"), after_step=0,
                                trigger="plan_short")
    v = judge(TASK, _report((18.5, 0.0, 0.0), planned=(18.5, 0.0, 0.0), replans=[aimed], closed_loop="on"),
              max_replans=20)
    assert v.cause == "plan_short" and "no plan to the goal was found before the first push (every pusher in " \
        "500 ms: time_limit)" in v.detail, v.detail


def test_a_failed_correction_comes_before_the_slip_that_asked_for_it():
    slip = [ContactRecord("left", 1, 20, slip_mm=1.5, slip_deg=0.0)]
    replans = [_replan(True), _replan(False, failure="no plan to the final tolerance in 50 ms")]
    v = judge(TASK, _report((21.5, 0.0, 0.0), contacts=slip, replans=replans, closed_loop="on"), max_replans=20)
    assert v.cause == "correction_not_found" and "no plan to the final tolerance in 50 ms" in v.detail
    v = judge(TASK, _report((21.5, 0.0, 0.0), contacts=slip, replans=[_replan(True)] * 3, closed_loop="on"),
              max_replans=3)
    assert v.cause == "corrections_exhausted"


def test_a_pad_off_the_object_is_a_lost_grasp():
    # The prism is 40 mm wide: 60 mm along x puts the pads' centre past its edge.
    v = judge(TASK, _report((60.0, 0.0, 0.0), contacts=[ContactRecord("left", 1, 20, slip_mm=40.0, slip_deg=0.0)]))
    assert v.cause == "grasp_lost"


def test_an_arm_without_a_tracker_gets_no_verdict_and_a_fault_is_a_miss():
    v = judge(TASK, _report(None))
    assert v.success is None and v.cause == "not_measured"
    fault = Verdict.for_fault((1, 1), "the arm server closed the connection")
    assert fault.success is False and fault.cause == "arm_fault" and "closed the connection" in fault.detail
    assert {v.cause, fault.cause} <= set(CAUSES)


@pytest.mark.parametrize("key", ["success", "tolerance", "cause", "verdict", "engine"])
def test_the_json_report_carries_the_verdict(key):
    report = _report((20.3, -0.2, 0.4))
    report.verdict = judge(TASK, report)
    assert key in report.as_dict()
    assert report.as_dict()["success"] is True and report.success is True


def test_angles_are_compared_within_one_turn():
    # A tracker reports theta in (-180, 180]; a plan may end at 360 deg, the same orientation.
    turned = dataclasses.replace(TASK, goal=(20.0, 0.0, 360.0))
    report = _report((20.1, 0.0, -0.2), planned=(20.0, 0.0, 360.0))
    report.goal = turned.goal
    v = judge(turned, report)
    assert v.success is True and "theta -0.20 deg" in v.detail
    assert report.final_error["theta"] == pytest.approx(-0.2) and report.goal_error["theta"] == pytest.approx(-0.2)
    assert Tolerance(0.5, 0.5).within({"x": 20.0, "z": 0.0, "theta": 179.9}, (20.0, 0.0, -179.9))


def test_execute_help_lists_every_cause_a_report_can_give():
    from click.testing import CliRunner

    from stablepush_cli.main import cli

    result = CliRunner().invoke(cli, ["execute", "--help"])
    assert result.exit_code == 0, result.output
    assert f"is one of {', '.join(CAUSES)} (docs/execution.md)" in " ".join(result.output.split())
