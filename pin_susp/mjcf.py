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

from .geometry import unit
from .urdf import BALL_AXES, Tree, _fmt

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
        if j.kind == "ball":
            steps = [
                (f"{j.name}_link_{k}" if i < 2 else body.name, f"{j.name}_{k}", "hinge", a)
                for i, (k, a) in enumerate(BALL_AXES)
            ]
        else:
            kind = "slide" if j.kind == "prismatic" else "hinge"
            steps = [(body.name, j.name, kind, j.axis)]
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
