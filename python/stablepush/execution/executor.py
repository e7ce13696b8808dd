"""The executor: streams a plan's end-effector waypoints (stream.py) to an arm server over the
arm protocol (protocol.py), lock-step, and reports what the arm confirmed.

Any fault (the server gone, a malformed or out-of-order reply, an error from the server, no reply
in time) ends the run with `ArmFault`: the arm is told to stop when it can still be reached, and
the fault names the last plan step the arm confirmed, from which `resume_from` continues.
"""
from __future__ import annotations

import dataclasses
import math
import socket
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Sequence

import numpy as np

from stablepush.errors import ArmFault
from stablepush.execution.closed_loop import ClosedLoop, Replan, aim, replan, switch_held
from stablepush.execution.guard import (
    GuardedApproach,
    from_touch,
    offset_along_approach_mm,
    seated_feature,
    touched_feature,
    turned_deg,
)
from stablepush.execution.protocol import PROTOCOL, LineReader, ProtocolError, decode, encode
from stablepush.execution.stream import ArmWaypoint, arm_trajectory, check_resume_from, past_touch
from stablepush.execution.verdict import Verdict, judge, within
from stablepush.execution.verdict import success_tolerance as judged_with
from stablepush.execution.world import Feature, place_features, scene_description
from stablepush.frames import grasp_transform, pose_to_matrix
from stablepush.plan.plan import Plan, Waypoint
from stablepush.plan.verify import check_plan
from stablepush.task.model import Task
from stablepush.units import MM, angle_difference_deg

DEFAULT_ACK_TIMEOUT = 5.0  # s to wait for any reply
# Past this change in the grasp when the last feature lets go (mm, deg), the grasp alone does not
# hold the final pose against gravity: ExecutionReport.release_moved.
RELEASE_MOVE = (0.5, 0.5)
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
    if task.pushes == "by_moving_pusher":
        return ["the task's pushes are by_moving_pusher (gravity fixed in G), but the executor pushes against "
                "fixed features, where gravity turns in G with theta: the plan was made for another cell"]
    return []


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
    engine: Optional[str] = None  # the simulator that ran it, as the arm server says ("mujoco"); None for an arm
    verdict: Optional[Verdict] = None  # whether it landed, and why not (stablepush.execution.verdict)
    ends_on_feature: bool = False  # the task's environment.end_on_feature: no release at the end

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
        change = {k: self.released_in_grasp[k] - self.final_in_grasp[k] for k in ("x", "z")}
        return {**change, "theta": angle_difference_deg(self.released_in_grasp["theta"], self.final_in_grasp["theta"])}

    @property
    def release_moved(self) -> bool:
        """Whether the object moved in the grasp by more than RELEASE_MOVE when the last feature let
        go: the grasp alone does not hold the final pose against gravity."""
        change = self.release_change
        return change is not None and (math.hypot(change["x"], change["z"]) > RELEASE_MOVE[0]
                                       or abs(change["theta"]) > RELEASE_MOVE[1])

    def as_dict(self) -> dict:
        verdict = self.verdict.as_dict() if self.verdict is not None else {}
        return {
            "task": self.task, "success": verdict.get("success"), "tolerance": verdict.get("tolerance"),
            "cause": verdict.get("cause"), "verdict": verdict.get("detail"), "engine": self.engine,
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
        }


def _error(actual: Optional[Dict[str, float]], pose: Sequence[float]) -> Optional[Dict[str, float]]:
    """`actual` minus `pose` (x, z mm, theta deg), and the distance mm; None when not measured."""
    if actual is None:
        return None
    dx, dz = actual["x"] - pose[0], actual["z"] - pose[1]
    return {"x": dx, "z": dz, "theta": angle_difference_deg(actual["theta"], pose[2]), "distance": math.hypot(dx, dz)}


