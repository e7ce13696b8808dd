"""The arm's joints along a plan's timed trajectory: whether the arm can follow the plan at all,
decided before any motion, and the joint trajectory a lab's controllers take (ros2_control's
joint_trajectory_controller, MoveIt's execution).

Every sample of the timed trajectory (execution.trajectory: the executor's stream) is solved for
the arm's joint positions (ik.solve_ik, each from the sample before, so the path stays on one
branch) on the MuJoCo model of the run's scene (cell_model.build_mjcf: the shipped arm, arm.xml, its
jaws, the object and the features where the executor places them). The cell check refuses a plan
(CellError, a PlanError: exit 2) first where a sample lies farther from the arm's first joint
than the chain's length (out of reach: by how much, from where), then at the first sample where
- no joint positions within the arm's limits put G within FK_TOLERANCE of the sample's pose
  (out of reach, or a joint at its limit: named, with how far G stays off);
- a joint would move faster than its speed limit between two samples (a branch flip, or a
  motion the joints cannot make; the URDF's `limit velocity`, else robot.max_joint_speed);
- a link of the arm comes closer than LINK_CLEARANCE to a feature or the floor (named, with the
  distance; the jaws and pads, which hold the object and stand FEATURE_CLEARANCE clear of the
  features along y by construction, are left out).
Poses are (x, y, z, qw, qx, qy, qz) in the world [m]; joint angles in rad.
"""
from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from stablepush.errors import PlanError
from stablepush.execution.arm import Arm, ArmReady, RobotDescription
from stablepush.execution.bags import JointSamples
from stablepush.execution.scene import Scene
from stablepush.execution.stream import ArmWaypoint
from stablepush.execution.trajectory import Trajectory, timed_trajectory
from stablepush.execution.world import place_features, scene_description
from stablepush.extras import require
from stablepush.frames import pose_to_matrix
from stablepush.kinematics import cell_model, ik
from stablepush.kinematics.arm_kinematics import ArmKinematics
from stablepush.kinematics.robot import arm_model, model_stamp, robot_description
from stablepush.plan.plan import Plan
from stablepush.plan.verify import check_plan
from stablepush.task.model import Robot, Task

mujoco = require("mujoco", "the arm's kinematics and the cell check")  # a kinematics library here, not a simulator

# G through the joints' forward kinematics stays this close to each sample (m, rad): the joint
# trajectory reproduces the Cartesian one within 0.01 mm and 0.01 deg.
FK_TOLERANCE = (1e-5, math.radians(0.01))
LINK_CLEARANCE = 0.0  # m a link of the arm keeps from a feature or the floor (0: touching is refused)
CLEARANCE_SEEN = 0.05  # m: distances past this are not measured (mj_geomDistance's distmax)
# The arm's bodies whose geoms are its links for the clearance check: those the joints move, less
# the jaws (their fingers hold the object and the pads touch it).
_JAW_BODIES = ("finger_pos", "finger_neg")


class CellError(PlanError):
    """A plan the arm cannot follow in its cell, found before any motion: `sample` (its index in
    the timed trajectory), `t` [s], `step` (the plan step) and why."""

    def __init__(self, sample: int, t: float, step: int, phase: str, reason: str):
        self.sample, self.t, self.step, self.phase, self.reason = sample, t, step, phase, reason
        super().__init__("", f"the arm cannot follow the plan: at t {t:.2f} s (sample {sample}, plan step {step}, "
                             f"{phase}) {reason}")

    def verdict(self) -> dict:
        """The refusal as plain JSON values (`stablepush check-cell --json`)."""
        return {"follows": False, "sample": self.sample, "t": self.t, "step": self.step, "phase": self.phase,
                "reason": self.reason}


