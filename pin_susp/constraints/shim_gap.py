"""A camber-shim stack between the camber block's face and the upright's."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .row import Row


def skew_many(n: np.ndarray) -> np.ndarray:
    """[n]× for n (n, 3): (n, 3, 3)."""
    S = np.zeros((len(n), 3, 3))
    S[:, 0, 1], S[:, 0, 2] = -n[:, 2], n[:, 1]
    S[:, 1, 0], S[:, 1, 2] = n[:, 2], -n[:, 0]
    S[:, 2, 0], S[:, 2, 1] = -n[:, 1], n[:, 0]
    return S


class ShimGap(Row):
    """r = p_body − p_block − t·n_block (3 rows, m): the faces' datum points ``body`` and
    ``block`` a shim stack of thickness t apart along the block's face normal
    n_block = R_block·n₀, which turns with the block: d(n_block) = ω_block × n_block,
    so J = J_body − J_block + t·[n_block]×·W_block (W: the angular Jacobian rows)."""

    size = 3
    angular = True

    def __init__(self, name: str, block, body, normal, thickness: float):
        self.name, self.block, self.body = name, block, body
        self.normal = np.asarray(normal, dtype=float)
        self.thickness = thickness
        self.frames = (block, body)

    def residual(self, kin) -> np.ndarray:
        n = kin.data.oMf[self.block.frame_id].rotation @ self.normal
        return self.body.position(kin) - self.block.position(kin) - self.thickness * n

    def jacobian(self, kin) -> np.ndarray:
        n = kin.data.oMf[self.block.frame_id].rotation @ self.normal
        j_block = kin.frame_jacobian(self.block.frame_id)
        return self.body.jacobian(kin) - j_block[:3] + self.thickness * pin.skew(n) @ j_block[3:]

    def fill(self, at, k, r, J, i) -> None:
        block, body = k
        n = at.M[block].rotation @ self.normal
        r[i : i + 3] = at.P[body] - at.P[block] - self.thickness * n
        if J is not None:
            j_block = at.J6[block]
            J[i : i + 3] = at.Jp[body] - j_block[:3] + self.thickness * pin.skew(n) @ j_block[3:]

    def fill_many(self, at, k, value, r, J, i) -> None:
        block, body = k
        n = at.R[block] @ self.normal
        r[:, i : i + 3] = at.P[body] - at.P[block] - self.thickness * n
        if J is not None:
            turn = skew_many(n) @ at.W[block]
            J[:, i : i + 3] = at.Jp[body] - at.Jp[block] + self.thickness * turn
