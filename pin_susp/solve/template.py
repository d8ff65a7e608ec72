"""A study's variants built on one Pinocchio model (docs/studies.md, Speed).

The variants of one geometry share their tree's structure — the same bodies,
joints, points and closures — and differ only in where those are: every link
frame is world-aligned at design (model/urdf.py), so the model that Pinocchio
parses from a variant's URDF is the first variant's with other joint origins,
joint axes and frame offsets. The first variant of a structure is built from
its URDF text as any model is; each later one is a copy of that model with its
own numbers set, the same floats the URDF text would have carried (written with
full precision, read back exactly). A tree with a floating root (a vehicle's
body, whose mass sits on a point's link) is always built from its text.

The copied model's joint limits are the first variant's: nothing solved reads
them (they are the URDF's, for other tools).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..model.tree import joint_steps
from ..model.urdf import ClosureSpec

_KEEP = 8  # structures remembered (a study has one; an axle's and a corner's differ)
_TEMPLATES: dict = {}
_AXES = {(1.0, 0.0, 0.0): "x", (0.0, 1.0, 0.0): "y", (0.0, 0.0, 1.0): "z"}


def _origins(tree, steps) -> dict:
    """link name → world position of its frame at design (the root links at 0, each
    point's link at the point)."""
    origin = {b.name: np.zeros(3) for b in tree.bodies if b.joint is None}
    for s in steps:
        origin[s.child] = s.origin
    for name, (_, position) in tree.points.items():  # each point is a link of its own
        origin[name] = position
    return origin


def signature(tree, steps) -> tuple:
    """What a model parsed from the tree's URDF is made of, without its numbers: a
    joint along a coordinate axis is another kind of Pinocchio joint than one along
    any other axis."""
    return (
        tree.name,
        tuple(
            (s.name, s.kind, s.parent, s.child, _AXES.get(tuple(map(float, s.axis)), "u"))
            for s in steps
        ),
        tuple((name, body) for name, (body, _) in tree.points.items()),
        tuple((c.name, c.kind, tuple(link for link, _ in c.anchors)) for c in tree.closures),
    )


def closure_specs(tree, origin: dict) -> list[ClosureSpec]:
    """The loop closures as urdf.read_closures reads them back from the tree's URDF."""
    return [
        ClosureSpec(c.name, c.kind, tuple((link, p - origin[link]) for link, p in c.anchors))
        for c in tree.closures
    ]


class _Template:
    """A parsed model and how to place a variant's numbers in a copy of it: per joint
    its step (by name), per frame the link or point whose design position it is at."""

    def __init__(self, model: pin.Model, tree, steps):
        self.model = pin.Model(model)
        self.ok = False
        by_name = {s.name: s for s in steps}
        self.joints = []  # (joint index, its step, its parent joint's step or None)
        for i in range(1, model.njoints):
            step = by_name.get(model.names[i])
            if step is None:
                return
            parent = model.parents[i]
            self.joints.append((i, step, by_name[model.names[parent]] if parent else None))
        points = {name: name for name in tree.points}
        points |= {f"{body}_to_{name}": name for name, (body, _) in tree.points.items()}
        links = {s.name: s.child for s in steps} | {s.child: s.child for s in steps}
        roots = {b.name for b in tree.bodies if b.joint is None}
        self.frames = []  # (frame index, "point" | "link", name)
        for f, frame in enumerate(model.frames):
            name = frame.name
            if name in points:
                self.frames.append((f, "point", points[name]))
            elif name in links:
                self.frames.append((f, "link", links[name]))
            elif f and name not in roots:  # the universe, a root link: at 0 always
                return
        # the numbers it was parsed from must come back exactly: else no template
        self.ok = self._same(model, tree, steps)

    def _same(self, model, tree, steps) -> bool:
        copy = self.place(tree, steps)
        for a, b in zip(copy.jointPlacements, model.jointPlacements, strict=True):
            if not (
                np.array_equal(a.translation, b.translation)
                and np.array_equal(a.rotation, b.rotation)
            ):
                return False
        for a, b in zip(copy.frames, model.frames, strict=True):
            if not np.array_equal(a.placement.homogeneous, b.placement.homogeneous):
                return False
        for i, _, _ in self.joints:
            if model.joints[i].shortname().endswith("Unaligned"):
                if not np.array_equal(
                    copy.joints[i].extract().axis, model.joints[i].extract().axis
                ):
                    return False
        return True

    def tree_like(self, model: pin.Model):
        """The bulk.Tree of a placed copy (from the template model's, built once)."""
        from .bulk import Tree

        if "_tree" not in self.__dict__:
            self._tree = Tree(self.model)
        return Tree.like(self._tree, model)

    def place(self, tree, steps) -> pin.Model:
        """A copy of the model with the tree's joint origins, axes and frame offsets."""
        model = pin.Model(self.model)
        origin = _origins(tree, steps)
        by_name = {s.name: s for s in steps}
        eye = np.eye(3)
        joint_at = {}
        for i, template_step, parent in self.joints:
            s = by_name[template_step.name]
            base = by_name[parent.name].origin if parent is not None else np.zeros(3)
            model.jointPlacements[i] = pin.SE3(eye, s.origin - base)
            joint_at[i] = s.origin
            joint = model.joints[i]
            if joint.shortname().endswith("Unaligned"):
                kind = (
                    pin.JointModelRevoluteUnaligned
                    if s.kind == "revolute"
                    else pin.JointModelPrismaticUnaligned
                )
                new = kind(*map(float, s.axis))  # normalised, as the URDF parser's
                new.setIndexes(joint.id, joint.idx_q, joint.idx_v, joint.idx_vExtended)
                model.joints[i] = pin.JointModel(new)
        for f, what, name in self.frames:
            frame = model.frames[f]
            at = tree.points[name][1] if what == "point" else origin[name]
            base = joint_at.get(frame.parentJoint, np.zeros(3))
            frame.placement = pin.SE3(eye, at - base)
            model.frames[f] = frame
        return model


def variant_model(tree, parse, closures: bool = True, bulk: bool = True):
    """(model, closure specs, its bulk.Tree or None) of a variant's tree: a copy of the
    model of the first tree of its structure with its own numbers, and its bulk tree
    likewise (``parse(tree)`` → (model, specs) builds one from the URDF text, for the
    first of each structure and for any tree this module cannot place); ``closures``:
    the specs read (else None); ``bulk``: the bulk tree made (else None)."""
    if tree.floating is not None:
        return (*parse(tree), None)
    steps = joint_steps(tree)
    key = signature(tree, steps)
    template = _TEMPLATES.get(key)
    if template is None:
        model, specs = parse(tree)
        if len(_TEMPLATES) >= _KEEP:
            _TEMPLATES.pop(next(iter(_TEMPLATES)))
        _TEMPLATES[key] = _Template(model, tree, steps)
        return model, specs, None
    if not template.ok:
        return (*parse(tree), None)
    model = template.place(tree, steps)
    specs = closure_specs(tree, _origins(tree, steps)) if closures else None
    return model, specs, template.tree_like(model) if bulk else None
