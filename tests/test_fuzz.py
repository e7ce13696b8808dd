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
    """The API surface (issues 24 and 69): sp.plan_task, sp.check, sp.check_plan, sp.trajectory and
    sp.save_plan with hostile arguments, a Task edited past its loader, another task's models; then
    every public function and value type (stablepush.__all__, design, evaluate_designs, evaluate,
    Batch, Spreads, SequentialTest, Runner, reach_map, SimulatedArm, RunOptions) with generated
    wrong types and values. Each call returns or raises a StablepushError or a TypeError, a bad
    value is refused before any work starts, and no crash by signal; the gaps still open are
    KNOWN_API_GAPS."""
    import re

    summary = _fuzz("api", 300, tmp_path)
    failures = [json.loads(line) for line in (tmp_path / "failures.jsonl").read_text().splitlines()] if (
        tmp_path / "failures.jsonl").exists() else []
    new = [f for f in failures if not any(re.search(gap, f"{f['case']} {f['problem']}") for gap in KNOWN_API_GAPS)]
    assert not new, new[:10]
    assert summary["cases"] == 600 and summary["exit_statuses"].get("refused", 0) > 200

def _fuzz(kind: str, count: int, scratch, timeout: float = 900) -> dict:
    worker = subprocess.run([sys.executable, str(FUZZ), kind, str(count), "2026", str(scratch)], capture_output=True,
                            text=True, preexec_fn=_cap_memory, timeout=timeout)
    current = (scratch / "current").read_text()[:2000] if (scratch / "current").exists() else ""
    assert worker.returncode == 0, f"{kind} worker died ({worker.returncode}) on:\n{current}\n{worker.stderr[-2000:]}"
    return json.loads(worker.stdout.strip().splitlines()[-1])


def test_generated_options_of_every_command_never_end_in_an_internal_error(tmp_path):
    """Issue 69: every command `stablepush --help` lists (plan, check, show, cone, bench, design,
    check-cell, sim-arm, reach, trajectory, execute, evaluate), its options generated from its
    click parameters (legal, edge and hostile values; folders, FIFOs, /dev/null, missing files and
    inputs as outputs), a quarter of evaluate's and execute's runs simulated; sim-arm in a child
    process. Exit 0-3 (5: execute's miss), no traceback, one `error:` line, no input written over."""
    from stablepush_cli.main import cli

    summary = _fuzz("options", 5, tmp_path)
    assert summary["failure_count"] == 0, summary["failures"]
    statuses = summary["exit_statuses"]
    assert {key.split(":")[0] for key in statuses if ":" in key} == set(cli.commands)
    assert "4" not in statuses and "hang" not in statuses and statuses.get("0", 0) > 0
    assert summary["slowest_s"] < 60, summary


def test_generated_robot_models_get_exit_0_1_or_2_with_one_line(tmp_path):
    """Issue 69: generated URDF and MJCF arms, mutated (encodings, names the project uses,
    couplings, includes of a FIFO or a loop, mesh paths, limits, truncation, joint types), given
    to check-cell and arm_model: exit 0, 1 or 2 in one line (or a StablepushError), no hang, the
    model never written over."""
    summary = _fuzz("robots", 40, tmp_path)
    assert summary["failure_count"] == 0, summary["failures"]
    assert summary["cases"] == 40 and set(summary["exit_statuses"]) <= {"0", "1", "2", "returned", "refused"}
    assert summary["exit_statuses"].get("2", 0) > 0 and summary["exit_statuses"].get("0", 0) > 0


# The API's open gaps (issue 69, "The API fuzz"): none left; a class found later is listed here,
# by a pattern of its case and problem, until it is fixed.
KNOWN_API_GAPS: list = []
