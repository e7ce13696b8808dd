"""The executor: streams a plan's end-effector waypoints (stream.py) to an arm (the port,
arm.py: a bridge over the arm protocol or a simulated arm in this process), lock-step, and
reports what the arm confirmed (report.py).

Any fault (the arm gone, a malformed or out-of-order reply, an error from the arm, no reply in
time) ends the run with `ArmFault`: the arm is told to stop when it can still be reached, and the
fault names the last plan step the arm confirmed, from which `resume_from` continues.
"""
from __future__ import annotations

import dataclasses
import math
import time
from collections import deque
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from stablepush.errors import ArmFault, SettingError
from stablepush.execution.arm import Arm, ArmError, ArmReady
from stablepush.execution.closed_loop import ClosedLoop, Replan, aim, replan, switch_held
from stablepush.execution.guard import GuardedApproach, GuardWatch, measured_pose
from stablepush.execution.protocol import DEFAULT_RATE_HZ, RATE_HZ, ProtocolError, check_state
from stablepush.execution.report import ContactRecord, ExecutionReport
from stablepush.execution.stream import ArmWaypoint, arm_trajectory, check_resume_from, contact_first, renumbered
from stablepush.execution.verdict import judge, success_tolerance, success_tolerance_of
from stablepush.execution.world import place_features, scene_description
from stablepush.frames import grasp_transform, pose_to_matrix
from stablepush.plan.files import MAX_WAYPOINTS
from stablepush.plan.plan import Plan, Waypoint
from stablepush.plan.verify import check_plan
from stablepush.pose import Tolerance
from stablepush.task.model import Task
from stablepush.units import MM, is_integer, is_real

# An arm whose reported pose stays this far from the commanded one (m, rad) for this many acks in
# a row is not following the stream (a real arm lags by a fraction of a mm): the run ends in a fault.
FOLLOW_LIMIT = (0.01, math.radians(5.0))
FOLLOW_ACKS = 50
# The object rides with the hand between two acks when its point at the pusher moved in the world
# within this fraction of the hand's motion there of where the hand alone would have taken it: the
# feature has not stopped it yet (the tilted-gravity offset with its feature 0.48 mm back: at most 1%
# while riding, 67% in the waypoint it met the feature, 100% after).
RIDE_FRACTION = 0.25


def execution_warnings(task: Task) -> List[str]:
    """What makes a run of this task on the executor's cell differ from its model (legal, but
    probably not meant): one line each."""
    if task.dynamics.pushes == "by_moving_pusher":
        return ["the task's pushes are by_moving_pusher (gravity fixed in G), but the executor pushes against "
                "fixed features, where gravity turns in G with theta: the plan was made for another cell"]
    return []


def _checked(state: dict, kind: str) -> dict:
    """`state` once it is one to act on (protocol.check_state: finite, within reach, a unit
    quaternion), from any arm; ArmError otherwise."""
    try:
        check_state(state, kind)
    except (ProtocolError, KeyError, TypeError) as exc:
        raise ArmError(f"{exc}" if isinstance(exc, ProtocolError) else f"{kind}: a malformed state ({exc})") from None
    return state


def _off_command(reported: Sequence[float], commanded: Sequence[float]) -> bool:
    """Whether a reported pose of G is farther than FOLLOW_LIMIT from the commanded one."""
    a, b = pose_to_matrix(reported), pose_to_matrix(commanded)
    cos = max(-1.0, min(1.0, (np.trace(a[:3, :3].T @ b[:3, :3]) - 1) / 2))
    return bool(np.linalg.norm(a[:3, 3] - b[:3, 3]) > FOLLOW_LIMIT[0] or math.acos(cos) > FOLLOW_LIMIT[1])


