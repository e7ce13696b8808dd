"""Waypoint keeps its own invariants (issue 58): a waypoint that exists can be written, read back and
checked against a task, so neither the plan file's reader nor check_plan re-checks its fields."""
import dataclasses
import json
import math

import numpy as np
import pytest

import stablepush as sp
from stablepush.plan.files import plan_from_dict, plan_to_dict

from conftest import TASKS


@pytest.mark.parametrize("fields, says", [
    ({"x": math.nan}, "waypoint.x: must be a finite number, got NaN"),
    ({"z": math.inf}, "waypoint.z: must be a finite number, got Infinity"),
    ({"theta": 10 ** 400}, "waypoint.theta: must be a finite number"),
    ({"theta": (1.0, 2.0)}, "waypoint.theta: must be a finite number, got [1.0, 2.0]"),
    ({"x": "1"}, 'waypoint.x: must be a finite number, got "1"'),
    ({"x": True}, "waypoint.x: must be a finite number, got true"),
    ({"pusher": 5}, "waypoint.pusher: must be a pusher name or null, got a number"),
    ({"pusher": b"left"}, "waypoint.pusher: must be a pusher name or null, got bytes"),
    ({"margin": math.nan}, "waypoint.margin: must be a finite number or null, got NaN"),
    ({"margin_per_normal": -math.inf}, "waypoint.margin_per_normal: must be a finite number or null"),
    ({"case": 1}, "waypoint.case: must be a string or null, got a number"),
    ({"contact": ((0, 0), (1, 0), (0, 1))}, "waypoint.contact: must be a PusherContact or None, got tuple"),
])
def test_a_waypoint_with_a_bad_field_cannot_be_made(fields, says):
    good = {"x": 1.0, "z": 2.0, "theta": 3.0, "pusher": "left", "margin": 0.5}
    with pytest.raises(sp.PlanError) as error:
        sp.Waypoint(**{**good, **fields})
    assert str(error.value).startswith(says)
    assert isinstance(error.value, ValueError)
    with pytest.raises(sp.PlanError, match=error.value.field.replace(".", r"\.")):
        dataclasses.replace(sp.Waypoint(**good), **fields)  # nor made by editing a good one


@pytest.mark.parametrize("point", [(0.0, math.nan), (0.0, 1.0, 2.0), 5, "ab", None])
def test_a_pusher_contact_of_other_than_two_finite_numbers_cannot_be_made(point):
    with pytest.raises(sp.PlanError, match=r"contact\.end: must be 2 finite numbers"):
        sp.PusherContact(start=(0.0, 0.0), end=point, normal=(0.0, 1.0))


def test_numbers_numpy_gives_are_numbers():
    w = sp.Waypoint(np.float64(1.0), np.int64(2), np.float32(3.0), margin=np.float64(0.1), margin_per_normal=0)
    contact = sp.PusherContact(start=np.array([0.0, 1.0]), end=[1, 2], normal=(0.0, 1.0))
    assert w.pose == (1.0, 2.0, 3.0) and sp.Waypoint(0, 0, 0, pusher="left", contact=contact).contact is contact


def test_the_file_reader_and_waypoint_say_the_same_of_a_field():
    """One check of a waypoint's fields: a plan file's waypoint is refused for what Waypoint refuses,
    in the same words, with where it is in the file."""
    task = sp.load_task(TASKS / "horizontal-offset-low-mu.yaml")
    data = json.loads(json.dumps(plan_to_dict(sp.plan_task(task, seed=1))))
    for key, value in (("x", "1"), ("pusher", 5), ("margin", 10 ** 400), ("case", [])):
        edited = json.loads(json.dumps(data))
        edited["waypoints"][2][key] = value
        with pytest.raises(sp.PlanError) as in_file:
            plan_from_dict(edited)
        with pytest.raises(sp.PlanError) as made:
            sp.Waypoint(**{"x": 0.0, "z": 0.0, "theta": 0.0, key: value})
        assert in_file.value.field == f"waypoints[2].{key}" and made.value.field == f"waypoint.{key}"
        assert in_file.value.reason == made.value.reason


def test_check_plan_refuses_what_is_not_a_waypoint_by_its_place():
    task = sp.load_task(TASKS / "horizontal-offset-low-mu.yaml")
    plan = sp.plan_task(task, seed=1)
    for entry in (None, (0.0, 0.0, 0.0), {"x": 0.0, "z": 0.0, "theta": 0.0}):
        steps = [plan.waypoints[0], entry] + plan.waypoints[2:]
        with pytest.raises(sp.PlanError, match=r"waypoints\[1\]: must be a Waypoint"):
            sp.check_plan(task, dataclasses.replace(plan, waypoints=steps))
    assert sp.check_plan(task, plan) is plan
