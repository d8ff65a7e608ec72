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

Many states (a sweep's steps, an optimiser's every evaluation) go through the
metric functions at once, the states stacked along the points' last axis; where
no column asked for reads the drivers' rates (a study's objective of plain
metrics) the tangent and its change are left out, and the states' dq/dh are
solved together. A study's variants, which differ only in their numbers, share
one model's frames and Pinocchio data.
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

    def __init__(self, corner, like: HardpointSensitivity | None = None):
        """``like``: the model of another corner of this one's structure (a study's
        variant), whose frames and Pinocchio data this one shares — every evaluation
        sets the data whole — its numbers its own."""
        self.corner = corner
        g = corner.geometry
        self.hardpoints = list(g.hardpoints)
        tree, self.params = _augment(corner.tree)
        # (kinematic: without shapes; a study's later corners of one structure copy the
        # first's model with their own numbers, bit for bit the parsed one: template.py)
        kinematic = replace(tree, visuals=[])
        self.model = m = variant_model(kinematic, _parse, closures=False, bulk=False)[0]
        if like is not None and _same_structure(like, self):
            self.kin = Kinematics(m, like.kin.data)
            self.real, self.virt, self.frames = like.real, like.virt, like.frames
            self.points = dict(like.points)
            self.rated, self.columns = like.rated, like.columns
        else:
            self.kin = Kinematics(m)
            self.real = np.array(
                [
                    m.joints[m.getJointId(corner.model.names[j])].idx_v
                    for j in range(1, corner.model.njoints)
                ]
            )
            self.virt = np.setdiff1d(np.arange(m.nv), self.real)
            self.rated = set()  # the sets of columns that read the rates (evaluated)
            self.columns = {j: m.joints[m.getJointId(j)].idx_v for j in self.params}  # in v
            self.frames = [n for n in corner.point_names if n != "contact_patch_center"]
            self.points = {
                n: FramePoint(n, m.getFrameId(n), corner.body_of(n)) for n in self.frames
            }
        self.points["contact_patch_center"] = ContactPatchPoint(
            "contact_patch_center",
            self.points["wheel_center"],
            self.points["axle_inboard"],
            self.points["axle_outboard"],
            g.wheel.radius,
            corner.mechanism.WHEEL_BODY,
        )
        self.B = self._virtual_map()
        self.B_virt = self.B[self.virt]
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
        tilts = {}  # a pivot's, by its end points (each pivot's three tilt joints share them)
        for joint, (kind, owner, a, extra) in self.params.items():
            v = self.columns[joint]
            if kind == "point":
                B[v] = moves[owner][:, a]
            elif kind in ("origin", "origin_back"):
                sign = 1.0 if kind == "origin" else -1.0
                B[v, [col[extra[0], a]]] = sign
            else:  # tilt of a pivot axis running extra[0] → extra[1]
                sign = 1.0 if kind == "tilt" else -1.0
                if extra not in tilts:
                    tilts[extra] = _tilts(g.hardpoints[extra[0]], g.hardpoints[extra[1]])
                ends = [(h, b) for h in (extra[1], extra[0]) for b in range(3)]
                for (h, b), eps in zip(ends, tilts[extra], strict=True):
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
        return self.at_many([(q, targets)], [step], only)[0]

    def at_many(self, states: list[tuple], steps: list[int], only=None) -> list[Sensitivity]:
        """``at`` at each state (q, targets), the metric functions run once for all;
        ``steps``: their step numbers."""
        return self.evaluated(states, steps, only)[1]

    def evaluated(self, states, steps, only=None, rates: bool = False) -> tuple:
        """(jets, a Sensitivity per state): at_many's, and the jets (jets_many) they came
        from, with the drivers' rates if ``rates`` or the columns ``only`` read them —
        a derivative column, a metric flagged ``rates``, or one found to: unknown (NaN)
        without them (an instant centre of a mechanism that finds it from the motion)."""
        key = None if only is None else frozenset(only)
        rates = rates or key in self.rated or needs_rates(self.corner.geometry, only)
        jets = self.jets_many(states, rates)
        out = self._collect(*jets, steps, only)
        if not rates and any(_unknown(s) for s in out):
            self.rated.add(key)
            jets = self.jets_many(states, True)
            out = self._collect(*jets, steps, only)
        return jets, out

    def jets(self, q: np.ndarray, targets: list[Target] | None = None) -> tuple[dict, dict]:
        """Every point at q, and its design position, as nested jet.Duals (jets_many's,
        of one state)."""
        return self.jets_many([(q, targets)])

    def jets_many(self, states: list[tuple], rates: bool = True) -> tuple[dict, dict]:
        """Every point at each state (q, targets), and its design position, as nested
        jet.Duals: outside, the hardpoint coordinates (n_h directions, per m); inside,
        the drivers (per m). For S states: positions (S, 3) m; d/dh (n_h, 1, S, 3);
        rates (k, S, 3); d rates/dh (n_h, k, S, 3). Without ``rates``, k = 0: no driver
        (a derivative column cannot be read, a metric of the rates is NaN)."""
        c = self.corner
        n, n_h = len(states), self.B.shape[1]
        at_once = None if rates else self._at_once(states)
        if rates:
            each = [self._state(q, targets, rates) for q, targets in states]
        points = {}
        for f in self.frames:
            if at_once is not None:
                pos, sens = at_once[0][f], at_once[1][f][:, None]
            else:
                pos = np.stack([e[0][f] for e in each])
                sens = np.stack([e[1][f] for e in each], axis=1)[:, None]
            if rates:
                rate = np.stack([e[2][f] for e in each], axis=1)
                mixed = np.stack([e[3][f] for e in each], axis=2)
            else:
                rate, mixed = np.empty((0, n, 3)), np.empty((n_h, 0, n, 3))
            points[f] = Dual(Dual(pos, rate), Dual(sens, mixed))
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

    def _state(self, q: np.ndarray, targets, rates: bool) -> tuple:
        """At one state: each frame's position (3,), d/dh (n_h, 3), and with ``rates``
        its rates (k, 3) and d rates/dh (n_h, k, 3)."""
        c = self.corner
        if targets is None:
            targets = [Target("wheel_center", "z", 0.0)]
        targets = c.held_targets(targets)  # the rack at design where none is given
        m, kin = self.model, self.kin
        qa = pin.neutral(m)
        qa[self.real] = q  # every joint has one dof: its q index is its v index
        kin.update(qa)
        n_h = self.B.shape[1]
        virt = self.virt

        # dq/dh holding the closures and the targets
        rows = [cl.jacobian(kin) for cl in self.closures]
        explicit = list(self._closure_explicit())
        for t in targets:
            d = t.unit_direction
            rows.append((d @ self.points[t.point].jacobian(kin))[None])
            e = np.zeros((1, n_h))
            if t.mode == "relative":
                e[0] = -(d @ self._design_rate(t.point))
            explicit.append(e)
        J = np.vstack(rows)
        F = J[:, virt] @ self.B_virt + np.vstack(explicit)
        dx = np.zeros((m.nv, n_h))
        dx[virt] = self.B_virt
        dx[self.real] = -np.linalg.solve(J[:, self.real], F)
        pos = {f: self.points[f].position(kin).copy() for f in self.frames}
        jac = {f: self._jac(f) for f in self.frames}
        sens = {f: (jac[f] @ dx).T for f in self.frames}  # (n_h, 3)
        if not rates:
            return pos, sens, None, None

        # the tangent of the motion per driver, and its change with each hardpoint
        drive = list(self.closures) + [PointTarget(self.points["wheel_center"], E[2])]
        if c.geometry.steering == "rack":
            drive.append(JointTarget(m, "rack_slide"))
        Jd = np.vstack([row.jacobian(kin) for row in drive])
        k = len(c.drivers)
        tangent = np.linalg.solve(Jd[:, self.real], c.drive_rhs)  # (nv_real, k): same rows

        anchors = [p for cl in self.closures for p in (cl.a, cl.b) if p.name not in self.points]
        jac |= {p.name: p.jacobian(kin) for p in anchors}
        rate = {f: (jac[f][:, self.real] @ tangent).T for f in self.frames}  # (k, 3)
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
        return pos, sens, rate, mixed

    def _at_once(self, states: list[tuple]) -> tuple:
        """Without the rates: ``_state``'s numbers for every state, its rows and frames
        read from Pinocchio state after state, the linear algebra done for all states at
        once (the states of each number of rows together): each frame's positions
        (S, 3) and d/dh (n_h, S, 3)."""
        m, kin, c = self.model, self.kin, self.corner
        n, n_h = len(states), self.B.shape[1]
        P = np.empty((len(self.frames), n, 3))
        J = np.empty((len(self.frames), n, 3, m.nv))
        rows, explicit = [], []
        qa = pin.neutral(m)
        for s, (q, targets) in enumerate(states):
            if targets is None:
                targets = [Target("wheel_center", "z", 0.0)]
            qa[self.real] = q
            kin.update(qa)
            r = [cl.jacobian(kin) for cl in self.closures]
            e = list(self._closure_explicit())
            for t in c.held_targets(targets):
                d = t.unit_direction
                r.append((d @ self.points[t.point].jacobian(kin))[None])
                e.append(np.zeros((1, n_h)))
                if t.mode == "relative":
                    e[-1][0] = -(d @ self._design_rate(t.point))
            rows.append(np.vstack(r))
            explicit.append(np.vstack(e))
            for i, f in enumerate(self.frames):
                P[i, s] = self.points[f].position(kin)
                J[i, s] = self._jac(f)
        # dq/dh holding the closures and the targets
        dx = np.zeros((n, m.nv, n_h))
        dx[:, self.virt] = self.B_virt
        groups: dict[int, list[int]] = {}
        for s, r in enumerate(rows):
            groups.setdefault(len(r), []).append(s)
        for at in groups.values():
            Jr = np.stack([rows[s] for s in at])
            F = Jr[:, :, self.virt] @ self.B_virt + np.stack([explicit[s] for s in at])
            dx[np.ix_(at, self.real)] = -np.linalg.solve(Jr[:, :, self.real], F)
        positions, moves = {}, {}
        for i, f in enumerate(self.frames):
            positions[f] = P[i]
            moves[f] = (J[i] @ dx).transpose(2, 0, 1)
        return positions, moves

    def _closure_explicit(self) -> list[np.ndarray]:
        """Each closure's explicit change with the hardpoints (cl.size, n_h): a distance
        closure's length is drawn from its points (worked out once)."""
        if "_explicit" not in self.__dict__:
            c, n_h = self.corner, self.B.shape[1]
            self._explicit = []
            for cl, ends in zip(self.closures, self.closure_points, strict=True):
                e = np.zeros((cl.size, n_h))
                if isinstance(cl, DistanceClosure):
                    a, b = (c.design_positions[p] for p in ends)
                    da, db = (self.design_rates[p] for p in ends)
                    e[0] = -(unit(b - a) @ (db - da))
                self._explicit.append(e)
        return self._explicit

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

    def _collect(self, points, design, steps: list[int], only=None) -> list[Sensitivity]:
        """A Sensitivity per state of the jets (``steps``: their step numbers); ``only``:
        the columns wanted (a study's), else every one."""
        g = self.corner.geometry
        ps = PointSet(points, design, g)
        n = len(self.hardpoints)
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
        shown = [m for m in METRICS if m.name in evaluated and (only is None or m.name in only)]
        drivers = self.corner.drivers
        out = []
        for s, step in enumerate(steps):
            values, units, metrics = {}, {}, {}
            for m in shown:
                v = evaluated[m.name]
                metrics[m.name] = float(of_state(v.val.val, s))
                values[m.name] = of_state(v.der.val[:, 0], s).reshape(n, 3) * 1e-3
                units[m.name] = f"{m.unit}/mm"
            for d in wanted:
                v = evaluated[d.metric.name]
                i = drivers.index(d.driver)
                metrics[d.name] = float(of_state(v.val.der[i], s)) * 1e-3
                values[d.name] = of_state(v.der.der[:, i], s).reshape(n, 3) * 1e-6
                units[d.name] = f"{d.unit}/mm"
            out.append(Sensitivity(step, self.hardpoints, values, units, metrics))
        return out


