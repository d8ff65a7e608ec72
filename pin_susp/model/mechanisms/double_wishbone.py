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

from ...maths.vectors import COINCIDENT, unit
from ..tree import Body, Closure, Joint, Tree
from . import (
    MATERIALS,
    STEERING_POINTS,
    Pointwise,
    axis_foot,
    chassis_mounts,
    pivot,
    rack_joint,
    rack_rod,
    robot,
    visuals,
    wheel_mounts,
    xml_name,
)

NAME = "double_wishbone"
TITLE = "Double wishbone"
STEERING = ("rack", "none")
ACTUATION = ("direct", "pushrod_rocker")
MOUNTS = ("lower_wishbone", "upright")
SPRINGS = ("none", "coilover", "torsion_bar")
WHEEL_BODY = "upright"
# keys of the file that this mechanism does not take: key → why
FORBIDDEN = {"config.strut": "config.strut is the spring of a MacPherson strut (type: macpherson)"}

WISHBONE_POINTS = (
    "lower_wishbone_inboard_front",
    "lower_wishbone_inboard_rear",
    "lower_wishbone_outboard",
    "upper_wishbone_inboard_front",
    "upper_wishbone_inboard_rear",
    "upper_wishbone_outboard",
)
AXLE_POINTS = ("axle_inboard", "axle_outboard")
PUSHROD_ROCKER_POINTS = ("pushrod_outboard", "pushrod_inboard", "rocker_axis_a", "rocker_axis_b")
COILOVER_POINTS = ("strut_top", "strut_bottom")
LBJ, UBJ = "lower_wishbone_outboard", "upper_wishbone_outboard"


def hardpoint_names(o) -> tuple[str, ...]:
    names = WISHBONE_POINTS + STEERING_POINTS[o.steering] + AXLE_POINTS
    if o.actuation == "pushrod_rocker":
        names += PUSHROD_ROCKER_POINTS
    if o.spring == "coilover":
        names += COILOVER_POINTS
    return names


def steering_points(o) -> tuple[str, str]:
    return STEERING_POINTS[o.steering]


def wheel_side_points(o) -> tuple[str, ...]:
    names = (LBJ, UBJ, STEERING_POINTS[o.steering][1], *AXLE_POINTS)
    if o.actuation_mount == "upright":
        if o.actuation == "pushrod_rocker":
            names += ("pushrod_outboard",)
        elif o.spring == "coilover":
            names += ("strut_bottom",)
    return names


def upright_points(o) -> tuple[str, ...]:
    return (LBJ, UBJ, STEERING_POINTS[o.steering][1], *AXLE_POINTS)


def prepare(p: dict[str, np.ndarray], o, r) -> None:
    """Reject geometry that defines no mechanism: coincident ends, balls on pivots."""
    inner, outer = STEERING_POINTS[o.steering]
    pairs = [
        ("lower_wishbone_inboard_front", "lower_wishbone_inboard_rear", "pivot axis"),
        ("upper_wishbone_inboard_front", "upper_wishbone_inboard_rear", "pivot axis"),
        (LBJ, UBJ, "steering axis"),
        (inner, outer, "link"),
    ]
    if o.spring == "coilover":
        pairs.append(("strut_top", "strut_bottom", "coilover"))
    if o.actuation == "pushrod_rocker":
        pairs.append(("rocker_axis_a", "rocker_axis_b", "rocker axis"))
        pairs.append(("pushrod_outboard", "pushrod_inboard", "pushrod"))
    distinct(p, pairs, r)
    for arm in ("lower_wishbone", "upper_wishbone"):
        arm_off_axis(p, arm, r)
    steering_arm(p, outer, LBJ, UBJ, r)
    if o.actuation == "pushrod_rocker":
        off_axis(
            p,
            "pushrod_inboard",
            "rocker_axis_a",
            "rocker_axis_b",
            r,
            "lies on the rocker axis (rocker_axis_a→rocker_axis_b): the pushrod cannot turn it",
        )


STEERING_ARM = 1e-3  # m: the least distance of the trackrod's outer end from the kingpin


