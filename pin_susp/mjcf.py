"""The corner's tree as MJCF, for MuJoCo and Pinocchio's MJCF parser.

The bodies and joints are those of the URDF (hinges, slides, the ball joint
as three hinges); every point is a ``<site>``. Loop closures become
``<equality><connect>``: a ball closure directly; a distance closure as a
rod body hung from its inboard end on a universal joint (two hinges normal
to the rod) whose outboard end is connected — two freedoms and three
equations leave exactly the one distance equation, with no free spin.
Everything sits under one joint-less ``chassis`` body (Pinocchio's MJCF
parser reads the first subtree only).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from .errors import PinSuspError
from .geometry import unit
from .urdf import Tree, _fmt

MASS = "0.001"  # kg; kinematics only, but MuJoCo needs moving bodies to have mass
INERTIA = "1e-06 1e-06 1e-06"


def tree_to_mjcf(tree: Tree, comment: str = "") -> str:
    root = ET.Element("mujoco", {"model": tree.name})
    ET.SubElement(root, "compiler", {"angle": "radian", "inertiafromgeom": "false"})
    ET.SubElement(root, "option", {"gravity": "0 0 0"})
    world = ET.SubElement(root, "worldbody")

    element, origin = {}, {}
    for body in tree.bodies:
        if body.joint is None:
            element[body.name] = ET.SubElement(world, "body", {"name": body.name, "pos": "0 0 0"})
            ET.SubElement(
                element[body.name],
                "inertial",
                {"pos": "0 0 0", "mass": MASS, "diaginertia": INERTIA},
            )
            origin[body.name] = np.zeros(3)
            continue
        j = body.joint
        parent = body.parent
        parts = j.steps()
        steps = [
            (
                body.name if i == len(parts) - 1 else f"{j.name}_link{suffix}",
                f"{j.name}{suffix}",
                "slide" if kind == "prismatic" else "hinge",
                axis,
            )
            for i, (suffix, kind, axis) in enumerate(parts)
        ]
        for name, joint, kind, axis in steps:
            el = ET.SubElement(
                element[parent], "body", {"name": name, "pos": _fmt(j.origin - origin[parent])}
            )
            ET.SubElement(
                el, "joint", {"name": joint, "type": kind, "pos": "0 0 0", "axis": _fmt(axis)}
            )
            ET.SubElement(el, "inertial", {"pos": "0 0 0", "mass": MASS, "diaginertia": INERTIA})
            element[name], origin[name] = el, j.origin
            parent = name

    body_of = {name: body for name, (body, _) in tree.points.items()}
    for name, (body, position) in tree.points.items():
        ET.SubElement(
            element[body],
            "site",
            {"name": name, "pos": _fmt(position - origin[body]), "size": "0.006"},
        )
    for v in tree.visuals:
        rgba = _fmt(tree.materials[v.material])
        attrs = {"contype": "0", "conaffinity": "0", "group": "1", "rgba": rgba}
        o = origin[v.body]
        if v.shape == "ball":
            attrs |= {"type": "sphere", "size": _fmt([v.radius]), "pos": _fmt(v.start - o)}
        else:
            attrs |= {
                "type": "cylinder" if v.material == "tyre" else "capsule",
                "size": _fmt([v.radius]),
                "fromto": _fmt(np.r_[v.start - o, v.end - o]),
            }
        ET.SubElement(element[v.body], "geom", attrs)

    equality = ET.SubElement(root, "equality")
    for c in tree.closures:
        (link_a, a), (link_b, b) = c.anchors
        body_a, body_b = body_of.get(link_a, link_a), body_of.get(link_b, link_b)
        if c.kind == "ball":
            ET.SubElement(
                equality,
                "connect",
                {
                    "name": c.name,
                    "body1": body_a,
                    "body2": body_b,
                    "anchor": _fmt(a - origin[body_a]),
                },
            )
            continue
        rod = unit(b - a)
        side = np.cross(rod, [0.0, 0.0, 1.0])
        if np.linalg.norm(side) < 1e-6:
            side = np.cross(rod, [1.0, 0.0, 0.0])
        u1 = unit(side)
        u2 = np.cross(rod, u1)
        parent = body_a
        for k, axis in ((1, u1), (2, u2)):
            name = f"{c.name}_rod" if k == 2 else f"{c.name}_rod_link"
            pos = a - origin[parent] if k == 1 else np.zeros(3)
            el = ET.SubElement(element[parent], "body", {"name": name, "pos": _fmt(pos)})
            ET.SubElement(
                el,
                "joint",
                {"name": f"{c.name}_rod_{k}", "type": "hinge", "pos": "0 0 0", "axis": _fmt(axis)},
            )
            ET.SubElement(el, "inertial", {"pos": "0 0 0", "mass": MASS, "diaginertia": INERTIA})
            element[name], origin[name] = el, a
            parent = name
        ET.SubElement(
            element[parent],
            "geom",
            {
                "type": "capsule",
                "size": "0.005",
                "fromto": _fmt(np.r_[0, 0, 0, b - a]),
                "contype": "0",
                "conaffinity": "0",
                "group": "1",
                "rgba": "0.18 0.62 0.31 1",
            },
        )
        ET.SubElement(
            equality,
            "connect",
            {"name": c.name, "body1": parent, "body2": body_b, "anchor": _fmt(b - a)},
        )

    ET.indent(root)
    head = f"<!-- {comment} -->\n" if comment else ""
    return head + ET.tostring(root, encoding="unicode") + "\n"


# what identifies the MJCF of a corner: its named elements, by kind, in this order
KINDS = ("site", "body", "joint", "equality constraint")


def check_mjcf(text: str, tree: Tree, source: str = "MJCF") -> None:
    """Raise PinSuspError unless ``text`` is the MJCF :func:`tree_to_mjcf` writes for ``tree``.

    The text must be XML with a ``<mujoco>`` root holding the same named
    sites, bodies, joints and equality constraints (sites on the same bodies,
    joints of the same types); positions are not compared, so the MJCF of a
    corner whose hardpoints moved since the export passes, and the comparison
    of the solutions shows the difference.
    """
    problem = _mjcf_problem(text, tree)
    if problem:
        raise PinSuspError(f"{source}: {problem}")


def _mjcf_problem(text: str, tree: Tree) -> str | None:
    if not text.strip():
        return "is empty: expected the MJCF written by pin-susp mjcf"
    if "\x00" in text or "\ufffd" in text:
        return "is not a text file: expected the MJCF (XML) written by pin-susp mjcf"
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        return f"is not valid XML ({exc})"
    if root.tag != "mujoco":
        what = " (a URDF?)" if root.tag == "robot" else ""
        return f"is not MJCF{what}: its root element is <{root.tag}>, not <mujoco>"
    ours, theirs = _elements(ET.fromstring(tree_to_mjcf(tree))), _elements(root)
    differences = []
    for kind in KINDS:
        mine, yours = ours[kind], theirs[kind]
        differences += [f"missing {kind} {_name(n)}" for n in mine if n not in yours]
        differences += [
            f"has a {kind} {_name(n)} this model does not have" for n in yours if n not in mine
        ]
        differences += [
            f"{kind} {_name(n)} is {' '.join(yours[n])}, not {' '.join(mine[n])}"
            for n in mine
            if n in yours and yours[n] != mine[n]
        ]
    if not differences:
        return None
    more = f" (and {len(differences) - 1} more differences)" if len(differences) > 1 else ""
    return (
        f"is not the MJCF of this geometry ({tree.name}): {differences[0]}{more}; "
        "write it with pin-susp mjcf GEOMETRY -o FILE"
    )


def _name(name: str) -> str:
    return name or "(unnamed)"


def _elements(root: ET.Element) -> dict[str, dict[str, tuple[str, ...]]]:
    """Named elements by kind, each with what must match: a site's body, a joint's type."""
    found: dict[str, dict[str, tuple[str, ...]]] = {kind: {} for kind in KINDS}
    for body in root.iter("body"):
        found["body"].setdefault(body.get("name", ""), ())
        for child in body:
            if child.tag == "site":
                found["site"].setdefault(child.get("name", ""), ("on body", body.get("name", "")))
            elif child.tag == "joint":
                found["joint"].setdefault(
                    child.get("name", ""), ("of type", child.get("type", "hinge"))
                )
    for site in root.findall("./worldbody/site"):
        found["site"].setdefault(site.get("name", ""), ("on body", "world"))
    for equality in root.iter("equality"):
        for child in equality:
            found["equality constraint"].setdefault(child.get("name", ""), (child.tag,))
    return found