def _off_command(reported: Sequence[float], commanded: Sequence[float]) -> bool:
    """Whether a reported pose of G is farther than FOLLOW_LIMIT from the commanded one."""
    a, b = pose_to_matrix(reported), pose_to_matrix(commanded)
    cos = max(-1.0, min(1.0, (np.trace(a[:3, :3].T @ b[:3, :3]) - 1) / 2))
    return bool(np.linalg.norm(a[:3, 3] - b[:3, 3]) > FOLLOW_LIMIT[0] or math.acos(cos) > FOLLOW_LIMIT[1])


class _Link:
    """The socket to the arm server: one JSON line at a time, each within the ack timeout."""

    def __init__(self, host: str, port: int, timeout: float):
        self.where = f"the arm server at {host}:{port}"
        self.timeout = timeout
        try:
            self.sock = socket.create_connection((host, port), timeout=timeout)
        except OSError as exc:
            raise ConnectionError(f"cannot reach {self.where} ({exc.strerror or exc})") from None
        self.reader = LineReader(self.sock, self.where)

    def send(self, message: dict) -> None:
        self.sock.settimeout(self.timeout)
        self.sock.sendall(encode(message))

    def receive(self, timeout: Optional[float] = None) -> dict:
        return decode(self.reader.read_line(self.timeout if timeout is None else timeout), "server")

    def close(self) -> None:
        try:
            self.sock.close()
        except OSError:
            pass


