"""Packaging columns (docs/results.md, "Driveshaft" and "Travel limits"): the
driveshaft's length, plunge and joint angles, the damper's margins to its travel
limits, the bump stop's force, and per step the hard limits it is past.

Each metric takes a metrics.PointSet and runs on plain arrays and jet.Duals alike
(``[..., k]`` indexing, ``axis=-1`` reductions, ``np.where`` for a max), so the
driveshaft's exact derivative columns come as every registered metric's do; the
registry entries (``DRIVESHAFT``, ``LIMITS``) sit here beside the functions and
``metrics.METRICS`` splices them in. ``limit_exceeded`` is a text column, made from
the numbers by ``limit_columns``.

The driveshaft runs from cv_inboard (chassis) to cv_outboard (the upright's, or the
point of the spin axis ``config.driveshaft.outboard_offset`` inboard of the wheel
centre): â = unit(axle_outboard − axle_inboard), d = cv_outboard − cv_inboard.
"""

from __future__ import annotations

import numpy as np

from ..maths.jet import cross
from ..model.geometry import Geometry, unit
from .registry import BOTH, Metric

LIMIT_COLUMN = "limit_exceeded"
# the hard limits a step can be past, as limit_exceeded names them (the step is flagged)
HARD_LIMITS = ("damper_stroke_min", "damper_stroke_max", "rebound")
# the driveshaft's limits a step can be past (warnings: the step is kept as good)
SOFT_LIMITS = ("driveshaft_plunge", "cv_angle_inboard", "cv_angle_outboard")


def cv_outboard(ps, design: bool = False):
    """The outboard joint: the hardpoint, or WC − offset·â."""
    p = ps.design if design else ps.points
    if "cv_outboard" in p:
        return p["cv_outboard"]
    spin = unit(p["axle_outboard"] - p["axle_inboard"])
    return p["wheel_center"] - spin * ps.geometry.driveshaft.outboard_offset


def _shaft(ps, design: bool = False):
    """d = cv_outboard − cv_inboard (m)."""
    p = ps.design if design else ps.points
    return cv_outboard(ps, design) - p["cv_inboard"]


def _angle(a, b):
    """The angle between two lines (either sense): atan2(|a × b|, |a·b|), 0…90°."""
    sine = np.linalg.norm(cross(a, b), axis=-1)
    return np.arctan2(sine, np.abs(np.sum(a * b, axis=-1)))


def driveshaft_length(ps):
    """|cv_outboard − cv_inboard|."""
    return np.linalg.norm(_shaft(ps), axis=-1)


def driveshaft_plunge(ps):
    """length − design length: + = the shaft extended (the joints further apart)."""
    return driveshaft_length(ps) - np.linalg.norm(_shaft(ps, design=True), axis=-1)


def cv_angle_inboard(ps):
    """The angle between the shaft and the diff's output axis (config.driveshaft
    .inboard_axis, chassis frame)."""
    return _angle(_shaft(ps), ps.geometry.driveshaft.inboard_axis)


def cv_angle_outboard(ps):
    """The angle between the shaft and the wheel's spin axis â."""
    return _angle(_shaft(ps), ps.spin_axis())


def _damper(ps, design: bool = False):
    p = ps.design if design else ps.points
    return np.linalg.norm(p["strut_top"] - p["strut_bottom"], axis=-1)


def damper_margin_compression(ps):
    """L − damper_stroke min: the damper length left to its shortest (negative: past)."""
    return _damper(ps) - ps.geometry.limits.stroke[0]


def _extension_limit(ps):
    """The damper's longest length: damper_stroke max, or design + rebound, the shorter."""
    lim = ps.geometry.limits
    ends = []
    if lim.stroke is not None:
        ends.append(lim.stroke[1] + 0.0 * _damper(ps, design=True))
    if lim.rebound is not None:
        ends.append(_damper(ps, design=True) + lim.rebound)
    return ends[0] if len(ends) == 1 else np.where(ends[0] < ends[1], ends[0], ends[1])


def damper_margin_extension(ps):
    """(the longest length) − L: the extension left, to the stroke's max or the rebound
    stop, whichever comes first (negative: past)."""
    return _extension_limit(ps) - _damper(ps)


