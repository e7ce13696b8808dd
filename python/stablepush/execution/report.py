"""The report of a run on an arm: what the arm confirmed, where the object landed in the grasp,
how each contact went, the closed loop's corrections and the verdict (verdict.py); `describe()`
gives it as the lines `stablepush execute` prints, `as_dict()` as its JSON.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence

from stablepush.errors import ArmFault
from stablepush.execution.closed_loop import Replan
from stablepush.execution.verdict import Verdict, success_tolerance
from stablepush.pose import Pose, Tolerance
from stablepush.task.model import Task

# Past this change in the grasp when the last feature lets go (mm, deg), the grasp alone does not
# hold the final pose against gravity: ExecutionReport.release_moved.
RELEASE_MOVE = (0.5, 0.5)


@dataclass
class ContactRecord:
    """How one stay on a feature went, measured in the world at the middle of the pusher's segment:
    `carried_mm`, how far the object rode with the hand into the push before the feature stopped
    it (a feature that far beyond its place along the push), and `slip_mm` / `slip_deg`, its motion
    after that, while the pusher pushed (zero when the pusher stuck). `found_mm`: where the guarded
    approach (guard.py) found the feature, mm beyond its place along the approach (negative: short
    of it); None when the approach was not guarded or met nothing within its reach. `seated_deg`:
    how far the object, at rest on the feature after the contact's first push, was turned in the
    world from where the plan holds it (about y, deg); past the guard's `seat_deg` the contact's
    other pushes were re-based there. None when not guarded or the contact is one push."""

    pusher: str
    first_step: int
    last_step: int
    slip_mm: Optional[float] = None
    slip_deg: Optional[float] = None
    carried_mm: Optional[float] = None
    feature_met: Optional[bool] = None  # False: the object rode with the hand through the whole contact
    found_mm: Optional[float] = None
    seated_deg: Optional[float] = None


@dataclass
class ExecutionReport:
    task: str
    resumed_from: int
    last_confirmed_step: int
    total_steps: int
    waypoints: int
    planned_final: Sequence[float]  # x mm, z mm, theta deg
    goal: Sequence[float]  # the task's goal, x mm, z mm, theta deg
    # The object in the grasp as the arm reports it (a simulator does): at the end of the last push,
    # still resting on the pusher, and at rest after the gripper has backed it off the feature (the
    # same pose when the run ends on the feature, environment.end_on_feature).
    final_in_grasp: Optional[Dict[str, float]]
    released_in_grasp: Optional[Dict[str, float]] = None
    contacts: List[ContactRecord] = field(default_factory=list)
    features: List[dict] = field(default_factory=list)
    wall_time_s: float = 0.0
    sim_steps_per_s: Optional[float] = None
    # "off", "on", or "no tracker" (closed loop asked for, but the arm reports no object_in_grasp)
    closed_loop: str = "off"
    guard: str = "off"  # the guarded approach (guard.py): "off", "on", or "no tracker"
    replans: List[Replan] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)  # execution_warnings(task)
    engine: Optional[str] = None  # the simulator that ran it, as the arm says ("mujoco"); None for a real arm
    simulated_geometry: Optional[str] = None  # the solid the simulator made of the object, as it says
    verdict: Optional[Verdict] = None  # whether it landed, and why not (stablepush.execution.verdict)
    ends_on_feature: bool = False  # the task's environment.end_on_feature: no release at the end
    # The run's steps as run (the plan's, or as the guard and the closed loop spliced them): each
    # [x mm, z mm, theta deg, pusher], the start's pusher None; the contacts' steps index them.
    steps: List[list] = field(default_factory=list)

    @property
    def success(self) -> Optional[bool]:
        """Whether the object landed at the goal within the verdict's tolerance (None: not measured)."""
        return self.verdict.success if self.verdict is not None else None

    @property
    def final_error(self) -> Optional[Dict[str, float]]:
        """Final pose in the grasp minus the plan's: x, z mm, theta deg, and the distance mm."""
        return _error(self.final_in_grasp, self.planned_final)

    @property
    def landed_in_grasp(self) -> Optional[Dict[str, float]]:
        """Where the object came to rest in the grasp, the pose the verdict judges: after the
        release when the arm reports it, else (and on a run that ends on its feature) at the end of
        the last push."""
        if self.ends_on_feature or self.released_in_grasp is None:
            return self.final_in_grasp
        return self.released_in_grasp

    @property
    def goal_error(self) -> Optional[Dict[str, float]]:
        """Where the object came to rest in the grasp minus the task's goal (the plan may stop
        within its tolerance)."""
        return _error(self.landed_in_grasp, self.goal)

    @property
    def release_change(self) -> Optional[Dict[str, float]]:
        """How the object moved in the grasp when the last feature let go (x, z mm, theta deg): nonzero
        when the grasp alone cannot hold the final pose against gravity."""
        if self.final_in_grasp is None or self.released_in_grasp is None or self.ends_on_feature:
            return None
        dx, dz, dtheta = Pose.of(self.released_in_grasp).minus(self.final_in_grasp)
        return {"x": dx, "z": dz, "theta": dtheta}

    @property
    def release_moved(self) -> bool:
        """Whether the object moved in the grasp by more than RELEASE_MOVE when the last feature let
        go: the grasp alone does not hold the final pose against gravity."""
        change = self.release_change
        return change is not None and (math.hypot(change["x"], change["z"]) > RELEASE_MOVE[0]
                                       or abs(change["theta"]) > RELEASE_MOVE[1])

    def describe(self, verbose: bool = False) -> List[str]:
        """The report in lines, as `stablepush execute` prints them: a line per correction of the
        closed loop and per contact with `verbose`, else one line summing each up."""
        lines = [f"{self.task}: steps {self.resumed_from + 1}-{self.last_confirmed_step} of {self.total_steps} "
                 f"confirmed, {self.waypoints} waypoints in {self.wall_time_s:.1f} s"
                 + (f" ({self.sim_steps_per_s:.0f} simulation steps/s)" if self.sim_steps_per_s else "")]
        if self.simulated_geometry:
            lines.append(f"simulated as: {self.simulated_geometry}")
        if self.final_error is None:
            return lines + ["the arm does not report the object, so the final pose in the grasp is not measured"]
        lines += self._landing_lines()
        if self.guard == "no tracker":
            lines.append("guard: the arm reports no object_in_grasp (no tracker), so each approach ended where the "
                         "plan puts its feature")
        if self.closed_loop == "no tracker":
            lines.append("closed loop: the arm reports no object_in_grasp (no tracker), so the plan ran open loop")
        if verbose:
            lines += [f"  {_describe_replan(r, self.goal)}" for r in self.replans]
            lines += [f"  {_describe_contact(c)}" for c in self.contacts if c.slip_mm is not None]
        else:
            lines += self._summary_lines()
        if self.verdict is not None and self.verdict.success is not None:
            lines.append(f"verdict: {self.verdict.detail}" + (f" [cause: {self.verdict.cause}]"
                                                               if self.verdict.cause else ""))
        return lines

    def _landing_lines(self) -> List[str]:
        """Where the object was on its last feature, and where it came to rest after the release."""
        err, f = self.final_error, self.final_in_grasp
        assert err is not None and f is not None, "describe asks it of a run whose object was measured"
        x, z, th = self.planned_final
        lines = [f"on the last feature, in the grasp: x {f['x']:.3f} z {f['z']:.3f} mm, theta {f['theta']:.3f} deg "
                 f"(plan {x:.3f}, {z:.3f}, {th:.3f}); error {err['distance']:.3f} mm, {err['theta']:+.3f} deg"]
        change = self.release_change
        if self.ends_on_feature:
            lines.append("the run ends with the object on its last feature (environment.end_on_feature), and is "
                         "judged there")
        elif change is not None:
            r = self.released_in_grasp
            assert r is not None, "a release change is measured from it"
            lines.append(f"at rest after the release: x {r['x']:.3f} z {r['z']:.3f} mm, theta {r['theta']:.3f} deg; "
                         f"it moved {math.hypot(change['x'], change['z']):.3f} mm, {change['theta']:+.3f} deg when "
                         f"the feature let go")
        return lines

    def _summary_lines(self) -> List[str]:
        """The corrections and the contacts in a line each (`verbose` gives each, as_dict keeps all)."""
        lines = []
        taken = [r for r in self.replans if r.solved and r.pushes]
        failed = [r for r in self.replans if not r.solved]
        if self.replans:
            last = f"; the last found none: {failed[-1].failure}" if failed else ""
            lines.append(f"closed loop: {len(self.replans)} comparison(s) off the plan, {len(taken)} correction(s) "
                         f"taken, {len(failed)} with none found{last} (each with -v)")
        measured = [c for c in self.contacts if c.slip_mm is not None]
        if measured:
            worst = max(measured, key=lambda c: c.slip_mm or 0.0)  # each measured: slip_mm set
            carried = max(c.carried_mm or 0.0 for c in measured)
            lines.append(f"{len(measured)} contact(s): the most slip at a pusher {worst.slip_mm:.3f} mm, "
                         f"{worst.slip_deg:.3f} deg ({worst.pusher}, steps {worst.first_step}-{worst.last_step}); "
                         f"the most carried to a feature {carried:.3f} mm (each with -v)")
        return lines

    def as_dict(self) -> dict:
        verdict = self.verdict.as_dict() if self.verdict is not None else {}
        return {
            "task": self.task, "success": verdict.get("success"), "tolerance": verdict.get("tolerance"),
            "cause": verdict.get("cause"), "verdict": verdict.get("detail"), "engine": self.engine,
            "simulated_geometry": self.simulated_geometry,
            "resumed_from": self.resumed_from, "last_confirmed_step": self.last_confirmed_step,
            "total_steps": self.total_steps, "waypoints": self.waypoints, "planned_final": list(self.planned_final),
            "goal": list(self.goal), "final_in_grasp": self.final_in_grasp, "final_error": self.final_error,
            "goal_error": self.goal_error,
            "released_in_grasp": self.released_in_grasp, "landed_in_grasp": self.landed_in_grasp,
            "release_change": self.release_change,
            "release_moved": self.release_moved, "ends_on_feature": self.ends_on_feature,
            "warnings": list(self.warnings),
            "contacts": [c.__dict__ for c in self.contacts], "features": self.features,
            "wall_time_s": self.wall_time_s, "sim_steps_per_s": self.sim_steps_per_s,
            "closed_loop": self.closed_loop, "guard": self.guard, "replans": [r.as_dict() for r in self.replans],
            "steps": [list(step) for step in self.steps],
        }


