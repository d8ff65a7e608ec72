"""What every report's panels share: the columns' labels, the x axis (what the sweep
moved: a corner's, an axle's or a vehicle's inputs), the panels' y spans (MIN_SPAN), their
grid, the header and the colours.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import matplotlib.pyplot as plt
import numpy as np

from ..columns.metrics import METRIC_BY_NAME, Derivative
from ..errors import InputError
from .results_file import VEHICLE_CORNERS, ResultsFile

LABELS = {  # columns the registry does not hold
    "motion_ratio": "Motion ratio",
    "spring_force": "Spring force (compression +)",
    "spring_torque": "Torsion bar torque (+ resisting bump)",
    "wheel_rate": "Wheel rate",
    "ride_rate": "Ride rate (wheel and tyre)",
}


def label(name: str) -> str:
    """Human label of a column, from the registry."""
    if name in METRIC_BY_NAME:
        return METRIC_BY_NAME[name].label
    if name in LABELS:
        return LABELS[name]
    if name.startswith("deriv_"):
        metric, driver = name.removeprefix("deriv_").split("_wrt_")
        return Derivative(METRIC_BY_NAME[metric], driver).label
    return name.replace("_", " ")


WHEEL_X = ("wheel_travel", "Wheel travel (+ bump) [mm]")
RACK_X = ("rack_displacement", "Rack position from centre (+ left) [mm]")
# results written before the rack_displacement column: the design position is unknown
RACK_ABSOLUTE_X = ("trackrod_inboard_y", "Rack position: trackrod inboard y (absolute) [mm]")
# an axle's sweep, by what it moved, in this order: a roll at a rack position is a roll
AXLE_X = {
    "roll": ("roll", "Roll (+ left wheel up relative to the chassis) [deg]"),
    "heave": ("heave", "Heave (+ bump) [mm]"),
    "rack travel": RACK_X,
}

# a vehicle's sweep (docs/vehicle.md, "The sweep"), by what it moved, in this order; the
# steering by the steering wheel's angle (the rack's travel without a c-factor), and a
# road's height under some corners (warp: ROAD) after
VEHICLE_X = {
    "heave": ("heave", "Heave of the body at the CG (+ up) [mm]"),
    "pitch": ("pitch", "Pitch (+ nose down) [deg]"),
    "roll": ("roll", "Roll (+ right side down) [deg]"),
    "steering": ("steering_wheel_angle", "Steering wheel angle (+ turning left) [deg]"),
}
ROAD = "contact_patch_road_z_"  # + a corner: the road's height under it, as solved


# a sweep that moved two inputs or more (a combined bump + steer, a roll at a steer):
# no one input is its x, so every panel is drawn against the step and the inputs
# are panels of their own, at the top
STEP_X = ("step_index", "Step ({} move together)")


def moved(results: ResultsFile) -> list[str]:
    """What the sweep moved, in order: a corner's 'wheel travel', 'rack travel'; an
    axle's 'roll', 'heave', 'rack travel'. Read from the results: an input held (a
    rack held at centre, a roll at a fixed heave) is not moved. A vehicle's: 'heave',
    'pitch', 'roll', 'steering', and 'road height (fr, rl)' for the corners whose road
    rose together (each its own input where they moved apart)."""
    if results.vehicle:
        out = [k for k, (x, _) in VEHICLE_X.items() if k != "steering" and varies(results[x])]
        if any(
            n in results.columns and varies(results[n])
            for n in ("steering_wheel_angle", "rack_displacement")
        ):
            out.append("steering")
        return out + road_inputs(results)
    if results.axle:
        return [k for k, (x, _) in AXLE_X.items() if x in results.columns and varies(results[x])]
    out = ["wheel travel"] if varies(results["wheel_travel"]) else []
    if any(
        n in results.columns and varies(results[n])
        for n in ("rack_displacement", RACK_ABSOLUTE_X[0])
    ):
        out.append("rack travel")
    return out


def road_inputs(results: ResultsFile) -> list[str]:
    """A vehicle's road heights that moved: 'road height (fr, rl)' for corners whose
    road rose together (to 1e-6 mm at every step), one input per group."""
    rising = [c for c in VEHICLE_CORNERS if has_values(results, ROAD + c)]
    rising = [c for c in rising if varies(results[ROAD + c])]
    groups: list[list[str]] = []
    for corner in rising:
        column = results[ROAD + corner]
        same = next(
            (
                g
                for g in groups
                if np.allclose(column, results[ROAD + g[0]], rtol=0.0, atol=1e-6, equal_nan=True)
            ),
            None,
        )
        if same is None:
            groups.append([corner])
        else:
            same.append(corner)
    return [f"road height ({', '.join(g)})" for g in groups]


def sweeps(results: ResultsFile) -> str | None:
    """What the sweep moved: 'wheel travel', 'rack travel', several joined ('a, b and c')
    (a combined sweep), or None (nothing: one step); an axle's: 'roll', 'heave',
    'rack travel'; a vehicle's: 'heave', 'pitch', 'roll', 'steering', 'road height
    (fr, rl)'."""
    return joined(moved(results)) or None


