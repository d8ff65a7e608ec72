"""The rack (docs/axle.md): one body on one prismatic joint (``rack_slide``) that
carries every corner's trackrod inboard end — the one shared steering input.

Each rack-steered corner's tree has the rack; composed (compose.compose_tree) it is
one body, the first corner's. Its column is the rack's travel from design.
"""

from __future__ import annotations

import numpy as np

JOINT = "rack_slide"
INBOARD = "trackrod_inboard"  # each rack-steered corner's point the rack carries
POINT = "left_trackrod_inboard"  # where the composed rack is read: the first corner's end


def has_rack(points) -> bool:
    """Whether a composed model's points include the rack's (its corners rack-steered)."""
    return POINT in points


def travel(p: dict, d: dict) -> np.ndarray | None:
    """The rack's travel along y from design (m) at every step; None without a rack."""
    if POINT not in p:
        return None
    return p[POINT][:, 1] - d[POINT][:, 1]


def columns(travelled: np.ndarray | None) -> dict:
    """``rack_displacement`` (mm), from ``travel``'s."""
    if travelled is None:
        return {}
    return {"rack_displacement": (travelled * 1e3, "mm")}
