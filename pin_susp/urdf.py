"""A kinematic tree (bodies, joints, points, loop closures) ↔ URDF text.

An architecture module (e.g. ``double_wishbone.py``) describes its tree in
world coordinates at the design state; this module writes it as URDF
(metres) and reads the loop closures back. Conventions of the file:

- every link frame is world-aligned at the design state, so joint value 0
  is the design state and each joint origin is a plain offset;
- a ball joint is three revolutes about z, y, x through two massless links
  (URDF has no ball joint);
- every point is a link on a fixed joint, so it shows as a frame in any
  URDF tool;
- loop closures are ``<pin_susp:loop_closure>`` elements (a namespace every
  URDF parser ignores), each with two ``<pin_susp:frame link=… xyz=…/>``.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from .errors import PinSuspError

NAMESPACE = "https://github.com/pin-susp/pin_susp/urdf"
BALL_AXES = (("z", (0.0, 0.0, 1.0)), ("y", (0.0, 1.0, 0.0)), ("x", (1.0, 0.0, 0.0)))
# Joint ranges only matter to tools that clamp; wide enough for any sweep.
REVOLUTE_LIMIT = np.pi
PRISMATIC_LIMIT = 0.5  # m
ROD_MIN_LENGTH = 1e-9  # m


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
    # (closures.LoopBranch): the pose keeps the sign it has at design. With
    # branch_kind "alignment": the sign of (b − a)·(d − c) instead.
    branch: tuple[str, str, str, str] | tuple[()] = ()
    branch_kind: str = "chirality"


@dataclass(frozen=True)
class Visual:
    """Simple shapes for viewers: a rod between two points, a ball, or a disc."""

    body: str
    shape: str  # "rod" | "ball" | "disc"
    material: str
    start: np.ndarray
    end: np.ndarray | None = None  # rod end, or disc axis point (centre ± axis)
    radius: float = 0.01


@dataclass
class Tree:
    name: str
    bodies: list[Body]
    points: dict[str, tuple[str, np.ndarray]]  # point name → (body, world position)
    closures: list[Closure]
    visuals: list[Visual] = field(default_factory=list)
    materials: dict[str, tuple[float, float, float, float]] = field(default_factory=dict)

    def __post_init__(self):
        # A rod between coincident points (a strut bottom on the rocker axis) has
        # no direction to draw along: it is left out rather than drawn as NaN.
        self.visuals = [
            v
            for v in self.visuals
            if v.shape != "rod" or np.linalg.norm(v.end - v.start) > ROD_MIN_LENGTH
        ]


def tree_to_urdf(tree: Tree, comment: str = "") -> str:
    """Render the tree as URDF text (metres, full float precision)."""
    robot = ET.Element("robot", {"name": tree.name, "xmlns:pin_susp": NAMESPACE})
    for name, rgba in tree.materials.items():
        mat = ET.SubElement(robot, "material", {"name": name})
        ET.SubElement(mat, "color", {"rgba": _fmt(rgba)})

    origin_of = {}  # link name → world position of its frame
    links = {}
    for body in tree.bodies:
        if body.joint is None:
            origin_of[body.name] = np.zeros(3)
            links[body.name] = ET.SubElement(robot, "link", {"name": body.name})
            continue
        j = body.joint
        parent = body.parent
        steps = j.steps()
        for i, (suffix, kind, axis) in enumerate(steps):
            # several freedoms at one point: massless links between them
            child = body.name if i == len(steps) - 1 else f"{j.name}_link{suffix}"
            links[child] = ET.SubElement(robot, "link", {"name": child})
            _joint(
                robot, f"{j.name}{suffix}", kind, parent, child, j.origin - origin_of[parent], axis
            )
            origin_of[child] = j.origin
            parent = child

    for v in tree.visuals:
        _visual(links[v.body], v, origin_of[v.body])

    for name, (body, position) in tree.points.items():
        ET.SubElement(robot, "link", {"name": name})
        _joint(robot, f"{body}_to_{name}", "fixed", body, name, position - origin_of[body])
        origin_of[name] = position

    for c in tree.closures:
        el = ET.SubElement(robot, "pin_susp:loop_closure", {"name": c.name, "type": c.kind})
        for link, position in c.anchors:
            ET.SubElement(
                el, "pin_susp:frame", {"link": link, "xyz": _fmt(position - origin_of[link])}
            )

    ET.indent(robot)
    text = ET.tostring(robot, encoding="unicode")
    head = '<?xml version="1.0"?>\n'
    if comment:
        head += f"<!-- {comment} -->\n"
    return head + text + "\n"


@dataclass(frozen=True)
class ClosureSpec:
    """A loop closure read back from URDF: anchors as (link, offset in the link frame)."""

    name: str
    kind: str
    anchors: tuple[tuple[str, np.ndarray], tuple[str, np.ndarray]]


def read_closures(urdf_text: str) -> list[ClosureSpec]:
    """The ``<pin_susp:loop_closure>`` elements of a URDF written by tree_to_urdf."""
    root = ET.fromstring(urdf_text)
    ns = {"pin_susp": NAMESPACE}
    closures = []
    for el in root.findall("pin_susp:loop_closure", ns):
        frames = el.findall("pin_susp:frame", ns)
        anchors = tuple(
            (f.get("link"), np.array([float(x) for x in f.get("xyz", "0 0 0").split()]))
            for f in frames
        )
        if len(anchors) != 2:
            raise ValueError(f"loop closure {el.get('name')!r} needs two frames")
        closures.append(ClosureSpec(el.get("name"), el.get("type"), anchors))
    return closures


def _joint(robot, name, kind, parent, child, xyz, axis=None):
    j = ET.SubElement(robot, "joint", {"name": name, "type": kind})
    ET.SubElement(j, "parent", {"link": parent})
    ET.SubElement(j, "child", {"link": child})
    ET.SubElement(j, "origin", {"xyz": _fmt(xyz), "rpy": "0 0 0"})
    if kind == "fixed":
        return
    ET.SubElement(j, "axis", {"xyz": _fmt(axis)})
    limit = REVOLUTE_LIMIT if kind == "revolute" else PRISMATIC_LIMIT
    ET.SubElement(
        j,
        "limit",
        {"lower": _fmt([-limit]), "upper": _fmt([limit]), "effort": "0", "velocity": "0"},
    )


def _visual(link, v: Visual, link_origin: np.ndarray):
    el = ET.SubElement(link, "visual")
    if v.shape == "ball":
        ET.SubElement(el, "origin", {"xyz": _fmt(v.start - link_origin), "rpy": "0 0 0"})
        geom = ET.SubElement(el, "geometry")
        ET.SubElement(geom, "sphere", {"radius": _fmt([v.radius])})
    else:
        # URDF cylinders lie along their local z: turn z onto the rod's direction.
        d = v.end - v.start
        length = float(np.linalg.norm(d))
        rot = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), d / length).matrix()
        center = v.start + 0.5 * d
        ET.SubElement(
            el,
            "origin",
            {"xyz": _fmt(center - link_origin), "rpy": _fmt(pin.rpy.matrixToRpy(rot))},
        )
        geom = ET.SubElement(el, "geometry")
        ET.SubElement(geom, "cylinder", {"radius": _fmt([v.radius]), "length": _fmt([length])})
    ET.SubElement(el, "material", {"name": v.material})


def _fmt(values) -> str:
    """Shortest text that reads back to the same floats (and -0 as 0).

    A non-finite number would make the file unreadable to other tools (urdfdom
    rejects it): it is a bug upstream, never written.
    """
    values = [float(x) + 0.0 for x in values]
    if not all(math.isfinite(x) for x in values):
        raise PinSuspError(f"refusing to write a non-finite number ({values}) into a model file")
    return " ".join(map(repr, values))
