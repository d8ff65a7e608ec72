"""Corner metrics: plain functions of solved point positions, and their registry.

Each function takes a :class:`PointSet` (every named point as an (n, 3) array in
metres, one row per step) and returns an (n,) array in SI (m, rad); NaN where the
metric is undefined. The same code runs on :class:`~pin_susp.maths.jet.Dual` points
and then also returns exact derivatives (along the motion, or with respect to a
hardpoint): so it indexes with ``[..., k]`` and reduces over ``axis=-1``.

The registry ``METRICS`` gives each column's name, unit, label, the conversion to
output units and the drivers it has derivative columns for; it alone decides which
columns a sweep writes and in what order (an entry is a registry.Metric; the columns
other tools report are other_tools.py's, the packaging ones packaging.py's).

Why one module of ~700 lines: the registry and the functions it names are read together
(each entry next to the function whose column it declares, in the CSV's order), and the
instant-centre and anti-geometry functions share the same few point helpers; split by
metric, a column's declaration would sit apart from its formula.
Definitions and signs follow docs/results.md: s = +1 left, −1 right; â =
unit(axle_outboard − axle_inboard); k̂ = unit(UBJ − LBJ); WC = wheel centre,
CP = contact patch.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..maths.jet import Dual, cross, value
from ..maths.jet import rate as jet_rate
from ..model.geometry import Geometry, unit
from . import other_tools, packaging
from .registry import BOTH, HUB_Z, RACK, STEERING_AXIS_FLAT, Metric  # noqa: F401 (as they were)

PARALLEL_PLANES = 1e-12  # |n₁ × n₂|² below this (unit normals): no instant axis
TOE_LINK = "toe_link_length"  # steers a toe-link corner (no derivative columns)
X, Y, Z = 0, 1, 2
EYE = np.eye(3)


@dataclass
class PointSet:
    """Solved positions (m) of every named point, design positions, and the geometry."""

    points: dict
    design: dict
    geometry: Geometry
    cache: dict = field(default_factory=dict, repr=False)

    def _cached(self, key, compute):
        """Shared constructions (axes, instant centres) are built once per point set."""
        if key not in self.cache:
            self.cache[key] = compute()
        return self.cache[key]

    @property
    def s(self) -> float:
        return self.geometry.sign

    def __getitem__(self, name: str):
        return self.points[name]

    def spin_axis(self):
        return self._cached("spin", lambda: unit(self["axle_outboard"] - self["axle_inboard"]))

    def kingpin(self):
        """(lower, upper) points of the steering axis (the mechanism's), or None."""
        return self._cached("kingpin", lambda: self.geometry.mechanism.kingpin(self))

    def _undefined(self):
        """NaN shaped like a point (its rates NaN too): for axes a mechanism lacks."""
        return self["wheel_center"] * np.nan

    def steering_axis(self):
        """k̂ = unit(upper − lower) of the kingpin; NaN without one (a trailing arm)."""

        def axis():
            ends = self.kingpin()
            return self._undefined() if ends is None else unit(ends[1] - ends[0])

        return self._cached("steer", axis)

    def steering_axis_on_ground(self):
        """G = L + t·K, K = U − L, t = (CP_z − L_z)/K_z: the axis at CP height."""
        return self._cached("ground", self._steering_axis_on_ground)

    def _steering_axis_on_ground(self):
        ends = self.kingpin()
        if ends is None:
            return self._undefined()
        lower, upper = ends
        k = upper - lower
        flat = np.abs(unit(k)[..., Z]) < STEERING_AXIS_FLAT
        kz = np.where(flat, np.nan, k[..., Z])
        t = (self["contact_patch_center"][..., Z] - lower[..., Z]) / kz
        return lower + t[..., None] * k

    def instant_axis_point(self, axis: int):
        """Where the instant axis crosses the plane through WC normal to ``axis`` (Y:
        side view, X: front view); NaN where there is none.

        From the mechanism's two planes when it names them (the wishbone planes),
        solved as two plane equations in the two other coordinates, relative to WC
        (Cramer's rule; the determinant is a component of n₁ × n₂), so a
        near-parallel pair gives a large but accurate point. Otherwise from the
        upright's bump twist: the point of that plane whose velocity has no
        component in it (the front- or side-view pole).
        """
        return self._cached(("ic", axis), lambda: self._instant_axis_point(axis))

    def _instant_axis_point(self, axis: int):
        planes = self.geometry.mechanism.instant_planes(self)
        if planes is None:
            return self._pole(axis)
        wc = self["wheel_center"]
        (n1, p1), (n2, p2) = planes
        d1, d2 = np.sum(n1 * (p1 - wc), axis=-1), np.sum(n2 * (p2 - wc), axis=-1)
        parallel = np.sum(np.cross(n1, n2) ** 2, axis=-1) < PARALLEL_PLANES
        a, b = (Y, Z) if axis == X else (X, Z)
        det = n1[..., a] * n2[..., b] - n1[..., b] * n2[..., a]
        det = np.where(parallel | ~(np.abs(det) > 0.0), np.nan, det)
        u = (d1 * n2[..., b] - d2 * n1[..., b]) / det
        v = (n1[..., a] * d2 - n2[..., a] * d1) / det
        return u + wc[..., a], v + wc[..., b]

    def twist(self, driver: int):
        """The wheel body's twist along a driver (0: hub z, 1: the rack or the toe
        link's length): (ω, v at WC).

        ω from the rates of the mechanism's upright points (a rigid body:
        v_i − v_c = ω × (p_i − p_c), solved in the least-squares sense with the
        3×3 matrix M = Σ(|r|²I − r rᵀ) inverted by its adjugate, so that it runs
        on jet.Duals); NaN without rates.
        """
        return self._cached(("twist", driver), lambda: self._twist(driver))

    def _twist(self, driver: int):
        names = self.geometry.mechanism.upright_points(self.geometry)
        pts = [self[n] for n in names]
        first = pts[0]
        if isinstance(first, Dual) and not isinstance(first.val, Dual):
            # a sweep's points: the rates' own rates are not known (NaN), so the twist's
            # are NaN too — computed on the plain values (the same numbers, half the work)
            rates = first.der.shape[0]
            vel = [jet_rate(p, driver).val for p in pts]
            wc = self["wheel_center"].val
            unknown = np.full((rates, *np.shape(wc)), np.nan)
            w, v_wc = _rigid_twist([p.val for p in pts], vel, wc)
            return Dual(w, unknown), Dual(v_wc, unknown)
        vel = [jet_rate(p, driver) for p in pts]
        return _rigid_twist(pts, vel, self["wheel_center"])

    def _pole(self, axis: int):
        """Front view (axis X): FVIC = (WC_y − v_z/ω_x, WC_z + v_y/ω_x); side view:
        SVIC = (WC_x + v_z/ω_y, WC_z − v_x/ω_y), with the bump twist (ω, v at WC)."""
        w, v = self.twist(0)
        wc = self["wheel_center"]
        ww = np.sum(w * w, axis=-1)
        # ω (nearly) in the view's plane: the pole is at infinity (as for parallel planes)
        c = w[..., axis]
        c = np.where(c * c < PARALLEL_PLANES * ww, np.nan, c)
        if axis == X:
            return wc[..., Y] - v[..., Z] / c, wc[..., Z] + v[..., Y] / c
        return wc[..., X] + v[..., Z] / c, wc[..., Z] - v[..., X] / c

    def steer_screw(self):
        """The steer screw axis: unit direction (upward), a point, and the pitch (m/rad),
        from the upright's twist along the steering driver."""

        def screw():
            w, v_wc = self.twist(1)
            v0 = v_wc - np.cross(w, self["wheel_center"])  # the body point at the origin
            ww = np.sum(w * w, axis=-1)
            up = np.where(w[..., Z] < 0.0, -1.0, 1.0)[..., None]
            k = unit(w) * up
            return k, np.cross(w, v0) / ww[..., None], np.sum(w * v0, axis=-1) / ww

        return self._cached("screw", screw)


def _rigid_twist(pts: list, vel: list, wc):
    """A rigid body's twist (ω, v at WC) from its points and their velocities, in the
    least-squares sense: v_i − v_c = ω × (p_i − p_c), with the 3×3 matrix
    M = Σ(|r|²I − r rᵀ) inverted by its adjugate (plain arrays or jet.Duals alike)."""
    c = sum(pts[1:], pts[0]) * (1.0 / len(pts))
    vc = sum(vel[1:], vel[0]) * (1.0 / len(vel))
    m = [0.0, 0.0, 0.0]  # columns of M
    b = 0.0
    for p, v in zip(pts, vel, strict=True):
        r = p - c
        rr = np.sum(r * r, axis=-1)[..., None]
        for j in range(3):
            m[j] = m[j] + rr * EYE[j] - r * r[..., j][..., None]
        b = b + cross(r, v - vc)
    rows = (cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1]))
    det = np.sum(m[0] * rows[0], axis=-1)[..., None]
    w = sum(np.sum(rows[j] * b, axis=-1)[..., None] * EYE[j] for j in range(3)) / det
    v_wc = vc + cross(w, wc - c)
    return w, v_wc


