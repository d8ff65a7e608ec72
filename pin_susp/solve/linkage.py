"""A corner's linkage: URDF → Pinocchio model, its points, closures and branches.

The Pinocchio model is parsed from the generated URDF text, and the loop
closures are read back from that same text: the URDF is the one
description of the mechanism. A Linkage is the geometry exactly as given
(no setup applied) and knows no sweeps: the setup solves (``setup.py``)
build on it, and so does :class:`pin_susp.subjects.corner.Corner`, which applies the
setup first — so the dependency runs corner → setup → linkage.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin

from .. import __version__
from ..columns.metrics import HUB_Z, RACK, TOE_LINK, metric_columns
from ..constraints import (
    BallClosure,
    ContactPatchPoint,
    DistanceClosure,
    FramePoint,
    JointTarget,
    Kinematics,
    LoopBranch,
    PointTarget,
)
from ..errors import InputError
from ..maths.jet import Dual, cross
from ..model.compose import compose_tree
from ..model.deadcentre import dead_centres
from ..model.geometry import DERIVED_POINTS, Geometry, contact_patch, unit
from ..model.urdf import read_closures, tree_to_urdf
from .bulk import rows_of, seed_tree, solve_all, tree_of
from .solver import NewtonSolver
from .template import variant_model

RACK_HELD = "rack held at design (the sweep gives no rack target)"


class Built:
    """A tree as a Pinocchio model: the URDF text, the model parsed from it, a
    FramePoint per named point, the loop closures read back from the same text
    (lengths from the design frames) and each loop's branch at design."""

    def __init__(self, tree, comment: str = "", template: bool = False):
        """``template``: a study's variant, on a copy of the first model of its tree's
        structure (template.py); its URDF text is written when first read."""
        self._tree, self._comment, self._urdf = tree, comment, None
        known = None  # its bulk tree, where a template gives it
        if template:
            self.model, specs, known = variant_model(tree, self._parse)
        else:
            self.model, specs = self._parse(tree)
        anchors = {}
        for spec in specs:
            for i, (link, offset) in enumerate(spec.anchors):
                anchors[spec.name, i] = self._add_anchor(f"{spec.name}/{i}", link, offset)
        self.kin = Kinematics(self.model)  # data after every frame is added
        if known is not None:
            seed_tree(self.kin, known)
        self.points = {
            name: FramePoint(name, self.model.getFrameId(name), body)
            for name, (body, _) in tree.points.items()
        }
        self.q_design = pin.neutral(self.model)
        self.kin.update(self.q_design)
        self.closures = []
        for spec in specs:
            a, b = anchors[spec.name, 0], anchors[spec.name, 1]
            if spec.kind == "ball":
                self.closures.append(BallClosure(spec.name, a, b))
            else:
                length = float(np.linalg.norm(b.position(self.kin) - a.position(self.kin)))
                self.closures.append(DistanceClosure(spec.name, a, b, length))
        self.branches = [
            LoopBranch(
                c.name,
                [self.points[n] for n in c.branch],
                self.kin,
                c.branch_kind,
                [self.points[n] for n in c.branch_fallback],
            )
            for c in tree.closures
            if c.branch
        ]

    @property
    def urdf(self) -> str:
        if self._urdf is None:
            self._urdf = tree_to_urdf(self._tree, comment=self._comment)
        return self._urdf

    def _parse(self, tree) -> tuple:
        model = pin.buildModelFromXML(self.urdf)
        return model, read_closures(self.urdf)

    def _add_anchor(self, name: str, link: str, offset: np.ndarray) -> FramePoint:
        parent = self.model.frames[self.model.getFrameId(link)]
        placement = parent.placement * pin.SE3(np.eye(3), offset)
        frame = pin.Frame(name, parent.parentJoint, placement, pin.OP_FRAME)
        return FramePoint(name, self.model.addFrame(frame), link)


def closure_row(closures: list, name: str) -> int:
    """The first row of the named closure among a solver's stacked rows."""
    row = 0
    for c in closures:
        if c.name == name:
            return row
        row += c.size
    raise KeyError(name)


