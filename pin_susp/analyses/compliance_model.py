"""The elastokinematic model of a corner or an axle (docs/compliance.md, "Model"): its
rigid kinematics plus the coordinates its compliant elements add, and its equilibrium
under a load — linear (one KKT solve at the kinematic pose) or nonlinear (the loaded
pose by Newton iterations on the same equations).

Coordinates x = (q; ε_b per compliant body; e per compliant link; s per tyre):
- a body with a bushing at a pickup of its pivot (a chassis child: a wishbone, a
  rocker) is given a rigid motion T_b relative to its rigid placement — its twist
  ε_b = (v, ω) in world axes about its pivot's midpoint o_b — and its revolute joint
  is held at the pose's angle (ε_b's turn about the pivot carries that freedom); a
  pickup of that pivot without a bushing is a ball joint there (T_b(p) = p);
- a compliant link's closure |b − a| = L + e, its stretch e a coordinate;
- a tyre's deflection s (world y, z) at the contact patch: the road's force acts at
  CP + s, the tyre spring between.

Every frame in a compliant body's subtree is moved by T_b after the tree's own
kinematics (``AugmentedKinematics``), and its Jacobian gets ε_b's columns — so the
existing closure rows, read from these frames, give the augmented Jacobians
unchanged. The potential is Σ ½ dᵢᵀKᵢdᵢ (dᵢ the bushing's deflection in its frame:
the pickup's displacement T_b(p) − p and the rotation log(R_b)) + Σ ½ k e² + ½ sᵀk s;
the load does work wᵀ(δx_p). At the kinematic pose (T = I, e = s = 0) the equilibrium
to first order is [K A ᵀ; A 0][δx; λ] = [G w; 0] — K = Σ Bᵢᵀ Kᵢ Bᵢ, A the held rows
(closures, springs, rack, the locks and balls above), G the load's map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..constraints import DistanceClosure, JointTarget, Kinematics
from ..constraints.kinematics import WORLD
from ..errors import InputError, PinSuspError

CONDITION = 1e12  # the reduced stiffness' condition number above which a freedom is unheld
NEWTON_TOL = 1e-9  # the loaded pose's force balance, relative to the largest load
STEP_TOL = 1e-14  # m, rad: the last step's largest part
MAX_ITER = 60
EYE3 = np.eye(3)


def skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def bushing_frame(axis: np.ndarray) -> np.ndarray:
    """R (columns x, y radial, z axial): z along the pivot line a → b; x the world
    vertical's part normal to it (the world x's, for a near-vertical pivot); y = z × x."""
    z = axis / math.sqrt(axis @ axis)
    up = np.array([0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = up - (up @ z) * z
    x /= math.sqrt(x @ x)
    return np.column_stack([x, skew(z) @ x, z])


@dataclass
class CompliantBody:
    name: str
    joint: str  # its revolute, held at the pose's angle
    column: int  # ε_b's first column in x
    origin: np.ndarray  # o_b (m)
    frames: list  # every frame its subtree carries
    bushings: list  # (column name, pickup position, R, K, suffix)
    balls: list  # rigid pickups: positions
    ends: tuple = ()  # the pivot's two points: (point, bushing's K or None, name, suffix)

    def place(self, kin) -> None:
        """The pivot's pickups, origin and bushing frame where the pose puts them (a
        car's chassis moves: its pickups with it)."""
        p = [point.position(kin).copy() for point, *_ in self.ends]
        R = bushing_frame(p[1] - p[0])
        self.origin = 0.5 * (p[0] + p[1])
        self.bushings = [
            (f"bushing_{n}", x, R, k, sfx)
            for x, (_, k, n, sfx) in zip(p, self.ends, strict=True)
            if k is not None
        ]
        self.balls = [x for x, (_, k, *_) in zip(p, self.ends, strict=True) if k is None]


