"""An axle's roll target: the angle of its contact patches' line over the track."""

from __future__ import annotations

import math

import numpy as np

from .row import Row


class RollTarget(Row):
    """r = atan2(ΔWC_z,L − ΔWC_z,R, CP_y,L − CP_y,R) − value (1 row, rad), ΔWC_z the
    wheel centres' rise from design (``design``: their design height difference, m):
    open-kinematics' roll, + = the left wheel higher relative to the chassis.

    A contact patch's y alone, in closed form: with â the spin axis and
    s = √(1 − a_z²), CP_y = WC_y + R·a_z·a_y/s (points.ContactPatchPoint's
    d̂ = unit(a_z·â − Ẑ), its y row); â turns with the upright, dâ = ω × â, so
    dCP_y = dWC_y + R·((a_z/s)·da_y + (a_y/s³)·da_z): a fixed combination of the
    wheel-centre frame's Jacobian rows (linear and angular), and so is the row's,
    d atan2(a, b) = (b·da − a·db)/(a² + b²).
    """

    name = "target roll"
    angular = True  # the wheel centres' rotations and angular Jacobians

    def __init__(self, wheels, radii, kin, design: float, value: float = 0.0, spin=None):
        self.frames = tuple(wheels)  # (left, right) wheel centres
        self.radii = radii
        self.design, self.value = design, value  # design: ΔWC_z,L − ΔWC_z,R offset (m)
        # each spin axis AI → AO in its wheel-centre frame (it turns with the upright)
        self.spin = [
            kin.data.oMf[w.frame_id].rotation.T @ a for w, a in zip(wheels, spin, strict=True)
        ]

    def residual(self, kin) -> np.ndarray:
        return self._from_frames([kin.data.oMf[p.frame_id] for p in self.frames])[0]

    def jacobian(self, kin) -> np.ndarray:
        placements = [kin.data.oMf[p.frame_id] for p in self.frames]
        return self._from_frames(placements, [kin.frame_jacobian(p.frame_id) for p in self.frames])[
            1
        ]

    def fill(self, at, k, r, J, i) -> None:
        a, b = k
        value, jacobian = self._from_frames(
            (at.M[a], at.M[b]), None if J is None else (at.J6[a], at.J6[b])
        )
        r[i : i + 1] = value
        if J is not None:
            J[i : i + 1] = jacobian

    def _from_frames(self, M, J=None) -> tuple:
        """From the wheel centres' placements M and Jacobians J (6 rows): a hot path
        (Python floats: numpy's scalars cost more than the arithmetic)."""
        y, z, c = [0.0, 0.0], [0.0, 0.0], [None, None]
        for k in (0, 1):
            ax, ay, az = (M[k].rotation @ self.spin[k]).tolist()
            _, wy, z[k] = M[k].translation.tolist()
            s = math.sqrt(1.0 - az * az)
            R = self.radii[k]
            y[k] = wy + R * az * ay / s
            # dCP_y = row 1 + R·(c_x ω_x + c_y ω_y + c_z ω_z), da = ω × â
            c[k] = (R * (ay * ay / s**3 - az * az / s), -R * ax * ay / s**3, R * az * ax / s)
        a = z[0] - z[1] - self.design
        b = y[0] - y[1]
        r = np.array([math.atan2(a, b) - self.value])
        if J is None:
            return r, None
        # d atan2(a, b) = (b·da − a·db)/(a² + b²): one row of weights per wheel centre
        scale = 1.0 / (a * a + b * b)
        rise, k = b * scale, a * scale
        (lx, ly, lz), (rx, ry, rz) = c
        w = np.array(
            [[0.0, -k, rise, -k * lx, -k * ly, -k * lz], [0.0, k, -rise, k * rx, k * ry, k * rz]]
        )
        return r, (w[0] @ J[0] + w[1] @ J[1])[None]

    def fill_many(self, at, k, value, r, J, i) -> None:
        y, z, c = [], [], []
        for side, f in enumerate(k):
            ax, ay, az = np.einsum("nij,j->in", at.R[f], self.spin[side])
            s = np.sqrt(1.0 - az * az)
            R = self.radii[side]
            y.append(at.P[f][:, 1] + R * az * ay / s)
            z.append(at.P[f][:, 2])
            c.append((R * (ay * ay / s**3 - az * az / s), -R * ax * ay / s**3, R * az * ax / s))
        a = z[0] - z[1] - self.design
        b = y[0] - y[1]
        r[:, i] = np.arctan2(a, b) - value
        if J is None:
            return
        scale = 1.0 / (a * a + b * b)
        rise, kk = (b * scale)[:, None], (a * scale)[:, None]
        zero = np.zeros(len(a))
        for side, f in enumerate(k):  # d(row) = ±(k·(dWC_y + c·ω) − rise·dWC_z)
            sign = -1.0 if side == 0 else 1.0
            lin = np.stack([zero, sign * kk[:, 0], -sign * rise[:, 0]], axis=1)
            ang = (sign * kk) * np.stack(c[side], axis=1)
            at.add(J, i, f, lin, ang)
