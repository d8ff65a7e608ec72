"""The kinematic tree every model file and the solver are built from: bodies, joints,
points, loop closures, visuals and springs, in world coordinates at the design state.

A mechanism module (mechanisms/) describes its corner as a :class:`Tree`; an axle
composes two. urdf.py writes a tree as URDF and mjcf.py as MJCF; linkage.py builds
the Pinocchio model from the URDF. Also here, because both files carry them: each
joint's freedoms (:func:`joint_steps`: a ball is three revolutes), the bodies'
masses and inertias from their drawn shapes (:func:`inertials`), and the joint
limits and the spring's sense from the design's first-order rates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

BALL_AXES = (("z", (0.0, 0.0, 1.0)), ("y", (0.0, 1.0, 0.0)), ("x", (1.0, 0.0, 0.0)))


ROD_MIN_LENGTH = 1e-9  # m


# Masses (config.inertia overrides the density and the wheel's mass)
DENSITY = 7850.0  # kg/m³: steel, the drawn links and joints


TYRE_DENSITY = 150.0  # kg/m³: rim, tyre, hub and brake spread over the drawn tyre cylinder


PLACEHOLDER_MASS = 1e-3  # kg: a link with no drawn shape (a ball joint's inner links)


PLACEHOLDER_INERTIA = 1e-6  # kg·m², each principal moment of such a link


# The damper (no geometry key gives one): N·s/m along a coilover; a torsion bar's is the
# same damper on the rocker's arm to the pushrod (N·m·s/rad: DAMPER × arm²)
DAMPER = 3000.0


# Joint limits: a joint's excursion over the wheel's travel and the rack's, to first
# order (its rates at design), times a margin for the curved path, plus a floor.
WHEEL_TRAVEL = 0.1  # m, ± at the wheel centre (each wheel's, independently)


RACK_TRAVEL = 0.05  # m, ±


LIMIT_MARGIN = 1.5


LIMIT_FLOOR = {"revolute": math.radians(10.0), "prismatic": 0.01}  # rad, m


# Velocity limits likewise, from the wheel's and the rack's speeds
WHEEL_SPEED = 5.0  # m/s


RACK_SPEED = 0.5  # m/s


SPEED_FLOOR = {"revolute": 1.0, "prismatic": 0.1}  # rad/s, m/s


# the widest written, and the limits where the rates are unknown
REVOLUTE_LIMIT = np.pi


PRISMATIC_LIMIT = 0.5  # m


SPEED_LIMIT = {"revolute": 100.0, "prismatic": 10.0}  # rad/s, m/s


EFFORT = 1e4  # N·m, N: passive joints; a tool that clamps applied efforts never clamps here


@dataclass(frozen=True)
class Joint:
    """A joint placing a body on its parent; origin and axis in world, design state."""

    name: str
    kind: str  # "revolute" | "prismatic" | "ball" | "universal"
    origin: np.ndarray
    axis: np.ndarray | None = None
    # The hardpoints that place it: (origin,) for a ball or universal, (origin, axis
    # end) for a revolute or slide whose axis runs origin → axis end. Used for
    # hardpoint sensitivities.
    defined_by: tuple[str, ...] = ()
    axis2: np.ndarray | None = None  # a universal joint's second axis (after ``axis``)

    def steps(self) -> list[tuple[str, str, np.ndarray]]:
        """The one-freedom joints it is made of: (name suffix, URDF type, axis).

        A ball is three revolutes about z, y, x; a universal two revolutes (axis,
        then axis2); the links between them are massless. Names: the ball's end
        in _z/_y/_x, the universal's in _a/_b; others are one joint of their name.
        """
        if self.kind == "ball":
            return [(f"_{k}", "revolute", np.array(a)) for k, a in BALL_AXES]
        if self.kind == "universal":
            return [("_a", "revolute", self.axis), ("_b", "revolute", self.axis2)]
        return [("", self.kind, self.axis)]


@dataclass(frozen=True)
class Body:
    name: str
    parent: str | None = None
    joint: Joint | None = None


@dataclass(frozen=True)
class Closure:
    """A loop closure between two anchors (link name, world position at design).

    ``ball``: the anchors coincide (3 equations). ``distance``: their distance
    stays at its design value (1 equation).
    """

    name: str
    kind: str
    anchors: tuple[tuple[str, np.ndarray], tuple[str, np.ndarray]]
    points: tuple[str, str] = ()  # the named points the anchors sit at
    # Four named points whose chirality tells this loop's two assemblies apart
    # (constraints.LoopBranch): the pose keeps the sign it has at design. With
    # branch_kind "alignment": the sign of (b − a)·(d − c) instead.
    branch: tuple[str, str, str, str] | tuple[()] = ()
    branch_kind: str = "chirality"
    # Four more points telling the same two assemblies apart (with the same kind), used
    # when ``branch``'s measure vanishes at design — e.g. a pivot placed on the other
    # ball joint: its plane is undefined, yet the loop still has two assemblies.
    branch_fallback: tuple[str, str, str, str] | tuple[()] = ()

    @property
    def branch_candidates(self) -> list[tuple[str, ...]]:
        """The branch's point sets in order of preference (constraints.pick_branch)."""
        return [b for b in (self.branch, self.branch_fallback) if b]


