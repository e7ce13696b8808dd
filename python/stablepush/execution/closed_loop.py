"""Closed-loop execution: with a sticking pusher the object's pose in the grasp is
observable, so as the object comes onto each feature and after each push the executor compares
the tracker's pose (`object_in_grasp` in the arm protocol) with the plan's and, past a threshold,
re-plans from the measured pose. On the feature of the plan's last contact the threshold is the
final tolerance: the contact ends at the goal, and a feature met early has pushed the object
along the push already, an error the pusher cannot push back once it is past the goal. So it is
after the last push from which a correction could still carry the object to another feature
(`switch_held`): past it, only the pusher in contact is left to push an error back, and one that
drags the object away from its plan (the high-mu offset's left pusher in a world of less pad
friction sags it 0.5 mm) cannot lift it.

The policy lives here; `executor.py` streams and splices. A re-plan
- aims at the task's goal within the final tolerance (a run is checked again at rest after its
  last push, and corrected again while it is off by more); a plan that itself ends outside it (a
  plan stops anywhere within the task's wider tolerance) is planned again to it before the first
  push (`aim`), where every push of the task is still ahead: at its end the pusher in contact may
  not be able to push the rest;
- is planned first robust to the worlds the loop is rated for: pushers whose mu is
  CORRECTION_MU_SPREAD lower than the task's and pads whose mu is that fraction either side of it
  (as `uncertainty: {pusher_mu: ..., pad_mu: ...}`): a run that needs a correction is in a world
  whose friction is not the model's, and a correction planned with the model's slips as the plan
  did (the low-mu offset at x0.85: 0.22 mm low with nominal corrections, 0.09 mm with robust
  ones; the high-mu offset at x0.85, whose left pusher slipped with pads of 15% less mu, 0.85 mm
  off with corrections robust to the pushers' mu alone, 0.06 mm with the pads' too); then with
  the task's own model (a task with `uncertainty:` keeps its box for both);
- first tries the pusher that is pushing now alone (no switch-over: the object stays on its
  feature), then every pusher of the task with one switch-over more than its budget; a switch-over
  carries the object between features in the pads alone, so that search switches pushers only
  where the pads hold TRANSIT_HOLD_RATIO times the object's weight (`hold_ratio`, the measured pose
  included when it starts with another pusher), and its plan is checked again against that rule
  and, for a task with `uncertainty:`, the weight at every corner of the box;
- when none of those is found, tries them all again with `pivot_steps` (turns about a pad's
  centre, docs/planner.md): a plan made to turn the object about a pad (the pivot) cannot be
  planned again once the object is off that centre (0.01 mm off, no plan was found) without them,
  and a feature met off its place puts it there (the pivot with features off by up to 0.5 mm /
  0.5 deg landed 3 of 8 trials without them, 8 with). Last, since they change the corrections they
  are not needed for (the low-mu offset's lifted less and ended 0.35 mm low);
- when none of those is found either and the run would miss its verdict otherwise, tries every
  pusher once more, switching where the pads hold TRANSIT_HOLD_RATIO_LEAST times the weight (the
  weight still held at rest at the worst corner of the worlds `evaluate` rates); the record names
  the attempt that found the correction taken;
- plans in the world the run is in: the features keep the object's world orientation they had
  (`Task.with_start`), so gravity in O on each feature is the world's, not the measured pose's;
- takes milliseconds (the planner's own time; limits below), between two waypoints;
- when none is found, says so with what each attempt ended with and, where the goal lies in a
  sense of x, z or theta no stable push moves the object in (`no_way_back`), that sense.
Poses are (x mm, z mm, theta deg), as in plan files.
"""
from __future__ import annotations

import dataclasses
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

from stablepush.errors import PadFaceError
from stablepush.plan.plan import Waypoint
from stablepush.plan.search import SearchRules, plan_task
from stablepush.pose import Pose, PoseLike, Tolerance
from stablepush.task.fields import PLANNER_PARAMETER_RANGES
from stablepush.task.mechanics import blocked_senses
from stablepush.task.model import Task
from stablepush.units import as_triple, pose_to_si

