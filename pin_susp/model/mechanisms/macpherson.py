"""The MacPherson strut corner (open-kinematics 0.4 format).

| body           | joint to parent                                        |
|----------------|--------------------------------------------------------|
| chassis        | root (fixed to the world)                              |
| lower_wishbone | revolute about inboard_front → inboard_rear            |
| upright        | ball at the lower ball joint (three revolutes)         |
| strut_rod      | prismatic along the strut axis, on the upright         |
| rack           | prismatic along Y (steering: rack only)                |

The strut is telescopic: its axis is the design line LBJ → strut_top, fixed
in the upright; the piston rod slides along it and its top is held at the
top mount by a ball closure (3 equations less the slide's freedom: the
point-on-line condition, 2). With the trackrod or fixed toe link (1
equation), mobility is 2 with a rack, 1 without. ``strut_bottom`` (the
clamp) sits on that line at its authored distance from the LBJ.
"""

from __future__ import annotations

import numpy as np

from ...maths.vectors import unit
from ..tree import Body, Closure, Joint, Tree
from . import (
    AXLE_POINTS,
    MATERIALS,
    STEERING_POINTS,
    Pointwise,
    chassis_mounts,
    pivot,
    rack_joint,
    rack_rod,
    robot,
    visuals,
    wheel_mounts,
    xml_name,
)
from .double_wishbone import arm_off_axis, arm_plane, distinct, steering_arm, steering_link

NAME = "macpherson"
TITLE = "MacPherson strut"
STEERING = ("rack", "none")
ACTUATION = ("direct",)
MOUNTS = ("upright",)
SPRINGS = ("coilover",)  # the strut is the spring and the damper
WHEEL_BODY = "upright"
FORBIDDEN = {
    "actuation": "the strut is the spring and damper of a MacPherson corner (no actuation)",
    "spring": "the strut is the spring and damper of a MacPherson corner "
    "(its rate goes in config.strut)",
    "config.camber_shim": "the camber shim is a double-wishbone option",
}

LOWER_ARM = (
    "lower_wishbone_inboard_front",
    "lower_wishbone_inboard_rear",
    "lower_wishbone_outboard",
)
LBJ, TOP, CLAMP = "lower_wishbone_outboard", "strut_top", "strut_bottom"
OFF_LINE = 1e-3  # m: how far the clamp may sit off the line LBJ → strut_top


def hardpoint_names(o) -> tuple[str, ...]:
    return LOWER_ARM + (TOP, CLAMP) + STEERING_POINTS[o.steering] + AXLE_POINTS


def steering_points(o) -> tuple[str, str]:
    return STEERING_POINTS[o.steering]


def wheel_side_points(o) -> tuple[str, ...]:
    return (LBJ, CLAMP, STEERING_POINTS[o.steering][1], *AXLE_POINTS)


def upright_points(o) -> tuple[str, ...]:
    return (LBJ, CLAMP, STEERING_POINTS[o.steering][1], *AXLE_POINTS)


def prepare(p: dict[str, np.ndarray], o, r) -> None:
    """Check the arm and the strut; put the clamp on the strut line (as authored
    within 1 mm), at its authored distance from the LBJ."""
    inner, outer = STEERING_POINTS[o.steering]
    distinct(
        p,
        [
            (LOWER_ARM[0], LOWER_ARM[1], "pivot axis"),
            (LBJ, TOP, "strut axis"),
            (inner, outer, "link"),
        ],
        r,
    )
    arm_off_axis(p, "lower_wishbone", r)
    steering_arm(p, outer, LBJ, TOP, r)
    axis = p[TOP] - p[LBJ]
    length = np.linalg.norm(axis)
    u = axis / length
    arm = p[CLAMP] - p[LBJ]
    along = arm @ u
    off = np.linalg.norm(arm - along * u)
    if off > OFF_LINE:
        r.fail(
            f"hardpoints.{CLAMP}",
            f"is {off * 1e3:.3g} mm off the strut line {LBJ}→{TOP} (at most 1 mm: the clamp "
            "sits on the strut, whose axis runs from the lower ball joint to the top mount)",
        )
    if not 0.0 < along < length:
        r.fail(
            f"hardpoints.{CLAMP}",
            f"must lie between {LBJ} and {TOP} on the strut line "
            f"({along * 1e3:.4g} mm from the LBJ along a {length * 1e3:.4g} mm line)",
        )
    p.update(settle(p))


