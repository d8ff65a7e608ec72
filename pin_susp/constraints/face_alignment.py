"""Two faces kept parallel: the camber block's and the upright's, across a shim stack."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .row import Row
from .shim_gap import skew_many


class FaceAlignment(Row):
    """r = R_body·n₀ − R_block·n₀ (3 rows, dimensionless): the faces' normals equal.
    The vector difference (not a cross product) rejects the anti-parallel branch.
    d(R·n₀) = ω × (R·n₀), so J = −[n_body]×·W_body + [n_block]×·W_block."""

    size = 3
    angular = True

    def __init__(self, name: str, block, body, normal):
        self.name, self.block, self.body = name, block, body
        self.normal = np.asarray(normal, dtype=float)
        self.frames = (block, body)

    def residual(self, kin) -> np.ndarray:
        rot = kin.data.oMf
        return (rot[self.body.frame_id].rotation - rot[self.block.frame_id].rotation) @ self.normal

    def jacobian(self, kin) -> np.ndarray:
        rot = kin.data.oMf
        n_body = rot[self.body.frame_id].rotation @ self.normal
        n_block = rot[self.block.frame_id].rotation @ self.normal
        w_body = kin.frame_jacobian(self.body.frame_id)[3:]
        w_block = kin.frame_jacobian(self.block.frame_id)[3:]
        return -pin.skew(n_body) @ w_body + pin.skew(n_block) @ w_block

    def fill(self, at, k, r, J, i) -> None:
        block, body = k
        R_block, R_body = at.M[block].rotation, at.M[body].rotation
        r[i : i + 3] = (R_body - R_block) @ self.normal
        if J is not None:
            n_body, n_block = R_body @ self.normal, R_block @ self.normal
            w_body, w_block = at.J6[body][3:], at.J6[block][3:]
            J[i : i + 3] = -pin.skew(n_body) @ w_body + pin.skew(n_block) @ w_block

    def fill_many(self, at, k, value, r, J, i) -> None:
        block, body = k
        R_block, R_body = at.R[block], at.R[body]
        r[:, i : i + 3] = (R_body - R_block) @ self.normal
        if J is not None:
            n_body, n_block = R_body @ self.normal, R_block @ self.normal
            J[:, i : i + 3] = -skew_many(n_body) @ at.W[body] + skew_many(n_block) @ at.W[block]
