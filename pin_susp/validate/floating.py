"""A floating body's step for an engine whose root is fixed (the point-based one): the
targets of a step that places a floating root (a vehicle's body at a BodyPose, its
targets in the road's frame) turned into the body's frame (README, How it works;
docs/vehicle.md, Validate).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..analyses.pointwise import Along, Z, as_target
from ..model.tree import BodyPose


@dataclass(frozen=True)
class OnRoad:
    """A wheel's contact patch at the road's height, from its points in the body's frame
    (``prefix``: its corner's label's) with the body placed at ``pose``: the lowest point
    of the tyre disc (``radius``, m) seen from the road, its z at ``value`` (m)."""

    prefix: str
    radius: float
    pose: BodyPose
    value: float

    def _parts(self, p):
        R = self.pose.rotation
        v = p[f"{self.prefix}axle_outboard"] - p[f"{self.prefix}axle_inboard"]
        a = R @ (v / np.linalg.norm(v))  # the spin axis, in the road's frame
        u = a[2] * a - Z
        return R, v, a, u, u / np.linalg.norm(u)

    def error(self, p) -> float:
        R, _, _, _, d = self._parts(p)
        center = R @ p[f"{self.prefix}wheel_center"] + self.pose.translation
        return center[2] + self.radius * d[2] - self.value

    def gradient(self, p) -> dict[str, np.ndarray]:
        # z of R·c + t + r·d̂, d̂ = unit(a_z·â − ẑ), â = R·unit(AO − AI): the chain rule
        R, v, a, u, d = self._parts(p)
        own = v / np.linalg.norm(v)
        dd = (np.eye(3) - np.outer(d, d)) / np.linalg.norm(u) @ (np.outer(a, Z) + a[2] * np.eye(3))
        dv = self.radius * dd[2] @ R @ ((np.eye(3) - np.outer(own, own)) / np.linalg.norm(v))
        return {
            f"{self.prefix}wheel_center": R[2].copy(),
            f"{self.prefix}axle_outboard": dv,
            f"{self.prefix}axle_inboard": -dv,
        }


def in_body_frame(targets: list, radii: dict) -> tuple[list, BodyPose | None]:
    """One step's targets for an engine whose root is fixed (the point-based one): where
    they hold a floating body at a :class:`BodyPose`, each in the body's frame — a
    point's coordinate along a direction turned into it, a contact patch's height on the
    road an :class:`OnRoad` (``radii``: each wheel's label prefix → its radius) — and
    the pose; else the targets as they are, and None."""
    pose = next((t for t in targets if isinstance(t, BodyPose)), None)
    if pose is None:
        return targets, None
    out = []
    for t in targets:
        if t is pose:
            continue
        t = as_target(t)
        if not isinstance(t, Along):
            raise ValueError(f"{t!r}: no target of a floating body's step")
        prefix = t.point.removesuffix("contact_patch_center")
        if prefix != t.point and prefix in radii and np.allclose(t.direction, Z, atol=0.0):
            out.append(OnRoad(prefix, radii[prefix], pose, t.value))
        else:  # d·(R·p + t) = v: (Rᵀd)·p = v − d·t
            direction = pose.rotation.T @ t.direction
            out.append(Along(t.point, direction, t.value - t.direction @ pose.translation))
    return out, pose