@dataclass(frozen=True)
class RunOptions:
    """How a run runs. `rate_hz`: waypoints per second. `resume_from`: the plan step to start from
    (after a fault). `pace`: hold the stream to rate_hz in wall-clock time (a real arm); without it
    waypoints go as fast as they are acknowledged (a simulator keeps its own clock); None: as the
    arm says (`Arm.paced`). `closed_loop`:
    compare the tracked pose with the plan and re-plan past its threshold (closed_loop.py; None:
    open loop). `guard`: end each approach by finding its feature by touch (guard.py; None: the
    approaches end where the plan puts the features). `success_tolerance` (mm, deg): the verdict's
    tolerance (None: the task's goal tolerance)."""

    rate_hz: float = DEFAULT_RATE_HZ
    resume_from: int = 0
    pace: Optional[bool] = None
    closed_loop: Optional[ClosedLoop] = None
    guard: Optional[GuardedApproach] = GuardedApproach()
    success_tolerance: "Optional[Tolerance | Tuple[float, float]]" = None

    def __post_init__(self):
        """Each option's type (TypeError) and range (SettingError naming it), as `execute` checks them."""
        rate = self.rate_hz
        if isinstance(rate, bool) or not is_real(rate) or not RATE_HZ[0] <= rate <= RATE_HZ[1]:
            raise SettingError("rate_hz", f"must be a number from {RATE_HZ[0]:g} to {RATE_HZ[1]:g}, "
                                          f"got {self.rate_hz!r:.40}")
        if (isinstance(self.resume_from, bool) or not is_integer(self.resume_from)
                or not 0 <= self.resume_from < MAX_WAYPOINTS):  # a plan file's steps at most
            raise SettingError("resume_from", f"must be a whole number from 0 to {MAX_WAYPOINTS - 1:,}, "
                                              f"got {self.resume_from!r:.40}")
        for name, kind in (("pace", bool), ("closed_loop", ClosedLoop), ("guard", GuardedApproach)):
            value = getattr(self, name)
            if value is not None and not isinstance(value, kind):
                raise TypeError(f"{name} must be a {kind.__name__} or None, got {type(value).__name__}")
        if self.success_tolerance is not None:
            success_tolerance_of(self.success_tolerance)


Progress = Callable[[ArmWaypoint, int, int], None]
Record = Callable[[ArmWaypoint, dict, Optional[str]], None]


def execute_plan(task: Task, plan: Plan, arm: Arm, options: RunOptions = RunOptions(), *,
                 progress: Optional[Progress] = None, record: Optional[Record] = None) -> ExecutionReport:
    """Stream the plan from step `options.resume_from` to `arm` (an open session is not needed:
    this says hello and bye) and report what it confirmed, with the verdict on where the object
    landed. With a closed loop, the tracker's pose as the object comes onto each feature and after
    each push is compared with the plan's and, past its threshold, the rest of the run is
    re-planned from the measured pose and spliced into the stream, and a plan that ends outside the
    loop's final tolerance is planned again to it first (`closed_loop.aim`); the world then holds a
    feature for every pusher of the task. `progress(waypoint, confirmed_step, total_steps)` is
    called per ack, and `record(waypoint, state, pusher)` with the arm's state and the pusher in
    contact (None between contacts; `bags.RunRecording`).
    PlanError before anything is sent when the plan does not belong to the task as it is now
    (stablepush.plan.verify.check_plan), has no push after `resume_from`, or is one the arm cannot
    follow in its cell (`Arm.check_cell`); ArmFault when the arm cannot go on (it is told to stop,
    and the fault names the last plan step it confirmed)."""
    plan = check_plan(task, plan)
    steps: List[Waypoint] = list(plan.waypoints)
    check_resume_from(steps, options.resume_from)
    arm.check_cell(task, plan, options.rate_hz)
    run = _Run(task, steps, options, progress, record)
    try:
        run.stream(arm)
    except (ArmError, KeyError) as exc:  # KeyError: a state that lacks a field it carried before
        reason = str(exc) if isinstance(exc, ArmError) else f"a reply lacks {exc}"
        # A step confirmed past where the steps changed is not the plan file's step of that number.
        replanned = run.replanned_from is not None and run.last_confirmed > run.replanned_from
        raise ArmFault(reason, run.last_confirmed, arm.stop() if arm.connected else None,
                       connected=arm.connected, replanned=replanned) from None
    except BaseException:  # anything else (a bug, Ctrl-C) ends the run too: the arm holds still first
        if arm.connected:
            arm.stop()
        raise
    finally:
        arm.close()
    return run.report()


