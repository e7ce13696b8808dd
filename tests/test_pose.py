"""The in-grasp Pose and the one Tolerance (docs/model.md section 1): the wrap rule, the share of
a tolerance a pose uses, and the refusal of a tolerance that is not two finite numbers above 0;
properties over generated poses, and the planner's goal test agreeing with the verdict's."""
import math

import numpy as np
import pytest

from stablepush.errors import SettingError
from stablepush.pose import Pose, Tolerance


@pytest.mark.parametrize("seed", range(5))
def test_within_is_used_at_most_one_and_a_whole_turn_is_no_turn(seed):
    rng = np.random.default_rng(seed)
    for _ in range(200):
        tol = Tolerance(float(rng.uniform(0.05, 3)), float(rng.uniform(0.05, 3)))
        goal = Pose(*rng.uniform(-50, 50, 2), float(rng.uniform(-400, 400)))
        pose = Pose(goal.x + rng.normal(0, tol.position), goal.z + rng.normal(0, tol.position),
                    goal.theta + rng.normal(0, tol.angle) + 360.0 * int(rng.integers(-2, 3)))
        assert tol.within(pose, goal) == (tol.used(pose, goal) <= 1.0)
        turned = Pose(pose.x, pose.z, pose.theta + 360.0)
        assert tol.used(turned, goal) == pytest.approx(tol.used(pose, goal), abs=1e-9)
        dx, dz, dtheta = pose.minus(goal)
        assert -180.0 <= dtheta < 180.0 and dx == pose.x - goal.x
        assert tol.scaled(0.5).within(pose, goal) == (tol.used(pose, goal) <= 0.5)


def test_a_pose_is_read_from_a_tuple_a_mapping_or_a_pose_and_goes_to_si():
    assert Pose.of((1, 2, 30)) == Pose.of({"x": 1, "z": 2, "theta": 30}) == Pose.of(Pose(1.0, 2.0, 30.0))
    assert Pose(1.0, 2.0, 180.0).si() == pytest.approx((1e-3, 2e-3, math.pi))
    assert tuple(Pose(1.0, 2.0, 3.0)) == (1.0, 2.0, 3.0)
    assert Tolerance(1.0, 2.0).si() == pytest.approx((1e-3, math.radians(2.0)))


@pytest.mark.parametrize("value", [(float("nan"), 0.5), (0.5, float("inf")), (0.0, 0.5), (0.5, -1.0), (1.0,), "ab"])
def test_a_tolerance_that_is_not_two_finite_numbers_above_0_is_refused(value):
    with pytest.raises(SettingError, match="tolerance: must be two finite numbers above 0"):
        Tolerance.of(value)


def test_the_planners_goal_test_and_the_verdicts_are_one_rule():
    """Task.at_goal had no angle wrap where the verdict had one: a start a whole turn from its goal
    was planned a turn round."""
    from conftest import shipped

    task = shipped("t-shaped")
    turned = (task.goal[0], task.goal[1], task.goal[2] + 360.0)
    assert task.at_goal(turned) and task.tolerance.within(turned, task.goal)