@dataclass(frozen=True)
class JointPath:
    """The arm's joint positions `q` [rad] (one row per sample, a column per joint of `joints`)
    at times `t` [s], with each sample's phase and plan step, and how closely they carry out the
    Cartesian trajectory: the largest error of G through forward kinematics (`fk_error_mm`,
    `fk_error_deg`), the fastest joint (`peak_speed`, rad/s), and the least clearance of a link
    (`clearance_mm`, from `nearest`: link body and feature or floor). `start` is where the joints
    stand, at rest, at t = 0 (the stream's start pose, before its first sample), and `robot` the
    arm's model as a bag names it (its base link, its URDF)."""

    joints: Tuple[str, ...]
    t: np.ndarray
    q: np.ndarray
    phase: List[str]
    step: np.ndarray
    fk_error_mm: float
    fk_error_deg: float
    peak_speed: float
    clearance_mm: float
    nearest: Tuple[str, str]
    start: np.ndarray
    robot: RobotDescription

    def __len__(self) -> int:
        return len(self.t)

    def velocities(self) -> np.ndarray:
        """Each joint's velocity [rad/s] at each sample, as a controller that is handed the samples
        needs it: the finite difference of the positions over their times (central, second order;
        the first sample's from the start at t = 0), zero at the last sample, where the stream ends
        and the arm stays."""
        v = _derivative(self.t, self.q, self.start)
        v[-1] = 0.0
        return v

    def accelerations(self, velocities: Optional[np.ndarray] = None) -> np.ndarray:
        """Each joint's acceleration [rad/s^2] at each sample: the finite difference of
        `velocities` (this path's, when not given) as they do of the positions, from rest at t = 0,
        zero at the last sample."""
        velocities = self.velocities() if velocities is None else velocities
        a = _derivative(self.t, velocities, np.zeros(len(self.joints)))
        a[-1] = 0.0
        return a

    def samples(self) -> JointSamples:
        """The joints as a bag writes them (bags.write_bag)."""
        qd = self.velocities()
        return JointSamples(self.joints, self.q, qd, self.accelerations(qd), self.robot)

    def columns(self) -> List[str]:
        return (["t"] + [f"{name}_rad" for name in self.joints] + [f"{name}_rad_s" for name in self.joints]
                + [f"{name}_rad_s2" for name in self.joints] + ["phase", "step"])

    def rows(self) -> List[list]:
        velocities = self.velocities()
        return [[float(t), *(float(v) for v in q), *(float(v) for v in qd), *(float(v) for v in qdd), phase, int(step)]
                for t, q, qd, qdd, phase, step in zip(self.t, self.q, velocities, self.accelerations(velocities),
                                                      self.phase, self.step)]

    def to_csv(self) -> str:
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(self.columns())
        writer.writerows(self.rows())
        return buffer.getvalue()

    def to_json(self) -> str:
        units = {"t": "s", "q": "rad", "qd": "rad/s", "qdd": "rad/s^2"}
        return json.dumps({"joints": list(self.joints), "units": units, "columns": self.columns(),
                           "rows": self.rows()}) + "\n"

    def verdict(self) -> dict:
        """That the arm follows the plan, with the figures of `describe`, as plain JSON values."""
        seen = self.clearance_mm < CLEARANCE_SEEN * 1e3
        return {"follows": True, "joints": list(self.joints), "samples": len(self), "fk_error_mm": self.fk_error_mm,
                "fk_error_deg": self.fk_error_deg, "peak_joint_speed": self.peak_speed,
                "least_clearance_mm": self.clearance_mm if seen else None,
                "nearest": list(self.nearest) if seen else None}

    def describe(self) -> str:
        clear = (f"least clearance {self.clearance_mm:.1f} mm ({self.nearest[0]} to {self.nearest[1]})"
                 if self.clearance_mm < CLEARANCE_SEEN * 1e3 else
                 f"every link over {CLEARANCE_SEEN * 1e3:g} mm from the features and the floor")
        return (f"{len(self)} samples on {len(self.joints)} joints; G through the joints within "
                f"{self.fk_error_mm:.5f} mm, {self.fk_error_deg:.5f} deg; fastest joint {self.peak_speed:.2f} rad/s "
                f"(within its limit); {clear}")


def _derivative(t: np.ndarray, values: np.ndarray, at_zero: np.ndarray) -> np.ndarray:
    """d values / dt at each of the times `t`, with `at_zero` the value at t = 0 before them
    (np.gradient: central differences, second order on uneven times too)."""
    times = np.concatenate([[0.0], np.asarray(t, float)])
    return np.gradient(np.vstack([at_zero, values]), times, axis=0)[1:]


