"""The statics of a corner, an axle or a vehicle at its solved poses: every member's
and joint's force under every load case at once (docs/loads.md; a vehicle's in its
chassis frame, the body's joints held as rigid rows: docs/vehicle.md, "Loads").

At a pose q the closures' Jacobian J_c, the spring's row J_s (d length/dq of a
coilover, d angle/dq of a torsion bar) and the rack's row J_r hold every
freedom; a load w_p at a point p of the upright does virtual work through the
Jacobian J_p of the upright's material point there. Equilibrium is one linear
solve, [J_c; J_s; J_r]ᵀ λ = −Σ J_pᵀ w_p (no friction, no mass), and each
multiplier is a member's force: a distance closure's −λ is its tension, a ball
closure's λ the force the inboard part puts on the outboard one, the spring's λ
its compression, the rack's −λ the trackrods' pull on it along +Y.

The forces through the tree's own joints (pivots, the lower ball joint, a
multilink's lower front link) follow from Pinocchio's inverse dynamics at rest
(``rnea`` with v = a = 0 and no gravity) with the applied loads and the closure
forces as external forces: ``data.f[j]`` is then the force the parent puts on
the subtree through joint j. A pivot's two bushings share its force and moment
(the axial part equally: docs/loads.md's convention); a wishbone whose only
load is its outboard ball joint is a pair of two-force legs. A wishbone that
carries more (the pushrod, a coilover) is not: its leg columns are blank, and
every wishbone's bushing loads are also written resolved along each leg
(``load_<arm>_<end>_bushing_along_leg``, + as a tension; README, Loads and rates).
"""

from __future__ import annotations

import math

import numpy as np

from ..constraints import BallClosure, BarTwist, DistanceClosure, JointTarget, RockerTurn
from ..errors import PinSuspError
from ..solve.solver import NewtonSolver
from .load_case import LoadCase

# |J| condition number above which a pose is at a toggle: a member's force is unbounded
TOGGLE = 1e10


