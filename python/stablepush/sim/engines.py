"""The physics engines a simulated arm can run on, by name: MuJoCo (`arm.py`, whose sliding pad
friction is stablepush's own Coulomb law, `friction.py`) and Drake (`drake_arm.py`, whose contact
solver alone decides stick and slip). Both build the same arm, grasp and world from a scene
(execution.scene.Scene) and answer to the same calls, so the in-process arm (local_arm.py), the
executor and the fidelity contract never ask which one they have. Importing this module loads neither engine.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from stablepush.errors import SettingError

if TYPE_CHECKING:
    from stablepush.execution.scene import Scene

ENGINES = ("mujoco", "drake")
DEFAULT_ENGINE = "mujoco"


def check_engine(engine: str) -> str:
    if engine not in ENGINES:
        raise SettingError("engine", f"must be one of {', '.join(ENGINES)}, got {engine!r:.40}")
    return engine


def load_engine(engine: str) -> str:
    """`engine`, checked and its package imported (stablepush.extras.MissingExtra naming the extra
    to install when it is not there)."""
    from stablepush.extras import require

    if check_engine(engine) == "drake":
        require("pydrake.all", "--engine drake")  # the arm's MJCF is read by Drake's parser: no MuJoCo needed
    else:
        require("mujoco", "the simulated arm (execute --sim, evaluate, sim-arm)")
    return engine


def make_arm(engine: str, scene: Scene, deviation=None, robot=None):
    """The simulated arm of `scene` on `engine` (SimArm or DrakeArm), in the world `deviation`
    (a `deviation.WorldDeviation`; None: the task's own), the arm of `robot` (a
    task.model.Robot; None: the shipped arm)."""
    from stablepush.sim.arm import SimArm
    from stablepush.sim.deviation import WorldDeviation

    deviation = deviation or WorldDeviation()
    if check_engine(engine) == "drake":
        from stablepush.sim.drake_arm import DrakeArm

        return DrakeArm(scene, deviation, robot)
    return SimArm(scene, deviation, robot)


def make_grasp(engine: str, scene: Scene):
    """The grasp of `scene` on a kinematic hand (no arm), on `engine`: the friction rig's world."""
    if check_engine(engine) == "drake":
        from stablepush.sim.drake_arm import DrakeGrasp

        return DrakeGrasp(scene, kinematic_hand=True)
    from stablepush.sim.arm import SimulatedGrasp

    return SimulatedGrasp(scene, kinematic_hand=True)
