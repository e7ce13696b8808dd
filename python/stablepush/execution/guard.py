"""The guarded approach: find each feature by touch rather than trust where the plan put it.

A feature off its place along the approach either pushes the object in the grasp before the
contact's first push (met early) or lets it ride with the hand into it (met late); every push of
the contact then carries that error to the goal, where the pusher cannot push it back (the
hexagon's and the tilted-gravity offset's misses, docs/results/evaluate-1000-trials.md). So the approach ends slowly
(world.GUARD_SPAN at stream.GUARD_SPEED) and the executor watches for the touch there: the arm's
`contact_force` past `touch_n` (a wrist force-torque sensor, which tells it before the pads slide),
or, from an arm that reports no force, the tracker's pose in the grasp moved past `touch_mm` or
`touch_deg` since the slow end began. The arm holds still `hold_s`, and the contact's pushes then
start from the measured pose with the feature where it was found (`found_feature`, or turned as
the object rests on it when the touch turned it: `touched_feature`), so they move the object in
the grasp as planned wherever the feature stands. A feature not met by the plan's
touch is sought up to `reach_mm` beyond it, as slowly; not met there, the contact runs as planned.

At the touch the object is not yet seated on the feature: a feature turned about y meets it at a
corner, and the pads' friction turns it on during the contact's first push (the pivot's prism, on
a left feature turned -0.4 deg, came to rest at -0.82 deg in the world there, and ended -0.95 deg
off). After that push, with the pusher sticking, the object holds still in the world, so its
measured world pose there (`seated_feature`), when it is turned more than `seat_deg` from the plan's,
is the feature's for the rest of the contact, turn included, and the pushes left are re-based on it
as at the touch (`from_touch`).

The guard needs the tracker's `object_in_grasp` (protocol.py) to measure where the object is, and
re-plans nothing; a cell without a tracker approaches as planned. Poses in the grasp are (x mm,
z mm, theta deg).
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, replace
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from stablepush.errors import SettingError
from stablepush.execution.stream import ArmWaypoint, arm_trajectory, contact_first, past_touch, renumbered
from stablepush.execution.world import RESTING_ANGLE, Feature
from stablepush.frames import angle_about_y, grasp_transform, pose_to_matrix, rot_y
from stablepush.plan.plan import Waypoint
from stablepush.task.model import Task
from stablepush.units import MM, angle_difference_deg

# Valid ranges of the guard's parameters (mm, deg, N, s). A touch threshold below the sensor's noise
# fires on noise; the reach is travel into where the plan says a feature is, so it stays short.
GUARD_PARAMETER_RANGES = {"touch_mm": (0.001, 0.5), "touch_deg": (0.001, 0.5), "touch_n": (0.01, 50.0),
                          "reach_mm": (0.0, 2.0), "hold_s": (0.0, 1.0), "seat_deg": (0.0, 2.0)}
# The thresholds read from the tracker, each kept this many standard deviations of its noise clear of it,
# and which of the noise's (mm, deg) it is held clear of.
NOISE_SIGMAS = 4.0
NOISE_THRESHOLDS = {"touch_mm": 0, "touch_deg": 1, "seat_deg": 1}


@dataclass(frozen=True)
class GuardedApproach:
    """When the feature has met the object: `touch_n` [N] of the arm's contact force, or, without
    one, the pose in the grasp moved `touch_mm` or `touch_deg` since the approach's slow end began
    (0.01 mm of the pivot's 1 mm unit push); how long to hold still before measuring where the
    object is (`hold_s` [s]: the arm's lag behind the stream settles); and how far past the plan's
    touch to seek a feature not met by then (`reach_mm`: features placed up to 0.5 mm off, turned
    up to 0.5 deg over a 30 mm face). After a contact's first push, an object at rest turned more
    than `seat_deg` [deg] in the world from where the plan holds it has met a turned feature; within
    it, the contact runs as planned. A flush face seats off by its contact's compliance, which
    changes with the load (the pivot's prism by -0.09 deg at its first push and -0.21 deg by its
    last, on a feature not turned); re-based on that, the pivot turned twice as far with the hand
    and ended 0.09 deg further off."""

    touch_mm: float = 0.01
    touch_n: float = 0.5
    touch_deg: float = 0.02
    reach_mm: float = 0.8
    hold_s: float = 0.05
    seat_deg: float = 0.15

    def __post_init__(self):
        for name, (low, high) in GUARD_PARAMETER_RANGES.items():
            value = getattr(self, name)
            if not low <= value <= high:
                raise SettingError(f"guard.{name}", f"must lie in [{low:g}, {high:g}], got {value!r}")

    @classmethod
    def for_tracker_noise(cls, noise_mm: float = 0.0, noise_deg: float = 0.0) -> "GuardedApproach":
        """The default guard with its touch and seat thresholds no lower than NOISE_SIGMAS standard
        deviations of the tracker's noise (mm, deg), so that noise alone does not read as a touch or
        a turn. SettingError (field `tracker_noise`) for a noise that would lift a threshold past its
        range (GUARD_PARAMETER_RANGES): a touch read only after the object has moved that far in the
        grasp is no touch, and the contact would start from a pose the noise makes up. Run such a
        tracker unguarded."""
        noise = (noise_mm, noise_deg)
        default = cls()
        most = [min(GUARD_PARAMETER_RANGES[name][1] for name, w in NOISE_THRESHOLDS.items() if w == which)
                / NOISE_SIGMAS for which in (0, 1)]
        if not all(0.0 <= v <= m for v, m in zip(noise, most)):  # written so that nan fails it too
            raise SettingError("tracker_noise", f"{noise_mm:g} mm / {noise_deg:g} deg is more than the guarded "
                                                f"approach can tell a touch from: it reads the touch past "
                                                f"{NOISE_SIGMAS:g} standard deviations of the noise, at most "
                                                f"{most[0] * NOISE_SIGMAS:g} mm and {most[1] * NOISE_SIGMAS:g} deg "
                                                f"from where the slow end began, so a noise of at most {most[0]:g} mm "
                                                f"and {most[1]:g} deg; run unguarded (--no-guard)")
        return cls(**{name: max(getattr(default, name), NOISE_SIGMAS * noise[which])
                      for name, which in NOISE_THRESHOLDS.items()})

    def met(self, before: Mapping[str, float], now: Mapping[str, float], force=None) -> bool:
        """Whether the feature has met the object: the arm's `contact_force` (N) past touch_n when
        it reports one, else the object moved in the grasp from `before` to `now` past the touch
        thresholds."""
        if force is not None:
            return float(np.linalg.norm(np.asarray(force, float))) > self.touch_n
        moved = math.hypot(float(now["x"]) - float(before["x"]), float(now["z"]) - float(before["z"]))
        turned = abs(angle_difference_deg(float(now["theta"]), float(before["theta"])))
        return moved > self.touch_mm or turned > self.touch_deg


def found_feature(feature: Feature, ee_pose, in_grasp) -> Feature:
    """The feature where it met the object: the object's world position there, G's world pose
    `ee_pose` times the measured pose in the grasp `in_grasp` (x mm, z mm, theta deg), with the
    world orientation the plan gives it on the feature. The measured orientation holds the arm's
    tracking error of the moment (a tenth of a degree), and the pushes would then hold the object
    that far off flush with the feature: it turns in the grasp by as much as it seats."""
    T_WO = feature.object_pose.copy()
    T_WO[:3, 3] = (pose_to_matrix(ee_pose) @ grasp_transform(in_grasp))[:3, 3]
    return replace(feature, object_pose=T_WO)


def touched_feature(feature: Feature, ee_pose, in_grasp) -> Feature:
    """The feature as the touch found it: `found_feature`, unless the touch left the object turned
    in the world, from where the plan holds it on the feature, past what the stream takes for
    resting on it (world.RESTING_ANGLE). Then the feature is taken turned, as the object rests on
    it (`seated_feature`): held to the plan's orientation, G's pose on it would differ from where
    G is by that turn, the stream would back off the feature and approach it again, and each
    touch would turn the object further."""
    seated = seated_feature(feature, ee_pose, in_grasp)
    if abs(math.radians(turned_deg(feature, seated))) > RESTING_ANGLE:
        return seated
    return found_feature(feature, ee_pose, in_grasp)


def seated_feature(feature: Feature, ee_pose, in_grasp) -> Feature:
    """The feature as the object rests on it after the contact's first push: the object's measured
    world pose, G's world pose `ee_pose` times the measured pose in the grasp `in_grasp` (x mm,
    z mm, theta deg), kept in the grasp plane (its turn about y and its x, z; the plan's y)."""
    T_measured = pose_to_matrix(ee_pose) @ grasp_transform(in_grasp)
    T_WO = feature.object_pose.copy()
    turn = angle_about_y(T_measured[:3, :3]) - angle_about_y(T_WO[:3, :3])
    T_WO[:3, :3] = rot_y(turn) @ T_WO[:3, :3]
    T_WO[[0, 2], 3] = T_measured[[0, 2], 3]
    return replace(feature, object_pose=T_WO)


def turned_deg(planned: Feature, seated: Feature) -> float:
    """How far the object on `seated` is turned about y from where `planned` holds it [deg]."""
    return math.degrees(angle_about_y(seated.object_pose[:3, :3]) - angle_about_y(planned.object_pose[:3, :3]))


def from_touch(steps: Sequence[Waypoint], k: int, measured: Sequence[float]) -> List[Waypoint]:
    """The plan with its contact from step k starting at the pose measured at the touch: the
    difference from the plan's pose k is taken out in equal parts over the contact's pushes, so that
    the contact still ends where the plan does. The object may have moved in the grasp before the
    touch (a touch read from the tracker pushes it a few hundredths of a millimetre along the
    approach; the low-mu offset's moved 0.07 mm in a transit between features), and a first push
    asked to undo all of it at once may ask the feature to pull (the pivot's first push, a pure
    turn, then turned the object with the hand and lost 0.37 deg)."""
    last = k + 1
    while last + 1 < len(steps) and steps[last + 1].pusher == steps[k + 1].pusher:
        last += 1
    d = [measured[0] - steps[k].pose[0], measured[1] - steps[k].pose[1], measured[2] - steps[k].pose[2]]
    x, z, theta = measured
    out = list(steps[:k]) + [Waypoint(x, z, theta, pusher=steps[k].pusher)]
    for i in range(k + 1, last):
        share = (last - i) / (last - k)
        out.append(replace(steps[i], x=steps[i].x + share * d[0], z=steps[i].z + share * d[1],
                           theta=steps[i].theta + share * d[2]))
    return out + list(steps[last:])


def offset_along_approach_mm(planned: Feature, found: Feature) -> float:
    """How far beyond its place (positive) or short of it (negative) the feature was found, along
    the approach (against the pusher's inward normal), at the object's origin [mm]."""
    shift = found.object_pose[:3, 3] - planned.object_pose[:3, 3]
    return float(-np.dot(planned.normal, shift)) / MM


def measured_pose(planned: Sequence[float], tracked: dict) -> Tuple[float, float, float]:
    """The tracker's pose in the grasp (x mm, z mm, theta deg) with theta on the planned pose's turn (a
    plan may run past +-180 deg; a tracker reports one turn)."""
    theta = planned[2] + angle_difference_deg(float(tracked["theta"]), planned[2])
    return float(tracked["x"]), float(tracked["z"]), theta


class GuardWatch:
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
        assert self.guard is not None, "since is set only while the watch is on, which it is with a guard"
        k, pusher = w.step, steps[w.step + 1].pushed_by  # the push the approach leads to
        slow_end_left = bool(pending) and pending[0].guarded
        if self.holding:
            if slow_end_left:
                return None
            # Held still: the contact's pushes start from where the object is, on the feature where it is.
            measured = measured_pose(steps[k].pose, state["object_in_grasp"])
            on_feature = touched_feature(features[pusher], state["ee_pose"], measured)
            self.found[k + 1] = offset_along_approach_mm(features[pusher], on_feature)
            features[pusher] = on_feature
            steps = from_touch(steps, k, measured)
            self.since, self.holding = None, False
            return steps, renumbered(w, rate_hz, arm_trajectory(task, steps, features, rate_hz, state["ee_pose"],
                                                                 resume_from=k, resting_on=pusher))
        if self.guard.met(self.since, state["object_in_grasp"], state.get("contact_force")):
            self.holding = True
            return steps, renumbered(w, rate_hz, [w] * max(1, round(self.guard.hold_s * rate_hz)))
        if not slow_end_left and not self.sought_past:  # at the plan's touch, nothing met: seek on past it
            self.sought_past = True
            past = past_touch(features[pusher], w.pose, self.guard.reach_mm * MM, rate_hz, k, [s.pose for s in steps])
            return steps, renumbered(w, rate_hz, past + list(pending))
        return None

    def _seated(self, task: Task, steps: List[Waypoint], features: Dict[str, Feature], w: ArmWaypoint, state: dict,
                rate_hz: float):
        """After push w.step: when it is its contact's first and more follow, the pushes left re-based
        on the feature where the object rests (guard.seated_feature), else None."""
        assert self.guard is not None, "called while the watch is on, which it is with a guard"
        k = w.step
        pusher = steps[k].pushed_by  # w is a push's
        if contact_first(steps, k) != k or k + 1 >= len(steps) or steps[k + 1].pusher != pusher \
                or "object_in_grasp" not in state:
            return None
        measured = measured_pose(steps[k].pose, state["object_in_grasp"])
        seated = seated_feature(features[pusher], state["ee_pose"], measured)
        self.seated[k] = turned_deg(features[pusher], seated)
        if abs(self.seated[k]) <= self.guard.seat_deg:
            return None
        features[pusher] = seated
        steps = from_touch(steps, k, measured)
        return steps, renumbered(w, rate_hz, arm_trajectory(task, steps, features, rate_hz, state["ee_pose"],
                                                             resume_from=k, resting_on=pusher))
