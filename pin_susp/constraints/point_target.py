"""A named point held on a plane: the usual sweep target (wheel-centre height, rack)."""

from __future__ import annotations

import numpy as np

from .row import Row


class PointTarget(Row):
    """r = P·d̂ − value (1 row, m): the point's coordinate along the unit direction d̂,
    less the target value (positive past it). J = d̂ᵀ·J_P; r̈ = d̂·a_P. The point is a
    FramePoint or a derived point (points.ContactPatchPoint), computed from its frames."""

    size = 1

    def __init__(self, point, direction: np.ndarray, value: float = 0.0):
        self.point = point
        self.direction = np.asarray(direction, dtype=float)
        self.value = value
        self.frames = tuple(point.frame_points)
        self._direct = self.frames == (point,)  # a frame itself: its position is the row's
        d = self.direction
        self._axis = int(np.argmax(np.abs(d))) if np.count_nonzero(d) == 1 else None

    @property
    def name(self) -> str:
        return f"target {self.point.name}"

    def residual(self, kin) -> np.ndarray:
        return np.array([self.point.position(kin) @ self.direction - self.value])

    def jacobian(self, kin) -> np.ndarray:
        return (self.direction @ self.point.jacobian(kin))[None]

    def fill(self, at, k, r, J, i) -> None:
        d = self.direction
        if not self._direct:
            p, jac = self.point.from_frames(
                [at.P[f] for f in k], None if J is None else [at.Jp[f] for f in k]
            )
            r[i] = p @ d - self.value
            if J is not None:
                J[i] = d @ jac
            return
        (f,) = k
        axis = self._axis
        if axis is None:
            r[i] = d @ at.P[f] - self.value
            if J is not None:
                J[i] = d @ at.Jp[f]
        else:  # an axis-aligned target reads one coordinate
            r[i] = d[axis] * at.P[f][axis] - self.value
            if J is not None:
                J[i] = d[axis] * at.Jp[f][axis]

    def fill_many(self, at, k, value, r, J, i) -> None:
        if self._direct:
            (f,) = k
            r[:, i] = at.P[f] @ self.direction - value
            if J is not None and len(at.cols[f]):
                J[:, i, at.cols[f]] = (at.Jc[f] @ self.direction).T
            return
        cols = at.cols[k[0]] if J is not None else None
        if cols is not None and len(cols) and all(np.array_equal(at.cols[f], cols) for f in k):
            # its frames on one body (a contact patch's): the chain rule in their columns
            p, jac = self.point.from_frames_many(
                [at.P[f] for f in k], [at.Jc[f].transpose(1, 2, 0) for f in k]
            )
            r[:, i] = p @ self.direction - value
            J[:, i, cols] = np.einsum("i,niv->nv", self.direction, jac)
            return
        p, jac = self.point.from_frames_many(
            [at.P[f] for f in k], None if J is None else [at.Jp[f] for f in k]
        )
        r[:, i] = p @ self.direction - value
        if J is not None:
            J[:, i] = np.einsum("i,niv->nv", self.direction, jac)

    def drift_many(self, at, k, V, A, qdd, out, i) -> None:
        if not self._direct:
            super().drift_many(at, k, V, A, qdd, out, i)
        out[:, i] = A[k[0]] @ self.direction
