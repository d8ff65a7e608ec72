"""Dead centres at design: a link whose line passes (nearly) through the pivot axis of
a body it works (docs/geometry.md, "Dead centres").

A link — a rigid distance closure (pushrod, droplink) or a coilover — that ends on a
body turning about a fixed axis (a rocker, a bar's arm, a wishbone, a trailing arm)
works it through the lever arm from the axis to that end. Seen along the axis, the
**transmission angle** is the angle at the end between the lever arm (axis → end)
and the link (end → its other end): 90° is ideal, and at 0° or 180° the link's line
passes through the axis — a dead centre, where the link has no leverage on the body.

Which way the motion ratio goes there depends on which of the two drives:

- the link drives the body (a pushrod its rocker, a droplink the bar's arm): the body
  turns ever faster per mm of the link's travel, the motion ratio through it rises
  toward infinity, and the body can flip over to its other assembly;
- the body drives the link (a rocker its coilover or droplink, a wishbone its pushrod):
  the link barely changes length as the body turns, the motion ratio through it
  falls toward zero (a spring there cannot hold the wheel).

Which drives is read off the tree: starting from the wheel's body, through joints and
loop closures (never through the chassis), the body reached first drives the other.
"""

from __future__ import annotations

import math
import warnings
from collections import deque
from dataclasses import dataclass

import numpy as np

from ..errors import PlausibilityWarning

# Within this many degrees of 0° or 180° at design, every command warns (a warning,
# not an error: draw and view must still show the geometry, to be fixed).
DEAD_CENTRE = 10.0  # deg


@dataclass(frozen=True)
class Transmission:
    """One link's end on a pivoted body at design. Lengths in metres."""

    link: str  # the link's name in the tree: "pushrod", "coilover", "left_droplink"
    end: str  # the link's end on the body (a point name)
    other: str  # the link's other end
    body: str  # the pivoted body: "rocker", "left_arb_arm", "lower_wishbone"
    axis: tuple[str, ...]  # the points that define the body's axis ((): none named)
    angle: float  # deg, 0…180: the transmission angle
    miss: float  # m: how far the link's line passes from the axis (seen along it)
    arm: float  # m: the lever arm, axis → end
    driven: bool  # the link drives the body: the motion ratio rises toward infinity

    @property
    def margin(self) -> float:
        """Degrees from dead centre: min(angle, 180° − angle)."""
        return min(self.angle, 180.0 - self.angle)

    @property
    def flow(self) -> str:
        """The motion's way through the pair: 'pushrod → rocker', 'rocker → coilover'."""
        link, body = _words(self.link), _words(self.body)
        return f"{link} → {body}" if self.driven else f"{body} → {link}"

    @property
    def consequence(self) -> str:
        link, body = _words(self.link), _words(self.body)
        if self.driven:
            return (
                f"the {body} turns ever faster per mm of {link} travel, so the motion ratio "
                f"through it rises toward infinity and the {body} can flip over to its "
                "other assembly (sweep steps near it fail)"
            )
        return (
            f"the {link} barely changes length as the {body} turns, so the motion ratio "
            f"through it falls toward zero"
            + (" (the spring cannot hold the wheel)" if "coilover" in self.link else "")
        )

    def message(self, source: str) -> str:
        body = _words(self.body)
        axis = f" {'–'.join(self.axis)}" if self.axis else ""
        return (
            f"{source}: {self.flow} is {self.margin:.1f}° from dead centre at design "
            f"(transmission angle {self.angle:.1f}°: the {self.other}–{self.end} line passes "
            f"{self.miss * 1e3:.2f} mm from the {body} axis{axis}, lever arm "
            f"{self.arm * 1e3:.0f} mm): {self.consequence} — move {self.end} round the "
            f"{body} axis, or {self.other}, so that the {_words(self.link)} meets the lever "
            "arm nearer 90°"
        )


def _words(name: str) -> str:
    return name.replace("_", " ")


