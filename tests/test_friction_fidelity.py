"""The friction-fidelity contract (`stablepush.sim.fidelity`): the simulated arm's contacts
must stick where Coulomb's law sticks and slide with mu N where it slides, or no plan measured on
it means anything. `python3 benchmarks/friction_fidelity.py` prints the same numbers as a table.
"""
import pytest

from stablepush.sim import fidelity, friction
from stablepush.task import check_push

from conftest import shipped


@pytest.mark.parametrize("load", [0.5, 0.9])
@pytest.mark.parametrize("pad_speed", [0.001, 0.005, 0.02])
def test_a_wall_holds_the_box_while_the_pads_slide_over_it(load, pad_speed):
    result = fidelity.wall_creep(load, pad_speed)
    assert result.wall_cone_use == pytest.approx(load, abs=0.06)  # the scene loads the wall as asked
    assert result.creep_um_per_mm <= fidelity.CREEP_LIMIT_UM_PER_MM[load], result
    assert result.pad_friction_ratio == pytest.approx(1.0, abs=fidelity.PAD_FRICTION_TOLERANCE), result
    assert result.pad_dropout_steps == 0, result


def test_stiff_pad_friction_alone_fails_the_contract(monkeypatch):
    """The solver's stiff friction on every pad point, sliding or not (the arm's first setting):
    sliding pads drop their contacts and the wall creeps ~37 um/mm. The contract catches it."""
    monkeypatch.setattr(friction, "SLIDE_SPEED", float("inf"))
    result = fidelity.wall_creep(0.5, 0.01, travel=0.004)
    assert result.creep_um_per_mm > 10 * fidelity.CREEP_LIMIT_UM_PER_MM[0.5]
    assert result.pad_dropout_steps > 0


@pytest.mark.parametrize("load", [0.5, 0.9])
def test_a_box_held_by_friction_alone_stays_put(load):
    result = fidelity.static_hold(load)
    assert result.moved_um <= fidelity.HOLD_LIMIT_UM, result


def test_a_pivot_through_the_sticking_pad_centre_holds_where_the_model_says_it_does():
    task = shipped("pivoting")
    verdict = check_push(task, (0, 0, 0), (0, 0, 1), "left")["left"]
    assert verdict["feasible"] and verdict["case"] == "sticking"
    result = fidelity.pivot(task, "left", turn_deg=30)
    assert result.moved_mm <= fidelity.PIVOT_LIMIT_MM, result
    assert abs(result.rotated_deg) <= fidelity.PIVOT_LIMIT_DEG, result
    assert abs(result.grasp_error_deg) <= fidelity.PIVOT_LIMIT_DEG, result


def test_a_pivot_the_model_calls_unstable_slips_at_the_pusher():
    """The other direction of the same cross-check: with the side pusher's mu at 0.2 the model
    says the pivot is not a stable push, and the simulated pusher indeed slips."""
    task = fidelity.with_pusher_mu(shipped("pivoting"), "left", 0.2)
    assert not check_push(task, (0, 0, 0), (0, 0, 1), "left")["left"]["feasible"]
    result = fidelity.pivot(task, "left", turn_deg=30)
    assert abs(result.rotated_deg) > 5 * fidelity.PIVOT_LIMIT_DEG, result


def test_a_pivot_by_the_servo_driven_arm_follows_its_plan():
    """The rig's hand is infinitely stiff; the arm's is not. On the arm, with its servos, IK and the
    executor's stream, the first 30 degrees of the pivoting plan must still turn about the stuck pad
    centre (with the sliding ring points' friction a few degrees off their slip it lost 0.5 deg here)."""
    result = fidelity.pivot_on_arm(shipped("pivoting"))
    assert result.pushes == fidelity.ARM_PIVOT_PUSHES
    assert result.error_mm <= fidelity.ARM_PIVOT_LIMIT_MM, result
    assert abs(result.error_deg) <= fidelity.ARM_PIVOT_LIMIT_DEG, result
