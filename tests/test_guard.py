"""The guarded approach's parts (stablepush.execution.guard): when a touch is read, how a
contact's plan starts from the pose measured at the touch, and where a seated object puts its
feature. End to end on the simulated arm:
tests/test_execute.py."""
import math

import numpy as np
import pytest

from stablepush.execution.guard import (
    GuardedApproach,
    found_feature,
    from_touch,
    seated_feature,
    touched_feature,
    turned_deg,
)
from stablepush.execution.world import Feature, near_pose
from stablepush.frames import grasp_transform, pose_to_matrix, quat_about_y, rot_y
from stablepush.plan import Waypoint


def test_a_touch_is_a_move_in_the_grasp_past_either_threshold():
    guard = GuardedApproach(touch_mm=0.01, touch_deg=0.02)
    at = {"x": 1.0, "z": 2.0, "theta": 179.995}
    assert not guard.met(at, {"x": 1.006, "z": 2.006, "theta": 179.995})  # 0.0085 mm
    assert guard.met(at, {"x": 1.008, "z": 2.008, "theta": 179.995})  # 0.0113 mm
    assert guard.met(at, {"x": 1.0, "z": 2.0, "theta": -179.98})  # 0.025 deg across +-180
    assert not guard.met(at, {"x": 1.0, "z": 2.0, "theta": -179.999})


def test_a_touch_is_read_from_the_contact_force_when_the_arm_reports_one():
    """A wrist force-torque reading tells the touch before the object moves in the grasp; the
    tracker's pose then does not count."""
    guard = GuardedApproach(touch_n=0.5)
    at = {"x": 0.0, "z": 0.0, "theta": 0.0}
    moved = {"x": 0.5, "z": 0.0, "theta": 0.0}
    assert not guard.met(at, moved, [0.3, 0.0, -0.3])  # 0.42 N
    assert guard.met(at, at, [0.0, 0.1, 0.6])  # 0.61 N
    assert guard.met(at, moved, None)


@pytest.mark.parametrize("field, value", [("touch_mm", 0.0), ("touch_deg", -1.0), ("reach_mm", 5.0),
                                          ("hold_s", 2.0), ("touch_n", 0.0), ("seat_deg", 3.0)])
def test_guard_parameters_outside_their_ranges_are_refused_by_name(field, value):
    with pytest.raises(ValueError, match=field):
        GuardedApproach(**{field: value})


def test_touch_thresholds_stay_clear_of_the_trackers_noise():
    assert GuardedApproach.for_tracker_noise() == GuardedApproach()
    guard = GuardedApproach.for_tracker_noise(0.05, 0.001)
    assert guard.touch_mm == pytest.approx(0.2) and guard.touch_deg == GuardedApproach().touch_deg
    assert guard.seat_deg == GuardedApproach().seat_deg
    assert GuardedApproach.for_tracker_noise(0.0, 0.1).seat_deg == pytest.approx(0.4)


def test_the_seated_feature_is_the_objects_measured_world_pose_in_the_grasp_plane():
    """The plan holds the object at (0.45, 0.1, 0.3) m turned 30 deg about y. G at (0.4, 0.1, 0.3) m turned
    20 deg; the object measured at (50 mm, -1 mm, 10.3 deg) in the grasp: in the world, G's turn plus
    10.3 deg (0.3 deg past the plan's 30) and G's origin plus R_y(20 deg)(50, 0, -1) mm. The plan's y and
    the feature's segment stay."""
    T_plan = np.eye(4)
    T_plan[:3, :3], T_plan[:3, 3] = rot_y(math.radians(30)), (0.45, 0.1, 0.3)
    feature = Feature("left", T_plan, np.zeros(3), np.ones(3), np.array([1.0, 0.0, 0.0]), 0.6)
    ee_pose = (0.4, 0.1, 0.3, *quat_about_y(math.radians(20)))
    seated = seated_feature(feature, ee_pose, (50.0, -1.0, 10.3))
    assert turned_deg(feature, seated) == pytest.approx(0.3)
    assert seated.object_pose[:3, :3] == pytest.approx(rot_y(math.radians(30.3)))
    expected = np.array([0.4, 0.1, 0.3]) + rot_y(math.radians(20)) @ np.array([0.05, 0.0, -0.001])
    assert seated.object_pose[:3, 3] == pytest.approx(expected)
    assert seated.start is feature.start and seated.normal is feature.normal


def test_a_touch_that_turned_the_object_rests_it_on_the_feature_turned():
    """The plan and G of the test above. A touch that left the object 0.3 deg past the plan's turn
    finds the feature in the plan's orientation; one that left it 1 deg past finds it turned, and G
    then rests the object on it where G is (the stream's near_pose: no backing off and approaching
    again), where the plan's orientation would put G 1 deg off and the stream would approach again."""
    T_plan = np.eye(4)
    T_plan[:3, :3], T_plan[:3, 3] = rot_y(math.radians(30)), (0.45, 0.1, 0.3)
    feature = Feature("left", T_plan, np.zeros(3), np.ones(3), np.array([1.0, 0.0, 0.0]), 0.6)
    ee_pose = (0.4, 0.1, 0.3, *quat_about_y(math.radians(20)))

    def g_on(found, measured):  # G's pose that holds the object at `measured` on `found`
        return found.object_pose @ np.linalg.inv(grasp_transform(measured))

    slight = (50.0, -1.0, 10.3)
    assert touched_feature(feature, ee_pose, slight).object_pose == pytest.approx(
        found_feature(feature, ee_pose, slight).object_pose)
    turned = (50.0, -1.0, 11.0)
    found, touched = found_feature(feature, ee_pose, turned), touched_feature(feature, ee_pose, turned)
    assert turned_deg(feature, touched) == pytest.approx(1.0)
    assert not near_pose(pose_to_matrix(ee_pose), g_on(found, turned))
    assert near_pose(pose_to_matrix(ee_pose), g_on(touched, turned), distance=1e-9, angle=1e-6)


def test_a_contact_starts_from_the_measured_pose_and_still_ends_where_the_plan_does():
    """Contact 'a' runs steps 1-4 from step 0; the touch measured (0.04, -0.02, 0.1) off step 0's pose
    is taken out in equal parts over its four pushes. Contact 'b' is left alone."""
    steps = [Waypoint(0.0, 0.0, 0.0)] + [Waypoint(float(i), 0.0, 0.0, pusher="a") for i in range(1, 5)] + \
        [Waypoint(4.0, float(i), 0.0, pusher="b") for i in range(1, 3)]
    out = from_touch(steps, 0, (0.04, -0.02, 0.1))
    assert out[0].pose == (0.04, -0.02, 0.1) and out[0].pusher is None
    for i, share in zip(range(1, 5), (0.75, 0.5, 0.25, 0.0)):
        assert out[i].pose == pytest.approx((i + 0.04 * share, -0.02 * share, 0.1 * share))
        assert out[i].pusher == "a"
    assert out[5:] == steps[5:] and len(out) == len(steps)
    later = from_touch(steps, 4, (4.0, 0.01, 0.0))  # contact 'b' from step 4
    assert later[:4] == steps[:4] and later[5].pose == pytest.approx((4.0, 1.005, 0.0)) and later[6] == steps[6]