THRESHOLD_FRACTION = 0.5  # default threshold: this fraction of the task's goal tolerance
FINAL_FRACTION = 0.2  # default final tolerance: this fraction of the task's goal tolerance
# The corrections' searches are bounded by stable-push tests, a count, so that a seed's run is the
# same on any machine under any load; their wall time is only a guard (GUARD_TIME_LIMIT), and a
# search it stops is reported (Replan.guard_fired). A correction that is found takes few tests (tens
# to thousands); a search that finds none runs its budget out: on 2 cores of 2026 about 1 M tests a
# second for line pushers, about 0.1 M for point pushers.
KEEP_PUSHER_CHECKS = 50_000  # for the re-plan with the current pusher alone
REPLAN_CHECKS = 500_000  # for the re-plan with every pusher
# for each of the aim's searches, before the first push: nothing waits on it (the robust large
# manipulation's takes 0.35-0.76 s of tests)
AIM_CHECKS = 2_000_000
GUARD_TIME_LIMIT = 30.0  # s: a search's wall time, past any of the budgets above on a working machine
MAX_REPLANS = 20  # per run: a world that keeps undoing the corrections is reported, not chased
MAX_FAILED_REPLANS = 3  # per run: past this, a pose the planner cannot leave is reported, not retried
# A correction may carry the object between features only where the pads hold this multiple of its
# weight: a world whose friction is a third below the model's still holds it (the closed loop is
# for worlds that differ from the model; with 1.0, a world with 15% less mu dropped the low-mu
# prism in transit, 13.8 mm / 45 deg off).
TRANSIT_HOLD_RATIO = 1.5
# Last, when no correction keeps TRANSIT_HOLD_RATIO and the run would otherwise miss its verdict: a
# switch-over where the pads hold this multiple, which still holds the weight at rest at the worst
# corner of the worlds `evaluate` rates (pad mu -15%, grip force -10%, mass +5% scale the ratio by
# 0.73), for where only another pusher can push the error back (the large manipulation's plan ends
# where the pads hold 1.47). The arm's moves between features shake the object more than rest
# does, so it is not risked for a run that has landed.
TRANSIT_HOLD_RATIO_LEAST = 1.4
# Corrections are planned first robust to pushers' mu this fraction below the task's and pads' mu this
# fraction either side of it: the spread of worlds (x0.85 to x1.15) the loop is rated for.
CORRECTION_MU_SPREAD = 0.15


@dataclass(frozen=True)
class ClosedLoop:
    """When to re-plan: after a push, when the measured pose is off the planned one by more than
    `threshold` in x, z or theta; after the last push, when it is off the goal by more than
    `final_tolerance` (Tolerances; a (mm, deg) pair is taken as one)."""

    threshold: Tolerance
    final_tolerance: Tolerance
    max_replans: int = MAX_REPLANS
    max_failed_replans: int = MAX_FAILED_REPLANS

    def __post_init__(self):
        for name in ("threshold", "final_tolerance"):
            object.__setattr__(self, name, Tolerance.of(getattr(self, name)))

    @classmethod
    def for_task(cls, task: Task, threshold: "Tolerance | Sequence[float] | None" = None,
                 final_tolerance: "Tolerance | Sequence[float] | None" = None) -> "ClosedLoop":
        return cls(threshold=Tolerance.of(threshold) if threshold else task.tolerance.scaled(THRESHOLD_FRACTION),
                   final_tolerance=(Tolerance.of(final_tolerance) if final_tolerance
                                    else task.tolerance.scaled(FINAL_FRACTION)))

    def may_replan(self, replans: Sequence["Replan"]) -> bool:
        """Whether the run may still re-plan, given the re-plans it made."""
        failed = sum(1 for r in replans if not r.solved and r.trigger != "plan_short")  # aim's: not a correction
        return len(replans) < self.max_replans and failed < self.max_failed_replans

    @staticmethod
    def off_by(measured: PoseLike, pose: PoseLike, limit: Tolerance) -> bool:
        """Whether `measured` lies beyond `limit` of `pose` in some coordinate."""
        return not limit.within(measured, pose)


