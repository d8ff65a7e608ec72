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
    """A corner as points and distances (SI units).

    The mechanism says which points move as one rigid part, which are joined
    by links, which stay on a line (``Mechanism.pointwise``); here each part
    becomes every distance between its points, each link one distance, each
    line condition the cross product (p − a) × unit(b − a) = 0.
    """

    def __init__(self, geometry: Geometry, hardpoints: dict[str, np.ndarray] | None = None):
        g = geometry
        hp = dict(hardpoints or g.hardpoints)
        self.geometry = g
        spec = g.mechanism.pointwise(g)
        self.inner = spec.rack
        fixed = set(spec.fixed)
        # points of one part that coincide are one point (two links meeting in a ball)
        self.alias = {}
        for pts in spec.parts.values():
            for a, b in itertools.combinations(pts, 2):
                if b not in self.alias and np.linalg.norm(hp[a] - hp[b]) < 1e-12:
                    self.alias[b] = self.alias.get(a, a)
        parts = {
            k: list(dict.fromkeys(self.alias.get(n, n) for n in pts))
            for k, pts in spec.parts.items()
        }
        links = [(self.alias.get(a, a), self.alias.get(b, b)) for a, b in spec.links]
        self.lines = [tuple(self.alias.get(n, n) for n in line) for line in spec.lines]
        named = {n for pts in parts.values() for n in pts} | {n for ab in links for n in ab}
        self.moving = sorted(named - fixed - {self.inner})
        self.column = {n: 3 * i for i, n in enumerate(self.moving)}
        self.rack = 3 * len(self.moving) if self.inner is not None else None
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
        out.update({b: out[a] for b, a in self.alias.items()})
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
        for point, a, b in self.lines:
            rows += list(np.cross(p[point] - p[a], (p[b] - p[a]) / np.linalg.norm(p[b] - p[a])))
        return np.array(rows)

    def jacobian(self, x: np.ndarray, targets) -> np.ndarray:
        """Analytic: distance rows, and targets on hardpoints or on points fixed to the
        upright (through â = unit(AO − AI)); a contact-patch target by central
        differences."""
        p = self.points(x)
        J = np.zeros((len(self.pairs) + len(targets) + 3 * len(self.lines), len(x)))
        for row, (a, b, _) in enumerate(self.pairs):
            u = (p[a] - p[b]) / np.linalg.norm(p[a] - p[b])
            self._add(J[row], a, u)
            self._add(J[row], b, -u)
        for k, (name, d, _) in enumerate(targets):
            row = J[len(self.pairs) + k]
            if name in self.hp:
                self._add(row, name, d)
            elif name != "contact_patch_center":
                for end, gradient in self._derived(name, p).items():
                    self._add(row, end, gradient.T @ d)
            else:
                h = 1e-7
                for i in range(len(x)):
                    e = np.zeros(len(x))
                    e[i] = h
                    row[i] = (self.points(x + e)[name] - self.points(x - e)[name]) @ d / (2 * h)
        if self.lines:  # the line conditions by central differences
            first, h = len(self.pairs) + len(targets), 1e-7
            for i in range(len(x)):
                e = np.zeros(len(x))
                e[i] = h
                up, down = self.residual(x + e, targets), self.residual(x - e, targets)
                J[first:, i] = (up[first:] - down[first:]) / (2 * h)
        return J

    def _add(self, row: np.ndarray, name: str, gradient: np.ndarray) -> None:
        """Add d(row)/d(point) = gradient to the row's columns of that point."""
        if name in self.column:
            row[self.column[name] : self.column[name] + 3] += gradient
        elif name in self.alias:
            self._add(row, self.alias[name], gradient)
        elif name == self.inner and self.rack is not None:
            row[self.rack] += gradient[1]

    def _derived(self, name: str, p) -> dict[str, np.ndarray]:
        """d(derived point)/d(axle_inboard), d/d(axle_outboard) as 3×3 matrices."""
        wheel = self.geometry.wheel
        v = p["axle_outboard"] - p["axle_inboard"]
        a = v / np.linalg.norm(v)
        D = (np.eye(3) - np.outer(a, a)) / np.linalg.norm(v)  # dâ/d(AO − AI)
        along = {
            "axle_midpoint": None,
            "wheel_center": 0.0,
            "wheel_inboard": -0.5 * wheel.section_width,
            "wheel_outboard": 0.5 * wheel.section_width,
        }[name]
        if along is None:
            return {"axle_inboard": 0.5 * np.eye(3), "axle_outboard": 0.5 * np.eye(3)}
        k = along - wheel.offset  # the point is AO + k·â
        return {"axle_outboard": np.eye(3) + k * D, "axle_inboard": -k * D}

    def solve(
        self,
        targets,
        x0: np.ndarray | None = None,
        jacobian: str = "analytic",
        longer: tuple[tuple[str, str], float] | None = None,
    ) -> tuple[np.ndarray, float]:
        """Hold each (point, unit direction, absolute value m); returns x and max |residual|.

        ``jacobian="2-point"`` lets scipy difference the residuals instead;
        ``longer`` = ((a, b), δ): the link between points a and b made δ (m) longer.
        """
        x0 = self.x0 if x0 is None else x0
        if longer is not None:
            (a, b), delta = longer
            saved = self.pairs
            self.pairs = [(p, q, d + delta if {p, q} == {a, b} else d) for p, q, d in saved]
            try:
                return self.solve(targets, x0, jacobian)
            finally:
                self.pairs = saved
        sol = least_squares(
            self.residual,
            x0,
            jac=self.jacobian if jacobian == "analytic" else jacobian,
            args=(targets,),
            method="lm",
            xtol=1e-15,
            ftol=1e-15,
            gtol=1e-15,
        )
        return sol.x, float(np.max(np.abs(sol.fun)))
