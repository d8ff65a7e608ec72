"""An anti-roll bar's twist (a held row of the statics)."""

from __future__ import annotations

import numpy as np

from .row import Row


class BarTwist(Row):
    """An anti-roll bar's twist (1 row, rad per dq): a U-bar's left arm's turn minus the
    right's (both about the bar's axis), a T-bar's crossbar turn about its stem. A held
    row: its residual is zero, its Jacobian the constant ±1 in the joints' columns. Its
    multiplier is the bar's torque (statics.py)."""

    size = 1
    name = "arb"

    def __init__(self, model, joints: list[str], name: str = "arb"):
        self.name = name  # its torque's column: torque_<name> (a vehicle's: arb_front)
        self.row = np.zeros((1, model.nv))
        for sign, joint in zip((1.0, -1.0), joints, strict=False):
            self.row[0, model.joints[model.getJointId(joint)].idx_v] = sign

    def residual(self, kin) -> np.ndarray:
        return np.zeros(1)

    def jacobian(self, kin) -> np.ndarray:
        return self.row

    def fill(self, at, k, r, J, i) -> None:
        r[i] = 0.0
        if J is not None:
            J[i] = self.row[0]

    def fill_many(self, at, k, value, r, J, i) -> None:
        r[:, i] = 0.0
        if J is not None:
            J[:, i] = self.row[0]
