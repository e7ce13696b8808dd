"""The end-effector waypoints that carry a plan out, at a fixed rate (what the executor streams).

During a push the pusher sticks to the object (that is what the plan guarantees), so the object
rests on its feature, fixed in W, while the gripper moves: with T_GO(q) the object's pose in the
grasp (docs/model.md section 1), G's world pose is

    T_WG(t) = T_WO · T_GO(q(t))^-1.

Between two contacts the gripper retracts the object from the feature along the pusher's inward
normal, moves it along y into a lane between features (lifting it over everything first when the
lanes differ), brings it opposite the next feature and approaches until the pusher's segment
touches. The approach's last GUARD_SPAN runs at GUARD_SPEED, slow enough that the executor sees the
feature meet the object within a few hundredths of a millimetre and starts the contact's pushes
from there (guard.py): a feature off its place along the approach is found, not pushed.
Poses are (x, y, z, qw, qx, qy, qz) in W [m].
"""
from __future__ import annotations

import dataclasses
import math
from collections import deque
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from stablepush.errors import PlanError
from stablepush.execution.world import GUARD_SPAN, Feature, contacts_of, near_pose
from stablepush.frames import grasp_transform, matrix_to_pose, pose_to_matrix, slerp, translation
from stablepush.plan.plan import Waypoint
from stablepush.task.model import Task
from stablepush.task.release import MOVE_SPEED  # m/s of G between contacts (the release's load depends on it)
from stablepush.units import MM, as_triple

TURN_SPEED = math.radians(60)  # rad/s of G between contacts
SETTLE_TIME = 0.2  # s held still at the end of the last push, before the final retract
# s held still after the final retract: the pads alone hold the object now, and the verdict judges
# where it comes to rest (stablepush.execution.verdict), not where it is while still sliding.
RELEASE_TIME = 0.3
LIFT_MARGIN = 0.02  # m above every feature when the object changes lanes
# The guarded end of each approach (world.GUARD_SPAN, guard.py) runs at this speed: 0.02 mm of G's
# travel a waypoint at 100 Hz.
GUARD_SPEED = 2.0e-3  # m/s
# Samples a trajectory may hold: 50 min of motion at 100 Hz. Each costs tens of microseconds to make
# and hundreds of bytes to keep, so a longer one is refused before it takes minutes and gigabytes.
MAX_TRAJECTORY_SAMPLES = 300_000


@dataclass(frozen=True)
class ArmWaypoint:
    """One streamed end-effector set-point. `step` is the plan step the motion is heading for
    (during a push) or the last one reached (otherwise); when `completes` is set, the arm's
    acknowledgement of this waypoint confirms that plan step. `planned` is that step's pose in the
    grasp (x mm, z mm, theta deg) in the plan being streamed, a re-planned one after a correction
    (so a recording can show the plan the arm was following, `stablepush.sim.mujoco.video`)."""

    seq: int
    t: float  # s from the start of the stream
    step: int
    completes: bool
    phase: str  # push | settle | retract | move | approach
    pose: Tuple[float, ...]
    planned: Optional[Tuple[float, float, float]] = None
    guarded: bool = False  # part of an approach's slow end, where the executor watches for the touch


