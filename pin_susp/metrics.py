"""Corner metrics: plain functions of solved point positions, and their registry.

Each function takes a :class:`PointSet` (every named point as an (n, 3)
array in metres, one row per step) and returns an (n,) array in SI (m,
rad); NaN where the metric is undefined. The registry ``METRICS`` gives the
column name, unit, label and the conversion to output units; it alone
decides which columns a sweep writes and in what order. Definitions and
signs follow spec/results.md: s = +1 left, −1 right; â = unit(axle_outboard −
axle_inboard); k̂ = unit(UBJ − LBJ); WC = wheel centre, CP = contact patch.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .geometry import Geometry, unit

STEERING_AXIS_FLAT = 1e-6  # |k_z| below this: the axis never meets the ground


@dataclass
class PointSet:
    """Solved positions (m) of every named point, design positions, and the geometry.

    ``rates`` optionally holds a velocity for each point (same shapes): the
    ``d_<metric>`` functions return the metric's directional derivative
    along it, exactly (the chain rule written out, no differencing).
    """

    points: dict[str, np.ndarray]
    design: dict[str, np.ndarray]
    geometry: Geometry
    rates: dict[str, np.ndarray] | None = None

    @property
    def s(self) -> float:
        return self.geometry.sign

    def __getitem__(self, name: str) -> np.ndarray:
        return self.points[name]

    def d(self, name: str) -> np.ndarray:
        return self.rates[name]

    def spin_axis(self) -> np.ndarray:
        return unit(self["axle_outboard"] - self["axle_inboard"])

    def d_spin_axis(self) -> np.ndarray:
        return _d_unit(
            self["axle_outboard"] - self["axle_inboard"],
            self.d("axle_outboard") - self.d("axle_inboard"),
        )

    def steering_axis(self) -> np.ndarray:
        return unit(self["upper_wishbone_outboard"] - self["lower_wishbone_outboard"])

    def d_steering_axis(self) -> np.ndarray:
        return _d_unit(
            self["upper_wishbone_outboard"] - self["lower_wishbone_outboard"],
            self.d("upper_wishbone_outboard") - self.d("lower_wishbone_outboard"),
        )

    def steering_axis_on_ground(self) -> np.ndarray:
        """G = LBJ + t·K, K = UBJ − LBJ, t = (CP_z − LBJ_z)/K_z: the axis at CP height."""
        lbj, k = self["lower_wishbone_outboard"], self["upper_wishbone_outboard"]
        k = k - lbj
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (self["contact_patch_center"][:, 2] - lbj[:, 2]) / k[:, 2]
        t[np.abs(unit(k)[:, 2]) < STEERING_AXIS_FLAT] = np.nan
        return lbj + t[:, None] * k

    def d_steering_axis_on_ground(self) -> np.ndarray:
        lbj = self["lower_wishbone_outboard"]
        k = self["upper_wishbone_outboard"] - lbj
        dlbj = self.d("lower_wishbone_outboard")
        dk = self.d("upper_wishbone_outboard") - dlbj
        h = self["contact_patch_center"][:, 2] - lbj[:, 2]
        dh = self.d("contact_patch_center")[:, 2] - dlbj[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = h / k[:, 2]
            dt = (dh * k[:, 2] - h * dk[:, 2]) / k[:, 2] ** 2
        return dlbj + dt[:, None] * k + t[:, None] * dk


def _d_unit(v: np.ndarray, dv: np.ndarray) -> np.ndarray:
    """d(v/|v|) = (dv − â(â·dv))/|v|, rows."""
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    a = v / n
    return (dv - a * np.sum(a * dv, axis=-1, keepdims=True)) / n


def _d_atan2(y, x, dy, dx):
    return (x * dy - y * dx) / (x * x + y * y)


def camber(ps: PointSet) -> np.ndarray:
    """−atan2(â_z, s·â_y): negative = top of the wheel leans inboard."""
    a = ps.spin_axis()
    return -np.arctan2(a[:, 2], ps.s * a[:, 1])


def d_camber(ps: PointSet) -> np.ndarray:
    a, da = ps.spin_axis(), ps.d_spin_axis()
    return -_d_atan2(a[:, 2], ps.s * a[:, 1], da[:, 2], ps.s * da[:, 1])


def caster(ps: PointSet) -> np.ndarray:
    """atan2(−k_x, k_z): positive = top of the steering axis rearward."""
    k = ps.steering_axis()
    return np.arctan2(-k[:, 0], k[:, 2])


def d_caster(ps: PointSet) -> np.ndarray:
    k, dk = ps.steering_axis(), ps.d_steering_axis()
    return _d_atan2(-k[:, 0], k[:, 2], -dk[:, 0], dk[:, 2])


def kpi(ps: PointSet) -> np.ndarray:
    """atan2(−s·k_y, k_z): positive = top of the steering axis inboard."""
    k = ps.steering_axis()
    return np.arctan2(-ps.s * k[:, 1], k[:, 2])


def d_kpi(ps: PointSet) -> np.ndarray:
    k, dk = ps.steering_axis(), ps.d_steering_axis()
    return _d_atan2(-ps.s * k[:, 1], k[:, 2], -ps.s * dk[:, 1], dk[:, 2])


def roadwheel_angle(ps: PointSet) -> np.ndarray:
    """atan2(â_x, s·â_y), the toe: positive = toe-in, on each side."""
    a = ps.spin_axis()
    return np.arctan2(a[:, 0], ps.s * a[:, 1])


def d_roadwheel_angle(ps: PointSet) -> np.ndarray:
    a, da = ps.spin_axis(), ps.d_spin_axis()
    return _d_atan2(a[:, 0], ps.s * a[:, 1], da[:, 0], ps.s * da[:, 1])


def _ground_direction(ps: PointSet) -> tuple[np.ndarray, np.ndarray]:
    flat = np.array([1.0, 1.0, 0.0])
    return ps.spin_axis() * flat, (ps.d_spin_axis() * flat if ps.rates is not None else None)


def scrub_radius(ps: PointSet) -> np.ndarray:
    """−(G − CP)·ŵ, ŵ = unit(â_x, â_y, 0): positive = axis meets the ground inboard of CP."""
    w = unit(_ground_direction(ps)[0])
    return -np.sum((ps.steering_axis_on_ground() - ps["contact_patch_center"]) * w, axis=1)


def d_scrub_radius(ps: PointSet) -> np.ndarray:
    h, dh = _ground_direction(ps)
    w, dw = unit(h), _d_unit(h, dh)
    gap = ps.steering_axis_on_ground() - ps["contact_patch_center"]
    dgap = ps.d_steering_axis_on_ground() - ps.d("contact_patch_center")
    return -np.sum(dgap * w + gap * dw, axis=1)


def mechanical_trail(ps: PointSet) -> np.ndarray:
    """G_x − CP_x: positive = contact patch behind the axis ground point."""
    return ps.steering_axis_on_ground()[:, 0] - ps["contact_patch_center"][:, 0]


def d_mechanical_trail(ps: PointSet) -> np.ndarray:
    return ps.d_steering_axis_on_ground()[:, 0] - ps.d("contact_patch_center")[:, 0]


def wheel_travel(ps: PointSet) -> np.ndarray:
    """WC_z − WC_z,design: positive = bump."""
    return ps["wheel_center"][:, 2] - ps.design["wheel_center"][:, 2]


def d_wheel_travel(ps: PointSet) -> np.ndarray:
    return ps.d("wheel_center")[:, 2]


def half_track(ps: PointSet) -> np.ndarray:
    """|CP_y|."""
    return np.abs(ps["contact_patch_center"][:, 1])


def d_half_track(ps: PointSet) -> np.ndarray:
    return np.sign(ps["contact_patch_center"][:, 1]) * ps.d("contact_patch_center")[:, 1]


def damper_length(ps: PointSet) -> np.ndarray:
    """|strut_top − strut_bottom| (coilover)."""
    return np.linalg.norm(ps["strut_top"] - ps["strut_bottom"], axis=1)


def d_damper_length(ps: PointSet) -> np.ndarray:
    u = unit(ps["strut_top"] - ps["strut_bottom"])
    return np.sum(u * (ps.d("strut_top") - ps.d("strut_bottom")), axis=1)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.sum(a * b, axis=1, keepdims=True)


def _rocker_arms(ps: PointSet):
    """û = unit(b − a), and w, w₀ = pushrod_inboard − a now and at design."""
    a = ps["rocker_axis_a"]
    u = unit(ps["rocker_axis_b"] - a)
    w = ps["pushrod_inboard"] - a
    w0 = ps.design["pushrod_inboard"] - ps.design["rocker_axis_a"]
    return u, w, w0


def rocker_angle(ps: PointSet) -> np.ndarray:
    """s·(rotation of pushrod_inboard about rocker_axis_a→b from design, right-hand rule)."""
    u, w, w0 = _rocker_arms(ps)
    arm, arm0 = w - u * _dot(u, w), w0 - u * _dot(u, w0)  # both normal to û
    y = np.sum(u * np.cross(arm0, arm), axis=1)
    return ps.s * np.arctan2(y, np.sum(arm0 * arm, axis=1))


def d_rocker_angle(ps: PointSet) -> np.ndarray:
    u, w, w0 = _rocker_arms(ps)
    du = _d_unit(
        ps["rocker_axis_b"] - ps["rocker_axis_a"], ps.d("rocker_axis_b") - ps.d("rocker_axis_a")
    )
    dw = ps.d("pushrod_inboard") - ps.d("rocker_axis_a")
    arm, arm0 = w - u * _dot(u, w), w0 - u * _dot(u, w0)
    darm = dw - u * _dot(u, dw) - du * _dot(u, w) - u * _dot(du, w)
    darm0 = -du * _dot(u, w0) - u * _dot(du, w0)
    cross = np.cross(arm0, arm)
    y, x = np.sum(u * cross, axis=1), np.sum(arm0 * arm, axis=1)
    dy = np.sum(du * cross + u * (np.cross(darm0, arm) + np.cross(arm0, darm)), axis=1)
    dx = np.sum(darm0 * arm + arm0 * darm, axis=1)
    return ps.s * _d_atan2(y, x, dy, dx)


def _always(g: Geometry) -> bool:
    return True


@dataclass(frozen=True)
class Metric:
    name: str
    unit: str  # output unit: "deg" or "mm"
    label: str
    function: Callable[[PointSet], np.ndarray]
    derivative: Callable[[PointSet], np.ndarray]  # along PointSet.rates
    applies: Callable[[Geometry], bool] = field(default=_always)

    @property
    def scale(self) -> float:
        """SI → output unit."""
        return {"deg": 180.0 / np.pi, "mm": 1e3}[self.unit]


METRICS = (
    Metric("camber", "deg", "Camber", camber, d_camber),
    Metric("caster", "deg", "Caster", caster, d_caster),
    Metric("kpi", "deg", "Kingpin inclination", kpi, d_kpi),
    Metric(
        "roadwheel_angle", "deg", "Roadwheel angle (toe, + in)", roadwheel_angle, d_roadwheel_angle
    ),
    Metric("scrub_radius", "mm", "Scrub radius", scrub_radius, d_scrub_radius),
    Metric("mechanical_trail", "mm", "Mechanical trail", mechanical_trail, d_mechanical_trail),
    Metric("wheel_travel", "mm", "Wheel travel (+ bump)", wheel_travel, d_wheel_travel),
    Metric("half_track", "mm", "Half track", half_track, d_half_track),
    Metric(
        "damper_length",
        "mm",
        "Damper length",
        damper_length,
        d_damper_length,
        lambda g: g.spring == "coilover",
    ),
    Metric(
        "rocker_angle", "deg", "Rocker angle", rocker_angle, d_rocker_angle, lambda g: g.has_pushrod
    ),
    Metric(
        "torsion_bar_twist",
        "deg",
        "Torsion bar twist",
        rocker_angle,
        d_rocker_angle,
        lambda g: g.spring == "torsion_bar",
    ),
)
METRIC_BY_NAME = {m.name: m for m in METRICS}


def metric_columns(
    geometry: Geometry, points: dict[str, np.ndarray], design: dict[str, np.ndarray]
) -> dict[str, tuple[np.ndarray, str]]:
    """Every metric that applies to this corner, in output units: name → (values, unit)."""
    ps = PointSet(points, design, geometry)
    return {m.name: (m.function(ps) * m.scale, m.unit) for m in METRICS if m.applies(geometry)}


def point_columns(names, points: dict[str, np.ndarray]) -> dict[str, tuple[np.ndarray, str]]:
    """``<point>_x/_y/_z`` in mm for every named point."""
    return {
        f"{name}_{axis}": (points[name][:, i] * 1e3, "mm")
        for name in names
        for i, axis in enumerate("xyz")
    }


@dataclass
class Pose:
    """One solved pose in output units: metrics (deg, mm) and points (mm)."""

    q: np.ndarray
    converged: bool
    iterations: int
    max_residual: float  # mm
    metrics: dict[str, float]
    points: dict[str, np.ndarray]
