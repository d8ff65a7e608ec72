"""Labelled corners' trees composed into one tree, with the elements they share
(README, How it works; docs/axle.md).

Each corner's tree (its mechanism module's) is prefixed by its label —
``left_upright``, ``left_upper_ball_joint``, ``left_wheel_center`` — and all hang
from one chassis; the bodies in ``SHARED`` (the chassis, the rack: one body on one
prismatic joint that carries every trackrod's inboard end) stay one. A corner's own
label ``""`` leaves its tree as it is. Each shared element (pin_susp/elements/) then
adds its bodies, joints, points and closures.
"""

from __future__ import annotations

from dataclasses import replace

from .tree import Body, Tree

SHARED = ("chassis", "rack")  # bodies every corner hangs from


def prefixed(tree: Tree, side: str) -> Tree:
    """The corner's tree with every body, joint, point and closure named ``side_…``;
    the chassis and the rack stay shared. The label ``""`` leaves the tree as it is."""
    if not side:
        return tree

    def body(name: str) -> str:
        return name if name in SHARED else f"{side}_{name}"

    def point(name: str) -> str:
        return f"{side}_{name}"

    def link(name: str) -> str:  # a closure anchor sits on a point's link or a body
        return point(name) if name in tree.points else body(name)

    bodies = [
        Body(
            body(b.name),
            None if b.parent is None else body(b.parent),
            None
            if b.joint is None or b.name in SHARED
            else replace(b.joint, name=body(b.joint.name)),
        )
        if b.name not in SHARED
        else b
        for b in tree.bodies
    ]
    points = {point(n): (body(b), p) for n, (b, p) in tree.points.items()}
    closures = [
        replace(
            c,
            name=f"{side}_{c.name}",
            anchors=tuple((link(a), p) for a, p in c.anchors),
            points=tuple(point(n) for n in c.points),
            branch=tuple(point(n) for n in c.branch),
            branch_fallback=tuple(point(n) for n in c.branch_fallback),
        )
        for c in tree.closures
    ]
    visuals = [replace(v, body=body(v.body)) for v in tree.visuals]
    # the spring's ends (two points, or a torsion bar's joint) and the wheel's body
    springs = [
        replace(
            s,
            side=side,
            ends=tuple(point(e) if e in tree.points else body(e) for e in s.ends),
        )
        for s in tree.springs
    ]
    corners = [
        {**m, "wheel_link": body(m["wheel_link"])} if "wheel_link" in m else dict(m)
        for m in tree.corners
    ]
    return Tree(
        f"{side}_{tree.name}",
        bodies,
        points,
        closures,
        visuals,
        dict(tree.materials),
        density=tree.density,
        wheel_mass=tree.wheel_mass,
        spring=springs,
        metadata=corners,
    )


def compose_tree(trees: dict, name: str, elements=()) -> Tree:
    """The labelled corners' trees (label → Tree) under one chassis, the shared bodies
    once (the first corner's), then each element's parts (``element.add_to``). The
    masses: the first corner's density and wheel mass; each corner's springs and
    ``<pin_susp:corner>``."""
    trees = {label: prefixed(tree, label) for label, tree in trees.items()}
    bodies, seen = [], set()
    for tree in trees.values():
        for b in tree.bodies:
            if b.name not in seen:  # the chassis, and the rack, once (the first's)
                bodies.append(b)
                seen.add(b.name)
    points, closures, visuals, materials = {}, [], [], {}
    springs, corners = [], []
    for tree in trees.values():
        points |= tree.points
        closures += tree.closures
        visuals += tree.visuals
        materials |= tree.materials
        springs += tree.springs
        corners += tree.corners
    for element in elements:
        element.add_to(bodies, points, closures, visuals, materials)
    first = next(iter(trees.values()))
    return Tree(
        name,
        bodies,
        points,
        closures,
        visuals,
        materials,
        density=first.density,
        wheel_mass=first.wheel_mass,
        spring=springs,
        metadata=corners,
    )
