"""An axle's heave target: the mean height of its wheel centres."""

from __future__ import annotations

import numpy as np

from .row import Row


class HeaveTarget(Row):
    """r = ½(WC_z,L + WC_z,R) − design − value (1 row, m): the wheel centres' mean rise
    from their design height ``design``, less the target heave (positive above it).
    J = ½(J_z,L + J_z,R); r̈ = ½(a_z,L + a_z,R)."""

    name = "target heave"

    def __init__(self, left, right, design: float, value: float = 0.0):
        self.frames = (left, right)
        self.design, self.value = design, value

    def residual(self, kin) -> np.ndarray:
        left, right = (p.position(kin) for p in self.frames)
        return np.array([0.5 * (left[2] + right[2]) - self.design - self.value])

    def jacobian(self, kin) -> np.ndarray:
        left, right = (p.jacobian(kin) for p in self.frames)
        return (0.5 * (left[2] + right[2]))[None]

    def fill(self, at, k, r, J, i) -> None:
        a, b = k
        r[i] = 0.5 * (at.P[a][2] + at.P[b][2]) - self.design - self.value
        if J is not None:
            J[i] = 0.5 * (at.Jp[a][2] + at.Jp[b][2])

    def fill_many(self, at, k, value, r, J, i) -> None:
        a, b = k
        r[:, i] = 0.5 * (at.P[a][:, 2] + at.P[b][:, 2]) - self.design - value
        if J is not None:  # ½ is exact: ½·J_a + ½·J_b is ½·(J_a + J_b) to the bit
            for f in k:
                if len(at.cols[f]):
                    J[:, i, at.cols[f]] += 0.5 * at.Jc[f][:, :, 2].T

    def drift_many(self, at, k, V, A, qdd, out, i) -> None:
        a, b = k
        out[:, i] = 0.5 * (A[a][:, 2] + A[b][:, 2])