def joint_path(task: Task, plan: Plan, rate_hz: float = 100.0, trajectory: Optional[Trajectory] = None,
               robot: Optional[Robot] = None) -> JointPath:
    """The joints of `robot` (the task's environment.robot when None) along the plan's timed
    trajectory at `rate_hz` (`trajectory`, when the caller has it already), once the plan is shown
    to belong to the task (check_plan) and the arm can follow it in its cell (CellError otherwise)."""
    if robot is not None and not isinstance(robot, Robot):
        raise TypeError(f"robot must be a Robot (stablepush.task.Robot) or None, got {type(robot).__name__}")
    plan = check_plan(task, plan)
    steps = list(plan.waypoints)
    scene = scene_description(task, place_features(task, steps), steps[0].pose)
    robot = robot if robot is not None else task.environment.robot
    return _Solver(scene, robot).solve(trajectory if trajectory is not None else timed_trajectory(task, plan, rate_hz))


_CHECKED: Dict[str, JointPath] = {}  # checked_path's answers by what they rest on
_CHECKED_KEPT = 8


def checked_path(task: Task, plan: Plan, rate_hz: float, robot: Robot) -> JointPath:
    """joint_path, remembered for the cell, plan, rate and robot it was asked of: a study's trials
    run one plan in one cell, and ask once per process."""
    key = json.dumps([task.identity(), task.environment.as_dict(), [list(w.pose) for w in plan.waypoints],
                      rate_hz, robot.as_dict(), model_stamp(robot)], default=str)
    if key not in _CHECKED:
        if len(_CHECKED) >= _CHECKED_KEPT:
            _CHECKED.pop(next(iter(_CHECKED)))
        _CHECKED[key] = joint_path(task, plan, rate_hz, robot=robot)
    return _CHECKED[key]