@dataclass(frozen=True)
class Visual:
    """Simple shapes for viewers: a rod between two points, a ball, or a disc."""

    body: str
    shape: str  # "rod" | "ball" | "disc"
    material: str
    start: np.ndarray
    end: np.ndarray | None = None  # rod end, or disc axis point (centre ± axis)
    radius: float = 0.01


@dataclass(frozen=True)
class Spring:
    """The corner's spring and damper, for the exports that simulate: a coilover
    between two points (``ends``: top, bottom; rate N/m, preload N in compression at
    design, damping N·s/m) or a torsion bar twisted by a joint (``ends``: the joint;
    rate N·m/rad, preload N·m resisting bump at design, damping N·m·s/rad). ``rate``
    None: the geometry gives none. ``side``: in an axle, the side whose spring it is
    (its ends are that side's ``left_…`` names); None in a corner."""

    kind: str  # "coilover" | "torsion_bar"
    ends: tuple[str, ...]
    rate: float | None = None
    preload: float = 0.0
    damping: float = 0.0
    side: str | None = None


@dataclass(frozen=True)
class FloatingBase:
    """The root body floats: a vehicle's sprung body on the road (docs/urdf.md). The
    URDF has no joint for it (its root link is the body: a robotics tool adds a floating
    base); the MJCF puts it on a ``<freejoint>`` ``joint`` above a ``plane`` geom at
    z = 0, the road. ``mass`` (kg, None: not given) at ``center`` (m, world at design)
    with ``inertia`` (kg·m², about the centre, world axes): the URDF's link ``frame``
    (a point of the root at the centre) carries it, so that the root link has none; the
    MJCF's root body does."""

    frame: str
    center: np.ndarray
    mass: float | None = None
    inertia: np.ndarray | None = None
    joint: str = "body_free"
    road: str = "road"


@dataclass(frozen=True)
class BodyPose:
    """Where a floating root (``FloatingBase``) is placed: its frame in the road's,
    w = R·p + t — a vehicle's body at a step's heave, pitch and roll (docs/vehicle.md),
    first among that step's targets for the validation's engines (their floating base
    held there; validate/floating.py for an engine whose root is fixed)."""

    rotation: np.ndarray
    translation: np.ndarray

    def to_road(self, points: dict) -> dict:
        """Points in the body's frame (name → (3,) m) in the road's."""
        return {n: self.rotation @ p + self.translation for n, p in points.items()}


@dataclass
class Tree:
    name: str
    bodies: list[Body]
    points: dict[str, tuple[str, np.ndarray]]  # point name → (body, world position)
    closures: list[Closure]
    visuals: list[Visual] = field(default_factory=list)
    materials: dict[str, tuple[float, float, float, float]] = field(default_factory=dict)
    density: float = DENSITY  # kg/m³ of the drawn links and joints
    wheel_mass: float | None = None  # kg of each tyre cylinder; None: TYRE_DENSITY × volume
    # a corner's spring, or an axle's (one per side, each with its ``side``)
    spring: Spring | list[Spring] | None = None
    # <pin_susp:corner>'s attributes: a corner's, or an axle's (one per side)
    metadata: dict[str, str] | list[dict[str, str]] = field(default_factory=dict)
    # the root floats (a vehicle's body), or None: the root is the world (a corner's chassis)
    floating: FloatingBase | None = None

    def __post_init__(self):
        # A rod between coincident points (a strut bottom on the rocker axis) has
        # no direction to draw along: it is left out rather than drawn as NaN.
        self.visuals = [
            v
            for v in self.visuals
            if v.shape != "rod" or np.linalg.norm(v.end - v.start) > ROD_MIN_LENGTH
        ]

    @property
    def springs(self) -> list[Spring]:
        """Every spring: none, the corner's, or an axle's two."""
        if self.spring is None:
            return []
        return [self.spring] if isinstance(self.spring, Spring) else list(self.spring)

    @property
    def corners(self) -> list[dict[str, str]]:
        """Every <pin_susp:corner>'s attributes: none, the corner's, or an axle's two."""
        if isinstance(self.metadata, dict):
            return [self.metadata] if self.metadata else []
        return [m for m in self.metadata if m]