class _Run:
    """One run through its waypoints: the steps being run (the plan's, or spliced by the guard
    and the closed loop), the waypoints still to send, and what the acks said so far."""

    def __init__(self, task: Task, steps: List[Waypoint], options: RunOptions, progress: Optional[Progress],
                 record: Optional[Record]):
        self.task, self.options, self.progress, self.record = task, options, progress, record
        self.started = time.perf_counter()
        self.replans: List[Replan] = []
        loop = options.closed_loop
        aimed = aim(task, steps, loop) if loop is not None and options.resume_from == 0 else None
        if aimed is not None:
            self.replans.append(aimed[0])
            steps = aimed[1] or steps
        self.steps = steps
        # The first step from which the run's steps are no longer the plan file's (None: they all are).
        self.replanned_from: Optional[int] = 0 if aimed is not None and aimed[1] else None
        self.features = place_features(task, steps, every_pusher=loop is not None)
        self.last_confirmed = options.resume_from
        self.loop_status = "off" if loop is None else "on"
        self.watch = GuardWatch(options.guard)
        self.contacts: Dict[int, ContactRecord] = {}
        self.touch_state: Optional[dict] = None  # as the object came onto the feature, by the plan
        self.met_state: Optional[dict] = None  # as the feature stopped it (a feature off its place: later)
        self.rode = False  # whether the object has ridden with the hand since touch_state
        self.settled: Optional[dict] = None
        self.sent = 0
        self.lagging = 0  # acks in a row whose reported pose is off the commanded one
        self.ready: Optional[ArmReady] = None

    def stream(self, arm: Arm) -> None:
        o = self.options
        scene = scene_description(self.task, self.features, self.steps[o.resume_from].pose)
        self.ready = arm.hello(scene, o.rate_hz, resume=o.resume_from > 0)
        self.state = _checked(self.ready.state, "ready")
        pace = arm.paced if o.pace is None else o.pace
        self.pending = deque(arm_trajectory(self.task, self.steps, self.features, o.rate_hz,
                                            self.state["ee_pose"], o.resume_from))
        next_time = time.perf_counter()
        while self.pending:
            w = self.pending.popleft()
            self.watch.before(w, self.state)
            if pace:  # one period after the last send, never sooner: an arm that stalled is not caught up in a burst
                next_time = max(next_time + 1.0 / o.rate_hz, time.perf_counter())
                time.sleep(max(0.0, next_time - time.perf_counter()))
            self._acknowledged(w, _checked(arm.move(w), "ack"))
        arm.bye()

    def _acknowledged(self, w: ArmWaypoint, state: dict) -> None:
        """What the arm's `state` after waypoint `w` tells: the contact's progress, whether the arm
        follows, and whether the guard or the closed loop changes the waypoints to come."""
        self.sent += 1
        if w.phase == "push" and self.touch_state is None:
            self.touch_state = self.state  # the object as it came to rest on the feature
        previous, self.state = self.state, state
        self._watch_ride(w, previous)
        self._check_following(w)
        if self.record is not None:
            self.record(w, state, self.steps[w.step].pusher if w.phase == "push" else None)
        if w.completes:
            self.last_confirmed = w.step
            _record(self.contacts, self.task, self.steps, w.step, self.touch_state, self.met_state, state, self.watch)
        guarded = self.watch.after(self.task, self.steps, self.features, w, state, self.pending, self.options.rate_hz)
        if guarded is not None:
            self.steps, self.pending = guarded
        self._compare(w)
        if w.phase != "push":
            self.touch_state = self.met_state = None
            self.rode = False
        if w.phase == "settle":
            self.settled = state
        if self.progress is not None:
            self.progress(w, self.last_confirmed, len(self.steps) - 1)

    def _watch_ride(self, w: ArmWaypoint, previous: dict) -> None:
        """During a push, note where the feature stopped the object riding with the hand."""
        if w.phase != "push" or self.touch_state is None or self.met_state is not None:
            return
        riding = _rode_with_hand(self.task, self.steps[w.step].pushed_by, previous, self.state)
        if riding is False:  # met during this waypoint: after a ride, its motion is still carried
            self.met_state = self.state if self.rode else previous
        self.rode = self.rode or bool(riding)

    def _check_following(self, w: ArmWaypoint) -> None:
        self.lagging = self.lagging + 1 if _off_command(self.state["ee_pose"], w.pose) else 0
        if self.lagging >= FOLLOW_ACKS:
            raise ArmError(f"the arm is not following: its reported pose stayed over {FOLLOW_LIMIT[0] * 1e3:g} mm "
                           f"or {math.degrees(FOLLOW_LIMIT[1]):g} deg from the commanded one for {FOLLOW_ACKS} "
                           f"waypoints (up to seq {w.seq})")

    def _compare(self, w: ArmWaypoint) -> None:
        """The closed loop: compare when the object has come onto a feature, after each push but
        the last, and once the object has come to rest after it; splice in a correction."""
        at_rest = w.phase == "settle" and not (self.pending and self.pending[0].phase == "settle")
        touched = w.phase == "approach" and bool(self.pending) and self.pending[0].phase == "push"
        if self.loop_status != "on" or not ((w.completes and w.step < len(self.steps) - 1) or at_rest or touched):
            return
        if "object_in_grasp" not in self.state:
            self.loop_status = "no tracker"  # the cell reports no pose in the grasp: open loop
            return
        loop = self.options.closed_loop
        assert loop is not None, "the loop is on (loop_status) only with a closed loop"
        if not loop.may_replan(self.replans):
            return
        spliced = self._correction(w, loop, touched)
        if spliced is not None:
            self.steps, new_points = spliced
            self.pending = renumbered(w, self.options.rate_hz, new_points)
            self.replanned_from = w.step if self.replanned_from is None else min(self.replanned_from, w.step)

    def _correction(self, w: ArmWaypoint, loop: ClosedLoop, touched: bool = False):
        """After plan step w.step: when the tracked pose is off the plan (or, at rest after the last
        push, off the goal) by more than the loop allows, re-plan from it and return the spliced
        steps and the waypoints that carry them out from where G is now (seq and t counted from this
        waypoint); else None. At rest off the goal by more than the verdict's tolerance the verdict is
        at stake, and the re-plan may take its last, riskier attempt (closed_loop.replan). `touched`:
        the object has just come onto the feature of the next push (w ends an approach); a feature
        met off its place has pushed it already, and every push of the contact would carry that error
        on. In the plan's last contact it is corrected past the loop's final tolerance: the contact
        ends at the goal, where an error along the push is one the pusher cannot push back (the
        hexagon's closed-loop misses, docs/results/evaluate-1000-trials.md). So it is after the last
        push of a contact from whose end a correction may still switch to another feature
        (closed_loop.switch_held): past it, the pusher in contact is the only one left. The feature
        in contact is updated: the object's pose on it becomes the measured one (G's pose times the
        tracked pose in the grasp), so the rest of this contact pushes from where the object really is."""
        task, steps, features, state = self.task, self.steps, self.features, self.state
        k = w.step
        tracked = state["object_in_grasp"]
        last = k == len(steps) - 1 and not touched
        pusher = (steps[k + 1] if touched else steps[k]).pushed_by  # the one the object rests on (a push's)
        final_contact = touched and all(s.pusher == pusher for s in steps[k + 1:])
        last_switch = not (last or touched) and steps[k + 1].pusher == pusher and switch_held(
            task, steps[k].pose, pusher) and not switch_held(task, steps[k + 1].pose, pusher)
        limit = loop.final_tolerance if last or final_contact or last_switch else loop.threshold
        if not loop.off_by(tracked, task.goal if last else steps[k].pose, limit):
            return None
        measured = measured_pose(steps[k].pose, tracked)
        trigger = "off_goal" if last else "on_touch" if touched else "last_switch" if last_switch else "off_plan"
        judged_within = success_tolerance(task, self.options.success_tolerance)
        record, new_steps = replan(task, measured, pusher, loop, k, steps[k].pose, trigger=trigger,
                                   verdict_at_stake=last and not judged_within.within(tracked, task.goal))
        self.replans.append(record)
        if not record.solved or record.pushes == 0:
            return None
        on_feature = pose_to_matrix(state["ee_pose"]) @ grasp_transform(measured)
        features[pusher] = dataclasses.replace(features[pusher], object_pose=on_feature)
        spliced = steps[:k] + [Waypoint(*measured, pusher=steps[k].pusher)] + new_steps[1:]
        points = arm_trajectory(task, spliced, features, self.options.rate_hz, state["ee_pose"], resume_from=k,
                                resting_on=pusher)
        return spliced, points

    def report(self) -> ExecutionReport:
        task, steps, state = self.task, self.steps, self.state
        assert self.ready is not None, "a run reports after stream, whose hello made it ready"
        report = ExecutionReport(
            task=task.name, resumed_from=self.options.resume_from, last_confirmed_step=self.last_confirmed,
            total_steps=len(steps) - 1, waypoints=self.sent, planned_final=steps[-1].pose, goal=task.goal,
            final_in_grasp=(self.settled or state).get("object_in_grasp"),
            released_in_grasp=state.get("object_in_grasp"), contacts=list(self.contacts.values()),
            features=[f.as_dict() for f in self.features.values()], wall_time_s=time.perf_counter() - self.started,
            sim_steps_per_s=state.get("steps_per_s"), closed_loop=self.loop_status, guard=self.watch.status,
            replans=self.replans, warnings=execution_warnings(task), engine=self.ready.engine,
            simulated_geometry=self.ready.geometry,
            ends_on_feature=task.environment.end_on_feature,
            steps=[[*w.pose, w.pusher] for w in steps],
        )
        loop = self.options.closed_loop
        report.verdict = judge(task, report, self.options.success_tolerance, loop.max_replans if loop else None)
        return report