def camber(ps: PointSet):
    """−atan2(â_z, s·â_y): negative = top of the wheel leans inboard."""
    a = ps.spin_axis()
    return -np.arctan2(a[..., Z], ps.s * a[..., Y])


def caster(ps: PointSet):
    """atan2(−k_x, k_z): positive = top of the steering axis rearward."""
    k = ps.steering_axis()
    return np.arctan2(-k[..., X], k[..., Z])


def kpi(ps: PointSet):
    """atan2(−s·k_y, k_z): positive = top of the steering axis inboard."""
    k = ps.steering_axis()
    return np.arctan2(-ps.s * k[..., Y], k[..., Z])


def roadwheel_angle(ps: PointSet):
    """atan2(â_x, s·â_y), the toe: positive = toe-in, on each side."""
    a = ps.spin_axis()
    return np.arctan2(a[..., X], ps.s * a[..., Y])


def scrub_radius(ps: PointSet):
    """−(G − CP)·ŵ, ŵ = unit(â_x, â_y, 0): positive = axis meets the ground inboard of CP."""
    w = unit(ps.spin_axis() * np.array([1.0, 1.0, 0.0]))
    return -np.sum((ps.steering_axis_on_ground() - ps["contact_patch_center"]) * w, axis=-1)


def mechanical_trail(ps: PointSet):
    """G_x − CP_x: positive = contact patch behind the axis ground point."""
    return ps.steering_axis_on_ground()[..., X] - ps["contact_patch_center"][..., X]


