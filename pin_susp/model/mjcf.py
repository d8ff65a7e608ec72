"""The corner's tree as MJCF, for MuJoCo and Pinocchio's MJCF parser.

The bodies and joints are those of the URDF (hinges, slides, the ball joint
as three hinges); every point is a ``<site>``. Loop closures become
``<equality><connect>``: a ball closure directly; a distance closure as a
rod body hung from its inboard end on a universal joint (two hinges normal
to the rod) whose outboard end is connected — two freedoms and three
equations leave exactly the one distance equation, with no free spin.
Everything sits under one joint-less ``chassis`` body (Pinocchio's MJCF
parser reads the first subtree only); a floating one (a vehicle's body,
``Tree.floating``) is on a ``<freejoint>`` above the road, a ``plane`` geom at
z = 0 that the tyres touch.

It simulates as written (docs/urdf.md): every body has the URDF's mass and
inertia (a closure's rod the mass of its drawn rod), every joint the URDF's
range; gravity is on; the spring is a tendon ``spring`` between its ends (a
torsion bar: the rocker pivot's stiffness) with the geometry's rate and
preload, and a damper (an axle's: ``left_spring`` and ``right_spring``); the
rack is held where ``ctrl`` puts it by the position actuator ``steering``; the
closures are stiff enough that a corner load opens them by micrometres, not
millimetres.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from ..errors import PinSuspError
from .geometry import unit
from .tree import (
    PLACEHOLDER_INERTIA,
    PLACEHOLDER_MASS,
    Tree,
    cylinder_inertia,
    design_rates,
    inertials,
    joint_limits,
    joint_steps,
    spring_sense,
)
from .urdf import number_text

ROD_RADIUS = 0.005  # m: a closure's rod body, drawn and weighed (at the tree's density)
GRAVITY = (0.0, 0.0, -9.81)  # m/s², ISO 8855: +Z up
TIMESTEP = 0.0005  # s: the stiff closures and the steering hold need it
# The spring where the geometry gives no rate (spring.rate / config.strut.rate): N/m,
# and a torsion bar's N·m/rad (50 N·m/deg)
SPRING_RATE = {"coilover": 50e3, "torsion_bar": 50.0 * 180.0 / np.pi}
# A torsion bar on a light rocker oscillates and diverges in MuJoCo (its stiffness is
# integrated explicitly, and a damper much stronger than the rocker's inertia fights the
# closures) unless the pivot has rotor inertia (armature): k·(ARMATURE_STEPS·timestep)²,
# its spring's period 2π·ARMATURE_STEPS timesteps, plus c·timestep/2 for the damper c
ARMATURE_STEPS = 5.0
STEERING_KP = 1e6  # N/m: the steering's hold on the rack
STEERING_KV = 2e3  # N·s/m
# Closures: MuJoCo's equality constraints are soft; these make them stiff (time
# constant 2 timesteps, MuJoCo's highest impedance). With its defaults (0.02 s,
# 0.9…0.95) the example pushrod corner under 1.5 kN settles 158 mm off the statics.
CLOSURE_SOLREF = "0.001 1"
# The road under a floating body (a vehicle's): the plane z = 0, which only the tyres touch
ROAD = {"type": "plane", "pos": "0 0 0", "size": "0 0 1", "rgba": "0.5 0.5 0.5 1"}
CLOSURE_SOLIMP = "0.9999 0.9999 0.001 0.5 2"


def tree_to_mjcf(tree: Tree, comment: str = "") -> str:
    root = ET.Element("mujoco", {"model": tree.name})
    ET.SubElement(root, "compiler", {"angle": "radian", "inertiafromgeom": "false"})
    ET.SubElement(
        root,
        "option",
        {
            "gravity": number_text(GRAVITY),
            "timestep": number_text([TIMESTEP]),
            "integrator": "implicitfast",
        },
    )
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "equality", {"solref": CLOSURE_SOLREF, "solimp": CLOSURE_SOLIMP})
    world = ET.SubElement(root, "worldbody")

    steps = joint_steps(tree)
    rates = design_rates(tree, steps)
    limits = joint_limits(steps, rates)
    masses = inertials(tree, steps)
    element, origin = {}, {}
    floating = tree.floating
    if floating is not None:  # the road under the floating body
        ET.SubElement(world, "geom", ROAD | {"name": floating.road})
    for body in tree.bodies:
        if body.joint is None:
            element[body.name] = ET.SubElement(world, "body", {"name": body.name, "pos": "0 0 0"})
            if floating is not None and floating.mass is not None:
                inertial = (floating.mass, floating.center, floating.inertia)
            else:
                inertial = (PLACEHOLDER_MASS, np.zeros(3), _placeholder())
            if floating is not None:
                ET.SubElement(element[body.name], "freejoint", {"name": floating.joint})
            _inertial(element[body.name], *inertial, 0.0)
            origin[body.name] = np.zeros(3)
    for s in steps:
        el = ET.SubElement(
            element[s.parent],
            "body",
            {"name": s.child, "pos": number_text(s.origin - origin[s.parent])},
        )
        reach = limits[s.name][0]
        ET.SubElement(
            el,
            "joint",
            {
                "name": s.name,
                "type": "slide" if s.kind == "prismatic" else "hinge",
                "pos": "0 0 0",
                "axis": number_text(s.axis),
                "limited": "true",
                "range": number_text([-reach, reach]),
            },
        )
        _inertial(el, *masses[s.child], s.origin)
        element[s.child], origin[s.child] = el, s.origin

    body_of = {name: body for name, (body, _) in tree.points.items()}
    for name, (body, position) in tree.points.items():
        ET.SubElement(
            element[body],
            "site",
            {"name": name, "pos": number_text(position - origin[body]), "size": "0.006"},
        )
    for v in tree.visuals:
        rgba = number_text(tree.materials[v.material])
        attrs = {"contype": "0", "conaffinity": "0", "group": "1", "rgba": rgba}
        if floating is not None and v.material == "tyre":  # on the road
            attrs |= {"contype": "1", "conaffinity": "1"}
        o = origin[v.body]
        if v.shape == "ball":
            attrs |= {
                "type": "sphere",
                "size": number_text([v.radius]),
                "pos": number_text(v.start - o),
            }
        else:
            attrs |= {
                "type": "cylinder" if v.material == "tyre" else "capsule",
                "size": number_text([v.radius]),
                "fromto": number_text(np.r_[v.start - o, v.end - o]),
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
                    "anchor": number_text(a - origin[body_a]),
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
            el = ET.SubElement(element[parent], "body", {"name": name, "pos": number_text(pos)})
            ET.SubElement(
                el,
                "joint",
                {
                    "name": f"{c.name}_rod_{k}",
                    "type": "hinge",
                    "pos": "0 0 0",
                    "axis": number_text(axis),
                },
            )
            if k == 1:
                _inertial(el, PLACEHOLDER_MASS, a, _placeholder(), a)
            else:  # the drawn rod, a solid cylinder
                mass = tree.density * np.pi * ROD_RADIUS**2 * np.linalg.norm(b - a)
                inertia = cylinder_inertia(mass, ROD_RADIUS, b - a)
                _inertial(el, mass, 0.5 * (a + b), inertia, a)
            element[name], origin[name] = el, a
            parent = name
        ET.SubElement(
            element[parent],
            "geom",
            {
                "type": "capsule",
                "size": number_text([ROD_RADIUS]),
                "fromto": number_text(np.r_[0, 0, 0, b - a]),
                "contype": "0",
                "conaffinity": "0",
                "group": "1",
                "rgba": "0.18 0.62 0.31 1",
            },
        )
        ET.SubElement(
            equality,
            "connect",
            {"name": c.name, "body1": parent, "body2": body_b, "anchor": number_text(b - a)},
        )
    _spring(root, element, tree, steps, rates)
    if any(s.name == "rack_slide" for s in steps):
        actuator = ET.SubElement(root, "actuator")
        reach = limits["rack_slide"][0]
        ET.SubElement(
            actuator,
            "position",
            {
                "name": "steering",
                "joint": "rack_slide",
                "kp": number_text([STEERING_KP]),
                "kv": number_text([STEERING_KV]),
                "ctrlrange": number_text([-reach, reach]),
            },
        )

    ET.indent(root)
    head = f"<!-- {comment} -->\n" if comment else ""
    return head + ET.tostring(root, encoding="unicode") + "\n"


def _placeholder() -> np.ndarray:
    return PLACEHOLDER_INERTIA * np.eye(3)


def _inertial(body, mass: float, center, inertia: np.ndarray, body_origin) -> None:
    """``fullinertia`` is ixx iyy izz ixy ixz iyz (body axes = world axes at design)."""
    ET.SubElement(
        body,
        "inertial",
        {
            "pos": number_text(np.asarray(center) - body_origin),
            "mass": number_text([mass]),
            "fullinertia": number_text(inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]),
        },
    )


def _spring(root, element: dict, tree: Tree, steps: list, rates) -> None:
    """A coilover: a spatial tendon ``spring`` through its two sites, of stiffness k and
    spring length ℓ₀ + P/k (its force is the preload P at the design length ℓ₀, and
    grows by k per metre of compression), with the damper. A torsion bar: the rocker
    pivot's stiffness k about a reference −s·P/k (s: the sense bump turns it), so that
    it resists bump with P at design, with the damper and the armature that keeps
    MuJoCo's explicit spring stable. An axle's springs: one per side, the tendons
    ``left_spring`` and ``right_spring`` (or each side's rocker pivot's stiffness)."""
    tendon = None
    for spring in tree.springs:
        rate = SPRING_RATE[spring.kind] if spring.rate is None else spring.rate
        if spring.kind == "coilover":
            top, bottom = spring.ends
            length = float(np.linalg.norm(tree.points[bottom][1] - tree.points[top][1]))
            if tendon is None:
                tendon = ET.SubElement(root, "tendon")
            el = ET.SubElement(
                tendon,
                "spatial",
                {
                    "name": "spring" if spring.side is None else f"{spring.side}_spring",
                    "stiffness": number_text([rate]),
                    "springlength": number_text([length + spring.preload / rate]),
                    "damping": number_text([spring.damping]),
                    "width": "0.012",
                    "rgba": number_text(tree.materials.get("strut", (0.8, 0.15, 0.15, 1.0))),
                },
            )
            ET.SubElement(el, "site", {"site": top})
            ET.SubElement(el, "site", {"site": bottom})
            continue
        sense = spring_sense(tree, steps, rates, spring)
        for joint in root.iter("joint"):
            if joint.get("name") == spring.ends[0]:
                joint.set("stiffness", number_text([rate]))
                joint.set("springref", number_text([-sense * spring.preload / rate]))
                joint.set("damping", number_text([spring.damping]))
                armature = rate * (ARMATURE_STEPS * TIMESTEP) ** 2 + 0.5 * spring.damping * TIMESTEP
                joint.set("armature", number_text([armature]))


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
    from .urdf import model_file_root, not_this_model

    root, problem = model_file_root(text, "MJCF")
    if problem:
        return problem
    ours, theirs = _elements(ET.fromstring(tree_to_mjcf(tree))), _elements(root)
    return not_this_model("MJCF", tree.name, {k: ours[k] for k in KINDS}, theirs, name=_name)


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
            elif child.tag == "freejoint":  # a floating root (a vehicle's body)
                found["joint"].setdefault(child.get("name", ""), ("of type", "free"))
    for site in root.findall("./worldbody/site"):
        found["site"].setdefault(site.get("name", ""), ("on body", "world"))
    for equality in root.iter("equality"):
        for child in equality:
            found["equality constraint"].setdefault(child.get("name", ""), (child.tag,))
    return found