@dataclass(frozen=True)
class Replan:
    """One correction: after plan step `after_step` the object was measured at `measured` where
    the plan had `planned` (`trigger`: "off_plan" after a push, "last_switch" after the last push
    from which a switch-over is held, "on_touch" as it came onto the feature of step after_step + 1,
    "off_goal" at rest after the last);
    whether a new plan from there was found and taken (`solved`), its pushers and length, and, when
    none was taken, why (`failure`)."""

    after_step: int
    measured: Tuple[float, float, float]
    planned: Tuple[float, float, float]
    solved: bool
    pushers: List[str]  # the new plan's pushers, one per contact
    pushes: int
    kept_pusher: bool  # the new plan starts with the pusher that was pushing
    planning_ms: float
    trigger: str = "off_plan"
    failure: Optional[str] = None  # one line: how many searches, how they ended (each in `tried`)
    attempt: Optional[str] = None  # how the correction taken was searched for (_Attempt.describe)
    tried: List[str] = field(default_factory=list)  # each failed search, and how it ended
    # a search stopped at GUARD_TIME_LIMIT before its count: this correction may differ on another machine
    guard_fired: bool = False


    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def _transits_held(task: Task, steps: Sequence[Waypoint], pusher: str, ratio: float = TRANSIT_HOLD_RATIO) -> bool:
    """Whether the pads hold `ratio` times the object's weight at every pose of `steps` where the
    pusher changes (the object travels between features there), `pusher` being the one in contact
    at steps[0]. With the task's uncertainty the pads must also hold at least the weight at every
    corner of its box: the box then says what the ratio stands in for."""
    nominal, corners = task.model, task.corner_models
    previous = pusher
    for before, step in zip(steps, steps[1:]):
        if step.pusher != previous:  # leaving `previous`'s feature: gravity in G as on that feature
            q, index = pose_to_si(before.pose), task.pusher_index(previous)
            if nominal.hold_ratio(q, index) < ratio or any(m.hold_ratio(q, index) < 1.0 for m in corners):
                return False
        previous = step.pushed_by  # a push: every step after steps[0]
    return True


def switch_held(task: Task, pose: Sequence[float], pusher: str) -> bool:
    """Whether a correction from `pose` (x mm, z mm, theta deg, resting on `pusher`'s feature) may still
    switch to another feature: the pads hold TRANSIT_HOLD_RATIO times the object's weight there in
    the task's model and at every corner of the box the first corrections are planned robust to
    (CORRECTION_MU_SPREAD, or the task's own uncertainty box), as those corrections ask."""
    q, index = pose_to_si(pose), task.pusher_index(pusher)
    box = _correction_box(task)  # its nominal model is the task's: a box changes no model
    return all(m.hold_ratio(q, index) >= TRANSIT_HOLD_RATIO for m in (box.model, *box.corner_models))


# By task: the task with the box switch_held asks at the corners of, kept with the models it has
# built, for the tasks of other runs of the same task in this process (evaluate's trials).
_CORRECTION_BOXES: "OrderedDict[str, Task]" = OrderedDict()


def _correction_box(task: Task) -> Task:
    """The task with the box the first corrections are planned robust to: its own, else
    CORRECTION_MU_SPREAD in pusher and pad mu."""
    key = repr((task.identity(), sorted(task.feature_orientations.items())))
    if key not in _CORRECTION_BOXES:
        _CORRECTION_BOXES[key] = task if task.uncertainty else dataclasses.replace(
            task, uncertainty={"pusher_mu": CORRECTION_MU_SPREAD, "pad_mu": CORRECTION_MU_SPREAD})
        while len(_CORRECTION_BOXES) > _AIMED_KEPT:
            _CORRECTION_BOXES.popitem(last=False)
    return _CORRECTION_BOXES[key]


# The aims made in this process, by task, plan and tolerance: `evaluate` runs one plan in many worlds,
# and a failed aim (the pegs') costs its whole time limit each time.
_AIMED: "OrderedDict[str, Optional[Tuple[Replan, List[Waypoint]]]]" = OrderedDict()
_AIMED_KEPT = 16