def trail_in_wheel_axes(ps: PointSet):
    """(G − CP)·ĥ, ĥ = s·(ŵ_y, −ŵ_x, 0) the wheel's heading on the ground (ŵ as for the
    scrub radius; ĥ = +x at zero toe): the trail along the wheel's own heading when
    steered, positive = contact patch behind the axis ground point."""
    w = unit(ps.spin_axis() * np.array([1.0, 1.0, 0.0]))
    d = ps.steering_axis_on_ground() - ps["contact_patch_center"]
    return ps.s * (d[..., X] * w[..., Y] - d[..., Y] * w[..., X])


def wheel_travel(ps: PointSet):
    """WC_z − WC_z,design: positive = bump."""
    return ps["wheel_center"][..., Z] - ps.design["wheel_center"][..., Z]


def half_track(ps: PointSet):
    """|CP_y| = s·CP_y."""
    return ps.s * ps["contact_patch_center"][..., Y]


def wheel_center_x(ps: PointSet):
    """WC_x: fore-aft wheel-centre motion (its derivative is the wheel recession)."""
    return ps["wheel_center"][..., X]


def damper_length(ps: PointSet):
    """|strut_top − strut_bottom| (coilover)."""
    return np.linalg.norm(ps["strut_top"] - ps["strut_bottom"], axis=-1)


