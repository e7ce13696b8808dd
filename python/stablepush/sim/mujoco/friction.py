"""Pad friction in MuJoCo that sticks and slides as Coulomb's law says (docs/execution.md, "Friction
fidelity").

Why the pads need this. MuJoCo's contact model is convex: a contact that slides with its friction
on the cone's boundary also gets a separating normal velocity of about mu |v_slip|. The jaws press
with a capped force, so while the pads slide over the object they are pushed apart at ~5 mm/s
(mu 0.45, 10 mm/s), lose every pad contact for one time step every ~2.75 ms, and the object, held
for that step by nothing, creeps along the feature that should hold it (37 um per mm pushed).
A soft friction reference (`solreffriction` 30 ms) avoided the separation but turned a sliding
point's friction 1.3-4.7 deg off its slip, and the pivot's twelve sliding ring points then pushed
its sticking pad centre 1.3 deg along. Even the stiff solver's friction on a sliding
pivot ring point is ~5 deg off the slip it produces.

So a sliding pad point gets Coulomb's friction from us: mu N, opposite the slip at the end of the
step (backward Euler, as an implicit solver would), with its contact made frictionless for that
step (no cone, so no separation). The direction is found by trial steps on a scratch copy of the
state: apply mu N along d, step, and compare d with the slip it produced; move d toward the
opposite of that slip and try again, until they agree within DIRECTION_TOLERANCE_DEG. The first
move is halfway; later ones are Anderson steps (the secant over the last two trials, all points at
once, `_next_directions`), since all points ride one object and one hand and a plain step
overshoots. A damped step matters: explicit friction on a slow slip (one 0.25 ms step of 15 N
changes a hand's speed by mm/s) would otherwise flip its direction every step and chatter. A
sliding point whose trial slip turns against its friction or falls under STICK_SPEED sticks
instead. The trial whose directions agree is the time step itself, when its sliding points touched
through the contacts the force was built on: the friction in it opposes the slip it produced, so
the arm takes that state (a copy). In a steady slide the last step's direction passes at once, so
a sliding step costs one `mj_step`, the trial's.

Which points may slide is decided from their own slip, measured by the simulator from its own
state (never told by the plan): a point that has slipped faster than SLIDE_SPEED for SLIDE_STEPS
steps is a candidate; a candidate that did not slide in the last step slides if, in a step with
every pad contact's friction left to the solver (stiff, implicit), its friction is on its cone and
it still slips. Every other point keeps the solver's stiff friction, which is what keeps a loaded
sticking pad in place.

The work runs in C++ (`_pad_friction`, cpp/sim/coulomb_pad_friction.cpp) against the MuJoCo library
of the installed wheel; this module holds its thresholds. tests/reference_pad_friction.py is the
same algorithm in numpy, which the compiled one is checked against.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from stablepush.extras import require

# Before _pad_friction, which links against MuJoCo's library: without the package, the extra to install.
mujoco = require("mujoco", "the simulated arm (execute --sim, evaluate, sim-arm)")

from stablepush.sim.mujoco import _pad_friction  # noqa: E402

SLIDE_SPEED = 5e-4  # m/s: a pad point slipping faster than this (SLIDE_STEPS steps running) may slide
STICK_SPEED = 1e-4  # m/s: a sliding pad point whose slip falls below this sticks again
# Consecutive time steps above SLIDE_SPEED before a point may slide: the arm's jolt at the start of
# a push makes a sticking pad centre slip for a step or two.
SLIDE_STEPS = 4
ON_CONE = 0.99  # |friction| / (mu N) in the solver's step from which a contact counts as sliding
DIRECTION_TOLERANCE_DEG = 0.5  # friction vs the opposite of the slip it produces, at the end of a step
MAX_TRIALS = 8  # trial steps per time step; the last trial's direction is taken if none agrees
FRICTIONLESS_MU = 1e-5  # MuJoCo's least friction coefficient (mjMINMU): the contact of a sliding point


if _pad_friction.MUJOCO_VERSION != mujoco.mj_version():
    _built = ".".join(str(_pad_friction.MUJOCO_VERSION))  # mjVERSION_HEADER: 330 is 3.3.0
    raise ImportError(
        f"stablepush's pad friction was built against MuJoCo {_built} but mujoco {mujoco.__version__} is "
        f"installed: pip install mujoco=={_built} (the version pyproject.toml pins), or reinstall stablepush")


class CoulombPadFriction:
    """Per pad point, stick by the solver or slide with Coulomb friction we apply (module docstring).

    `pad_geoms` are the ids of the pad point geoms; every explicit contact pair that holds one of
    them is switched with it. `step(data)` takes one time step in place of `mj_step`, after the
    step's drives are set: it writes `model.pair_friction` of the pad pairs and `data.qfrc_applied`
    (which it owns: nothing else in the simulated arm applies forces) with the sliding points'
    friction, sum of J_t^T f_t with f_t = mu N d [N], d the unit friction direction in the contact's
    tangent plane, then steps, or takes the scratch step that already is this step. The thresholds
    are read when it is made.
    """

    def __init__(self, model: Any, pad_geoms: Sequence[int]):  # model: a mujoco.MjModel
        self.model = model  # the compiled friction keeps the model's address: this keeps the model alive
        parameters = _pad_friction.PadFrictionParameters(
            slide_speed=SLIDE_SPEED, stick_speed=STICK_SPEED, slide_steps=SLIDE_STEPS, on_cone=ON_CONE,
            directions_agree=float(np.cos(np.radians(DIRECTION_TOLERANCE_DEG))), max_trials=MAX_TRIALS,
            frictionless_mu=FRICTIONLESS_MU)
        self._compiled = _pad_friction.CoulombPadFriction(model._address, [int(g) for g in pad_geoms], parameters)

    def step(self, data: Any) -> None:  # data: a mujoco.MjData
        self._compiled.step(data._address)

    def update(self, data: Any) -> None:  # data: a mujoco.MjData
        """The friction of the next step only (`step` without its step): `mujoco.mj_step` after it
        takes the same step as `step`."""
        self._compiled.update(data._address)

    @property
    def slipping(self) -> np.ndarray:
        """Per pad point: a candidate to slide, by its own slip speed."""
        return self._compiled.slipping

    @property
    def sliding(self) -> np.ndarray:
        """Per pad point: slid with our friction in the last step."""
        return self._compiled.sliding

    @property
    def solver_steps(self) -> int:
        """Scratch steps with the solver's friction, deciding new sliders."""
        return self._compiled.solver_steps

    @property
    def trial_steps(self) -> int:
        """Scratch steps finding the friction's direction."""
        return self._compiled.trial_steps

    @property
    def copied_steps(self) -> int:
        """Time steps `step` copied from the scratch data (an accepted trial, or the solver's step)."""
        return self._compiled.copied_steps
