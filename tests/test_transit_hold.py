"""Switch-overs only where the pads hold (`plan_task(rules=SearchRules(min_transit_hold=...))`): between two features
the object is carried by the pads alone, so the search may change pusher only at a pose where
`hold_ratio` (with the gravity of the feature being left) reaches the given factor."""
import pytest

from stablepush.plan.search import SearchRules, plan_task
from stablepush.units import pose_to_si

from conftest import shipped

LOW_MU = shipped("horizontal-offset-low-mu")  # bottom -> left: one switch-over, where the pads hold 4.26 times


def _switch_holds(task, plan):
    model, holds = task.model, []
    for before, after in zip(plan.waypoints[1:], plan.waypoints[2:]):
        if after.pusher != before.pusher:
            holds.append(model.hold_ratio(pose_to_si(before.pose), task.pusher_index(before.pusher)))
    return holds


def test_without_the_rule_the_low_mu_offset_switches_where_the_pads_hold_4_26_times():
    plan = plan_task(LOW_MU, seed=1)
    assert plan.pusher_sequence == ["bottom", "left"]
    assert _switch_holds(LOW_MU, plan) == [pytest.approx(4.26, abs=0.01)]


@pytest.mark.parametrize("factor", [1.5, 3.0, 4.0, 4.2, 4.3, 5.0, 20.0])
def test_every_switch_over_of_a_plan_is_where_the_pads_hold_the_factor(factor):
    plan = plan_task(LOW_MU, seed=1, rules=SearchRules(min_transit_hold=factor), time_limit=0.3)
    assert all(h >= factor for h in _switch_holds(LOW_MU, plan)), (factor, _switch_holds(LOW_MU, plan))
    # The offset needs the bottom pusher's lift and then the left one: no switch-over, no plan.
    assert plan.solved == (factor <= 4.2), (factor, plan.outcome, plan.pusher_sequence)


def test_a_replan_from_a_feature_makes_a_transit_at_its_start():
    # Started on the bottom pusher's feature where the pads hold 4.26 times: a plan that begins with
    # the left pusher leaves that feature at the start, allowed below 4.26 and refused above.
    plan = plan_task(LOW_MU, seed=1)
    k = next(i for i, w in enumerate(plan.waypoints) if w.pusher == "left") - 1
    on_bottom = LOW_MU.with_start(plan.waypoints[k].pose)
    assert plan_task(on_bottom, seed=1, rules=SearchRules(4.0, start_pusher="bottom"), time_limit=0.3).solved
    refused = plan_task(on_bottom, seed=1, rules=SearchRules(4.5, start_pusher="bottom"), time_limit=0.3)
    assert not refused.solved and refused.pusher_sequence[:1] in ([], ["bottom"]), refused.pusher_sequence
    # Not started on a feature, the same search leaves with the left pusher at once: what refused
    # it above was the transit at the start, not the search.
    assert plan_task(on_bottom, seed=1, rules=SearchRules(4.5), time_limit=0.3).pusher_sequence == ["left"]


def test_with_start_keeps_the_features_orientation():
    task = shipped("large-manipulation")  # no environment.features: each feature at the start's theta
    moved = task.with_start((14.6, -13.7, 44.0))
    assert moved.start == (14.6, -13.7, 44.0)
    assert [moved.feature_angle(p) for p in moved.pusher_names] == [task.start[2]] * len(task.pushers)
    q = pose_to_si(moved.start)
    assert moved.model.hold_ratio(q, 0) == pytest.approx(task.model.hold_ratio(q, 0))


def test_a_correction_switches_where_the_pads_hold_1_4_times_when_nothing_holding_1_5_is_found():
    """The large manipulation, 0.61 mm low at its plan's end in a world of pad mu x0.90 (evaluate's
    trial 32): only another pusher lifts it, and the pads hold 1.47 times the weight there. The
    correction's last attempt switches there, and says so, when the run would miss its verdict
    otherwise."""
    from stablepush.execution.closed_loop import (
        TRANSIT_HOLD_RATIO,
        TRANSIT_HOLD_RATIO_LEAST,
        ClosedLoop,
        _transits_held,
        replan,
    )

    task = shipped("large-manipulation")
    measured = (15.029502682765594, -13.611996401049778, 45.325170827884875)
    loop = ClosedLoop.for_task(task)
    refused, _ = replan(task, measured, "left", loop, 57, task.goal, "off_goal")  # a landed run risks no such switch
    assert not refused.solved and "1.4 times" not in refused.failure
    record, steps = replan(task, measured, "left", loop, 57, task.goal, "off_goal", verdict_at_stake=True)
    assert record.solved and steps[1].pusher != "left", record.failure
    assert "hold 1.4 times" in record.attempt
    assert _transits_held(task, steps, "left", TRANSIT_HOLD_RATIO_LEAST)
    assert not _transits_held(task, steps, "left", TRANSIT_HOLD_RATIO)
    hold = task.model.hold_ratio(pose_to_si(measured), task.pusher_index("left"))
    assert TRANSIT_HOLD_RATIO_LEAST <= hold < TRANSIT_HOLD_RATIO
