"""Vector maths on points and directions (m), below every other module.

The geometry, the mechanisms, the metrics and the plots all normalise vectors and
call two points "the same point" within one tolerance; these live here, under all
of them, so that none needs another for its maths. So does the crossing of two
front-view lines (an axle's roll centre), which the axle and its drawing share.
"""

from __future__ import annotations

import numpy as np

# Anything closer than this is "the same point" for an axis or a link.
COINCIDENT = 1e-6  # m


def unit(v: np.ndarray) -> np.ndarray:
    """v / |v| along the last axis."""
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def direction(v) -> np.ndarray | None:
    """The unit vector along v, None for the zero vector; safe for any finite v
    (scaled first, so that neither 1e300 nor 1e-300 over- or underflows)."""
    v = np.asarray(v, dtype=float)
    biggest = np.max(np.abs(v))
    if not biggest > 0.0:
        return None
    v = v / biggest
    return v / np.linalg.norm(v)


def roll_centre(sides):
    """Where the lines CP→FVIC of the two sides cross (front view): each side given as
    (CP_y, CP_z, FVIC_y, FVIC_z); NaN where an FVIC is blank or the lines are
    parallel — within 1e-9 rad: closer to parallel, the crossing (thousands of km
    away) is rounding error. Plain arithmetic, so it runs on jet.Duals (its
    derivative in roll)."""
    (ly, lz, fly, flz), (ry, rz, fry, frz) = sides
    d1y, d1z, d2y, d2z = fly - ly, flz - lz, fry - ry, frz - rz
    det = d1y * d2z - d1z * d2y
    scale = np.sqrt((d1y * d1y + d1z * d1z) * (d2y * d2y + d2z * d2z))
    with np.errstate(invalid="ignore", divide="ignore"):
        det = np.where(np.abs(det) > 1e-9 * scale, det, np.nan)
        t = ((ry - ly) * d2z - (rz - lz) * d2y) / det
    return ly + t * d1y, lz + t * d1z
