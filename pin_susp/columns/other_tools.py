"""Corner metrics other tools report (docs/results.md, "Metrics other tools report"):
Lotus SHARK's kingpin offset and castor trail at the hub and its mechanical trail
normal to the steering axis, the spatial camber, OptimumK's kinematic instant centre;
and the axle's kinematic roll centre from its contact patches' velocities.

Each corner function takes a metrics.PointSet, as metrics.py's do, and runs on plain
arrays and jet.Duals alike (``[..., k]`` indexing, ``axis=-1`` reductions), so its
exact derivative columns come the same way. Its registry entries (``AT_HUB``,
``KINEMATIC``) sit here beside the functions; ``metrics.METRICS`` splices them in.

ŵ = unit(â_x, â_y, 0): the spin axis laid on the ground (outboard); ĥ = s·(ŵ_y, −ŵ_x, 0):
the wheel's heading on the ground (+x at zero toe, either side).
"""

from __future__ import annotations

import numpy as np

from ..maths.vectors import roll_centre
from ..model.geometry import unit
from .registry import BOTH, STEERING_AXIS_FLAT, Metric

X, Y, Z = 0, 1, 2
FLAT = np.array([1.0, 1.0, 0.0])


def _lateral(ps):
    """ŵ: the spin axis laid on the ground, unit, outboard."""
    return unit(ps.spin_axis() * FLAT)


def _along(ps, d, w):
    """d·ŵ (lateral, outboard) and d·ĥ (along the wheel's heading) of a vector d."""
    return d[..., X] * w[..., X] + d[..., Y] * w[..., Y], ps.s * (
        d[..., X] * w[..., Y] - d[..., Y] * w[..., X]
    )


def axis_at_hub(ps):
    """H = L + t·K, K = U − L, t = (WC_z − L_z)/K_z: the steering axis at the wheel
    centre's height; NaN without a kingpin or with a flat one."""

    def at():
        ends = ps.kingpin()
        if ends is None:
            return ps["wheel_center"] * np.nan
        lower, upper = ends
        k = upper - lower
        flat = np.abs(unit(k)[..., Z]) < STEERING_AXIS_FLAT
        kz = np.where(flat, np.nan, k[..., Z])
        t = (ps["wheel_center"][..., Z] - lower[..., Z]) / kz
        return lower + t[..., None] * k

    return ps._cached("hub_axis", at)


def kingpin_offset_at_hub(ps):
    """−(H − WC)·ŵ: the steering axis's lateral distance from the wheel centre at its
    height, in the wheel's axes; positive = the axis inboard of the wheel centre."""
    return -_along(ps, axis_at_hub(ps) - ps["wheel_center"], _lateral(ps))[0]


def caster_trail_at_hub(ps):
    """(H − WC)·ĥ: the steering axis's distance ahead of the wheel centre at its height,
    along the wheel's heading; positive = the wheel centre behind the axis (as
    mechanical_trail; Lotus' "castor trail (hub)" is its negative)."""
    return _along(ps, axis_at_hub(ps) - ps["wheel_center"], _lateral(ps))[1]


def normal_trail(ps):
    """t·k_z/√(k_h² + k_z²), t = (G − CP)·ĥ, k_h = k̂·ĥ: the contact patch's distance
    from the steering axis measured normal to it, in the wheel's side view (Lotus'
    "mechanical trail"; trail·cos(caster) at zero toe); positive = CP behind the axis."""
    w = _lateral(ps)
    trail = _along(ps, ps.steering_axis_on_ground() - ps["contact_patch_center"], w)[1]
    k = ps.steering_axis()
    kh, kz = _along(ps, k, w)[1], k[..., Z]
    return trail * kz / np.sqrt(kh * kh + kz * kz)


def camber_spatial(ps):
    """−asin(â_z) = −atan2(â_z, √(â_x² + â_y²)): the wheel plane's true inclination from
    the vertical; positive = top outboard (= camber at zero toe)."""
    a = ps.spin_axis()
    return -np.arctan2(a[..., Z], np.sqrt(a[..., X] * a[..., X] + a[..., Y] * a[..., Y]))


def kinematic_instant_center_y(ps):
    """The bump twist's front-view pole y, WC_y − v_z/ω_x (kingpin turn included)."""
    return ps._pole(X)[0]


def kinematic_instant_center_z(ps):
    """The bump twist's front-view pole z, WC_z + v_y/ω_x."""
    return ps._pole(X)[1]


AT_HUB = (
    Metric(
        "kingpin_offset_at_hub",
        "mm",
        "Kingpin offset at the hub",
        kingpin_offset_at_hub,
        drivers=BOTH,
    ),
    Metric(
        "caster_trail_at_hub", "mm", "Caster trail at the hub", caster_trail_at_hub, drivers=BOTH
    ),
    Metric("normal_trail", "mm", "Trail normal to the steering axis", normal_trail, drivers=BOTH),
    Metric("camber_spatial", "deg", "Spatial camber", camber_spatial, drivers=BOTH),
)
KINEMATIC = tuple(
    Metric(f"kinematic_instant_center_{a}", "mm", label, f, always_written=True, rates=True)
    for a, label, f in (
        ("y", "Kinematic front-view IC y", kinematic_instant_center_y),
        ("z", "Kinematic front-view IC z", kinematic_instant_center_z),
    )
)


def kinematic_roll_centre(cps: dict) -> dict:
    """``kinematic_roll_center_y``, ``_z`` (mm) of an axle: where the two sides' lines
    through the contact patch, normal to its velocity in the front view, cross.

    ``cps``: side → the contact patch as a jet.Dual (m) whose first rate is along that
    side's own wheel-centre z, the other wheel and the rack held. The line of a side is
    (P − CP)·(v_y, v_z) = 0; blank where the lines are within 1e-9 rad of parallel
    (maths.vectors.roll_centre)."""
    lines = []
    for cp in cps.values():
        p, v = cp.val, cp.der[0]
        lines.append((p[:, Y], p[:, Z], p[:, Y] - v[:, Z], p[:, Z] + v[:, Y]))
    y, z = roll_centre(lines)
    return {"kinematic_roll_center_y": (y * 1e3, "mm"), "kinematic_roll_center_z": (z * 1e3, "mm")}