def execute_plan(
    task: Task,
    plan: Plan,
    host: str,
    port: int,
    *,
    rate_hz: float,
    resume_from: int = 0,
    pace: bool = True,
    ack_timeout: float = DEFAULT_ACK_TIMEOUT,
    closed_loop: Optional[ClosedLoop] = None,
    guard: Optional[GuardedApproach] = GuardedApproach(),
    success_tolerance: Optional[Sequence[float]] = None,
    progress: Optional[Callable[[ArmWaypoint, int, int], None]] = None,
    record: Optional[Callable[[ArmWaypoint, dict, Optional[str]], None]] = None,
) -> ExecutionReport:
    """Stream the plan from step `resume_from` to the arm server at host:port. `pace` holds the
    stream to rate_hz in wall-clock time (a real arm); without it waypoints go as fast as they are
    acknowledged (a simulator keeps its own clock). With `closed_loop`, the tracker's pose as the
    object comes onto each feature and after each push is compared with the plan's and, past its
    threshold, the rest of the run is re-planned from the measured pose and spliced into the stream
    (`stablepush.closed_loop`), and a plan that ends outside the loop's final tolerance is planned
    again to it first (`closed_loop.aim`); the world then holds a feature for every pusher of the
    task. With `guard`, each approach ends by finding its feature by touch (guard.py; None: the
    approaches end where the plan puts the features). The report's verdict judges the final pose with
    `success_tolerance` (mm, deg; default: the task's goal tolerance). `progress(waypoint,
    confirmed_step, total_steps)` is called per ack, and `record(waypoint, state, pusher)` with the
    arm's state and the pusher in contact (None between contacts; `bags.RunRecording`).
    PlanError before anything is sent when the plan does not belong to the task as it is now
    (stablepush.plan.verify.check_plan) or has no push after `resume_from`."""
    steps: List[Waypoint] = list(check_plan(task, plan).waypoints)
    check_resume_from(steps, resume_from)
    started = time.perf_counter()
    replans: List[Replan] = []
    aimed = aim(task, steps, closed_loop) if closed_loop is not None and resume_from == 0 else None
    if aimed is not None:
        replans.append(aimed[0])
        steps = aimed[1] or steps
    # The first step from which the run's steps are no longer the plan file's (None: they all are).
    replanned_from: Optional[int] = 0 if aimed is not None and aimed[1] else None
    features = place_features(task, steps, every_pusher=closed_loop is not None)
    scene = scene_description(task, features, steps[resume_from].pose)
    last_confirmed = resume_from
    loop_status = "off" if closed_loop is None else "on"
    watch = _GuardWatch(guard)
    link = None
    try:
        link = _Link(host, port, ack_timeout)
        link.send({"type": "hello", "protocol": PROTOCOL, "rate_hz": rate_hz, "scene": scene,
                   "continue": resume_from > 0})
        ready = _expect(link.receive(), "ready")
        pending = deque(arm_trajectory(task, steps, features, rate_hz, ready["state"]["ee_pose"], resume_from))
        contacts: Dict[int, ContactRecord] = {}
        touch_state: Optional[dict] = None  # as the object came onto the feature, by the plan
        met_state: Optional[dict] = None  # as the feature stopped it (a feature off its place: later)
        rode = False  # whether the object has ridden with the hand since touch_state
        state = ready["state"]
        settled: Optional[dict] = None
        sent = 0
        lagging = 0  # acks in a row whose reported pose is off the commanded one
        next_time = time.perf_counter()
        while pending:
            w = pending.popleft()
            watch.before(w, state)
            if pace:  # one period after the last send, never sooner: an arm that stalled is not caught up in a burst
                next_time = max(next_time + 1.0 / rate_hz, time.perf_counter())
                time.sleep(max(0.0, next_time - time.perf_counter()))
            link.send({"type": "waypoint", "seq": w.seq, "t": w.t, "step": w.step, "phase": w.phase,
                       "pose": list(w.pose)})
            reply = _expect(link.receive(), "ack")
            if reply["seq"] != w.seq:
                raise ProtocolError(f"out-of-order acknowledgement: expected seq {w.seq}, got {reply['seq']}")
            sent += 1
            if w.phase == "push" and state is not None and touch_state is None:
                touch_state = state  # the object as it came to rest on the feature
            previous, state = state, reply["state"]
            if w.phase == "push" and touch_state is not None and met_state is None:
                riding = _rode_with_hand(task, steps[w.step].pusher, previous, state)
                if riding is False:  # met during this waypoint: after a ride, its motion is still carried
                    met_state = state if rode else previous
                rode = rode or bool(riding)
            lagging = lagging + 1 if _off_command(state["ee_pose"], w.pose) else 0
            if lagging >= FOLLOW_ACKS:
                raise ProtocolError(f"the arm is not following: its reported pose stayed over "
                                    f"{FOLLOW_LIMIT[0] * 1e3:g} mm or {math.degrees(FOLLOW_LIMIT[1]):g} deg from the "
                                    f"commanded one for {FOLLOW_ACKS} waypoints (up to seq {w.seq})")
            if record is not None:
                record(w, state, steps[w.step].pusher if w.phase == "push" else None)
            if w.completes:
                last_confirmed = w.step
                _record(contacts, task, steps, w.step, touch_state, met_state, state, watch)
            guarded = watch.after(task, steps, features, w, state, pending, rate_hz)
            if guarded is not None:
                steps, pending = guarded
            # Compare when the object has come onto a feature, after each push but the last, and
            # once the object has come to rest after it.
            at_rest = w.phase == "settle" and not (pending and pending[0].phase == "settle")
            touched = w.phase == "approach" and bool(pending) and pending[0].phase == "push"
            if loop_status == "on" and ((w.completes and w.step < len(steps) - 1) or at_rest or touched):
                if "object_in_grasp" not in state:
                    loop_status = "no tracker"  # the cell reports no pose in the grasp: open loop
                elif closed_loop.may_replan(replans):
                    spliced = _correct(task, steps, features, closed_loop, w, state, rate_hz, replans,
                                       judged_with(task, success_tolerance), touched)
                    if spliced is not None:
                        steps, new_points = spliced
                        pending = _renumbered(w, rate_hz, new_points)
                        replanned_from = w.step if replanned_from is None else min(replanned_from, w.step)
            if w.phase != "push":
                touch_state = met_state = None
                rode = False
            if w.phase == "settle":
                settled = state
            if progress is not None:
                progress(w, last_confirmed, len(steps) - 1)
        link.send({"type": "bye"})
    except (ConnectionError, TimeoutError, ProtocolError, OSError, KeyError) as exc:
        stopped = _stop(link) if link is not None else None
        reason = str(exc) if not isinstance(exc, KeyError) else f"a reply lacks {exc}"
        # A step confirmed past where the steps changed is not the plan file's step of that number.
        replanned = replanned_from is not None and last_confirmed > replanned_from
        raise ArmFault(reason, last_confirmed, stopped, connected=link is not None, replanned=replanned) from None
    finally:
        if link is not None:
            link.close()
    report = ExecutionReport(
        task=task.name, resumed_from=resume_from, last_confirmed_step=last_confirmed, total_steps=len(steps) - 1,
        waypoints=sent, planned_final=steps[-1].pose, goal=task.goal,
        final_in_grasp=(settled or state).get("object_in_grasp"), released_in_grasp=state.get("object_in_grasp"),
        contacts=list(contacts.values()), features=[f.as_dict() for f in features.values()],
        wall_time_s=time.perf_counter() - started, sim_steps_per_s=state.get("steps_per_s"),
        closed_loop=loop_status, guard=watch.status, replans=replans, warnings=execution_warnings(task),
        engine=ready.get("engine"), ends_on_feature=bool(task.environment.get("end_on_feature", False)),
    )
    report.verdict = judge(task, report, success_tolerance, closed_loop.max_replans if closed_loop else None)
    return report


