"""The vehicle report's panels (docs/vehicle.md, "The report"): per corner a line each
(the front solid, the rear dashed; the left and the right a colour each), per axle a
line each (the front solid, the rear dashed), and the whole car's columns, against
what the sweep moved.
"""

from __future__ import annotations

from matplotlib import colormaps
from matplotlib.colors import to_hex

from .axes import Panel, has_values, marker_for, moved
from .results_file import VEHICLE_CORNERS, ResultsFile

AXLES = ("front", "rear")


def _corners(base: str) -> tuple[str, tuple]:
    """A column per corner: ``camber_fl`` ..., the front solid, the rear dashed, the
    left and the right a colour each."""
    return f"{base}_<corner>", tuple(
        (f"{base}_{c}", c, "-" if c[0] == "f" else "--", "left" if c[1] == "l" else "right")
        for c in VEHICLE_CORNERS
    )


def _axles(base: str) -> tuple[str, tuple]:
    """A column per axle: ``roll_center_z_front``, ``_rear`` (dashed)."""
    lines = tuple((f"{base}_{a}", a, "-" if a == "front" else "--", "car") for a in AXLES)
    return f"{base}_<axle>", lines


def _car(name: str) -> tuple[str, tuple]:
    """One column of the whole car's."""
    return name, ((name, "", "-", "car"),)


# The vehicle report: title, (y label, lines: column, legend name, style, colour role)
VEHICLE_PANELS = (
    ("Camber to ground", _corners("camber_to_ground")),
    ("Camber (to the chassis)", _corners("camber")),
    ("Toe: roadwheel angle (+ in)", _corners("roadwheel_angle")),
    ("Wheel travel (+ bump, to the chassis)", _corners("wheel_travel")),
    ("Roll centre height", _axles("roll_center_z")),
    ("Roll centre lateral position (+ left)", _axles("roll_center_y")),
    ("Roll axis height at the CG", _car("roll_axis_height_at_cg")),
    ("Roll axis inclination (+ front roll centre higher)", _car("roll_axis_inclination")),
    ("Pitch centre x (+ forward)", _car("pitch_center_x")),
    ("Pitch centre height", _car("pitch_center_z")),
    (
        "Anti geometry under braking",
        (
            "anti_dive_front, anti_lift_rear",
            (
                ("anti_dive_front", "anti-dive front", "-", "car"),
                ("anti_lift_rear", "anti-lift rear", "--", "car"),
            ),
        ),
    ),
    (
        "Anti geometry under drive",
        (
            "anti_lift_front, anti_squat_rear",
            (
                ("anti_lift_front", "anti-lift front", "-", "car"),
                ("anti_squat_rear", "anti-squat rear", "--", "car"),
            ),
        ),
    ),
    (
        "Wheelbase on the road",
        (
            "wheelbase_<side>",
            (
                ("wheelbase_left", "left", "-", "left"),
                ("wheelbase_right", "right", "-", "right"),
            ),
        ),
    ),
    ("Track", _axles("track")),
    ("Anti-roll bar twist (first − second corner's arm)", _axles("arb_twist")),
    ("Roll stiffness", _axles("roll_stiffness")),
    ("Ackermann (front)", _car("ackermann_front")),
    ("Turning radius (+ left)", _car("turning_radius")),
)
# drawn when the steering moved: the wheels' yaw, which the roadwheel angle's toe hides
STEER_PANEL = ("Steer angle (ISO yaw, + left)", _corners("steer_angle"))
# the corners' exact rates along the body's inputs that moved (docs/vehicle.md)
RATES = {"heave": "mm of heave", "pitch": "degree of pitch", "roll": "degree of roll"}


def rate_panels(inputs: list[str]) -> list[tuple[str, tuple]]:
    """Camber and toe change per each body input that moved."""
    out = []
    for d in (i for i in inputs if i in RATES):
        out.append((f"Camber change per {RATES[d]}", _corners(f"deriv_camber_wrt_{d}")))
        out.append((f"Toe change per {RATES[d]}", _corners(f"deriv_roadwheel_angle_wrt_{d}")))
    return out


def vehicle_panels(results: list[ResultsFile], xname: str, xlabel: str) -> list[Panel]:
    """The vehicle report's panels: each of VEHICLE_PANELS (the steer angle when the
    steering moved; the camber and toe rates along the body's inputs that moved) whose
    columns have a value in some file, against the sweep's x."""
    inputs = list(dict.fromkeys(k for r in results for k in moved(r)))
    specs = list(VEHICLE_PANELS[:3])
    if "steering" in inputs:
        specs.append(STEER_PANEL)
    specs += list(VEHICLE_PANELS[3:]) + rate_panels(inputs)
    out = []
    for title, (shown, lines) in specs:
        if any(has_values(r, line[0]) for r in results for line in lines):
            out.append(_panel(results, title, shown, lines, xname, xlabel))
    return out


def colours(k: int, files: int) -> dict[str, str]:
    """The colours of the k-th of ``files`` files: its left and right corners', and its
    axles' and the whole car's. One file: blue, red and near-black; several: a hue per
    file (matplotlib's tab20 pairs), its left dark, its right light, the rest dark."""
    if files == 1:
        return {"left": "C0", "right": "C3", "car": "0.15"}
    pair = colormaps["tab20"]
    dark, light = to_hex(pair(2 * (k % 10))), to_hex(pair(2 * (k % 10) + 1))
    return {"left": dark, "right": light, "car": dark}


def _panel(results, title: str, shown: str, lines: tuple, xname: str, xlabel: str) -> Panel:
    first = next(r for r in results if any(line[0] in r.columns for line in lines))
    unit = next(first.units.get(n, "") for n, *_ in lines if n in first.columns)
    panel = Panel(title, f"{shown} [{unit}]" if unit else shown, xlabel, unit=unit)
    for k, r in enumerate(results):
        palette = colours(k, len(results))
        for name, who, style, role in lines:
            if not has_values(r, name):  # a blank column: no line, no legend entry
                continue
            who = " ".join(w for w in (r.label if len(results) > 1 else "", who) if w)
            panel.lines.append(
                (r[xname], r[name], who or "_nolegend_", style, palette[role], marker_for(r, name))
            )
    # a legend where a line is named (a corner, an axle, a file): even when it is alone
    panel.legend = any(not line[2].startswith("_") for line in panel.lines)
    return panel
