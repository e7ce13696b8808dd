"""The planner and environment sections as typed values (stablepush.PlannerSettings,
stablepush.task.model.Cell): the task file's form in and out, the core's declared parameters, and
a field of the wrong shape refused by name."""
import dataclasses

import pytest

import stablepush as sp
from stablepush.task.model import PLANNER_DEFAULTS, Cell

from conftest import shipped


def test_a_task_files_planner_section_is_typed_settings_that_round_trip():
    task = shipped("pivoting")
    settings = task.planner
    assert isinstance(settings, sp.PlannerSettings)
    assert settings.step == (1.0, 1.0) and isinstance(settings.seed, int)
    assert sp.PlannerSettings.from_mapping(settings.as_dict()) == settings
    assert set(settings.as_dict()) >= set(PLANNER_DEFAULTS)


def test_replace_changes_what_it_names_tuning_keys_too_and_none_leaves_a_key_as_it_is():
    settings = sp.PlannerSettings(seed=7, tolerance=(0.5, 0.5))
    changed = settings.replace(time_limit=2, pivot_steps=1, seed=None)
    assert changed.time_limit == 2.0 and changed.seed == 7 and changed.tolerance == (0.5, 0.5)
    assert changed.tuning == {"pivot_steps": 1} and settings.tuning == {}
    assert changed.core_parameters() == {"seed": "7", "max_switches": "1", "pivot_steps": "1"}


@pytest.mark.parametrize("changes, says", [
    ({"seed": 1.5}, "planner.seed must be an integer"),
    ({"max_switches": True}, "planner.max_switches must be an integer"),
    ({"step": (1.0,)}, "planner.step must be 2 numbers"),
    ({"tolerance": (1.0, float("nan"))}, "planner.tolerance: must be finite"),
    ({"time_limit": "10"}, "planner.time_limit must be a number"),
    ({"goal_biass": 0.1}, "planner.goal_biass: not a planner setting"),
])
def test_a_setting_of_the_wrong_shape_is_refused_by_name_in_code_too(changes, says):
    with pytest.raises((TypeError, ValueError), match=says):
        sp.PlannerSettings().replace(**changes)
    with pytest.raises((TypeError, ValueError), match=says):  # a task edited with a mapping
        dataclasses.replace(shipped("pivoting"), planner={**PLANNER_DEFAULTS, **changes})


def test_a_task_edited_with_settings_plans_as_one_read_from_its_file():
    task = shipped("horizontal-offset-high-mu")
    edited = dataclasses.replace(task, planner=task.planner.replace(tolerance=[0.5, 0.5]))
    from_mapping = dataclasses.replace(task, planner={**task.planner.as_dict(), "tolerance": [0.5, 0.5]})
    assert edited == from_mapping
    assert sp.plan_task(edited, seed=1).waypoints == sp.plan_task(from_mapping, seed=1).waypoints


def test_the_environment_section_is_a_typed_cell_that_round_trips():
    task = shipped("horizontal-offset-high-mu")
    cell = task.environment
    assert isinstance(cell, Cell) and cell.home == (450.0, 0.0, 300.0) and cell.end_on_feature is True
    assert Cell.from_mapping(cell.as_dict()) == cell
    edited = dataclasses.replace(task, environment={**cell.as_dict(), "retract": 30})
    assert edited.environment == dataclasses.replace(cell, retract=30.0)


@pytest.mark.parametrize("changes, says", [
    ({"home": [0, 0]}, "environment.home must be 3 numbers"),
    ({"retract": float("inf")}, "environment.retract: must be finite"),
    ({"end_on_feature": "yes"}, "environment.end_on_feature must be true or false"),
    ({"features": {"left": [0, 0, 0]}}, "environment.features.left must be 4 numbers"),
])
def test_a_cell_of_the_wrong_shape_is_refused_by_name_in_code_too(changes, says):
    with pytest.raises((TypeError, ValueError), match=says):
        dataclasses.replace(shipped("pivoting"), environment={**Cell().as_dict(), **changes})
