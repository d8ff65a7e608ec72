"""The trailing or semi-trailing arm: one revolute, no closure, no steering.

| body         | joint to parent                                             |
|--------------|-------------------------------------------------------------|
| chassis      | root (fixed to the world)                                   |
| trailing_arm | revolute about arm_pivot_inboard → arm_pivot_outboard       |

The arm carries the spindle (and a coilover's bottom). A pivot axis parallel
to y is a pure trailing arm; a skewed one a semi-trailing arm. Mobility 1
(bump); the instant axis is the pivot axis, and there is no kingpin.
"""

from __future__ import annotations

import numpy as np

from ..tree import Body, Tree
from . import (
    AXLE_POINTS,
    COILOVER_POINTS,
    MATERIALS,
    Pointwise,
    axis_foot,
    chassis_mounts,
    pivot,
    robot,
    visuals,
    wheel_mounts,
    xml_name,
)
from .double_wishbone import distinct, off_axis

NAME = "trailing_arm"
TITLE = "Trailing arm"
STEERING = ("none",)
ACTUATION = ("direct",)
MOUNTS = ("trailing_arm",)
SPRINGS = ("none", "coilover")  # a coilover from strut_top (chassis) to strut_bottom (arm)
WHEEL_BODY = "trailing_arm"
FORBIDDEN = {
    "config.camber_shim": "the camber shim is a double-wishbone option",
    "config.strut": "config.strut is the spring of a MacPherson strut (type: macpherson)",
}
PIVOT = ("arm_pivot_inboard", "arm_pivot_outboard")


def hardpoint_names(o) -> tuple[str, ...]:
    return PIVOT + AXLE_POINTS + (COILOVER_POINTS if o.spring == "coilover" else ())


def steering_points(o) -> tuple[()]:
    return ()


def upright_points(o) -> tuple[str, ...]:
    """The pivot points move with the arm as they do with the chassis: not at all."""
    return PIVOT + AXLE_POINTS


def wheel_side_points(o) -> tuple[str, ...]:
    return AXLE_POINTS + (("strut_bottom",) if o.spring == "coilover" else ())


def settle(p: dict) -> dict:
    return {}


def prepare(p: dict[str, np.ndarray], o, r) -> None:
    pairs = [(*PIVOT, "pivot axis")]
    if o.spring == "coilover":
        pairs.append(("strut_top", "strut_bottom", "coilover"))
    distinct(p, pairs, r)
    for point in ("axle_outboard", "strut_bottom")[: 2 if o.spring == "coilover" else 1]:
        off_axis(p, point, *PIVOT, r, f"lies on the arm's pivot axis ({PIVOT[0]}→{PIVOT[1]})")


def tree(g, shapes: bool = True) -> Tree:
    p = g.design_points()
    bodies = [Body("chassis"), Body("trailing_arm", "chassis", pivot("arm_pivot", *PIVOT, p))]
    body_of = dict.fromkeys(PIVOT, "chassis") | dict.fromkeys(AXLE_POINTS, "trailing_arm")
    body_of |= wheel_mounts("trailing_arm", g) | chassis_mounts(g)
    if g.spring == "coilover":
        body_of |= {"strut_top": "chassis", "strut_bottom": "trailing_arm"}
    points = {name: (body, p[name]) for name, body in body_of.items()}
    foot = axis_foot(p[PIVOT[0]], p[PIVOT[1]], p["axle_midpoint"])
    rods = [
        ("trailing_arm", "wishbone", p[PIVOT[0]], p[PIVOT[1]]),
        ("trailing_arm", "wishbone", foot, p["axle_midpoint"]),
        ("trailing_arm", "upright", p["axle_inboard"], p["axle_outboard"]),
    ]
    if g.spring == "coilover":
        rods.append(
            (
                "trailing_arm",
                "wishbone",
                axis_foot(p[PIVOT[0]], p[PIVOT[1]], p["strut_bottom"]),
                p["strut_bottom"],
            )
        )
    return Tree(
        name=xml_name(g.name),
        bodies=bodies,
        points=points,
        closures=[],
        visuals=visuals(g, p, body_of, rods, {"trailing_arm": "wishbone"}) if shapes else [],
        materials=MATERIALS,
        **robot(g),
    )


def kingpin(ps):
    return None  # no steering axis: caster, KPI, scrub and trail stay blank


def instant_planes(ps):
    return None  # the bump twist: a rotation about the pivot axis


def pointwise(o) -> Pointwise:
    arm = [*PIVOT, *AXLE_POINTS] + (["strut_bottom"] if o.spring == "coilover" else [])
    fixed = set(PIVOT) | ({"strut_top"} if o.spring == "coilover" else set())
    return Pointwise({"trailing_arm": arm}, [], [], fixed, None)
