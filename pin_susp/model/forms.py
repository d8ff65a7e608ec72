"""The other ways a geometry file may give the wheel and the rocker (docs/geometry.md,
"The wheel by its centre" and "A rocker by its pivot and axis"), turned into the
file's own form before it is read: the spindle points ``axle_inboard`` and
``axle_outboard`` from the wheel's centre, static camber and toe; ``rocker_axis_a`` and
``rocker_axis_b`` from ``rocker_pivot``, ``rocker_axis`` and the bearing spacing.

Each works on data in mm (pin_susp.model.units first): ``canonical_corner`` on a
corner's, ``canonical_axle`` on an axle's. What they give is what the file would have
said in the spindle-point form, so the Geometry, the URDF and everything after them
are the same whichever form a file used.
"""

from __future__ import annotations

import numpy as np

from ..maths.vectors import direction
from .units import axle_in_mm, corner_in_mm
from .wheel import CENTRE_KEYS

SPINDLE = ("axle_inboard", "axle_outboard")
SPINDLE_LENGTH = 50.0  # mm: axle_inboard → axle_outboard of a wheel given by its centre
MAX_ANGLE = 45.0  # deg: a static camber or toe beyond is not a car's (a unit slip)
BEARING_SPACING = 40.0  # mm: rocker_axis_a → rocker_axis_b about rocker_pivot, by default
ROCKER = ("rocker_pivot", "rocker_axis")
ROCKER_AB = ("rocker_axis_a", "rocker_axis_b")
PLANE = "normal_of_plane"
DAMPER_END = "strut_bottom"  # the damper's end on the rocker


def spin_axis(camber_deg: float, toe_deg: float, sign: float) -> np.ndarray:
    """The unit spin axis â (outboard) of a wheel at camber γ and toe δ (ISO: + top
    outboard, + toe-in) on the side of sign s: â ∝ (tan δ, s, −tan γ), so that
    camber = −atan2(â_z, s·â_y) and toe = atan2(â_x, s·â_y) (docs/results.md)."""
    g, d = np.radians(camber_deg), np.radians(toe_deg)
    a = np.array([np.tan(d), sign, -np.tan(g)])
    return a / np.linalg.norm(a)


def spindle_points(hp: dict, wheel, side: str, r, hp_key: str, wheel_key: str, mirror=False):
    """``hp`` with the spindle points of the wheel given by its centre (``wheel``'s
    center, static_camber, static_toe, offset: mm, deg) put in — ``hp`` itself when the
    file gives the spindle points; exactly one of the two forms. ``mirror``: the centre
    is the left wheel's, this (right) side's is its mirror image."""
    given = [k for k in CENTRE_KEYS if isinstance(wheel, dict) and k in wheel]
    spindle = [k for k in SPINDLE if k in hp]
    if given and spindle:
        r.fail(
            f"{wheel_key}.{given[0]}",
            f"given with {hp_key}.{spindle[0]}: the wheel is either by its centre "
            f"({wheel_key}.center, static_camber, static_toe) or by its spindle points "
            f"({hp_key}.axle_inboard, axle_outboard), not both",
        )
    if spindle:
        return hp
    if not given:
        r.fail(
            f"{hp_key}.axle_inboard",
            f"missing point: give the spindle points ({hp_key}.axle_inboard, axle_outboard) "
            f"or the wheel by its centre ({wheel_key}.center, static_camber, static_toe)",
        )
    for k in CENTRE_KEYS:
        if k not in wheel:
            r.fail(
                f"{wheel_key}.{k}",
                "missing key (a wheel given by its centre needs center, static_camber and "
                "static_toe)",
            )
    center = r.point(wheel["center"], f"{wheel_key}.center")
    sign = 1.0 if side == "left" else -1.0
    if mirror:
        center = center * np.array([1.0, -1.0, 1.0])
    elif sign * center[1] <= 0.0:
        r.fail(
            f"{wheel_key}.center",
            f"y = {center[1]:g} mm on a {side} corner (the wheel centre of a {side} corner "
            f"has y {'>' if sign > 0 else '<'} 0; check 'side' or the sign of y)",
        )
    angles = []
    for k in ("static_camber", "static_toe"):
        x = r.number(wheel[k], f"{wheel_key}.{k}")
        if abs(x) > MAX_ANGLE:
            r.fail(f"{wheel_key}.{k}", f"{x:g}° is beyond ±{MAX_ANGLE:g}° (degrees, at design)")
        angles.append(x)
    a = spin_axis(*angles, sign)
    outboard = center + r.length(wheel.get("offset", 0.0), f"{wheel_key}.offset") * a
    inboard = outboard - SPINDLE_LENGTH * a
    return hp | {"axle_inboard": inboard.tolist(), "axle_outboard": outboard.tolist()}