def rocker_angle(ps: PointSet):
    """s·(rotation of pushrod_inboard about rocker_axis_a→b from design, right-hand rule)."""
    u = unit(ps["rocker_axis_b"] - ps["rocker_axis_a"])
    w = ps["pushrod_inboard"] - ps["rocker_axis_a"]
    w0 = ps.design["pushrod_inboard"] - ps.design["rocker_axis_a"]
    arm = w - u * np.sum(u * w, axis=-1, keepdims=True)  # both normal to û
    arm0 = w0 - u * np.sum(u * w0, axis=-1, keepdims=True)
    y = np.sum(u * np.cross(arm0, arm), axis=-1)
    return ps.s * np.arctan2(y, np.sum(arm0 * arm, axis=-1))


def rocker_transmission_angle(ps: PointSet):
    """Angle between the rocker arm (axis → pushrod_inboard) and the pushrod
    (pushrod_inboard → pushrod_outboard), both seen along the rocker axis: 90° is
    ideal; near 0° or 180° the rocker goes over centre (its motion ratio flips)."""
    u = unit(ps["rocker_axis_b"] - ps["rocker_axis_a"])
    arm = ps["pushrod_inboard"] - ps["rocker_axis_a"]
    rod = ps["pushrod_outboard"] - ps["pushrod_inboard"]
    arm = arm - u * np.sum(u * arm, axis=-1, keepdims=True)
    rod = rod - u * np.sum(u * rod, axis=-1, keepdims=True)
    sine = np.sum(u * np.cross(arm, rod), axis=-1)
    return np.abs(np.arctan2(sine, np.sum(arm * rod, axis=-1)))


def rack_displacement(ps: PointSet):
    """TRI_y − TRI_y,design: rack travel from its design (centre) position, + = left."""
    return ps["trackrod_inboard"][..., Y] - ps.design["trackrod_inboard"][..., Y]


def isa_caster(ps: PointSet):
    """The steer screw axis's caster: atan2(−k_x, k_z), k̂ upward."""
    k = ps.steer_screw()[0]
    return np.arctan2(-k[..., X], k[..., Z])


def isa_kpi(ps: PointSet):
    """The steer screw axis's inclination: atan2(−s·k_y, k_z)."""
    k = ps.steer_screw()[0]
    return np.arctan2(-ps.s * k[..., Y], k[..., Z])


def isa_pitch(ps: PointSet):
    """s·ω·v₀/|ω|² (mm/rad in the CSV): the steer screw's travel along its axis per
    radian about it; positive = right-handed on a left corner (its mirror image on
    a right one), so both sides of a symmetric car read the same."""
    return ps.s * ps.steer_screw()[2]


def svic_x(ps: PointSet):
    """Side-view instant centre x: instant axis ∩ plane y = WC_y."""
    return ps.instant_axis_point(Y)[0]


def svic_z(ps: PointSet):
    """Side-view instant centre z."""
    return ps.instant_axis_point(Y)[1]


def fvic_y(ps: PointSet):
    """Front-view instant centre y: instant axis ∩ plane x = WC_x."""
    return ps.instant_axis_point(X)[0]


def fvic_z(ps: PointSet):
    """Front-view instant centre z."""
    return ps.instant_axis_point(X)[1]


def svsa_length(ps: PointSet):
    """SVIC_x − CP_x: positive = instant centre ahead of the contact patch."""
    return svic_x(ps) - ps["contact_patch_center"][..., X]


def fvsa_length(ps: PointSet):
    """√(dy² + dz²)·(−s·sign(dy)), d = FVIC − CP: positive = FVIC inboard of the CP."""
    y, z = ps.instant_axis_point(X)
    cp = ps["contact_patch_center"]
    dy, dz = y - cp[..., Y], z - cp[..., Z]
    return np.sqrt(dy * dy + dz * dz) * (-ps.s * np.sign(dy))


def svsa_angle(ps: PointSet):
    """atan((SVIC_z − CP_z)/(SVIC_x − CP_x)), in (−90°, 90°)."""
    x, z = ps.instant_axis_point(Y)
    cp = ps["contact_patch_center"]
    return np.arctan((z - cp[..., Z]) / (x - cp[..., X]))


