"""The verdict on a run: did the object land at the task's goal in the grasp, and if not, why.

A run lands when the object stays where it was put: its pose in the grasp at rest, held by the
pads alone after the last feature has let go (`ExecutionReport.landed_in_grasp`), is within the
tolerance of the goal in each coordinate: |dx|, |dz| <= mm and |dtheta| <= deg, the rule by
which the planner itself stops (`Task.at_goal`). A task whose run ends on its last feature
(`environment.end_on_feature`) is judged there, since nothing lets go. The tolerance is the
task's `planner.tolerance` unless the caller gives one (`execute`, `evaluate` and the API take
the same override, `success_tolerance`).

A miss is given one cause, the first of CAUSES that applies, so a script can act on it:

- `moved_on_release`: the object was within the tolerance on its last feature and the release
  moved it out: the pads alone do not hold it there against gravity (the plan's `final_hold`);
- `grasp_lost`: where the object came to rest some pad is no longer on it (`grasp_maintained`);
- `correction_not_found`: the closed loop was off the plan and found no correction (each re-plan's
  `failure` says why; the plan's own shortfall, found before the first push, is `plan_short`);
- `corrections_exhausted`: the closed loop made as many corrections as it may and is still off;
- `feature_off`: the object rode with the hand into a push, before its feature stopped it, by
  more than SLIP_FRACTION of the tolerance, and ends that much short (the executor's
  ContactRecord.carried_mm): the feature stood beyond its place along the push (an approach that
  is not guarded ends where the plan puts it), or the object had moved in the grasp. The fixture,
  not the pusher's friction, is to blame;
- `pusher_slipped`: a pusher slipped on its feature by more than SLIP_FRACTION of the tolerance;
- `plan_short`: the plan itself ends outside the tolerance (the planner's own tolerance is wider);
- `drift`: none of the above, the error grew without one large slip.

A run that ends in an arm fault is the cause `arm_fault` (`Verdict.for_fault`); a run whose arm
does not report the object in the grasp has no verdict (`success` None, cause `not_measured`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence

from stablepush.errors import SettingError
from stablepush.pose import Pose, PoseLike, Tolerance
from stablepush.task.model import Task

CAUSES = ("moved_on_release", "grasp_lost", "correction_not_found", "corrections_exhausted", "feature_off",
          "pusher_slipped", "plan_short", "drift", "arm_fault", "not_measured")
# A contact counts as met late or slipped past this fraction of the tolerance (mm at the pusher, deg).
SLIP_FRACTION = 0.5


@dataclass(frozen=True)
class Verdict:
    """success: the run landed (None: the arm does not report the object, so it is not known);
    tolerance: the Tolerance it was judged with; cause: one of CAUSES for a miss, else None; detail:
    one sentence for a person."""

    success: Optional[bool]
    tolerance: Tolerance
    cause: Optional[str]
    detail: str

    def __post_init__(self):
        object.__setattr__(self, "tolerance", success_tolerance_of(self.tolerance))

    @classmethod
    def for_fault(cls, tolerance: "Tolerance | Sequence[float]", reason: str) -> "Verdict":
        return cls(False, success_tolerance_of(tolerance), "arm_fault", f"the run ended in an arm fault: {reason}")

    def as_dict(self) -> dict:
        return {"success": self.success, "tolerance": self.tolerance.as_list(), "cause": self.cause,
                "detail": self.detail}


def success_tolerance(task: Task, tolerance: "Tolerance | Sequence[float] | None" = None) -> Tolerance:
    """The Tolerance a run of `task` is judged with: `tolerance` (a Tolerance or mm, deg), else the
    task's own. ValueError for one that is not two finite numbers above 0."""
    return task.tolerance if tolerance is None else success_tolerance_of(tolerance)


def success_tolerance_of(value: "Tolerance | Sequence[float]") -> Tolerance:
    """`value` (a Tolerance or mm, deg) as the success tolerance: SettingError naming it otherwise."""
    try:
        return Tolerance.of(value)
    except SettingError as exc:
        raise SettingError("success_tolerance", exc.reason) from None