def _pusher_point(task: Task, pusher: str) -> np.ndarray:
    """The middle of the pusher's segment in O, homogeneous [m]."""
    spec = task.pushers[task.pusher_index(pusher)]
    return np.array([(spec.a[0] + spec.b[0]) / 2 * MM, 0.0, (spec.a[1] + spec.b[1]) / 2 * MM, 1.0])


def _rode_with_hand(task: Task, pusher: str, before: dict, after: dict) -> Optional[bool]:
    """Whether, between two acks, the object's point at the pusher moved in the world with the hand
    (RIDE_FRACTION): True while a feature beyond its place has not stopped it yet, False once the
    feature holds it; None when the hand did not move there or the arm does not report the object."""
    if "object_pose" not in before or "object_pose" not in after:
        return None
    point = _pusher_point(task, pusher)
    p0, p1 = pose_to_matrix(before["object_pose"]) @ point, pose_to_matrix(after["object_pose"]) @ point
    rode = pose_to_matrix(after["ee_pose"]) @ np.linalg.inv(pose_to_matrix(before["ee_pose"])) @ p0
    hand = float(np.linalg.norm((rode - p0)[:3]))
    if hand < 1e-7:  # m: the hand stood still, which tells nothing
        return None
    return float(np.linalg.norm((p1 - rode)[:3])) <= RIDE_FRACTION * hand