class _Stream:
    """Accumulates waypoints at a fixed rate."""

    def __init__(self, rate_hz: float, start_pose: np.ndarray, step: int, planned: Sequence[Sequence[float]]):
        self.period = 1.0 / rate_hz
        self.points: List[ArmWaypoint] = []
        self.pose = start_pose
        self.step = step
        self.planned = [as_triple(float(v) for v in pose) for pose in planned]  # each plan step's pose in the grasp

    def _emit(self, T: np.ndarray, phase: str, step: int, completes: bool = False, guarded: bool = False) -> None:
        if len(self.points) >= MAX_TRAJECTORY_SAMPLES:
            raise PlanError("waypoints", f"the trajectory passes {MAX_TRAJECTORY_SAMPLES} samples "
                                         f"({MAX_TRAJECTORY_SAMPLES * self.period / 60:.0f} min of motion at "
                                         f"{1 / self.period:g} Hz) by plan step {step}: a lower rate, or a "
                                         f"shorter plan")
        self.points.append(ArmWaypoint(seq=len(self.points), t=(len(self.points) + 1) * self.period, step=step,
                                       completes=completes, phase=phase, pose=tuple(matrix_to_pose(T)),
                                       planned=self.planned[step], guarded=guarded))
        self.pose = T

    def move(self, target: np.ndarray, phase: str, guarded_speed: Optional[float] = None) -> None:
        """A straight move of G to `target` with smooth (3s^2 - 2s^3) timing, or, with
        `guarded_speed` [m/s], at that constant speed with its waypoints marked `guarded`."""
        start = self.pose
        distance = float(np.linalg.norm(target[:3, 3] - start[:3, 3]))
        q0 = np.array(matrix_to_pose(start)[3:])
        q1 = np.array(matrix_to_pose(target)[3:])
        angle = 2 * math.acos(min(1.0, abs(float(np.dot(q0, q1)))))
        duration = max(distance / (guarded_speed or MOVE_SPEED), angle / TURN_SPEED)
        if duration < 1e-9:
            return
        n = max(1, math.ceil(duration / self.period))
        for i in range(1, n + 1):
            s = i / n
            if guarded_speed is None:
                s = s * s * (3 - 2 * s)
            T = pose_to_matrix([*(start[:3, 3] + s * (target[:3, 3] - start[:3, 3])), *slerp(q0, q1, s)])
            self._emit(T, phase, self.step, guarded=guarded_speed is not None)

    def push(self, T_WO: np.ndarray, q0, q1, duration: float, step: int, come_to_rest: bool = False) -> None:
        """One unit push: q moves from q0 to q1 over `duration` while the object stays at T_WO, at
        constant speed, or, with `come_to_rest` (the last push of a contact), along
        s(u) = u + u^2 - u^3: the same speed at the start, none at the end. An arm stopped dead from
        full speed overshoots its lag, and the high-mu offset then sagged 0.2 mm and 0.45 deg in the
        grasp before the settle hold ended (docs/results/execute-shipped.md).
        s'(u) = 1 + 2u - 3u^2 peaks at 4/3, at u = 1/3: the eased push is faster than the stability
        test assumed on its way to rest (docs/execution.md). The push takes the fewest whole periods
        that last `duration` (the model's step time): a rate that does not divide it pushes slower."""
        n = max(1, math.ceil(duration / self.period - 1e-9))
        for i in range(1, n + 1):
            u = i / n
            s = u + u * u - u ** 3 if come_to_rest else u
            q = [a + (b - a) * s for a, b in zip(q0, q1)]
            self._emit(T_WO @ np.linalg.inv(grasp_transform(q)), "push", step, completes=i == n)
        self.step = step

    def hold(self, duration: float, phase: str) -> None:
        for _ in range(max(1, round(duration / self.period))):
            self._emit(self.pose, phase, self.step)


def check_resume_from(steps: Sequence[Waypoint], resume_from: int, field: str = "resume_from") -> None:
    """PlanError (naming `field`) unless the plan has a push after step `resume_from`."""
    if not 0 <= resume_from < len(steps) - 1:
        raise PlanError(field, f"must be a step from 0 to {len(steps) - 2} (the plan has {len(steps) - 1} pushes)")


