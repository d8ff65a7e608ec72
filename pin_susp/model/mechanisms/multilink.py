"""The five-link corner: the upright held by five rigid links (docs/geometry.md).

| body             | joint to parent                                          |
|------------------|----------------------------------------------------------|
| chassis          | root (fixed to the world)                                |
| lower_front_link | universal at its inboard end (two revolutes normal to it)|
| upright          | ball at the link's outboard end (three revolutes)        |
| rack             | prismatic along Y (steering: rack only)                  |

The other links — upper front, upper rear, lower rear — and the trackrod (or
fixed toe link) are distance closures between their ends (4 equations). The
upright then has 5 − 4 = 1 freedom with the rack held: mobility 2 with a
rack (bump, steer), 1 with a fixed toe link. Outboard ends of two links may
coincide (two links meeting in one ball joint): a multilink whose upper and
lower link pairs meet in points is a double wishbone.

The steering axis is the virtual kingpin through the two virtual ball
joints — for each link pair the midpoint of the common perpendicular of the
two link lines at the current pose. The instant centres come from the
upright's bump twist (``instant_planes`` is None).
"""

from __future__ import annotations

import numpy as np

from ...maths.vectors import unit
from ..tree import Body, Closure, Joint, Tree
from . import (
    AXLE_POINTS,
    COILOVER_POINTS,
    MATERIALS,
    STEERING_POINTS,
    Pointwise,
    chassis_mounts,
    common_perpendicular_midpoint,
    rack_joint,
    rack_rod,
    robot,
    visuals,
    wheel_mounts,
    xml_name,
)
from .double_wishbone import distinct, steering_link

NAME = "multilink"
TITLE = "Five-link multilink"
STEERING = ("rack", "none")
ACTUATION = ("direct",)
MOUNTS = ("upright",)
SPRINGS = ("none", "coilover")  # a coilover from strut_top (chassis) to strut_bottom (upright)
WHEEL_BODY = "upright"
FORBIDDEN = {
    "config.camber_shim": "the camber shim is a double-wishbone option",
    "config.strut": "config.strut is the spring of a MacPherson strut (type: macpherson)",
}

LINKS = ("upper_front_link", "upper_rear_link", "lower_front_link", "lower_rear_link")
TREE_LINK = "lower_front_link"  # the link that carries the upright in the tree
RANK_TOLERANCE = 1e-9  # relative singular value below which the link lines are dependent


def ends(link: str) -> tuple[str, str]:
    return f"{link}_inboard", f"{link}_outboard"


def hardpoint_names(o) -> tuple[str, ...]:
    names = tuple(p for link in LINKS for p in ends(link))
    names += STEERING_POINTS[o.steering] + AXLE_POINTS
    if o.spring == "coilover":
        names += COILOVER_POINTS
    return names


def steering_points(o) -> tuple[str, str]:
    return STEERING_POINTS[o.steering]


def upright_points(o) -> tuple[str, ...]:
    return tuple(ends(link)[1] for link in LINKS) + (STEERING_POINTS[o.steering][1], *AXLE_POINTS)


def wheel_side_points(o) -> tuple[str, ...]:
    names = upright_points(o)
    return names + (("strut_bottom",) if o.spring == "coilover" else ())


def settle(p: dict) -> dict:
    return {}


def prepare(p: dict[str, np.ndarray], o, r) -> None:
    """Distinct link ends, and five link lines that leave the upright exactly one
    motion with the rack held (that it moves the wheel up and down is checked on
    the model: Linkage._check_mobility)."""
    inner, outer = STEERING_POINTS[o.steering]
    pairs = [(*ends(link), "link") for link in LINKS] + [(inner, outer, "link")]
    if o.spring == "coilover":
        pairs.append(("strut_top", "strut_bottom", "coilover"))
    distinct(p, pairs, r)
    members = [ends(link) for link in LINKS] + [(inner, outer)]
    lines = _plucker(p, members)
    rank = np.linalg.matrix_rank(lines, tol=RANK_TOLERANCE * np.linalg.norm(lines, 2))
    if rank < len(members):
        tol = RANK_TOLERANCE * np.linalg.norm(lines, 2)
        dependent = [  # the links any one of which the others make redundant
            i
            for i in range(len(members))
            if np.linalg.matrix_rank(np.delete(lines, i, axis=0), tol=tol) == rank
        ]
        redundant = members[dependent[0]][1]
        named = ", ".join(f"{a}→{b}" for a, b in (members[i] for i in dependent))
        r.fail(
            f"hardpoints.{redundant}",
            f"the five links leave the upright free: their lines are dependent (rank {rank} "
            f"of 5; this link adds no constraint the others do not), so the upright has "
            f"{6 - rank} freedoms{' with the rack held' if o.steering == 'rack' else ''}, "
            f"not 1 (the dependent lines: {named})",
        )