def settle(p: dict) -> dict:
    """The clamp on the strut line LBJ → strut_top at its authored distance from the
    LBJ (works on jet.Duals: hardpoint sensitivities move it with the axis)."""
    return {
        CLAMP: p[LBJ]
        + np.linalg.norm(p[CLAMP] - p[LBJ], axis=-1, keepdims=True) * unit(p[TOP] - p[LBJ])
    }


def tree(g, shapes: bool = True) -> Tree:
    p = g.design_points()
    inner, outer = g.steering_points
    axis = unit(p[TOP] - p[LBJ])
    bodies = [
        Body("chassis"),
        Body("lower_wishbone", "chassis", pivot("lower_wishbone_pivot", *LOWER_ARM[:2], p)),
        Body(
            "upright",
            "lower_wishbone",
            Joint("lower_ball_joint", "ball", p[LBJ], defined_by=(LBJ,)),
        ),
        Body(
            "strut_rod",
            "upright",
            Joint("strut_slide", "prismatic", p[CLAMP], axis, defined_by=(LBJ, TOP)),
        ),
    ]
    if g.steering == "rack":
        bodies.append(Body("rack", "chassis", rack_joint(p, inner)))
    body_of = (
        {
            LOWER_ARM[0]: "chassis",
            LOWER_ARM[1]: "chassis",
            LBJ: "lower_wishbone",
            TOP: "chassis",
            CLAMP: "upright",
            inner: "rack" if g.steering == "rack" else "chassis",
            outer: "upright",
            "axle_inboard": "upright",
            "axle_outboard": "upright",
        }
        | wheel_mounts("upright", g)
        | chassis_mounts(g)
    )
    points = {name: (body, p[name]) for name, body in body_of.items()}
    closures = [
        # the strut's two assemblies: the top mount on the clamp's side of the LBJ, or
        # (the upright turned end for end) on the other
        Closure(
            "strut_top_mount",
            "ball",
            ((TOP, p[TOP]), ("strut_rod", p[TOP])),
            (TOP, TOP),
            branch=(LBJ, TOP, LBJ, CLAMP),
            branch_kind="alignment",
        ),
        steering_link(g, p, (LBJ, TOP, inner, outer)),
    ]
    rods = [
        ("lower_wishbone", "wishbone", p[LOWER_ARM[0]], p[LBJ]),
        ("lower_wishbone", "wishbone", p[LOWER_ARM[1]], p[LBJ]),
        ("upright", "upright", p[LBJ], p[CLAMP]),
        ("upright", "upright", p["axle_inboard"], p["axle_outboard"]),
        ("upright", "upright", p["axle_midpoint"], p[outer]),
        ("strut_rod", "strut", p[TOP], p[CLAMP]),
    ]
    if g.steering == "rack":
        rods.append(rack_rod(p, inner))
    return Tree(
        name=xml_name(g.name),
        bodies=bodies,
        points=points,
        closures=closures,
        visuals=visuals(g, p, body_of, rods, {"lower_wishbone": "wishbone"}) if shapes else [],
        materials=MATERIALS,
        **robot(g),
    )


def kingpin(ps):
    """The steering axis: LBJ → strut top mount."""
    return ps[LBJ], ps[TOP]


def instant_planes(ps):
    """The lower-arm plane, and the plane through the top mount normal to the strut."""
    return [arm_plane(ps, "lower_wishbone"), (unit(ps[TOP] - ps[LBJ]), ps[TOP])]


def pointwise(o) -> Pointwise:
    inner, outer = STEERING_POINTS[o.steering]
    parts = {
        "lower_wishbone": list(LOWER_ARM),
        "upright": [LBJ, CLAMP, outer, *AXLE_POINTS],
    }
    fixed = {LOWER_ARM[0], LOWER_ARM[1], TOP}
    if o.steering == "none":
        fixed.add(inner)
    return Pointwise(
        parts, [(outer, inner)], [(TOP, LBJ, CLAMP)], fixed, inner if o.steering == "rack" else None
    )