def _record(contacts: Dict[int, ContactRecord], task: Task, steps: Sequence[Waypoint], step: int,
            touch_state: Optional[dict], met_state: Optional[dict], state: dict, watch: GuardWatch) -> None:
    """Update the record of the contact that plan step `step` belongs to with the object's motion in
    the world since it came onto the feature by the plan (`touch_state`): up to where the feature
    stopped it (`met_state`; None: not yet) it was carried, after that it slipped (when the arm
    reports the object); with what the guarded approach found of its feature (`watch`)."""
    pusher = steps[step].pushed_by  # a push's step: it completes
    first = contact_first(steps, step)
    record = contacts.setdefault(first, ContactRecord(pusher, first, step))
    record.last_step = step
    record.found_mm = watch.found.get(first)
    record.seated_deg = watch.seated.get(first)
    if touch_state is None or "object_pose" not in state or "object_pose" not in touch_state:
        return
    point = _pusher_point(task, pusher)
    T0 = pose_to_matrix(touch_state["object_pose"])
    Tm = pose_to_matrix((met_state or state)["object_pose"])
    T1 = pose_to_matrix(state["object_pose"])
    record.feature_met = met_state is not None
    record.carried_mm = float(np.linalg.norm((Tm @ point - T0 @ point)[:3])) / MM
    record.slip_mm = float(np.linalg.norm((T1 @ point - Tm @ point)[:3])) / MM
    R = Tm[:3, :3].T @ T1[:3, :3]
    record.slip_deg = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(R) - 1) / 2))))
