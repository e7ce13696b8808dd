"""The pad friction's first implementation, in numpy: the reference the compiled one
(`stablepush.sim.mujoco._pad_friction`, cpp/sim/coulomb_pad_friction.cpp) is checked against in
tests/test_pad_friction.py, bit for bit. The algorithm and its thresholds are
stablepush/sim/mujoco/friction.py's."""
from __future__ import annotations

from typing import Sequence

import mujoco
import numpy as np

from stablepush.sim.mujoco.friction import (
    DIRECTION_TOLERANCE_DEG,
    FRICTIONLESS_MU,
    MAX_TRIALS,
    ON_CONE,
    SLIDE_SPEED,
    SLIDE_STEPS,
    STICK_SPEED,
)

_DIRECTIONS_AGREE = np.cos(np.radians(DIRECTION_TOLERANCE_DEG))


class ReferencePadFriction:
    """stablepush.sim.mujoco.friction.CoulombPadFriction's interface and behaviour, in numpy."""

    def __init__(self, model, pad_geoms: Sequence[int]):
        self.model = model
        n_points = len(pad_geoms)
        slot_of_geom = {int(g): k for k, g in enumerate(pad_geoms)}
        slot = np.full(model.ngeom, -1, dtype=np.int32)
        for geom, k in slot_of_geom.items():
            slot[geom] = k
        # the pad point of each geom pair (or -1): a contact's slot in one lookup, as it is met every step
        self._slot_of_pair = np.maximum(slot[:, None], slot[None, :])
        pairs, pair_slots = [], []
        for i in range(model.npair):
            for geom in (model.pair_geom1[i], model.pair_geom2[i]):
                if geom in slot_of_geom:
                    pairs.append(i)
                    pair_slots.append(slot_of_geom[geom])
        self._pairs = np.array(pairs, dtype=int)
        self._pair_slots = np.array(pair_slots, dtype=int)
        self._mu = model.pair_friction[self._pairs, :2].copy()  # the task's (and world's) pad mu
        self._point_mu = np.zeros(n_points)
        self._point_mu[self._pair_slots] = self._mu[:, 0]
        self._scratch = mujoco.MjData(model)
        self._state_kind = mujoco.mjtState.mjSTATE_INTEGRATION
        self._state = np.zeros(mujoco.mj_stateSize(model, self._state_kind))
        self.slipping = np.zeros(n_points, dtype=bool)  # candidates, by their own slip speed
        self.sliding = np.zeros(n_points, dtype=bool)  # sliding with our friction in the last step
        # per sliding point, its unit friction as a world vector in the contact rows' sign convention (_PadContacts)
        self._direction = np.zeros((n_points, 3))
        self._fast_steps = np.zeros(n_points, dtype=int)
        self.solver_steps = 0  # scratch steps with the solver's friction, deciding new sliders
        self.trial_steps = 0  # scratch steps finding the friction's direction
        self._frictionless = None  # which pad pairs model.pair_friction makes frictionless now, as bytes
        self._set_frictionless(self.sliding)

    def step(self, data) -> None:
        """update, then mj_step: where the compiled one copies an accepted trial, this steps again
        with that trial's force, which repeats it to the bit."""
        self.update(data)
        mujoco.mj_step(self.model, data)

    def update(self, data) -> None:
        contacts = _PadContacts(self, data)
        # Candidates from the previous step's slip (the tangential rows of efc_vel, m/s: the cones are
        # elliptic, so those rows are the contact frame's tangents). A point touching the object through
        # several convex pieces slips if any of them does; a point that touches nothing does not.
        slip = np.hypot(data.efc_vel[contacts.rows + 1], data.efc_vel[contacts.rows + 2])
        fast = contacts.count(slip > SLIDE_SPEED) > 0
        slow = contacts.count(slip >= STICK_SPEED) == 0
        self._fast_steps = np.where(fast, self._fast_steps + 1, 0)
        self.slipping = contacts.touched & ((self._fast_steps >= SLIDE_STEPS) | (self.slipping & ~slow))
        data.qfrc_applied[:] = 0.0
        sliding = self.sliding & self.slipping
        if self.slipping.any():
            mujoco.mj_getState(self.model, data, self._state, self._state_kind)
            # N of each pad contact in the previous step, where a sliding contact had no cone to skew it
            normal = contacts.normal_by_key()
            solver = None
            if (self.slipping & ~sliding).any():
                solver = self._solver_step()
                sliding |= self._new_sliders(solver, self.slipping & ~sliding)
            if sliding.any():
                sliding = self._coulomb_friction(data, sliding, normal, solver if solver is not None else contacts)
        if (sliding != self.sliding).any() or self.slipping.any():
            self._set_frictionless(sliding)  # a scratch step may have changed the pairs
        self.sliding = sliding

    def _solver_step(self) -> "_PadContacts":
        """The step from the current state with every pad contact's friction left to the solver."""
        s = self._scratch
        self._set_frictionless(np.zeros_like(self.sliding))
        mujoco.mj_setState(self.model, s, self._state, self._state_kind)
        s.qfrc_applied[:] = 0.0
        mujoco.mj_step(self.model, s)
        self.solver_steps += 1
        return _PadContacts(self, s)

    def _new_sliders(self, solver: "_PadContacts", new: np.ndarray) -> np.ndarray:
        """Which `new` candidates slide in the solver's step (all their contacts on the cone and
        slipping at its end); their friction direction starts from the solver's."""
        s = self._scratch
        mu = self._point_mu[solver.slots]
        tangential = np.hypot(s.efc_force[solver.rows + 1], s.efc_force[solver.rows + 2])
        on_cone = tangential >= ON_CONE * mu * s.efc_force[solver.rows]
        slip = _norm(solver.tangential(solver.end_velocity()))
        slides = on_cone & (slip >= STICK_SPEED)
        sliding = new & (solver.count(~slides) == 0) & solver.touched
        friction = solver.tangential(s.efc_force)
        take = sliding[solver.slots]
        self._direction[solver.slots[take]] = _unit(friction[take])
        return sliding

    def _coulomb_friction(self, data, sliding: np.ndarray, normal, at: "_PadContacts") -> np.ndarray:
        """Find each sliding point's friction direction by trial steps (module docstring), write the
        friction into data.qfrc_applied and return the points that slide."""
        m, s = self.model, self._scratch
        history = None  # (directions, residual) of the last trial, for the Anderson step
        for _ in range(MAX_TRIALS):
            qfrc = self._generalized_friction(at, sliding, normal)
            pushed_through = np.sort(at.keys[sliding[at.slots]])
            self._set_frictionless(sliding)
            mujoco.mj_setState(m, s, self._state, self._state_kind)
            s.qfrc_applied[:] = qfrc
            mujoco.mj_step(m, s)
            self.trial_steps += 1
            trial = _PadContacts(self, s)
            # the trial stands as the step only if our force went through the contacts the step has
            same_contacts = np.array_equal(np.sort(trial.keys[sliding[trial.slots]]), pushed_through)
            sliding = sliding & trial.touched  # a point that touches nothing has no friction
            v_end = trial.tangential(trial.end_velocity())
            in_trial = sliding[trial.slots]
            speed = _norm(v_end)
            opposite = -v_end / np.maximum(speed, 1e-12)[:, None]
            agree = (self._direction[trial.slots] * opposite).sum(1)
            # our friction turned the slip back, or stopped it: the point sticks (the solver's friction)
            sticks = in_trial & ((agree <= 0) | (speed < STICK_SPEED))
            at = trial
            if sticks.any():
                sliding = sliding & (trial.count(sticks) == 0)
                history = None
            if not sliding.any():
                return sliding
            if sticks.any():
                continue
            if agree[in_trial].min() >= _DIRECTIONS_AGREE:
                if same_contacts:  # the trial is the step
                    data.qfrc_applied[:] = qfrc
                    return sliding
                break
            points = trial.slots[in_trial]
            history = self._next_directions(points, opposite[in_trial], history)
        data.qfrc_applied[:] = self._generalized_friction(at, sliding, normal)
        return sliding

    def _next_directions(self, points: np.ndarray, opposite: np.ndarray, history):
        """Move the directions of `points` toward `opposite` (the opposite of the slip each produced):
        a fixed-point problem d = F(d). All points ride one object and one hand, so their slips answer
        together and a plain step can overshoot (on the large manipulation a turn of d by 1 deg turned
        the slip by -3 deg, and averaging cycled); one Anderson step (the secant over the last two
        trials, all points at once) takes that gain out. Returns the history for the next call."""
        d = self._direction[points].ravel()
        residual = opposite.ravel() - d
        if history is not None and history[0].shape == d.shape:
            dd, dr = d - history[0], residual - history[1]
            # summed one term after another, as the compiled version does (BLAS's `@` sums in another
            # order, and a pivot's sliding pads turn that last bit into micrometres)
            denominator, numerator = 0.0, 0.0
            for a, b in zip(dr.tolist(), residual.tolist()):
                denominator += a * a
                numerator += a * b
            gamma = numerator / denominator if denominator > 0 else 0.0
            step = residual - gamma * (dd + dr)
        else:
            step = 0.5 * residual
        self._direction[points] = _unit((d + step).reshape(-1, 3))
        return d, residual

    def _generalized_friction(self, at: "_PadContacts", sliding: np.ndarray, normal) -> np.ndarray:
        """J^T f of the `sliding` points' contacts in `at`: f = mu N d, d each point's direction in
        its contact's tangent plane [N -> generalized]."""
        take = sliding[at.slots]
        points = at.slots[take]
        return at.generalized_force(take, self._point_mu[points] * normal(at, take), self._direction[points])

    def _set_frictionless(self, sliding: np.ndarray) -> None:
        frictionless = sliding[self._pair_slots]
        key = frictionless.tobytes()
        if key == self._frictionless:
            return  # the pairs hold these values already (every write comes through here)
        mu = self._mu.copy()
        mu[frictionless] = FRICTIONLESS_MU
        self.model.pair_friction[self._pairs, :2] = mu
        self._frictionless = key


