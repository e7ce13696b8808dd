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
from stablepush.plan import plan_task
from stablepush.sim import scene as scene_mod
from stablepush.sim.arm import SimArm
from stablepush.sim.friction import CoulombPadFriction

from conftest import shipped
from reference_pad_friction import ReferencePadFriction

WAYPOINTS = 120  # 1.2 s of the pivot's plan: the first pushes, where the ring points slide


def _object_path(friction_class):
    """The object's pose (x, y, z m; quaternion) after each of the pivot plan's first waypoints on the
    arm, with the given pad friction, and the friction object at the end."""
    task = shipped("pivoting")
    steps = list(plan_task(task).waypoints)
    features = place_features(task, steps)
    scene = scene_description(task, features, steps[0].pose)
    arm = SimArm(scene)
    arm.pad_friction = friction_class(arm.model, scene_mod.pad_geoms(arm.model))
    q = arm._object_qpos
    path = []
    for point in arm_trajectory(task, steps, features, 100.0, scene["gripper_pose"])[:WAYPOINTS]:
        arm.move_to(point.pose, 0.01)
        path.append(arm.data.qpos[q:q + 7].copy())
    return np.array(path), arm.pad_friction


@pytest.mark.slow
def test_the_compiled_pad_friction_moves_the_object_as_the_numpy_reference_to_the_bit():
    compiled, compiled_friction = _object_path(CoulombPadFriction)
    reference, reference_friction = _object_path(ReferencePadFriction)
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


def _end_state(friction_class):
    """The arm's whole state after the pivot's first waypoints, what the next step reads of its
    last one (contacts, constraint forces and velocities), and the friction object."""
    _, friction = _object_path(friction_class)
    data = friction.stepped_data
    state = np.zeros(mujoco.mj_stateSize(friction.model, mujoco.mjtState.mjSTATE_INTEGRATION))
    mujoco.mj_getState(friction.model, data, state, mujoco.mjtState.mjSTATE_INTEGRATION)
    return (state, data.efc_force[:data.nefc].copy(), data.efc_vel[:data.nefc].copy(), data.contact.geom.copy(),
            friction.model.pair_friction.copy()), friction


@pytest.mark.slow
def test_a_time_step_copied_from_the_scratch_is_the_step_mj_step_takes(monkeypatch):
    # An accepted trial (or the solver's step, where no point slides) is copied into the arm's data
    # instead of stepped again. update leaves the trial's force in qfrc_applied, so mj_step after it
    # must land on the same state to the bit: the copy saves a step and changes nothing.
    def keep_data(step):
        def stepped(self, data):
            self.stepped_data = data
            step(self, data)
        return stepped
    monkeypatch.setattr(CoulombPadFriction, "step", keep_data(CoulombPadFriction.step))
    monkeypatch.setattr(_SteppedAgain, "step", keep_data(_SteppedAgain.step))
    copied, copied_friction = _end_state(CoulombPadFriction)
    stepped, stepped_friction = _end_state(_SteppedAgain)
    # the pivot's ring points slide: most of the time steps came from the scratch
    time_steps = round(WAYPOINTS * 0.01 / scene_mod.TIMESTEP)
    assert copied_friction.copied_steps > 0.5 * time_steps
    assert stepped_friction.copied_steps == 0
    assert copied_friction.trial_steps == stepped_friction.trial_steps
    assert copied_friction.solver_steps == stepped_friction.solver_steps
    for a, b in zip(copied, stepped):
        np.testing.assert_array_equal(a, b)
