"""Quasi-static loads: the force in every member and joint at a solved pose
(spec/loads.md).

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
(the axial part equally: spec/loads.md's convention); a wishbone whose only
load is its outboard ball joint is a pair of two-force legs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from scipy.linalg import lapack

from .closures import BallClosure, DistanceClosure, JointTarget
from .errors import PinSuspError
from .sweep import Sweep
from .yamlio import Reader, load_yaml

# |J| condition number above which a pose is at a toggle: a member's force is unbounded
TOGGLE = 1e10
CASE_KEYS = ("contact_patch", "wheel_center", "moment")


@dataclass(frozen=True)
class LoadCase:
    """Loads on one wheel, world (chassis) axes: force at the contact patch (N, the
    road on the tyre), force at the wheel centre (N) and a moment (N·m)."""

    name: str
    contact_patch: np.ndarray
    wheel_center: np.ndarray
    moment: np.ndarray


def load_cases(source) -> list[LoadCase]:
    """Read a load-case file (spec/loads.md): ``cases:`` a list of {name,
    contact_patch: {fx, fy, fz}, wheel_center: {…}, moment: {mx, my, mz}}."""
    data, name, _ = load_yaml(source)
    r = Reader(name)
    r.mapping(data, "", required=("cases",), optional=("version",))
    cases = data["cases"]
    if not isinstance(cases, list) or not cases:
        r.fail("cases", "expected a list of load cases")
    out, seen = [], set()
    for i, case in enumerate(cases):
        key = f"cases[{i}]"
        r.mapping(case, key, required=("name",), optional=(*CASE_KEYS, "left", "right"))
        for side in ("left", "right"):
            if side in case:
                r.fail(f"{key}.{side}", "a side block is for an axle's load cases")
        title = r.text(case["name"], f"{key}.name")
        if title in seen:
            r.fail(f"{key}.name", f"{title!r} names two cases")
        seen.add(title)
        vectors = {}
        for part, axes in (("contact_patch", "f"), ("wheel_center", "f"), ("moment", "m")):
            block = case.get(part, {})
            names = tuple(f"{axes}{a}" for a in "xyz")
            block = r.mapping(block, f"{key}.{part}", optional=names)
            vectors[part] = np.array(
                [r.number(block.get(n, 0.0), f"{key}.{part}.{n}") for n in names]
            )
        out.append(LoadCase(str(title), **vectors))
    return out


def member_forces(corner, sweep, cases: list, solutions=None, results=None, progress=None):
    """Every force column at every step of a sweep under every load case (spec/loads.md):
    a Results with one row per step and case — ``step_index``, ``load_case``,
    ``loads_unbounded`` (1 at a toggle: the forces there are blank, not huge), the
    forces, then the sweep's own columns. ``corner``: a Corner; ``sweep``: a Sweep,
    path or dict; ``cases``: LoadCases or a load-case file."""
    from .corner import Results
    from .sweep import load_sweep

    if not isinstance(sweep, Sweep):
        sweep = load_sweep(sweep)
    if not isinstance(cases, list):
        cases = load_cases(cases)
    statics = Statics(corner)
    if solutions is None:
        solutions = corner.solve_steps(sweep)
    if results is None:
        results = Results.from_solutions(corner, solutions, sweep)
    names = statics.names
    rows = []
    for i, solution in enumerate(solutions):
        if solution.converged:
            rows += statics.solve_cases(solution.q, cases)
        else:
            rows += [dict.fromkeys(names, np.nan) | {"loads_unbounded": np.nan} for _ in cases]
        if progress is not None:
            progress(i + 1, len(solutions))
    n = len(cases)
    columns = {
        "step_index": np.repeat(results["step_index"], n),
        "load_case": np.array([c.name for c in cases] * len(solutions), dtype=object),
    }
    units = {"step_index": "", "load_case": ""}
    for name in ["loads_unbounded", *names]:
        columns[name] = np.array([row[name] for row in rows])
        units[name] = (
            "N·m" if name.startswith("torque") else "" if name == "loads_unbounded" else "N"
        )
    for name, values in results.columns.items():
        if name != "step_index":
            columns[name] = np.repeat(values, n)
            units[name] = results.units.get(name, "")
    return Results(columns, units, results.meta)


class Statics:
    """The equilibrium of one corner (a Linkage) at its poses."""

    def __init__(self, corner):
        g = corner.geometry
        self.corner, self.model = corner, corner.model
        self.data = self.model.createData()
        self.upright = corner.mechanism.WHEEL_BODY
        held = []
        if g.spring == "none":
            raise PinSuspError(
                f"{g.source}: spring.type: none leaves bump without a load path (no member "
                "holds the wheel up): give the corner a spring for its loads"
            )
        if g.spring == "coilover":
            top, bottom = corner.points["strut_top"], corner.points["strut_bottom"]
            held.append(DistanceClosure("spring", top, bottom, 0.0))
        else:  # a torsion bar: the rocker's turn about its axis
            held.append(_RockerTurn(corner))
        if g.steering == "rack":
            held.append(JointTarget(self.model, "rack_slide"))
        self.rows = list(corner.closures) + held
        self._names = None
        self.size = sum(row.size for row in self.rows)
        if self.size != self.model.nv:
            raise PinSuspError(
                f"{g.source}: the closures, spring and rack hold {self.size} of the "
                f"{self.model.nv} freedoms: the loads are not determined"
            )

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """The held rows' Jacobian at q (the corner's kinematics updated to q)."""
        kin = self.corner.kin
        kin.update(q)
        return np.vstack([row.jacobian(kin) for row in self.rows])

    def applied(self, case: LoadCase) -> np.ndarray:
        """Σ J_pᵀ w_p: the generalised force of the case at the current pose."""
        corner, kin = self.corner, self.corner.kin
        wc = corner.points["wheel_center"]
        J = kin.frame_jacobian(wc.frame_id)  # linear at WC, angular: the upright's
        r = corner.points["contact_patch_center"].position(kin) - wc.position(kin)
        at_patch = J[:3] - _skew(r) @ J[3:]  # the upright's material point at the patch
        return (
            at_patch.T @ case.contact_patch
            + J[:3].T @ case.wheel_center
            + J[3:].T @ case.moment  # a couple: the same at any point of the upright
        )

    def solve(self, q: np.ndarray, case: LoadCase) -> dict[str, float]:
        """Every force column at the pose q under the case (N, N·m)."""
        return self.solve_cases(q, [case])[0]

    def solve_cases(self, q: np.ndarray, cases: list[LoadCase]) -> list[dict[str, float]]:
        """The columns under each case at q: one factorisation of the held rows for all
        cases. At a toggle (the rows singular: a member cannot hold its load, the force
        is unbounded) every force is NaN and ``loads_unbounded`` is 1."""
        J = self.jacobian(q)
        lu, pivots, info = lapack.dgetrf(J.T)
        rcond = lapack.dgecon(lu, np.abs(J).sum(axis=1).max())[0] if info == 0 else 0.0
        if rcond < 1.0 / TOGGLE:
            return [dict.fromkeys(self.names, np.nan) | {"loads_unbounded": 1.0} for _ in cases]
        applied = np.column_stack([self.applied(case) for case in cases])
        lam = lapack.dgetrs(lu, pivots, -applied)[0]
        return [
            self._columns(q, lam[:, k], case) | {"loads_unbounded": 0.0}
            for k, case in enumerate(cases)
        ]

    @property
    def names(self) -> list[str]:
        """The force columns, in order (worked out once, at the design state)."""
        if self._names is None:
            q = self.corner.q_design
            zero = LoadCase("", np.zeros(3), np.zeros(3), np.zeros(3))
            self.jacobian(q)
            self._names = list(self._columns(q, np.zeros(self.size), zero))
        return self._names

    # ---------------------------------------------------------------- the columns

    def _columns(self, q, lam, case) -> dict[str, float]:
        corner, kin, model = self.corner, self.corner.kin, self.model
        out, external = {}, [pin.Force.Zero() for _ in range(model.njoints)]

        def push(point, force, moment=None):
            """A force (and couple) at a frame point, world axes, as the joint's fext."""
            frame = model.frames[point.frame_id]
            if frame.parentJoint == 0:
                return
            p = point.position(kin)
            couple = np.cross(p, force) if moment is None else np.cross(p, force) + moment
            world = pin.Force(force, couple)
            external[frame.parentJoint] += kin.data.oMi[frame.parentJoint].actInv(world)

        i = 0
        for row in self.rows:
            value = lam[i : i + row.size]
            i += row.size
            if isinstance(row, BallClosure):
                out |= _vector(
                    f"load_{row.name.removesuffix('_mount')}", -value
                )  # outboard on inboard
                push(row.b, value)
                push(row.a, -value)
            elif isinstance(row, DistanceClosure):
                u = row.b.position(kin) - row.a.position(kin)
                u /= np.linalg.norm(u)
                name = "force_spring" if row.name == "spring" else f"force_{row.name}"
                out[name] = value[0] if row.name == "spring" else -value[0]
                push(row.b, value[0] * u)
                push(row.a, -value[0] * u)
            elif isinstance(row, _RockerTurn):
                out["torque_spring"] = value[0]
                push(row.point, np.zeros(3), value[0] * row.axis(kin))
            else:  # the rack: held by the steering
                out["force_rack"] = -value[0]
        # the applied loads, on the upright
        wc = corner.points["wheel_center"]
        patch = corner.points["contact_patch_center"].position(kin)
        push(
            wc,
            case.wheel_center,
            case.moment + np.cross(patch - wc.position(kin), case.contact_patch),
        )
        push(wc, case.contact_patch)
        out |= self._tree_loads(q, external)
        return out

    def _tree_loads(self, q, external) -> dict[str, float]:
        """Forces through the tree's joints: pivot bushings (on the chassis), the
        lower ball joint (outboard on inboard), a two-force link's tension, legs."""
        corner, model, data = self.corner, self.model, self.data
        gravity = model.gravity.copy()
        model.gravity = pin.Motion.Zero()
        zero = np.zeros(model.nv)
        self.tau = pin.rnea(model, data, q, zero, zero, pin.StdVec_Force(external)).copy()
        model.gravity = gravity
        kin = corner.kin
        design = corner.design_positions
        out = {}
        for body in corner.tree.bodies:
            j = body.joint
            if j is None:
                continue
            last = j.name + {"ball": "_x", "universal": "_b"}.get(j.kind, "")
            index = model.getJointId(last)
            world = kin.data.oMi[index].act(data.f[index])  # parent on child, world origin
            force, moment = world.linear.copy(), world.angular.copy()
            if j.kind == "ball":
                out |= _vector(f"load_{j.name}", -force)
            elif j.kind == "universal":  # a link: chassis → ball joint, two-force
                inboard, outboard = (
                    kin.data.oMf[corner.points[n].frame_id].translation
                    for n in (f"{body.name}_inboard", f"{body.name}_outboard")
                )
                u = (inboard - outboard) / np.linalg.norm(inboard - outboard)
                out[f"force_{body.name}"] = force @ u
            elif j.kind == "revolute" and len(j.defined_by) == 2:
                a, b = (design[n] for n in j.defined_by)
                at_a = moment - np.cross(a, force)  # about bushing a
                d = b - a
                on_b = np.cross(at_a, d) / (d @ d) + 0.5 * (force @ d) / (d @ d) * d
                on_a = force - on_b
                for n, f in zip(j.defined_by, (on_a, on_b), strict=True):
                    out |= _vector(f"load_{_bushing(n)}", -f)  # on the chassis
                out |= self._legs(body.name, j.defined_by, force)
        return out

    def _legs(self, arm: str, pickups, force) -> dict[str, float]:
        """A wishbone loaded at its outboard ball alone: the tension in each leg (N);
        blank when anything else loads the arm (a pushrod, spring or droplink)."""
        corner = self.corner
        outboard = f"{arm}_outboard"
        if not arm.endswith("wishbone") or outboard not in corner.points:
            return {}
        others = [n for n, (b, _) in corner.tree.points.items() if b == arm and n != outboard]
        kin = corner.kin
        out_p = corner.points[outboard].position(kin)
        legs = [out_p - corner.design_positions[n] for n in pickups]
        u = np.column_stack([leg / np.linalg.norm(leg) for leg in legs])
        names = [f"force_{arm}_{'front' if 'front' in n else 'rear'}" for n in pickups]
        if others:
            return dict.fromkeys(names, np.nan)
        # the chassis holds the arm through the legs: force = Σ tension · (pickup → ball)ˆ
        # pulled toward the chassis: the chassis's force on the arm is −Σ t·u
        t = np.linalg.lstsq(u, -force, rcond=None)[0]
        return dict(zip(names, t, strict=True))