def aim(task: Task, steps: Sequence[Waypoint], loop: ClosedLoop) -> Optional[Tuple[Replan, List[Waypoint]]]:
    """Before the first push: when the plan `steps` ends off the goal by more than the loop's final
    tolerance, plan again from its start to the goal within it, with the task's pushers, as few
    switch-overs as the plan makes first and then one more at a time up to the task's budget (a plan
    like the one that was checked is preferred), and the transit rule of corrections (a switch-over
    only where the pads hold TRANSIT_HOLD_RATIO times the weight). None when the plan ends within
    it; else the record (trigger "plan_short") and the new steps (empty when none was found: the
    plan runs as it is). The same task, plan and tolerance get the answer of their first aim in
    this process (the search is seeded; only its time limit could tell two apart)."""
    key = repr((task.identity(), task.planner, [(w.pose, w.pusher) for w in steps], loop.final_tolerance))
    if key not in _AIMED:
        _AIMED[key] = _aim(task, steps, loop)
        while len(_AIMED) > _AIMED_KEPT:
            _AIMED.popitem(last=False)
    _AIMED.move_to_end(key)
    found = _AIMED[key]
    return None if found is None else (found[0], list(found[1]))


def _aim(task: Task, steps: Sequence[Waypoint], loop: ClosedLoop) -> Optional[Tuple[Replan, List[Waypoint]]]:
    start, end = steps[0].pose, steps[-1].pose
    at = lambda pose: loop.final_tolerance.within(pose, task.goal)  # noqa: E731
    if at(end) or at(start):
        return None
    switches = sum(1 for a, b in zip(steps[1:], steps[2:]) if a.pusher != b.pusher)
    elapsed, tried, ended, found, guarded = 0.0, [], [], [], False
    for budget in range(min(switches, task.planner.max_switches), task.planner.max_switches + 1):
        planner = counted(task.planner, AIM_CHECKS).replace(tolerance=loop.final_tolerance.as_list(),
                                                            max_switches=budget)
        result = _search(dataclasses.replace(task.with_start(start), planner=planner),
                         transit_hold=1.0 if task.uncertainty else TRANSIT_HOLD_RATIO)
        if isinstance(result, PadFaceError):
            tried.append(f"{budget} switch-over(s): {result.reason}")
            ended.append("off_faces")
            continue
        elapsed += result.stats["planning_time_s"]
        guarded = guarded or result.guard_fired
        if not result.solved:
            tried.append(f"{budget} switch-over(s) in {AIM_CHECKS:,} tests: {_ended_by(result)}")
            ended.append(_ended(result))
        elif not _transits_held(task, result.waypoints, result.waypoints[1].pusher):
            tried.append(_unheld_note(result.pusher_sequence, TRANSIT_HOLD_RATIO))
            ended.append("transit")
        else:
            found = list(result.waypoints)
            break
    notes = [] if found else _way_back_note(task, end, loop.final_tolerance, "from the plan's end")  # run as it is
    record = Replan(after_step=0, measured=as_triple(start), planned=as_triple(end), solved=bool(found),
                    pushers=result.pusher_sequence if found else [], pushes=max(len(found) - 1, 0),
                    kept_pusher=False, planning_ms=elapsed * 1e3, trigger="plan_short",
                    failure=None if found else _summed_up(ended, notes), tried=[] if found else tried + notes,
                    guard_fired=guarded)
    return record, found


def no_way_back(task: Task, pose: Sequence[float], tolerance: "Tolerance | Sequence[float]") -> Optional[str]:
    """When the goal lies, from `pose` (x mm, z mm, theta deg, in the task's world), beyond
    `tolerance` in a sense of x, z or theta in which no stable unit push of the task's
    pushers moves the object by more than mechanics.NO_WAY_BACK of a unit step (`blocked_senses`,
    headings every 10 deg): those senses, each with the largest such push ("-x (at most 0.05 of a
    unit step)"), else None. Why a correction cannot exist from there."""
    gap = Pose.of(task.goal).minus(pose)
    return blocked_senses(task.with_start(pose), pose, gap, tolerance)


# How a failed search ended, as its one-line summary counts it (_summed_up): a Plan.outcome, or the
# transit rule refusing the plan found.
_ENDED = {"time_limit": "out of tests", "guard": "stopped by the wall-time guard", "unreachable": "unreachable",
          "goal_over_switch_limit": "over the switch-overs", "invalid_start": "no grasp at the start",
          "transit": "a transit the pads do not hold", "off_faces": "a path off the part's faces"}