def _wheelbase_over_height(ps: PointSet):
    """L/h, h = CG_z − CP_z."""
    g = ps.geometry
    return g.wheelbase / (g.cg_position[Z] - ps["contact_patch_center"][..., Z])


def anti_dive(ps: PointSet):
    """Front axle: 100·fbb·(L/h)·(SVIC_z − CP_z)/(CP_x − SVIC_x)."""
    x, z = ps.instant_axis_point(Y)
    cp = ps["contact_patch_center"]
    tan = (z - cp[..., Z]) / (cp[..., X] - x)
    return 100.0 * ps.geometry.front_brake_bias * _wheelbase_over_height(ps) * tan


def anti_lift(ps: PointSet):
    """Rear axle: 100·(1 − fbb)·(L/h)·(SVIC_z − CP_z)/(SVIC_x − CP_x)."""
    x, z = ps.instant_axis_point(Y)
    cp = ps["contact_patch_center"]
    tan = (z - cp[..., Z]) / (x - cp[..., X])
    return 100.0 * (1.0 - ps.geometry.front_brake_bias) * _wheelbase_over_height(ps) * tan


def anti_squat(ps: PointSet):
    """Driven axle: 100·(L/h)·tanθ, tanθ = (SVIC_z − WC_z)/(WC_x − SVIC_x) front,
    (SVIC_z − WC_z)/(SVIC_x − WC_x) rear."""
    x, z = ps.instant_axis_point(Y)
    wc = ps["wheel_center"]
    run = wc[..., X] - x if ps.geometry.axle_position == "front" else x - wc[..., X]
    return 100.0 * _wheelbase_over_height(ps) * (z - wc[..., Z]) / run


def _rack(g: Geometry) -> bool:
    return g.steering == "rack"


def _steered(g: Geometry) -> bool:
    """The steer screw axis: along the rack, or the fixed toe link's length."""
    return bool(g.steering_points)


def _anti(axle: str, needs_bias: bool):
    def applies(g: Geometry) -> bool:
        have = g.axle_position == axle and g.wheelbase is not None and g.cg_position is not None
        if needs_bias:
            return have and g.front_brake_bias is not None
        return have and g.driven_axle == axle

    return applies


def _anti_squat_applies(g: Geometry) -> bool:
    return g.axle_position is not None and _anti(g.axle_position, False)(g)


