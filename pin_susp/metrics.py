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
    """Solved positions (m) of every named point, design positions, and the geometry."""

    points: dict[str, np.ndarray]
    design: dict[str, np.ndarray]
    geometry: Geometry

    @property
    def s(self) -> float:
        return self.geometry.sign

    def __getitem__(self, name: str) -> np.ndarray:
        return self.points[name]

    def spin_axis(self) -> np.ndarray:
        return unit(self["axle_outboard"] - self["axle_inboard"])

    def steering_axis(self) -> np.ndarray:
        return unit(self["upper_wishbone_outboard"] - self["lower_wishbone_outboard"])

    def steering_axis_on_ground(self) -> np.ndarray:
        """G: the point of the steering axis at the contact patch height."""
        lbj = self["lower_wishbone_outboard"]
        k = self.steering_axis()
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (self["contact_patch_center"][:, 2] - lbj[:, 2]) / k[:, 2]
        t[np.abs(k[:, 2]) < STEERING_AXIS_FLAT] = np.nan
        return lbj + t[:, None] * k


def camber(ps: PointSet) -> np.ndarray:
    """−atan2(â_z, s·â_y): negative = top of the wheel leans inboard."""
    a = ps.spin_axis()
    return -np.arctan2(a[:, 2], ps.s * a[:, 1])


def caster(ps: PointSet) -> np.ndarray:
    """atan2(−k_x, k_z): positive = top of the steering axis rearward."""
    k = ps.steering_axis()
    return np.arctan2(-k[:, 0], k[:, 2])


def kpi(ps: PointSet) -> np.ndarray:
    """atan2(−s·k_y, k_z): positive = top of the steering axis inboard."""
    k = ps.steering_axis()
    return np.arctan2(-ps.s * k[:, 1], k[:, 2])


def roadwheel_angle(ps: PointSet) -> np.ndarray:
    """atan2(â_x, s·â_y), the toe: positive = toe-in, on each side."""
    a = ps.spin_axis()
    return np.arctan2(a[:, 0], ps.s * a[:, 1])


def scrub_radius(ps: PointSet) -> np.ndarray:
    """−(G − CP)·ŵ, ŵ = unit(â_x, â_y, 0): positive = axis meets the ground inboard of CP."""
    a = ps.spin_axis()
    w = unit(a * np.array([1.0, 1.0, 0.0]))
    return -np.sum((ps.steering_axis_on_ground() - ps["contact_patch_center"]) * w, axis=1)


def mechanical_trail(ps: PointSet) -> np.ndarray:
    """G_x − CP_x: positive = contact patch behind the axis ground point."""
    return ps.steering_axis_on_ground()[:, 0] - ps["contact_patch_center"][:, 0]


def wheel_travel(ps: PointSet) -> np.ndarray:
    """WC_z − WC_z,design: positive = bump."""
    return ps["wheel_center"][:, 2] - ps.design["wheel_center"][:, 2]


def half_track(ps: PointSet) -> np.ndarray:
    """|CP_y|."""
    return np.abs(ps["contact_patch_center"][:, 1])


def damper_length(ps: PointSet) -> np.ndarray:
    """|strut_top − strut_bottom| (coilover)."""
    return np.linalg.norm(ps["strut_top"] - ps["strut_bottom"], axis=1)


def _always(g: Geometry) -> bool:
    return True


@dataclass(frozen=True)
class Metric:
    name: str
    unit: str  # output unit: "deg" or "mm"
    label: str
    function: Callable[[PointSet], np.ndarray]
    applies: Callable[[Geometry], bool] = field(default=_always)

    @property
    def scale(self) -> float:
        """SI → output unit."""
        return {"deg": 180.0 / np.pi, "mm": 1e3}[self.unit]


METRICS = (
    Metric("camber", "deg", "Camber", camber),
    Metric("caster", "deg", "Caster", caster),
    Metric("kpi", "deg", "Kingpin inclination", kpi),
    Metric("roadwheel_angle", "deg", "Roadwheel angle (toe, + in)", roadwheel_angle),
    Metric("scrub_radius", "mm", "Scrub radius", scrub_radius),
    Metric("mechanical_trail", "mm", "Mechanical trail", mechanical_trail),
    Metric("wheel_travel", "mm", "Wheel travel (+ bump)", wheel_travel),
    Metric("half_track", "mm", "Half track", half_track),
    Metric("damper_length", "mm", "Damper length", damper_length, lambda g: g.spring == "coilover"),
)


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
