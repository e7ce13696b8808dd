"""A calibration session: probes chosen by the model (probes.py), run on the arm one at a time,
each outcome folded into the posterior (belief.py), until every friction coefficient that a safe
probe can reach is known to its target, or the probes run out; then the object is pushed back to
the start by a plan of the calibrated task.

Each probe runs as a plan (stablepush.execution.run.run_plan) on a fresh arm session from
`arm_for()`: the same `Arm` and tracker as `stablepush execute`, so a lab's bridge works
unchanged. The object's pose in the grasp that the tracker reports after a probe is where the next
one starts. Grip force and mass are taken as the task gives them (the gripper's setting, a scale)
unless settings.estimate names one of them.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Tuple

from stablepush.calibration.belief import Belief, Interval, grid
from stablepush.calibration.probes import (
    Instrument,
    Probe,
    Unknowns,
    WorldGrid,
    candidates,
    probe_plan,
    probe_world,
    stuck,
)
from stablepush.calibration.settings import PAD_PRODUCT, CalibrationSettings
from stablepush.errors import PlanError
from stablepush.execution.arm import Arm
from stablepush.execution.executor import RunOptions
from stablepush.execution.run import run_plan
from stablepush.plan.search import plan_task
from stablepush.task.model import UNCERTAIN, Task, require_task

LEAST_BITS = 0.02  # a probe expected to tell less is not worth running


@dataclass
class ProbeRecord:
    """One probe as run: which pusher pushed how (`move`, per unit push, `pushes` of them) from
    `start`, what the posterior expected (`p_stuck`, `bits`), the world it was planned in
    (`planned_in`: the task fields of that grid cell), the `outcome` ("stuck", "slipped", or
    "not observed" with `error`), the contact's measured slip and where the object `landed`."""

    pusher: str
    start: Tuple[float, float, float]
    move: Tuple[float, float, float]
    pushes: int
    p_stuck: float
    bits: float
    planned_in: Dict[str, float]
    outcome: str = "not observed"
    slip_mm: Optional[float] = None
    slip_deg: Optional[float] = None
    landed: Optional[Tuple[float, float, float]] = None
    error: Optional[str] = None
    wall_time_s: float = 0.0

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass
class Calibration:
    """What a calibration found: per task field (`gripper.mu`, or the grip force or mass estimated
    instead; `pushers.NAME.mu`) its estimate and
    interval, the fields it could not identify and why, every probe, why it stopped, and the run
    back to the start (`returned`: whether it landed, where, or why not)."""

    task: Task
    estimates: Dict[str, Interval]
    unidentified: Dict[str, str]
    probes: List[ProbeRecord]
    stopped: str
    settings: CalibrationSettings
    returned: Optional[dict] = None
    wall_time_s: float = 0.0

    def calibrated_task(self) -> Task:
        """The task as calibrated, for plans that hold wherever the world lies in the intervals:
        the pads' quantity at its estimate with an uncertainty box (`pad_mu`, or `grip_force` or
        `mass` when that was estimated) of its interval's half-width as a share of the estimate;
        each identified pusher's mu at its interval's low end, with no box of its own: a push
        stable there is stable at any higher mu (a pusher's cone only grows with its mu,
        docs/model.md section 7), so one `pusher_mu` box over every pusher, as wide as the least
        known one's interval, would ask more of the plan than the intervals do. The task's own
        `pusher_mu` is kept where a pusher was not identified."""
        values = {name: interval.low if name.startswith("pushers.") else interval.value
                  for name, interval in self.estimates.items()}
        box = dict(self.task.uncertainty)
        for key, field_name in UNCERTAIN.items():
            if field_name in PAD_PRODUCT and field_name in self.estimates:
                box[key] = _share(self.estimates[field_name])
        if not any(name.startswith("pushers.") for name in self.unidentified):
            box.pop("pusher_mu", None)
        return dataclasses.replace(self.task.with_values(values), uncertainty={k: v for k, v in box.items() if v > 0})

    def as_dict(self) -> dict:
        return {"task": self.task.name, "stopped": self.stopped,
                "estimates": {name: i.as_dict() for name, i in self.estimates.items()},
                "unidentified": dict(self.unidentified), "probes": [p.as_dict() for p in self.probes],
                "uncertainty": self.calibrated_task().uncertainty, "returned": self.returned,
                "at_grid_edge": self.at_grid_edge(), "settings": dataclasses.asdict(self.settings),
                "wall_time_s": self.wall_time_s}

    def at_grid_edge(self) -> Dict[str, str]:
        """The estimates whose interval reaches an end of the grid (`low` or `high`): the posterior
        knows only the task's value times 1 -+ settings.spread, so a world beyond it is reported at
        that end, and the other estimates lean to make up for it. A grid that starts at 0 (no
        lower value is possible) has no low end to reach."""
        out = {}
        for name, interval in self.estimates.items():
            low, high = grid(self.task.value(name), self.settings.spread, 2)
            if interval.high >= high * (1.0 - 1e-9):
                out[name] = "high"
            elif low > 0.0 and interval.low <= low * (1.0 + 1e-9):
                out[name] = "low"
        return out

    def describe(self) -> List[str]:
        """The lines `stablepush calibrate` prints."""
        lines = [f"{self.task.name}: {len(self.probes)} probe(s), stopped: {self.stopped} "
                 f"({self.wall_time_s:.1f} s)"]
        edges = self.at_grid_edge()
        for name, i in self.estimates.items():
            lines.append(f"  {name}: {i.value:.4g} ({self.settings.level:.0%} interval {i.low:.4g} to {i.high:.4g}, "
                         f"+-{_share(i):.1%}; the task said {self.task.value(name):.4g})")
            if name in edges:
                factor = 1.0 + self.settings.spread if edges[name] == "high" else 1.0 - self.settings.spread
                lines.append(f"    at the grid's {edges[name]} end (the task's value x{factor:g}): the world may lie "
                             f"beyond it, and the other estimates then lean to make up for it")
        for name, why in self.unidentified.items():
            lines.append(f"  {name}: not identified: {why}")
        if self.returned is not None:
            lines.append(f"  back to the start: {self.returned['outcome']}")
        return lines