def _describe_replan(r: Replan, goal: Sequence[float]) -> str:
    """One comparison of the closed loop: when, how far off, and what it did."""
    off, ref = {"off_goal": (r.measured, goal), "plan_short": (r.planned, goal)}.get(r.trigger, (r.measured, r.planned))
    dx, dz, dth = (m - p for m, p in zip(off, ref))
    if r.solved and r.pushes == 0:
        outcome = "within the final tolerance of the goal already; nothing to correct"
    elif r.solved:
        kept = ", starting with the pusher in contact" if r.kept_pusher and len(r.pushers) > 1 else ""
        kept = " (the pusher in contact alone)" if r.kept_pusher and len(r.pushers) == 1 else kept
        how = f" (search: {r.attempt})" if r.attempt else ""
        outcome = f"re-planned {r.pushes} push(es), {' -> '.join(r.pushers)}{kept}{how}"
    else:
        outcome = f"no correction taken: {r.failure}; kept the plan"
    when = {"off_goal": f"after step {r.after_step}: off the goal by",
            "on_touch": f"on the feature of step {r.after_step + 1}: off the plan by",
            "last_switch": f"after step {r.after_step}, the last a switch-over is held from: off the plan by",
            "plan_short": "before the first push: the plan ends off the goal by"}.get(
        r.trigger, f"after step {r.after_step}: off the plan by")
    return f"{when} {math.hypot(dx, dz):.3f} mm, {dth:+.3f} deg; {outcome} ({r.planning_ms:.1f} ms)"


