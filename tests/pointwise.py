"""An independent formulation of a double-wishbone corner, for cross-checks.

Unknowns are the coordinates of the moving hardpoints (and the rack
displacement); constraints are rigid-body distances between hardpoints;
scipy's least_squares solves them. It shares no code with pin_susp: the
derived points, the shim assembly and the metrics are written again here
from spec/geometry.md, spec/results.md and the reference article.
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.optimize import least_squares


def _vec(v) -> np.ndarray:
    return np.array([v["x"], v["y"], v["z"]], float) if isinstance(v, dict) else np.array(v, float)


class PointwiseCorner:
    """Hardpoints in mm, as in the file; solutions in mm."""

    def __init__(self, data: dict, hardpoints: dict | None = None):
        hp = hardpoints or {k: _vec(v) for k, v in data["hardpoints"].items()}
        config = data["config"]
        steering = config.get("steering", {}).get("type", "rack")
        actuation = data.get("actuation", {}).get("type", "direct")
        mount = data.get("actuation", {}).get("mount", "lower_wishbone")
        spring = data.get("spring", {}).get("type", "none")
        self.inner, self.outer = (
            ("trackrod_inboard", "trackrod_outboard")
            if steering == "rack"
            else ("toe_link_inboard", "toe_link_outboard")
        )
        bodies = {
            "lower_wishbone": [
                "lower_wishbone_inboard_front",
                "lower_wishbone_inboard_rear",
                "lower_wishbone_outboard",
            ],
            "upper_wishbone": [
                "upper_wishbone_inboard_front",
                "upper_wishbone_inboard_rear",
                "upper_wishbone_outboard",
            ],
            "upright": [
                "lower_wishbone_outboard",
                "upper_wishbone_outboard",
                self.outer,
                "axle_inboard",
                "axle_outboard",
            ],
        }
        fixed = {n for n in hp if "inboard_front" in n or "inboard_rear" in n}
        fixed |= {"strut_top", "rocker_axis_a", "rocker_axis_b", self.inner}
        self.links = [(self.outer, self.inner)]
        if actuation == "pushrod_rocker":
            bodies[mount].append("pushrod_outboard")
            bodies["rocker"] = ["rocker_axis_a", "rocker_axis_b", "pushrod_inboard"]
            if spring == "coilover":
                bodies["rocker"].append("strut_bottom")
            self.links.append(("pushrod_outboard", "pushrod_inboard"))
        elif spring == "coilover":
            bodies[mount].append("strut_bottom")
        self.moving = sorted({n for pts in bodies.values() for n in pts} - fixed)
        self.column = {n: 3 * i for i, n in enumerate(self.moving)}
        self.rack = 3 * len(self.moving)
        self.pairs = [
            (a, b, np.linalg.norm(hp[a] - hp[b]))
            for pts in bodies.values()
            for a, b in itertools.combinations(pts, 2)
            if not (a in fixed and b in fixed)
        ]
        self.pairs += [(a, b, np.linalg.norm(hp[a] - hp[b])) for a, b in self.links]
        self.hp = hp
        self.s = 1.0 if data.get("side", "left") == "left" else -1.0
        tire = config["wheel"]["tire"]
        self.offset = config["wheel"].get("offset", 0.0)
        self.width = tire["section_width"]
        self.radius = tire["rim_diameter"] * 25.4 / 2 + tire["aspect_ratio"] * tire["section_width"]
        self.x = np.concatenate([hp[n] for n in self.moving] + [[0.0]])

    def points(self, x) -> dict[str, np.ndarray]:
        out = dict(self.hp)
        out.update({n: x[c : c + 3] for n, c in self.column.items()})
        out[self.inner] = self.hp[self.inner] + np.array([0.0, x[self.rack], 0.0])
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
        p = self.points(x)
        res = [np.linalg.norm(p[a] - p[b]) - d for a, b, d in self.pairs]
        res.append(p["wheel_center"][2] - wc_z)
        res.append(x[self.rack] - rack)
        return np.array(res)

    def jacobian(self, x, wc_z, rack):
        p = self.points(x)
        J = np.zeros((len(self.pairs) + 2, len(x)))
        for row, (a, b, _) in enumerate(self.pairs):
            u = (p[a] - p[b]) / np.linalg.norm(p[a] - p[b])
            for name, sign in ((a, 1.0), (b, -1.0)):
                if name in self.column:
                    J[row, self.column[name] : self.column[name] + 3] += sign * u
                elif name == self.inner:
                    J[row, self.rack] += sign * u[1]
        v = p["axle_outboard"] - p["axle_inboard"]
        n = np.linalg.norm(v)
        a = v / n
        da_dz = ((np.eye(3) - np.outer(a, a)) / n)[2]  # d â_z / d(AO − AI)
        ao, ai = self.column["axle_outboard"], self.column["axle_inboard"]
        J[-2, ao : ao + 3] = np.array([0, 0, 1.0]) - self.offset * da_dz
        J[-2, ai : ai + 3] = self.offset * da_dz
        J[-1, self.rack] = 1.0
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


def rodrigues(v: np.ndarray, rotvec: np.ndarray) -> np.ndarray:
    """v turned by the rotation vector (axis·angle)."""
    angle = np.linalg.norm(rotvec)
    if angle < 1e-300:
        return v.copy()
    k = rotvec / angle
    return v * np.cos(angle) + np.cross(k, v) * np.sin(angle) + k * (k @ v) * (1 - np.cos(angle))


def shim_assembly(data: dict) -> dict[str, np.ndarray]:
    """The camber-shim solve of the reference article: 7 unknowns, 10 residuals (mm).

    x = [upper wishbone angle, camber block rotation vector about the UBJ,
    upright body rotation vector about the LBJ]; residuals: datum A and B
    closures, face normal alignment, trackrod length with the rack fixed.
    Returns the moved hardpoints.
    """
    hp = {k: _vec(v) for k, v in data["hardpoints"].items()}
    shim = data["config"]["camber_shim"]
    n0 = _vec(shim["shim_face_normal"])
    n0 = n0 / np.linalg.norm(n0)
    td, ts = shim["design_thickness"], shim["setup_thickness"]
    a, b = _vec(shim["shim_face_point_a"]), _vec(shim["shim_face_point_b"])
    front, rear = hp["upper_wishbone_inboard_front"], hp["upper_wishbone_inboard_rear"]
    axis = (rear - front) / np.linalg.norm(rear - front)
    ubj, lbj = hp["upper_wishbone_outboard"], hp["lower_wishbone_outboard"]
    steering = data["config"].get("steering", {}).get("type", "rack")
    inner, outer = (
        ("trackrod_inboard", "trackrod_outboard")
        if steering == "rack"
        else ("toe_link_inboard", "toe_link_outboard")
    )
    length = np.linalg.norm(hp[outer] - hp[inner])
    block = {d: p - td / 2 * n0 - ubj for d, p in (("a", a), ("b", b))}
    body = {d: p + td / 2 * n0 - lbj for d, p in (("a", a), ("b", b))}

    def residual(x):
        ubj_x = front + rodrigues(ubj - front, axis * x[0])
        n_block, n_body = rodrigues(n0, x[1:4]), rodrigues(n0, x[4:7])
        res = []
        for d in "ab":
            p_block = ubj_x + rodrigues(block[d], x[1:4])
            p_body = lbj + rodrigues(body[d], x[4:7])
            res.append(p_body - p_block - ts * n_block)
        res.append(n_body - n_block)
        tro = lbj + rodrigues(hp[outer] - lbj, x[4:7])
        res.append([np.linalg.norm(tro - hp[inner]) - length])
        return np.concatenate(res)

    sol = least_squares(residual, np.zeros(7), method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.max(np.abs(sol.fun)) < 1e-10, sol.fun
    x = sol.x
    moved = {"upper_wishbone_outboard": front + rodrigues(ubj - front, axis * x[0])}
    on_body = [outer, "axle_inboard", "axle_outboard"]
    if data.get("actuation", {}).get("mount") == "upright":
        on_body += [
            n
            for n in ("pushrod_outboard", "strut_bottom")
            if n in hp and not (n == "strut_bottom" and data["actuation"]["type"] != "direct")
        ]
    for name in on_body:
        moved[name] = lbj + rodrigues(hp[name] - lbj, x[4:7])
    return moved