def steering_arm(p, outer: str, lower: str, upper: str, r) -> None:
    """The trackrod (or toe link) must reach the upright away from the steering axis:
    on it, the link cannot turn the upright, and 'bump' would steer it instead."""
    axis = unit(p[upper] - p[lower])
    arm = p[outer] - p[lower]
    if np.linalg.norm(arm - axis * (arm @ axis)) < STEERING_ARM:
        r.fail(
            f"hardpoints.{outer}",
            f"lies on the steering axis {lower}→{upper} (within 1 mm): the link has no "
            "steering arm to hold the upright's turn about it",
        )


def arm_off_axis(p, arm: str, r) -> None:
    off_axis(
        p,
        f"{arm}_outboard",
        f"{arm}_inboard_front",
        f"{arm}_inboard_rear",
        r,
        f"lies on the {arm} pivot axis (inboard_front→inboard_rear): the arm has no length",
    )


def settle(p: dict) -> dict:
    """Hardpoints placed by others (none here; see macpherson.settle)."""
    return {}


def distinct(p, pairs, r) -> None:
    """Each (a, b, what): two points that must not coincide."""
    for a, b, what in pairs:
        if np.linalg.norm(p[b] - p[a]) < COINCIDENT:
            r.fail(f"hardpoints.{b}", f"coincides with {a}: the {what} needs two distinct points")


def off_axis(p, point: str, a: str, b: str, r, problem: str) -> None:
    """A point that an axis a → b turns must not lie on that axis."""
    axis = unit(p[b] - p[a])
    arm = p[point] - p[a]
    if np.linalg.norm(arm - axis * (arm @ axis)) < COINCIDENT:
        r.fail(f"hardpoints.{point}", problem)


def tree(g, shapes: bool = True) -> Tree:
    """Bodies, joints, points and closures of one corner at its design state (its
    drawn shapes too with ``shapes``)."""
    p = g.design_points()
    inner, outer = g.steering_points

    bodies = [
        Body("chassis"),
        Body(
            "lower_wishbone",
            "chassis",
            pivot(
                "lower_wishbone_pivot",
                "lower_wishbone_inboard_front",
                "lower_wishbone_inboard_rear",
                p,
            ),
        ),
        Body(
            "upright",
            "lower_wishbone",
            Joint("lower_ball_joint", "ball", p[LBJ], defined_by=(LBJ,)),
        ),
        Body(
            "upper_wishbone",
            "chassis",
            pivot(
                "upper_wishbone_pivot",
                "upper_wishbone_inboard_front",
                "upper_wishbone_inboard_rear",
                p,
            ),
        ),
    ]
    if g.steering == "rack":
        bodies.append(Body("rack", "chassis", rack_joint(p, inner)))
    if g.has_pushrod:
        bodies.append(
            Body("rocker", "chassis", pivot("rocker_pivot", "rocker_axis_a", "rocker_axis_b", p))
        )

    body_of = (
        {
            "lower_wishbone_inboard_front": "chassis",
            "lower_wishbone_inboard_rear": "chassis",
            LBJ: "lower_wishbone",
            "upper_wishbone_inboard_front": "chassis",
            "upper_wishbone_inboard_rear": "chassis",
            UBJ: "upper_wishbone",
            inner: "rack" if g.steering == "rack" else "chassis",
        }
        | upright_mounts(g)
        | chassis_mounts(g)
    )
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
            ((UBJ, p[UBJ]), ("upright", p[UBJ])),
            (UBJ, UBJ),
            branch=("upper_wishbone_inboard_front", "upper_wishbone_inboard_rear", LBJ, UBJ),
            # an upper pivot on the LBJ leaves that plane undefined: the LBJ's circle
            # about the lower pivot meets the upright's sphere about the UBJ on either
            # side of the plane (lower pivot axis, UBJ) — the upright upside down
            branch_fallback=(
                "lower_wishbone_inboard_front",
                "lower_wishbone_inboard_rear",
                UBJ,
                LBJ,
            ),
        ),
        steering_link(g, p, (LBJ, UBJ, inner, outer)),
    ]
    if g.has_pushrod:
        closures.append(pushrod(p))
    return Tree(
        name=xml_name(g.name),
        bodies=bodies,
        points=points,
        closures=closures,
        visuals=_visuals(g, p, body_of) if shapes else [],
        materials=MATERIALS,
        **robot(g),
    )