def _search(task: Task, transit_hold: float, start_pusher: Optional[str] = None):
    """A correction's search (plan_task, without its explanation or deeper end), switching pushers
    where the pads hold `transit_hold` times the weight, or the PadFaceError of a path that takes a
    mesh part's pads off its faces: that correction is not taken, and the others are tried."""
    rules = SearchRules(min_transit_hold=transit_hold, start_pusher=start_pusher, explain=False, deepen=False)
    try:
        return plan_task(task, rules=rules)
    except PadFaceError as exc:
        return exc


def _summed_up(ended: Sequence[str], notes: Sequence[str]) -> str:
    """The failed searches in one line: how many, how each kind ended (`ended`: _ENDED's keys),
    and what no_way_back found (`notes`)."""
    counts = {kind: ended.count(kind) for kind in dict.fromkeys(ended)}
    kinds = ", ".join(f"{_ENDED.get(kind, kind)} {n}" for kind, n in counts.items())
    return "; ".join([f"{len(ended)} search(es) failed ({kinds})"] + list(notes))


def _unheld_note(pushers: Sequence[str], ratio: float) -> str:
    """Why a plan found was not taken: a switch-over the transit rule refuses."""
    return (f"{' -> '.join(pushers)} carries the object between features where the pads hold less than "
            f"{ratio:g} times its weight")


def _way_back_note(task: Task, pose: Sequence[float], tolerance: Tolerance, where: str) -> List[str]:
    """A failed search's last line, when `no_way_back` finds senses blocked from `pose`."""
    blocked = no_way_back(task, pose, tolerance)
    return [f"{where} no stable push moves the object toward the goal along {blocked}"] if blocked else []


@dataclass(frozen=True)
class _Attempt:
    """One way to look for a correction: with the pusher in contact alone, or with every pusher and
    one switch-over more than the task allows (a correction may need a pusher the plan did not),
    switching only where the pads hold `transit_hold` times the weight; robust to the pushers' mu
    CORRECTION_MU_SPREAD lower and the pads' that much either way, or with the task's model; with
    the planner's pivot steps, or without."""

    every_pusher: bool
    checks: int  # stable-push tests the search may make
    robust: bool
    pivot_steps: bool = False
    transit_hold: float = TRANSIT_HOLD_RATIO

    def describe(self, pusher: str) -> str:
        who = "every pusher" if self.every_pusher else pusher + " alone"
        robust = f", pusher mu -{CORRECTION_MU_SPREAD:.0%}, pad mu +-{CORRECTION_MU_SPREAD:.0%}" if self.robust else ""
        pivot = ", pivot steps" if self.pivot_steps else ""
        hold = f", switch-overs where the pads hold {self.transit_hold:g} times the weight" \
            if self.every_pusher and self.transit_hold != TRANSIT_HOLD_RATIO else ""
        return f"{who}{robust}{pivot}{hold} in {self.checks:,} tests"


# Robust first, and the pusher in contact first: no switch-over, the object stays on its feature;
# the same with pivot steps when none of those is found; last, switch-overs where the pads hold less.
ATTEMPTS = tuple(_Attempt(every, limit, robust, pivot) for pivot in (False, True) for robust in (True, False)
                 for every, limit in ((False, KEEP_PUSHER_CHECKS), (True, REPLAN_CHECKS))) \
    + (_Attempt(True, REPLAN_CHECKS, robust=False, transit_hold=TRANSIT_HOLD_RATIO_LEAST),)


