"""What a clearance check measures (docs/clearance.md): each corner's wheel as two
solids of revolution about its spin axis — the tyre (from the rim's radius out to
its unloaded radius) and the rim's barrel (RIM_WALL thick inside the rim's radius),
both the tyre's section width wide — the subject's drawn links as capsules and
balls, the ``clearance:`` bodies on the chassis (model/clearance_bodies.py), and the
pairs between them; each body's pose at a configuration.

A shape is fixed to one body (its tree's drawn rods and balls, a clearance body on
the chassis), or runs between two points on two bodies (a distance closure: trackrod,
toe link, pushrod, droplink; the coilover). Positions are in metres, world axes; at
the design configuration (``pin.neutral``) every link frame is world-aligned at its
joint, so a body's placement at q moves its design points by
``G = oMf(q) · oMf(design)⁻¹``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

RIM_WALL = 0.010  # m: the rim's barrel, inside its bead seat (rim_diameter / 2)
LINK, COILOVER = 0.007, 0.012  # m: a closure's capsule radius, a coilover's (as drawn)
RIM_SHARE = 0.5  # a tyre given by its diameter alone: its rim's radius, of the tyre's


@dataclass
class Shape:
    """A capsule (``radius`` about the segment ``a`` → ``b``; a ball: a == b), a box or
    a mesh. ``bodies``: the bodies its ends ``a`` and ``b`` move with (a body-fixed
    shape: the same twice); ``a``, ``b``: design positions (m). A box or a mesh: its
    ``geometry`` (coal) placed at design by ``rotation`` and ``a`` (its centre, or the
    mesh's origin), with ``samples`` (design positions of points on its surface) to
    locate it against a wheel. ``label``: the corner it belongs to (None: shared)."""

    name: str
    kind: str  # "capsule" | "box" | "mesh"
    bodies: tuple[str, str]
    a: np.ndarray
    b: np.ndarray
    radius: float = 0.0
    label: str | None = None
    geometry: object = None
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    samples: np.ndarray | None = None
    user: bool = False  # a clearance: body


@dataclass
class Ring:
    """A solid of revolution about a wheel's spin axis: radii ``inner`` to ``outer``,
    axially ``half_width`` either side of ``centre`` (m, design), on ``body``."""

    name: str
    label: str
    part: str  # "tyre" | "rim"
    body: str
    centre: np.ndarray
    axis: np.ndarray
    inner: float
    outer: float
    half_width: float


@dataclass
class Pair:
    ring: Ring
    shape: Shape

    @property
    def name(self) -> str:
        return f"{self.ring.name}/{self.shape.name}"


def _label_of(model, name: str) -> str | None:
    """The corner a body or closure belongs to, by its prefix; None: shared (a corner's
    own: its one label)."""
    labels = list(model.labels)
    if labels == [""]:
        return ""
    for label in labels:
        if name.startswith(model.prefix(label)):
            return label
    return None


def _point_at(tree, body: str, p: np.ndarray) -> str | None:
    """The named point at ``p`` (design), one of ``body``'s first, if any."""
    found = [
        (b != body, name) for name, (b, q) in tree.points.items() if np.linalg.norm(q - p) < 1e-9
    ]
    return min(found)[1] if found else None


def wheel_rings(model) -> list[Ring]:
    """Each corner's rim and tyre, from its tyre's drawn cylinder and its rim diameter."""
    out = []
    for label, g in model.corners.items():
        prefix = model.prefix(label)
        body = prefix + g.mechanism.WHEEL_BODY
        tyre = next(v for v in model.tree.visuals if v.body == body and v.material == "tyre")
        axis = tyre.end - tyre.start
        width = float(np.linalg.norm(axis))
        centre, axis = 0.5 * (tyre.start + tyre.end), axis / width
        outer = float(tyre.radius)
        rim = g.wheel.rim_diameter
        rim = 0.5 * rim if rim is not None else RIM_SHARE * outer
        half = 0.5 * width
        out.append(
            Ring(f"{prefix}rim", label, "rim", body, centre, axis, rim - RIM_WALL, rim, half)
        )
        out.append(Ring(f"{prefix}tyre", label, "tyre", body, centre, axis, rim, outer, half))
    return out


def link_shapes(model) -> list[Shape]:
    """The subject's drawn links: its tree's rods (capsules) and balls, every distance
    closure between its points, each corner's coilover — the tyres' cylinders aside."""
    tree = model.tree
    out, seen = [], {}
    for v in tree.visuals:
        if v.material == "tyre" or v.shape not in ("rod", "ball"):
            continue
        start = _point_at(tree, v.body, v.start) or "point"
        if v.shape == "ball":
            name, end = f"{v.body}:{start}", v.start
        else:
            stop = _point_at(tree, v.body, v.end) or "point"
            name, end = f"{v.body}:{start}-{stop}", v.end
        seen[name] = seen.get(name, 0) + 1
        if seen[name] > 1:
            name = f"{name}#{seen[name]}"
        label = _label_of(model, v.body)
        out.append(Shape(name, "capsule", (v.body, v.body), v.start, end, v.radius, label))
    ends = [(c.name, c.points) for c in tree.closures if c.kind == "distance" and c.points]
    for label, g in model.corners.items():
        if "strut_top" in g.hardpoints:  # the coilover, drawn between its ends
            prefix = model.prefix(label)
            ends.append((f"{prefix}coilover", (prefix + "strut_top", prefix + "strut_bottom")))
    for name, (a, b) in ends:
        if a not in tree.points or b not in tree.points:
            continue
        (body_a, pa), (body_b, pb) = tree.points[a], tree.points[b]
        radius = COILOVER if name.endswith("coilover") else LINK
        out.append(Shape(name, "capsule", (body_a, body_b), pa, pb, radius, _label_of(model, name)))
    return out


def user_shapes(bodies, chassis: str = "chassis") -> list[Shape]:
    """The ``clearance:`` bodies as shapes on the chassis, with their coal geometry."""
    import coal

    out = []
    for body in bodies:
        if body.kind == "tube":
            out.append(
                Shape(body.name, "capsule", (chassis, chassis), body.start, body.end, body.radius)
            )
            out[-1].user = True
            continue
        if body.kind == "box":
            geometry = coal.Box(*body.size)
            grid = np.linspace(-0.5, 0.5, 11)
            u, w = np.meshgrid(grid, grid)
            faces = []
            for axis in range(3):
                for side in (-0.5, 0.5):
                    f = np.zeros((u.size, 3))
                    f[:, axis] = side
                    f[:, (axis + 1) % 3], f[:, (axis + 2) % 3] = u.ravel(), w.ravel()
                    faces.append(f)
            local = np.vstack(faces) * body.size
            samples = local @ body.rotation.T + body.center
            shape = Shape(body.name, "box", (chassis, chassis), body.center, body.center)
            shape.geometry, shape.rotation, shape.samples = geometry, body.rotation, samples
        else:
            geometry = coal.BVHModelOBBRSS()
            vertices = coal.StdVec_Vec3s()
            for v in body.vertices:
                vertices.append(np.asarray(v, dtype=float))
            triangles = coal.StdVec_Triangle()
            for a, b, c in body.faces:
                triangles.append(coal.Triangle(int(a), int(b), int(c)))
            geometry.beginModel(len(body.faces), len(body.vertices))
            geometry.addSubModel(vertices, triangles)
            geometry.endModel()
            centroids = body.vertices[body.faces].mean(axis=1)
            samples = np.vstack([body.vertices, centroids])
            zero = np.zeros(3)
            shape = Shape(body.name, "mesh", (chassis, chassis), zero, zero)
            shape.geometry, shape.samples = geometry, samples
        shape.user = True
        out.append(shape)
    return out


def jointed(tree, shape: Shape, body: str) -> bool:
    """Whether a shape meets ``body`` at a joint: it is on it, on a body jointed to it,
    or a link with an end on it."""
    parent = {b.name: b.parent for b in tree.bodies}
    return any(
        end == body or parent.get(end) == body or parent.get(body) == end for end in shape.bodies
    )


def pairs(model, bodies=()) -> tuple[list[Pair], list[tuple[str, str]]]:
    """The pairs measured and those skipped (name, why): each corner's rim against its
    corner's and the shared links (what sits inside the wheel, and the links that reach
    it); its tyre against the same links but those of the wheel's own body (the rim lies
    between) and against every clearance body."""
    rings = wheel_rings(model)
    shapes = link_shapes(model)
    users = user_shapes(bodies)
    measured, skipped = [], []
    for ring in rings:
        for shape in shapes:
            if shape.label not in (ring.label, None):
                continue
            if ring.part == "tyre" and shape.bodies == (ring.body, ring.body):
                skipped.append((f"{ring.name}/{shape.name}", "on the wheel's body, inside the rim"))
                continue
            measured.append(Pair(ring, shape))
        if ring.part == "tyre":
            measured += [Pair(ring, shape) for shape in users]
    return measured, skipped


class Poses:
    """Every body's placement at configurations: ``rotation[k, i]``, ``translation[k,
    i]`` of the i-th of ``bodies`` at the k-th configuration (G = oMf(q)·oMf(design)⁻¹:
    a design point p is at R·p + t)."""

    def __init__(self, model, bodies: list[str], qs: list[np.ndarray]):
        pin_model = model.model
        data = pin_model.createData()
        ids = [pin_model.getFrameId(b) for b in bodies]
        pin.framesForwardKinematics(pin_model, data, pin.neutral(pin_model))
        origins = np.array([data.oMf[i].translation for i in ids])
        n = len(qs)
        self.bodies = list(bodies)
        self.rotation = np.empty((n, len(ids), 3, 3))
        self.translation = np.empty((n, len(ids), 3))
        for k, q in enumerate(qs):
            pin.framesForwardKinematics(pin_model, data, q)
            for i, f in enumerate(ids):
                oMf = data.oMf[f]
                self.rotation[k, i] = oMf.rotation
                self.translation[k, i] = oMf.translation - oMf.rotation @ origins[i]

    def place(self, body: str, p: np.ndarray) -> np.ndarray:
        """Design point(s) ``p`` ((3,) or (m, 3)) of ``body`` at every configuration:
        (n, 3) or (n, m, 3)."""
        i = self.bodies.index(body)
        R, t = self.rotation[:, i], self.translation[:, i]
        if p.ndim == 1:
            return np.einsum("kij,j->ki", R, p) + t
        return np.einsum("kij,mj->kmi", R, p) + t[:, None]

    def turn(self, body: str, v: np.ndarray) -> np.ndarray:
        """A design direction of ``body`` at every configuration (n, 3)."""
        return np.einsum("kij,j->ki", self.rotation[:, self.bodies.index(body)], v)

    def rotations(self, body: str) -> np.ndarray:
        return self.rotation[:, self.bodies.index(body)]
