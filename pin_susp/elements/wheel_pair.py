"""The pair of corners across an axle (docs/axle.md): what the two wheels are together.

Its sweep quantities — ``heave`` (the wheel centres' mean rise, mm) and ``roll`` (the
angle over the track, deg) — each a solver row on both wheel centres (HeaveTarget,
RollTarget), read in SI (``value``).
"""

from __future__ import annotations

import numpy as np

from ..constraints import HeaveTarget, RollTarget
from ..errors import InputError
from ..vectors import unit

SIDES = ("left", "right")


class WheelPair:
    """The left and right corners of an axle, as one element: its quantities' rows."""

    quantities = ("heave", "roll")

    def check_targets(self, targets, source: str) -> None:
        """Nothing beyond its rows' own checks."""

    def add_to(self, bodies, points, closures, visuals, materials) -> None:
        """Nothing: the pair adds no part to the tree."""

    def row(self, model, i: int, t, source: str):
        """The solver's row for the quantity target ``targets[i]`` (its value set later);
        a roll of ±90 deg or more refused (an angle over the track)."""
        p, d = model.points, model.design_positions
        if t.quantity == "roll" and np.any(np.abs(np.asarray(t.values, dtype=float)) >= 90.0):
            raise InputError(
                source,
                f"targets[{i}]",
                "roll is an angle over the track: it lies within ±90 deg (got "
                f"{np.abs(np.asarray(t.values, dtype=float)).max():g})",
            )
        if t.quantity == "heave":
            z0 = 0.5 * (d["left_wheel_center"][2] + d["right_wheel_center"][2])
            return HeaveTarget(p["left_wheel_center"], p["right_wheel_center"], z0)
        z0 = d["left_wheel_center"][2] - d["right_wheel_center"][2]
        wheels = (p["left_wheel_center"], p["right_wheel_center"])
        radii = [model.corners[s].wheel.radius for s in SIDES]
        spin = [unit(d[f"{s}_axle_outboard"] - d[f"{s}_axle_inboard"]) for s in SIDES]
        model.kin.update_positions(model.q_design)
        return RollTarget(wheels, radii, model.kin, z0, spin=spin)

    @staticmethod
    def value(t) -> np.ndarray:
        """A quantity target's values in SI: heave m, roll rad."""
        v = np.asarray(t.values, dtype=float)
        return v * 1e-3 if t.quantity == "heave" else np.radians(v)