def _plucker(p, members) -> np.ndarray:
    """Rows (p × u, u) of each member's line: a twist (ω, v₀) keeps the member's length
    when row · twist = 0, i.e. u · (v₀ + ω × p) = 0."""
    rows = []
    for a, b in members:
        u = unit(p[b] - p[a])
        rows.append(np.r_[np.cross(p[a], u), u])
    return np.array(rows)


def tree(g, shapes: bool = True) -> Tree:
    p = g.design_points()
    inner, outer = g.steering_points
    t_in, t_out = ends(TREE_LINK)
    along = unit(p[t_out] - p[t_in])
    side = np.cross(along, [0.0, 0.0, 1.0])
    if np.linalg.norm(side) < 1e-6:
        side = np.cross(along, [1.0, 0.0, 0.0])
    u1 = unit(side)
    bodies = [
        Body("chassis"),
        Body(
            TREE_LINK,
            "chassis",
            Joint(
                f"{TREE_LINK}_inboard_joint",
                "universal",
                p[t_in],
                u1,
                (t_in,),
                axis2=np.cross(along, u1),
            ),
        ),
        Body(
            "upright",
            TREE_LINK,
            Joint(f"{TREE_LINK}_outboard_joint", "ball", p[t_out], defined_by=(t_out,)),
        ),
    ]
    if g.steering == "rack":
        bodies.append(Body("rack", "chassis", rack_joint(p, inner)))
    body_of = {p_in: "chassis" for p_in, _ in map(ends, LINKS)}
    body_of |= {ends(link)[1]: "upright" for link in LINKS if link != TREE_LINK}
    body_of[t_out] = TREE_LINK
    body_of |= {inner: "rack" if g.steering == "rack" else "chassis", outer: "upright"}
    body_of |= dict.fromkeys(AXLE_POINTS, "upright") | wheel_mounts("upright", g)
    body_of |= chassis_mounts(g)
    if g.spring == "coilover":
        body_of |= {"strut_top": "chassis", "strut_bottom": "upright"}
    points = {name: (body, p[name]) for name, body in body_of.items()}

    # Branches: each link's outboard end against a plane of points it does not move.
    uf, ur, lf, lr = (ends(link) for link in LINKS)
    branch = {
        "upper_front_link": (ur[0], uf[0], lf[1], uf[1]),
        "upper_rear_link": (uf[0], ur[0], lf[1], ur[1]),
        "lower_rear_link": (lf[0], lr[0], uf[1], lr[1]),
    }
    closures = [
        Closure(link, "distance", tuple((n, p[n]) for n in ends(link)), ends(link), branch[link])
        for link in LINKS
        if link != TREE_LINK
    ]
    closures.append(steering_link(g, p, (lf[1], uf[1], inner, outer)))
    rods = [(TREE_LINK, "wishbone", p[t_in], p[t_out])]
    rods += [("upright", "upright", p[ends(link)[1]], p["axle_midpoint"]) for link in LINKS]
    rods += [
        ("upright", "upright", p["axle_inboard"], p["axle_outboard"]),
        ("upright", "upright", p["axle_midpoint"], p[outer]),
    ]
    if g.steering == "rack":
        rods.append(rack_rod(p, inner))
    return Tree(
        name=xml_name(g.name),
        bodies=bodies,
        points=points,
        closures=closures,
        visuals=visuals(g, p, body_of, rods, {TREE_LINK: "wishbone"}) if shapes else [],
        materials=MATERIALS,
        **robot(g),
    )


def kingpin(ps):
    """The virtual kingpin: lower and upper virtual ball joints (each link pair's
    common-perpendicular midpoint at the current pose)."""
    uf, ur, lf, lr = (ends(link) for link in LINKS)
    lower = common_perpendicular_midpoint(ps[lf[0]], ps[lf[1]], ps[lr[0]], ps[lr[1]])
    upper = common_perpendicular_midpoint(ps[uf[0]], ps[uf[1]], ps[ur[0]], ps[ur[1]])
    return lower, upper


def instant_planes(ps):
    return None  # the bump twist gives the instant centres


def pointwise(o) -> Pointwise:
    inner, outer = STEERING_POINTS[o.steering]
    upright = [*upright_points(o)]
    if o.spring == "coilover":
        upright.append("strut_bottom")
    links = [ends(link) for link in LINKS] + [(outer, inner)]
    fixed = {ends(link)[0] for link in LINKS} | ({"strut_top"} if o.spring == "coilover" else set())
    if o.steering == "none":
        fixed.add(inner)
    return Pointwise(
        {"upright": upright}, links, [], fixed, inner if o.steering == "rack" else None
    )
