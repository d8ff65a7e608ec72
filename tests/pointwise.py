"""Independent computations for cross-checks.

``PointwiseCorner`` wraps pin_susp.analyses.pointwise — hardpoint coordinates as
unknowns, rigid distances, scipy least_squares — which shares no kinematics
with the Pinocchio path; ``PointwiseVehicle`` is the same machinery for a whole
car, its points in the road's frame under a body pose given. The shim assembly
and the metrics are written again here from the reference article and
docs/results.md.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from pin_susp.analyses.pointwise import Along, PointwiseLinkage, labelled


def _vec(v) -> np.ndarray:
    return np.array([v["x"], v["y"], v["z"]], float) if isinstance(v, dict) else np.array(v, float)


class PointwiseCorner:
    """pin_susp.analyses.pointwise (points as unknowns, scipy) with a mm interface for the tests."""

    def __init__(self, data: dict, hardpoints: dict | None = None):
        from pin_susp.analyses.pointwise import PointwiseCorner as Points
        from pin_susp.model.geometry import load_geometry

        si = None if hardpoints is None else {k: v * 1e-3 for k, v in hardpoints.items()}
        self.points_model = Points(load_geometry(data), si)
        self.hp = {k: v * 1e3 for k, v in self.points_model.hp.items()}

    def solve(self, wc_z: float, rack: float, x0=None):
        """Wheel centre z (absolute, mm) and rack displacement (mm)."""
        m = self.points_model
        targets = [("wheel_center", np.array([0.0, 0.0, 1.0]), wc_z * 1e-3)]
        if m.rack is not None:
            tri_y = m.hp[m.inner][1]
            targets.append((m.inner, np.array([0.0, 1.0, 0.0]), tri_y + rack * 1e-3))
        x, residual = m.solve(targets, x0)
        return x, residual * 1e3

    def points(self, x) -> dict[str, np.ndarray]:
        return {k: v * 1e3 for k, v in self.points_model.points(x).items()}


def spec_metrics(p: dict[str, np.ndarray], s: float) -> dict[str, float]:
    """camber, caster, kpi, toe, scrub, trail, half track as docs/results.md writes them."""
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


class PointwiseAxle:
    """pin_susp.analyses.pointwise's axle (both corners, the rack, the bar: points as unknowns,
    scipy) with the sweep's own units: mm, deg, relative point targets from its own
    design state."""

    def __init__(self, axle):
        from pin_susp.analyses.pointwise import PointwiseAxle as Points

        self.points_model = Points(axle)

    def solve(self, targets, step: int):
        """Step ``step`` of a sweep's targets, from the design state: (points in mm,
        max |residual| in SI)."""
        m = self.points_model
        values = []
        for t in targets:
            v = float(t.values[step])
            if t.quantity == "roll":
                values.append(np.radians(v))
            elif t.quantity == "heave" or t.mode == "absolute":
                values.append(v * 1e-3)
            else:  # relative: from the design position along the direction
                values.append(v * 1e-3 + m.design[f"{t.side}_{t.point}"] @ t.unit_direction)
        x, residual = m.solve(m.targets(targets, values))
        return {k: v * 1e3 for k, v in m.points(x).items()}, residual


def body_rotation(pitch: float, roll: float) -> np.ndarray:
    """R_y(pitch)·R_x(roll) (rad): + pitch nose down (+x goes to −z), + roll right side
    down (+y, the left, goes to +z), ISO 8855."""
    c, s = np.cos(pitch), np.sin(pitch)
    ry = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    c, s = np.cos(roll), np.sin(roll)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    return ry @ rx


def _cross(v: np.ndarray) -> np.ndarray:
    """[v]×: the matrix of w ↦ v × w."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


