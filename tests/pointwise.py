"""An independent formulation of a double-wishbone corner, for cross-checks.

Unknowns are the coordinates of the moving hardpoints (and the rack
displacement); constraints are rigid-body distances between hardpoints;
scipy's least_squares solves them. It shares no code with pin_susp: the
derived points and metrics are written again here from spec/geometry.md
and spec/results.md.
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.optimize import least_squares

UPRIGHT = (
    "lower_wishbone_outboard",
    "upper_wishbone_outboard",
    "outer",
    "axle_inboard",
    "axle_outboard",
)


class PointwiseCorner:
    """Hardpoints in mm, as in the file; solutions in mm."""

    def __init__(self, data: dict):
        hp = {
            k: np.array([v["x"], v["y"], v["z"]], float)
            if isinstance(v, dict)
            else np.array(v, float)
            for k, v in data["hardpoints"].items()
        }
        self.steering = data["config"].get("steering", {}).get("type", "rack")
        self.inner, outer = (
            ("trackrod_inboard", "trackrod_outboard")
            if self.steering == "rack"
            else ("toe_link_inboard", "toe_link_outboard")
        )
        self.names = [n.replace("outer", outer) for n in UPRIGHT]
        self.hp = hp
        self.s = 1.0 if data.get("side", "left") == "left" else -1.0
        tire = data["config"]["wheel"]["tire"]
        self.offset = data["config"]["wheel"].get("offset", 0.0)
        self.width = tire["section_width"]
        self.radius = tire["rim_diameter"] * 25.4 / 2 + tire["aspect_ratio"] * tire["section_width"]
        # Rigid upright: every pairwise distance between its five points.
        self.pairs = [
            (i, j, np.linalg.norm(hp[self.names[i]] - hp[self.names[j]]))
            for i, j in itertools.combinations(range(5), 2)
        ]
        self.arms = []  # (upright point index, chassis point, length)
        for i, arm in ((0, "lower_wishbone"), (1, "upper_wishbone")):
            for end in ("inboard_front", "inboard_rear"):
                c = hp[f"{arm}_{end}"]
                self.arms.append((i, c, np.linalg.norm(hp[self.names[i]] - c)))
        self.link = np.linalg.norm(hp[self.names[2]] - hp[self.inner])
        self.x = np.concatenate([hp[n] for n in self.names] + [[0.0]])

    def unpack(self, x):
        return x[:15].reshape(5, 3), x[15]

    def points(self, x) -> dict[str, np.ndarray]:
        p, rack = self.unpack(x)
        out = dict(self.hp)
        out.update(zip(self.names, p, strict=True))
        out[self.inner] = self.hp[self.inner] + np.array([0.0, rack, 0.0])
        a = out["axle_outboard"] - out["axle_inboard"]
        a = a / np.linalg.norm(a)
        wc = out["axle_outboard"] - self.offset * a
        down = np.array([0.0, 0.0, -1.0]) + a[2] * a
        down = down / np.linalg.norm(down)
        out.update(
            axle_midpoint=0.5 * (out["axle_inboard"] + out["axle_outboard"]),
            wheel_center=wc,
            wheel_inboard=wc - 0.5 * self.width * a,
            wheel_outboard=wc + 0.5 * self.width * a,
            contact_patch_center=wc + self.radius * down,
        )
        return out

    def residual(self, x, wc_z, rack):
        p, r = self.unpack(x)
        res = [np.linalg.norm(p[i] - p[j]) - d for i, j, d in self.pairs]
        res += [np.linalg.norm(p[i] - c) - d for i, c, d in self.arms]
        tri = self.hp[self.inner] + np.array([0.0, r, 0.0])
        res.append(np.linalg.norm(p[2] - tri) - self.link)
        a = p[4] - p[3]
        a = a / np.linalg.norm(a)
        res.append((p[4] - self.offset * a)[2] - wc_z)
        res.append(r - rack)
        return np.array(res)

    def jacobian(self, x, wc_z, rack):
        p, r = self.unpack(x)
        J = np.zeros((len(self.pairs) + 4 + 3, 16))
        row = 0
        for i, j, _ in self.pairs:
            u = (p[i] - p[j]) / np.linalg.norm(p[i] - p[j])
            J[row, 3 * i : 3 * i + 3], J[row, 3 * j : 3 * j + 3] = u, -u
            row += 1
        for i, c, _ in self.arms:
            J[row, 3 * i : 3 * i + 3] = (p[i] - c) / np.linalg.norm(p[i] - c)
            row += 1
        d = p[2] - (self.hp[self.inner] + np.array([0.0, r, 0.0]))
        u = d / np.linalg.norm(d)
        J[row, 6:9], J[row, 15] = u, -u[1]
        row += 1
        v = p[4] - p[3]
        n = np.linalg.norm(v)
        a = v / n
        da_dv = (np.eye(3) - np.outer(a, a)) / n  # d â / d(AO − AI)
        J[row, 12:15] = np.array([0, 0, 1.0]) - self.offset * da_dv[2]
        J[row, 9:12] = self.offset * da_dv[2]
        row += 1
        J[row, 15] = 1.0
        return J

    def solve(self, wc_z: float, rack: float, x0=None):
        """Wheel centre z (absolute, mm) and rack displacement (mm)."""
        x0 = self.x if x0 is None else x0
        sol = least_squares(
            self.residual,
            x0,
            jac=self.jacobian,
            args=(wc_z, rack),
            method="lm",
            xtol=1e-15,
            ftol=1e-15,
            gtol=1e-15,
        )
        return sol.x, float(np.max(np.abs(sol.fun)))


def spec_metrics(p: dict[str, np.ndarray], s: float) -> dict[str, float]:
    """camber, caster, kpi, toe, scrub, trail, half track as spec/results.md writes them."""
    a = p["axle_outboard"] - p["axle_inboard"]
    a = a / np.linalg.norm(a)
    lbj, ubj = p["lower_wishbone_outboard"], p["upper_wishbone_outboard"]
    k = (ubj - lbj) / np.linalg.norm(ubj - lbj)
    cp = p["contact_patch_center"]
    g = lbj + (cp[2] - lbj[2]) / k[2] * k
    w = np.array([a[0], a[1], 0.0]) / np.hypot(a[0], a[1])
    return {
        "camber": -np.degrees(np.arctan2(a[2], s * a[1])),
        "caster": np.degrees(np.arctan2(-k[0], k[2])),
        "kpi": np.degrees(np.arctan2(-s * k[1], k[2])),
        "roadwheel_angle": np.degrees(np.arctan2(a[0], s * a[1])),
        "scrub_radius": -float((g - cp) @ w),
        "mechanical_trail": g[0] - cp[0],
        "half_track": abs(cp[1]),
    }
