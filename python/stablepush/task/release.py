"""What the pads must hold when a run lets go of the object: its weight and the load of the hand's
acceleration as the arm backs off the last feature, anywhere the plan may end.

Why the static hold ratio (StablePushModel.hold_ratio, docs/model.md section 2) is not enough for a
cure. At a hold ratio of 1 the pads' friction just balances the weight, but a run's release is
not static: the executor backs G off the last feature by environment.retract along the feature's
normal with smooth timing (execution/stream.py: s = 3u^2 - 2u^3 at MOVE_SPEED), whose acceleration
is largest, 6 v^2 / d, when the feature has just let go; the pads then carry m (g - a), and the
arm's joint servos, following set-points that change slope every waypoint, turn that
acceleration partly across the normal too. Measured on the simulated arm (G's acceleration over
10 ms in the final retract): 2.6-3.4 m/s^2 along the normal and up to 0.6 across for 50 g parts,
against 6 v^2 / d = 3 m/s^2 for the default 20 mm retract. A bar gripped with exactly the force
the static ratio asks for slid 28 mm on release; gripped so that the pads hold m (g - a) for
every |a| <= 6 v^2 / d, it landed. And the plan ends anywhere within planner.tolerance of the
goal, where the centre of mass may be half a tolerance further from the pads.

So the hold a cure asks for is `release_hold_ratio`: the static ratio with gravity g - a, the
least over accelerations a of magnitude RELEASE_ACCELERATION in DIRECTIONS directions (on the
circle: the ratio's inverse is a gauge of the load, convex in a, so the least over the disc lies
on its rim) and over the corners of the task's uncertainty box.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
from typing import Dict, List, Sequence, Tuple

import numpy as np

from stablepush.task.model import Task
from stablepush.units import MM, as_triple, pose_to_si

# m/s: the executor's speed of G between contacts and on the retract (execution.stream moves at it),
# defined here, below the executor, since the release's load depends on it
MOVE_SPEED = 0.1
DIRECTIONS = 12  # accelerations tried around the circle, 30 deg apart


def release_acceleration(task: Task) -> float:
    """The peak acceleration [m/s^2] of G as the run backs off its last feature: 6 v^2 / d of the
    smooth retract over environment.retract (3 m/s^2 for the default 20 mm)."""
    return 6.0 * MOVE_SPEED ** 2 / (task.environment.retract * MM)


def release_hold_ratio(task: Task, pose: Sequence[float], pusher: int) -> float:
    """The factor of the release's load the pads alone hold at `pose` (x, z mm, theta deg) after
    pusher `pusher`'s feature lets go: the static hold ratio with gravity g - a (g as on that
    feature), the least over |a| = release_acceleration and over the uncertainty box's corners.
    At least 1: the pads hold the object through the release. +inf without gravity."""
    q = pose_to_si(pose)
    accel = release_acceleration(task)
    turns = [(math.cos(2 * math.pi * k / DIRECTIONS), math.sin(2 * math.pi * k / DIRECTIONS))
             for k in range(DIRECTIONS)]
    least = math.inf
    # Each corner of the uncertainty box as a task (Task.corner_models' own), its gravity replaced.
    for corner in task.corner_tasks:
        g = np.asarray(corner.model.gravity_in_gripper(q, pusher), float)
        if not g.any():
            continue  # no weight: the arm's acceleration alone is not a release the model speaks of
        for c, s in turns:
            loaded = dataclasses.replace(corner, gravity=tuple(g - accel * np.array([c, s])), uncertainty={})
            least = min(least, loaded.model.hold_ratio(q, -1))
    return least


def goal_poses(task: Task) -> List[Tuple[float, float, float]]:
    """The goal and the corners of its tolerance box (x, z mm, theta deg): a plan ends anywhere in it."""
    (x, z, theta), (mm, deg) = task.goal, task.planner.tolerance
    return [as_triple(task.goal)] + [(x + sx * mm, z + sz * mm, theta + st * deg)
                                 for sx, sz, st in itertools.product((-1.0, 1.0), repeat=3)]


def goal_release_holds(task: Task) -> Dict[str, float]:
    """Per pusher, release_hold_ratio at the least favourable pose within the goal's tolerance
    (goal_poses), with gravity as on that pusher's feature."""
    poses = goal_poses(task)
    return {p.name: min(release_hold_ratio(task, pose, i) for pose in poses) for i, p in enumerate(task.pushers)}


def needed_hold_ratio(task: Task, pushers: Sequence[str]) -> float:
    """The planner.min_hold_ratio (a static ratio, the planner's test at a plan's end) that makes a
    plan that ends with one of `pushers` end where the pads also hold the release's load: above
    the static ratio of every goal pose (goal_poses) where they do not, rounded up to 0.01; 1 when
    they hold it wherever the static ratio is 1."""
    models = task.corner_models
    need = 1.0
    for i, p in enumerate(task.pushers):
        if p.name not in pushers:
            continue
        for pose in goal_poses(task):
            if release_hold_ratio(task, pose, i) < 1.0:
                need = max(need, min(m.hold_ratio(pose_to_si(pose), i) for m in models))
    return math.floor(need * 100.0) / 100.0 + 0.01 if need > 1.0 else 1.0