def fault_report(task: Task, fault: ArmFault, success_tolerance: Optional[Sequence[float]] = None) -> dict:
    """The report of a run that ended in an arm fault, in the fields of ExecutionReport.as_dict that
    a script reads first: the verdict (cause "arm_fault"), the reason and where to resume."""
    verdict = Verdict.for_fault(judged_with(task, success_tolerance), fault.reason)
    return {"task": task.name, "success": verdict.success, "tolerance": list(verdict.tolerance),
            "cause": verdict.cause, "verdict": verdict.detail, "last_confirmed_step": fault.last_confirmed_step,
            "arm_stopped": fault.arm_stopped, "connected": fault.connected, "replanned": fault.replanned}


class _GuardWatch:
    """The guarded approach through one run (guard.py): from the first waypoint of an approach's
    slow end, watch for the touch; on it, hold still, then splice in the contact started from the
    measured pose on the feature where it was found; at the plan's touch with nothing met, seek on
    past it. After a contact's first push, splice in the pushes left on the feature where the
    object rests (seated). `found` and `seated`: the contact's first push (plan step) -> where its
    feature was found (mm) and how the object rested turned on it (deg), keyed as the run's contact
    records are."""

    def __init__(self, guard: Optional[GuardedApproach]):
        self.guard = guard
        self.status = "off" if guard is None else "on"  # or "no tracker"
        self.found: Dict[int, float] = {}
        self.seated: Dict[int, float] = {}
        self._clear()

    def _clear(self) -> None:
        self.since: Optional[dict] = None  # the pose in the grasp as the slow end began
        self.sought_past = False  # this approach has gone on past the plan's touch
        self.holding = False  # met: held still before the pose is measured

    def before(self, w: ArmWaypoint, state: dict) -> None:
        """Before waypoint `w` is sent, with the arm's last `state`."""
        if not w.guarded:
            if w.phase != "approach":
                self._clear()
            return
        if self.since is None and self.status == "on":
            if "object_in_grasp" in state:
                self.since = state["object_in_grasp"]
            else:
                self.status = "no tracker"  # no pose in the grasp to start from: approach as planned

    def after(self, task: Task, steps: List[Waypoint], features: Dict[str, Feature], w: ArmWaypoint,
              state: dict, pending: deque, rate_hz: float):
        """After the arm acknowledged `w` with `state`: the new (steps, pending waypoints) when the
        stream changes here, else None. `features` is updated in place with a feature found."""
        if w.completes and w.phase == "push" and self.status == "on":
            return self._seated(task, steps, features, w, state, rate_hz)
        if not w.guarded or self.since is None:
            return None
        k, pusher = w.step, steps[w.step + 1].pusher
        slow_end_left = bool(pending) and pending[0].guarded
        if self.holding:
            if slow_end_left:
                return None
            # Held still: the contact's pushes start from where the object is, on the feature where it is.
            measured = _measured(steps[k].pose, state["object_in_grasp"])
            on_feature = touched_feature(features[pusher], state["ee_pose"], measured)
            self.found[k + 1] = offset_along_approach_mm(features[pusher], on_feature)
            features[pusher] = on_feature
            steps = from_touch(steps, k, measured)
            self.since, self.holding = None, False
            return steps, _renumbered(w, rate_hz, arm_trajectory(task, steps, features, rate_hz, state["ee_pose"],
                                                                 resume_from=k, resting_on=pusher))
        if self.guard.met(self.since, state["object_in_grasp"], state.get("contact_force")):
            self.holding = True
            return steps, _renumbered(w, rate_hz, [w] * max(1, round(self.guard.hold_s * rate_hz)))
        if not slow_end_left and not self.sought_past:  # at the plan's touch, nothing met: seek on past it
            self.sought_past = True
            past = past_touch(features[pusher], w.pose, self.guard.reach_mm * MM, rate_hz, k, [s.pose for s in steps])
            return steps, _renumbered(w, rate_hz, past + list(pending))
        return None

    def _seated(self, task: Task, steps: List[Waypoint], features: Dict[str, Feature], w: ArmWaypoint, state: dict,
                rate_hz: float):
        """After push w.step: when it is its contact's first and more follow, the pushes left re-based
        on the feature where the object rests (guard.seated_feature), else None."""
        k = w.step
        pusher = steps[k].pusher
        if _contact_first(steps, k) != k or k + 1 >= len(steps) or steps[k + 1].pusher != pusher \
                or "object_in_grasp" not in state:
            return None
        measured = _measured(steps[k].pose, state["object_in_grasp"])
        seated = seated_feature(features[pusher], state["ee_pose"], measured)
        self.seated[k] = turned_deg(features[pusher], seated)
        if abs(self.seated[k]) <= self.guard.seat_deg:
            return None
        features[pusher] = seated
        steps = from_touch(steps, k, measured)
        return steps, _renumbered(w, rate_hz, arm_trajectory(task, steps, features, rate_hz, state["ee_pose"],
                                                             resume_from=k, resting_on=pusher))


