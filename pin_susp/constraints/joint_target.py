"""A joint held at a value: the rack at its design position, a rocker at its angle."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .row import Row


class JointTarget(Row):
    """r = q_j − value (1 row; rad for a revolute joint, m for a prismatic one).
    J = e_j (a one in the joint's column of v); r̈ = q̈_j. Holds the rack at its design
    position, or the rocker at its design angle, while a setup adjuster is applied."""

    size = 1

    def __init__(self, model: pin.Model, joint: str, value: float = 0.0):
        j = model.joints[model.getJointId(joint)]
        self.name = f"hold {joint}"
        self.index_q, self.index_v = j.idx_q, j.idx_v
        self.row = np.zeros((1, model.nv))
        self.row[0, self.index_v] = 1.0
        self.value = value

    def residual(self, kin) -> np.ndarray:
        return np.array([kin.q[self.index_q] - self.value])

    def jacobian(self, kin) -> np.ndarray:
        return self.row

    def fill(self, at, k, r, J, i) -> None:
        r[i] = at.q[self.index_q] - self.value
        if J is not None:
            J[i] = self.row[0]

    def fill_many(self, at, k, value, r, J, i) -> None:
        r[:, i] = at.q[:, self.index_q] - value
        if J is not None:
            J[:, i, self.index_v] = 1.0

    def drift_many(self, at, k, V, A, qdd, out, i) -> None:
        out[:, i] = qdd[:, self.index_v]
