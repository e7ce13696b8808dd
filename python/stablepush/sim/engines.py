"""The physics engines a simulated arm can run on, by name, in one registry: MuJoCo (`mujoco/arm.py`,
whose sliding pad friction is stablepush's own Coulomb law, `mujoco/friction.py`) and Drake
(`drake/arm.py`, whose contact solver alone decides stick and slip). Both build the same arm,
grasp and world from a scene (execution.scene.Scene) and answer to the same calls, `EngineArm`
and `EngineGrasp` below, so the in-process arm (local_arm.py), the executor and the fidelity
contract never ask which one they have. Importing this module loads neither engine.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, Dict, Sequence

import numpy as np

from stablepush.errors import SettingError

if TYPE_CHECKING:
    from typing import Protocol

    from stablepush.execution.scene import Scene

    class EngineGrasp(Protocol):
        """A grasp on a kinematic hand (the friction rig's world), as fidelity.py drives it."""

        timestep: float  # s
        steps_per_second: float  # simulated steps per wall-clock second, so far

        def step_hand(self, motion: Sequence[float], velocity: Sequence[float]) -> None: ...
        def object_matrix(self) -> np.ndarray: ...
        def in_grasp(self) -> Dict[str, float]: ...
        def pad_contacts(self) -> int: ...
        def contact_force_on_object(self, pusher: str) -> np.ndarray: ...

    class EngineArm(Protocol):
        """A simulated arm, as the arm port in this process (local_arm.py) drives it: G tracked
        toward each streamed pose (tracking.TrackingArm), held on stop, its state reported."""

        scene: Scene
        steps_per_second: float

        def move_to(self, pose: Sequence[float], duration: float) -> None: ...
        def stop(self) -> None: ...
        def state(self, contact_force: bool = False) -> dict: ...
        def describe(self) -> str: ...


@dataclass(frozen=True)
class Engine:
    """One engine: the package it needs (`requires`, as stablepush.extras names it), the module and
    classes of its arm and of its grasp on a kinematic hand."""

    requires: str
    module: str
    arm: str
    grasp: str


# The one place an engine is named. Drake reads the arm's MJCF with its own parser: no MuJoCo needed.
REGISTRY: Dict[str, Engine] = {
    "mujoco": Engine("mujoco", "stablepush.sim.mujoco.arm", "SimArm", "SimulatedGrasp"),
    "drake": Engine("pydrake.all", "stablepush.sim.drake.arm", "DrakeArm", "DrakeGrasp"),
}
ENGINES = tuple(REGISTRY)
DEFAULT_ENGINE = "mujoco"


def check_engine(engine: str) -> str:
    if engine not in REGISTRY:
        raise SettingError("engine", f"must be one of {', '.join(ENGINES)}, got {engine!r:.40}")
    return engine


def load_engine(engine: str) -> str:
    """`engine`, checked and its package imported (stablepush.extras.MissingExtra naming the extra
    to install when it is not there)."""
    from stablepush.extras import require

    require(REGISTRY[check_engine(engine)].requires, f"the simulated arm on {engine} (execute --sim, evaluate, "
                                                     f"sim-arm)")
    return engine


def make_arm(engine: str, scene: Scene, deviation=None, robot=None) -> EngineArm:
    """The simulated arm of `scene` on `engine`, in the world `deviation` (a
    `deviation.WorldDeviation`; None: the task's own), the arm of `robot` (a task.model.Robot;
    None: the shipped arm)."""
    from stablepush.sim.deviation import WorldDeviation

    spec = REGISTRY[load_engine(engine)]
    return getattr(importlib.import_module(spec.module), spec.arm)(scene, deviation or WorldDeviation(), robot)


def make_grasp(engine: str, scene: Scene) -> EngineGrasp:
    """The grasp of `scene` on a kinematic hand (no arm), on `engine`: the friction rig's world."""
    spec = REGISTRY[load_engine(engine)]
    return getattr(importlib.import_module(spec.module), spec.grasp)(scene, kinematic_hand=True)
