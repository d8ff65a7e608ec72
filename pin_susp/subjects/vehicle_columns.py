"""What only the whole car has (docs/vehicle.md, Columns): the roll axis through both
axles' roll centres, the pitch centre, the anti-dive, -lift and -squat with the car's
own wheelbase, CG and brake and drive split, and the turning radius.

Every column is measured in the chassis frame (where the corners' and the axles'
columns are: at design, the road's), from the columns already written at the step:
each corner's side-view instant centre (``svic_x_fl``, ``svic_z_fl``), each axle's
roll centre (``roll_center_z_front``) and steer angles, and the contact patches and
wheel centres (``plain``: every point, m).
"""

from __future__ import annotations

import numpy as np

from ..model.steering import turning_radius as radius_of

ENDS = {"front": ("fl", "fr"), "rear": ("rl", "rr")}


def vehicle_columns(car, plain: dict, columns: dict) -> dict:
    """name → (values, unit): the roll axis, the pitch centre, the anti %, the turning
    radius. ``car``: the Vehicle; ``plain``: every point (n, 3) m, chassis frame;
    ``columns``: name → values (output units) written so far."""
    v = car.vehicle
    mm = 1e3
    cp = {c: plain[f"{c}_contact_patch_center"] * mm for c in car.labels}
    wc = {c: plain[f"{c}_wheel_center"] * mm for c in car.labels}
    x = {end: 0.5 * (cp[a][:, 0] + cp[b][:, 0]) for end, (a, b) in ENDS.items()}
    out = {}
    rc = {end: columns.get(f"roll_center_z_{end}") for end in ENDS}
    if rc["front"] is not None and rc["rear"] is not None:
        rise, run = rc["front"] - rc["rear"], x["front"] - x["rear"]
        out["roll_axis_inclination"] = (np.degrees(np.arctan2(rise, run)), "deg")
        at_cg = rc["rear"] + rise * (v.cg[0] * mm - x["rear"]) / run
        out["roll_axis_height_at_cg"] = (at_cg, "mm")
    sv = {}
    for end, labels in ENDS.items():  # each axle's side view: the mean of its two corners
        have = all(f"svic_x_{c}" in columns for c in labels)
        if not have:
            continue
        sv[end] = (
            np.mean([columns[f"svic_x_{c}"] for c in labels], axis=0),
            np.mean([columns[f"svic_z_{c}"] for c in labels], axis=0),
            np.mean([cp[c] for c in labels], axis=0),
        )
    if len(sv) == 2:
        out |= pitch_centre(sv)
    out |= anti_columns(car, cp, wc, columns)
    out |= turning_radius(car, columns)
    return out


def pitch_centre(sv: dict) -> dict:
    """The side-view intersection of the lines from each axle's contact patch to its
    instant centre (the mean of its two corners'), mm; blank where they are parallel."""
    (xf, zf, pf), (xr, zr, pr) = sv["front"], sv["rear"]
    # p + s·(SVIC − p) on each line: solve the 2×2 for the front line's parameter
    df = np.stack([xf - pf[:, 0], zf - pf[:, 2]], axis=1)
    dr = np.stack([xr - pr[:, 0], zr - pr[:, 2]], axis=1)
    gap = np.stack([pr[:, 0] - pf[:, 0], pr[:, 2] - pf[:, 2]], axis=1)
    cross = df[:, 0] * dr[:, 1] - df[:, 1] * dr[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        s = (gap[:, 0] * dr[:, 1] - gap[:, 1] * dr[:, 0]) / cross
        s = np.where(np.abs(cross) > 1e-12 * np.hypot(*df.T) * np.hypot(*dr.T), s, np.nan)
    return {
        "pitch_center_x": (pf[:, 0] + s * df[:, 0], "mm"),
        "pitch_center_z": (pf[:, 2] + s * df[:, 1], "mm"),
    }


def anti_columns(car, cp: dict, wc: dict, columns: dict) -> dict:
    """anti_dive_front, anti_lift_rear (braking, by the brake bias), anti_squat_rear,
    anti_lift_front (driving, by the drive split), %: 100·share·tanθ·L/h per corner,
    the mean of the axle's two; θ the side-view angle from the reaction point (the
    contact patch where the brake or drive is outboard, the wheel centre where it is
    inboard) to the SVIC, h the CG's height over the contact patch. Blank where the
    axle is not braked or driven."""
    v = car.vehicle
    out = {}
    cases = (
        ("anti_dive_front", "front", v.brake_share("front"), v.brake_reaction("front")),
        ("anti_lift_rear", "rear", v.brake_share("rear"), v.brake_reaction("rear")),
        ("anti_squat_rear", "rear", v.drive_share("rear"), v.drive_reaction("rear")),
        ("anti_lift_front", "front", v.drive_share("front"), v.drive_reaction("front")),
    )
    for name, end, share, reaction in cases:
        labels = ENDS[end]
        if not all(f"svic_x_{c}" in columns for c in labels):
            continue
        if not share:
            out[name] = (np.full(len(cp[labels[0]]), np.nan), "%")
            continue
        per_corner = []
        for c in labels:
            at = cp[c] if reaction == "outboard" else wc[c]
            run = columns[f"svic_x_{c}"] - at[:, 0]
            if end == "front":
                run = -run  # the SVIC behind the front axle, ahead of the rear
            tan = (columns[f"svic_z_{c}"] - at[:, 2]) / run
            height = v.cg[2] * 1e3 - cp[c][:, 2]
            per_corner.append(100.0 * share * tan * v.wheelbase / height)
        with np.errstate(invalid="ignore"):
            out[name] = (np.mean(per_corner, axis=0), "%")
    return out


def turning_radius(car, columns: dict) -> dict:
    """``turning_radius`` (m, + turning left): the step's wheelbase on the road (the
    mean of left and right) over the tangent of the front wheels' mean steer angle from
    design; blank with the rack at centre."""
    steer = [columns.get(f"steer_angle_{c}") for c in ENDS["front"]]
    travel = columns.get("rack_displacement")
    if any(s is None for s in steer) or travel is None:
        return {}
    design = [car.design_steer(c) for c in ENDS["front"]]
    base = 0.5 * (columns["wheelbase_left"] + columns["wheelbase_right"])  # on the road
    radius = radius_of(steer, design, base * 1e-3, travel * 1e-3)  # model/steering.py
    return {"turning_radius": (radius, "m")}