def bump_stop_force(ps):
    """rate · max(0, (L_design − L) − gap), N: the bump stop's push along the damper."""
    lim = ps.geometry.limits
    squeeze = _damper(ps, design=True) - _damper(ps) - lim.bump_stop_gap
    return np.where(squeeze > 0.0, squeeze, 0.0 * squeeze + 0.0) * lim.bump_stop_rate


def _has_shaft(g: Geometry) -> bool:
    return g.driveshaft is not None


def _limit(name: str):
    def applies(g: Geometry) -> bool:
        lim = g.limits
        if lim is None:
            return False
        if name == "stroke":
            return lim.stroke is not None
        if name == "extension":
            return lim.stroke is not None or lim.rebound is not None
        return lim.bump_stop_rate is not None

    return applies


DRIVESHAFT = (
    Metric("driveshaft_length", "mm", "Driveshaft length", driveshaft_length, _has_shaft, BOTH),
    Metric(
        "driveshaft_plunge",
        "mm",
        "Driveshaft plunge (+ extended)",
        driveshaft_plunge,
        _has_shaft,
        BOTH,
    ),
    Metric("cv_angle_inboard", "deg", "Inboard CV angle", cv_angle_inboard, _has_shaft, BOTH),
    Metric("cv_angle_outboard", "deg", "Outboard CV angle", cv_angle_outboard, _has_shaft, BOTH),
)
LIMITS = (
    Metric(
        "damper_margin_compression",
        "mm",
        "Damper compression left",
        damper_margin_compression,
        _limit("stroke"),
    ),
    Metric(
        "damper_margin_extension",
        "mm",
        "Damper extension left",
        damper_margin_extension,
        _limit("extension"),
    ),
    Metric("bump_stop_force", "N", "Bump stop force", bump_stop_force, _limit("bump_stop")),
)
PACKAGING = DRIVESHAFT + LIMITS


def limit_columns(g: Geometry, out: dict, only=None) -> dict:
    """``limit_exceeded``: per step the limits it is past, by name, several joined by
    ``+``, blank where none (and where the step has no pose): the hard ones
    (``damper_stroke_min``, ``damper_stroke_max``, ``rebound``: HARD_LIMITS) from
    ``damper_length``, then the driveshaft's (``driveshaft_plunge`` past max_plunge,
    ``cv_angle_inboard`` / ``cv_angle_outboard`` past max_cv_angle) from their columns,
    all in ``out`` (mm, deg). Nothing for a corner with none of those limits, or where
    ``only`` (a set of the columns wanted) leaves it out."""
    if only is not None and LIMIT_COLUMN not in only:
        return {}
    lim, shaft = g.limits, g.driveshaft
    checks = []  # (name, column, low, high) in the columns' units
    if lim is not None and "damper_length" in out:
        if lim.stroke is not None:
            checks.append(("damper_stroke_min", "damper_length", lim.stroke[0] * 1e3, None))
            checks.append(("damper_stroke_max", "damper_length", None, lim.stroke[1] * 1e3))
        if lim.rebound is not None:
            p = g.design_points()
            design = float(np.linalg.norm(p["strut_top"] - p["strut_bottom"]))
            checks.append(("rebound", "damper_length", None, (design + lim.rebound) * 1e3))
    if shaft is not None and shaft.max_plunge is not None:
        checks.append(("driveshaft_plunge", "driveshaft_plunge", None, shaft.max_plunge * 1e3))
    if shaft is not None and shaft.max_cv_angle is not None:
        for name in ("cv_angle_inboard", "cv_angle_outboard"):
            checks.append((name, name, None, float(np.degrees(shaft.max_cv_angle))))
    checks = [c for c in checks if c[1] in out]
    if not checks:
        return {}
    past = []
    with np.errstate(invalid="ignore"):  # a blank cell (no pose) is past nothing
        for name, column, low, high in checks:
            v = np.asarray(out[column][0], dtype=float)
            if name == "driveshaft_plunge":
                v = np.abs(v)  # plunge either way
            past.append((name, v < low if low is not None else v > high))
    n = len(past[0][1])
    text = ["+".join(name for name, hit in past if hit[i]) for i in range(n)]
    return {LIMIT_COLUMN: (np.array(text, dtype=object), "")}


def exceeded(column) -> list[set]:
    """Per step the names a ``limit_exceeded`` column's cell lists (a set each)."""
    return [set(str(c).split("+")) - {"", "nan"} for c in column]