class _Solver:
    """IK, limits, speed and clearance along one trajectory, on the MuJoCo model of its scene."""

    def __init__(self, scene: Scene, robot: Robot):
        self.arm = arm_model(robot)
        self.robot = robot_description(robot)
        model = mujoco.MjModel.from_xml_string(cell_model.build_mjcf(scene, robot=robot))
        self.kin = ArmKinematics(model, self.arm.joints)
        self.model, self.data = model, self.kin.data
        # out of reach, the first sample says so (CellError) from the nearest posture found
        self.home, _ = ik.find_home(self.kin, scene.gripper_pose, self.arm.home_guesses, self.kin.lower,
                                    self.kin.upper)
        links = _link_bodies(model, self.arm.joints)
        self.link_geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] in links]
        self.obstacles = [model.geom(cell_model.feature_geom(f.pusher)).id for f in scene.features]
        self.obstacles.append(model.geom("floor").id)
        self.base = robot.base
        self._arm_reach()

    def _arm_reach(self) -> None:
        """How far from the arm's shoulder (`shoulder`, in the world [m]) G can be (`reach`) and
        its last joint's anchor can be (`wrist_reach`), and where that anchor is in G's frame
        (`wrist`). The distance from each joint's anchor to the next's, and from the last to G, do
        not change as the joints turn (each pair rides one link), so their sums bound the reach; a
        sliding joint adds its travel. The last anchor rides the flange with G, so a sample's pose
        of G (its orientation too) puts it at one place. The shoulder is the first joint's anchor,
        or the first anchor that the joints before it cannot move."""
        m, d = self.model, self.kin.data
        R, p, _ = self.kin(np.clip(np.zeros(len(self.arm.joints)), self.kin.lower, self.kin.upper))
        ids = [m.joint(j).id for j in self.arm.joints]
        anchors = [d.xanchor[j].copy() for j in ids]
        # An anchor on the axes of every joint before it (a shoulder above a turning base) stays put:
        # the reach is measured from the last such.
        first = 0
        def fixed(k: int) -> bool:
            return all(m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
                       and np.linalg.norm(np.cross(anchors[k] - d.xanchor[j], d.xaxis[j])) < 1e-9 for j in ids[:k])

        while first + 1 < len(ids) and fixed(first + 1):
            first += 1
        self.first_joint = self.arm.joints[first]
        ids, anchors = ids[first:], anchors[first:]
        sliding = [j for j in ids if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE]
        travel = sum(float(m.jnt_range[j, 1] - m.jnt_range[j, 0]) for j in sliding)
        self.wrist_reach = sum(float(np.linalg.norm(b - a)) for a, b in zip(anchors, anchors[1:])) + travel
        self.reach = self.wrist_reach + float(np.linalg.norm(p - anchors[-1]))
        self.shoulder, self.wrist = anchors[0], R.T @ (anchors[-1] - p)

    def _out_of_reach(self, traj: Trajectory) -> None:
        """CellError at the first sample where G, or the last joint the sample's pose of G places,
        lies farther from the arm's shoulder than the chain reaches: no posture gets there, and
        no joint limit is to blame."""
        from scipy.spatial.transform import Rotation

        position = np.asarray(traj.position)
        wxyz = np.asarray(traj.quaternion_wxyz)
        wrist = position + Rotation.from_quat(wxyz[:, [1, 2, 3, 0]]).apply(self.wrist)
        for points, reach, what in ((position, self.reach, "the plan's TCP poses lie"),
                                    (wrist, self.wrist_reach, f"the plan's TCP poses put its last joint "
                                                              f"({self.arm.joints[-1]})")):
            beyond = np.linalg.norm(points - self.shoulder, axis=1) - reach
            if (beyond > 0.0).any():
                break
        else:
            return
        i = int(np.argmax(beyond > 0.0))
        shoulder = ", ".join(f"{v * 1e3:.0f}" for v in self.shoulder)
        base = ", ".join(f"{v:g}" for v in self.base[:3])
        raise CellError(i, float(traj.t[i]), int(traj.step[i]), traj.phase[i],
                        f"out of reach: {what} up to {beyond.max() * 1e3:.0f} mm beyond the arm's reach of "
                        f"{reach * 1e3:.0f} mm from its joint {self.first_joint} at [{shoulder}] mm, its "
                        f"base at [{base}] mm (environment.robot.base, --base)")

    def _solve(self, pose: Sequence[float], q_start: np.ndarray, home: np.ndarray, iterations: int):
        q, _ = ik.solve_ik(self.kin, pose, q_start, home, self.kin.lower, self.kin.upper, iterations)
        return q

    def solve(self, traj: Trajectory) -> JointPath:
        self._out_of_reach(traj)
        q_prev = self.home
        rows, worst = [], (0.0, 0.0)
        peak, least, nearest = 0.0, math.inf, ("", "")
        dt = 1.0 / traj.rate_hz
        for i in range(len(traj)):
            pose = [*traj.position[i], *traj.quaternion_wxyz[i]]
            q = self._solve(pose, q_prev, self.home, ik.IK_ITERATIONS)
            off = self._fk_error(q, pose)
            if off[0] > FK_TOLERANCE[0] or off[1] > FK_TOLERANCE[1]:  # near the edge of reach: look harder
                q = self._solve(pose, q, self.home, 20 * ik.IK_ITERATIONS)
                off = self._fk_error(q, pose)
            where = (i, float(traj.t[i]), int(traj.step[i]), traj.phase[i])
            if off[0] > FK_TOLERANCE[0] or off[1] > FK_TOLERANCE[1]:
                raise CellError(*where, self._why_unreached(q, off))
            speed = np.abs(q - q_prev) / dt
            fast = self.arm.too_fast(q_prev, q, dt) if i > 0 else None
            if fast is not None:
                raise CellError(*where, f"{fast} (a branch flip, or a motion too fast for it)")
            clearance, pair = self._clearance(q)
            if clearance < LINK_CLEARANCE:
                raise CellError(*where, f"link {pair[0]} runs {-clearance * 1e3:.1f} mm into {pair[1]}")
            if clearance < least:
                least, nearest = clearance, pair
            peak = max(peak, float(speed.max())) if i > 0 else peak
            worst = (max(worst[0], off[0]), max(worst[1], off[1]))
            rows.append(q)
            q_prev = q
        return JointPath(joints=self.arm.joints, t=np.asarray(traj.t), q=np.array(rows), phase=list(traj.phase),
                         step=np.asarray(traj.step), fk_error_mm=worst[0] * 1e3, fk_error_deg=math.degrees(worst[1]),
                         peak_speed=peak, clearance_mm=least * 1e3, nearest=nearest, start=self.home,
                         robot=self.robot)

    def _fk_error(self, q: np.ndarray, pose: Sequence[float]) -> Tuple[float, float]:
        """How far G through the joints' forward kinematics is from `pose`: (m, rad)."""
        R, p, _ = self.kin(q)
        target = pose_to_matrix(pose)
        return float(np.linalg.norm(target[:3, 3] - p)), float(np.linalg.norm(ik.rotation_vector(target[:3, :3] @ R.T)))

    def _why_unreached(self, q: np.ndarray, off: Tuple[float, float]) -> str:
        at_limit = [name for name, v, lo, hi in zip(self.arm.joints, q, self.kin.lower, self.kin.upper)
                    if min(v - lo, hi - v) < 1e-6]
        limits = f"; at its limit: joint {', '.join(at_limit)}" if at_limit else ""
        return (f"no joint positions within the arm's limits put G there: it stays {off[0] * 1e3:.3f} mm, "
                f"{math.degrees(off[1]):.3f} deg off{limits}")

    def _clearance(self, q: np.ndarray) -> Tuple[float, Tuple[str, str]]:
        """The least distance [m] from a link to an obstacle at joint positions `q`, and which."""
        self.kin(q)  # places the scratch data's geoms
        least, pair = math.inf, ("", "")
        fromto = np.zeros(6)
        for g in self.link_geoms:
            for o in self.obstacles:
                d = mujoco.mj_geomDistance(self.model, self.data, g, o, CLEARANCE_SEEN, fromto)
                if d < least:
                    least, pair = d, (self.model.body(self.model.geom_bodyid[g]).name, self.model.geom(o).name)
        return least, pair