def arm_trajectory(
    task: Task,
    steps: Sequence[Waypoint],
    features: Dict[str, Feature],
    rate_hz: float,
    start_pose: Sequence[float],
    resume_from: int = 0,
    resting_on: Optional[str] = None,
) -> List[ArmWaypoint]:
    """The end-effector waypoints that carry out plan steps resume_from+1 .. end, starting with
    G at `start_pose` holding the object at plan pose `resume_from`, on the feature of pusher
    `resting_on` (default: the one that pushed it there; none at step 0)."""
    check_resume_from(steps, resume_from)
    env = task.environment
    retract = env.retract * MM
    home = np.asarray(env.home, float) * MM
    lane_of = {name: f.object_pose[1, 3] + env.lane_offset * MM for name, f in features.items()}
    reach = max(math.hypot(x, z) for x, z in task.object.vertices) * MM
    top = max(max(f.start[2], f.end[2]) for f in features.values())

    stream = _Stream(rate_hz, pose_to_matrix(start_pose), resume_from, [s.pose for s in steps])
    # On a resume the object may still rest on a feature: back off it first.
    if resting_on is None and resume_from > 0:
        resting_on = steps[resume_from].pusher
    current: Optional[Feature] = features.get(resting_on) if resting_on is not None else None
    lane = home[1] + env.lane_offset * MM
    for contact in contacts_of(steps):
        if contact.last <= resume_from:
            continue
        first = max(contact.first, resume_from)
        feature = features[contact.pusher]
        q_first = steps[first].pose
        touching = feature.object_pose @ np.linalg.inv(grasp_transform(q_first))
        guarded_from = translation(feature.normal * min(GUARD_SPAN, retract)) @ touching
        if near_pose(stream.pose, touching) and current is not None:
            stream.move(touching, "approach")  # resting on it, up to the arm's tracking error
        elif current is None and (near_pose(stream.pose, touching) or near_pose(stream.pose, guarded_from)):
            stream.move(guarded_from, "approach")  # the run starts at this feature (scene_description)
            stream.move(touching, "approach", guarded_speed=GUARD_SPEED)
        else:
            approach = translation(feature.normal * retract) @ touching
            if current is not None:
                stream.move(translation(current.normal * retract) @ stream.pose, "retract")
                lane = lane_of[current.pusher]
            target_lane = lane_of[feature.pusher]
            stream.move(_with(stream.pose, y=lane), "move")
            if abs(target_lane - lane) > 1e-9:
                clear_z = top + math.hypot(*q_first[:2]) * MM + reach + LIFT_MARGIN
                stream.move(_with(stream.pose, z=max(clear_z, stream.pose[2, 3])), "move")
                stream.move(_with(stream.pose, y=target_lane), "move")
            stream.move(_with(approach, y=target_lane), "move")
            stream.move(approach, "approach")
            stream.move(guarded_from, "approach")
            stream.move(touching, "approach", guarded_speed=GUARD_SPEED)
        for i in range(first + 1, contact.last + 1):
            stream.push(feature.object_pose, steps[i - 1].pose, steps[i].pose, task.dynamics.step_time, i,
                        come_to_rest=i == contact.last)
        current = feature
    stream.hold(SETTLE_TIME, "settle")
    if current is not None and not env.end_on_feature:
        stream.move(translation(current.normal * retract) @ stream.pose, "retract")
        stream.hold(RELEASE_TIME, "retract")
    return stream.points


def past_touch(feature: Feature, touching: Sequence[float], reach: float, rate_hz: float, step: int,
               planned: Sequence[Sequence[float]]) -> List[ArmWaypoint]:
    """The guarded approach carried on past the plan's touch (`touching`, G's pose there), for a
    feature beyond its place: up to `reach` [m] further along the approach at GUARD_SPEED, then
    back to the plan's touch if nothing was met (the contact's pushes, streamed after these, start
    there). `step`: the plan step the object is at; `planned`: every plan step's pose in the grasp."""
    start = pose_to_matrix(touching)
    stream = _Stream(rate_hz, start, step, planned)
    stream.move(translation(-feature.normal * reach) @ start, "approach", guarded_speed=GUARD_SPEED)
    stream.move(start, "approach")
    return stream.points


def _with(T: np.ndarray, **coordinate) -> np.ndarray:
    out = T.copy()
    for axis, value in coordinate.items():
        out["xyz".index(axis), 3] = value
    return out


def renumbered(w: ArmWaypoint, rate_hz: float, points: Sequence[ArmWaypoint]) -> deque:
    """`points` streamed next after `w`: seq and t counted on from it."""
    period = 1.0 / rate_hz
    return deque(dataclasses.replace(p, seq=w.seq + 1 + i, t=w.t + (i + 1) * period) for i, p in enumerate(points))


def contact_first(steps: Sequence[Waypoint], step: int) -> int:
    """The first push of the contact that plan step `step` (a push) belongs to: the run's contact
    records and the guard's findings are keyed by it."""
    first = step
    while first > 1 and steps[first - 1].pusher == steps[step].pusher:
        first -= 1
    return first