def joined(words: list[str]) -> str:
    """'a', 'a and b', 'a, b and c'."""
    return " and ".join(w for w in (", ".join(words[:-1]), words[-1] if words else "") if w)


def input_column(results: list[ResultsFile], kind: str) -> tuple[str, str]:
    """The column (and its axis label) that records an input ('wheel travel', 'roll',
    ...) in these files: the rack from centre, or the absolute rack of old files."""
    if results[0].vehicle:
        if kind.startswith("road height ("):
            corners = kind.removeprefix("road height (").removesuffix(")").split(", ")
            where = joined(corners)
            return ROAD + corners[0], f"Road height under {where} (+ up) [mm]"
        if kind == "steering" and not all(has_values(r, VEHICLE_X[kind][0]) for r in results):
            return RACK_X  # no c-factor: the rack's travel
        return VEHICLE_X[kind]
    if results[0].axle:
        return AXLE_X[kind]
    if kind == "wheel travel":
        return WHEEL_X
    if all("rack_displacement" in r.columns for r in results):
        return RACK_X
    return RACK_ABSOLUTE_X  # one old file: all absolute, so the lines stay comparable


def x_axis(results: ResultsFile | list[ResultsFile]) -> tuple[str, str]:
    """The x column and label: what the sweep moved (wheel travel, rack travel from
    centre; an axle's roll, heave, rack; a vehicle's heave, pitch, roll, steering wheel,
    a road height), or the step when it moved several inputs.

    Several files must have moved the same thing, else an InputError naming
    two that differ (a file where nothing moved goes with any).
    """
    files = [results] if isinstance(results, ResultsFile) else results
    moving = [(r, kind) for r in files if (kind := sweeps(r)) is not None]
    first, first_kind = moving[0] if moving else (None, None)
    for r, kind in moving[1:]:
        if kind != first_kind:
            raise InputError(
                r.source,
                "",
                f"x is {kind} but {first.source}'s is {first_kind}: plot them separately",
            )
    if first is not None and len(moved(first)) > 1:
        return STEP_X[0], STEP_X[1].format(first_kind)
    default = "roll" if files[0].axle or files[0].vehicle else "wheel travel"
    return input_column(files, first_kind or default)


def varies(column: np.ndarray) -> bool:
    finite = column[np.isfinite(column)]
    return finite.size > 1 and float(np.ptp(finite)) > 1e-6