class _RockerTurn:
    """A torsion bar's row: the rocker's turn about its axis a→b (rad per dq)."""

    size = 1
    name = "spring"

    def __init__(self, corner):
        self.corner = corner
        self.point = corner.points["pushrod_inboard"]  # any frame on the rocker

    def axis(self, kin) -> np.ndarray:
        p = self.corner.points
        a, b = p["rocker_axis_a"].position(kin), p["rocker_axis_b"].position(kin)
        return (b - a) / np.linalg.norm(b - a)

    def jacobian(self, kin) -> np.ndarray:
        return (self.axis(kin) @ kin.frame_jacobian(self.point.frame_id)[3:])[None]


def _vector(name: str, v) -> dict[str, float]:
    return {f"{name}_{a}": float(v[i]) for i, a in enumerate("xyz")}


def _bushing(point: str) -> str:
    """The bushing at a pivot pickup: lower_wishbone_inboard_front →
    lower_wishbone_front_bushing, rocker_axis_a → rocker_a_bushing."""
    for part in ("inboard_", "axis_", "pivot_"):
        point = point.replace(part, "")
    return f"{point}_bushing"


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


# ---------------------------------------------------------------- rates


class SpringRates:
    """The spring's force and the rates at the wheel along bump (spec/loads.md):
    ``spring_force`` (N, compression +) or ``spring_torque`` (N·m, a torsion bar's,
    + resisting bump) = preload + rate · deflection from design; ``wheel_rate`` =
    d(F·MR)/dz = rate·MR² + F·dMR/dz (N/mm), and ``ride_rate`` = wheel and tyre rate in
    series where the tyre's rate is given.

    MR and dMR/dz are exact: the second derivative of the spring's length (a torsion
    bar's angle) along the bump motion (hub z, the rack or toe link held) comes from
    the second-order solution of the closures, J·q″ = −(J̇·q′), with J̇·q′ the rows'
    drift read from Pinocchio's frame accelerations at velocity q′ and zero q̈.
    """

    def __init__(self, corner):
        g = corner.geometry
        self.corner, self.model = corner, corner.model
        self.data = self.model.createData()
        self.solver = corner._drive  # closures + hub z (+ the rack held)
        self.torsion = g.spring == "torsion_bar"
        if self.torsion:
            self.turn = _RockerTurn(corner)
            self.sense = 1.0
            self.sense = 1.0 if self.derivatives(corner.q_design)[1] >= 0.0 else -1.0
        else:
            self.top, self.bottom = corner.points["strut_top"], corner.points["strut_bottom"]
        self.design = self.derivatives(corner.q_design)[0]

    def _linear(self, frame: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and classical acceleration of a frame origin (world)."""
        model, data = self.model, self.data
        p = data.oMf[frame].translation.copy()
        v = pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED).linear
        a = pin.getFrameClassicalAcceleration(model, data, frame, pin.LOCAL_WORLD_ALIGNED).linear
        return p, v, a

    def _length(self, a_frame: int, b_frame: int) -> tuple[float, float, float]:
        """|p_b − p_a| and its first and second rates at the current motion state."""
        pa, va, aa = self._linear(a_frame)
        pb, vb, ab = self._linear(b_frame)
        d, dv = pb - pa, vb - va
        length = float(np.linalg.norm(d))
        u = d / length
        along = float(u @ dv)
        return length, along, float(u @ (ab - aa) + (dv @ dv - along * along) / length)

    def _state(self, q, v, a) -> None:
        pin.forwardKinematics(self.model, self.data, q, v, a)
        pin.updateFramePlacements(self.model, self.data)

    def derivatives(self, q: np.ndarray) -> tuple[float, float, float]:
        """The spring's length (m; a torsion bar's signed angle, rad) and its first and
        second derivatives along the wheel centre's z (per m, per m²)."""
        solver = self.solver
        solver.evaluate(q)
        v = solver.tangent()[:, 0]  # dq/dz, the other drivers held
        zero = np.zeros(self.model.nv)
        self._state(q, v, zero)
        drift = []
        for row in solver.rows:
            if isinstance(row, BallClosure):
                drift.extend(self._linear(row.b.frame_id)[2] - self._linear(row.a.frame_id)[2])
            elif isinstance(row, DistanceClosure):
                drift.append(self._length(row.a.frame_id, row.b.frame_id)[2])
            elif isinstance(row, JointTarget):
                drift.append(0.0)
            else:  # the wheel centre's height: a point target along a fixed direction
                drift.append(row.direction @ self._linear(row.point.frame_id)[2])
        a = np.linalg.solve(solver.jacobian, -np.array(drift))
        self._state(q, v, a)
        if self.torsion:
            frame = self.turn.point.frame_id
            kin = self.corner.kin
            kin.update(q)
            axis = self.turn.axis(kin)
            w = pin.getFrameVelocity(self.model, self.data, frame, pin.LOCAL_WORLD_ALIGNED)
            dw = pin.getFrameAcceleration(self.model, self.data, frame, pin.LOCAL_WORLD_ALIGNED)
            angle = _turned(self.corner, q)
            return self.sense * angle, self.sense * axis @ w.angular, self.sense * axis @ dw.angular
        return self._length(self.top.frame_id, self.bottom.frame_id)

    def columns(self, qs: list) -> dict:
        """name → (values per configuration, unit); None configurations give NaN."""
        g = self.corner.geometry
        n = len(qs)
        force, wheel = np.full(n, np.nan), np.full(n, np.nan)
        for i, q in enumerate(qs):
            if q is None:
                continue
            x, dx, ddx = self.derivatives(q)
            if self.torsion:  # wind-up (rad, + in bump) and its rates
                stiffness = g.spring_rate * 180.0 / np.pi  # N·m/rad
                force[i] = g.spring_preload + stiffness * (x - self.design)
                ratio, dratio = dx, ddx
            else:  # compression (m) and the motion ratio, −dℓ/dz
                stiffness = g.spring_rate * 1e3  # N/m
                force[i] = g.spring_preload + stiffness * (self.design - x)
                ratio, dratio = -dx, -ddx
            wheel[i] = (stiffness * ratio * ratio + force[i] * dratio) * 1e-3  # N/mm
        out = {
            ("spring_torque" if self.torsion else "spring_force"): (
                force,
                "N·m" if self.torsion else "N",
            ),
            "wheel_rate": (wheel, "N/mm"),
        }
        if g.wheel.tyre_rate is not None:
            out["ride_rate"] = (1.0 / (1.0 / wheel + 1.0 / g.wheel.tyre_rate), "N/mm")
        return out


def _turned(corner, q: np.ndarray) -> float:
    """The rocker's turn (rad) about rocker_axis_a→b from design, right-hand rule."""
    p = corner.points
    kin = corner.kin
    kin.update_positions(q)
    a, b = p["rocker_axis_a"].position(kin), p["rocker_axis_b"].position(kin)
    u = (b - a) / np.linalg.norm(b - a)
    arm = p["pushrod_inboard"].position(kin) - a
    arm0 = corner.design_positions["pushrod_inboard"] - a
    arm, arm0 = arm - u * (u @ arm), arm0 - u * (u @ arm0)
    return float(np.arctan2(u @ np.cross(arm0, arm), arm0 @ arm))


def rate_columns(corner, qs: list) -> dict:
    """The spring's force and the wheel and ride rates, where the geometry gives the
    spring's rate (else nothing)."""
    if corner.geometry.spring_rate is None or corner.geometry.spring == "none":
        return {}
    return SpringRates(corner).columns(qs)
