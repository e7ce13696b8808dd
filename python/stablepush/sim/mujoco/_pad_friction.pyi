"""
The simulated arm's pad friction in C++ (stablepush.sim.mujoco.friction explains it; SI units)
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
__all__: list[str] = ['CoulombPadFriction', 'MUJOCO_VERSION', 'PadFrictionParameters']
class PadFrictionParameters:
    """
    The pad friction's thresholds (friction.py).
    """
    def __init__(self, *, slide_speed: typing.SupportsFloat | typing.SupportsIndex, stick_speed: typing.SupportsFloat | typing.SupportsIndex, slide_steps: typing.SupportsInt | typing.SupportsIndex, on_cone: typing.SupportsFloat | typing.SupportsIndex, directions_agree: typing.SupportsFloat | typing.SupportsIndex, max_trials: typing.SupportsInt | typing.SupportsIndex, frictionless_mu: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class CoulombPadFriction:
    """
    Per pad point, stick by the solver or slide with Coulomb friction (friction.py).
    """
    def __init__(self, model_address: typing.SupportsInt | typing.SupportsIndex, pad_geoms: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex], parameters: PadFrictionParameters) -> None:
        """
        model_address: MjModel._address; the model must outlive this object.
        """
    def step(self, data_address: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        One time step (update, then mj_step or the scratch's copy): data_address is MjData._address.
        """
    def update(self, data_address: typing.SupportsInt | typing.SupportsIndex) -> None:
        """
        The next step's friction only: mj_step after it takes the step `step` takes. data_address is MjData._address of the model's data.
        """
    @property
    def copied_steps(self) -> int:
        ...
    @property
    def sliding(self) -> numpy.typing.NDArray[numpy.bool]:
        ...
    @property
    def slipping(self) -> numpy.typing.NDArray[numpy.bool]:
        ...
    @property
    def solver_steps(self) -> int:
        ...
    @property
    def trial_steps(self) -> int:
        ...
MUJOCO_VERSION: int = 330
