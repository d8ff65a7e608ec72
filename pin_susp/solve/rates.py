"""The spring's force and the rates at the wheel: columns of a sweep's results where
the geometry gives the spring's rate (docs/loads.md, README "Loads and rates").

Kinematics, not statics: the motion ratio MR = −dℓ/dz of the spring (a torsion
bar's angle) along bump and its derivative dMR/dz, exact from the closures'
first- and second-order solutions, then F = preload + rate · deflection and the
wheel rate d(F·MR)/dz. ``Corner`` and ``AxleModel`` write these columns with
their metrics; the member forces under load cases are ``loads.py``, above them.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..constraints import BallClosure, DistanceClosure, JointTarget, RockerTurn


class SpringRates:
    """The spring's force and the rates at the wheel along bump (docs/loads.md):
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
            self.turn = RockerTurn(corner)
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
            angle = turned(self.corner, q)
            return self.sense * angle, self.sense * axis @ w.angular, self.sense * axis @ dw.angular
        return self._length(self.top.frame_id, self.bottom.frame_id)

    def derivatives_at_once(self, qs: list) -> tuple | None:
        """``derivatives`` for every configuration at once, on the model's tree (bulk.py):
        arrays (x, ẋ, ẍ) with NaN where q is None; None where the tree or the rows are
        not of the kinds handled there (then each is computed by ``derivatives``)."""
        from ..constraints import length_rates
        from .bulk import Frames, rows_of, solve_all, tree_of

        tree, rows = tree_of(self.corner.kin), rows_of(self.solver)
        if not (tree.supported and rows.supported and rows.nrows == self.model.nv):
            return None
        solved = [i for i, q in enumerate(qs) if q is not None]
        n, out = len(solved), np.full((3, len(qs)), np.nan)
        if not n:
            return tuple(out)
        Q = np.array([qs[i] for i in solved])
        R, o = tree.placements(Q)
        a = tree.axes(R)
        _, J = rows.evaluate(Q, np.zeros((n, len(self.solver.targets))), placed=(R, o))
        T = solve_all(J, self.solver.unit_rhs)
        if T is None:
            return None
        v, zero = T[:, :, 0], np.zeros((n, self.model.nv))  # dq/dz, the other drivers held
        P = rows.frames.positions(R, o)
        drift = rows.second(R, o, P, tree.motion(o, a, v, zero), zero)
        qdd = solve_all(J, -drift[:, :, None])
        if qdd is None:
            return None
        state = tree.motion(o, a, v, qdd[:, :, 0])
        points = self.corner.points
        if self.torsion:
            names = ("rocker_axis_a", "rocker_axis_b", "pushrod_inboard")
            frames = Frames(tree, [points[k].frame_id for k in names])
            A, B, arm = frames.positions(R, o)
            u = (B - A) / np.linalg.norm(B - A, axis=1)[:, None]
            arm = arm - A
            arm0 = self.corner.design_positions["pushrod_inboard"] - A
            arm = arm - u * np.einsum("ni,ni->n", u, arm)[:, None]
            arm0 = arm0 - u * np.einsum("ni,ni->n", u, arm0)[:, None]
            angle = np.arctan2(
                np.einsum("ni,ni->n", u, np.cross(arm0, arm)), np.einsum("ni,ni->n", arm0, arm)
            )
            joint = frames.joint[2]  # the rocker's
            w, dw = state[0][joint], state[1][joint]
            values = (angle, np.einsum("ni,ni->n", u, w), np.einsum("ni,ni->n", u, dw))
            out[:, solved] = self.sense * np.array(values)
            return tuple(out)
        frames = Frames(tree, [self.top.frame_id, self.bottom.frame_id])
        P = frames.positions(R, o)
        V, A = frames.motion(P, o, state)
        out[:, solved] = length_rates(P[1] - P[0], V[1] - V[0], A[1] - A[0])
        return tuple(out)

    def columns(self, qs: list) -> dict:
        """name → (values per configuration, unit); None configurations give NaN."""
        g = self.corner.geometry
        n = len(qs)
        derivatives = self.derivatives_at_once(qs)
        if derivatives is None:  # one configuration after another
            derivatives = np.full((3, n), np.nan)
            for i, q in enumerate(qs):
                if q is not None:
                    derivatives[:, i] = self.derivatives(q)
        x, dx, ddx = derivatives
        if self.torsion:  # wind-up (rad, + in bump) and its rates
            stiffness = g.spring_rate * 180.0 / np.pi  # N·m/rad
            force = g.spring_preload + stiffness * (x - self.design)
            ratio, dratio = dx, ddx
        else:  # compression (m) and the motion ratio, −dℓ/dz
            stiffness = g.spring_rate * 1e3  # N/m
            force = g.spring_preload + stiffness * (self.design - x)
            ratio, dratio = -dx, -ddx
        wheel = (stiffness * ratio * ratio + force * dratio) * 1e-3  # N/mm
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


def turned(corner, q: np.ndarray) -> float:
    """The rocker's turn (rad) about rocker_axis_a→b from design, right-hand rule (a
    torsion bar's wind-up)."""
    p = corner.points
    kin = corner.kin
    kin.update_positions(q)
    a, b = p["rocker_axis_a"].position(kin), p["rocker_axis_b"].position(kin)
    u = (b - a) / np.linalg.norm(b - a)
    arm = p["pushrod_inboard"].position(kin) - a
    arm0 = corner.design_positions["pushrod_inboard"] - a
    arm, arm0 = arm - u * (u @ arm), arm0 - u * (u @ arm0)
    return float(np.arctan2(u @ np.cross(arm0, arm), arm0 @ arm))


RATE_COLUMNS = {"spring_force", "spring_torque", "wheel_rate", "ride_rate"}


def rate_columns(corner, qs: list) -> dict:
    """The spring's force and the wheel and ride rates, where the geometry gives the
    spring's rate (else nothing)."""
    if not corner.geometry.rated_spring:
        return {}
    return SpringRates(corner).columns(qs)
