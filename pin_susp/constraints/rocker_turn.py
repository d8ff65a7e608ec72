"""A torsion bar's row: the rocker's turn about its axis (a held row of the statics)."""

from __future__ import annotations

import numpy as np

from .row import Row


class RockerTurn(Row):
    """The rocker's turn about its axis â = unit(b − a) (1 row, rad per dq): a held row —
    its residual is zero, only its Jacobian counts, J = âᵀ·W_rocker (the angular
    Jacobian rows of a frame on the rocker). Its multiplier is the torsion bar's torque
    (statics.py)."""

    size = 1
    angular = True

    def __init__(self, subject, prefix: str = ""):
        self.subject, self.prefix = subject, prefix
        self.name = f"{prefix}spring"
        p = subject.points
        self.point = p[f"{prefix}pushrod_inboard"]  # any frame on the rocker
        self.frames = (p[f"{prefix}rocker_axis_a"], p[f"{prefix}rocker_axis_b"], self.point)

    def residual(self, kin) -> np.ndarray:
        return np.zeros(1)

    def axis(self, kin) -> np.ndarray:
        a, b = self.frames[0].position(kin), self.frames[1].position(kin)
        return (b - a) / np.linalg.norm(b - a)

    def jacobian(self, kin) -> np.ndarray:
        return (self.axis(kin) @ kin.frame_jacobian(self.point.frame_id)[3:])[None]

    def fill(self, at, k, r, J, i) -> None:
        r[i] = 0.0
        if J is not None:
            a, b, f = k
            d = at.P[b] - at.P[a]
            J[i] = (d / np.linalg.norm(d)) @ at.J6[f][3:]

    def fill_many(self, at, k, value, r, J, i) -> None:
        r[:, i] = 0.0
        if J is not None:
            a, b, f = k
            d = at.P[b] - at.P[a]
            axis = d / np.sqrt(np.einsum("ni,ni->n", d, d))[:, None]
            J[:, i] = np.einsum("ni,niv->nv", axis, at.W[f])