def _share(interval: Interval) -> float:
    return interval.half_width / interval.value if interval.value > 0 else interval.half_width


def instrument_of(task: Task, settings: CalibrationSettings) -> Instrument:
    """How `task`'s probes are read: settings.boundary a share of the pads' sliding friction."""
    return Instrument(settings.pushes, settings.error_rate,
                      settings.boundary * 2.0 * task.gripper.mu * task.gripper.grip_force)


def estimates_of(belief: Belief, unknowns: Unknowns, probed: List[bool], settings: CalibrationSettings,
                 pushes: str = "safe push") -> Tuple[Dict[str, Interval], Dict[str, str]]:
    """Each unknown's interval, or why it has none: `probed[i]`, whether any of the `pushes` by
    pusher i could tell anything (its outcome uncertain over the grid)."""
    estimates: Dict[str, Interval] = {}
    unidentified: Dict[str, str] = {}
    if not belief.observations:
        unidentified.update({name: "no probe was observed" for name in unknowns.pad_fields})
    elif len(unknowns.pad_fields) == 1:
        estimates[unknowns.pad_field] = belief.pad_interval(settings.level)
    else:
        pad = belief.pad_interval(settings.level)
        scales = sorted(unknowns.product_scale(v) for v in (pad.value, pad.low, pad.high))
        why = (f"enters the stable-push test only through the product {' x '.join(PAD_PRODUCT[:2])} / "
               f"{PAD_PRODUCT[2]} (docs/model.md section 7), which the probes put at {scales[1]:.3g} "
               f"({scales[0]:.3g} to {scales[2]:.3g}) times the task's; name one of "
               f"{', '.join(unknowns.pad_fields)} alone with --estimate to read the product as that one")
        unidentified.update({name: why for name in unknowns.pad_fields})
    for i, name in enumerate(unknowns.pusher_names):
        field_name = f"pushers.{name}.mu"
        if not probed[i]:
            unidentified[field_name] = (f"no {pushes} by {name} from where the object was flips within the grid "
                                        f"(its mu times {1 - settings.spread:g} to {1 + settings.spread:g})")
        elif not belief.informative(i):
            unidentified[field_name] = f"no push by {name} that could tell was observed"
        else:
            estimates[field_name] = belief.pusher_interval(i, settings.level)
    return estimates, unidentified


ArmFactory = Callable[[], Arm]
ProbeProgress = Callable[[ProbeRecord, int], None]


