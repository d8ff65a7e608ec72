"""The double-wishbone corner as a kinematic tree plus loop closures.

| body           | joint to parent                                   |
|----------------|---------------------------------------------------|
| chassis        | root (fixed to the world)                         |
| lower_wishbone | revolute about inboard_front → inboard_rear       |
| upright        | ball at the lower ball joint (three revolutes)    |
| upper_wishbone | revolute about inboard_front → inboard_rear       |
| rack           | prismatic along Y (steering: rack only)           |

Closures: the upper ball joint (upright = upper wishbone, 3 equations) and
the trackrod or fixed toe link (a distance, 1 equation). Mobility is
nv − 4: bump and steer with a rack, bump alone with a fixed toe link.
"""

from __future__ import annotations

import numpy as np

from .geometry import Geometry, unit
from .urdf import Body, Closure, Joint, Tree, Visual

MATERIALS = {
    "chassis": (0.35, 0.35, 0.38, 1.0),
    "wishbone": (0.12, 0.42, 0.85, 1.0),
    "upright": (0.90, 0.45, 0.10, 1.0),
    "rack": (0.20, 0.65, 0.30, 1.0),
    "tyre": (0.08, 0.08, 0.08, 0.45),
    "strut": (0.80, 0.15, 0.15, 1.0),
}
ROD = 0.008  # m, visual radius of links
BALL = 0.014  # m, visual radius of joints


def corner_tree(g: Geometry) -> Tree:
    """Bodies, joints, points and closures of one corner at its design state."""
    p = g.design_points()
    lbj, ubj = p["lower_wishbone_outboard"], p["upper_wishbone_outboard"]
    inner, outer = g.steering_points

    bodies = [
        Body("chassis"),
        Body("lower_wishbone", "chassis", _pivot("lower_wishbone", p)),
        Body("upright", "lower_wishbone", Joint("lower_ball_joint", "ball", lbj)),
        Body("upper_wishbone", "chassis", _pivot("upper_wishbone", p)),
    ]
    if g.steering == "rack":
        bodies.append(
            Body(
                "rack", "chassis", Joint("rack_slide", "prismatic", p[inner], np.array([0, 1.0, 0]))
            )
        )

    body_of = {
        "lower_wishbone_inboard_front": "chassis",
        "lower_wishbone_inboard_rear": "chassis",
        "lower_wishbone_outboard": "lower_wishbone",
        "upper_wishbone_inboard_front": "chassis",
        "upper_wishbone_inboard_rear": "chassis",
        "upper_wishbone_outboard": "upper_wishbone",
        inner: "rack" if g.steering == "rack" else "chassis",
        outer: "upright",
        "axle_inboard": "upright",
        "axle_outboard": "upright",
    }
    if g.spring == "coilover":
        body_of["strut_top"] = "chassis"
        body_of["strut_bottom"] = g.actuation_mount
    for name in ("axle_midpoint", "wheel_center", "wheel_inboard", "wheel_outboard"):
        body_of[name] = "upright"
    points = {name: (body, p[name]) for name, body in body_of.items()}

    closures = [
        Closure(
            "upper_ball_joint",
            "ball",
            (("upper_wishbone_outboard", ubj), ("upright", ubj)),
        ),
        Closure(
            "trackrod" if g.steering == "rack" else "toe_link",
            "distance",
            ((inner, p[inner]), (outer, p[outer])),
        ),
    ]
    return Tree(
        name=_xml_name(g.name),
        bodies=bodies,
        points=points,
        closures=closures,
        visuals=_visuals(g, p, body_of),
        materials=MATERIALS,
    )


def _pivot(arm: str, p: dict[str, np.ndarray]) -> Joint:
    front = p[f"{arm}_inboard_front"]
    axis = unit(p[f"{arm}_inboard_rear"] - front)
    return Joint(f"{arm}_pivot", "revolute", front, axis)


def _visuals(g: Geometry, p: dict[str, np.ndarray], body_of: dict[str, str]) -> list[Visual]:
    inner, outer = g.steering_points
    rods = [
        ("lower_wishbone", "wishbone", "lower_wishbone_inboard_front", "lower_wishbone_outboard"),
        ("lower_wishbone", "wishbone", "lower_wishbone_inboard_rear", "lower_wishbone_outboard"),
        ("upper_wishbone", "wishbone", "upper_wishbone_inboard_front", "upper_wishbone_outboard"),
        ("upper_wishbone", "wishbone", "upper_wishbone_inboard_rear", "upper_wishbone_outboard"),
        ("upright", "upright", "lower_wishbone_outboard", "upper_wishbone_outboard"),
        ("upright", "upright", "axle_inboard", "axle_outboard"),
        ("upright", "upright", "axle_midpoint", outer),
    ]
    visuals = [Visual(body, "rod", mat, p[a], p[b], ROD) for body, mat, a, b in rods]
    if g.steering == "rack":
        # The rack runs from the trackrod's inboard end to the car's centre plane.
        centre = p[inner] * np.array([1.0, 0.0, 1.0])
        if np.linalg.norm(p[inner] - centre) > 1e-6:
            visuals.append(Visual("rack", "rod", "rack", centre, p[inner], ROD))
    # The tyre: a disc of the real radius and section width.
    visuals.append(
        Visual("upright", "rod", "tyre", p["wheel_inboard"], p["wheel_outboard"], g.wheel.radius)
    )
    for name, body in body_of.items():
        if name in g.hardpoints:
            material = "strut" if name.startswith("strut") else _material(body)
            visuals.append(Visual(body, "ball", material, p[name], radius=BALL))
    return visuals


def _material(body: str) -> str:
    return {"lower_wishbone": "wishbone", "upper_wishbone": "wishbone"}.get(body, body)


def _xml_name(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "corner"
