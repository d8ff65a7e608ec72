"""The double-wishbone corner as a kinematic tree plus loop closures.

| body           | joint to parent                                   |
|----------------|---------------------------------------------------|
| chassis        | root (fixed to the world)                         |
| lower_wishbone | revolute about inboard_front → inboard_rear       |
| upright        | ball at the lower ball joint (three revolutes)    |
| upper_wishbone | revolute about inboard_front → inboard_rear       |
| rack           | prismatic along Y (steering: rack only)           |
| rocker         | revolute about rocker_axis_a → b (pushrod_rocker) |

Closures: the upper ball joint (upright = upper wishbone, 3 equations),
the trackrod or fixed toe link (a distance, 1 equation) and, with a
pushrod-rocker, the pushrod (a distance, 1 equation, which takes the
rocker's freedom). Mobility is 2 with a rack (bump, steer), 1 with a fixed
toe link (bump).
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
    "rocker": (0.55, 0.25, 0.70, 1.0),
    "tyre": (0.08, 0.08, 0.08, 0.45),
    "strut": (0.80, 0.15, 0.15, 1.0),
}
ROD = 0.008  # m, visual radius of links
BALL = 0.014  # m, visual radius of joints
Y = np.array([0.0, 1.0, 0.0])


def corner_tree(g: Geometry) -> Tree:
    """Bodies, joints, points and closures of one corner at its design state."""
    p = g.design_points()
    lbj, ubj = p["lower_wishbone_outboard"], p["upper_wishbone_outboard"]
    inner, outer = g.steering_points

    bodies = [
        Body("chassis"),
        Body("lower_wishbone", "chassis", _pivot("lower_wishbone", p)),
        Body(
            "upright",
            "lower_wishbone",
            Joint("lower_ball_joint", "ball", lbj, defined_by=("lower_wishbone_outboard",)),
        ),
        Body("upper_wishbone", "chassis", _pivot("upper_wishbone", p)),
    ]
    if g.steering == "rack":
        bodies.append(Body("rack", "chassis", Joint("rack_slide", "prismatic", p[inner], Y)))
    if g.has_pushrod:
        a, b = p["rocker_axis_a"], p["rocker_axis_b"]
        pivot = Joint(
            "rocker_pivot", "revolute", a, unit(b - a), ("rocker_axis_a", "rocker_axis_b")
        )
        bodies.append(Body("rocker", "chassis", pivot))

    body_of = {
        "lower_wishbone_inboard_front": "chassis",
        "lower_wishbone_inboard_rear": "chassis",
        "lower_wishbone_outboard": "lower_wishbone",
        "upper_wishbone_inboard_front": "chassis",
        "upper_wishbone_inboard_rear": "chassis",
        "upper_wishbone_outboard": "upper_wishbone",
        inner: "rack" if g.steering == "rack" else "chassis",
    } | upright_mounts(g)
    if g.has_pushrod:
        body_of |= {
            "pushrod_outboard": g.actuation_mount,
            "pushrod_inboard": "rocker",
            "rocker_axis_a": "chassis",
            "rocker_axis_b": "chassis",
        }
    if g.spring == "coilover":
        body_of["strut_top"] = "chassis"
        body_of["strut_bottom"] = "rocker" if g.has_pushrod else g.actuation_mount
    points = {name: (body, p[name]) for name, body in body_of.items()}

    # Each loop's branch: the UBJ's circle about the upper pivot meets the upright's
    # sphere about the LBJ on either side of the plane (pivot axis, LBJ); the
    # steering arm's circle about the kingpin meets the trackrod's sphere on either
    # side of the plane (kingpin, trackrod inboard); likewise the rocker.
    closures = [
        Closure(
            "upper_ball_joint",
            "ball",
            (("upper_wishbone_outboard", ubj), ("upright", ubj)),
            ("upper_wishbone_outboard", "upper_wishbone_outboard"),
            branch=(
                "upper_wishbone_inboard_front",
                "upper_wishbone_inboard_rear",
                "lower_wishbone_outboard",
                "upper_wishbone_outboard",
            ),
        ),
        Closure(
            "trackrod" if g.steering == "rack" else "toe_link",
            "distance",
            ((inner, p[inner]), (outer, p[outer])),
            (inner, outer),
            branch=("lower_wishbone_outboard", "upper_wishbone_outboard", inner, outer),
        ),
    ]
    if g.has_pushrod:
        ends = ("pushrod_outboard", "pushrod_inboard")
        closures.append(
            Closure(
                "pushrod",
                "distance",
                tuple((n, p[n]) for n in ends),
                ends,
                branch=("rocker_axis_a", "rocker_axis_b", "pushrod_outboard", "pushrod_inboard"),
            )
        )
    return Tree(
        name=_xml_name(g.name),
        bodies=bodies,
        points=points,
        closures=closures,
        visuals=_visuals(g, p, body_of),
        materials=MATERIALS,
    )


def upright_mounts(g: Geometry) -> dict[str, str]:
    """Points carried by the upright (its body below a camber shim), incl. derived ones."""
    names = [g.steering_points[1], "axle_inboard", "axle_outboard"]
    if g.actuation_mount == "upright":
        if g.has_pushrod:
            names.append("pushrod_outboard")
        elif g.spring == "coilover":
            names.append("strut_bottom")
    names += ["axle_midpoint", "wheel_center", "wheel_inboard", "wheel_outboard"]
    return dict.fromkeys(names, "upright")


def _pivot(arm: str, p: dict[str, np.ndarray]) -> Joint:
    front = p[f"{arm}_inboard_front"]
    axis = unit(p[f"{arm}_inboard_rear"] - front)
    return Joint(
        f"{arm}_pivot",
        "revolute",
        front,
        axis,
        (f"{arm}_inboard_front", f"{arm}_inboard_rear"),
    )


def _visuals(g: Geometry, p: dict[str, np.ndarray], body_of: dict[str, str]) -> list[Visual]:
    inner, outer = g.steering_points
    lbj, ubj = p["lower_wishbone_outboard"], p["upper_wishbone_outboard"]
    rods = [
        ("lower_wishbone", "wishbone", p["lower_wishbone_inboard_front"], lbj),
        ("lower_wishbone", "wishbone", p["lower_wishbone_inboard_rear"], lbj),
        ("upper_wishbone", "wishbone", p["upper_wishbone_inboard_front"], ubj),
        ("upper_wishbone", "wishbone", p["upper_wishbone_inboard_rear"], ubj),
        ("upright", "upright", lbj, ubj),
        ("upright", "upright", p["axle_inboard"], p["axle_outboard"]),
        ("upright", "upright", p["axle_midpoint"], p[outer]),
    ]
    if g.steering == "rack":
        # The rack runs from the trackrod's inboard end to the car's centre plane.
        centre = p[inner] * np.array([1.0, 0.0, 1.0])
        if np.linalg.norm(p[inner] - centre) > 1e-6:
            rods.append(("rack", "rack", centre, p[inner]))
    if g.has_pushrod:
        rods.append(("rocker", "rocker", p["rocker_axis_a"], p["rocker_axis_b"]))
        for arm_end in ("pushrod_inboard", "strut_bottom"):
            if body_of.get(arm_end) == "rocker":
                rods.append(("rocker", "rocker", _axis_foot(p, arm_end), p[arm_end]))
    visuals = [Visual(body, "rod", mat, a, b, ROD) for body, mat, a, b in rods]
    # The tyre: a disc of the real radius and section width.
    visuals.append(
        Visual("upright", "rod", "tyre", p["wheel_inboard"], p["wheel_outboard"], g.wheel.radius)
    )
    for name, body in body_of.items():
        if name in g.hardpoints:
            material = "strut" if name.startswith("strut") else _material(body)
            visuals.append(Visual(body, "ball", material, p[name], radius=BALL))
    return visuals


def _axis_foot(p: dict[str, np.ndarray], name: str) -> np.ndarray:
    """The point of the rocker axis nearest ``name``: where a rocker arm starts."""
    a = p["rocker_axis_a"]
    axis = unit(p["rocker_axis_b"] - a)
    return a + axis * ((p[name] - a) @ axis)


def _material(body: str) -> str:
    return {"lower_wishbone": "wishbone", "upper_wishbone": "wishbone"}.get(body, body)


def _xml_name(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "corner"
