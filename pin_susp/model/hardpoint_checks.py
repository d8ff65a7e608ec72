"""The checks of a corner's hardpoints that their positions decide (docs/geometry.md):
parse_geometry's, and a Geometry given other hardpoints and checked the same way (a
study's variant: docs/studies.md, Speed).
"""

from __future__ import annotations

import numpy as np

from ..maths.vectors import COINCIDENT, unit
from . import packaging
from .units import MM


def check_points(hardpoints: dict, o, r) -> None:
    """parse_geometry's checks of a corner's hardpoints (m) that their positions decide,
    through ``r``; ``o``: its choices (geometry.Options, or the Geometry itself). The
    mechanism's ``prepare`` may settle some of them in place."""
    from . import mechanisms

    mech, side = mechanisms.get(o.type), o.side
    sign = 1.0 if side == "left" else -1.0
    # Chassis pickups may cross the centreline (cross-car dampers, rockers, bars);
    # what rides with the wheel must be on the wheel's side.
    for key in mech.wheel_side_points(o):
        p = hardpoints[key]
        if sign * p[1] < 0.0:
            want = "y >= 0" if side == "left" else "y <= 0"
            r.fail(
                f"hardpoints.{key}",
                f"y = {p[1] / MM:g} mm on a {side} corner (the points that ride with the "
                f"wheel have {want}; check 'side' or the sign of y)",
            )
    if np.linalg.norm(hardpoints["axle_outboard"] - hardpoints["axle_inboard"]) < COINCIDENT:
        r.fail(
            "hardpoints.axle_outboard",
            "coincides with axle_inboard: the spin axis needs two distinct points",
        )
    spin = unit(hardpoints["axle_outboard"] - hardpoints["axle_inboard"])
    if sign * spin[1] <= 0.0:
        r.fail(
            "hardpoints.axle_outboard",
            "the spin axis axle_inboard→axle_outboard points inboard or straight up/down: "
            f"axle_outboard must be outboard (toward {'+' if sign > 0 else '-'}y) of axle_inboard",
        )
    mech.prepare(hardpoints, o, r)


def checked(hardpoints: dict, g, r) -> tuple:
    """``hardpoints`` (m) — each of ``g``'s — checked as parse_geometry checks them
    (through ``r``; the mechanism may settle some of its entries): the driveshaft and
    the travel limits they give with the rest of ``g``."""
    check_points(hardpoints, g, r)
    config = g.data["config"]
    driveshaft = packaging.read_driveshaft(config, hardpoints, g.side, r)
    return driveshaft, packaging.read_limits(config, hardpoints, r)


def with_points(g, points_mm: dict[str, np.ndarray], r):
    """``g`` with other hardpoints, checked (``checked``): ``points_mm`` each of its
    hardpoints (mm, as its file gives them once in canonical form, before the mechanism
    settles any); the rest of ``g`` unchanged (a study's variant, docs/studies.md
    Speed). ``g.data`` stays the design's."""
    from dataclasses import replace

    hardpoints = {name: points_mm[name] * MM for name in g.hardpoints}
    driveshaft, limits = checked(hardpoints, g, r)
    return replace(g, hardpoints=hardpoints, driveshaft=driveshaft, limits=limits)
