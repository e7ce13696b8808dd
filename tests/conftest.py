import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TASKS = ROOT / "data" / "tasks"
sys.path.insert(0, str(Path(__file__).resolve().parent))

from stablepush.task import load_task, parse_task  # noqa: E402


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