def _correct(task: Task, steps: List[Waypoint], features: Dict[str, Feature], loop: ClosedLoop, w: ArmWaypoint,
             state: dict, rate_hz: float, replans: List[Replan], success_tolerance: Sequence[float],
             touched: bool = False):
    """After plan step w.step: when the tracked pose is off the plan (or, at rest after the last
    push, off the goal) by more than the loop allows, re-plan from it and return the spliced steps and the
    waypoints that carry them out from where G is now (seq and t counted from this waypoint);
    else None. At rest off the goal by more than `success_tolerance` (mm, deg) the verdict is at
    stake, and the re-plan may take its last, riskier attempt (closed_loop.replan). `touched`: the
    object has just come onto the feature of the next push (w ends an approach); a feature met off
    its place has pushed it already, and every push of the contact would carry that error on. In
    the plan's last contact it is corrected past the loop's final tolerance: the contact ends at the
    goal, where an error along the push is one the pusher cannot push back (the hexagon's closed-loop
    misses, docs/evaluate.md). So it is after the last push of a contact from whose end a correction
    may still switch to another feature (closed_loop.switch_held): past it, the pusher in contact is
    the only one left. `features` is updated in place: the object's pose on the
    feature in contact becomes the measured one (G's pose times the tracked pose in the grasp), so
    the rest of this contact pushes from where the object really is."""
    k = w.step
    tracked = state["object_in_grasp"]
    last = k == len(steps) - 1 and not touched
    pusher = steps[k + 1].pusher if touched else steps[k].pusher  # the one the object rests on
    final_contact = touched and all(s.pusher == pusher for s in steps[k + 1:])
    last_switch = not (last or touched) and steps[k + 1].pusher == pusher and switch_held(
        task, steps[k].pose, pusher) and not switch_held(task, steps[k + 1].pose, pusher)
    limit = loop.final_tolerance if last or final_contact or last_switch else loop.threshold
    if not loop.off_by(tracked, task.goal if last else steps[k].pose, limit):
        return None
    measured = _measured(steps[k].pose, tracked)
    trigger = "off_goal" if last else "on_touch" if touched else "last_switch" if last_switch else "off_plan"
    record, new_steps = replan(task, measured, pusher, loop, k, steps[k].pose, trigger=trigger,
                               verdict_at_stake=last and not within(tracked, task.goal, success_tolerance))
    replans.append(record)
    if not record.solved or record.pushes == 0:
        return None
    on_feature = pose_to_matrix(state["ee_pose"]) @ grasp_transform(measured)
    features[pusher] = dataclasses.replace(features[pusher], object_pose=on_feature)
    spliced = steps[:k] + [Waypoint(*measured, pusher=steps[k].pusher)] + new_steps[1:]
    points = arm_trajectory(task, spliced, features, rate_hz, state["ee_pose"], resume_from=k, resting_on=pusher)
    return spliced, points