def judge(task: Task, report, tolerance: "Tolerance | Sequence[float] | None" = None,
          max_replans: Optional[int] = None) -> Verdict:
    """The verdict on a completed run (`ExecutionReport`), judged with `tolerance` (mm, deg; default:
    the task's). `max_replans`: the closed loop's budget, when it ran."""
    tol = success_tolerance(task, tolerance)
    final, landed = report.final_in_grasp, report.landed_in_grasp
    if final is None or landed is None:
        return Verdict(None, tol, "not_measured", "the arm does not report the object in the grasp, so whether "
                                                  "it landed is not known")
    off = f"{_offsets(landed, task.goal)} (tolerance {tol.describe()})"
    if tol.within(landed, task.goal):
        return Verdict(True, tol, None, f"landed: {off}")

    def miss(cause: str, why: str) -> Verdict:
        return Verdict(False, tol, cause, f"missed: {off}: {why}")

    if tol.within(final, task.goal):  # on the feature it was within: the release moved it out
        change = report.release_change
        moved = f"{math.hypot(change['x'], change['z']):.2f} mm, {change['theta']:+.2f} deg"
        return miss("moved_on_release", f"on its last feature it was within the tolerance "
                                        f"({_offsets(final, task.goal)}); when the feature let go it moved in the "
                                        f"grasp by {moved}: the pads alone do not hold it there against gravity")
    if not task.model.grasp_maintained(Pose.of(landed).si()):
        return miss("grasp_lost", "a pad is no longer on the object where it came to rest")
    failed = [r for r in report.replans if not r.solved and r.trigger != "plan_short"]
    if failed:
        last = failed[-1]
        return miss("correction_not_found", f"no correction found after step {last.after_step} ({last.failure})")
    if report.closed_loop == "on" and max_replans is not None and len(report.replans) >= max_replans:
        return miss("corrections_exhausted", f"the closed loop made its {max_replans} corrections and is still off")
    late = [c for c in report.contacts if c.carried_mm is not None and c.carried_mm > SLIP_FRACTION * tol.position]
    if late:
        worst = max(late, key=lambda c: c.carried_mm)
        if worst.feature_met is False:
            return miss("feature_off", f"{worst.pusher}'s feature was not met: the object rode with the hand "
                                       f"{worst.carried_mm:.2f} mm, through steps {worst.first_step}-{worst.last_step}")
        where = ("its feature beyond its place along the push, or the object moved in the grasp"
                 if worst.found_mm is None else
                 f"the guarded approach found the feature {worst.found_mm:+.2f} mm from its place")
        return miss("feature_off", f"{worst.pusher}'s feature was met late: the object rode with the hand "
                                   f"{worst.carried_mm:.2f} mm into step {worst.first_step} before it stopped it "
                                   f"({where})")
    slipped = [c for c in report.contacts if c.slip_mm is not None
               and (c.slip_mm > SLIP_FRACTION * tol.position or c.slip_deg > SLIP_FRACTION * tol.angle)]
    if slipped:
        worst = max(slipped, key=lambda c: c.slip_mm / tol.position + c.slip_deg / tol.angle)
        return miss("pusher_slipped", f"{worst.pusher} slipped {worst.slip_mm:.2f} mm, {worst.slip_deg:.2f} deg on its "
                                      f"feature over steps {worst.first_step}-{worst.last_step}")
    planned = Pose.of(report.planned_final)
    if not tol.within(planned, task.goal):
        aimed = [r for r in report.replans if r.trigger == "plan_short"]
        why = f" and no plan to the goal was found before the first push ({aimed[0].failure})" if aimed else ""
        return miss("plan_short", f"the plan itself ends at {_offsets(planned, task.goal)} from the goal{why}")
    return miss("drift", "no pusher slipped past half the tolerance; the error built up over the run")


def _offsets(pose: PoseLike, goal: PoseLike) -> str:
    """`pose` minus `goal`, each coordinate named: the tolerance is per coordinate, so is the line."""
    dx, dz, dtheta = Pose.of(pose).minus(goal)
    return f"x {dx:+.2f} mm, z {dz:+.2f} mm, theta {dtheta:+.2f} deg"