def steering_link(g, p, branch) -> Closure:
    """The trackrod (rack) or the fixed toe link: a distance between its ends."""
    inner, outer = g.steering_points
    return Closure(
        "trackrod" if g.steering == "rack" else "toe_link",
        "distance",
        ((inner, p[inner]), (outer, p[outer])),
        (inner, outer),
        branch=branch,
    )


def pushrod(p) -> Closure:
    ends = ("pushrod_outboard", "pushrod_inboard")
    return Closure(
        "pushrod",
        "distance",
        tuple((n, p[n]) for n in ends),
        ends,
        branch=("rocker_axis_a", "rocker_axis_b", "pushrod_outboard", "pushrod_inboard"),
    )


def upright_mounts(g) -> dict[str, str]:
    """Points carried by the upright (its body below a camber shim), incl. derived ones."""
    names = [g.steering_points[1], "axle_inboard", "axle_outboard"]
    if g.actuation_mount == "upright":
        if g.has_pushrod:
            names.append("pushrod_outboard")
        elif g.spring == "coilover":
            names.append("strut_bottom")
    return dict.fromkeys(names, "upright") | wheel_mounts("upright", g)


def kingpin(ps):
    """The ball joints: LBJ → UBJ."""
    return ps[LBJ], ps[UBJ]


def instant_planes(ps):
    """The wishbone planes (pivot axis and ball joint)."""
    return [arm_plane(ps, arm) for arm in ("upper_wishbone", "lower_wishbone")]


def arm_plane(ps, arm: str):
    front = ps[f"{arm}_inboard_front"]
    n = unit(np.cross(ps[f"{arm}_inboard_rear"] - front, ps[f"{arm}_outboard"] - front))
    return n, front


def pointwise(o) -> Pointwise:
    inner, outer = STEERING_POINTS[o.steering]
    parts = {
        "lower_wishbone": [*WISHBONE_POINTS[:3]],
        "upper_wishbone": [*WISHBONE_POINTS[3:]],
        "upright": [LBJ, UBJ, outer, *AXLE_POINTS],
    }
    links = [(outer, inner)]
    fixed = {*WISHBONE_POINTS[:2], *WISHBONE_POINTS[3:5]}
    mount = "upright" if o.actuation_mount == "upright" else "lower_wishbone"
    if o.actuation == "pushrod_rocker":
        parts[mount].append("pushrod_outboard")
        parts["rocker"] = ["rocker_axis_a", "rocker_axis_b", "pushrod_inboard"]
        if o.spring == "coilover":
            parts["rocker"].append("strut_bottom")
        links.append(("pushrod_outboard", "pushrod_inboard"))
        fixed |= {"rocker_axis_a", "rocker_axis_b"}
    elif o.spring == "coilover":
        parts[mount].append("strut_bottom")
    if o.spring == "coilover":
        fixed.add("strut_top")
    if o.steering == "none":
        fixed.add(inner)
    return Pointwise(parts, links, [], fixed, inner if o.steering == "rack" else None)


def _visuals(g, p, body_of):
    inner, outer = g.steering_points
    lbj, ubj = p[LBJ], p[UBJ]
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
        rods.append(rack_rod(p, inner))
    if g.has_pushrod:
        rods.append(("rocker", "rocker", p["rocker_axis_a"], p["rocker_axis_b"]))
        for arm_end in ("pushrod_inboard", "strut_bottom"):
            if body_of.get(arm_end) == "rocker":
                foot = axis_foot(p["rocker_axis_a"], p["rocker_axis_b"], p[arm_end])
                rods.append(("rocker", "rocker", foot, p[arm_end]))
    return visuals(
        g, p, body_of, rods, {"lower_wishbone": "wishbone", "upper_wishbone": "wishbone"}
    )
