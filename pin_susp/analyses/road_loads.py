"""A vehicle's load case given as a steady acceleration (docs/vehicle.md, "Loads"): the
forces of the attitude's equilibrium at (ax, ay) on each wheel, at every step of a
sweep.

At (ax, ay) the attitude (attitude.py) finds the body's pose and each wheel's
vertical load F_z; its tyres' forces follow from them (``Attitude._tyre_forces``: the
lateral force split front to rear by the moment about the car's CG and left to right
by the wheels' loads, the longitudinal one by the brake bias or the drive split). Each
wheel then carries, in the road's axes:

- the road's force (f_x, f_y, F_z) on the tyre, at its material point on the road:
  the wheel's lowest point along the road's normal;
- its unsprung mass's weight and inertia, −m·g·(ax, ay, 1), at the wheel centre.

At a sweep's step both are turned into the chassis frame by the body's pitch and roll
there (the loads' statics is the chassis frame's: statics.py), and written as a force
at the wheel centre with the moment of the tyre's force about it. Where the brake
(ax < 0) or the drive (ax ≥ 0) of that axle is inboard, the moment's part about the
spin axis goes to the body through the driveshaft, not through the upright: it is left
out of the upright's, as the attitude's tyre turns with the body about its spin axis.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .load_case import AccelerationCase


def has_accelerations(cases: list) -> bool:
    """Whether any case is a steady acceleration's."""
    return any(isinstance(c, AccelerationCase) for c in cases)


class RoadLoads:
    """The wheels' forces of each steady-acceleration case of a vehicle ``car``, found
    once (the attitude's equilibria, all at once): ``at(qs)`` gives them at the sweep's
    solved configurations."""

    def __init__(self, car, cases: list, source: str = "<cases>"):
        from .attitude import Attitude, G

        self.car, self.cases = car, cases
        steady = [c for c in cases if isinstance(c, AccelerationCase)]
        self.attitude = attitude = Attitude(car)
        self.forces = {}  # case name → (road force (4, 3), unsprung (4, 3), inboard (4,))
        if not steady:
            return
        ax = np.array([c.ax for c in steady])
        ay = np.array([c.ay for c in steady])
        s = attitude.equilibria(ax, ay)
        Fz = s["loads"]
        fx, fy = attitude._tyre_forces(ax, ay, Fz)
        index = {c.name: i for i, c in enumerate(cases)}
        for k, case in enumerate(steady):
            if s["why"][k]:
                raise InputError(
                    source,
                    f"cases[{index[case.name]}]",
                    f"{case.name!r} (ax {case.ax:g} g, ay {case.ay:g} g): {s['why'][k]}",
                )
            road = np.stack([fx[k], fy[k], Fz[k]], axis=1)  # (4, 3), N
            unsprung = np.array(
                [
                    -attitude.masses["unsprung"][c] * G * np.array([case.ax, case.ay, 1.0])
                    for c in car.labels
                ]
            )
            ends = ["front" if c[0] == "f" else "rear" for c in car.labels]
            inboard = np.array(
                [attitude.brakes_in[e] if case.ax < 0 else attitude.drive_in[e] for e in ends]
            )
            self.forces[case.name] = (road, unsprung, inboard)
        self.equilibria = s

    def at(self, qs: list) -> np.ndarray:
        """W (poses × 9 per wheel × cases): each case's loads on each wheel at the solved
        configurations ``qs`` (the world's), in the chassis frame — a wheel-load case's
        as given, a steady acceleration's turned and placed as this module says."""
        from ..maths.vectors import unit

        car = self.car
        n, labels = len(qs), car.labels
        W = np.zeros((n, 9 * len(labels), len(self.cases)))
        if not n:
            return W
        Q = np.array(qs, dtype=float)
        pitch, roll = Q[:, car.body_q[1]], Q[:, car.body_q[2]]
        R = _turns(pitch, roll)  # chassis → road, (n, 3, 3)
        normal = R[:, 2, :]  # the road's normal in the chassis frame: Rᵀẑ
        chassis = car.chassis_configurations(list(Q))
        names = ("wheel_center", "axle_inboard", "axle_outboard")
        points = {f"{c}_{k}": np.empty((n, 3)) for c in labels for k in names}
        for i, q in enumerate(chassis):
            where = car.positions(q)
            for name in points:
                points[name][i] = where[name]
        for col, case in enumerate(self.cases):
            if not isinstance(case, AccelerationCase):
                for k, label in enumerate(labels):
                    w = case.wheel(label)
                    W[:, 9 * k : 9 * k + 9, col] = np.r_[w.contact_patch, w.wheel_center, w.moment]
                continue
            road, unsprung, inboard = self.forces[case.name]
            for k, label in enumerate(labels):
                spin = unit(points[f"{label}_axle_outboard"] - points[f"{label}_axle_inboard"])
                down = unit(np.einsum("ni,ni->n", spin, normal)[:, None] * spin - normal)
                arm = car.points[f"{label}_contact_patch_center"].radius * down
                tyre = np.einsum("nji,j->ni", R, road[k])  # Rᵀ f: chassis axes
                moment = np.cross(arm, tyre)
                if inboard[k]:  # its spin-axis part to the body, through the driveshaft
                    moment -= np.einsum("ni,ni->n", moment, spin)[:, None] * spin
                inertia = np.einsum("nji,j->ni", R, unsprung[k])
                W[:, 9 * k + 3 : 9 * k + 6, col] = tyre + inertia
                W[:, 9 * k + 6 : 9 * k + 9, col] = moment
        return W


def _turns(pitch: np.ndarray, roll: np.ndarray) -> np.ndarray:
    """R_y(pitch)·R_x(roll) (n, 3, 3): the chassis frame's axes in the road's (the
    body's pose, elements/body.py's to_world)."""
    cp, sp, cr, sr = np.cos(pitch), np.sin(pitch), np.cos(roll), np.sin(roll)
    zero, one = np.zeros_like(pitch), np.ones_like(pitch)
    Ry = np.stack(
        [
            np.stack([cp, zero, sp], -1),
            np.stack([zero, one, zero], -1),
            np.stack([-sp, zero, cp], -1),
        ],
        -2,
    )
    Rx = np.stack(
        [
            np.stack([one, zero, zero], -1),
            np.stack([zero, cr, -sr], -1),
            np.stack([zero, sr, cr], -1),
        ],
        -2,
    )
    return Ry @ Rx
