"""The arm's forward kinematics and Jacobian on a compiled MuJoCo model of its cell (cell_model.py),
the `ik.Kinematics` that IK solves on: for the cell check (cell_path.py), a joint-level arm
(stablepush.bridge) and the simulated arm on MuJoCo alike. MuJoCo serves here as a kinematics
library; nothing is simulated."""
from __future__ import annotations

from typing import Sequence

import numpy as np

from stablepush.extras import require
from stablepush.kinematics.robot import GRIPPER_SITE

mujoco = require("mujoco", "the arm's kinematics and the cell check")


class ArmKinematics:
    """The arm's forward kinematics on a MuJoCo model of its scene, for IK (ik.Kinematics): q [rad]
    of the arm's `joints` (base to flange) -> G's rotation and position in the world [m] and its
    Jacobian (linear rows over angular), computed on scratch data so the simulation's state is not
    touched. `lower` and `upper` are the joints' limits [rad] (infinite for an unlimited joint)."""

    def __init__(self, model, joints: Sequence[str]):
        m = self.model = model
        ids = [m.joint(j).id for j in joints]
        self.qpos_adr = np.array([m.jnt_qposadr[j] for j in ids])
        self.dof_adr = np.array([m.jnt_dofadr[j] for j in ids])
        limited = m.jnt_limited[ids].astype(bool)
        self.lower = np.where(limited, m.jnt_range[ids, 0], -np.inf)
        self.upper = np.where(limited, m.jnt_range[ids, 1], np.inf)
        self.site = m.site(GRIPPER_SITE).id
        self.data = mujoco.MjData(m)
        self._jacp = np.zeros((3, m.nv))
        self._jacr = np.zeros((3, m.nv))

    def __call__(self, q: np.ndarray):
        d = self.data
        d.qpos[self.qpos_adr] = q
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_comPos(self.model, d)
        mujoco.mj_jacSite(self.model, d, self._jacp, self._jacr, self.site)
        J = np.vstack([self._jacp, self._jacr])[:, self.dof_adr]
        return d.site_xmat[self.site].reshape(3, 3), d.site_xpos[self.site].copy(), J

