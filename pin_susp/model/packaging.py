"""A corner's packaging inputs (docs/geometry.md, "Driveshaft" and "Travel limits"): the
driveshaft's joints ``hardpoints.cv_inboard`` / ``cv_outboard`` and
``config.driveshaft``, the damper's travel limits ``config.limits``, read and checked
(one message per problem naming the key) into :class:`Driveshaft` and :class:`Limits`
(SI: m, rad, N/m) for the Geometry.

The columns they give (driveshaft length, plunge and joint angles; the damper's
margins, the bump stop's force, the limits a step is past) are
:mod:`pin_susp.columns.packaging`'s.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import PlausibilityWarning
from ..io.yamlio import MAX_LENGTH_MM, Reader
from ..maths.vectors import COINCIDENT, direction

MM = 1e-3
CV_POINTS = ("cv_inboard", "cv_outboard")  # on the chassis (or diff), on the upright
DRIVESHAFT_KEYS = ("outboard_offset", "inboard_axis", "max_plunge", "max_cv_angle")
LIMIT_KEYS = ("damper_stroke", "bump_stop", "rebound")


@dataclass(frozen=True)
class Driveshaft:
    """``config.driveshaft`` (SI): the outboard joint's offset inboard of the wheel
    centre along the spin axis (None: ``hardpoints.cv_outboard`` is given), the diff's
    output axis (unit, chassis frame), the allowed plunge (m) and joint angle (rad)."""

    outboard_offset: float | None
    inboard_axis: np.ndarray
    max_plunge: float | None = None
    max_cv_angle: float | None = None


@dataclass(frozen=True)
class Limits:
    """``config.limits`` (SI): the damper's length range (m), the bump stop's gap (m)
    and rate (N/m), the rebound stop's extension from design (m); None: not given."""

    stroke: tuple[float, float] | None = None
    bump_stop_gap: float | None = None
    bump_stop_rate: float | None = None
    rebound: float | None = None


def cv_points(hardpoints) -> tuple[str, ...]:
    """The driveshaft's joints a file's ``hardpoints:`` gives (optional points of every
    mechanism)."""
    return tuple(n for n in CV_POINTS if isinstance(hardpoints, dict) and n in hardpoints)


def placed_points(shaft: Driveshaft | None, p: dict) -> dict:
    """The outboard joint where ``config.driveshaft.outboard_offset`` places it (not a
    hardpoint: the point of the spin axis that far inboard of the wheel centre), from
    the design points ``p`` (m); {} where cv_outboard is a hardpoint or there is no
    driveshaft."""
    if shaft is None or shaft.outboard_offset is None:
        return {}
    spin = p["axle_outboard"] - p["axle_inboard"]  # plain arrays or jet.Duals
    spin = spin / np.linalg.norm(spin, axis=-1)[..., None]
    return {"cv_outboard": p["wheel_center"] - spin * shaft.outboard_offset}


def read_driveshaft(config: dict, p: dict, side: str, r: Reader) -> Driveshaft | None:
    """The driveshaft of a corner with ``hardpoints.cv_inboard`` (None without one):
    ``p`` its hardpoints (m), ``config`` its file's ``config:``."""
    block = config.get("driveshaft")
    if "cv_inboard" not in p:
        if "cv_outboard" in p:
            r.fail("hardpoints.cv_outboard", "a driveshaft needs hardpoints.cv_inboard too")
        if block is not None:
            r.fail("config.driveshaft", "needs hardpoints.cv_inboard (the shaft's inboard joint)")
        return None
    driven, at = config.get("driven_axle"), config.get("axle_position")
    if driven is not None and at is not None and driven != at:
        r.fail(
            "hardpoints.cv_inboard",
            f"a driveshaft on a {at} corner, but config.driven_axle is {driven}: only a "
            "driven corner has one",
        )
    _check_inboard_joint(p, side, r)
    key = "config.driveshaft"
    s = r.mapping({} if block is None else block, key, optional=DRIVESHAFT_KEYS)
    offset = None
    if "cv_outboard" in p:
        if "outboard_offset" in s:
            r.fail(
                f"{key}.outboard_offset",
                "hardpoints.cv_outboard is given: the offset places it only where it is not",
            )
        sign = 1.0 if side == "left" else -1.0
        if sign * p["cv_outboard"][1] < 0.0:
            r.fail(
                "hardpoints.cv_outboard",
                f"y = {p['cv_outboard'][1] / MM:g} mm on a {side} corner: it rides with the "
                "wheel, on its side of the car",
            )
        if np.linalg.norm(p["cv_outboard"] - p["cv_inboard"]) < COINCIDENT:
            r.fail("hardpoints.cv_outboard", "coincides with cv_inboard: the shaft has no length")
    elif "outboard_offset" not in s:
        r.fail(
            f"{key}.outboard_offset",
            "missing (mm): without hardpoints.cv_outboard the outboard joint is on the spin "
            "axis this far inboard of the wheel centre",
        )
    else:
        offset = r.length(s["outboard_offset"], f"{key}.outboard_offset") * MM
    axis = np.array([0.0, 1.0, 0.0])
    if "inboard_axis" in s:
        axis = direction(r.vector(s["inboard_axis"], f"{key}.inboard_axis"))
        if axis is None:
            r.fail(f"{key}.inboard_axis", "is the zero vector (it needs a direction)")
    plunge = None if "max_plunge" not in s else _positive_length(s, key, "max_plunge", r)
    angle = None
    if "max_cv_angle" in s:
        angle = r.positive(s["max_cv_angle"], f"{key}.max_cv_angle")
        if angle >= 90.0:
            r.fail(f"{key}.max_cv_angle", f"must be below 90 deg, got {angle:g}")
        angle = np.radians(angle)
    return Driveshaft(offset, axis, plunge, angle)


