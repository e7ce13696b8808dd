"""Hostile inputs, fuzzed: 2,000 mutated task files, 200 mutated plan files, 120 generated meshes
and 80 plans that do not fit their task per run, each given to the CLI (tests/fuzz_cli.py), in
child processes with a memory cap, so that a crash by signal or a runaway allocation fails here
instead of taking pytest down."""
import json
import resource
import subprocess
import sys
from pathlib import Path

FUZZ = Path(__file__).with_name("fuzz_cli.py")
MEMORY_CAP = 3 * 1024 ** 3  # bytes of address space per worker


def _cap_memory():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))


def test_mutated_task_and_plan_files_get_exit_0_1_or_2_with_one_line(tmp_path):
    runs = {}
    for kind, count in (("tasks", 2000), ("plans", 200)):
        scratch = tmp_path / kind
        scratch.mkdir()
        runs[kind] = (scratch, subprocess.Popen([sys.executable, str(FUZZ), kind, str(count), "2026", str(scratch)],
                                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                                preexec_fn=_cap_memory))
    for kind, (scratch, worker) in runs.items():
        out, err = worker.communicate(timeout=900)
        current = (scratch / "current").read_text()[:2000] if (scratch / "current").exists() else ""
        assert worker.returncode == 0, f"{kind} worker died ({worker.returncode}) on:\n{current}\n{err[-2000:]}"
        summary = json.loads(out.strip().splitlines()[-1])
        assert summary["failure_count"] == 0, summary["failures"]
        assert summary["cases"] >= (2000 if kind == "tasks" else 200)
        assert set(summary["exit_statuses"]) <= {"0", "1", "2"}
        # Bounded time per case (a hang guard, not a speed target): planning is limited to 0.02 s.
        assert summary["slowest_s"] < 20.0, summary


def test_generated_meshes_and_plans_that_do_not_fit_their_task_get_one_line(tmp_path):
    """The campaign's new surfaces (issue 24): generated meshes (holes, two bodies, flat, huge,
    damaged bytes; STL, OBJ, PLY, OFF) planned, and valid plan files cut short, reversed or made for
    another goal or model, given to trajectory."""
    for kind, count in (("meshes", 120), ("semantics", 80)):
        scratch = tmp_path / kind
        scratch.mkdir()
        worker = subprocess.run([sys.executable, str(FUZZ), kind, str(count), "2026", str(scratch)],
                                capture_output=True, text=True, preexec_fn=_cap_memory, timeout=900)
        assert worker.returncode == 0, f"{kind} worker died ({worker.returncode}): {worker.stderr[-2000:]}"
        summary = json.loads(worker.stdout.strip().splitlines()[-1])
        assert summary["failure_count"] == 0, summary["failures"]
        assert summary["cases"] == count and set(summary["exit_statuses"]) <= {"0", "1", "2"}
        assert summary["exit_statuses"].get("2", 0) > 0  # the hostile ones were refused


def test_the_python_api_misused_refuses_with_its_own_errors(tmp_path):
    """The API surface (issue 24): sp.plan_task, sp.check, sp.check_plan, sp.trajectory and sp.save_plan
    with hostile arguments, a Task edited past its loader, another task's models. Each call returns
    or raises a StablepushError, TypeError or ValueError: no AttributeError, ZeroDivisionError or
    OverflowError from inside (the first run found 55 of 300), and no crash by signal."""
    worker = subprocess.run([sys.executable, str(FUZZ), "api", "300", "2026", str(tmp_path)], capture_output=True,
                            text=True, preexec_fn=_cap_memory, timeout=900)
    assert worker.returncode == 0, f"api worker died ({worker.returncode}): {worker.stderr[-2000:]}"
    summary = json.loads(worker.stdout.strip().splitlines()[-1])
    assert summary["failure_count"] == 0, summary["failures"]
    assert summary["cases"] == 300 and summary["exit_statuses"].get("refused", 0) > 100
