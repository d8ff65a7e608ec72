"""A kinematic tree (tree.py: bodies, joints, points, loop closures) ↔ URDF text.

A mechanism module (e.g. ``double_wishbone.py``) describes its tree in world
coordinates at the design state; this module writes it as URDF (metres) and reads
the loop closures back. Conventions of the file:

- every link frame is world-aligned at the design state, so joint value 0
  is the design state and each joint origin is a plain offset;
- a ball joint is three revolutes about z, y, x through two massless links
  (URDF has no ball joint);
- every point is a link on a fixed joint, so it shows as a frame in any
  URDF tool;
- loop closures are ``<pin_susp:loop_closure>`` elements (a namespace every
  URDF parser ignores), each with two ``<pin_susp:frame link=… xyz=…/>``;
- every moving link has an ``<inertial>``: its drawn shapes as solids
  (:func:`inertials`); the root has none (it is fixed to the world, or a floating
  body's mass is on a point's link, ``tree.FloatingBase``), and a tree without
  visuals (a study's variants) is written without any;
- each joint's limits are what the wheel's and the rack's travel ask of it,
  to first order, with a margin (:func:`joint_limits`);
- ``<pin_susp:corner>``, ``<pin_susp:spring>`` and
  ``<pin_susp:design_configuration>`` say which side, which tyre, which spring
  and which joint values are the design state (an axle: a corner and a spring
  per side, each with its ``side``); ``<pin_susp:floating_base>`` that the root
  link floats (a vehicle's body on the road).

docs/urdf.md has the rules and their numbers.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import PinSuspError
from .tree import (
    EFFORT,
    Step,
    Tree,
    Visual,
    design_rates,
    inertials,
    joint_limits,
    joint_steps,
    spring_sense,
)

NAMESPACE = "https://github.com/pin-susp/pin_susp/urdf"


def tree_to_urdf(tree: Tree, comment: str = "") -> str:
    """Render the tree as URDF text (metres, full float precision)."""
    robot = ET.Element("robot", {"name": tree.name, "xmlns:pin_susp": NAMESPACE})
    for name, rgba in tree.materials.items():
        mat = ET.SubElement(robot, "material", {"name": name})
        ET.SubElement(mat, "color", {"rgba": number_text(rgba)})

    steps = joint_steps(tree)
    rates = design_rates(tree, steps)
    limits = joint_limits(steps, rates)
    # without any shape (a study's variants, never exported) the file stays kinematic
    masses = inertials(tree, steps) if tree.visuals else {}
    origin_of = {}  # link name → world position of its frame
    links = {}
    for body in tree.bodies:
        if body.joint is None:
            origin_of[body.name] = np.zeros(3)
            links[body.name] = ET.SubElement(robot, "link", {"name": body.name})
    for s in steps:
        links[s.child] = ET.SubElement(robot, "link", {"name": s.child})
        if masses:
            _inertial(links[s.child], *masses[s.child], s.origin)
        xyz = s.origin - origin_of[s.parent]
        _joint(robot, s.name, s.kind, s.parent, s.child, xyz, s.axis, limits[s.name])
        origin_of[s.child] = s.origin

    for v in tree.visuals:
        _visual(links[v.body], v, origin_of[v.body])

    floating = tree.floating
    for name, (body, position) in tree.points.items():
        link = ET.SubElement(robot, "link", {"name": name})
        if floating is not None and name == floating.frame and floating.mass is not None:
            _inertial(link, floating.mass, floating.center, floating.inertia, position)
        _joint(robot, f"{body}_to_{name}", "fixed", body, name, position - origin_of[body])
        origin_of[name] = position

    for c in tree.closures:
        el = ET.SubElement(robot, "pin_susp:loop_closure", {"name": c.name, "type": c.kind})
        for link, position in c.anchors:
            ET.SubElement(
                el, "pin_susp:frame", {"link": link, "xyz": number_text(position - origin_of[link])}
            )
    _metadata(robot, tree, steps, rates)

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


def _joint(robot, name, kind, parent, child, xyz, axis=None, limits=None):
    j = ET.SubElement(robot, "joint", {"name": name, "type": kind})
    ET.SubElement(j, "parent", {"link": parent})
    ET.SubElement(j, "child", {"link": child})
    ET.SubElement(j, "origin", {"xyz": number_text(xyz), "rpy": "0 0 0"})
    if kind == "fixed":
        return
    ET.SubElement(j, "axis", {"xyz": number_text(axis)})
    reach, speed = limits
    ET.SubElement(
        j,
        "limit",
        {
            "lower": number_text([-reach]),
            "upper": number_text([reach]),
            "effort": number_text([EFFORT]),
            "velocity": number_text([speed]),
        },
    )


def _inertial(link, mass: float, center: np.ndarray, inertia: np.ndarray, origin: np.ndarray):
    el = ET.SubElement(link, "inertial")
    ET.SubElement(el, "origin", {"xyz": number_text(center - origin), "rpy": "0 0 0"})
    ET.SubElement(el, "mass", {"value": number_text([mass])})
    names = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    values = inertia[np.triu_indices(3)]
    ET.SubElement(el, "inertia", {n: number_text([v]) for n, v in zip(names, values, strict=True)})


def _metadata(robot, tree: Tree, steps: list[Step], rates) -> None:
    """The corner's side, tyre and spring (an axle's: each side's), and its design
    configuration (all joints 0)."""
    for corner in tree.corners:
        ET.SubElement(robot, "pin_susp:corner", dict(corner))
    for spring in tree.springs:
        attrs = {} if spring.side is None else {"side": spring.side}
        attrs["type"] = spring.kind
        if spring.kind == "coilover":
            attrs |= {"top": spring.ends[0], "bottom": spring.ends[1]}
        else:
            sense = spring_sense(tree, steps, rates, spring)
            attrs |= {"joint": spring.ends[0], "bump": number_text([sense])}
        if spring.rate is not None:
            attrs["rate"] = number_text([spring.rate])
        attrs["preload"] = number_text([spring.preload])
        attrs["damping"] = number_text([spring.damping])
        ET.SubElement(robot, "pin_susp:spring", attrs)
    if tree.floating is not None:  # the root is no world: a tool adds a floating base
        root = next(b.name for b in tree.bodies if b.parent is None)
        attrs = {"link": root, "mass_link": tree.floating.frame, "road_z": "0.0"}
        ET.SubElement(robot, "pin_susp:floating_base", attrs)
    design = ET.SubElement(robot, "pin_susp:design_configuration")
    for s in steps:
        ET.SubElement(design, "pin_susp:joint", {"name": s.name, "value": "0.0"})


def _visual(link, v: Visual, link_origin: np.ndarray):
    el = ET.SubElement(link, "visual")
    if v.shape == "ball":
        ET.SubElement(el, "origin", {"xyz": number_text(v.start - link_origin), "rpy": "0 0 0"})
        geom = ET.SubElement(el, "geometry")
        ET.SubElement(geom, "sphere", {"radius": number_text([v.radius])})
    else:
        # URDF cylinders lie along their local z: turn z onto the rod's direction.
        d = v.end - v.start
        length = float(np.linalg.norm(d))
        rot = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), d / length).matrix()
        center = v.start + 0.5 * d
        ET.SubElement(
            el,
            "origin",
            {
                "xyz": number_text(center - link_origin),
                "rpy": number_text(pin.rpy.matrixToRpy(rot)),
            },
        )
        geom = ET.SubElement(el, "geometry")
        ET.SubElement(
            geom, "cylinder", {"radius": number_text([v.radius]), "length": number_text([length])}
        )
    ET.SubElement(el, "material", {"name": v.material})


def number_text(values) -> str:
    """Shortest text that reads back to the same floats (and -0 as 0).

    A non-finite number would make the file unreadable to other tools (urdfdom
    rejects it): it is a bug upstream, never written.
    """
    values = [float(x) + 0.0 for x in values]
    if not all(math.isfinite(x) for x in values):
        raise PinSuspError(f"refusing to write a non-finite number ({values}) into a model file")
    return " ".join(map(repr, values))


# the two model files a user may hand back to validate: (format, root tag, command)
MODEL_FILES = {"URDF": ("robot", "urdf"), "MJCF": ("mujoco", "mjcf")}


def model_file_root(text: str, kind: str) -> tuple[ET.Element | None, str | None]:
    """A model file's XML root (``kind``: URDF or MJCF), or why the text is not one:
    empty, not text, not XML, or the other format."""
    tag, command = MODEL_FILES[kind]
    if not text.strip():
        return None, f"is empty: expected the {kind} written by pin-susp {command}"
    if "\x00" in text or "\ufffd" in text:
        return None, f"is not a text file: expected the {kind} (XML) written by pin-susp {command}"
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        return None, f"is not valid XML ({exc})"
    if root.tag != tag:
        other = next((k for k, (t, _) in MODEL_FILES.items() if t == root.tag), None)
        article = {"URDF": "a URDF", "MJCF": "an MJCF"}
        what = f" ({article[other]}?)" if other else ""
        return None, f"is not {kind}{what}: its root element is <{root.tag}>, not <{tag}>"
    return root, None


def not_this_model(kind: str, tree_name: str, ours: dict, theirs: dict, name=str) -> str | None:
    """Why a model file (``kind``: URDF or MJCF) is not this geometry's, from its
    elements and ours (element kind → {name: description}); None when they match."""
    differences = []
    for element, mine in ours.items():
        yours = theirs[element]
        differences += [f"missing {element} {name(n)}" for n in mine if n not in yours]
        differences += [
            f"has a {element} {name(n)} this model does not have" for n in yours if n not in mine
        ]
        differences += [
            f"{element} {name(n)} is {' '.join(yours[n])}, not {' '.join(mine[n])}"
            for n in mine
            if n in yours and yours[n] != mine[n]
        ]
    if not differences:
        return None
    more = f" (and {len(differences) - 1} more differences)" if len(differences) > 1 else ""
    command = MODEL_FILES[kind][1]
    return (
        f"is not the {kind} of this geometry ({tree_name}): {differences[0]}{more}; "
        f"write it with pin-susp {command} GEOMETRY -o FILE"
    )
