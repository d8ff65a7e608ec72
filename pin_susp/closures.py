"""Points, loop closures and targets: each gives residual rows and their Jacobian.

Every object here has ``residual(kin)`` and ``jacobian(kin)`` for the
current state of a :class:`Kinematics`; the Newton solver only stacks their
rows. Residuals are in metres; Jacobians are d(residual)/dv with v in the
tangent space of the joint configuration (``pin.integrate``).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

WORLD = pin.LOCAL_WORLD_ALIGNED


class Kinematics:
    """Pinocchio model + data; ``update(q)`` computes every frame and Jacobian."""

    def __init__(self, model: pin.Model):
        self.model = model
        self.data = model.createData()
        self._tree = None

    @property
    def tree(self):
        """The model's tree as arrays, for many configurations at once (bulk.Tree)."""
        if self._tree is None:
            from .bulk import Tree

            self._tree = Tree(self.model)
        return self._tree

    def update(self, q: np.ndarray) -> None:
        self.q = q
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)

    def update_positions(self, q: np.ndarray) -> None:
        """Frame placements only (no Jacobians): enough for residuals."""
        self.q = q
        pin.framesForwardKinematics(self.model, self.data, q)

    def frame_jacobian(self, frame_id: int) -> np.ndarray:
        """6×nv: linear velocity of the frame origin, then angular velocity, world axes.
        (Pinocchio returns a 6-vector when nv = 1: reshaped.)"""
        return pin.getFrameJacobian(self.model, self.data, frame_id, WORLD).reshape(6, -1)


class FramePoint:
    """A point fixed to a body: a Pinocchio frame of the model."""

    def __init__(self, name: str, frame_id: int, body: str):
        self.name = name
        self.frame_id = frame_id
        self.body = body

    def position(self, kin: Kinematics) -> np.ndarray:
        return kin.data.oMf[self.frame_id].translation

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        return kin.frame_jacobian(self.frame_id)[:3]


class ContactPatchPoint:
    """CP = WC + R·d̂(â): the lowest point of the tyre disc; not fixed to a body.

    Its Jacobian is the chain rule through â = unit(AO − AI) and d̂: with
    u = −Ẑ + a_z·â, du = (dâ·Ẑ)·â + a_z·dâ and dd̂ = (I − d̂d̂ᵀ)·du / |u|.
    """

    def __init__(
        self,
        name: str,
        center: FramePoint,
        axle_in: FramePoint,
        axle_out: FramePoint,
        radius,
        body: str = "upright",
    ):
        self.name, self.body = name, body
        self.center, self.axle_in, self.axle_out = center, axle_in, axle_out
        self.radius = radius

    @property
    def frame_points(self) -> tuple:
        return (self.center, self.axle_in, self.axle_out)

    def position(self, kin: Kinematics) -> np.ndarray:
        return self.from_frames([p.position(kin) for p in self.frame_points])[0]

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        P = [p.position(kin) for p in self.frame_points]
        return self.from_frames(P, [p.jacobian(kin) for p in self.frame_points])[1]

    def from_frames(self, P, J=None) -> tuple:
        """(position, Jacobian or None) from its frames' positions P and Jacobians J
        (wheel centre, axle inboard, axle outboard): for the solver's batch."""
        v = P[2] - P[1]
        n = math.sqrt(v @ v)
        a = v / n
        u = a * a[2]  # wheel_down's, inline (a hot path): d̂ = unit(a_z·â − Ẑ)
        u[2] -= 1.0
        norm = math.sqrt(u @ u)
        down = u / norm
        position = P[0] + self.radius * down
        if J is None:
            return position, None
        dv = J[2] - J[1]
        da = (dv - a[:, None] * (a @ dv)) / n
        du = a[:, None] * da[2] + a[2] * da
        dd = (du - down[:, None] * (down @ du)) / norm
        return position, J[0] + self.radius * dd


class BallClosure:
    """Two anchors on different bodies coincide: r = p_b − p_a (3 rows, m)."""

    size = 3

    def __init__(self, name: str, a: FramePoint, b: FramePoint):
        self.name, self.a, self.b = name, a, b

    def residual(self, kin: Kinematics) -> np.ndarray:
        return self.b.position(kin) - self.a.position(kin)

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        return self.b.jacobian(kin) - self.a.jacobian(kin)


