"""A vehicle's tangents from its sweep's own (docs/vehicle.md): the drivers' at the
chassis frame and the body's rates from the tangents per target the march keeps where
a sweep is solved at once (Assembly.solve_steps, ``tangents_by_targets``), and where a
corner's own model's joints are in the vehicle's configuration (its label_corner).
Vehicle's, split from vehicle.py."""

from __future__ import annotations

import numpy as np

from ..solve.bulk import Frames, rows_of, solve_all, tree_of
from .vehicle_export import DERIVED
from .vehicle_file import LABELS


class VehicleTangents:
    """The Vehicle's tangent work (vehicle.py): ``drive_tangents``, ``body_rates`` and
    ``_joints_in_vehicle``."""

    def drive_tangents(self, qs: list, chassis: list, tangents) -> list | None:
        """dq per driver (each corner's wheel-centre z in the chassis frame, the rack, the
        body's joints, each toe link's length: drive_rhs's columns) at the chassis-frame
        configurations, from the sweep's tangents per target with each toe link's after
        them (Assembly.solve_steps, ``tangents_by_targets``), every step at once: the
        closures do not see the body's joints, so the tangents per target span the
        drivers' too, D = T·(J_d·T)⁻¹ with J_d the drivers' rows at the chassis frame,
        and a toe link's is its own less D·(J_d·x). None where a solved step has none
        (a marched sweep), or where the first step's disagree with the drive solver's
        own there (to 1e-9 of their size)."""
        solved = [i for i, q in enumerate(qs) if q is not None]
        k = self.drive_rhs.shape[1]
        targets = len(self._drive.targets)
        if not solved or tangents is None:
            return None
        given = [tangents[i] for i in solved]
        nv = self.model.nv
        if any(t is None or t.shape[0] != nv for t in given):
            return None
        T = np.array(given)
        extra = k - targets
        if T.shape[2] < self.mobility + extra:
            return None
        per_target, closure = T[:, :, : T.shape[2] - extra], T[:, :, T.shape[2] - extra :]
        if per_target.shape[2] != targets:  # as many targets as drivers
            return None
        Qc = np.array([chassis[i] for i in solved])
        frames, rack_v = self._drive_frames()
        if rack_v is None:
            return None
        tree = tree_of(self.kin)
        many = Frames(tree, frames)
        R, o = tree.placements(Qc)
        Jc, _ = many.compact(many.positions(R, o), o, tree.axes(R))

        def rows(X):  # the drivers' rows times X (n, nv, c): (n, drivers, c)
            out = [
                np.einsum("sn,nsk->nk", Jf[:, :, 2], X[:, cols])
                for Jf, cols in zip(Jc, many.cols, strict=True)
            ]
            out += [X[:, rack_v]] + [X[:, v] for v in self.body_v]
            return np.stack(out, axis=1)

        across = rows(per_target)
        try:
            D = per_target @ np.linalg.inv(across)
        except np.linalg.LinAlgError:
            return None
        if extra:
            D = np.concatenate([D, closure - D @ rows(closure)], axis=2)
        if not np.isfinite(D).all():
            return None
        self._drive.evaluate(Qc[0])  # the first step's, as label_motion would solve it
        check = self._drive.tangent(self.drive_rhs)
        if not np.allclose(D[0], check, rtol=0.0, atol=1e-9 * max(1.0, np.abs(check).max())):
            return None
        out = [None] * len(qs)
        for i, d in zip(solved, D, strict=True):
            out[i] = d
        return out

    def _joints_in_vehicle(self, label: str, model) -> tuple | None:
        """Where a corner's own model's joints (``model``) are in the vehicle's q: (its
        indices, the vehicle's), each joint its label's (``fl_lower_wishbone_pivot``) or
        the shared one (``rack_slide``) of as many values; None where one is neither."""
        own, theirs = [], []
        for joint, name in zip(model.joints[1:], model.names[1:], strict=True):
            named = self.prefix(label) + name
            if not self.model.existJointName(named):
                named = name
                if not self.model.existJointName(named):
                    return None
            other = self.model.joints[self.model.getJointId(named)]
            if other.nq != joint.nq or other.nv != joint.nv:
                return None
            own += range(joint.idx_q, joint.idx_q + joint.nq)
            theirs += range(other.idx_q, other.idx_q + other.nq)
        return np.array(own, dtype=int), np.array(theirs, dtype=int)

    def body_rates(self, sweep, qs: list, columns: dict, tangents=None) -> dict:
        """d(column)/d(heave) per mm and d/d(pitch), d/d(roll) per deg, the other targets
        held: the sweep's tangent dq/d(target) at every solved step (``tangents``' where
        the sweep's solve has every solved step's, per target — bulk.newton_all's, at the
        solution — else its rows' Jacobian, all steps at once), each corner's
        chassis-frame wheel-centre rate along it, times the corner's own rate along its
        hub z (its rack held: the steering is a target)."""
        solved = [i for i, q in enumerate(qs) if q is not None]
        n = len(qs)
        if not solved:
            return {}
        targets = self.held_targets(sweep.targets)
        want = [i for i, t in enumerate(targets) if t.quantity in ("heave", "pitch", "roll")]
        Q = np.array([qs[i] for i in solved])
        given = [None if tangents is None else tangents[i] for i in solved]
        if all(t is not None and t.shape[0] == self.model.nv for t in given):
            T = np.array(given)[:, :, want]  # each step's per target (its first columns)
        else:
            solver = self.solver_for(sweep.targets, sweep.source)
            rows = rows_of(solver)
            zero = np.zeros((len(Q), len(targets)))
            _, J = rows.evaluate(Q, zero)
            rhs = np.zeros((rows.nrows, len(want)))
            for c, i in enumerate(want):
                rhs[rows.first_target + i, c] = 1.0
            T = solve_all(J, rhs)
            if T is None:
                return {}
        tree = tree_of(self.kin)
        Qc = np.array(self.chassis_configurations(list(Q)))
        frames = [self.points[f"{label}_wheel_center"].frame_id for label in LABELS]
        many = Frames(tree, frames)
        R, o = tree.placements(Qc)
        Jc, _ = many.compact(many.positions(R, o), o, tree.axes(R))
        # each wheel centre's z row in the columns that move it, the body's joints' left out
        still = set(self.body_v)
        rows = []
        for Jf, cols in zip(Jc, many.cols, strict=True):
            keep = [s for s, v in enumerate(cols) if v not in still]
            rows.append((Jf[keep, :, 2], cols[keep]))
        out = {}
        for c, i in enumerate(want):
            quantity = targets[i].quantity
            scale, per = (1.0, "mm") if quantity == "heave" else (np.pi / 180.0 * 1e3, "deg")
            for label, (Jz, cols) in zip(LABELS, rows, strict=True):
                rate = np.full(n, np.nan)  # chassis-frame wheel-centre z, m per unit
                rate[solved] = np.einsum("sn,ns->n", Jz, T[:, cols, c])
                rate = rate * scale  # mm per mm, or mm per deg
                out[f"deriv_wheel_center_z_wrt_{quantity}_{label}"] = (rate, f"mm/{per}")
                for name in DERIVED:
                    gain = columns.get(f"deriv_{name}_wrt_hub_z_{label}")
                    if gain is not None:
                        out[f"deriv_{name}_wrt_{quantity}_{label}"] = (gain * rate, f"deg/{per}")
        return out