def rocker_points(hp: dict, actuation, spring, side: str, r, hp_key: str, act_key: str):
    """``hp`` with rocker_axis_a/b from rocker_pivot and rocker_axis (a direction, or
    normal_of_plane: the plane through the pivot, pushrod_inboard and strut_bottom) and
    the bearing spacing (``actuation.bearing_spacing``, mm, default 40): a/b = pivot ∓
    spacing/2 along the axis. ``hp`` itself when the file gives rocker_axis_a/b."""
    act = actuation if isinstance(actuation, dict) else {}
    given = [k for k in ROCKER if k in hp]
    ab = [k for k in ROCKER_AB if k in hp]
    spaced = "bearing_spacing" in act
    if given and ab:
        r.fail(
            f"{hp_key}.{given[0]}",
            f"given with {hp_key}.{ab[0]}: the rocker's axis is either rocker_pivot and "
            "rocker_axis or rocker_axis_a and rocker_axis_b, not both",
        )
    if spaced and act.get("type") != "pushrod_rocker":
        r.fail(f"{act_key}.bearing_spacing", "this corner has no rocker (actuation pushrod_rocker)")
    if spaced and not given:
        r.fail(
            f"{act_key}.bearing_spacing",
            "the rocker's bearings are rocker_axis_a and rocker_axis_b here: the spacing is "
            "for a rocker given by rocker_pivot and rocker_axis",
        )
    if not given or act.get("type") != "pushrod_rocker":
        return hp  # no rocker form (a rocker_pivot without a rocker: an unknown point)
    for k in ROCKER:
        if k not in hp:
            r.fail(
                f"{hp_key}.{k}",
                "missing (a rocker by its pivot needs rocker_pivot and rocker_axis)",
            )
    pivot = r.point(hp["rocker_pivot"], f"{hp_key}.rocker_pivot")
    spacing = BEARING_SPACING
    if spaced:
        spacing = r.positive(act["bearing_spacing"], f"{act_key}.bearing_spacing")
        r.length(spacing, f"{act_key}.bearing_spacing")
    key, value = f"{hp_key}.rocker_axis", hp["rocker_axis"]
    if value == PLANE:
        axis = _plane_normal(hp, pivot, side, spring, r, hp_key)
    elif isinstance(value, str):
        r.fail(key, f"expected a direction [x, y, z] or {PLANE}, got {value!r}")
    else:
        axis = direction(r.vector(value, key))
        if axis is None:
            r.fail(key, "is the zero vector (the rocker's axis needs a direction)")
    out = {k: v for k, v in hp.items() if k not in ROCKER}
    half = 0.5 * spacing * axis
    return out | {
        "rocker_axis_a": (pivot - half).tolist(),
        "rocker_axis_b": (pivot + half).tolist(),
    }


def _plane_normal(hp, pivot, side: str, spring, r, hp_key: str) -> np.ndarray:
    """s·unit((pushrod_inboard − pivot) × (strut_bottom − pivot)): mirror images on a
    left and a right corner."""
    key = f"{hp_key}.rocker_axis"
    coilover = isinstance(spring, dict) and spring.get("type") == "coilover"
    if not coilover or DAMPER_END not in hp or "pushrod_inboard" not in hp:
        r.fail(
            key,
            f"{PLANE} is the normal of the plane through rocker_pivot, pushrod_inboard and "
            "the damper's end on the rocker (strut_bottom, spring type coilover): give the "
            "axis as a direction [x, y, z]",
        )
    arm = r.point(hp["pushrod_inboard"], f"{hp_key}.pushrod_inboard") - pivot
    damper = r.point(hp[DAMPER_END], f"{hp_key}.{DAMPER_END}") - pivot
    n = np.cross(arm, damper)
    # sin of the angle between the arms below 1e-6 (or an arm of no length): no plane
    if not np.linalg.norm(n) > 1e-6 * np.linalg.norm(arm) * np.linalg.norm(damper):
        r.fail(
            key,
            f"{PLANE}: rocker_pivot, pushrod_inboard and {DAMPER_END} are on one line (or "
            "two coincide), so they span no plane: give the axis as a direction [x, y, z]",
        )
    return (1.0 if side == "left" else -1.0) * direction(n)


def canonical_corner(data: dict, r) -> dict:
    """A corner file's data in mm and N with its spindle points and rocker_axis_a/b."""
    data = corner_in_mm(data, r)
    hp = data.get("hardpoints")
    config = data.get("config")
    if not isinstance(hp, dict) or not isinstance(config, dict):
        return data  # the reader names what is wrong
    side = r.choice(data.get("side", "left"), "side", ("left", "right"))
    wheel = config.get("wheel")
    out = spindle_points(hp, wheel, side, r, "hardpoints", "config.wheel")
    actuation, spring = data.get("actuation", {}), data.get("spring", {})
    out = rocker_points(out, actuation, spring, side, r, "hardpoints", "actuation")
    if out is hp:
        return data
    data = data | {"hardpoints": out}
    if "wheel" in config:
        data["config"] = config | {"wheel": _without(wheel, CENTRE_KEYS)}
    if "actuation" in data:
        data["actuation"] = _without(actuation, ("bearing_spacing",))
    return data


def canonical_axle(data: dict, r) -> dict:
    """An axle file's data in mm and N with each side's spindle points and rocker axis
    (``axle_config.wheel``'s centre is the left wheel's, the right's its mirror)."""
    data = axle_in_mm(data, r)
    hp, config = data.get("hardpoints"), data.get("axle_config")
    if not isinstance(hp, dict) or not isinstance(config, dict):
        return data
    wheel = config.get("wheel")
    actuation, spring = config.get("actuation", {}), config.get("spring", {})
    out = dict(hp)
    for side in ("left", "right"):
        if not isinstance(hp.get(side), dict):
            continue
        key, mirror = f"hardpoints.{side}", side == "right"
        points = spindle_points(hp[side], wheel, side, r, key, "axle_config.wheel", mirror)
        out[side] = rocker_points(points, actuation, spring, side, r, key, "axle_config.actuation")
    if all(out.get(s) is hp.get(s) for s in ("left", "right")):
        return data
    config = dict(config)
    if "wheel" in config:
        config["wheel"] = _without(wheel, CENTRE_KEYS)
    if "actuation" in config:
        config["actuation"] = _without(actuation, ("bearing_spacing",))
    return data | {"hardpoints": out, "axle_config": config}


def _without(block, keys) -> dict:
    return {k: v for k, v in block.items() if k not in keys} if isinstance(block, dict) else block
