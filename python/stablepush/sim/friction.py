"""Pad friction in MuJoCo that slides and sticks as Coulomb's law says (README, "Friction
fidelity").

Why the pads need this. MuJoCo's contact model is convex: a contact that slides with its friction
on the cone's boundary also gets a separating normal velocity of about mu |v_slip|. The jaws press
with a capped force, so while the pads slide over the object they are pushed apart at ~5 mm/s
(mu 0.45, 10 mm/s), lose every pad contact for one time step every ~2.75 ms, and the object, held
for that step by nothing, creeps along the feature that should hold it (37 um per mm pushed).
A soft friction reference (`solreffriction`, time constant SLIDING_SOLREFFRICTION[0] s) keeps a
sliding pad on its cone without the separation, and its friction within 0.1% of mu N; but a pad
that must stick under load then creeps. So each pad point chooses its friction reference by its
own slip speed, measured by the simulator from its own state (never told by the plan): soft once
it has slid faster than SLIDE_SPEED for SLIDE_STEPS steps, stiff again once it is slower than
STICK_SPEED. The gap between the two thresholds (hysteresis) keeps a point from chattering.
"""
from __future__ import annotations

from typing import Dict, List, Sequence

import numpy as np

SLIDING_SOLREFFRICTION = (0.03, 1.0)  # time constant s, damping ratio: friction of a sliding pad point
STICKING_SOLREFFRICTION = (0.0, 0.0)  # MuJoCo's "same as the contact's solref": stiff
SLIDE_SPEED = 5e-4  # m/s: a sticking pad point whose slip exceeds this starts to slide
STICK_SPEED = 1e-4  # m/s: a sliding pad point whose slip falls below this sticks again
# Consecutive time steps (1 ms) above SLIDE_SPEED before a point counts as sliding: the arm's jolt
# at the start of a push makes a sticking pad centre slip for a step or two, and switched to the
# soft reference it then drifts (the pivot lost 3.6 deg with 1 step, 1.9 deg with 4). Longer waits
# outlast the ~11 steps between the drop-outs of a stiff sliding pad and never switch it.
SLIDE_STEPS = 4


class SlipSwitchedPadFriction:
    """Per pad point, the friction reference of its contact pairs, switched by its slip speed.

    `pad_geoms` are the ids of the pad point geoms; every explicit contact pair that holds one of
    them is switched with it. Call `update(data)` before each `mj_step`: it reads the slip of the
    previous step's pad contacts (the tangential rows of `efc_vel`, m/s; the cones are elliptic, so
    those rows are the contact frame's tangents) and writes `model.pair_solreffriction`.
    """

    def __init__(self, model, pad_geoms: Sequence[int]):
        self.model = model
        slot_of_geom: Dict[int, int] = {int(g): k for k, g in enumerate(pad_geoms)}
        self._slot_of_geom = np.full(model.ngeom, -1, dtype=int)
        for geom, slot in slot_of_geom.items():
            self._slot_of_geom[geom] = slot
        pairs: List[int] = []
        pair_slots: List[int] = []
        for i in range(model.npair):
            for geom in (model.pair_geom1[i], model.pair_geom2[i]):
                if geom in slot_of_geom:
                    pairs.append(i)
                    pair_slots.append(slot_of_geom[geom])
        self._pairs = np.array(pairs, dtype=int)
        self._pair_slots = np.array(pair_slots, dtype=int)
        self.sliding = np.zeros(len(pad_geoms), dtype=bool)
        self._fast_steps = np.zeros(len(pad_geoms), dtype=int)
        self._sliding_ref = np.array(SLIDING_SOLREFFRICTION)
        self._sticking_ref = np.array(STICKING_SOLREFFRICTION)
        self._apply()

    def update(self, data) -> None:
        n = data.ncon
        geoms = data.contact.geom[:n]
        slots = np.maximum(self._slot_of_geom[geoms[:, 0]], self._slot_of_geom[geoms[:, 1]])
        rows = data.contact.efc_address[:n]
        keep = (slots >= 0) & (rows >= 0)
        slots, rows = slots[keep], rows[keep]
        slip = np.hypot(data.efc_vel[rows + 1], data.efc_vel[rows + 2])
        # A point touching the object through several convex pieces slides if any of them does;
        # a point that touches nothing does not slide.
        touched = np.zeros_like(self.sliding)
        fast = np.zeros_like(self.sliding)
        slow = np.ones_like(self.sliding)
        touched[slots] = True
        np.logical_or.at(fast, slots, slip > SLIDE_SPEED)
        np.logical_and.at(slow, slots, slip < STICK_SPEED)
        self._fast_steps = np.where(fast, self._fast_steps + 1, 0)
        sliding = touched & ((self._fast_steps >= SLIDE_STEPS) | (self.sliding & ~slow))
        if (sliding != self.sliding).any():
            self.sliding = sliding
            self._apply()

    def _apply(self) -> None:
        on = self.sliding[self._pair_slots][:, None]
        self.model.pair_solreffriction[self._pairs] = np.where(on, self._sliding_ref, self._sticking_ref)
