"""The compiled pad friction (cpp/sim/coulomb_pad_friction.cpp) against its numpy reference
(reference_pad_friction.py): the same algorithm written twice, run on the same arm and plan.

The pivot's pushes make the pad's ring points slide about its sticking centre, so every branch runs:
new sliders decided by the solver's step, trial steps for the friction's direction, points that
stick again. Both do the same floating-point operations in the same order, so the states must be
the same to the bit: the pivot turns a last-bit difference into micrometres within seconds (the
rig's 30 deg pivot ended 0.0025 and 0.0098 mm off while the reference summed its Anderson step
with BLAS), and a tolerance would hide a real slip.
"""
import mujoco
import numpy as np
import pytest

from stablepush.execution.stream import arm_trajectory
from stablepush.execution.world import place_features, scene_description
from stablepush.kinematics import cell_model
from stablepush.plan import plan_task
from stablepush.sim.mujoco.arm import SimArm
from stablepush.sim.mujoco.friction import CoulombPadFriction

from conftest import shipped
from reference_pad_friction import ReferencePadFriction

WAYPOINTS = 120  # 1.2 s of the pivot's plan: the first pushes, where the ring points slide


def _object_path(friction_class):
    """The object's pose (x, y, z m; quaternion) after each of the pivot plan's first waypoints on the
    arm, with the given pad friction, and the arm at the end."""
    task = shipped("pivoting")
    steps = list(plan_task(task).waypoints)
    features = place_features(task, steps)
    scene = scene_description(task, features, steps[0].pose)
    arm = SimArm(scene)
    arm.pad_friction = friction_class(arm.model, cell_model.pad_geoms(arm.model))
    q = arm._object_qpos
    path = []
    for point in arm_trajectory(task, steps, features, 100.0, scene.gripper_pose)[:WAYPOINTS]:
        arm.move_to(point.pose, 0.01)
        path.append(arm.data.qpos[q:q + 7].copy())
    return np.array(path), arm


@pytest.mark.slow
def test_the_compiled_pad_friction_moves_the_object_as_the_numpy_reference_to_the_bit():
    compiled, compiled_arm = _object_path(CoulombPadFriction)
    reference, reference_arm = _object_path(ReferencePadFriction)
    compiled_friction, reference_friction = compiled_arm.pad_friction, reference_arm.pad_friction
    # the pads slid over the object (the hand turned about it), and the sliding points' directions
    # took trial steps: the comparison is not of two resting grasps
    assert reference_friction.trial_steps > 1000
    assert compiled_friction.trial_steps == reference_friction.trial_steps
    assert compiled_friction.solver_steps == reference_friction.solver_steps
    np.testing.assert_array_equal(compiled, reference)


def test_a_pad_geom_not_in_the_model_is_refused_by_name():
    task = shipped("pivoting")
    steps = list(plan_task(task).waypoints)
    arm = SimArm(scene_description(task, place_features(task, steps), steps[0].pose))
    with pytest.raises(ValueError, match=f"pad geom {arm.model.ngeom} is not in the model"):
        CoulombPadFriction(arm.model, [arm.model.ngeom])


class _SteppedAgain(CoulombPadFriction):
    """The compiled friction, with every time step taken by mj_step after `update` (never a copy of
    the scratch step)."""

    def step(self, data) -> None:
        self.update(data)
        mujoco.mj_step(self.model, data)


def _end_state(arm) -> list:
    """The arm's whole state after its last step, and what the next step reads of that step
    (contacts, constraint forces and velocities, the pad pairs' friction)."""
    m, d = arm.model, arm.data
    state = np.zeros(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(m, d, state, mujoco.mjtState.mjSTATE_INTEGRATION)
    return [state, d.efc_force[:d.nefc].copy(), d.efc_vel[:d.nefc].copy(), d.contact.geom.copy(),
            m.pair_friction.copy()]


@pytest.mark.slow
def test_a_time_step_copied_from_the_scratch_is_the_step_mj_step_takes():
    # An accepted trial (or the solver's step, where no point slides) is copied into the arm's data
    # instead of stepped again. update leaves the trial's force in qfrc_applied, so mj_step after it
    # must land on the same state to the bit: the copy saves a step and changes nothing.
    _, copied = _object_path(CoulombPadFriction)
    _, stepped = _object_path(_SteppedAgain)
    # the pivot's ring points slide: most of the time steps came from the scratch
    time_steps = round(WAYPOINTS * 0.01 / cell_model.TIMESTEP)
    assert copied.pad_friction.copied_steps > 0.5 * time_steps
    assert stepped.pad_friction.copied_steps == 0
    assert copied.pad_friction.trial_steps == stepped.pad_friction.trial_steps
    assert copied.pad_friction.solver_steps == stepped.pad_friction.solver_steps
    for a, b in zip(_end_state(copied), _end_state(stepped)):
        np.testing.assert_array_equal(a, b)
