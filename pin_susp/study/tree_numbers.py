"""A corner variant's tree numbers straight from its design points, every variant of a
batch at once (docs/studies.md, Speed).

Each number a corner's tree is built from is one of its design points, the unit
vector from one design point to another, or a constant: a joint's origin is a
hardpoint, a revolute joint's axis the unit vector from one pivot point to the other,
a ball's axes and the rack's are the world's. Which each number is, is read off the
trees of the design and of two probe variants (together.py). Where every number is
found so, a batch's numbers (its frames' positions, its joints' origins and axes at
design) are gathered from its variants' design points — their hardpoints checked as a
file's are, the wheel's points derived from them — with no tree built per variant;
else each variant's tree is built and read.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import permutations

import numpy as np

from ..maths.vectors import unit

# m (and for unit vectors): a number is a formula's where it is that close in every
# sample (the probes' points are far further apart than this)
MATCH = 1e-14


def design_points_many(g, hardpoints: dict) -> dict:
    """Each design point (name → (n, 3)) of n variants of ``g``, from their hardpoints
    (name → (n, 3), in m: Geometry.design_points on arrays of points)."""
    return replace(g, hardpoints=hardpoints).design_points()


def _axis(P: dict, a: str, b: str) -> np.ndarray:
    """The unit vector a → b, normalised again as Together.numbers normalises axes."""
    u = unit(P[b] - P[a])
    return u / np.linalg.norm(u, axis=-1, keepdims=True)


class TreeNumbers:
    """Where each of a tree's numbers comes from: per read frame and per joint origin a
    design point's name or a constant (3,); per joint axis a constant or a pair of
    design points' names (its unit vector)."""

    def __init__(self, frames: list, origins: list, axes: list):
        self.frames, self.origins, self.axes = frames, origins, axes

    @classmethod
    def found(cls, P: dict, numbers: list[tuple]) -> TreeNumbers | None:
        """From samples (the design, the probes): ``P`` their design points (name →
        (samples, 3)), ``numbers`` each one's (E, J, A) read from its tree; None where
        some number is none of those."""
        names = list(P)
        E, J, A = (np.array([x[k] for x in numbers]) for k in range(3))

        def same(x, y) -> bool:
            return bool(np.allclose(x, y, rtol=0.0, atol=MATCH))

        def source(rows):
            named = next((n for n in names if same(P[n], rows)), None)
            if named is not None:
                return named
            return rows[0].copy() if same(rows, rows[0]) else None

        frames = [source(E[:, c]) for c in range(E.shape[1])]
        origins = [np.zeros(3)] + [source(J[:, j]) for j in range(1, J.shape[1])]
        axes = [np.zeros(3)]
        for j in range(1, A.shape[1]):
            rows = A[:, j]
            if same(rows, rows[0]):
                axes.append(rows[0].copy())
                continue
            pair = next((ab for ab in permutations(names, 2) if same(_axis(P, *ab), rows)), None)
            axes.append(pair)
        if any(x is None for x in (*frames, *origins, *axes)):
            return None
        return cls(frames, origins, axes)

    def __call__(self, P: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(E (n, F, 3), J (n, nj, 3), A (n, nj, 3)) of n variants, their design points
        ``P`` (name → (n, 3))."""
        n = len(next(iter(P.values())))

        def point(x):
            return P[x] if isinstance(x, str) else np.broadcast_to(x, (n, 3))

        E = np.stack([point(x) for x in self.frames], axis=1)
        J = np.stack([point(x) for x in self.origins], axis=1)
        A = np.stack([_axis(P, *x) if isinstance(x, tuple) else point(x) for x in self.axes], 1)
        return E, J, A