class Session:
    """A calibration of `task` on the arms `arm_for` makes (one per run): `step()` runs the next
    probe, `result()` says what is known; `calibrate` runs the whole of it."""

    def __init__(self, task: Task, arm_for: ArmFactory, settings: CalibrationSettings = CalibrationSettings()):
        self.task = require_task(task)
        self.arm_for, self.settings = arm_for, settings
        self.unknowns = Unknowns.of(task, settings.spread, settings.grid, settings.estimate)
        self.worlds = WorldGrid(task, self.unknowns)
        self.belief: Belief = self.unknowns.belief()
        self.instrument = instrument_of(task, settings)
        self.at: Tuple[float, float, float] = tuple(task.start)  # type: ignore[assignment]
        self.probes: List[ProbeRecord] = []
        self.ever_informative = [False] * len(task.pushers)
        self.started = time.perf_counter()
        self.stopped = ""

    def done(self) -> Optional[str]:
        """Why to stop now (None: go on)."""
        if len(self.probes) >= self.settings.max_probes:
            return f"the probe budget ({self.settings.max_probes})"
        if self.belief.observations and self._targets_met():
            return "every identified mu within its target"
        return None

    def _targets_met(self) -> bool:
        pad_target, pusher_target = self.settings.target
        if _share(self.belief.pad_interval(self.settings.level)) > pad_target:
            return False
        return all(_share(self.belief.pusher_interval(i, self.settings.level)) <= pusher_target
                   for i, seen in enumerate(self.ever_informative) if seen)

    def step(self) -> Optional[ProbeRecord]:
        """Choose and run the next probe; None when no safe probe is worth running."""
        if self.worlds.at != self.at:  # gravity on each feature as the object is turned now
            self.worlds = WorldGrid(self.task, self.unknowns, self.at)
        options = candidates(self.task, self.worlds, self.belief, self.at, self.instrument)
        for p in options:
            self.ever_informative[p.index] |= p.bits >= LEAST_BITS
        options = [p for p in options if p.bits >= LEAST_BITS]
        for probe in options[:3]:  # the best the arm can follow in its cell
            record = self._run(probe)
            if record is not None:
                self.probes.append(record)
                if record.outcome in ("stuck", "slipped"):
                    self.belief.observe(probe.index, probe.chance, record.outcome == "stuck")
                if record.landed is not None:
                    self.at = record.landed
                return record
        return None

    def _run(self, probe: Probe) -> Optional[ProbeRecord]:
        world = probe_world(self.task, self.unknowns, self.belief, probe)
        planned_in = {name: world.value(name) for name in (self.unknowns.pad_field, f"pushers.{probe.pusher}.mu")}
        record = ProbeRecord(probe.pusher, probe.start, probe.move, probe.pushes, probe.p_stuck, probe.bits, planned_in)
        plan = probe_plan(world, probe)
        started = time.perf_counter()
        try:
            run = run_plan(world, plan, self.arm_for(), RunOptions(rate_hz=self.settings.rate_hz, guard=None))
        except PlanError:  # the arm cannot follow it in its cell: the next best
            return None
        record.wall_time_s = time.perf_counter() - started
        if run.fault is not None:
            record.error = f"the run ended in a fault: {run.fault.reason}"
            return record
        report = run.report_or_fault()
        landed = report.landed_in_grasp
        if landed is not None:
            record.landed = tuple(float(landed[k]) for k in ("x", "z", "theta"))  # type: ignore[assignment]
        contact = report.contacts[0].__dict__ if report.contacts else {}
        observed = stuck(contact)
        record.slip_mm, record.slip_deg = contact.get("slip_mm"), contact.get("slip_deg")
        if observed is None:
            record.error = "the arm reports no object_in_grasp: calibration needs a tracker"
        else:
            record.outcome = "stuck" if observed else "slipped"
        return record

    def result(self, stopped: str) -> Calibration:
        estimates, unidentified = estimates_of(self.belief, self.unknowns, self.ever_informative, self.settings)
        return Calibration(self.task, estimates, unidentified, self.probes, stopped, self.settings,
                           wall_time_s=time.perf_counter() - self.started)

    def back_to_start(self, calibration: Calibration) -> dict:
        """Plan from where the object is to the task's start in the calibrated task and run it."""
        if self.task.tolerance.within(self.at, self.task.start):
            return {"outcome": "at the start already", "pose": list(self.at)}
        calibrated = calibration.calibrated_task()
        back = dataclasses.replace(calibrated.with_start(self.at), goal=self.task.start)
        plan = plan_task(back, seed=self.task.planner.seed)
        if not plan.solved:
            return {"outcome": f"no plan back to the start ({plan.outcome})", "pose": list(self.at)}
        run = run_plan(back, plan, self.arm_for(), RunOptions(rate_hz=self.settings.rate_hz))
        if run.fault is not None:
            return {"outcome": f"the run back ended in a fault: {run.fault.reason}", "pose": list(self.at)}
        report = run.report_or_fault()
        landed = report.landed_in_grasp
        pose = [float(landed[k]) for k in ("x", "z", "theta")] if landed is not None else None
        return {"outcome": "landed" if report.success else f"missed ({report.verdict and report.verdict.cause})",
                "pose": pose}


def calibrate(task: Task, arm_for: ArmFactory, settings: CalibrationSettings = CalibrationSettings(),
              progress: Optional[ProbeProgress] = None) -> Calibration:
    """Calibrate `task`'s friction on the arms `arm_for()` makes (module docstring). Ctrl-C
    (KeyboardInterrupt) between or during a probe stops it there: what was measured is kept (a
    probe cut short is not counted) and nothing more is run."""
    session = Session(task, arm_for, settings)
    stopped = None
    try:
        while stopped is None:
            stopped = session.done()
            if stopped is None:
                record = session.step()
                if record is None:
                    stopped = "no safe probe left that is worth running"
                elif progress is not None:
                    progress(record, len(session.probes))
    except KeyboardInterrupt:
        stopped = "interrupted"
    calibration = session.result(stopped)
    if settings.return_to_start and stopped != "interrupted":
        calibration.returned = session.back_to_start(calibration)
    return calibration
