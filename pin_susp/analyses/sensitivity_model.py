"""The sensitivities' model: a corner rebuilt with virtual joints at its hardpoints, and
d(metric)/d(hardpoint coordinate) at a solved state, exact (``sensitivity.py`` runs it
over a sweep, an axle and the tables).

Moving a hardpoint changes the mechanism, not its state, so it is turned into
kinematics: the corner's tree is rebuilt with *virtual joints*, all at zero,
that move each hardpoint:

- a point fixed to a body hangs from it by three prismatic joints (x, y, z);
- a pivot is wrapped as  translate(δ) · tilt(ε) · pivot · tilt(−ε) · translate(−δ):
  at zero joint angle the wrapper is the identity (the drawn points stay),
  at an angle q it turns about the line through o + δ along ω + ε × ω — the
  pivot line moved (δ, from its origin point) and tilted (ε = ω × δω, from
  either end). A ball joint needs only the translation.

A hardpoint coordinate is then a fixed combination B of virtual joint
velocities, and Pinocchio's Jacobians give ∂r/∂h = J_virtual·B. With the
closures and targets r(q, h) = 0, dq/dh = −J_q⁻¹(∂r/∂h) (plus the explicit
change of link lengths and of relative target values). For the derivative
columns (camber gain, bump steer, ...) the tangent t (J_drive·t = e) is
differentiated too: d(J t)/dh = J̇(t)·dx/dh by the symmetry of second
derivatives, with J̇ from ``computeJointJacobiansTimeVariation``. Points go
into the metric functions as nested dual numbers (jet.Dual), which return
the metric, its derivative along the motion, and both their hardpoint
sensitivities — no finite differences anywhere.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ..columns.metrics import METRICS, PointSet, derivative_columns
from ..constraints import (
    BallClosure,
    ContactPatchPoint,
    DistanceClosure,
    FramePoint,
    JointTarget,
    Kinematics,
    PointTarget,
)
from ..maths.jet import Dual
from ..model.geometry import contact_patch, unit, wheel_points
from ..model.packaging import placed_points
from ..model.sweep import Target
from ..model.tree import Body, Joint, Tree
from ..model.urdf import tree_to_urdf
from ..solve.template import variant_model

V = "__v_"  # marks virtual joints and links
AXES = "xyz"
E = np.eye(3)


@dataclass
class Sensitivity:
    """d(metric)/d(hardpoint coordinate) at one state, output units per mm.

    ``values[name]`` is an array (hardpoints, 3 axes) for every metric and
    derivative column ``name``; ``units[name]`` its unit (e.g. "deg/mm").
    """

    step: int
    hardpoints: list[str]
    values: dict[str, np.ndarray]
    units: dict[str, str]
    metrics: dict[str, float]  # the metric values at that state, output units


class HardpointSensitivity:
    """The corner rebuilt with virtual joints; sensitivities at solved states."""

    def __init__(self, corner):
        self.corner = corner
        g = corner.geometry
        self.hardpoints = list(g.hardpoints)
        tree, self.params = _augment(corner.tree)
        # (kinematic: without shapes; a study's later corners of one structure copy the
        # first's model with their own numbers, bit for bit the parsed one: template.py)
        self.model = variant_model(replace(tree, visuals=[]), _parse, closures=False)[0]
        self.kin = Kinematics(self.model)
        m = self.model
        self.real = np.array(
            [
                m.joints[m.getJointId(corner.model.names[j])].idx_v
                for j in range(1, corner.model.njoints)
            ]
        )
        self.frames = [n for n in corner.point_names if n != "contact_patch_center"]
        self.points = {n: FramePoint(n, m.getFrameId(n), corner.body_of(n)) for n in self.frames}
        self.points["contact_patch_center"] = ContactPatchPoint(
            "contact_patch_center",
            self.points["wheel_center"],
            self.points["axle_inboard"],
            self.points["axle_outboard"],
            g.wheel.radius,
            corner.mechanism.WHEEL_BODY,
        )
        self.B = self._virtual_map()
        # Design positions move with the hardpoints too (relative targets, wheel travel).
        q0 = pin.neutral(m)
        self.kin.update(q0)
        self.design_rates = {f: self._jac(f) @ self.B for f in self.frames}  # (3, n_h)
        self.closures = self._closures()

    # -- construction ---------------------------------------------------------
    def _virtual_map(self) -> np.ndarray:
        """B: virtual joint velocity per unit move of each hardpoint coordinate."""
        g = self.corner.geometry
        names = self.hardpoints
        n_h = 3 * len(names)
        col = {(h, a): 3 * i + a for i, h in enumerate(names) for a in range(3)}
        # How each frame's drawn position moves: itself, or the derived-point formulas.
        moves = {}
        seed = {h: np.zeros((n_h, 3)) for h in ("axle_inboard", "axle_outboard")}
        for h in seed:
            for a in range(3):
                seed[h][col[h, a], a] = 1.0
        axle = {h: Dual(g.hardpoints[h], seed[h]) for h in seed}
        derived = wheel_points(axle["axle_inboard"], axle["axle_outboard"], g.wheel)
        derived |= placed_points(g.driveshaft, derived | axle)  # a driveshaft's outer joint
        # hardpoints placed by others (the MacPherson clamp on its strut line)
        seeds = {}
        for h in g.hardpoints:
            d = np.zeros((n_h, 3))
            d[[col[h, a] for a in range(3)], range(3)] = 1.0
            seeds[h] = Dual(g.hardpoints[h], d)
        settled = g.mechanism.settle(seeds)
        owners = {rec[1] for rec in self.params.values() if rec[0] == "point"}
        for f in owners:
            point = f.split("__")[-1] if f.startswith("anchor__") else f
            if point in settled:
                d = settled[point].der
            elif point in g.hardpoints:
                d = seeds[point].der
            else:
                d = derived[point].der
            moves[f] = d
        B = np.zeros((self.model.nv, n_h))
        m = self.model
        for joint, (kind, owner, a, extra) in self.params.items():
            v = m.joints[m.getJointId(joint)].idx_v
            if kind == "point":
                B[v] = moves[owner][:, a]
            elif kind in ("origin", "origin_back"):
                sign = 1.0 if kind == "origin" else -1.0
                B[v, [col[extra[0], a]]] = sign
            else:  # tilt of a pivot axis running extra[0] → extra[1]
                sign = 1.0 if kind == "tilt" else -1.0
                o, e = g.hardpoints[extra[0]], g.hardpoints[extra[1]]
                w = unit(e - o)
                project = (E - np.outer(w, w)) / np.linalg.norm(e - o)
                for h, s in ((extra[1], 1.0), (extra[0], -1.0)):
                    for b in range(3):
                        eps = np.cross(w, s * project[:, b])  # ε = ω × δω
                        B[v, col[h, b]] += sign * eps[a]
        return B

    def _closures(self) -> list:
        """The corner's closures on this model's frames (anchors included)."""
        out = []
        self.closure_points = []
        for c, spec in zip(self.corner.closures, self.corner.tree.closures, strict=True):
            ends = []
            for i, (link, _) in enumerate(spec.anchors):
                name = _anchor_name(spec, i)
                if link in self.points:
                    ends.append(self.points[link])
                else:
                    ends.append(FramePoint(name, self.model.getFrameId(name), link))
            kind = BallClosure if isinstance(c, BallClosure) else DistanceClosure
            out.append(
                kind(c.name, *ends) if kind is BallClosure else kind(c.name, *ends, c.length)
            )
            self.closure_points.append(spec.points)
        return out

    def _jac(self, f: str) -> np.ndarray:
        return self.points[f].jacobian(self.kin)

    # -- evaluation -------------------------------------------------------------
    def at(
        self, q: np.ndarray, targets: list[Target] | None = None, step: int = 0, only=None
    ) -> Sensitivity:
        """Sensitivities at the solved configuration q (of the corner's model),
        holding ``targets`` (default: wheel-centre height and rack at design)."""
        return self._collect(*self.jets(q, targets), step, only)

    def jets(self, q: np.ndarray, targets: list[Target] | None = None) -> tuple[dict, dict]:
        """Every point at q, and its design position, as nested jet.Duals: outside, the
        hardpoint coordinates (n_h directions, per m); inside, the drivers (per m).
        Positions (1, 3) m; d/dh (n_h, 1, 1, 3); rates (k, 1, 3); d rates/dh (n_h, k, 1, 3).
        """
        c = self.corner
        if targets is None:
            targets = [Target("wheel_center", "z", 0.0)]
        targets = c.held_targets(targets)  # the rack at design where none is given
        m, kin = self.model, self.kin
        qa = pin.neutral(m)
        qa[self.real] = q  # every joint has one dof: its q index is its v index
        kin.update(qa)
        n_h = self.B.shape[1]
        virt = np.setdiff1d(np.arange(m.nv), self.real)

        # dq/dh holding the closures and the targets
        rows, explicit = [], []
        for cl, ends in zip(self.closures, self.closure_points, strict=True):
            rows.append(cl.jacobian(kin))
            e = np.zeros((cl.size, n_h))
            if isinstance(cl, DistanceClosure):  # its length is drawn from the hardpoints
                a, b = (c.design_positions[p] for p in ends)
                da, db = (self.design_rates[p] for p in ends)
                e[0] = -(unit(b - a) @ (db - da))
            explicit.append(e)
        for t in targets:
            d = t.unit_direction
            rows.append((d @ self.points[t.point].jacobian(kin))[None])
            e = np.zeros((1, n_h))
            if t.mode == "relative":
                e[0] = -(d @ self._design_rate(t.point))
            explicit.append(e)
        J = np.vstack(rows)
        F = J[:, virt] @ self.B[virt] + np.vstack(explicit)
        dx = np.zeros((m.nv, n_h))
        dx[virt] = self.B[virt]
        dx[self.real] = -np.linalg.solve(J[:, self.real], F)

        # the tangent of the motion per driver, and its change with each hardpoint
        drive = list(self.closures) + [PointTarget(self.points["wheel_center"], E[2])]
        if c.geometry.steering == "rack":
            drive.append(JointTarget(m, "rack_slide"))
        Jd = np.vstack([row.jacobian(kin) for row in drive])
        k = len(c.drivers)
        tangent = np.linalg.solve(Jd[:, self.real], c.drive_rhs)  # (nv_real, k): same rows

        pos = {f: self.points[f].position(kin).copy() for f in self.frames}
        anchors = [p for cl in self.closures for p in (cl.a, cl.b) if p.name not in self.points]
        jac = {p.name: p.jacobian(kin) for p in anchors} | {f: self._jac(f) for f in self.frames}
        rate = {f: (jac[f][:, self.real] @ tangent).T for f in self.frames}  # (k, 3)
        sens = {f: (jac[f] @ dx).T for f in self.frames}  # (n_h, 3)
        mixed = {f: np.zeros((n_h, k, 3)) for f in self.frames}
        for i in range(k):
            ta = np.zeros(m.nv)
            ta[self.real] = tangent[:, i]
            pin.computeJointJacobiansTimeVariation(m, kin.data, qa, ta)
            jdot = {
                p.name: pin.getFrameJacobianTimeVariation(
                    m, kin.data, p.frame_id, pin.LOCAL_WORLD_ALIGNED
                )[:3]
                for p in anchors + [self.points[f] for f in self.frames]
            }
            drive_dot = np.vstack([self._row_dot(row, jac, jdot, ta) for row in drive])
            dt = -np.linalg.solve(Jd[:, self.real], drive_dot @ dx)  # (nv_real, n_h)
            for f in self.frames:
                mixed[f][:, i] = (jdot[f] @ dx + jac[f][:, self.real] @ dt).T

        points = {
            f: Dual(
                Dual(pos[f][None], rate[f][:, None]),
                Dual(sens[f][:, None, None], mixed[f][:, :, None]),
            )
            for f in self.frames
        }
        design = {
            f: Dual(c.design_positions[f][None], self.design_rates[f].T[:, None, None])
            for f in self.frames
        }
        for pts in (points, design):
            a = unit(pts["axle_outboard"] - pts["axle_inboard"])
            pts["contact_patch_center"] = contact_patch(
                pts["wheel_center"], a, c.geometry.wheel.radius
            )
        return points, design

    def _design_rate(self, point: str) -> np.ndarray:
        if point in self.design_rates:
            return self.design_rates[point]
        # the contact patch: through its formula, with the design rates as Duals
        d = {
            f: Dual(self.corner.design_positions[f], self.design_rates[f].T)
            for f in ("wheel_center", "axle_inboard", "axle_outboard")
        }
        cp = contact_patch(
            d["wheel_center"],
            unit(d["axle_outboard"] - d["axle_inboard"]),
            self.corner.geometry.wheel.radius,
        )
        return cp.der.T

    def _row_dot(self, row, jac, jdot, v) -> np.ndarray:
        """d(row Jacobian)/dτ along the joint velocity v (augmented columns)."""
        if isinstance(row, JointTarget):
            return np.zeros((1, self.model.nv))
        if isinstance(row, PointTarget):
            return (row.direction @ jdot[row.point.name])[None]
        ja, jb = jac[row.a.name], jac[row.b.name]
        da, db = jdot[row.a.name], jdot[row.b.name]
        if isinstance(row, BallClosure):
            return db - da
        d = row.b.position(self.kin) - row.a.position(self.kin)
        n = np.linalg.norm(d)
        u = d / n
        u_dot = (E - np.outer(u, u)) @ ((jb - ja) @ v) / n
        return (u_dot @ (jb - ja) + u @ (db - da))[None]

    def _collect(self, points, design, step, only=None) -> Sensitivity:
        """``only``: the columns wanted (a study's), else every one."""
        g = self.corner.geometry
        ps = PointSet(points, design, g)
        n = len(self.hardpoints)
        values, units, metrics = {}, {}, {}
        wanted = derivative_columns(g)
        if only is not None:
            wanted = [d for d in wanted if d.name in only]
            needed = set(only) | {d.metric.name for d in wanted}
        with np.errstate(invalid="ignore", divide="ignore"):
            evaluated = {
                m.name: m.function(ps) * m.scale
                for m in METRICS
                if m.applies(g) and (only is None or m.name in needed)
            }
        for m in METRICS:
            if m.name not in evaluated or only is not None and m.name not in only:
                continue
            v = evaluated[m.name]
            metrics[m.name] = float(v.val.val[0])
            values[m.name] = v.der.val[:, 0, 0].reshape(n, 3) * 1e-3
            units[m.name] = f"{m.unit}/mm"
        drivers = self.corner.drivers
        for d in wanted:
            v = evaluated[d.metric.name]
            i = drivers.index(d.driver)
            metrics[d.name] = float(v.val.der[i, 0]) * 1e-3
            values[d.name] = v.der.der[:, i, 0].reshape(n, 3) * 1e-6
            units[d.name] = f"{d.unit}/mm"
        return Sensitivity(step, self.hardpoints, values, units, metrics)


def _parse(tree: Tree) -> tuple:
    return pin.buildModelFromXML(tree_to_urdf(tree)), None


def _augment(tree: Tree) -> tuple[Tree, dict]:
    """The tree with virtual joints; params: virtual joint → (kind, owner, axis, extra)."""
    bodies, params = [], {}

    def chain(parent: str, last: str, origin, links: list[tuple[str, str, int, tuple]]):
        """Hang ``links`` (joint name, kind, axis, record) in a row from parent; the last
        link is named ``last``."""
        for i, (name, kind, a, record) in enumerate(links):
            child = last if i == len(links) - 1 else f"{name}_link"
            joint_kind = "prismatic" if kind.startswith(("point", "origin")) else "revolute"
            if kind == "real":
                bodies.append(Body(child, parent, record))
            else:
                bodies.append(Body(child, parent, Joint(name, joint_kind, origin, E[a])))
                params[name] = record
            parent = child
        return parent

    for body in tree.bodies:
        j = body.joint
        if j is None or not j.defined_by:
            bodies.append(body)
            continue
        axis_by_points = j.kind in ("revolute", "prismatic")  # tilts when its ends move
        links = [
            (f"{j.name}{V}o{AXES[a]}", "origin", a, ("origin", j.name, a, j.defined_by))
            for a in range(3)
        ]
        if axis_by_points:
            links += [
                (f"{j.name}{V}t{AXES[a]}", "tilt", a, ("tilt", j.name, a, j.defined_by))
                for a in range(3)
            ]
        links.append((f"{j.name}{V}real", "real", 0, j))
        if axis_by_points:
            links += [
                (f"{j.name}{V}c{AXES[a]}", "tilt_back", a, ("tilt_back", j.name, a, j.defined_by))
                for a in (2, 1, 0)
            ]
        links += [
            (f"{j.name}{V}p{AXES[a]}", "origin_back", a, ("origin_back", j.name, a, j.defined_by))
            for a in range(3)
        ]
        chain(body.parent, body.name, j.origin, links)

    hanging = [(name, body, pos) for name, (body, pos) in tree.points.items()]
    for c in tree.closures:
        for i, (link, pos) in enumerate(c.anchors):
            if link not in tree.points:  # an anchor on a body: give it its own point
                hanging.append((_anchor_name(c, i), link, pos))
    for name, body, pos in hanging:
        links = [(f"{name}{V}{AXES[a]}", "point", a, ("point", name, a, ())) for a in range(3)]
        chain(body, name, pos, links)
    return Tree(tree.name + "_sensitivity", bodies, {}, []), params


def _anchor_name(closure, i: int) -> str:
    """The frame of a closure anchor that sits on a body (not on a point link)."""
    return f"anchor__{closure.name}__{i}__{closure.points[i]}"