def _measured(planned: Sequence[float], tracked: dict) -> tuple:
    """The tracker's pose in the grasp (x mm, z mm, theta deg) with theta on the planned pose's turn (a
    plan may run past +-180 deg; a tracker reports one turn)."""
    theta = planned[2] + angle_difference_deg(float(tracked["theta"]), planned[2])
    return float(tracked["x"]), float(tracked["z"]), theta


def _renumbered(w: ArmWaypoint, rate_hz: float, points: Sequence[ArmWaypoint]) -> deque:
    """`points` streamed next after `w`: seq and t counted on from it."""
    period = 1.0 / rate_hz
    return deque(dataclasses.replace(p, seq=w.seq + 1 + i, t=w.t + (i + 1) * period) for i, p in enumerate(points))


def _expect(message: dict, kind: str) -> dict:
    if message["type"] == "error":
        raise ProtocolError(f"the arm server reported: {message['message']}")
    if message["type"] != kind:
        raise ProtocolError(f"expected {kind!r} from the arm server, got {message['type']!r}")
    return message


def _stop(link: _Link, within: float = 2.0) -> Optional[bool]:
    """Tell the arm to hold still; True when it confirmed within `within` s (replies that keep
    coming do not extend it), None when it could not be reached or did not confirm."""
    deadline = time.monotonic() + within
    try:
        link.send({"type": "stop"})
        while True:
            reply = link.receive(max(0.0, deadline - time.monotonic()))
            if reply["type"] in ("stopped", "error"):  # the server stops the arm itself before reporting an error
                return True
    except (ConnectionError, TimeoutError, ProtocolError, OSError):
        return None


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


def _contact_first(steps: Sequence[Waypoint], step: int) -> int:
    """The first push of the contact that plan step `step` (a push) belongs to: the run's contact
    records and the guard's findings are keyed by it."""
    first = step
    while first > 1 and steps[first - 1].pusher == steps[step].pusher:
        first -= 1
    return first


def _record(contacts: Dict[int, ContactRecord], task: Task, steps: Sequence[Waypoint], step: int,
            touch_state: Optional[dict], met_state: Optional[dict], state: dict, watch: "_GuardWatch") -> None:
    """Update the record of the contact that plan step `step` belongs to with the object's motion in
    the world since it came onto the feature by the plan (`touch_state`): up to where the feature
    stopped it (`met_state`; None: not yet) it was carried, after that it slipped (when the arm
    reports the object); with what the guarded approach found of its feature (`watch`)."""
    pusher = steps[step].pusher
    first = _contact_first(steps, step)
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