def _link_bodies(model, joints: Sequence[str]) -> set:
    """The bodies the arm's joints move, less the jaws."""
    moved = set()
    for j in joints:
        moved.add(int(model.jnt_bodyid[model.joint(j).id]))
    for b in range(model.nbody):  # and every body below one of them
        parent = b
        while parent != 0 and parent not in moved:
            parent = int(model.body_parentid[parent])
        if parent in moved:
            moved.add(b)
    jaws = {model.body(name).id for name in _JAW_BODIES}
    return {b for b in moved if b not in jaws and model.body(b).name != cell_model.OBJECT_BODY}


def modelled(arm: Arm, robot: Robot) -> Arm:
    """`arm` checked against `robot` before any motion (ModelledArm), when the task or the command
    line names an arm; else `arm` as it is: a server's arm is not the shipped one by default."""
    return arm if robot == Robot() else ModelledArm(arm, robot)


class ModelledArm(Arm):
    """An arm (a real arm's server over TCP, most often) with the model of it that the lab gave
    (`robot`): every call goes to `arm`, and `check_cell` refuses, before any motion, a plan the
    model says it cannot follow (checked_path)."""

    def __init__(self, arm: Arm, robot: Robot):
        self.arm, self.robot = arm, robot
        arm_model(robot)  # a model that cannot carry the jaws is the caller's error now (RobotError)

    @property
    def connected(self) -> bool:  # type: ignore[override]
        return self.arm.connected

    @property
    def paced(self) -> bool:  # type: ignore[override]
        return self.arm.paced

    def check_cell(self, task: Task, plan: Plan, rate_hz: float) -> None:
        checked_path(task, plan, rate_hz, self.robot)

    def robot_description(self) -> RobotDescription:
        return robot_description(self.robot)

    def hello(self, scene: Scene, rate_hz: float, resume: bool) -> ArmReady:
        return self.arm.hello(scene, rate_hz, resume)

    def move(self, waypoint: ArmWaypoint) -> dict:
        return self.arm.move(waypoint)

    def stop(self) -> Optional[bool]:
        return self.arm.stop()

    def bye(self) -> None:
        self.arm.bye()

    def close(self) -> None:
        self.arm.close()