class AugmentedKinematics(Kinematics):
    """The tree's kinematics at q with each compliant body's subtree moved by its T_b
    (pin.SE3, world); ``frame_jacobian`` has the n = nv + extra columns of x."""

    def __init__(self, model: pin.Model, bodies: list, n: int):
        super().__init__(model)
        self.bodies, self.n = bodies, n
        self.owner = {f: k for k, b in enumerate(bodies) for f in b.frames}
        self.T = [pin.SE3.Identity() for _ in bodies]
        self.rigid = {}

    def update(self, q: np.ndarray, T: list | None = None) -> None:
        """The frames at q, each compliant subtree moved by its T (none given: every T
        the identity, the rigid tree's frames as they are)."""
        self.q = q
        self.moved = T is not None
        self.T = [pin.SE3.Identity() for _ in self.bodies] if T is None else T
        self.cache = {}
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        if not self.moved:
            return
        oMf = self.data.oMf
        for b, M in zip(self.bodies, self.T, strict=True):
            for f in b.frames:
                self.rigid[f] = oMf[f].translation.copy()
                oMf[f] = M * oMf[f]

    update_positions = update

    def frame_jacobian(self, frame_id: int) -> np.ndarray:
        """The frame's 6 × n Jacobian in x (read-only: one array per frame and update)."""
        out = self.cache.get(frame_id)
        if out is None:
            out = self.cache[frame_id] = self._jacobian(frame_id)
            out.flags.writeable = False
        return out

    def _jacobian(self, frame_id: int) -> np.ndarray:
        model, data, nv = self.model, self.data, self.model.nv
        out = np.zeros((6, self.n))
        k = self.owner.get(frame_id)
        if k is None:
            out[:, :nv] = pin.getFrameJacobian(model, data, frame_id, WORLD).reshape(6, -1)
            return out
        joint = model.frames[frame_id].parentJoint
        J = pin.getJointJacobian(model, data, joint, pin.WORLD).reshape(6, -1)
        here = data.oMf[frame_id].translation
        if self.moved:
            R = self.T[k].rotation
            out[:3, :nv] = R @ (J[:3] - skew(self.rigid[frame_id]) @ J[3:])
            out[3:, :nv] = R @ J[3:]
        else:  # T = I: the tree's own (LOCAL_WORLD_ALIGNED) Jacobian
            out[:3, :nv] = J[:3] - skew(here) @ J[3:]
            out[3:, :nv] = J[3:]
        b = self.bodies[k]
        c = b.column
        out[:3, c : c + 3] = EYE3
        out[:3, c + 3 : c + 6] = -skew(here - b.origin)
        out[3:, c + 3 : c + 6] = EYE3
        return out