class Statics:
    """The equilibrium of a corner (a Linkage) or an axle (an AxleModel) at its poses,
    every load case at once.

    Per pose: the held rows' Jacobian J from the solver's batch — the closures, then
    each spring, an axle's anti-roll bar, the rack — and λ from Jᵀλ = −G·W, with
    G = [J_cp; J_wc; J_ω]ᵀ per wheel and W the cases' loads (a column each). With as
    many rows as freedoms that is one solve per pose for all cases, every pose at once
    (``solve_poses``). An axle whose bar (or rigid bar) shares the load with the
    springs has one row more than freedoms: statically
    indeterminate, it shares by stiffness — the λ of least complementary energy
    Σ λ_e²/k_e over the springs and the bar (Menabrea), i.e. the one whose elastic
    deflections are compatible.

    A tree joint's force (the parent's on its subtree) is minus the sum of the
    external forces on the subtree — the applied loads and the closures' multipliers
    at their ends, which bodies carry them being fixed by the tree — so no inverse
    dynamics runs per case (the tests check it against Pinocchio's ``rnea``).
    """

    def __init__(self, subject):
        self.subject, self.model = subject, subject.model
        held, compliance = [], []
        for label, g in subject.corners.items():
            prefix = subject.prefix(label)
            source = g.source
            if g.spring == "none":
                raise PinSuspError(
                    f"{source}: spring.type: none leaves bump without a load path (no member "
                    "holds the wheel up): give the corner a spring for its loads"
                )
            if g.spring == "coilover":
                top, bottom = (subject.points[f"{prefix}strut_{e}"] for e in ("top", "bottom"))
                held.append(DistanceClosure(f"{prefix}spring", top, bottom, 0.0))
                stiffness = None if g.spring_rate is None else g.spring_rate * 1e3  # N/m
            else:  # a torsion bar: the rocker's turn about its axis
                turn = RockerTurn(subject, prefix)
                # + resisting bump, as the sweep's spring_torque: bump turns the rocker
                # about a→b in the sense s·spring_sense (motion_ratio > 0 at design)
                turn.resisting = -g.sign * subject.spring_senses[label]
                held.append(turn)
                stiffness = None if g.spring_rate is None else g.spring_rate * 180 / np.pi
            compliance.append(stiffness)
        for joints, k, *name in subject.shared_springs:  # an axle's anti-roll bar, twisted
            held.append(BarTwist(self.model, list(joints), *name))
            compliance.append(None if k is None else k * 180 / np.pi)  # N·m/rad
        if "rack_slide" in [self.model.names[j] for j in range(self.model.njoints)]:
            held.append(JointTarget(self.model, "rack_slide"))
            compliance.append(np.inf)  # held by the steering: rigid
        for joint in subject.held_joints:  # a vehicle's body, held as a corner's chassis is
            held.append(JointTarget(self.model, joint))
            compliance.append(np.inf)
        self.solver = NewtonSolver(subject.kin, [*subject.closures, *held], [])
        self.rows = self.solver.rows
        self.size = self.solver.nrows
        source = subject.source
        if self.size < self.model.nv:
            raise PinSuspError(
                f"{source}: the closures, springs and rack hold {self.size} of the "
                f"{self.model.nv} freedoms: the loads are not determined"
            )
        # compliance per row (1/k; 0 for a rigid row): needed where rows outnumber freedoms
        self.compliance = None
        if self.size > self.model.nv:
            if any(k is None for k in compliance):
                raise PinSuspError(
                    f"{source}: the anti-roll bar and the springs share the load by their "
                    "stiffnesses: give each spring's rate (spring.rate) and the bar's "
                    "(axle_config.anti_roll.stiffness)"
                )
            c = np.zeros(self.size)
            c[self.size - len(held) :] = [1.0 / k for k in compliance]
            self.compliance = c
        self._plan()

    # ---------------------------------------------------------------- the plan

    def _plan(self) -> None:
        """Which multiplier acts where, which tree joint's subtree holds each end, and
        the column each output comes from (fixed by the tree: worked out once)."""
        subject, model = self.subject, self.model
        joint_of = lambda point: model.frames[point.frame_id].parentJoint  # noqa: E731
        self.ends = []  # (first multiplier, size, point, sign, the other end or None)
        self.direct = []  # (name, first multiplier, size, factor): the rows' own outputs
        self.couples = []  # (multiplier, a torsion bar's rocker turn)
        col = 0
        for row in self.rows:
            if isinstance(row, BallClosure):
                self.ends += [(col, 3, row.b, 1.0, None), (col, 3, row.a, -1.0, None)]
                name = row.name.removesuffix("_mount")
                self.direct.append((f"load_{name}", col, 3, -1.0))  # outboard on inboard
            elif isinstance(row, DistanceClosure):
                self.ends += [(col, 1, row.b, 1.0, row.a), (col, 1, row.a, -1.0, row.b)]
                spring = row.name.endswith("spring")  # compression +, a link's tension +
                self.direct.append((f"force_{row.name}", col, 1, 1.0 if spring else -1.0))
            elif isinstance(row, RockerTurn):
                self.couples.append((col, row))
                self.direct.append((f"torque_{row.prefix}spring", col, 1, row.resisting))
            elif isinstance(row, BarTwist):
                self.direct.append((f"torque_{row.name}", col, 1, 1.0))
            elif row.name == "hold rack_slide":  # held by the steering: the trackrods' pull
                self.direct.append(("force_rack", col, 1, -1.0))  # on it is −λ
            else:  # a held joint of the body: the load the wheels put on it along it, −λ
                joint = row.name.removeprefix("hold ")
                kind = model.joints[model.getJointId(joint)].shortname()
                what = "force" if kind.startswith("JointModelP") else "torque"
                self.direct.append((f"{what}_{joint}", col, 1, -1.0))
            col += row.size
        self.wheels = [
            (subject.points[f"{p}wheel_center"], subject.points[f"{p}contact_patch_center"])
            for p in map(subject.prefix, subject.labels)
        ]
        kin = subject.kin
        kin.update_positions(subject.q_design)
        self.spin = []  # each spin axis AI → AO in its wheel centre's frame
        for wc, cp in self.wheels:
            a = cp.axle_out.position(kin) - cp.axle_in.position(kin)
            self.spin.append(kin.data.oMf[wc.frame_id].rotation.T @ (a / np.linalg.norm(a)))
        self.joints = []  # (body, joint, index, ends inside, wheels inside, couples inside)
        for body in subject.tree.bodies:
            j = body.joint
            if j is None or j.name in subject.held_joints:  # a held body's: its rows' columns
                continue
            index = model.getJointId(j.name + {"ball": "_x", "universal": "_b"}.get(j.kind, ""))
            first = model.getJointId(j.name + {"ball": "_z", "universal": "_a"}.get(j.kind, ""))
            inside = lambda joint, first=first: first in model.supports[joint]  # noqa: E731
            ends = [k for k, e in enumerate(self.ends) if inside(joint_of(e[2]))]
            wheels = [k for k, (wc, _) in enumerate(self.wheels) if inside(joint_of(wc))]
            couples = [k for k, (_, t) in enumerate(self.couples) if inside(joint_of(t.point))]
            self.joints.append((body, j, index, ends, wheels, couples))
        # the ends as arrays: their frames (and the other end's), signs, multipliers
        self.frames = list(dict.fromkeys(e[2].frame_id for e in self.ends))
        place = {f: i for i, f in enumerate(self.frames)}
        self.end_at = np.array([place[e[2].frame_id] for e in self.ends], dtype=int)
        self.end_other = np.array([place[(e[4] or e[2]).frame_id] for e in self.ends], dtype=int)
        self.end_sign = np.array([e[3] for e in self.ends])
        self.end_rows = np.array(
            [[e[0] + (i if e[1] == 3 else 0) for i in range(3)] for e in self.ends], dtype=int
        )
        self.distance_ends = np.array([k for k, e in enumerate(self.ends) if e[1] == 1], dtype=int)
        self.directions = np.array(
            [np.eye(3) if e[1] == 3 else np.zeros((3, 3)) for e in self.ends]
        )
        self.specs = [self._joint_spec(body, j) for body, j, *_ in self.joints]
        self.wheel_joints = [
            [k for k, joint in enumerate(self.joints) if w in joint[4]]
            for w in range(len(self.wheels))
        ]
        self.couple_joints = [
            [k for k, joint in enumerate(self.joints) if c in joint[5]]
            for c in range(len(self.couples))
        ]
        self.extra_points = {}  # the points a joint's columns read at each pose
        for spec in self.specs:
            if spec[0] == "link":
                self.extra_points |= {spec[1].name: spec[1], spec[2].name: spec[2]}
            elif spec[0] == "pivot" and spec[4] is not None:
                self.extra_points[spec[5].name] = spec[5]
        self.subtree = np.zeros((len(self.joints), len(self.ends)))
        for k, (_, _, _, ends, _, _) in enumerate(self.joints):
            self.subtree[k, ends] = 1.0
        names = [
            n for name, _, size, _ in self.direct for n in (_xyz(name) if size == 3 else [name])
        ]
        for body, j, *_ in self.joints:
            names += self._joint_names(body, j)
        self.names = [_sided(n, subject.labels) for n in names]

    def _point(self, body: str, name: str) -> str:
        """A corner point's name in the subject: a labelled corner's carry its prefix (an
        axle's ``left_`` of its body ``left_upper_wishbone``)."""
        label = body.split("_", 1)[0]
        return self.subject.prefix(label) + name if label in self.subject.labels else name

    def _named(self, body: str, point: str) -> str:
        """A point's name in the subject: an axle's corner points carry their side."""
        sided = self._point(body, point)
        return sided if sided in self.subject.design_positions else point

    def _joint_names(self, body, j) -> list[str]:
        if self._bearing(body, j):  # a ball joint by its name; a bar's pivot by its point
            pivot = j.kind != "ball" and j.defined_by
            return _xyz(f"load_{j.defined_by[0] if pivot else j.name}")
        if j.kind == "universal":
            return [f"force_{body.name}"]
        if j.kind == "revolute" and len(j.defined_by) == 2:
            names = [f"load_{_bushing(self._point(body.name, n))}" for n in j.defined_by]
            legs = self._legs(body.name, j.defined_by)
            if legs is None:
                return _xyz(names[0]) + _xyz(names[1])
            along = [f"{name}_along_leg" for name in names]  # each bushing's load on its leg
            return _xyz(names[0]) + _xyz(names[1]) + list(legs) + along
        return []

    def _bearing(self, body, j) -> bool:
        """Whether a joint's load is written as one vector: a ball joint, a T-bar's
        pivot (universal, or revolute when rigid) — not a link or a two-bush pivot."""
        if j.kind == "ball":
            return True
        if j.kind == "universal":
            return f"{body.name}_inboard" not in self.subject.points
        return j.kind == "revolute" and len(j.defined_by) != 2

    def _legs(self, arm: str, pickups) -> dict | None:
        """A wishbone's legs: name → pickup (in the pivot's order); None for an arm that
        is no wishbone."""
        outboard = f"{arm}_outboard"
        if not arm.endswith("wishbone") or outboard not in self.subject.points:
            return None
        return {
            f"force_{arm}_{'front' if 'front' in n else 'rear'}": self._named(arm, n)
            for n in pickups
        }

    def _two_force(self, arm: str) -> bool:
        """Whether a wishbone's legs are two-force members: the arm is loaded at its
        outboard ball alone. A pushrod (or a coilover, a droplink) on it loads it
        elsewhere too: its legs then bend, and only the bushing loads resolved along
        each leg are written (``..._bushing_along_leg``), the leg columns blank."""
        outboard = f"{arm}_outboard"
        return not [
            n for n, (b, _) in self.subject.tree.points.items() if b == arm and n != outboard
        ]

    def not_two_force(self) -> dict[str, tuple[list, list, list]]:
        """The wishbones whose legs are not two-force members: arm → (the other points
        that load it, e.g. ``pushrod_outboard``; its blank leg columns; its bushings'
        ``..._along_leg`` columns), by the columns' names (an axle's with their side)."""
        out = {}
        for body, j, *_ in self.joints:
            arm = body.name
            if j.kind != "revolute" or len(j.defined_by) != 2:
                continue
            legs = self._legs(arm, j.defined_by)
            if not legs or self._two_force(arm):
                continue
            outboard = f"{arm}_outboard"
            points = [
                n for n, (b, _) in self.subject.tree.points.items() if b == arm and n != outboard
            ]
            along = [f"load_{_bushing(self._point(arm, n))}_along_leg" for n in j.defined_by]
            names = [_sided(n, self.subject.labels) for n in [*legs, *along]]
            out[arm] = (points, names[:2], names[2:])
        return out

    # ---------------------------------------------------------------- solving

    def loads_matrix(self, cases: list) -> np.ndarray:
        """W (9 per wheel × cases): each wheel's contact-patch force, wheel-centre force
        and moment, a case a column (an axle's case: its left and right parts)."""
        parts = [[c.wheel(label) for label in self.subject.labels] for c in cases]
        return np.array(
            [np.concatenate([np.r_[w.contact_patch, w.wheel_center, w.moment] for w in p])
             for p in parts], dtype=float
        ).T  # fmt: skip

    def solve_poses(self, qs: list, W: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(values (poses × self.names × cases), unbounded (poses)): every pose's
        kinematics read in turn, then the statics of all poses at once, as stacked
        arrays (a handful of numpy calls whatever the number of steps). ``W``: the
        cases' loads (``loads_matrix``), or each pose's (poses × 9 per wheel × cases:
        a vehicle's steady accelerations, road_loads.py)."""
        kin, model = self.subject.kin, self.model
        n = len(qs)
        W = W if W.ndim == 3 else W[None]
        Js = np.empty((n, self.size, model.nv))
        Gs = np.empty((n, model.nv, W.shape[1]))
        P = np.empty((n, len(self.frames), 3))
        wheels = np.empty((n, len(self.wheels), 2, 3))  # (wheel centre, contact patch)
        axes = np.empty((n, len(self.couples), 3))
        extra = {k: np.empty((n, 3)) for k in self.extra_points}
        for i, q in enumerate(qs):
            self.solver.evaluate(q)  # the kinematics (Jacobians too) and the held rows at q
            Js[i] = self.solver.jacobian
            self._load_map(wheels[i], Gs[i])
            oMf = kin.data.oMf
            P[i] = [oMf[f].translation for f in self.frames]
            for k, (_, turn) in enumerate(self.couples):
                axes[i, k] = turn.axis(kin)
            for name, point in self.extra_points.items():
                extra[name][i] = point.position(kin)
        lam, unbounded = self._multipliers(Js, Gs @ W)
        out = [factor * lam[:, col : col + size] for _, col, size, factor in self.direct]
        # every closure end's force (poses × ends × 3 × cases) and its moment
        at, other = P[:, self.end_at], P[:, self.end_other]
        u = self.end_sign[None, :, None] * (at - other)  # a distance's (b − a) at either end
        dist = u[:, self.distance_ends]
        directions = np.broadcast_to(self.directions, (n, *self.directions.shape)).copy()
        column = directions[..., 0]  # a view: û in column 0 of a distance end's
        column[:, self.distance_ends] = dist / np.linalg.norm(dist, axis=2)[..., None]
        forces = self.end_sign[None, :, None, None] * np.einsum(
            "seij,sejc->seic", directions, lam[:, self.end_rows]
        )
        moments = np.cross(at[..., None], forces, axisa=2, axisb=2, axisc=2)
        through_f = -np.einsum("je,seic->sjic", self.subtree, forces)
        through_m = -np.einsum("je,seic->sjic", self.subtree, moments)
        for k in range(len(self.wheels)):
            w = W[:, 9 * k : 9 * k + 9]
            load_f = w[:, 0:3] + w[:, 3:6]
            load_m = (
                np.cross(wheels[:, k, 1][..., None], w[:, 0:3], axisa=1, axisb=1, axisc=1)
                + np.cross(wheels[:, k, 0][..., None], w[:, 3:6], axisa=1, axisb=1, axisc=1)
                + w[:, 6:9]
            )
            for j in self.wheel_joints[k]:
                through_f[:, j] -= load_f
                through_m[:, j] -= load_m
        for k, (col, _) in enumerate(self.couples):
            couple = axes[:, k, :, None] * lam[:, col][:, None, :]
            for j in self.couple_joints[k]:
                through_m[:, j] -= couple
        for j, spec in enumerate(self.specs):
            out += self._joint_columns(spec, through_f[:, j], through_m[:, j], extra)
        values = np.concatenate(out, axis=1)
        values[unbounded] = np.nan
        return values, unbounded

    def _multipliers(self, Js: np.ndarray, GW: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """λ per pose (poses × rows × cases) from Jᵀλ = −G·W, and which poses are at a
        toggle (the held rows singular there)."""
        if self.compliance is None:
            # square: singular where the Hadamard ratio |det J| / Π‖row‖ ∈ (0, 1] is tiny
            # (rows dependent), or where a row all but vanishes against the others (a
            # member square to its motion); an SVD per pose costs ten times more
            sign, logdet = np.linalg.slogdet(Js)
            norms = np.linalg.norm(Js, axis=2)
            with np.errstate(divide="ignore", invalid="ignore"):  # a zero row: singular
                ratio = logdet - np.log(norms).sum(axis=1)
            small = norms.min(axis=1) < norms.max(axis=1) / TOGGLE
            unbounded = (sign == 0) | small | ~(ratio >= -np.log(TOGGLE))  # NaN: too
        else:
            s = np.linalg.svd(Js, compute_uv=False)
            unbounded = s[:, -1] < s[:, 0] / TOGGLE
        Jt = Js.transpose(0, 2, 1)
        if unbounded.any():
            Jt = Jt.copy()
            Jt[unbounded] = np.eye(*Jt.shape[1:])  # any solvable stand-in: blanked later
        if self.compliance is None:  # as many rows as freedoms
            return np.linalg.solve(Jt, -GW), unbounded
        # one row more than freedoms: the λ of least Σ c·λ² among the equilibria
        U, S, Vt = np.linalg.svd(Jt)
        rank = S.shape[1]
        particular = Vt[:, :rank].transpose(0, 2, 1) @ (
            (U.transpose(0, 2, 1) @ -GW) / S[:, :, None]
        )
        free = Vt[:, rank:].transpose(0, 2, 1)  # the null space of Jᵀ: self-stresses
        C = self.compliance[None, :, None] * free
        t = np.linalg.solve(free.transpose(0, 2, 1) @ C, -(C.transpose(0, 2, 1) @ particular))
        return particular + free @ t, unbounded

    def _load_map(self, places: np.ndarray | None = None, out: np.ndarray | None = None):
        """G (nv × 9 per wheel) = [J_cp; J_wc; J_ω]ᵀ at the current kinematics, with the
        upright's material point at the contact patch (into ``out`` if given);
        ``places`` (wheels × 2 × 3) receives each wheel's centre and contact patch.

        The patch CP = WC + R·d̂, d̂ = unit(a_z·â − Ẑ), with the spin axis â turning with
        the wheel centre's frame (its direction there fixed at design)."""
        kin = self.subject.kin
        G = np.empty((self.model.nv, 9 * len(self.wheels))) if out is None else out
        for k, (wc, cp) in enumerate(self.wheels):
            Jw = kin.frame_jacobian(wc.frame_id)  # linear at WC, angular: the upright's
            M = kin.data.oMf[wc.frame_id]
            ax, ay, az = (M.rotation @ self.spin[k]).tolist()
            norm = math.sqrt(1.0 - az * az)
            r = (
                az * ax * cp.radius / norm,
                az * ay * cp.radius / norm,
                (az * az - 1.0) * cp.radius / norm,
            )
            center = M.translation
            if places is not None:
                places[k, 0], places[k, 1] = center, center + r
            w = Jw[3:]
            G[:, 9 * k : 9 * k + 3] = (Jw[:3] - _skew(r) @ w).T
            G[:, 9 * k + 3 : 9 * k + 6] = Jw[:3].T
            G[:, 9 * k + 6 : 9 * k + 9] = w.T
        return G

    def generalized(self, q: np.ndarray, case) -> np.ndarray:
        """Σ J_pᵀ w_p at q: the case's generalised force (its virtual work per dq)."""
        self.subject.kin.update(q)
        return self._load_map() @ self.loads_matrix([case])[:, 0]

    def _joint_spec(self, body, j) -> tuple:
        """What a tree joint writes, with what is fixed about it worked out once."""
        subject = self.subject
        if self._bearing(body, j):
            return ("ball",)
        if j.kind == "universal":  # a link from a universal joint to a ball: two-force
            ends = (subject.points[f"{body.name}_inboard"], subject.points[f"{body.name}_outboard"])
            return ("link", *ends)
        if j.kind != "revolute" or len(j.defined_by) != 2:
            return ("none",)
        a, b = (subject.design_positions[self._named(body.name, n)] for n in j.defined_by)
        d = b - a
        legs = self._legs(body.name, j.defined_by)
        pickups = None
        if legs is not None:
            pickups = np.array([subject.design_positions[n] for n in legs.values()])
        ball = subject.points.get(f"{body.name}_outboard")
        two_force = legs is not None and self._two_force(body.name)
        return ("pivot", a, d[:, None], d[:, None] / (d @ d), pickups, ball, two_force)

    def _joint_columns(self, spec, force, moment, extra) -> list[np.ndarray]:
        """From the parent's force on a subtree (poses × 3 × cases) and its moment about
        the world origin: a ball joint's load, a link's tension, a pivot's bushings and
        legs (each poses × rows × cases)."""
        kind = spec[0]
        if kind == "ball":
            return [-force]  # outboard on inboard (a pivot's: the bar on the chassis)
        if kind == "link":
            u = extra[spec[1].name] - extra[spec[2].name]
            u = u / np.linalg.norm(u, axis=1)[:, None]
            return [np.einsum("si,sic->sc", u, force)[:, None]]
        if kind == "none":
            return []
        _, a, d, d_scaled, pickups, ball, two_force = spec
        if pickups is not None:  # a wishbone: its legs' directions, pickup → ball
            U = (extra[ball.name][:, None, :] - pickups[None]).transpose(0, 2, 1)  # s × 3 × 2
            U = U / np.linalg.norm(U, axis=1)[:, None, :]
        if two_force:  # two two-force legs: each bush takes its leg's pull
            Ut = U.transpose(0, 2, 1)
            # the chassis holds the arm through its legs: force = −Σ tension · (pickup → ball)ˆ
            t = np.linalg.solve(Ut @ U, Ut @ -force)  # exact: the force is in their plane
            out = [U[:, :, :1] * t[:, 0:1], U[:, :, 1:] * t[:, 1:2], t]  # tension · û
        else:
            at_a = moment - np.cross(a[None, :, None], force, axisa=1, axisb=1, axisc=1)
            dd = float((d.T @ d)[0, 0])
            on_b = np.cross(at_a, d[None], axisa=1, axisb=1, axisc=1) / dd + d_scaled[None] * (
                0.5 * np.einsum("i,sic->sc", d[:, 0], force)[:, None]
            )
            out = [on_b - force, -on_b]  # the bushings' loads on the chassis (axial: halves)
            if pickups is None:
                return out
            out.append(np.full((force.shape[0], 2, force.shape[2]), np.nan))  # no leg forces
        # each bushing's load on the chassis resolved along its leg (+ pulling the chassis
        # toward the ball, as a leg's tension): the leg's tension where it is two-force
        along = [np.einsum("si,sic->sc", U[:, :, k], out[k])[:, None] for k in range(2)]
        return [*out, *along]

    def solve_cases(self, q: np.ndarray, cases: list[LoadCase]) -> list[dict[str, float]]:
        """The columns under each case at q, as dicts; at a toggle every force is NaN and
        ``loads_unbounded`` is 1."""
        (values,), (unbounded,) = self.solve_poses([q], self.loads_matrix(cases))
        flag = float(unbounded)  # at a toggle the values are NaN already
        return [
            dict(zip(self.names, values[:, k].tolist(), strict=True)) | {"loads_unbounded": flag}
            for k in range(len(cases))
        ]

    def solve(self, q: np.ndarray, case: LoadCase) -> dict[str, float]:
        """Every force column at the pose q under the case (N, N·m)."""
        return self.solve_cases(q, [case])[0]


def _xyz(name: str) -> list[str]:
    return [f"{name}_{a}" for a in "xyz"]


def _sided(name: str, labels: tuple[str, ...]) -> str:
    """A column's name with its corner's label last: an axle's force_left_trackrod →
    force_trackrod_left, load_left_lower_ball_joint_x → load_lower_ball_joint_x_left (a
    corner's, labelled "", as it is)."""
    head, _, rest = name.partition("_")
    for label in labels:
        if label and rest.startswith(label + "_"):
            return f"{head}_{rest[len(label) + 1 :]}_{label}"
    return name


def _bushing(point: str) -> str:
    """The bushing at a pivot pickup: lower_wishbone_inboard_front →
    lower_wishbone_front_bushing, rocker_axis_a → rocker_a_bushing."""
    for part in ("inboard_", "axis_", "pivot_"):
        point = point.replace(part, "")
    return f"{point}_bushing"


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