@dataclass(frozen=True)
class Step:
    """One freedom of the URDF: a revolute or prismatic joint from parent to child
    link; axis and origin in world at design (where every link frame is world-aligned)."""

    name: str
    kind: str  # "revolute" | "prismatic"
    axis: np.ndarray
    origin: np.ndarray
    parent: str
    child: str


def joint_steps(tree: Tree) -> list[Step]:
    """The tree's one-freedom joints in file order: a ball is three, a universal two,
    with links between them (``<joint>_link_z``, ...)."""
    out = []
    for body in tree.bodies:
        if body.joint is None:
            continue
        j = body.joint
        parent = body.parent
        parts = j.steps()
        for i, (suffix, kind, axis) in enumerate(parts):
            child = body.name if i == len(parts) - 1 else f"{j.name}_link{suffix}"
            out.append(
                Step(f"{j.name}{suffix}", kind, np.asarray(axis, float), j.origin, parent, child)
            )
            parent = child
    return out


# ---------------------------------------------------------------- masses


def inertials(tree: Tree, steps: list[Step] | None = None) -> dict:
    """link → (mass kg, centre of mass m, inertia kg·m² about it), world axes at design,
    for every moving link: its drawn shapes as solids — a rod a cylinder and a ball a
    sphere of the tree's density, a tyre a cylinder of the wheel's mass (or of
    TYRE_DENSITY) — summed (where shapes overlap, twice); a link with no shape (a ball
    joint's inner links) gets the placeholder."""
    shapes = {}
    for v in tree.visuals:
        shapes.setdefault(v.body, []).append(_solid(v, tree))
    out = {}
    for s in steps if steps is not None else joint_steps(tree):
        parts = shapes.get(s.child)
        if not parts:
            out[s.child] = (PLACEHOLDER_MASS, s.origin, PLACEHOLDER_INERTIA * np.eye(3))
            continue
        mass = sum(m for m, _, _ in parts)
        center = sum(m * c for m, c, _ in parts) / mass
        inertia = np.zeros((3, 3))
        for m, c, own in parts:  # each about the link's centre of mass (parallel axes)
            d = c - center
            inertia += own + m * (d @ d * np.eye(3) - np.outer(d, d))
        # round-off in the products of inertia: zero, so that the text is the same everywhere
        inertia[np.abs(inertia) < 1e-12 * np.max(np.abs(inertia))] = 0.0
        out[s.child] = (mass, center, inertia)
    return out


def _solid(v: Visual, tree: Tree) -> tuple[float, np.ndarray, np.ndarray]:
    """A shape's mass, centre and inertia about its centre (world axes)."""
    r = v.radius
    if v.shape == "ball":
        mass = tree.density * 4.0 / 3.0 * np.pi * r**3
        return mass, v.start, 0.4 * mass * r * r * np.eye(3)
    d = v.end - v.start
    length = float(np.linalg.norm(d))
    volume = np.pi * r * r * length
    if v.material != "tyre":
        mass = tree.density * volume
    else:
        mass = tree.wheel_mass if tree.wheel_mass is not None else TYRE_DENSITY * volume
    return mass, v.start + 0.5 * d, cylinder_inertia(mass, r, d)


def cylinder_inertia(mass: float, radius: float, length_axis: np.ndarray) -> np.ndarray:
    """A solid cylinder's inertia about its centre, its axis along ``length_axis``
    (whose norm is the length): ½mr² about the axis, m(3r² + L²)/12 across it."""
    length = float(np.linalg.norm(length_axis))
    u = length_axis / length
    across = mass * (3.0 * radius * radius + length * length) / 12.0
    along = 0.5 * mass * radius * radius
    return across * np.eye(3) + (along - across) * np.outer(u, u)


# ---------------------------------------------------------------- joint limits