def transmissions(tree) -> list[Transmission]:
    """Every link's end on a body that turns about a fixed axis (a revolute joint on
    the chassis — the root, or a vehicle's body on the road), with its transmission
    angle at design."""
    names = [b.name for b in tree.bodies]
    root = (
        "chassis" if "chassis" in names else next(b.name for b in tree.bodies if b.parent is None)
    )
    pivoted = {
        b.name: b.joint
        for b in tree.bodies
        if b.parent == root and b.joint is not None and b.joint.kind == "revolute"
    }
    if not pivoted:
        return []
    reach = _reach(tree, root)
    links = [(c.name, c.points, True) for c in tree.closures if c.kind == "distance" and c.points]
    for s in tree.springs:
        if s.kind == "coilover":
            side = f"{s.side}_" if s.side else ""
            links.append((f"{side}coilover", s.ends, False))
    out = []
    for name, ends, rigid in links:
        if not all(e in tree.points for e in ends):
            continue
        for end, other in (ends, ends[::-1]):
            body = tree.points[end][0]
            if body not in pivoted:
                continue
            joint = pivoted[body]
            far = reach.get(body, math.inf)
            near = reach.get(tree.points[other][0], math.inf)
            out.append(
                _transmission(
                    name,
                    end,
                    other,
                    body,
                    joint,
                    tree,
                    driven=rigid and near < far,
                )
            )
    return out


def _transmission(name, end, other, body, joint, tree, driven: bool) -> Transmission:
    u = np.asarray(joint.axis, dtype=float)
    u = u / np.linalg.norm(u)
    p, q = tree.points[end][1], tree.points[other][1]
    arm = p - joint.origin
    rod = q - p
    arm = arm - u * (u @ arm)  # both seen along the axis
    rod = rod - u * (u @ rod)
    sine = float(u @ np.cross(arm, rod))
    angle = math.degrees(abs(math.atan2(sine, float(arm @ rod))))
    rod_length = float(np.linalg.norm(rod))
    miss = abs(sine) / rod_length if rod_length > 0.0 else 0.0  # |arm| · sin(angle)
    axis = tuple(tree_point_name(n, body, tree) for n in joint.defined_by)
    return Transmission(
        name, end, other, body, axis, angle, miss, float(np.linalg.norm(arm)), driven
    )


def tree_point_name(name: str, body: str, tree) -> str:
    """A joint's defining point as the tree names it (an axle's are ``left_…``)."""
    if name in tree.points:
        return name
    side = body.partition("_")[0]
    prefixed = f"{side}_{name}"
    return prefixed if prefixed in tree.points else name


def _reach(tree, root: str) -> dict[str, int]:
    """Each body's distance from the wheel's body (or bodies) through joints and loop
    closures, never through the chassis."""
    edges: dict[str, set] = {}

    def join(a, b):
        if a != b and root not in (a, b):
            edges.setdefault(a, set()).add(b)
            edges.setdefault(b, set()).add(a)

    for b in tree.bodies:
        if b.parent is not None:
            join(b.name, b.parent)
    for c in tree.closures:
        a, b = (tree.points[n][0] if n in tree.points else n for n, _ in c.anchors)
        join(a, b)
    starts = [m["wheel_link"] for m in tree.corners if "wheel_link" in m]
    reach = dict.fromkeys(starts, 0)
    queue = deque(starts)
    while queue:
        a = queue.popleft()
        for b in edges.get(a, ()):
            if b not in reach:
                reach[b] = reach[a] + 1
                queue.append(b)
    return reach


def dead_centres(tree, limit: float = DEAD_CENTRE) -> list[Transmission]:
    """The links within ``limit`` degrees of dead centre at design, nearest first."""
    near = [t for t in transmissions(tree) if t.margin < limit]
    return sorted(near, key=lambda t: t.margin)


def warn_dead_centres(tree, source: str, mirrored: bool = False) -> list[Transmission]:
    """A PlausibilityWarning for each link near dead centre at design (docs/geometry.md,
    "Dead centres"); the ones found. ``mirrored``: an axle whose right side mirrors its
    left, said once (for the left)."""
    found = [t for t in dead_centres(tree) if not (mirrored and t.body.startswith("right_"))]
    for t in found:
        left = mirrored and t.body.startswith("left_")
        note = " (the mirrored right side likewise)" if left else ""
        warnings.warn(t.message(source) + note, PlausibilityWarning, stacklevel=3)
    return found