def _describe_contact(c: ContactRecord) -> str:
    """One contact: where the guard found its feature, how far the object was carried, its slip."""
    found = "" if c.found_mm is None else f"feature found {c.found_mm:+.3f} mm from its place; "
    found += "" if c.seated_deg is None else f"seated turned {c.seated_deg:+.3f} deg; "
    return (f"{c.pusher:<12} steps {c.first_step:>3}-{c.last_step:<3} {found}carried to the feature "
            f"{c.carried_mm:.3f} mm, then slip at the pusher {c.slip_mm:.3f} mm, {c.slip_deg:.3f} deg")


def _error(actual: Optional[Dict[str, float]], pose: Sequence[float]) -> Optional[Dict[str, float]]:
    """`actual` minus `pose` (x, z mm, theta deg), and the distance mm; None when not measured."""
    if actual is None:
        return None
    dx, dz, dtheta = Pose.of(actual).minus(pose)
    return {"x": dx, "z": dz, "theta": dtheta, "distance": math.hypot(dx, dz)}


def fault_report(task: Task, fault: ArmFault, tolerance: "Tolerance | Sequence[float] | None" = None) -> dict:
    """The report of a run that ended in an arm fault, in the fields of ExecutionReport.as_dict that
    a script reads first: the verdict (cause "arm_fault"), the reason and where to resume."""
    verdict = Verdict.for_fault(success_tolerance(task, tolerance), fault.reason)
    return {"task": task.name, "success": verdict.success, "tolerance": verdict.tolerance.as_list(),
            "cause": verdict.cause, "verdict": verdict.detail, "last_confirmed_step": fault.last_confirmed_step,
            "arm_stopped": fault.arm_stopped, "connected": fault.connected, "replanned": fault.replanned}