def read_limits(config: dict, p: dict, r: Reader) -> Limits | None:
    """``config.limits`` of a corner (None without it): ``p`` its hardpoints (m); the
    damper is strut_top → strut_bottom."""
    if "limits" not in config:
        return None
    key = "config.limits"
    s = r.mapping(config["limits"], key, optional=LIMIT_KEYS)
    if "strut_top" not in p:
        r.fail(key, "travel limits need a damper (spring type coilover: strut_top, strut_bottom)")
    design = float(np.linalg.norm(p["strut_top"] - p["strut_bottom"]))
    stroke = None
    if "damper_stroke" in s:
        value, k = s["damper_stroke"], f"{key}.damper_stroke"
        if not isinstance(value, list | tuple) or len(value) != 2:
            r.fail(k, "expected [min, max]: the damper's shortest and longest length (mm)")
        low, high = (_positive_length(value, k, i, r, f"{k}[{i}]") for i in (0, 1))
        if low >= high:
            r.fail(k, f"min {low / MM:g} mm must be below max {high / MM:g} mm")
        if not low <= design <= high:
            r.fail(
                k,
                f"the damper's design length {design / MM:.6g} mm is outside "
                f"[{low / MM:g}, {high / MM:g}] mm",
            )
        stroke = (low, high)
    gap = rate = None
    if "bump_stop" in s:
        k = f"{key}.bump_stop"
        b = r.mapping(s["bump_stop"], k, required=("gap", "rate"))
        gap = r.number(b["gap"], f"{k}.gap", 0.0, limit=MAX_LENGTH_MM) * MM
        rate = r.positive(b["rate"], f"{k}.rate") * 1e3  # N/mm → N/m
    rebound = None if "rebound" not in s else _positive_length(s, key, "rebound", r)
    return Limits(stroke, gap, rate, rebound)


def _positive_length(s: dict, key: str, name: str, r: Reader, where: str | None = None):
    where = where or f"{key}.{name}"
    x = r.number(s[name], where, limit=MAX_LENGTH_MM)
    if x <= 0.0:
        r.fail(where, f"must be > 0 mm, got {x:g}")
    return x * MM


def mirrored_driveshaft(block):
    """An axle file's ``axle_config.driveshaft`` for its right corner: the inboard axis
    (given for the left) mirrored through y = 0; the rest as it is."""
    if not isinstance(block, dict) or "inboard_axis" not in block:
        return block
    axis = block["inboard_axis"]
    if isinstance(axis, dict) and isinstance(axis.get("y"), int | float):
        axis = axis | {"y": -axis["y"]}
    elif isinstance(axis, list) and len(axis) == 3 and isinstance(axis[1], int | float):
        axis = [axis[0], -axis[1], axis[2]]
    return block | {"inboard_axis": axis}


def _check_inboard_joint(p: dict, side: str, r: Reader) -> None:
    """cv_inboard inboard of the upright (its spindle's inner point): an error; across
    the car's centre line: a warning (an offset diff can put both outputs on one side,
    but rarely far)."""
    sign = 1.0 if side == "left" else -1.0
    y, spindle = sign * p["cv_inboard"][1], sign * p["axle_inboard"][1]
    if y >= spindle:
        r.fail(
            "hardpoints.cv_inboard",
            f"y = {p['cv_inboard'][1] / MM:g} mm is outboard of the upright (axle_inboard "
            f"at y = {p['axle_inboard'][1] / MM:g} mm): the inboard joint sits on the chassis "
            "or the diff, inboard of the wheel",
        )
    if y < -0.1:  # m: 100 mm across the centre line
        warnings.warn(
            f"{r.source}: hardpoints.cv_inboard: y = {p['cv_inboard'][1] / MM:g} mm is "
            f"{-y / MM:g} mm across the car's centre line from this {side} corner: "
            "a diff offset that far, or the wrong sign of y?",
            PlausibilityWarning,
            stacklevel=3,
        )
