"""A run of a plan on an arm, with what it writes: `run_plan` streams the plan (executor.py) to
any arm behind the port (arm.py), records the run when an output needs it, and writes each output
(the JSON report, an MCAP bag, a video: `stablepush.sim.mujoco.video.RunVideo`) whether the run landed,
missed or ended in a fault. `stablepush execute`, evaluate's trials, the fidelity contract and the
benchmarks all run plans through it.
"""
from __future__ import annotations

import abc
import json
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

from stablepush.errors import ArmFault, OutputError
from stablepush.execution.arm import Arm
from stablepush.execution.bags import RunRecording
from stablepush.execution.executor import Progress, RunOptions, execute_plan
from stablepush.execution.report import ExecutionReport, fault_report
from stablepush.outputs import require_suffix, write_atomically
from stablepush.plan.plan import Plan
from stablepush.task.model import Task


@dataclass
class RunResult:
    """How a run ended: its `report` (None after a fault) or its `fault` (None after a report), the
    `recording` when one was kept, a line per output written (`written`), and each output that
    could not be written with its error (`failed`)."""

    task: Task
    plan: Plan
    options: RunOptions
    report: Optional[ExecutionReport] = None
    fault: Optional[ArmFault] = None
    recording: Optional[RunRecording] = None
    written: List[str] = field(default_factory=list)
    failed: List[Tuple["RunOutput", OutputError]] = field(default_factory=list)

    @property
    def success(self) -> Optional[bool]:
        """Landed (True), missed or faulted (False), or not judged (None: the arm reports no object)."""
        return False if self.fault is not None else self._report().success

    def report_or_fault(self) -> ExecutionReport:
        """The run's report; its ArmFault raised when it ended in one."""
        if self.fault is not None:
            raise self.fault
        return self._report()

    def _report(self) -> ExecutionReport:
        assert self.report is not None, "a run that ended in no fault has its report (run_plan)"
        return self.report

    def as_dict(self) -> dict:
        """The run's JSON report: ExecutionReport.as_dict, or after a fault `fault_report`."""
        if self.fault is not None:
            return fault_report(self.task, self.fault, self.options.success_tolerance)
        return self._report().as_dict()

    def write(self, outputs: Sequence["RunOutput"]) -> None:
        """Write each of `outputs`: a line each in `written`, or, for one that cannot be written
        (OutputError), the error in `failed`; one output's failure does not keep the others back."""
        for output in outputs:
            try:
                line = output.write(self)
            except OutputError as exc:
                self.failed.append((output, exc))
                continue
            if line:
                self.written.append(line)


class RunOutput(abc.ABC):
    """Something a run writes when it ends, landed, missed or faulted."""

    #: Whether it needs every acknowledged waypoint recorded (a bag, a video).
    records: bool = False

    @abc.abstractmethod
    def write(self, run: RunResult) -> Optional[str]:
        """Write it; the line that says where (None: nothing to write for this run). OutputError
        when it cannot be written."""


class JsonReport(RunOutput):
    """The run's report as JSON (RunResult.as_dict) at `path`."""

    def __init__(self, path: str):
        self.path = path

    def write(self, run: RunResult) -> str:
        write_atomically(self.path, json.dumps(run.as_dict(), indent=1) + "\n")
        return f"report written to {self.path}"


class BagRecording(RunOutput):
    """The recorded run and its report as one MCAP bag at `path` (bags.RunRecording.write), stamped
    from `start_ns` (Unix ns; None: when the run started)."""

    records = True

    def __init__(self, path: str, start_ns: Optional[int] = None):
        require_suffix("a run's bag", path, (".mcap",))
        self.path = path
        self.start_ns = start_ns

    def write(self, run: RunResult) -> str:
        assert run.recording is not None, "a run with an output that records is recorded (run_plan)"
        run.recording.write(self.path, run.as_dict(), start_ns=self.start_ns)
        return f"run recorded to {self.path}"


def recording_for(task: Task, plan: Plan, options: RunOptions, outputs: Sequence[RunOutput]) -> Optional[RunRecording]:
    """A recording of the run when one of `outputs` needs it (a bag, a video), else None."""
    if not any(output.records for output in outputs):
        return None
    return RunRecording.for_run(task, plan, options.closed_loop is not None)


def run_plan(task: Task, plan: Plan, arm: Arm, options: RunOptions = RunOptions(), outputs: Sequence[RunOutput] = (),
             *, progress: Optional[Progress] = None, recording: Optional[RunRecording] = None) -> RunResult:
    """Run `plan` of `task` on `arm` (execute_plan) and write `outputs` (RunResult.write). A fault
    ends the run, not the call: it is the result's `fault`, and the outputs are written for it
    too. The run is recorded into `recording`, else into one of its own when an output needs it
    (`recording_for`), with the arm's model when the arm has one (Arm.robot_description). PlanError,
    before anything moves, when the plan does not belong to the task."""
    recording = recording if recording is not None else recording_for(task, plan, options, outputs)
    if recording is not None and recording.robot is None:
        recording.robot = arm.robot_description()
    result = RunResult(task, plan, options, recording=recording)
    try:
        result.report = execute_plan(task, plan, arm, options, progress=progress, record=recording)
    except ArmFault as fault:
        result.fault = fault
    result.write(outputs)
    return result