def header(fig, title: str, note: str, handles: list, bottom: float = 0.0) -> None:
    """The figure's title, a note under it (a combined sweep's) and a legend of
    ``handles`` (the files, or the load cases) under that; the panels below, above
    ``bottom`` inches (room for a note under them)."""
    height = fig.get_figheight()  # inches: the title, the note and the legend get their room
    fig.suptitle(title, fontsize=12, y=1.0 - 0.12 / height, va="top")
    used = 0.4
    if note:
        fig.text(
            0.5, 1.0 - used / height, note, ha="center", va="top", fontsize=9, gid="combined_note"
        )
        used += 0.22
    if handles:
        ncol = min(len(handles), 6)
        fig.legend(
            handles=handles,
            loc="upper center",
            bbox_to_anchor=(0.5, 1.0 - (used - 0.05) / height),
            ncol=ncol,
            fontsize=9,
        )
        used += 0.05 + 0.25 * -(-len(handles) // ncol)
    fig.tight_layout(rect=(0, bottom / height, 1, 1.0 - (used + 0.05) / height))


def colour(k: int) -> str:
    """The colour of the k-th results file, the same on every panel."""
    return f"C{k % 10}"


def all_of(results: list[ResultsFile], kind: str, other: str, which: str) -> bool:
    """Whether the files are of a kind (their attribute ``kind``: an axle's, forces); an
    InputError naming one that is not when another is: two kinds are plotted apart."""
    first = next((r for r in results if getattr(r, kind)), None)
    odd = next((r for r in results if not getattr(r, kind)), None)
    if first is not None and odd is not None:
        raise InputError(
            odd.source, "", f"{other}, but {first.source} {which}: plot them separately"
        )
    return first is not None


@dataclass
class Panel:
    """One panel of a report: its lines (x, y, legend label, line style, colour, marker);
    ``marks``: x values to mark with a vertical line (a force report's toggles);
    ``unit``: its y unit, which sets the smallest span drawn (MIN_SPAN)."""

    title: str
    ylabel: str
    xlabel: str
    lines: list = field(default_factory=list)
    legend: bool = False
    marks: list = field(default_factory=list)
    unit: str = ""


# The smallest span of a panel's y axis, by unit: a column that varies by less is
# drawn in this span about its mean, so solver noise (1e-12 mm, 1e-14 deg) and
# variations too small to matter on a car are drawn flat instead of being blown up to
# the full height. Each is a step an engineer could set or measure on the car:
MIN_SPAN = {
    "mm": 0.5,  # half a millimetre: a hardpoint's build tolerance, a shim's thinnest
    "deg": 0.05,  # 3 arc minutes: about the finest toe or camber step a setup sheet gives
    "%": 1.0,  # anti-dive, -lift, -squat: a percent
    "mm/mm": 0.01,  # a motion ratio, a track change per bump
    "deg/mm": 0.001,  # camber gain, bump steer: 0.05° over 50 mm of travel
    "deg/deg": 0.01,  # camber per degree of roll
    "mm/deg": 0.5,  # roll-centre migration per degree of roll
    "mm/rad": 1.0,  # the steer screw's pitch
    "N": 10.0,  # a spring's force, a member's load: a kilogram
    "N/mm": 1.0,  # wheel, ride and spring rates
    "N·m": 1.0,  # a torsion bar's or the anti-roll bar's torque
    "N·m/deg": 1.0,  # roll stiffness
}
RELATIVE_SPAN = 1e-6  # a unit not listed: a millionth of the values' size (at least 1e-9)
# a column whose values span less than this share of its panel's smallest span is
# constant, to the drawing's resolution (under 2 pixels of a panel's ~200): drawn
# flat and labelled with its value
CONSTANT_SHARE = 0.01


def min_span(unit: str, values: np.ndarray) -> float:
    """The smallest y span a panel of this unit shows (MIN_SPAN)."""
    if unit in MIN_SPAN:
        return MIN_SPAN[unit]
    return max(RELATIVE_SPAN * float(np.max(np.abs(values))), 1e-9)


def _fit_y(ax, panel: Panel) -> None:
    """Widen the y axis to the panel's smallest span when its lines vary less; a
    constant column (to CONSTANT_SHARE of that) is labelled with its value."""
    ys = [np.asarray(y, dtype=float) for _, y, *_ in panel.lines]
    ys = np.concatenate([y[np.isfinite(y)] for y in ys]) if ys else np.array([])
    if ys.size == 0:
        return
    lo, hi = float(ys.min()), float(ys.max())
    span, least = hi - lo, min_span(panel.unit, ys)
    if span >= least:
        return
    middle = 0.5 * (lo + hi)
    half = 0.55 * least  # matplotlib's own 5 % margin each side
    ax.set_ylim(middle - half, middle + half)
    if span <= CONSTANT_SHARE * least:
        digits = max(0, int(np.ceil(-np.log10(least / 10.0))))
        value = np.round(middle, digits) + 0.0  # not -0.00
        text = (
            f"constant {value:.{digits}f} {panel.unit}"
            if panel.unit in MIN_SPAN
            else f"constant {middle:.6g} {panel.unit}"
        )
        ax.text(
            0.5,
            0.62,
            text.rstrip(),
            transform=ax.transAxes,
            ha="center",
            va="bottom",
            fontsize=9,
            color="0.25",
            gid="constant_note",
        )


def grid(drawn: list[Panel]):
    """The panels, four to a row (a legend in those that ask for one)."""
    ncols = 4
    nrows = -(-len(drawn) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.4 * ncols, 3.1 * nrows), squeeze=False)
    for ax, panel in zip(axes.flat, drawn, strict=False):
        for x, y, name, style, colour, marker in panel.lines:
            # a lone point (one row, or one step between failed ones) shows as a dot
            ax.plot(x, y, style, label=name, linewidth=1.6, color=colour, marker=marker)
        _fit_y(ax, panel)
        ax.set_title(panel.title, fontsize=10)
        ax.set_ylabel(panel.ylabel, fontsize=8)
        ax.set_xlabel(panel.xlabel, fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=8)
        if panel.legend:
            ax.legend(fontsize=7)
        for x in panel.marks:
            ax.axvline(x, color="0.4", ls=":", lw=1.0, gid="toggle")
    for ax in list(axes.flat)[len(drawn) :]:
        ax.set_visible(False)
    return fig