METRICS = (
    Metric("camber", "deg", "Camber", camber, drivers=BOTH, plausible=(-10.0, 10.0)),
    Metric("caster", "deg", "Caster", caster, drivers=BOTH, plausible=(-10.0, 20.0)),
    Metric("kpi", "deg", "Kingpin inclination", kpi, drivers=BOTH, plausible=(-10.0, 35.0)),
    Metric(
        "roadwheel_angle",
        "deg",
        "Roadwheel angle (toe, + in)",
        roadwheel_angle,
        drivers=BOTH,
        plausible=(-10.0, 10.0),
    ),
    Metric("scrub_radius", "mm", "Scrub radius", scrub_radius, drivers=BOTH, plausible=(-150, 150)),
    Metric(
        "mechanical_trail",
        "mm",
        "Mechanical trail",
        mechanical_trail,
        drivers=BOTH,
        plausible=(-100.0, 150.0),
    ),
    Metric("wheel_travel", "mm", "Wheel travel (+ bump)", wheel_travel),
    Metric("half_track", "mm", "Half track", half_track, drivers=BOTH, plausible=(250, 1300)),
    # trail and scrub both along the wheel's own heading (scrub_radius already is)
    Metric(
        "trail_in_wheel_axes",
        "mm",
        "Mechanical trail along the wheel's heading",
        trail_in_wheel_axes,
        drivers=BOTH,
    ),
    Metric(
        "scrub_in_wheel_axes",
        "mm",
        "Scrub radius in the wheel's axes (= scrub_radius)",
        scrub_radius,
        drivers=BOTH,
    ),
    *other_tools.AT_HUB,  # Lotus' offset and trails at the hub, spatial camber
    Metric(
        "wheel_center_x", "mm", "Wheel centre x", wheel_center_x, drivers=(HUB_Z,), written=False
    ),
    Metric(
        "damper_length",
        "mm",
        "Damper length",
        damper_length,
        lambda g: "strut_top" in g.hardpoints,
        drivers=(HUB_Z,),
    ),
    Metric(
        "rocker_angle",
        "deg",
        "Rocker angle",
        rocker_angle,
        lambda g: g.has_pushrod,
        drivers=(HUB_Z,),
    ),
    Metric(
        "torsion_bar_twist",
        "deg",
        "Torsion bar twist",
        rocker_angle,
        lambda g: g.spring == "torsion_bar",
        drivers=(HUB_Z,),
    ),
    Metric(
        "rocker_transmission_angle",
        "deg",
        "Rocker transmission angle",
        rocker_transmission_angle,
        lambda g: g.has_pushrod,
    ),
    Metric("rack_displacement", "mm", "Rack travel from centre", rack_displacement, _rack),
    Metric(
        "isa_caster",
        "deg",
        "Steer screw axis caster",
        isa_caster,
        _steered,
        always_written=True,
        rates=True,
    ),
    Metric(
        "isa_kpi",
        "deg",
        "Steer screw axis inclination",
        isa_kpi,
        _steered,
        always_written=True,
        rates=True,
    ),
    Metric(
        "isa_pitch",
        "mm/rad",
        "Steer screw pitch",
        isa_pitch,
        _steered,
        always_written=True,
        rates=True,
    ),
    Metric("svic_x", "mm", "Side-view IC x", svic_x, always_written=True),
    Metric("svic_z", "mm", "Side-view IC z", svic_z, always_written=True),
    Metric("fvic_y", "mm", "Front-view IC y", fvic_y, always_written=True),
    Metric("fvic_z", "mm", "Front-view IC z", fvic_z, always_written=True),
    *other_tools.KINEMATIC,  # the bump twist's front-view pole (OptimumK's kinematic IC)
    Metric("svsa_length", "mm", "Side-view swing arm length", svsa_length, always_written=True),
    Metric("fvsa_length", "mm", "Front-view swing arm length", fvsa_length, always_written=True),
    Metric("svsa_angle", "deg", "Side-view swing arm angle", svsa_angle, always_written=True),
    Metric(
        "anti_dive",
        "%",
        "Anti-dive",
        anti_dive,
        _anti("front", True),
        always_written=True,
        needs="config.axle_position: front, front_brake_bias, cg_position and wheelbase",
    ),
    Metric(
        "anti_lift",
        "%",
        "Anti-lift",
        anti_lift,
        _anti("rear", True),
        always_written=True,
        needs="config.axle_position: rear, front_brake_bias, cg_position and wheelbase",
    ),
    Metric(
        "anti_squat",
        "%",
        "Anti-squat",
        anti_squat,
        _anti_squat_applies,
        always_written=True,
        needs="config.axle_position, driven_axle (the same axle), cg_position and wheelbase",
    ),
    *packaging.PACKAGING,  # the driveshaft; the damper's travel limits, its bump stop
)
METRIC_BY_NAME = {m.name: m for m in METRICS}
# The standard kinematics set: the setup sheet's static values, the report's first panels.
STANDARD = (
    "camber",
    "roadwheel_angle",
    "caster",
    "kpi",
    "scrub_radius",
    "mechanical_trail",
    "half_track",
)


@dataclass(frozen=True)
class Derivative:
    """A derivative column: d metric / d driver, per mm of hub z or rack travel."""

    metric: Metric
    driver: str

    @property
    def name(self) -> str:
        return f"deriv_{self.metric.name}_wrt_{self.driver}"

    @property
    def unit(self) -> str:
        return f"{self.metric.unit}/mm"

    @property
    def label(self) -> str:
        return f"d {self.metric.label} / d {'hub z' if self.driver == HUB_Z else 'rack'}"

    @property
    def scale(self) -> float:
        """d(SI)/d(m) → output unit per mm."""
        return self.metric.scale * 1e-3