def _norm(v: np.ndarray) -> np.ndarray:
    """Each row's Euclidean norm, as np.linalg.norm(v, axis=1) computes it, without its wrapper."""
    return np.sqrt((v * v).sum(1))


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(_norm(v), 1e-12)[:, None]


class _PadContacts:
    """The pad contacts of an MjData after its step (so its contacts, efc_J and efc_force belong to
    the state the step started from, and qvel to the state it ended in): per contact its pad point
    (slot), first constraint row, geom-pair key and tangent directions.

    Tangential vectors are in the world, with the sign convention of the contact frame's rows (the
    one in which J maps generalized velocities to contact velocities and friction dissipates)."""

    def __init__(self, friction: ReferencePadFriction, data):
        self.model, self.data = friction.model, data
        n = data.ncon
        contact = data.contact  # MuJoCo builds this view at each access: once per step, not per field
        geoms = contact.geom[:n]
        slots = friction._slot_of_pair[geoms[:, 0], geoms[:, 1]]
        rows = contact.efc_address[:n]
        index = np.flatnonzero((slots >= 0) & (rows >= 0))
        self.slots, self.rows = slots[index], rows[index]
        pairs = geoms[index]
        self.keys = pairs[:, 0] * self.model.ngeom + pairs[:, 1]
        frames = contact.frame[index].reshape(-1, 3, 3)
        self._t1, self._t2 = frames[:, 1], frames[:, 2]
        self._n_points = len(friction.slipping)
        self.touched = np.bincount(self.slots, minlength=self._n_points) > 0

    def count(self, flags: np.ndarray) -> np.ndarray:
        """How many of each pad point's contacts have `flags`."""
        return np.bincount(self.slots, weights=flags, minlength=self._n_points)

    def tangential(self, per_row: np.ndarray) -> np.ndarray:
        """The tangential rows of a constraint-space vector as world vectors, one per contact."""
        return per_row[self.rows + 1][:, None] * self._t1 + per_row[self.rows + 2][:, None] * self._t2

    def end_velocity(self) -> np.ndarray:
        """J qvel: each constraint row's velocity at the end of the step [m/s]."""
        velocity = np.zeros(self.data.nefc)
        mujoco.mj_mulJacVec(self.model, self.data, velocity, self.data.qvel)
        return velocity

    def normal_by_key(self):
        """N of each of these contacts, to look up by geom pair: `normal(at, take)` gives N of
        `at`'s contacts `take`, from here where the pair was in contact, else from `at` itself."""
        order = np.argsort(self.keys)
        keys, forces = self.keys[order], self.data.efc_force[self.rows[order]]

        def normal(at: "_PadContacts", take: np.ndarray) -> np.ndarray:
            wanted = at.keys[take]
            found = at.data.efc_force[at.rows[take]].copy()
            if len(keys):
                i = np.minimum(np.searchsorted(keys, wanted), len(keys) - 1)
                hit = keys[i] == wanted
                found[hit] = forces[i[hit]]
            return found
        return normal

    def generalized_force(self, take: np.ndarray, magnitude: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """J^T of forces on these contacts `take` [N -> generalized]: `magnitude` [N] along world unit
        `directions` projected on each contact's tangent plane and made unit again."""
        t1, t2 = self._t1[take], self._t2[take]
        d = _unit((directions * t1).sum(1)[:, None] * t1 + (directions * t2).sum(1)[:, None] * t2)
        force = magnitude[:, None] * d
        rows = self.rows[take]
        per_row = np.zeros(self.data.nefc)
        per_row[rows + 1] = (force * t1).sum(1)
        per_row[rows + 2] = (force * t2).sum(1)
        out = np.zeros(self.model.nv)
        mujoco.mj_mulJacTVec(self.model, self.data, out, per_row)
        return out
