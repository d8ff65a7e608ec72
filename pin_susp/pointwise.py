"""An independent formulation of the corner: points as unknowns, scipy least_squares.

It shares no kinematics with the Pinocchio path: the unknowns are the
coordinates of the moving hardpoints (and the rack's displacement), the
constraints are rigid-body distances between hardpoints of one part, the
derived points are written again from spec/geometry.md. ``pin-susp
validate`` and the tests solve every step with it and compare.
"""

from __future__ import annotations

import itertools

import numpy as np
from scipy.optimize import least_squares

from .geometry import Geometry

Y = np.array([0.0, 1.0, 0.0])


class PointwiseCorner:
    """A corner as points and distances (SI units)."""

    def __init__(self, geometry: Geometry, hardpoints: dict[str, np.ndarray] | None = None):
        g = geometry
        hp = dict(hardpoints or g.hardpoints)
        self.geometry = g
        self.inner, self.outer = g.steering_points
        mount = g.actuation_mount
        parts = {
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
        fixed |= {"strut_top", "rocker_axis_a", "rocker_axis_b"}
        if g.steering == "none":
            fixed.add(self.inner)
        links = [(self.outer, self.inner)]
        if g.has_pushrod:
            parts[mount].append("pushrod_outboard")
            parts["rocker"] = ["rocker_axis_a", "rocker_axis_b", "pushrod_inboard"]
            if g.spring == "coilover":
                parts["rocker"].append("strut_bottom")
            links.append(("pushrod_outboard", "pushrod_inboard"))
        elif g.spring == "coilover":
            parts[mount].append("strut_bottom")
        self.moving = sorted({n for pts in parts.values() for n in pts} - fixed - {self.inner})
        self.column = {n: 3 * i for i, n in enumerate(self.moving)}
        self.rack = 3 * len(self.moving) if g.steering == "rack" else None
        self.pairs = [
            (a, b, float(np.linalg.norm(hp[a] - hp[b])))
            for pts in parts.values()
            for a, b in itertools.combinations(pts, 2)
            if not (a in fixed and b in fixed)
        ]
        self.pairs += [(a, b, float(np.linalg.norm(hp[a] - hp[b]))) for a, b in links]
        self.hp = hp
        n = 3 * len(self.moving) + (1 if self.rack is not None else 0)
        self.x0 = np.zeros(n)
        for name, c in self.column.items():
            self.x0[c : c + 3] = hp[name]

    def points(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """Every hardpoint and derived point for the unknowns x."""
        out = dict(self.hp)
        out.update({n: x[c : c + 3] for n, c in self.column.items()})
        if self.rack is not None:
            out[self.inner] = self.hp[self.inner] + x[self.rack] * Y
        wheel = self.geometry.wheel
        a = out["axle_outboard"] - out["axle_inboard"]
        a = a / np.linalg.norm(a)
        center = out["axle_outboard"] - wheel.offset * a
        down = np.array([0.0, 0.0, -1.0]) + a[2] * a
        out.update(
            axle_midpoint=0.5 * (out["axle_inboard"] + out["axle_outboard"]),
            wheel_center=center,
            wheel_inboard=center - 0.5 * wheel.section_width * a,
            wheel_outboard=center + 0.5 * wheel.section_width * a,
            contact_patch_center=center + wheel.radius * down / np.linalg.norm(down),
        )
        return out

    def residual(self, x: np.ndarray, targets) -> np.ndarray:
        p = self.points(x)
        rows = [np.linalg.norm(p[a] - p[b]) - d for a, b, d in self.pairs]
        rows += [p[name] @ d - value for name, d, value in targets]
        return np.array(rows)

    def jacobian(self, x: np.ndarray, targets) -> np.ndarray:
        """Distance rows by hand; target rows (derived points) by central differences."""
        p = self.points(x)
        J = np.zeros((len(self.pairs) + len(targets), len(x)))
        for row, (a, b, _) in enumerate(self.pairs):
            u = (p[a] - p[b]) / np.linalg.norm(p[a] - p[b])
            for name, sign in ((a, 1.0), (b, -1.0)):
                if name in self.column:
                    J[row, self.column[name] : self.column[name] + 3] += sign * u
                elif name == self.inner and self.rack is not None:
                    J[row, self.rack] += sign * u[1]
        h = 1e-7
        for i in range(len(x)):
            e = np.zeros(len(x))
            e[i] = h
            plus, minus = self.points(x + e), self.points(x - e)
            for k, (name, d, _) in enumerate(targets):
                J[len(self.pairs) + k, i] = (plus[name] - minus[name]) @ d / (2 * h)
        return J

    def solve(self, targets, x0: np.ndarray | None = None) -> tuple[np.ndarray, float]:
        """Hold each (point, unit direction, absolute value m); returns x and max |residual|."""
        x0 = self.x0 if x0 is None else x0
        sol = least_squares(
            self.residual,
            x0,
            jac=self.jacobian,
            args=(targets,),
            method="lm",
            xtol=1e-15,
            ftol=1e-15,
            gtol=1e-15,
        )
        return sol.x, float(np.max(np.abs(sol.fun)))
