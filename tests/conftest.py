import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TASKS = ROOT / "data" / "tasks"
sys.path.insert(0, str(Path(__file__).resolve().parent))

from stablepush.task import load_task, parse_task  # noqa: E402

# Modules that run the simulated arm, a fuzz campaign or thousands of LP cross-checks, and single
# tests of several seconds: `-m "not slow"` leaves them out, so the rest (the mechanics, the
# planner, files, the CLI) runs in about a minute serially, half that on scripts/test.sh's two
# xdist workers. A search with a time limit takes as long on any machine: one that plans goal
# after goal for 1.5 s each (the ledge's, 27 s) is slow like its grid siblings.
SLOW_MODULES = {"test_fuzz", "test_execute", "test_sim_arm", "test_friction_fidelity", "test_reliability",
                "test_robust", "test_point_pushers", "test_cross_check", "test_evaluate", "test_reach", "test_readme", "test_bags",
                "test_calibrate_sim"}
SLOW_TESTS = {
    "test_h_representation_matches_generators",
    "test_large_manipulation_reaches_a_zero_switch_plan_for_nine_of_ten_seeds",
    "test_pivot_turns_the_object_with_a_side_pusher_through_sticking_steps",
    "test_no_goal_the_ledge_cannot_end_at_is_reached_by_a_long_search",
}


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.module.__name__ in SLOW_MODULES or item.originalname in SLOW_TESTS:
            item.add_marker(pytest.mark.slow)


@pytest.fixture(scope="session")
def tasks_dir():
    return TASKS


def task_text(name: str) -> str:
    return (TASKS / f"{name}.yaml").read_text()


def task_with(name: str, edit) -> "object":
    """The shipped task `name` with `edit(dict)` applied, validated as a user's file would be."""
    import yaml

    data = yaml.safe_load(task_text(name))
    edit(data)
    return parse_task(yaml.safe_dump(data), source=f"{name} (edited)")


def shipped(name: str):
    return load_task(TASKS / f"{name}.yaml")