def design_rates(tree: Tree, steps: list[Step] | None = None):
    """(drivers, rates): each one-freedom joint's rate per driver at the design state
    (nv × k), the drivers being each wheel centre's height (a point ``wheel_center`` or
    ``<side>_wheel_center``: "wheel") and the rack (``rack_slide``: "rack").

    J·dq = e_j with J the closures' rows and the drivers', from the joints' design
    twists alone: every link frame is world-aligned at design, so a revolute about â
    through o moves a point p at â × (p − o), a slide at â. None when a row is not
    finite or no driver is found (then the widest limits are written).
    """
    steps = steps if steps is not None else joint_steps(tree)
    index = {s.name: i for i, s in enumerate(steps)}
    chain = {b.name: [] for b in tree.bodies if b.joint is None}
    for i, s in enumerate(steps):
        chain[s.child] = [*chain.get(s.parent, []), i]
    nv = len(steps)
    axes = np.array([s.axis for s in steps]).reshape(nv, 3)
    origins = np.array([s.origin for s in steps]).reshape(nv, 3)
    slides = np.array([s.kind == "prismatic" for s in steps], dtype=bool)

    def jacobian(link: str, p: np.ndarray) -> np.ndarray:
        body = tree.points[link][0] if link in tree.points else link
        J = np.zeros((nv, 3))
        i = np.array(chain.get(body, []), dtype=int)
        a, r = axes[i], p - origins[i]
        turn = a[:, [1, 2, 0]] * r[:, [2, 0, 1]] - a[:, [2, 0, 1]] * r[:, [1, 2, 0]]  # â × r
        J[i] = np.where(slides[i, None], a, turn)
        return J.T

    rows, drivers = [], []
    with np.errstate(all="ignore"):
        for c in tree.closures:
            (link_a, a), (link_b, b) = c.anchors
            gap = jacobian(link_b, b) - jacobian(link_a, a)
            rows.extend(gap if c.kind == "ball" else [(b - a) / np.linalg.norm(b - a) @ gap])
        for name, (_, p) in tree.points.items():
            if name == "wheel_center" or name.endswith("_wheel_center"):
                rows.append(jacobian(name, p)[2])
                drivers.append("wheel")
        if "rack_slide" in index:
            rows.append(np.eye(nv)[index["rack_slide"]])
            drivers.append("rack")
        if not drivers or not nv or not np.all(np.isfinite(rows)):
            return None
        rhs = np.zeros((len(rows), len(drivers)))
        rhs[-len(drivers) :] = np.eye(len(drivers))
        try:
            rates = np.linalg.lstsq(np.array(rows), rhs, rcond=None)[0]
        except np.linalg.LinAlgError:
            return None
    return (drivers, rates) if np.all(np.isfinite(rates)) else None


def joint_limits(steps: list[Step], rates) -> dict[str, tuple[float, float]]:
    """name → (range ±, velocity limit) of each one-freedom joint: LIMIT_MARGIN × its
    first-order excursion with every wheel at ±WHEEL_TRAVEL and the rack at
    ±RACK_TRAVEL, plus LIMIT_FLOOR (the velocity likewise from WHEEL_SPEED and
    RACK_SPEED, plus SPEED_FLOOR); at most ±π (±0.5 m), the widest also where the
    rates are unknown."""
    out = {}
    for i, s in enumerate(steps):
        widest = REVOLUTE_LIMIT if s.kind == "revolute" else PRISMATIC_LIMIT
        if rates is None:
            out[s.name] = (widest, SPEED_LIMIT[s.kind])
            continue
        drivers, x = rates
        rate = np.abs(x[i])
        travel = np.array([WHEEL_TRAVEL if d == "wheel" else RACK_TRAVEL for d in drivers])
        speed = np.array([WHEEL_SPEED if d == "wheel" else RACK_SPEED for d in drivers])
        reach = LIMIT_MARGIN * float(rate @ travel) + LIMIT_FLOOR[s.kind]
        fast = LIMIT_MARGIN * float(rate @ speed) + SPEED_FLOOR[s.kind]
        out[s.name] = (min(reach, widest), min(fast, SPEED_LIMIT[s.kind]))
    return out


def spring_sense(tree: Tree, steps: list[Step], rates, spring: Spring | None = None) -> float:
    """+1 when bump turns a torsion bar's joint positively, else −1: the rate of
    ``spring``'s joint (default: the corner's spring) per its wheel's travel — the
    first wheel's, or in an axle the wheel of the spring's side."""
    spring = spring if spring is not None else (tree.springs or [None])[0]
    if spring is None or rates is None:
        return 1.0
    drivers, x = rates
    names = [s.name for s in steps]
    if spring.ends[0] not in names or "wheel" not in drivers:
        return 1.0
    column = drivers.index("wheel")
    if spring.side is not None:  # the k-th wheel driver is the k-th wheel centre point
        wheels = [n for n in tree.points if n == "wheel_center" or n.endswith("_wheel_center")]
        mine = f"{spring.side}_wheel_center"
        if mine in wheels:
            column = [i for i, d in enumerate(drivers) if d == "wheel"][wheels.index(mine)]
    return -1.0 if x[names.index(spring.ends[0]), column] < 0.0 else 1.0
