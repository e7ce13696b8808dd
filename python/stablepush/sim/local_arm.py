"""A simulated arm in this process, behind the arm port (stablepush.execution.arm): the world of
each session's scene built on a physics engine (engines.py), as `deviation` alters it. A run
drives it with calls, no socket; `stablepush sim-arm` (server.py) serves one over TCP.
"""
from __future__ import annotations

from typing import Any, Callable, Optional

from stablepush.execution.arm import Arm, ArmError, ArmReady, RobotDescription
from stablepush.execution.scene import Scene
from stablepush.execution.stream import ArmWaypoint
from stablepush.extras import MissingExtra, require
from stablepush.kinematics.cell_model import simulated_geometry, simulated_outline
from stablepush.kinematics.robot import arm_model, robot_description
from stablepush.plan.plan import Plan
from stablepush.sim.deviation import WorldDeviation
from stablepush.sim.engines import DEFAULT_ENGINE, load_engine, make_arm
from stablepush.task.model import Robot, Task


class SimulatedArm(Arm):
    """The simulated arm of `robot` (a task.model.Robot; None: the shipped arm) on `engine`
    (loaded here: a missing one is `MissingExtra` now, not a fault later), in the world
    `deviation` makes of each scene. `log(text)` hears of each world built."""

    def __init__(self, engine: str = DEFAULT_ENGINE, deviation: WorldDeviation = WorldDeviation(),
                 log: Optional[Callable[[str], None]] = None, robot: Optional[Robot] = None):
        if robot is not None and not isinstance(robot, Robot):
            raise TypeError(f"robot must be a Robot (stablepush.task.Robot), got {type(robot).__name__}")
        if not isinstance(deviation, WorldDeviation):
            raise TypeError(f"deviation must be a WorldDeviation, got {type(deviation).__name__}")
        self.engine = load_engine(engine)
        self.robot = robot if robot is not None else Robot()
        arm_model(self.robot)  # a model that cannot carry the jaws is the caller's error now (RobotError)
        self.deviation = deviation
        self.log = log or (lambda text: None)
        self.sim: Any = None  # the engine's arm (mujoco.arm.SimArm or drake.arm.DrakeArm) of the current world
        self._scene: Optional[Scene] = None
        self._period = 0.01

    @property
    def name(self) -> str:
        return f"stablepush sim-arm ({self.engine})"

    def robot_description(self) -> RobotDescription:
        return robot_description(self.robot)

    def check_cell(self, task: Task, plan: Plan, rate_hz: float) -> None:
        """The arm's joints along the plan (joint_path.checked_path): CellError, before any
        motion, where it cannot follow. The check runs on MuJoCo's kinematics: on Drake without
        MuJoCo installed it is skipped, and the log says so."""
        try:
            require("mujoco", "the cell check")
        except MissingExtra:
            self.log("the cell is not checked: the check runs on MuJoCo, which is not installed ([sim])")
            return
        from stablepush.kinematics.cell_path import checked_path

        path = checked_path(task, plan, rate_hz, self.robot)
        self.log(f"cell checked: {path.describe()}")

    def hello(self, scene: Scene, rate_hz: float, resume: bool) -> ArmReady:
        """A fresh world built from `scene`, or, with `resume` and the scene the one it has, the
        world as the last session left it. ArmError when no world can be built from it."""
        self._period = 1.0 / float(rate_hz)
        if self.sim is not None and resume and scene.same_world(self._scene):
            self.log("world kept from the previous session (continue)")
        else:
            try:
                sim = make_arm(self.engine, scene, self.deviation, self.robot)
            except Exception as exc:  # noqa: BLE001 - any scene no world can be built from is the caller's error
                raise ArmError(f"hello: cannot build a world from this scene ({type(exc).__name__}: "
                               f"{' '.join(str(exc).split())[:200]})") from None
            self.sim, self._scene = sim, scene
            _, tolerance = simulated_outline(scene.object.polygon)
            simplified = f"; outline simplified within {tolerance * 1e3:g} mm" if tolerance else ""
            self.log(f"world built for {'a task' if scene.task is None else scene.task} ({sim.describe()}{simplified})")
        self.connected = True
        return ArmReady(state=self.sim.state(), arm=self.name, engine=self.engine,
                        geometry=simulated_geometry(scene.object))

    def move(self, waypoint: ArmWaypoint) -> dict:
        """Track G to the waypoint over one period. The wrist's force is read during approaches,
        where the guarded approach reads it: on Drake it costs as much as the step (its contact
        results), so not on every waypoint. ArmError, the arm stopped, when it cannot follow."""
        try:
            self.sim.move_to(waypoint.pose, self._period)
            return self.sim.state(contact_force=waypoint.phase == "approach")
        except Exception as exc:  # noqa: BLE001 - a simulator that fails is an arm that cannot go on
            self.sim.stop()
            raise ArmError(f"the simulated arm: {' '.join(str(exc).split())[:300]}") from None

    def stop(self) -> Optional[bool]:
        if self.sim is None:
            return None
        self.sim.stop()
        return True

    def state(self) -> dict:
        """Where the arm stands now."""
        return self.sim.state()

    @property
    def steps_per_second(self) -> float:
        return self.sim.steps_per_second if self.sim is not None else 0.0
