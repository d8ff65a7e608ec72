"""Which assembly of a closed loop a pose is on: each loop's chirality, and its guard.

The measures work on plain 3-sequences at one configuration (``chirality``,
``alignment``: floats, fast) and on arrays of points (n, 3) for n at once
(``chirality_many``, ``alignment_many``: the batched path's check).
"""

from __future__ import annotations

import math

import numpy as np

from ..maths.jet import cross
from .kinematics import Kinematics


def chirality(a, b, c, d) -> float:
    """Signed volume of the tetrahedron a, b, c, d over the product of its edge
    lengths from a: the sine-like measure of which side of the plane (a, b, c)
    the point d lies on. Works on plain 3-sequences (floats, fast)."""
    u = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    v = (c[0] - a[0], c[1] - a[1], c[2] - a[2])
    w = (d[0] - a[0], d[1] - a[1], d[2] - a[2])
    det = (
        u[0] * (v[1] * w[2] - v[2] * w[1])
        - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
    )
    scale = math.sqrt((u[0] ** 2 + u[1] ** 2 + u[2] ** 2) * (v[0] ** 2 + v[1] ** 2 + v[2] ** 2))
    scale *= math.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
    return det / scale if scale > 0.0 else 0.0


def alignment(a, b, c, d) -> float:
    """cos of the angle between b − a and d − c: which way along a line a point lies
    (a telescopic strut's top mount stays on the clamp's side of the lower ball
    joint). Works on plain 3-sequences."""
    u = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    w = (d[0] - c[0], d[1] - c[1], d[2] - c[2])
    scale = math.sqrt((u[0] ** 2 + u[1] ** 2 + u[2] ** 2) * (w[0] ** 2 + w[1] ** 2 + w[2] ** 2))
    return (u[0] * w[0] + u[1] * w[1] + u[2] * w[2]) / scale if scale > 0.0 else 0.0


MEASURES = {"chirality": chirality, "alignment": alignment}


class LoopBranch:
    """Which assembly of a closed loop a pose is on: the sign of its chirality.

    A loop closed by a ball or a distance has two assemblies for one input —
    the circle a point sweeps about its last joint axis meets the sphere (or
    point) it must reach twice, mirror images through a plane. Four points
    spanning that plane and the moving point (``points``, declared by the
    mechanism with its closure) have a signed volume whose sign tells the two
    apart; it is fixed at the design state. Crossing zero is passing the
    loop's toggle (lock-up): a Newton step that lands on the other sign has
    found the other assembly, however small its residual.

    ``fallback``: four more points telling the same assemblies apart (the loop seen
    from its other crank), kept instead when ``points``' measure vanishes at design
    (three of them on a line: a pivot placed on the other ball joint), so that such
    a design's loop is still guarded (pick_branch).
    """

    # |chirality| at design below this: the loop sits at its toggle, no side to keep
    DEGENERATE = 1e-6

    def __init__(
        self, name: str, points: list, kin: Kinematics, kind: str = "chirality", fallback=()
    ):
        self.name = name
        self.kind = kind  # or "alignment": a point's side along a line
        self.measure = MEASURES[kind]
        candidates = [list(c) for c in (points, fallback) if c]
        self.points, value = pick_branch(
            candidates, self.measure, lambda p: p.position(kin).tolist()
        )
        self.sign = math.copysign(1.0, value)
        self.degenerate = abs(value) < self.DEGENERATE

    def chirality(self, kin: Kinematics) -> float:
        return self.measure(*(p.position(kin).tolist() for p in self.points))


def pick_branch(candidates: list, measure, position) -> tuple:
    """The first of a loop's point sets (``candidates``) whose ``measure`` at design
    (``position(point)``) is clear of zero, and that value; the first set when none is
    (the loop sits at its toggle: no side to keep)."""
    first = None
    for points in candidates:
        value = measure(*(position(p) for p in points))
        if abs(value) >= LoopBranch.DEGENERATE:
            return points, value
        if first is None:
            first = points, value
    return first


class BranchGuard:
    """Every loop's branch checked at once, each moving frame read once (a hot path:
    it runs at every accepted Newton solution)."""

    def __init__(self, loops: list[LoopBranch], kin: Kinematics):
        self.loops = [loop for loop in loops if not loop.degenerate]
        model = kin.model
        fixed = {}  # frames on the chassis: their positions never change
        moving = []
        for loop in self.loops:
            for p in loop.points:
                if model.frames[p.frame_id].parentJoint == 0:
                    fixed[p.frame_id] = p.position(kin).tolist()
                elif p.frame_id not in moving:
                    moving.append(p.frame_id)
        self.moving = moving
        self.fixed = fixed
        self.ids = [
            (*(p.frame_id for p in loop.points), loop.sign, loop.name, loop.measure)
            for loop in self.loops
        ]

    def left(self, kin: Kinematics) -> str | None:
        """The name of the first loop off its design branch, or None."""
        if not self.loops:
            return None
        oMf = kin.data.oMf
        at = dict(self.fixed)
        for f in self.moving:
            at[f] = oMf[f].translation.tolist()
        for a, b, c, d, sign, name, measure in self.ids:
            if measure(at[a], at[b], at[c], at[d]) * sign <= 0.0:
                return name
        return None

    def holds_many(self, at: dict) -> bool:
        """Whether every loop keeps its design sign at n configurations at once; ``at``:
        each of the loops' frames' positions (n, 3) by frame id (bulk.Frames)."""
        for loop in self.loops:
            points = [at[p.frame_id] for p in loop.points]
            if np.any(MEASURES_MANY[loop.kind](*points) * loop.sign <= 0.0):
                return False
        return True

    @property
    def frame_ids(self) -> list[int]:
        """Every frame the loops' measures read, in order."""
        return sorted({p.frame_id for loop in self.loops for p in loop.points})


def chirality_many(a, b, c, d) -> np.ndarray:
    """chirality for arrays of points (n, 3)."""
    u, v, w = b - a, c - a, d - a
    det = np.einsum("ni,ni->n", u, cross(v, w))
    scale = np.sqrt(
        np.einsum("ni,ni->n", u, u) * np.einsum("ni,ni->n", v, v) * np.einsum("ni,ni->n", w, w)
    )
    return np.where(scale > 0.0, det / np.where(scale > 0.0, scale, 1.0), 0.0)


def alignment_many(a, b, c, d) -> np.ndarray:
    """alignment for arrays of points (n, 3)."""
    u, w = b - a, d - c
    scale = np.sqrt(np.einsum("ni,ni->n", u, u) * np.einsum("ni,ni->n", w, w))
    dot = np.einsum("ni,ni->n", u, w)
    return np.where(scale > 0.0, dot / np.where(scale > 0.0, scale, 1.0), 0.0)


MEASURES_MANY = {"chirality": chirality_many, "alignment": alignment_many}