class PointwiseVehicle(PointwiseLinkage):
    """A whole car with no Pinocchio: every moving hardpoint of its four corners in the
    road's (world) frame, and the rack's travel, as unknowns (SI units).

    ``corners``: label (fl, fr, rl, rr) → Geometry; ``cg`` (3,), m, chassis frame. The
    chassis points are placed in the world by the body's pose (:meth:`place`):
    w = c + h·ẑ + R_y(θ)·R_x(φ)·(p − c). Each corner's parts, links and lines are
    pin_susp.analyses.pointwise's (:func:`labelled`, names prefixed ``fl_`` ...); the
    rack slides along the body's y; the derived wheel points are computed in the world,
    so ``<c>_contact_patch_center`` is the wheel's lowest point on the road's vertical.
    Rows: the rigid distances, the lines, each contact patch at its road height, the
    rack's travel."""

    def __init__(self, corners: dict, cg):
        self.rack_dir = np.array([0.0, 1.0, 0.0])  # the body's y in the world
        super().__init__(*labelled(corners)[:4])
        self.labels = tuple(corners)
        self.chassis = dict(self.hp)  # every hardpoint at design, chassis frame
        self.cg = np.asarray(cg, dtype=float)
        self.place(0.0, 0.0, 0.0)

    def place(self, heave: float, pitch: float, roll: float) -> None:
        """Put the chassis (its fixed points, the rack at design) at the body's pose (m,
        rad): the moving points then come from the unknowns."""
        self.pose = (heave, pitch, roll)
        self.R = body_rotation(pitch, roll)
        self.shift = self.cg + np.array([0.0, 0.0, heave])
        self.hp = {n: self.shift + self.R @ (p - self.cg) for n, p in self.chassis.items()}
        self.rack_dir = self.R @ np.array([0.0, 1.0, 0.0])

    def to_chassis(self, w: np.ndarray) -> np.ndarray:
        """A world point back in the chassis frame at the current pose."""
        return self.cg + self.R.T @ (w - self.shift)

    def points(self, x: np.ndarray) -> dict[str, np.ndarray]:
        out = super().points(x)
        for inner in self.racks:  # along the body's y, not the world's
            out[inner] = self.hp[inner] + x[self.rack] * self.rack_dir
        return out

    def _add(self, row: np.ndarray, name: str, gradient: np.ndarray) -> None:
        if name in self.racks:
            row[self.rack] += gradient @ self.rack_dir
        else:
            super()._add(row, name, gradient)

    def jacobian(self, x: np.ndarray, targets) -> np.ndarray:
        """The distance and target rows as PointwiseLinkage writes them, then each line
        row (p − a) × û, û = unit(b − a), analytic: d/dp = −[û]×, d/db = [p − a]×·D,
        d/da = [û]× − [p − a]×·D, D = (I − ûûᵀ)/|b − a| (no planes here)."""
        lines, self.lines = self.lines, []
        try:
            J = super().jacobian(x, targets)
        finally:
            self.lines = lines
        p = self.points(x)
        rows = []
        for point, a, b in lines:
            v = p[b] - p[a]
            u, d = v / np.linalg.norm(v), p[point] - p[a]
            D = (np.eye(3) - np.outer(u, u)) / np.linalg.norm(v)
            block = np.zeros((3, len(x)))
            for name, g in (
                (point, -_cross(u)),
                (b, _cross(d) @ D),
                (a, _cross(u) - _cross(d) @ D),
            ):
                for i in range(3):
                    self._add(block[i], name, g[i])
            rows.append(block)
        return np.vstack([J, *rows])

    def guess(self) -> np.ndarray:
        """The design state carried by the current pose (the wheels still in the body)."""
        x = np.zeros_like(self.x0)
        for name, c in self.column.items():
            x[c : c + 3] = self.hp[name]
        return x

    def solve_pose(self, heave, pitch, roll, road_z=None, rack=0.0, x0=None):
        """The car at the body's pose (m, rad), each corner's contact patch at its road
        height (``road_z``: label → m, default 0), the rack ``rack`` (m) from design
        along the body's y; returns x and max |residual| (m)."""
        self.place(heave, pitch, roll)
        road_z = road_z or {}
        z = np.array([0.0, 0.0, 1.0])
        targets = [Along(f"{c}_contact_patch_center", z, road_z.get(c, 0.0)) for c in self.labels]
        if self.racks:
            inner = self.racks[0]
            targets.append(Along(inner, self.rack_dir, self.hp[inner] @ self.rack_dir + rack))
        return self.solve(targets, self.guess() if x0 is None else x0)
