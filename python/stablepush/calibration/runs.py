"""Calibration from runs already made (`calibrate --from RUN.json`): every contact of a run's
report is a probe the plan chose, its pushes the report's `steps`, its outcome the contact's
measured slip. A production plan's pushes are stable with a margin across its task's box, so its
contacts stick wherever the world lies inside that box: they bound the friction from one side
only, and narrow the intervals only where a world lies outside it (docs/calibrate.md).

The same pushes run again tell what they told the first time: where the simulator or the model
errs on a push, it errs on every run of it, so repeats are not fresh evidence. Counted as such, 20
runs of one plan excluded the world's mu from the pads' interval in 3 of 12 hidden worlds
(benchmarks/calibrate.py --runs 20). So the contacts that made the same pushes are one
observation, their majority outcome (a tie: none); runs of one plan start where the tracker
sees the object, so "the same" is within SAME_PUSH."""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, List, Mapping, Sequence, Tuple

import numpy as np

from stablepush import strict_json
from stablepush.calibration.probes import Unknowns, WorldGrid, stuck
from stablepush.calibration.session import Calibration, CalibrationSettings, ProbeRecord, estimates_of, instrument_of
from stablepush.errors import SettingError
from stablepush.inputs import read_capped
from stablepush.outputs import protect_input
from stablepush.task.model import Task, require_task

# Two contacts make the same push when each of their steps is within this (mm, deg): a run starts
# where the tracker sees the object, so runs of one plan shift its steps by the tracker's noise
# (0.02-0.05 mm), which moves the push's margins by nothing the grid resolves.
SAME_PUSH = (0.1, 0.1)
MAX_REPORT_BYTES = 64 * 1024 * 1024  # a run report's JSON: a long closed-loop run's is a few MB


def read_run_report(path: str) -> Mapping[str, Any]:
    """A run's JSON report (`execute --json`) from `path`: SettingError naming the file when it
    cannot be read or is not a report."""
    try:
        report = strict_json.loads(read_capped(path, MAX_REPORT_BYTES).decode("utf-8"))
        protect_input(path, "a run report")
    except (OSError, ValueError) as exc:  # no such file, not a regular one, too large, not UTF-8 or JSON
        raise SettingError(str(path), f"cannot read a run report: {' '.join(str(exc).split())[:200]}") from None
    if not isinstance(report, dict) or "contacts" not in report:
        raise SettingError(str(path), "not a run report (`stablepush execute --json` writes one)")
    return report


def _steps(report: Mapping[str, Any], source: str) -> List[Tuple[Tuple[float, float, float], str]]:
    steps = report.get("steps")
    if not isinstance(steps, list) or not steps:
        raise SettingError(source, "the report has no `steps` (the run's pushes): a report of stablepush 0.x "
                                   "before calibration; run the plan again to record them")
    out = []
    for k, step in enumerate(steps):
        if not isinstance(step, list) or len(step) != 4:
            raise SettingError(f"{source}: steps[{k}]", "must be [x mm, z mm, theta deg, pusher]")
        out.append(((float(step[0]), float(step[1]), float(step[2])), step[3]))
    return out


@dataclass
class _Push:
    """The pushes of the runs' contacts that are one push (`same`): by `pusher` through `poses`
    (x mm, z mm, theta deg per step), its least `margins` over the grid and every outcome seen."""

    pusher: int
    poses: np.ndarray
    margins: np.ndarray
    outcomes: List[bool]

    def same(self, pusher: int, poses: np.ndarray) -> bool:
        """Whether a contact by `pusher` through `poses` makes this push: each step within SAME_PUSH."""
        return (pusher == self.pusher and poses.shape == self.poses.shape
                and bool((np.abs(poses - self.poses) <= np.array([SAME_PUSH[0], SAME_PUSH[0], SAME_PUSH[1]])).all()))


def calibrate_from_runs(task: Task, reports: Sequence[Tuple[str, Mapping[str, Any]]],
                        settings: CalibrationSettings = CalibrationSettings()) -> Calibration:
    """What the runs' `reports` ((source, report as JSON) pairs, written by `execute --json` or
    evaluate's trials) say of `task`'s friction: each contact's pushes, stable or not over the
    grid, against its observed stick or slip."""
    require_task(task)
    started = time.perf_counter()
    unknowns = Unknowns.of(task, settings.spread, settings.grid, settings.estimate)
    worlds = WorldGrid(task, unknowns)
    belief = unknowns.belief()
    instrument = instrument_of(task, settings)
    records: List[ProbeRecord] = []
    seen = [False] * len(task.pushers)
    pushes: List[_Push] = []
    for source, report in reports:
        if report.get("task") != task.name:
            raise SettingError(source, f"a run of task {str(report.get('task'))[:80]!r}, not {task.name!r}")
        steps = _steps(report, source)
        for contact in report.get("contacts") or []:
            outcome = stuck(contact)
            first, last = int(contact["first_step"]), int(contact["last_step"])
            pusher = task.pusher_index(contact["pusher"], f"{source}: contacts[].pusher")
            poses = np.array([pose for pose, _ in steps[first - 1:last + 1]])
            push = next((p for p in pushes if p.same(pusher, poses)), None)
            if push is None:
                margins = np.full((len(unknowns.pad_axis),) * 2, np.inf)
                for before, after in zip(poses[:-1], poses[1:]):
                    margins = np.minimum(margins, worlds.margins([tuple(before)], tuple(after - before))[:, :, pusher])
                push = _Push(pusher, poses, margins, [])
                pushes.append(push)
                seen[pusher] |= bool((margins > 0.0).any() and not (margins > 0.0).all())
            record = ProbeRecord(contact["pusher"], steps[first - 1][0], (0.0, 0.0, 0.0), last - first + 1,
                                 p_stuck=float("nan"), bits=float("nan"), planned_in={},
                                 slip_mm=contact.get("slip_mm"), slip_deg=contact.get("slip_deg"))
            if outcome is not None:
                push.outcomes.append(outcome)
                record.outcome = "stuck" if outcome else "slipped"
            records.append(record)
    for push in pushes:
        stuck_count = sum(push.outcomes)
        if 2 * stuck_count != len(push.outcomes):  # a tie (or none observed) tells nothing
            belief.observe(push.pusher, instrument.chance(push.margins), 2 * stuck_count > len(push.outcomes))
    estimates, unidentified = estimates_of(belief, unknowns, seen, settings, pushes="push of the runs")
    return Calibration(task, estimates, unidentified, records, f"{len(reports)} run report(s) read", settings,
                       wall_time_s=time.perf_counter() - started)