class FrameMotion:
    """Points fixed to bodies, at many configurations, with their rates along a
    tangent of the solution manifold: each point grouped by the joint that carries
    it, every step's joint placements and twists read once, then all points at once
    (p = o + R·l moves at v + ω × (p − o))."""

    def __init__(self, kin, names: list[str], points: dict, design_positions: dict):
        self.kin, self.names = kin, list(names)
        groups = {}
        for i, name in enumerate(self.names):
            frame = kin.model.frames[points[name].frame_id]
            if frame.parentJoint == 0:
                offset = design_positions[name]
            else:
                offset = frame.placement.translation
            groups.setdefault(frame.parentJoint, []).append((i, offset))
        self.groups = [
            (j, np.array([i for i, _ in g]), np.array([o for _, o in g])) for j, g in groups.items()
        ]

    def __call__(
        self, qs: list, tangent_at, k: int, tangents=None, columns=None
    ) -> tuple[np.ndarray, list]:
        """Positions (m, n, 3) of the m points at the n configurations and, for each
        list of driver columns in ``columns`` (default: all k), their rates along
        those drivers (m, len(columns), n, 3): each point's own rates contiguous;
        ``tangent_at(i, q)`` updates the kinematics (Jacobians too) at q and returns dq
        per driver (nv × k). A None configuration gives NaN.

        ``tangents(Q, steps, placed)``: dq per driver at every solved configuration at
        once ((len(Q), nv, k), or None; ``placed``: the tree's placements at Q): then
        every step is evaluated at once on the model's tree (bulk.Tree) instead of one
        Pinocchio call after another.
        """
        columns = [list(range(k))] if columns is None else [list(c) for c in columns]
        solved = [i for i, q in enumerate(qs) if q is not None]
        if tangents is not None and tree_of(self.kin).supported and solved:
            Q = np.array([qs[i] for i in solved]).reshape(len(solved), self.kin.model.nq)
            placed = tree_of(self.kin).placements(Q)
            T = tangents(Q, solved, placed)
            if T is not None:
                return self._at_once(len(qs), solved, placed, T, columns)
        n, m = len(qs), len(self.names)
        pos = np.full((n, m, 3), np.nan)
        rates = np.full((k, n, m, 3), np.nan)
        moving = [(j, index, local) for j, index, local in self.groups if j != 0]
        rotation = np.full((len(moving), n, 3, 3), np.nan)
        origin = np.full((len(moving), n, 3), np.nan)
        twist = np.full((len(moving), n, 6, k), np.nan)
        model, data = self.kin.model, self.kin.data
        for i, q in enumerate(qs):
            if q is None:
                continue
            tangent = tangent_at(i, q)
            oMi = data.oMi
            for g, (joint, _, _) in enumerate(moving):
                placement = oMi[joint]
                rotation[g, i] = placement.rotation
                origin[g, i] = placement.translation
                twist[g, i] = (
                    pin.getJointJacobian(model, data, joint, pin.LOCAL_WORLD_ALIGNED).reshape(6, -1)
                    @ tangent
                )
        for j, index, local in self.groups:
            if j == 0:  # the chassis: fixed points
                pos[:, index] = local
                rates[:, :, index] = 0.0
        for g, (_, index, local) in enumerate(moving):
            arms = np.einsum("nij,mj->nmi", rotation[g], local)
            pos[:, index] = arms + origin[g][:, None]
            v = np.moveaxis(twist[g, :, :3], -1, 0)  # (k, n, 3)
            w = np.moveaxis(twist[g, :, 3:], -1, 0)
            rates[:, :, index] = v[:, :, None] + cross(w[:, :, None], arms[None])
        unsolved = np.array([q is None for q in qs])
        pos[unsolved] = np.nan
        rates[:, unsolved] = np.nan
        own = [np.ascontiguousarray(np.moveaxis(rates[c], 2, 0)) for c in columns]
        return np.ascontiguousarray(pos.transpose(1, 0, 2)), own

    def _at_once(self, n: int, solved: list, placed: tuple, T: np.ndarray, columns: list):
        """__call__ for every solved configuration at once (``placed``: the tree's
        placements there, T: their tangents), each list of columns' rates written
        straight in its final layout (m, k, n, 3)."""
        tree = tree_of(self.kin)
        R, o = placed
        a = tree.axes(R)
        count, m = len(T), len(self.names)
        pos = np.empty((m, count, 3))
        # a still point's rates stay 0 (v + w × arm of zeros gives +0)
        rates = [np.zeros((m, len(c), count, 3)) for c in columns]
        # only the driver columns some list asks for, each list's picked from them
        need = sorted({i for c in columns for i in c})
        picks = [[need.index(i) for i in c] for c in columns]
        T = T[:, :, need]
        for j, index, local in self.groups:
            if j == 0:  # the chassis: fixed points
                pos[index] = local[:, None]
                continue
            # arms (g, 1, n, 3): each point's offset from its joint's origin
            arms = (R[j].reshape(-1, 3) @ local.T).reshape(count, 3, -1).transpose(2, 0, 1)
            pos[index] = arms + o[j][None]
            # the lists along whose drivers its joints move (a vehicle's other corners
            # stay still along one's: their tangents there are zeros)
            moving = T[:, tree.moved_by(j)]  # (n, s, k)
            live = [i for i, c in enumerate(picks) if moving[:, :, c].any()]
            if not live:
                continue
            v, w = twist(tree, j, o, a, T)  # (k, n, 3) each
            arms = np.ascontiguousarray(arms)[:, None]
            for i in live:
                c = picks[i]
                rates[i][index] = v[c][None] + cross(w[c][None], arms)
        if count == n:
            return pos, rates
        out_pos = np.full((m, n, 3), np.nan)
        out_pos[:, solved] = pos
        out_rates = []
        for r in rates:
            full = np.full((m, r.shape[1], n, 3), np.nan)
            full[:, :, solved] = r
            out_rates.append(full)
        return out_pos, out_rates