class DistanceClosure:
    """A rigid link between two ball joints: r = |p_b − p_a| − L (1 row, m)."""

    size = 1

    def __init__(self, name: str, a: FramePoint, b: FramePoint, length: float):
        self.name, self.a, self.b, self.length = name, a, b, length

    def residual(self, kin: Kinematics) -> np.ndarray:
        return np.array([np.linalg.norm(self.b.position(kin) - self.a.position(kin)) - self.length])

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        d = self.b.position(kin) - self.a.position(kin)
        return (d / np.linalg.norm(d)) @ (self.b.jacobian(kin) - self.a.jacobian(kin))[None]


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
        self.measure = MEASURES[kind]  # or "alignment": a point's side along a line
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


class PointTarget:
    """A named point held on a plane: r = P·d̂ − value (1 row, m)."""

    size = 1

    def __init__(self, point, direction: np.ndarray, value: float = 0.0):
        self.point = point
        self.direction = np.asarray(direction, dtype=float)
        self.value = value

    @property
    def name(self) -> str:
        return f"target {self.point.name}"

    def residual(self, kin: Kinematics) -> np.ndarray:
        return np.array([self.point.position(kin) @ self.direction - self.value])

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        return (self.direction @ self.point.jacobian(kin))[None]


class JointTarget:
    """A joint held at a value: r = q_j − value (1 row; rad or m).

    Holds the rack at its design position, or the rocker at its design
    angle, while a setup adjuster is applied.
    """

    size = 1

    def __init__(self, model: pin.Model, joint: str, value: float = 0.0):
        j = model.joints[model.getJointId(joint)]
        self.name = f"hold {joint}"
        self.index_q, self.index_v = j.idx_q, j.idx_v
        self.row = np.zeros((1, model.nv))
        self.row[0, self.index_v] = 1.0
        self.value = value

    def residual(self, kin: Kinematics) -> np.ndarray:
        return np.array([kin.q[self.index_q] - self.value])

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        return self.row


class ShimGap:
    """A shim stack between two faces: p_body − p_block − t·n_block = 0 (3 rows, m).

    ``block`` and ``body`` are the facing datum points of the camber block and
    the upright body; n_block = R_block·n₀ turns with the block, so
    d(n_block) = ω_block × n_block.
    """

    size = 3

    def __init__(self, name: str, block: FramePoint, body: FramePoint, normal, thickness: float):
        self.name, self.block, self.body = name, block, body
        self.normal = np.asarray(normal, dtype=float)
        self.thickness = thickness

    def residual(self, kin: Kinematics) -> np.ndarray:
        n = kin.data.oMf[self.block.frame_id].rotation @ self.normal
        return self.body.position(kin) - self.block.position(kin) - self.thickness * n

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        n = kin.data.oMf[self.block.frame_id].rotation @ self.normal
        j_block = kin.frame_jacobian(self.block.frame_id)
        return self.body.jacobian(kin) - j_block[:3] + self.thickness * pin.skew(n) @ j_block[3:]


class FaceAlignment:
    """Two faces keep one orientation: R_body·n₀ − R_block·n₀ = 0 (3 rows).

    The vector difference (not a cross product) rejects the anti-parallel branch.
    """

    size = 3

    def __init__(self, name: str, block: FramePoint, body: FramePoint, normal):
        self.name, self.block, self.body = name, block, body
        self.normal = np.asarray(normal, dtype=float)

    def residual(self, kin: Kinematics) -> np.ndarray:
        rot = kin.data.oMf
        return (rot[self.body.frame_id].rotation - rot[self.block.frame_id].rotation) @ self.normal

    def jacobian(self, kin: Kinematics) -> np.ndarray:
        rot = kin.data.oMf
        n_body = rot[self.body.frame_id].rotation @ self.normal
        n_block = rot[self.block.frame_id].rotation @ self.normal
        w_body = kin.frame_jacobian(self.body.frame_id)[3:]
        w_block = kin.frame_jacobian(self.block.frame_id)[3:]
        return -pin.skew(n_body) @ w_body + pin.skew(n_block) @ w_block
