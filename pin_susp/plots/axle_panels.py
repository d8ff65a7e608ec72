"""The axle report's panels: a line per side (the right dashed) against roll, heave or
rack travel, Ackermann against the mean steer angle.
"""

from __future__ import annotations

import numpy as np

from .axes import (
    Panel,
    colour,
    has_values,
    marker_for,
    varies,
)
from .results_file import ResultsFile

# The axle report: title, columns (a line each: the left side solid, the right dashed)
AXLE_PANELS = (
    ("Camber (to the chassis)", ("camber_left", "camber_right")),
    ("Camber to ground", ("camber_to_ground_left", "camber_to_ground_right")),
    ("Toe: roadwheel angle (+ in)", ("roadwheel_angle_left", "roadwheel_angle_right")),
    ("Steer angle (ISO yaw, + left)", ("steer_angle_left", "steer_angle_right")),
    ("Roll centre height", ("roll_center_z",)),
    ("Roll centre lateral position (+ left)", ("roll_center_y",)),
    ("Anti-roll bar twist (left − right arm)", ("arb_twist",)),
    ("Camber change per roll", ("deriv_camber_wrt_roll_left", "deriv_camber_wrt_roll_right")),
    ("Track", ("track",)),
    ("Ride height change (+ body up)", ("ride_height_change",)),
    ("Heave link length", ("heave_link_length",)),
    (
        "Roll steer: toe change per roll",
        ("deriv_roadwheel_angle_wrt_roll_left", "deriv_roadwheel_angle_wrt_roll_right"),
    ),
    ("Roll centre height change per roll", ("deriv_roll_center_z_wrt_roll",)),
    ("Roll centre lateral migration per roll", ("deriv_roll_center_y_wrt_roll",)),
    ("Front-view IC height", ("fvic_z_left", "fvic_z_right")),
    ("Side-view IC height", ("svic_z_left", "svic_z_right")),
    ("Motion ratio", ("motion_ratio_left", "motion_ratio_right")),
    ("Spring force (compression +)", ("spring_force_left", "spring_force_right")),
    ("Torsion bar torque", ("spring_torque_left", "spring_torque_right")),
    ("Wheel rate", ("wheel_rate_left", "wheel_rate_right")),
    ("Ride rate (wheel and tyre)", ("ride_rate_left", "ride_rate_right")),
    ("Roll stiffness", ("roll_stiffness",)),
    ("Anti-roll bar wheel rate", ("arb_wheel_rate",)),
)
# Ackermann is read against the steer, whatever else the sweep moved
ACKERMANN = ("ackermann", "Ackermann", "Mean steer angle ½(left + right) (ISO yaw, + left) [deg]")


def axle_panels(results: list[ResultsFile], xname: str, xlabel: str) -> list[Panel]:
    """The axle report's panels: each of AXLE_PANELS whose columns have a value in some
    file, against the sweep's x; Ackermann against the mean steer angle when the rack
    moved. Colour by file, line style by side."""
    out = []
    for title, names in AXLE_PANELS:
        if any(has_values(r, n) for r in results for n in names):
            out.append(_axle_panel(results, title, names, xlabel, lambda r: r[xname]))
    name, title, steer_label = ACKERMANN
    steers = any(
        has_values(r, "rack_displacement") and varies(r["rack_displacement"]) for r in results
    )
    if steers and any(has_values(r, name) for r in results):
        out.append(_axle_panel(results, title, (name,), steer_label, mean_steer_angle))
    return out


def mean_steer_angle(r: ResultsFile) -> np.ndarray:
    """½(steer_angle_left + steer_angle_right), deg: the axle's steer (+ left)."""
    return 0.5 * (r["steer_angle_left"] + r["steer_angle_right"])


def _axle_panel(results, title: str, names: tuple, xlabel: str, x) -> Panel:
    first = next(r for r in results if any(n in r.columns for n in names))
    unit = next(first.units.get(n, "") for n in names if n in first.columns)
    shown = names[0].removesuffix("_left") + ("_<side>" if len(names) > 1 else "")
    panel = Panel(title, f"{shown} [{unit}]" if unit else shown, xlabel, unit=unit)
    for k, r in enumerate(results):
        for name in names:
            if name not in r.columns:
                continue
            side = name.rpartition("_")[2] if len(names) > 1 else ""
            who = " ".join(w for w in (r.label if len(results) > 1 else "", side) if w)
            style = "--" if side == "right" else "-"
            panel.lines.append(
                (x(r), r[name], who or "_nolegend_", style, colour(k), marker_for(r, name))
            )
    panel.legend = len(panel.lines) > 1
    return panel
