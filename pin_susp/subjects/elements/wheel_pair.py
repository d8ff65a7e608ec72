"""The pair of corners across an axle (docs/axle.md): what the two wheels are together.

Its sweep quantities — ``heave`` (the wheel centres' mean rise, mm) and ``roll`` (the
angle over the track, deg) — each a solver row on both wheel centres (HeaveTarget,
RollTarget), read in SI (``value``). Its columns (``columns``): heave, roll, body roll,
camber to ground, ride height, track, the roll centre, the rack's travel, the steer
angles and Ackermann, then the other elements' (``model.elements``); the exact rates
along roll, the bar's twist rates and the roll stiffness.
"""

from __future__ import annotations

import numpy as np

from ...columns.metrics import PointSet, fvic_y, fvic_z
from ...columns.other_tools import kinematic_roll_centre
from ...constraints import HeaveTarget, RollTarget
from ...errors import InputError
from ...maths.jet import Dual
from ...maths.vectors import roll_centre, unit
from ...model import steering
from . import rack

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

    def columns_of(self, model, points: dict, sides: dict) -> dict:
        """The pair's columns (name → (values, unit)) from every point's motion
        (``points``: name → {side: jet.Dual}) and each side's corner columns
        (``sides``: side → its metric columns, unsuffixed)."""
        plain = {k: v["left"].val for k, v in points.items()}
        cps = {s: points[f"{s}_contact_patch_center"][s] for s in SIDES}
        return pair_columns(model, plain, sides, cps) | roll_rates(model, points, sides)

    @staticmethod
    def value(t) -> np.ndarray:
        """A quantity target's values in SI: heave m, roll rad."""
        v = np.asarray(t.values, dtype=float)
        return v * 1e-3 if t.quantity == "heave" else np.radians(v)


def roll_rates(model, points: dict, sides: dict) -> dict:
    """Exact derivatives along roll: the left wheel centre up and the right one down
    equally, the rack held (docs/axle.md): camber and toe per side (deg/deg), the
    U-bar's twist per side's hub z, and the roll centre's migration (mm/deg).

    With h the antisymmetric wheel-centre move, roll = atan2(a, b), a = Δz_L − Δz_R,
    b = CP_y,L − CP_y,R, so dθ/dh = (2b − a·(ḃ_L + ḃ_R)) / (a² + b²), where ḃ_side
    is that side's contact patch y rate along its own hub z (the sides meet only at
    the rack). A side's metric then moves at ±(d metric/d hub z) / (dθ/dh).
    """

    cp = {s: points[f"{s}_contact_patch_center"][s] for s in SIDES}
    wc = {s: points[f"{s}_wheel_center"][s].val[:, 2] for s in SIDES}
    d = model.design_positions
    a = (wc["left"] - d["left_wheel_center"][2]) - (wc["right"] - d["right_wheel_center"][2])
    b = cp["left"].val[:, 1] - cp["right"].val[:, 1]
    rate = {s: cp[s].der[0][:, 1] for s in SIDES}  # d CP_y / d own hub z
    dtheta = (2.0 * b - a * (rate["left"] - rate["right"] * -1.0)) / (a * a + b * b)
    # per side: m of its own hub z per radian of roll (+ left, − right)
    per_rad = {"left": 1.0 / dtheta, "right": -1.0 / dtheta}
    deg = np.pi / 180.0
    out = {}
    for side in SIDES:
        for name in ("camber", "roadwheel_angle"):
            gain = sides[side][f"deriv_{name}_wrt_hub_z"][0] * 1e3  # deg per m
            out[f"deriv_{name}_wrt_roll_{side}"] = (gain * per_rad[side] * deg, "deg/deg")
    # the roll centre as a function of both sides' CP and FVIC, pushed along roll
    parts = []
    for s in SIDES:
        g = model.corners[s]
        own = {k: points[f"{s}_{k}"][s] for k in model.corner_points[s]}
        design = {k: d[f"{s}_{k}"][None] for k in model.corner_points[s]}
        ps = PointSet(own, design, g)
        with np.errstate(invalid="ignore", divide="ignore"):
            values = (cp[s][..., 1], cp[s][..., 2], fvic_y(ps), fvic_z(ps))
        # Dual over one direction, roll (rad): d/dθ = d/d(own hub z) · per_rad
        parts.append(tuple(Dual(v.val * 1e3, v.der[0] * per_rad[s] * 1e3) for v in values))
    with np.errstate(invalid="ignore", divide="ignore"):
        rc = roll_centre(parts)
    out["deriv_roll_center_y_wrt_roll"] = (rc[0].der * deg, "mm/deg")
    out["deriv_roll_center_z_wrt_roll"] = (rc[1].der * deg, "mm/deg")
    out |= model.bar.rate_columns(model, points)
    return out | roll_stiffness(model, sides, out, per_rad)