def twist(tree, joint: int, o: np.ndarray, a: np.ndarray, T: np.ndarray) -> tuple:
    """The velocity of a joint's origin and its angular velocity (k, n, 3) along each
    tangent column (T: (n, nv, k)): Tree.twist_jacobian times T, in the joints that move
    it alone (a revolute one k moves the origin at a_k × (o − o_k) and turns it at a_k, a
    prismatic one moves it at a_k)."""
    n, _, k = T.shape
    v, w = np.zeros((k, n, 3)), np.zeros((k, n, 3))
    revolute, prismatic = tree._moves[joint]
    if revolute[0]:
        ks, vs = revolute
        along = T[:, vs, :]  # (n, s, k)
        v += np.einsum("snx,nsk->knx", cross(a[ks], o[joint] - o[ks]), along)
        w += np.einsum("snx,nsk->knx", a[ks], along)
    if prismatic[0]:
        ks, vs = prismatic
        v += np.einsum("snx,nsk->knx", a[ks], T[:, vs, :])
    return v, w


class Composed:
    """Labelled corners and the elements they share as one Pinocchio model at its design
    state (README, How it works): what a corner (one corner, labelled ``""``) and an
    axle (``left``, ``right``, with a rack, an anti-roll bar, a heave link) are built as.

    ``_compose`` composes each corner's tree prefixed by its label (compose.compose_tree;
    a lone corner labelled ``""`` keeps its own tree and names), adds the elements,
    builds the model (:class:`Built`) and sets: ``tree``, ``urdf``, ``model``, ``kin``,
    ``points`` (each corner's contact patch included), ``closures``, ``branches``,
    ``q_design``, ``mobility``, ``dead_centres``, ``corner_points`` (label → its
    corner's point names, unprefixed), ``output_points`` (every point written: each
    corner's, with the elements' of its label, then the elements' shared ones) and
    ``design_positions``.
    """

    # the shortest set of configurations whose motion is evaluated at once (bulk.py); a
    # shorter one's one Pinocchio call after another (an axle's: the numbers it always
    # had, to the last bit — its loads' forces move in the 12th digit otherwise)
    motion_at_once_from = 0
    # joints the drivers hold (a vehicle's body on the road: its rates are the chassis
    # frame's, the body still)
    held_joints: tuple[str, ...] = ()

    def _compose(
        self, corners: dict, elements=(), name: str = "", comment: str = "", visuals: bool = True
    ) -> None:
        self._corners = dict(corners)
        trees = {label: g.mechanism.tree(g, shapes=visuals) for label, g in corners.items()}
        if list(trees) == [""] and not elements:
            self.tree = trees[""]  # one corner: its own tree
        else:
            self.tree = compose_tree(trees, name, elements)
        # links near dead centre at design (warned when the file was read): the
        # failure report names them as the cause of steps out of reach
        self.dead_centres = dead_centres(self.tree)
        built = Built(
            self.tree if visuals else replace(self.tree, visuals=[]), comment, not visuals
        )
        self._built, self.model, self.kin = built, built.model, built.kin
        self.points: dict[str, FramePoint | ContactPatchPoint] = dict(built.points)
        self.corner_points = {}
        for label, g in corners.items():
            p = f"{label}_" if label else ""
            self.points[f"{p}contact_patch_center"] = ContactPatchPoint(
                f"{p}contact_patch_center",
                self.points[f"{p}wheel_center"],
                self.points[f"{p}axle_inboard"],
                self.points[f"{p}axle_outboard"],
                g.wheel.radius,
                f"{p}{g.mechanism.WHEEL_BODY}",
            )
            self.corner_points[label] = tuple(g.hardpoints) + DERIVED_POINTS
        self.q_design = built.q_design
        self.closures, self.branches = built.closures, built.branches
        self.mobility = self.model.nv - sum(c.size for c in self.closures)
        owned = {
            (f"{label}_" if label else "") + n
            for label, names in self.corner_points.items()
            for n in names
        }
        extras = [n for n in self.tree.points if n not in owned]
        self.output_points = []  # each corner's points, then its elements', then shared
        prefixes = tuple(f"{label}_" for label in corners if label)
        for label, names in self.corner_points.items():
            p = f"{label}_" if label else ""
            self.output_points += [p + n for n in names]
            self.output_points += [n for n in extras if label and n.startswith(p)]
        self.output_points += [n for n in extras if not prefixes or not n.startswith(prefixes)]
        self.design_positions = self.positions(self.q_design)

    @property
    def urdf(self) -> str:
        """The model's URDF text (written when first read)."""
        return self._built.urdf

    def positions(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """World position (m) of every named point (prefixed by its label) at q."""
        pin.framesForwardKinematics(self.model, self.kin.data, q)
        return {n: self.points[n].position(self.kin).copy() for n in self.output_points}

    def _drivers(self) -> None:
        """The drivers of the rates, as the drive solver's rows and right-hand sides: each
        corner's wheel-centre z, the rack (one, shared) where there is one, and each
        toe-link corner's toe link length (a column of 1 on that closure's row: J·dq = e,
        the row's value changed by one). ``driver_columns``: label → its corner's
        columns (its hub z, then the rack or its toe link)."""
        labels = list(self._corners)
        prefix = {label: f"{label}_" if label else "" for label in labels}
        z = np.array([0.0, 0.0, 1.0])
        drive = [PointTarget(self.points[f"{prefix[lb]}wheel_center"], z) for lb in labels]
        rack = self.model.existJointName("rack_slide")
        if rack:
            drive.append(JointTarget(self.model, "rack_slide"))
        drive += [JointTarget(self.model, joint) for joint in self.held_joints]
        self._drive = NewtonSolver(self.kin, self.closures, drive, self.branches)
        self.drive_rhs, self.driver_columns = self._drive.unit_rhs, {}
        for c, (label, g) in enumerate(self._corners.items()):
            # the rack: its corners' (a vehicle's rear, on toe links, has none of it)
            steered = rack and g.steering == "rack"
            self.driver_columns[label] = [c, len(labels)] if steered else [c]
            if g.steering == "none" and g.steering_points:
                toe = np.zeros((self._drive.nrows, 1))
                toe[closure_row(self.closures, f"{prefix[label]}toe_link")] = 1.0
                self.driver_columns[label].append(self.drive_rhs.shape[1])
                self.drive_rhs = np.hstack([self.drive_rhs, toe])
        frames = [n for n in self.output_points if "contact_patch_center" not in n]
        self._frame_motion = FrameMotion(self.kin, frames, self.points, self.design_positions)

    @property
    def quantities(self) -> dict:
        """quantity → what reads a quantity target (Assembly's shared elements): none."""
        return {}

    def readable(self, t) -> bool:
        """Whether a target names a quantity this model has, or one of its corners."""
        if t.quantity is not None:
            return t.quantity in self.quantities
        return (t.side or "") in self._corners

    def point_of(self, t) -> str:
        """A point target's point in the model: its corner's label as a prefix."""
        return (f"{t.side}_" if t.side else "") + t.point

    def held_targets(self, targets: list) -> list:
        """The targets a sweep's steps hold: its own, and where a rack-steered model's
        sweep gives every target but the rack's (a bump-only sweep; heave and roll, or a
        wheel height per side) the rack held at design (rack_displacement 0;
        ``sweep_notes`` says so). Every other set of targets as given (checked by the
        subject's ``solver_for``, assembly.py)."""
        targets = list(targets)
        if not self.model.existJointName("rack_slide") or len(targets) != self.mobility - 1:
            return targets
        for t in targets:
            if not self.readable(t):
                return targets  # refused when the targets are read
            point = None if t.quantity is not None else self.points.get(self.point_of(t))
            if point is not None and point.body == "rack":
                return targets
        from ..model.sweep import Target

        steps = len(targets[0].values) if targets else 1
        first = next(iter(self._corners))
        inboard = self._corners[first].steering_points[0]
        return [*targets, Target(inboard, "y", np.zeros(steps), side=first or None)]

    def sweep_notes(self, targets) -> list[str]:
        """What the summary says of how the sweep's targets (or a Sweep's) were read."""
        targets = list(getattr(targets, "targets", targets))
        return [RACK_HELD] if len(self.held_targets(targets)) > len(targets) else []

    def drive_rows_at_design(self) -> np.ndarray:
        """The closures' rows and the drivers' (each corner's wheel-centre z, the rack)
        at design, stacked: of full rank when the drivers fix the pose (the closures'
        first, as many as ``mobility`` fewer than the joints' freedoms)."""
        self._drive.evaluate(self.q_design)
        return self._drive.jacobian

    def closure_drivers(self, solver) -> np.ndarray | None:
        """The drivers that change a closure's value (a toe link's length: drive_rhs's
        columns after its targets') as right-hand sides of ``solver``'s rows (the
        closures first, as the drive solver's; the targets held), or None."""
        columns = self.drive_rhs[:, len(self._drive.targets) :]
        if not columns.shape[1]:
            return None
        closures = sum(c.size for c in self.closures)
        extra = np.zeros((solver.nrows, columns.shape[1]))
        extra[:closures] = columns[:closures]
        return extra

    def label_motion(self, qs: list, tangents: list | None = None) -> dict:
        """Every point (prefixed) at each configuration, as a jet.Dual per corner's label:
        its rates along that corner's drivers (``driver_columns``: its hub z, the others
        held, and the rack or its toe link) — name → {label: Dual(position (n, 3) m,
        rates (k, n, 3))}. Each rate column is the tangent of the solution manifold,
        J·dq = e_j (``tangents``' where the sweep's solve has it, dq per driver, else
        solved here; every step at once on the model's tree, bulk.py), pushed through
        the joint Jacobians; each contact patch follows by the chain rule. A None
        configuration (a step that did not converge) gives NaN."""
        k = self.drive_rhs.shape[1]

        def known(i: int):
            t = None if tangents is None else tangents[i]
            return t if t is not None and t.shape[1] == k else None

        def tangent_at(i: int, q: np.ndarray) -> np.ndarray:
            t = known(i)
            if t is not None:
                self.kin.update(q)
                return t
            self._drive.evaluate(q)
            return self._drive.tangent(self.drive_rhs)

        def at_once(Q: np.ndarray, steps: list, placed: tuple) -> np.ndarray | None:
            given = [known(i) for i in steps]
            if all(t is not None for t in given):
                return np.array(given)
            rows = rows_of(self._drive)
            if not rows.supported or rows.nrows != self.model.nv:
                return None
            zero = np.zeros((len(Q), len(self._drive.targets)))
            _, J = rows.evaluate(Q, zero, placed=placed)
            return solve_all(J, self.drive_rhs)

        many = at_once if len(qs) >= self.motion_at_once_from else None
        labels = list(self.driver_columns)
        pos, rates = self._frame_motion(
            qs, tangent_at, k, many, [self.driver_columns[label] for label in labels]
        )
        own = dict(zip(labels, rates, strict=True))  # each label's rates: (m, k_label, n, 3)
        out = {
            name: {label: Dual(pos[j], own[label][j]) for label in own}
            for j, name in enumerate(self._frame_motion.names)
        }
        for label, g in self._corners.items():
            p = f"{label}_" if label else ""
            wheel, inboard, outboard = (
                out[f"{p}{n}"] for n in ("wheel_center", "axle_inboard", "axle_outboard")
            )
            out[f"{p}contact_patch_center"] = {
                s: contact_patch(wheel[s], unit(outboard[s] - inboard[s]), g.wheel.radius)
                for s in own
            }
        return out


class Linkage(Composed):
    """The kinematic model of one corner at its geometry's design state."""

    def __init__(self, geometry: Geometry, visuals: bool = True):
        """``visuals``: the URDF's shapes (a study's variants, never drawn, go without)."""
        self.geometry = geometry
        self.mechanism = geometry.mechanism
        comment = (
            f"generated by pin_susp {__version__} from {Path(geometry.source).name};"
            " regenerate with: pin-susp urdf GEOMETRY -o FILE"
        )
        self._compose({"": geometry}, comment=comment, visuals=visuals)
        self.point_names = self.corner_points[""]
        self.actuators = ("rack",) if geometry.steering == "rack" else ()
        # The drivers: wheel-centre z, and the rack or the fixed toe link's length (which
        # steers a toe-link corner: its steer screw axis).
        self._drivers()
        self._check_mobility()
        self.drivers = (HUB_Z, RACK) if geometry.steering == "rack" else (HUB_Z,)
        if geometry.steering == "none" and geometry.steering_points:
            self.drivers = (HUB_Z, TOE_LINK)
        # The sense in which bump winds a torsion bar at design (motion_ratio's sign).
        self.spring_sense = 1.0
        if geometry.spring == "torsion_bar":
            design = {k: v[None] for k, v in self.design_positions.items()}
            columns = metric_columns(geometry, self.motion([self.q_design]), design)
            self.spring_sense = -1.0 if columns["motion_ratio"][0][0] < 0.0 else 1.0

    def _check_mobility(self) -> None:
        """The closures must be independent at design, and the wheel must move in bump:
        otherwise the file describes no suspension (one clear error naming the points of
        the closures or joints concerned, not a singular solve)."""
        rows = self.drive_rows_at_design()
        n = len(rows) - len(self._drive.targets)
        if n:
            u, s, _ = np.linalg.svd(rows[:n])
            if s[-1] <= 1e-9 * s[0]:
                raise InputError(
                    self.geometry.source,
                    "hardpoints",
                    "the linkage's closures are dependent at the design state (a link that "
                    "adds no constraint, or a loop at its toggle): the corner has more "
                    f"freedoms than {self.mobility} and no pose can be solved "
                    f"({self._closure_points(u[:, -1])})",
                )
        _, s, vt = np.linalg.svd(rows)
        if s[-1] <= 1e-9 * s[0]:  # (a lone zero row too: a wheel that cannot rise)
            held = " with the rack held" if self.geometry.steering == "rack" else ""
            raise InputError(
                self.geometry.source,
                "hardpoints",
                f"the linkage locks the wheel for bump: its one motion{held} does not move "
                f"the wheel centre up or down ({self._joint_points(vt[-1])})".replace(" ()", ""),
            )

    def _closure_points(self, weights: np.ndarray) -> str:
        """The closures a dependent combination of closure rows is made of, with their
        points: 'closures trackrod (trackrod_inboard, trackrod_outboard), ...'."""
        points = {c.name: c.points for c in self.tree.closures}
        named, row = [], 0
        scale = np.abs(weights).max()
        for c in self.closures:
            if np.abs(weights[row : row + c.size]).max() > 1e-6 * scale:
                ends = points.get(c.name, ())
                named.append(f"{c.name} ({', '.join(ends)})" if ends else c.name)
            row += c.size
        return "closures " + ", ".join(named)

    def _joint_points(self, motion: np.ndarray) -> str:
        """The joints a motion dq turns or slides, by the points that place them."""
        defined = {
            b.joint.name: b.joint.defined_by for b in self.tree.bodies if b.joint is not None
        }
        scale = np.abs(motion).max()
        names: list[str] = []
        for j in range(1, self.model.njoints):
            v = self.model.joints[j].idx_v
            if np.abs(motion[v : v + self.model.joints[j].nv]).max() <= 1e-6 * scale:
                continue
            joint = self.model.names[j]
            base = next((k for k in defined if joint == k or joint.startswith(k + "_")), None)
            for point in defined.get(base, ()):
                if point not in names:
                    names.append(point)
        if not names:
            return ""
        said = f"the wheel centre held, the joints at {', '.join(names)} still move"
        if "rocker_axis_a" in names:  # a file may give the axis as pivot + direction
            said += "; a rocker by rocker_pivot and rocker_axis has its axis points there"
        return said

    def motion(self, qs: list, tangents: list | None = None) -> dict[str, Dual]:
        """Every named point at each configuration, with its exact rates per driver.

        name → Dual(position (n, 3) m, rates (k, n, 3) m/m) for the k drivers
        of ``self.drivers``: hub z (wheel-centre z with the rack held) and rack
        displacement (rack with wheel-centre z held), or the toe link's length
        (wheel-centre z held) on a toe-link corner. Each rate column is the
        tangent of the solution manifold, J·dq = e_j (from ``tangents`` where
        the sweep's solve already has it, else solved here), pushed through the
        joint Jacobians: a point p on joint j moves at v_j + ω_j × (p − o_j).
        The contact patch follows by the chain rule (jet.Dual). A None
        configuration (a step that did not converge) gives NaN.
        """
        return {name: by_label[""] for name, by_label in self.label_motion(qs, tangents).items()}

    def body_of(self, point: str) -> str:
        return self.points[point].body
