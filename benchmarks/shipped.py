"""The example tasks in the repository's data/tasks/, which the benchmarks run when no task is named.

They are found next to this folder, so a copy of benchmarks/ run from elsewhere has none; the
benchmarks that run every example then stop and say so rather than print an empty table.
"""
from pathlib import Path
from typing import List

TASKS = Path(__file__).resolve().parent.parent / "data" / "tasks"


def shipped_tasks(more: bool = True) -> List[Path]:
    """The task files of data/tasks/ and, with `more`, of data/tasks/more/, each folder sorted by name."""
    paths = sorted(TASKS.glob("*.yaml")) + (sorted((TASKS / "more").glob("*.yaml")) if more else [])
    if not paths:
        raise SystemExit(f"no example tasks in {TASKS}: name the task files, or run the benchmarks/ of a "
                         "repository clone")
    return paths