def roll_stiffness(model, sides: dict, rates: dict, per_rad: dict) -> dict:
    """Where the springs' rates (and a bar's stiffness) are given: ``roll_stiffness``
    (N·m/deg) = Σ springs' k·(dℓ/dφ)² + the bar's k·(dθ/dφ)², and ``arb_wheel_rate``
    (N/mm), the bar's rate at each wheel in roll (one up, the other down): ½·k·(dθ/dh)²."""
    bar = model.bar  # elements.AntiRollBar (kind "none" without one)
    if any(model.corners[s].spring_rate is None for s in SIDES):
        return {}
    if bar.kind != "none":
        if bar.rigid or bar.axle.anti_roll_stiffness is None:
            return {}  # a locked bar does not roll; without its stiffness: unknown
    total, out = 0.0, {}
    for side in SIDES:
        g = model.corners[side]
        if g.spring == "torsion_bar":  # wind-up rate deg/mm → rad/m, k N·m/deg → N·m/rad
            turn = np.radians(sides[side]["deriv_torsion_bar_twist_wrt_hub_z"][0]) * 1e3
            k = g.spring_rate * 180.0 / np.pi
        else:  # length rate mm/mm, k N/mm → N/m
            turn, k = sides[side]["deriv_damper_length_wrt_hub_z"][0], g.spring_rate * 1e3
        total = total + k * (turn * per_rad[side]) ** 2
    bar = model.bar.roll_term(rates, per_rad)
    if bar is not None:
        total = total + bar[0]
        out["arb_wheel_rate"] = bar[1]
    out["roll_stiffness"] = (total * np.pi / 180.0, "N·m/deg")
    return out


def pair_columns(model, p: dict, sides: dict, cps: dict) -> dict:
    """heave, roll, body_roll, camber to ground, ride height, track, roll centre (the
    geometric one, and the kinematic one from ``cps``: side → its contact patch's
    motion along its own hub z, other_tools.kinematic_roll_centre), rack, steer angles
    and Ackermann, the U-bar's arm angles and twist, the heave link."""
    d = {k: v[None] for k, v in model.design_positions.items()}
    dz = {s: p[f"{s}_wheel_center"][:, 2] - d[f"{s}_wheel_center"][:, 2] for s in SIDES}
    cp = {s: p[f"{s}_contact_patch_center"] for s in SIDES}
    track = cp["left"][:, 1] - cp["right"][:, 1]
    out = {
        "heave": (0.5 * (dz["left"] + dz["right"]) * 1e3, "mm"),
        "roll": (np.degrees(np.arctan2(dz["left"] - dz["right"], track)), "deg"),
    }
    body_roll = np.degrees(np.arctan2(cp["right"][:, 2] - cp["left"][:, 2], track))
    out["body_roll"] = (body_roll, "deg")
    for side, s in (("left", 1.0), ("right", -1.0)):
        camber = sides[side]["camber"][0]
        out[f"camber_to_ground_{side}"] = (camber - s * body_roll, "deg")
    cp0 = {s: d[f"{s}_contact_patch_center"][:, 2] for s in SIDES}
    change = -0.5 * ((cp["left"][:, 2] - cp0["left"]) + (cp["right"][:, 2] - cp0["right"]))
    out["ride_height_change"] = (change * 1e3, "mm")
    out["track"] = (np.abs(track) * 1e3, "mm")
    rc = roll_centre(
        [
            (cp[s][:, 1] * 1e3, cp[s][:, 2] * 1e3, sides[s]["fvic_y"][0], sides[s]["fvic_z"][0])
            for s in SIDES
        ]
    )
    out["roll_center_y"], out["roll_center_z"] = (rc[0], "mm"), (rc[1], "mm")
    out |= kinematic_roll_centre(cps)
    travel = rack.travel(p, d)
    out |= rack.columns(travel)
    steer = {}
    for side, s in (("left", 1.0), ("right", -1.0)):
        steer[side] = -s * sides[side]["roadwheel_angle"][0]
        out[f"steer_angle_{side}"] = (steer[side], "deg")
    out |= steer_columns(model, steer, track, travel)
    for element in model.elements:
        out |= element.columns(model, p, d)
    return out


def steer_columns(model, steer: dict, track: np.ndarray, travel) -> dict:
    """``ackermann`` (%, blank without a rack or a wheelbase, or with the rack at centre)
    and, with a rack, ``steer_angle_inner``, ``steer_angle_outer`` (deg, from design,
    unsigned; blank with the rack at centre): model/steering.py's formulas."""
    both = (steer["left"], steer["right"])
    design = (model.design_steer["left"], model.design_steer["right"])
    wheelbase = model.corners["left"].wheelbase
    out = {"ackermann": (steering.ackermann(both, design, wheelbase, track, travel), "%")}
    if travel is None:
        return out
    inner, outer = steering.inner_outer(both, design)
    centred = np.abs(travel) < steering.STRAIGHT
    inner[centred] = outer[centred] = np.nan
    return out | {"steer_angle_inner": (inner, "deg"), "steer_angle_outer": (outer, "deg")}
