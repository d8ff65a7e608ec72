"""The points rows are written on: a frame of the model, or the contact patch.

A point has ``position(kin)`` and ``jacobian(kin)`` (3 rows, m; d/dv) and the same
from its frames' data: ``frame_points`` (the FramePoints it is computed from),
``from_frames(P, J)`` at one configuration and ``from_frames_many(P, J)`` for n.
"""

from __future__ import annotations

import math

import numpy as np

from .kinematics import Kinematics


class FramePoint:
    """A point fixed to a body: a Pinocchio frame of the model."""

    def __init__(self, name: str, frame_id: int, body: str):
        self.name = name
        self.frame_id = frame_id
        self.body = body

    @property
    def frame_points(self) -> tuple:
        return (self,)

    def position(self, kin: Kinematics) -> np.ndarray:
        return kin.data.oMf[self.frame_id].translation

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        return kin.frame_jacobian(self.frame_id)[:3]

    @staticmethod
    def from_frames(P, J=None) -> tuple:
        return P[0], None if J is None else J[0]

    @staticmethod
    def from_frames_many(P, J=None) -> tuple:
        return P[0], None if J is None else J[0]


class ContactPatchPoint:
    """CP = WC + R·d̂(â): the lowest point of the tyre disc; not fixed to a body.

    â = unit(AO − AI) is the spin axis, d̂ = unit(a_z·â − Ẑ) the disc's downward
    radius (m). Its Jacobian is the chain rule through â and d̂: with
    u = a_z·â − Ẑ, du = da_z·â + a_z·dâ and dd̂ = (I − d̂d̂ᵀ)·du / |u|,
    dâ = (I − ââᵀ)·d(AO − AI) / |AO − AI|.
    """

    def __init__(
        self,
        name: str,
        center: FramePoint,
        axle_in: FramePoint,
        axle_out: FramePoint,
        radius,
        body: str = "upright",
    ):
        self.name, self.body = name, body
        self.center, self.axle_in, self.axle_out = center, axle_in, axle_out
        self.radius = radius

    @property
    def frame_points(self) -> tuple:
        return (self.center, self.axle_in, self.axle_out)

    def position(self, kin: Kinematics) -> np.ndarray:
        return self.from_frames([p.position(kin) for p in self.frame_points])[0]

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        P = [p.position(kin) for p in self.frame_points]
        return self.from_frames(P, [p.jacobian(kin) for p in self.frame_points])[1]

    def from_frames(self, P, J=None) -> tuple:
        """(position, Jacobian or None) from its frames' positions P and Jacobians J
        (wheel centre, axle inboard, axle outboard), one configuration."""
        v = P[2] - P[1]
        n = math.sqrt(v @ v)
        a = v / n
        u = a * a[2]  # wheel_down's, inline (a hot path): d̂ = unit(a_z·â − Ẑ)
        u[2] -= 1.0
        norm = math.sqrt(u @ u)
        down = u / norm
        position = P[0] + self.radius * down
        if J is None:
            return position, None
        dv = J[2] - J[1]
        da = (dv - a[:, None] * (a @ dv)) / n
        du = a[:, None] * da[2] + a[2] * da
        dd = (du - down[:, None] * (down @ du)) / norm
        return position, J[0] + self.radius * dd

    def from_frames_many(self, P, J=None) -> tuple:
        """The same for n configurations: P (n, 3) each, J (n, 3, nv) each."""
        v = P[2] - P[1]
        n = np.sqrt(np.einsum("ni,ni->n", v, v))[:, None]
        a = v / n
        u = a * a[:, 2:3]
        u[:, 2] -= 1.0
        norm = np.sqrt(np.einsum("ni,ni->n", u, u))[:, None]
        down = u / norm
        position = P[0] + self.radius * down
        if J is None:
            return position, None
        dv = J[2] - J[1]
        da = (dv - a[:, :, None] * np.einsum("ni,niv->nv", a, dv)[:, None]) / n[:, :, None]
        du = a[:, :, None] * da[:, 2:3] + a[:, 2:3, None] * da
        dd = (du - down[:, :, None] * np.einsum("ni,niv->nv", down, du)[:, None]) / norm[:, :, None]
        return position, J[0] + self.radius * dd
