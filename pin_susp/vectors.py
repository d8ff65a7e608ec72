"""Vector maths on points and directions (m), below every other module.

The geometry, the mechanisms, the metrics and the plots all normalise vectors and
call two points "the same point" within one tolerance; these live here, under all
of them, so that none needs another for its maths.
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