def derivative_columns(g: Geometry) -> list[Derivative]:
    """Derivative columns of this corner: every applicable metric × its drivers."""
    drivers = (HUB_Z, RACK) if g.steering == "rack" else (HUB_Z,)
    return [Derivative(m, d) for d in drivers for m in METRICS if d in m.drivers and m.applies(g)]


def metric_columns(
    geometry: Geometry, points: dict, design: dict, spring_sense: float = 1.0, only=None
) -> dict:
    """Metric, derivative and motion-ratio columns in output units: name → (values, unit).

    ``points`` are plain (n, 3) arrays, or jet.Duals whose rates have one leading
    axis per driver of ``derivative_columns(geometry)`` (hub z, then rack); with
    Duals the derivative columns are included.

    ``motion_ratio`` is the spring's deflection per mm of wheel travel, positive
    when bump loads the spring as it does at the design state: a coilover's
    compression (−d damper_length/d hub z, mm/mm), a torsion bar's wind-up
    (``spring_sense``·d twist/d hub z, deg/mm, where ``spring_sense`` = ±1 is the
    sign of d twist/d hub z at design, so the rocker axis's a→b order does not
    matter). A sign change through a sweep means the rocker went over centre.

    ``only``: a set of column names to compute (and what they need), the rest left
    out; None for every column.
    """
    ps = PointSet(points, design, geometry)
    n = np.shape(value(points["wheel_center"]))[:-1]
    derivatives = derivative_columns(geometry)
    if only is not None:  # what the wanted columns need: their metrics, the spring's rate
        only = set(only)
        if "motion_ratio" in only:
            only |= {"deriv_damper_length_wrt_hub_z", "deriv_torsion_bar_twist_wrt_hub_z"}
        derivatives = [d for d in derivatives if d.name in only]
        needed = only | {d.metric.name for d in derivatives}
    with np.errstate(invalid="ignore", divide="ignore"):  # undefined → NaN → empty cell
        values = {
            m.name: m.function(ps) * m.scale
            for m in METRICS
            if m.applies(geometry) and (only is None or m.name in needed)
        }
    out = {}
    for m in METRICS:
        if m.name in values and m.written:
            out[m.name] = (value(values[m.name]), m.unit)
        elif m.always_written and (only is None or m.name in only):
            out[m.name] = (np.full(n, np.nan), m.unit)
    out |= packaging.limit_columns(geometry, out, only)  # the limits a step is past
    if not isinstance(points["wheel_center"], Dual):
        return out
    drivers = (HUB_Z, RACK) if geometry.steering == "rack" else (HUB_Z,)
    for d in derivatives:
        rates = values[d.metric.name].der[drivers.index(d.driver)]
        out[d.name] = (rates * 1e-3, d.unit)
    spring = {"coilover": "deriv_damper_length_wrt_hub_z"}.get(geometry.spring)
    if geometry.spring == "torsion_bar":
        spring = "deriv_torsion_bar_twist_wrt_hub_z"
    if spring in out:
        coilover = geometry.spring == "coilover"  # its compression; a bar's wind-up
        sense = -1.0 if coilover else spring_sense
        out["motion_ratio"] = (sense * out[spring][0], "mm/mm" if coilover else "deg/mm")
    return out


def point_columns(names, points: dict[str, np.ndarray]) -> dict[str, tuple[np.ndarray, str]]:
    """``<point>_x/_y/_z`` in mm for every named point."""
    return {
        f"{name}_{axis}": (points[name][:, i] * 1e3, "mm")
        for name in names
        for i, axis in enumerate("xyz")
    }


@dataclass
class Pose:
    """One solved pose in output units: metrics (deg, mm), points (mm), derivatives."""

    q: np.ndarray
    converged: bool
    iterations: int
    max_residual: float  # mm
    metrics: dict[str, float]
    points: dict[str, np.ndarray]
    derivatives: dict[str, float] = field(default_factory=dict)
