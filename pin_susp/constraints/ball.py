"""A ball joint closing a loop: two anchors on different bodies coincide."""

from __future__ import annotations

import numpy as np

from .row import Row


class BallClosure(Row):
    """r = p_b − p_a (3 rows, m, world axes): zero when the anchors a and b (FramePoints
    on the two bodies the ball joint connects) coincide. J = J_b − J_a (linear rows of
    the frames' LOCAL_WORLD_ALIGNED Jacobians); r̈ = a_b − a_a."""

    size = 3

    def __init__(self, name: str, a, b):
        self.name, self.a, self.b = name, a, b
        self.frames = (a, b)

    def residual(self, kin) -> np.ndarray:
        return self.b.position(kin) - self.a.position(kin)

    def jacobian(self, kin) -> np.ndarray:
        return self.b.jacobian(kin) - self.a.jacobian(kin)

    def fill(self, at, k, r, J, i) -> None:
        a, b = k
        r[i : i + 3] = at.P[b] - at.P[a]
        if J is not None:
            J[i : i + 3] = at.Jp[b] - at.Jp[a]

    def fill_many(self, at, k, value, r, J, i) -> None:
        a, b = k
        r[:, i : i + 3] = at.P[b] - at.P[a]
        if J is not None:
            at.add_rows(J, i, b)
            at.add_rows(J, i, a, -1.0)

    def drift_many(self, at, k, V, A, qdd, out, i) -> None:
        a, b = k
        out[:, i : i + 3] = A[b] - A[a]