class ComplianceModel:
    """A subject's compliant model (module docstring). ``compliances``: label → its
    corner's Compliance (model/compliance.py)."""

    def __init__(self, subject, compliances: dict):
        self.subject = subject
        model = subject.model
        self.model, nv = model, model.nv
        col = nv
        self.bodies, self.links, self.tyres = [], {}, []
        closures = list(subject.closures)
        link_names = {c.name: c for c in closures if isinstance(c, DistanceClosure)}
        tree_bodies = {b.name: b for b in subject.tree.bodies}
        links, tyres = [], []
        for label, comp in compliances.items():
            prefix, g = subject.prefix(label), subject.corners[label]
            source, suffix = g.source, subject.suffix(label)
            pivots = {}  # body → its bushings' pickups
            for pickup in comp.bushings:
                key = f"compliance.bushings.{pickup}"
                body = self._pivot_body(tree_bodies, pickup, prefix)
                if body is None:
                    raise InputError(
                        source,
                        key,
                        "not a pickup of a pivot on the chassis (a bushing sits at one of "
                        "the two points of a wishbone's or a rocker's pivot)",
                    )
                pivots.setdefault(body, []).append(pickup)
            for body, pickups in pivots.items():
                b = tree_bodies[body]
                ends = [subject.design_positions[prefix + n] for n in self._unprefixed(b, prefix)]
                R = bushing_frame(ends[1] - ends[0])
                jid = model.getJointId(b.joint.name)
                frames = [
                    f
                    for f in range(len(model.frames))
                    if jid in model.supports[model.frames[f].parentJoint]
                ]
                bushings, balls, at = [], [], []
                for n, p in zip(self._unprefixed(b, prefix), ends, strict=True):
                    k = comp.bushings[n] if n in pickups else None
                    at.append((subject.points[prefix + n], k, n, suffix))
                    if k is not None:
                        bushings.append((f"bushing_{n}", p, R, k, suffix))
                    else:
                        balls.append(p)
                origin = 0.5 * (ends[0] + ends[1])
                self.bodies.append(
                    CompliantBody(
                        body, b.joint.name, col, origin, frames, bushings, balls, tuple(at)
                    )
                )
                col += 6
            for name, k in comp.links.items():
                closure = link_names.get(prefix + name)
                if closure is None or name == "spring":
                    known = ", ".join(
                        sorted(n.removeprefix(prefix) for n in link_names if n.startswith(prefix))
                    )
                    raise InputError(
                        source, f"compliance.links.{name}", f"no such link here (links: {known})"
                    )
                links.append((closure.name, k, name, suffix))
            if comp.tyre:
                tyres.append((label, comp.tyre.get("lateral"), comp.tyre.get("vertical")))
        for name, *rest in links:  # x: q, every body's ε, every link's e, every tyre's s
            self.links[name] = (col, *rest)
            col += 1
        for label, *rest in tyres:
            self.tyres.append((label, col, *rest))
            col += 2
        self.n = col
        self.kin = AugmentedKinematics(model, self.bodies, self.n)
        self.rows = closures + self._held_rows()
        self.wheels = [
            (subject.points[f"{p}wheel_center"], subject.points[f"{p}contact_patch_center"])
            for p in map(subject.prefix, subject.labels)
        ]
        self.tyre_col = {label: (c, kl, kv) for label, c, kl, kv in self.tyres}

    @staticmethod
    def _unprefixed(body, prefix: str) -> list[str]:
        return [n.removeprefix(prefix) for n in body.joint.defined_by]

    def _pivot_body(self, bodies: dict, point: str, prefix: str) -> str | None:
        """The chassis child of the corner (its bodies prefixed) whose pivot has the point."""
        for b in bodies.values():
            j = b.joint
            if (
                j is not None
                and b.parent == "chassis"
                and b.name.startswith(prefix)
                and j.kind == "revolute"
                and len(j.defined_by) == 2
                and point in self._unprefixed(b, prefix)
            ):
                return b.name
        return None

    def _held_rows(self) -> list:
        """The springs (rigid: the wheel's height held), the rack, a vehicle's body."""
        subject, model = self.subject, self.model
        held = []
        for label, g in subject.corners.items():
            prefix = subject.prefix(label)
            if g.spring == "none":
                raise PinSuspError(
                    f"{g.source}: spring.type: none leaves bump without a load path: give the "
                    "corner a spring for its compliance"
                )
            if g.spring == "coilover":
                top, bottom = (subject.points[f"{prefix}strut_{e}"] for e in ("top", "bottom"))
                held.append(_Held(DistanceClosure(f"{prefix}spring", top, bottom, 0.0)))
            else:  # a torsion bar: its rocker held at its angle
                joint = f"{prefix}rocker_pivot"
                if any(b.joint == joint for b in self.bodies):
                    raise InputError(
                        g.source,
                        "compliance.bushings",
                        "a rocker with a torsion bar on bushings is not modelled yet",
                    )
                held.append(_Held(JointTarget(model, joint)))
        names = [model.names[j] for j in range(model.njoints)]
        for joint in ("rack_slide", *subject.held_joints):
            if joint in names:
                held.append(_Held(JointTarget(model, joint)))
        return held

    # ------------------------------------------------------------ one state

    def evaluate(self, q, T, e, s, w=None, at_pose=False):
        """At the state (q, T, e, s): the held rows' residual c and Jacobian A, the
        elastic gradient g and Gauss-Newton stiffness K, the load map G (n × 9 per
        wheel), the frames' data for the outputs; ``w`` the loads (9 per wheel);
        ``at_pose``: the state is ``at_pose``'s own (its kinematics already updated)."""
        kin, n = self.kin, self.n
        if not at_pose:
            kin.update(q, T)
        c, A = [], []
        for row in self.active:
            r = np.atleast_1d(row.residual(kin))
            J = np.atleast_2d(row.jacobian(kin))
            if J.shape[1] < n:
                J = np.pad(J, ((0, 0), (0, n - J.shape[1])))
            link = self.links.get(row.name)
            if link is not None:
                r = r - e[link[0] - self._e0]
                J = J.copy()
                J[0, link[0]] = -1.0
            c.append(r)
            A.append(J)
        grad, K = np.zeros(n), np.zeros((n, n))
        deflections = {}
        for b, M in zip(self.bodies, T, strict=True):
            jrow = np.zeros((1, n))
            jm = self.model.joints[self.model.getJointId(b.joint)]
            jrow[0, jm.idx_v] = 1.0
            c.append(np.array([q[jm.idx_q] - self.q0[jm.idx_q]]))
            A.append(jrow)
            cb = b.column
            for p in b.balls:
                moved = M.act(p)
                c.append(moved - p)
                J = np.zeros((3, n))
                J[:, cb : cb + 3] = np.eye(3)
                J[:, cb + 3 : cb + 6] = -skew(moved - b.origin)
                A.append(J)
            phi = pin.log3(M.rotation)
            Jl = pin.Jlog3(M.rotation) @ M.rotation.T
            for name, p, R, Kb, suffix in b.bushings:
                moved = M.act(p)
                d = np.concatenate([R.T @ (moved - p), R.T @ phi])
                D = np.zeros((6, 6))
                D[:3, :3] = R.T
                D[:3, 3:] = -R.T @ skew(moved - b.origin)
                D[3:, 3:] = R.T @ Jl
                grad[cb : cb + 6] += D.T @ Kb @ d
                K[cb : cb + 6, cb : cb + 6] += D.T @ Kb @ D
                deflections[(name, suffix)] = (d, D, cb)
        for col, k, *_ in self.links.values():
            grad[col] += k * e[col - self._e0]
            K[col, col] += k
        for _, col, kl, kv in self.tyres:
            for i, k in enumerate((kl, kv)):
                if k is not None:
                    grad[col + i] += k * s[col + i - self._s0]
                    K[col + i, col + i] += k
                else:  # rigid in that direction: held
                    row = np.zeros((1, n))
                    row[0, col + i] = 1.0
                    c.append(np.array([s[col + i - self._s0]]))
                    A.append(row)
        G = self.load_map()
        return np.concatenate(c), np.vstack(A), grad, K, G, deflections

    def load_map(self) -> np.ndarray:
        """G (n × 9 per wheel): the contact patch's (the upright's material point there,
        plus the tyre's deflection), the wheel centre's and the upright's turn columns."""
        kin = self.kin
        G = np.zeros((self.n, 9 * len(self.wheels)))
        for k, (wc, cp) in enumerate(self.wheels):
            Jw = kin.frame_jacobian(wc.frame_id)
            r = cp.position(kin) - wc.position(kin)
            G[:, 9 * k : 9 * k + 3] = (Jw[:3] - skew(r) @ Jw[3:]).T
            G[:, 9 * k + 3 : 9 * k + 6] = Jw[:3].T
            G[:, 9 * k + 6 : 9 * k + 9] = Jw[3:].T
            tyre = self.tyre_col.get(self.subject.labels[k])
            if tyre is not None:
                G[tyre[0], 9 * k + 1] += 1.0
                G[tyre[0] + 1, 9 * k + 2] += 1.0
        return G

    # ------------------------------------------------------------ solves

    def at_pose(self, q0: np.ndarray):
        """Fix the kinematic pose q0 (the reference of every deflection)."""
        self.q0 = q0
        self._e0 = self.model.nv + 6 * len(self.bodies)
        self._s0 = self._e0 + len(self.links)
        kin = self.kin
        kin.update(q0)
        for b in self.bodies:
            b.place(kin)
        self.active = []  # the held rows, each zero at q0 (a spring at its length there)
        for row in self.rows:
            if isinstance(row, _Held):
                row = _Held(row.row, row.row.residual(kin))
            self.active.append(row)
        self.zero = (
            [pin.SE3.Identity() for _ in self.bodies],
            np.zeros(len(self.links)),
            np.zeros(2 * len(self.tyres)),
        )

    def linear(self, q0: np.ndarray, loads: np.ndarray):
        """δx (n × cases) of the first-order equilibrium at q0 under ``loads`` (9 per
        wheel × cases), and the state's data (``evaluate``'s) at q0."""
        self.at_pose(q0)
        state = self.evaluate(q0, *self.zero, at_pose=True)
        _, A, _, K, G, _ = state
        return solve_kkt(K, A, G @ loads, self.subject.source), state

    def nonlinear(self, q0: np.ndarray, w: np.ndarray):
        """The loaded pose under one case's loads ``w`` (9 per wheel): (q, T, e, s), by
        Newton-type iterations on the equilibrium ∇Π − G(x)w + Aᵀλ = 0, c(x) = 0 (the
        Gauss-Newton stiffness and the held rows' Jacobian as its matrix)."""
        self.at_pose(q0)
        q = q0.copy()
        T, e, s = (list(self.zero[0]), self.zero[1].copy(), self.zero[2].copy())
        lam = None
        scale = max(float(np.abs(w).max()), 1e-300)
        for _ in range(MAX_ITER):
            c, A, grad, K, G, _ = self.evaluate(q, T, e, s)
            if lam is None:
                lam = np.zeros(len(c))
            f = grad - G @ w + A.T @ lam
            m = len(c)
            M = np.zeros((self.n + m, self.n + m))
            M[: self.n, : self.n], M[: self.n, self.n :], M[self.n :, : self.n] = K, A.T, A
            step = np.linalg.solve(M, -np.concatenate([f, c]))
            dx, lam = step[: self.n], lam + step[self.n :]
            q = pin.integrate(self.model, q, dx[: self.model.nv])
            for k, b in enumerate(self.bodies):
                v, wv = dx[b.column : b.column + 3], dx[b.column + 3 : b.column + 6]
                Rd = pin.exp3(wv)
                T[k] = pin.SE3(Rd, b.origin - Rd @ b.origin + v) * T[k]
            e = e + dx[self._e0 : self._s0]
            s = s + dx[self._s0 :]
            if np.abs(dx).max() < STEP_TOL and np.abs(f).max() < NEWTON_TOL * scale:
                return q, T, e, s
        raise PinSuspError(f"{self.subject.source}: the loaded pose did not converge")


class _Held:
    """A driver's row held at its value at the pose: a spring at its length, the rack
    and a rocker (a torsion bar's) at their positions."""

    def __init__(self, row, value=0.0):
        self.row, self.value, self.name = row, value, row.name

    def residual(self, kin):
        return self.row.residual(kin) - self.value

    def jacobian(self, kin):
        return self.row.jacobian(kin)


def solve_kkt(K: np.ndarray, A: np.ndarray, F: np.ndarray, source: str) -> np.ndarray:
    """δx minimising ½δxᵀKδx − Fᵀδx under A·δx = 0 (every column of F): through A's
    null space N, δx = N (NᵀKN)⁻¹ NᵀF. A freedom neither held nor sprung: an error."""
    _, S, Vt = np.linalg.svd(A)
    rank = int((S > S[0] * 1e-12).sum())
    N = Vt[rank:].T
    Kr = N.T @ K @ N
    ev = np.linalg.eigvalsh(Kr)
    if ev.min() <= ev.max() / CONDITION:
        raise PinSuspError(
            f"{source}: the compliance leaves a freedom neither held nor sprung (a bushing "
            "with no rate in some direction and no other part holding it): give it a rate"
        )
    return N @ np.linalg.solve(Kr, N.T @ F)