def needs_rates(g, only=None) -> bool:
    """Whether the columns ``only`` (None: every one) read the drivers' rates: a
    derivative column, or a metric of the rates (``Metric.rates``)."""
    if only is None:
        return True
    return any(d.name in only for d in derivative_columns(g)) or any(
        m.rates for m in METRICS if m.name in only
    )


def _unknown(s: Sensitivity) -> bool:
    return any(np.isnan(v).any() for v in s.values.values()) or any(
        np.isnan(v) for v in s.metrics.values()
    )


def of_state(x: np.ndarray, s: int) -> np.ndarray:
    """State s's entries of x (the states on its last axis; a column of the design
    alone, one entry)."""
    return x[..., s if x.shape[-1] > 1 else 0]


def _tilts(o: np.ndarray, e: np.ndarray) -> list[np.ndarray]:
    """A pivot axis o → e: its tilt ε = ω × δω per unit move of e's coordinates (x, y,
    z), then of o's."""
    w = unit(e - o)
    project = (E - np.outer(w, w)) / np.linalg.norm(e - o)
    return [np.cross(w, s * project[:, b]) for s in (1.0, -1.0) for b in range(3)]


def _same_structure(a: HardpointSensitivity, b: HardpointSensitivity) -> bool:
    """Whether two sensitivity models are of one structure, their Pinocchio data then
    interchangeable: the same joints, of the same kinds, and as many frames (named by
    the points and links: the tree's structure), and each joint along an axis of its
    own (a pivot's) along the same axis — the data keeps it, from the model it was
    made for."""
    ma, mb = a.model, b.model
    if a.hardpoints != b.hardpoints or ma.nframes != mb.nframes or list(ma.names) != list(mb.names):
        return False
    for x, y in zip(ma.joints, mb.joints, strict=True):
        kind = x.shortname()
        if kind != y.shortname():
            return False
        if kind.endswith("Unaligned") and not np.array_equal(x.extract().axis, y.extract().axis):
            return False
    return True


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