def replan(task: Task, measured: Sequence[float], pusher: str, loop: ClosedLoop, after_step: int,
           planned: Sequence[float], trigger: str = "off_plan",
           verdict_at_stake: bool = False) -> Tuple[Replan, List[Waypoint]]:
    """Plan from the measured pose to the task's goal within the loop's final tolerance, trying
    ATTEMPTS in turn (robust first, the pusher pushing now alone first, pivot steps after those,
    switch-overs where the pads hold TRANSIT_HOLD_RATIO_LEAST last, only with `verdict_at_stake`:
    the run, ended here, would miss its success tolerance) and taking
    the first plan whose transits are held. Returns the record and the new plan's steps (empty when
    none was found); the first step is the measured pose."""
    base = dataclasses.replace(task.with_start(measured), planner=task.planner.replace(
        tolerance=loop.final_tolerance.as_list()))
    if base.at_goal(base.start):  # off the plan but at the goal already: nothing to correct
        return Replan(after_step=after_step, measured=as_triple(measured), planned=as_triple(planned), solved=True,
                      pushers=[], pushes=0, kept_pusher=False, planning_ms=0.0, trigger=trigger), []
    spec = task.pushers[task.pusher_index(pusher)]
    elapsed, tried, ended, steps, found_by, guarded = 0.0, [], [], [], None, False
    robust = dataclasses.replace(base, uncertainty={"pusher_mu": CORRECTION_MU_SPREAD, "pad_mu": CORRECTION_MU_SPREAD})
    for attempt in ATTEMPTS:
        least = attempt.transit_hold != TRANSIT_HOLD_RATIO
        own_box = (attempt.robust or least) and bool(task.uncertainty)
        if own_box or (attempt.pivot_steps and task.planner.tuning.get("pivot_steps")):
            continue  # the task's own box is the model and its rule of every attempt; its pivot steps are in all
        if least and not verdict_at_stake:
            continue
        planner = counted(base.planner, attempt.checks).replace(pivot_steps=1 if attempt.pivot_steps else None)
        start = robust if attempt.robust else base
        if attempt.every_pusher:
            most = PLANNER_PARAMETER_RANGES["max_switches"][2]
            candidate = dataclasses.replace(start, planner=planner.replace(
                max_switches=int(min(task.planner.max_switches + 1, most))))
        else:
            candidate = dataclasses.replace(start, pushers=(spec,), planner=planner.replace(max_switches=0))
        # Every pusher: the search itself switches only where the pads hold, so that a correction
        # may detour to where a switch-over is safe. It holds every model to one factor: the
        # attempt's with the nominal model alone, the corners' 1.0 with the task's uncertainty box
        # (whose nominal 1.5 _transits_held checks after), and the attempt's at every corner of the
        # robust attempts' box too (its pads' mu is 15% lower at two of them: the stricter rule, as
        # measured).
        transit_hold = (1.0 if task.uncertainty else attempt.transit_hold) if attempt.every_pusher else 0.0
        result = _search(candidate, transit_hold, start_pusher=pusher)
        if isinstance(result, PadFaceError):
            tried.append(f"{attempt.describe(pusher)}: {result.reason}")
            ended.append("off_faces")
            continue
        elapsed += result.stats["planning_time_s"]
        guarded = guarded or result.guard_fired
        if not result.solved:
            tried.append(f"{attempt.describe(pusher)}: {_ended_by(result)}")
            ended.append(_ended(result))
            continue
        if not _transits_held(task, result.waypoints, pusher, attempt.transit_hold):
            tried.append(f"{attempt.describe(pusher)}: {_unheld_note(result.pusher_sequence, attempt.transit_hold)}")
            ended.append("transit")
            continue
        steps, found_by = list(result.waypoints), attempt.describe(pusher)
        break
    notes = [] if steps else _way_back_note(task, measured, loop.final_tolerance, "from here")
    record = Replan(after_step=after_step, measured=as_triple(measured), planned=as_triple(planned), solved=bool(steps),
                    pushers=result.pusher_sequence if steps else [], pushes=max(len(steps) - 1, 0),
                    kept_pusher=bool(steps[1:]) and steps[1].pusher == pusher, planning_ms=elapsed * 1e3,
                    trigger=trigger, failure=None if steps else _summed_up(ended, notes), attempt=found_by,
                    tried=[] if steps else tried + notes, guard_fired=guarded)
    return record, steps


def counted(planner, checks: int):
    """`planner` (PlannerSettings) bounded by `checks` stable-push tests (the task's own check_limit,
    when lower), with GUARD_TIME_LIMIT as its wall-time guard."""
    return planner.with_check_limit(checks).replace(time_limit=GUARD_TIME_LIMIT)


def _ended(plan) -> str:
    """How a search that found no plan ended, as _ENDED names it: its outcome, or `guard` where the
    wall-time guard stopped it before its count of tests."""
    return "guard" if plan.guard_fired else plan.outcome


def _ended_by(plan) -> str:
    """How a search that found no plan ended, in a few words (an unreachable goal with its reason)."""
    if plan.outcome == "unreachable":
        return plan.message  # the reason, decided at once
    ended = _ended(plan)
    return _ENDED[ended] if ended in ("time_limit", "guard") else ended