def lone_marker(y: np.ndarray) -> str | None:
    """A dot marker when some value has no finite neighbour (a line would not show it)."""
    finite = np.isfinite(y)
    lone = finite & ~np.r_[False, finite[:-1]] & ~np.r_[finite[1:], False]
    return "o" if np.any(lone) else None


def has_values(r: ResultsFile, name: str) -> bool:
    return name in r.columns and bool(np.any(np.isfinite(r[name])))


def marker_for(r: ResultsFile, name: str) -> str | None:
    return lone_marker(r[name])


def combined_note(results: list[ResultsFile], xname: str) -> str:
    """What the figure says of a sweep that moved several inputs ('' for one input):
    which moved, over what range, and that the panels are against the step."""
    if xname != STEP_X[0]:
        return ""
    r = next(r for r in results if len(moved(r)) > 1)
    parts = []
    for kind in moved(r):
        column = input_column(results, kind)[0]
        unit = r.units.get(column, "")
        finite = r[column][np.isfinite(r[column])]
        tiny = 1e-9 * max(np.abs(finite).max(), 1e-300)  # a solver's roundoff reads 0
        first, last = (0.0 if abs(v) <= tiny else v for v in (finite[0], finite[-1]))
        parts.append(f"{kind} {first:.4g} → {last:.4g} {unit}".rstrip())
    return (
        f"A combined sweep: {joined(parts)} move together. Every panel is drawn "
        "against the step (the inputs first): a curve shows what both inputs do at once, "
        "not a gain along one."
    )


def input_panels(results: list[ResultsFile], xname: str) -> list[Panel]:
    """A sweep that moved several inputs: a panel per input against the step (for a
    forces file, the rows of its first load case: the steps once)."""
    if xname != STEP_X[0]:
        return []
    r0 = next(r for r in results if len(moved(r)) > 1)
    out = []
    for kind in moved(r0):
        column, axis = input_column(results, kind)
        unit = r0.units.get(column, "")
        panel = Panel(
            f"Input: {axis.rpartition(' [')[0]}",
            f"{column} [{unit}]" if unit else column,
            STEP_X[1].format(sweeps(r0)),
            unit=unit,
        )
        for k, r in enumerate(results):
            if not has_values(r, column):
                continue
            rows = slice(None)
            if r.forces:
                rows = r["load_case"] == r["load_case"][0]
            who = r.label if len(results) > 1 and not r.forces else "_nolegend_"
            x, y = r[xname][rows], r[column][rows]
            panel.lines.append((x, y, who, "-", "0.25" if r.forces else colour(k), lone_marker(y)))
        out.append(panel)
    return out
