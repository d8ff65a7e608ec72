"""The standard kinematics report and 2D drawings, with matplotlib (Agg, no display).

``report_figure`` draws one panel per metric against what the sweep moved:
wheel travel for a bump sweep, rack travel from centre (the
``rack_displacement`` column) for a steer sweep, several results files as
several lines (a colour per file, the same on every panel, and one legend of
the files); labels and units come from the metric registry and the CSV's
own units. Results of older versions have no ``rack_displacement``: they are
plotted against the absolute ``trackrod_inboard_y`` and the axis says so.
What moved is read from the results (an input held, like a rack at centre,
did not move). A sweep that moved two inputs (bump and steer together) has no
one x: every panel is drawn against the step, the inputs first as panels of
their own, and a note under the title says what moved over what range.
Files whose sweeps moved different things (a bump sweep and a steer sweep)
are refused with an :class:`InputError` naming both: their lines cannot share
an x axis, and two reports say more than one squeezed figure.

A panel's y axis spans at least its unit's MIN_SPAN (0.5 mm, 0.05°, ...):
solver noise and variations too small to matter are drawn flat, not blown up to
the panel's height; a column constant to 1 % of that span is labelled with its
value. A cell beyond ±1e300 (no axis can span it) is refused as it is read.

``drawing_figure`` draws the corner in front and side view at its design
state, with the instant-centre construction of the as-set corner: front view,
each ball joint to the FVIC (the instant axis ∩ plane x = WC_x) and the line
from the contact patch through the FVIC to the car centreline, where it gives
the roll centre of a symmetric axle; side view, each ball joint to the SVIC
and the contact patch to the SVIC (the anti-dive/-lift line). An instant
centre at infinity (parallel arm planes) or further than 20 m is not drawn
but noted; the view stays on the corner and lines run off its edges. The
tyre is its silhouette: the two rim-edge circles, projected, cut at the road.
``labels=True`` names every hardpoint and adds a legend of the colours.

An axle's results (per-side columns, ``roll``, ``heave``) give the axle report
(``axle_panels``): a line per side (the right dashed) against roll, heave or
rack travel — what the sweep varied, the step when it varied several — and
Ackermann against the mean steer angle when the rack moved. ``axle_drawing_figure`` draws the
axle in front view at design or at a pose (``axle_pose``: a step of its
results), with each side's FVIC construction and the roll centre where the
two contact-patch lines cross.

A forces CSV (``pin-susp loads``: a ``load_case`` column, a row per step and
case) gives the force report (``force_figure``): a panel per member (the
two-force members, the spring, the rack) and per joint (the magnitude of its
load vector) on the same grid, a line per load case; a step at a toggle
(``loads_unbounded`` = 1, its forces blank) is a gap, marked by a dotted line
and noted under the panels. Forces and a sweep's results are refused together.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field, replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.transforms import Bbox  # noqa: E402

from .errors import InputError, PinSuspError  # noqa: E402
from .geometry import unit, wheel_down  # noqa: E402
from .io.atomic import FULL, atomic_write  # noqa: E402
from .metrics import (  # noqa: E402
    HUB_Z,
    METRIC_BY_NAME,
    RACK,
    STANDARD,
    Derivative,
    PointSet,
    X,
    Y,
)
from .yamlio import read_input  # noqa: E402

EXTRA = (
    "svic_z",
    "fvic_z",
    "anti_dive",
    "anti_lift",
    "anti_squat",
    "rocker_angle",
    "rocker_transmission_angle",
    "damper_length",
    "motion_ratio",
    # the spring's, where the geometry gives its rate (docs/results.md)
    "spring_force",
    "spring_torque",
    "wheel_rate",
    "ride_rate",
)
DERIVED = ("camber", "roadwheel_angle")  # their derivative columns get panels
TEXT = ("load_case",)  # columns of names, not numbers
# beyond this a value cannot be drawn: an axis spanning it overflows a float in
# matplotlib's tick arithmetic (±8e307 already does); pin_susp's own columns stay far
# below (an instant centre is blank, not huge, when the arms are parallel)
DRAWABLE = 1e300


class ResultsFile:
    """A results CSV read back: columns as float arrays (empty cells → NaN), units.

    Anything that is not a results CSV pin_susp could have written (binary,
    empty, no rows, ragged rows, a corrupt ``# units:`` line, no numbers at
    all) is an :class:`InputError` naming the file; empty cells and empty
    columns are fine (a failed step, an undefined metric) and are not drawn.
    """

    def __init__(self, path: str | Path, name: str | Path | None = None, raw: bytes | None = None):
        """``name``: what messages and the legend call the file (default: ``path``);
        ``raw``: its contents when they are at hand (a CSV written to a stream)."""
        self.path = Path(path)
        self.source = source = str(path if name is None else name)
        self.label = Path(source).stem
        try:
            if raw is None:
                raw = read_input(self.path)
        except OSError as exc:
            raise InputError(source, "", f"cannot be read ({exc.strerror})") from None
        if not raw.strip():
            raise InputError(source, "", "is empty: not a pin_susp results CSV")
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            text = None
        if text is None or "\x00" in text:
            raise InputError(source, "", "is not a text file: not a pin_susp results CSV")
        comments, lines, numbers = [], [], []
        for number, line in enumerate(text.splitlines(keepends=True), start=1):
            if line.startswith("#"):
                comments.append(line.rstrip("\r\n"))
            elif line.strip():
                lines.append(line)
                numbers.append(number)
        # the csv module: a load case's name is quoted when it holds a comma
        reader = csv.reader(lines)
        try:
            rows = [(numbers[reader.line_num - 1], row) for row in reader]
        except csv.Error as exc:
            raise InputError(source, f"line {numbers[reader.line_num - 1]}", str(exc)) from None
        if not rows or "step_index" not in rows[0][1]:
            raise InputError(source, "", "not a pin_susp results CSV (no step_index column)")
        (_, header), body = rows[0], rows[1:]
        if not body:
            raise InputError(source, "", "no data rows (only a header)")
        seen: set[str] = set()
        twice = next((n for n in header if n in seen or seen.add(n)), None)
        if twice is not None:
            raise InputError(source, twice, "this column appears twice in the header")
        for number, row in body:
            if len(row) != len(header):
                raise InputError(
                    source,
                    f"line {number}",
                    f"{len(row)} cells, but the header has {len(header)} columns "
                    "(a damaged or hand-edited file)",
                )
        self.units = {}
        for line in comments:
            if line.startswith("# units:"):
                self.units = _units(source, line.removeprefix("# units:"))
        self.columns = {}
        for j, name in enumerate(header):
            if name in TEXT:
                self.columns[name] = np.array([row[j] for _, row in body], dtype=object)
                continue
            try:
                self.columns[name] = np.array([_cell(row[j]) for _, row in body])
            except ValueError:
                raise InputError(source, name, "has a cell that is not a number") from None
            column = self.columns[name]
            big = np.flatnonzero(np.isfinite(column) & (np.abs(column) > DRAWABLE))
            if big.size:
                raise InputError(
                    source,
                    f"{name}: line {body[big[0]][0]}",
                    f"{column[big[0]]:.3g}: beyond ±{DRAWABLE:.0e} no plot axis can hold it "
                    "(pin_susp writes nothing that large: a damaged or hand-edited file)",
                )
        # forces (pin-susp loads): a row per step and load case, the sweep's columns after
        self.forces = "load_case" in self.columns
        # an axle's results: every corner column per side, and the axle's own
        self.axle = "camber_left" in self.columns
        travel, shape = ("heave", "roll") if self.axle else ("wheel_travel", "camber")
        for needed in (travel, shape):
            if needed not in self.columns:
                raise InputError(source, needed, "missing column: not a sweep results CSV")
        values = [c for n, c in self.columns.items() if n not in TEXT]
        if not any(np.any(np.isfinite(c)) for c in values):
            raise InputError(source, "", "no numbers in it: every data cell is empty")
        if not np.any(np.isfinite(self.columns[travel])):
            converged = self.columns.get("solver_converged")
            if converged is not None and not np.any(converged == 1.0):
                raise InputError(source, "", "no step of this sweep converged: nothing to plot")
            raise InputError(source, travel, "no values: every cell is empty")

    def __getitem__(self, name):
        return self.columns[name]


def _cell(text: str) -> float:
    """A CSV cell as written by pin_susp: a number, empty (NaN), True or False."""
    text = text.strip()
    if text == "":
        return np.nan
    if text in ("True", "False"):
        return float(text == "True")
    return float(text)


def _units(source: str, text: str) -> dict[str, str]:
    """The ``# units:`` comment: a JSON object of column → unit."""
    try:
        units = json.loads(text)
    except ValueError as exc:
        raise InputError(source, "# units", f"not valid JSON ({exc})") from None
    if not isinstance(units, dict):
        raise InputError(source, "# units", f"expected a JSON object, got {type(units).__name__}")
    bad = next((k for k, v in units.items() if not isinstance(v, str)), None)
    if bad is not None:
        raise InputError(source, f"# units: {bad}", f"expected a unit string, got {units[bad]!r}")
    return units


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


# a sweep that moved two inputs or more (a combined bump + steer, a roll at a steer):
# no one input is its x, so every panel is drawn against the step and the inputs
# are panels of their own, at the top
STEP_X = ("step_index", "Step ({} move together)")


def moved(results: ResultsFile) -> list[str]:
    """What the sweep moved, in order: a corner's 'wheel travel', 'rack travel'; an
    axle's 'roll', 'heave', 'rack travel'. Read from the results: an input held (a
    rack held at centre, a roll at a fixed heave) is not moved."""
    if results.axle:
        return [k for k, (x, _) in AXLE_X.items() if x in results.columns and _varies(results[x])]
    out = ["wheel travel"] if _varies(results["wheel_travel"]) else []
    if any(
        n in results.columns and _varies(results[n])
        for n in ("rack_displacement", RACK_ABSOLUTE_X[0])
    ):
        out.append("rack travel")
    return out


def sweeps(results: ResultsFile) -> str | None:
    """What the sweep moved: 'wheel travel', 'rack travel', several joined by 'and'
    (a combined sweep), or None (nothing: one step); an axle's: 'roll', 'heave',
    'rack travel'."""
    return " and ".join(moved(results)) or None


def input_column(results: list[ResultsFile], kind: str) -> tuple[str, str]:
    """The column (and its axis label) that records an input ('wheel travel', 'roll',
    ...) in these files: the rack from centre, or the absolute rack of old files."""
    if results[0].axle:
        return AXLE_X[kind]
    if kind == "wheel travel":
        return WHEEL_X
    if all("rack_displacement" in r.columns for r in results):
        return RACK_X
    return RACK_ABSOLUTE_X  # one old file: all absolute, so the lines stay comparable


def x_axis(results: ResultsFile | list[ResultsFile]) -> tuple[str, str]:
    """The x column and label: what the sweep moved (wheel travel, rack travel from
    centre; an axle's roll, heave, rack), or the step when it moved several inputs.

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
    default = "roll" if files[0].axle else "wheel travel"
    return input_column(files, first_kind or default)


def _varies(column: np.ndarray) -> bool:
    finite = column[np.isfinite(column)]
    return finite.size > 1 and float(np.ptp(finite)) > 1e-6


def panels(results: list[ResultsFile], xname: str) -> list[str]:
    """The corner report's metric columns with a value in some file, in order: the
    standard metrics, EXTRA, and the derivatives of DERIVED along what the sweep moved
    (bump and steer both for a combined sweep, drawn against the step)."""
    drivers = {"wheel_travel": (HUB_Z,), STEP_X[0]: (HUB_Z, RACK)}.get(xname, (RACK,))
    names = list(STANDARD) + list(EXTRA)
    names += [f"deriv_{m}_wrt_{d}" for d in drivers for m in DERIVED]
    return [n for n in names if any(_has(r, n) for r in results)]


def report_figure(results: list[ResultsFile]):
    """One panel per metric against what the sweep moved, one line (and one colour) per
    results file, a legend of the files; a sweep that moved several inputs against the
    step, its inputs drawn first. An axle's results: the axle report (``axle_panels``)."""
    if not results:
        raise PinSuspError("no results file to plot")
    if _all_of(results, "forces", "a sweep's results", "holds forces (pin-susp loads)"):
        return force_figure(results)
    axle = _all_of(results, "axle", "a corner's results", "is an axle's")
    xname, xlabel = x_axis(results)
    for r in results[1:]:
        if xname not in r.columns or not np.any(np.isfinite(r[xname])):
            raise InputError(
                r.source,
                xname,
                f"no values, but {results[0].label} is plotted against it: "
                "plot results of the same kind of sweep together",
            )
    if axle:
        drawn = axle_panels(results, xname, xlabel)
        title = "pin_susp axle kinematics: "
    else:
        drawn = [_corner_panel(results, name, xname, xlabel) for name in panels(results, xname)]
        title = "pin_susp kinematics: "
    if not drawn:
        files = ", ".join(r.source for r in results)
        raise InputError(files, "", "no metric column has a value to plot")
    drawn = input_panels(results, xname) + drawn
    fig = _grid(drawn)
    handles = []
    if not axle and len(results) > 1:  # the axle's panels name file and side themselves
        from matplotlib.lines import Line2D

        handles = [
            Line2D([], [], color=_colour(k), lw=1.6, label=r.label) for k, r in enumerate(results)
        ]
    _header(
        fig, title + ", ".join(r.label for r in results), combined_note(results, xname), handles
    )
    return fig


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
        parts.append(f"{kind} {finite[0]:.4g} → {finite[-1]:.4g} {unit}".rstrip())
    return (
        f"A combined sweep: {' and '.join(parts)} move together. Every panel is drawn "
        "against the step (the inputs first): a curve shows what both inputs do at once, "
        "not a gain along one."
    )


def _header(fig, title: str, note: str, handles: list, bottom: float = 0.0) -> None:
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
            if not _has(r, column):
                continue
            rows = slice(None)
            if r.forces:
                rows = r["load_case"] == r["load_case"][0]
            who = r.label if len(results) > 1 and not r.forces else "_nolegend_"
            x, y = r[xname][rows], r[column][rows]
            panel.lines.append((x, y, who, "-", "0.25" if r.forces else _colour(k), lone_marker(y)))
        out.append(panel)
    return out


def _colour(k: int) -> str:
    """The colour of the k-th results file, the same on every panel."""
    return f"C{k % 10}"


def _all_of(results: list[ResultsFile], kind: str, other: str, which: str) -> bool:
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


def _corner_panel(results: list[ResultsFile], name: str, xname: str, xlabel: str) -> Panel:
    unit = next((r.units.get(name, "") for r in results if name in r.columns), "")
    panel = Panel(label(name), f"{name} [{unit}]" if unit else name, xlabel, unit=unit)
    for k, r in enumerate(results):
        if name in r.columns:  # a file's colour by its place in the list, on every panel
            panel.lines.append((r[xname], r[name], r.label, "-", _colour(k), _marker(r, name)))
    return panel


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


def _grid(drawn: list[Panel]):
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
        if any(_has(r, n) for r in results for n in names):
            out.append(_axle_panel(results, title, names, xlabel, lambda r: r[xname]))
    name, title, steer_label = ACKERMANN
    steers = any(_has(r, "rack_displacement") and _varies(r["rack_displacement"]) for r in results)
    if steers and any(_has(r, name) for r in results):
        out.append(_axle_panel(results, title, (name,), steer_label, mean_steer_angle))
    return out


def mean_steer_angle(r: ResultsFile) -> np.ndarray:
    """½(steer_angle_left + steer_angle_right), deg: the axle's steer (+ left)."""
    return 0.5 * (r["steer_angle_left"] + r["steer_angle_right"])


def _has(r: ResultsFile, name: str) -> bool:
    return name in r.columns and bool(np.any(np.isfinite(r[name])))


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
                (x(r), r[name], who or "_nolegend_", style, _colour(k), _marker(r, name))
            )
    panel.legend = len(panel.lines) > 1
    return panel


def _marker(r: ResultsFile, name: str) -> str | None:
    return lone_marker(r[name])


def lone_marker(y: np.ndarray) -> str | None:
    """A dot marker when some value has no finite neighbour (a line would not show it)."""
    finite = np.isfinite(y)
    lone = finite & ~np.r_[False, finite[:-1]] & ~np.r_[finite[1:], False]
    return "o" if np.any(lone) else None


# ---------------------------------------------------------------- the force report

STYLES = ("-", "--", ":", "-.")  # several forces files: one line style each


def force_figure(results: list[ResultsFile]):
    """The force report of forces CSVs (``pin-susp loads``): ``force_panels`` on the
    report's grid, a legend of the load cases, and a note of the steps at a toggle."""
    xname, xlabel = x_axis(results)
    drawn = input_panels(results, xname) + force_panels(results, xname, xlabel)
    fig = _grid(drawn)
    handles = {}
    for ax in fig.axes:
        for line in ax.get_lines():
            if not line.get_label().startswith("_"):
                handles.setdefault(line.get_label(), line)
    notes = [n for n in (toggle_note(r, xname) for r in results) if n]
    if notes:
        fig.text(0.01, 0.01, "\n".join(notes), fontsize=8, va="bottom", gid="toggle_note")
    sign = "members: tension +, spring: compression +, joints: magnitude of the load"
    title = f"pin_susp forces ({sign}): " + ", ".join(r.label for r in results)
    bottom = (0.16 * len(notes) + 0.1) if notes else 0.0
    _header(fig, title, combined_note(results, xname), list(handles.values()), bottom=bottom)
    return fig


def force_panels(results: list[ResultsFile], xname: str, xlabel: str) -> list[Panel]:
    """One panel per member (``force_<member>``, the spring, the rack) and per joint (the
    magnitude of ``load_<joint>_{x,y,z}``), a line per load case (per file and case for
    several files: a colour per case, a line style per file). A member or joint with no
    value anywhere has no panel; a toggle's rows (blank forces) are gaps, marked."""
    members, joints = force_columns(results)
    cases = list(dict.fromkeys(c for r in results for c in r["load_case"]))
    marks = sorted({x for r in results for x in toggles(r, xname)[1]})
    out = []
    for name in members + joints:
        column = f"load_{name}_x" if name in joints else name
        unit = next((r.units.get(column, "N") for r in results if column in r.columns), "N")
        if name in joints:
            title = f"{name.replace('_', ' ').capitalize()} load (magnitude)"
            ylabel = f"|load_{name}| [{unit}]"
        else:
            title, ylabel = _member_title(name), f"{name} [{unit}]" if unit else name
        panel = Panel(title, ylabel, xlabel, marks=marks, unit=unit)
        for k, r in enumerate(results):
            y_all = joint_load(r, name) if name in joints else r.columns.get(name)
            if y_all is None:
                continue
            for case in dict.fromkeys(r["load_case"]):
                rows = r["load_case"] == case
                who = f"{r.label}: {case}" if len(results) > 1 else str(case)
                colour = f"C{cases.index(case) % 10}"
                y = y_all[rows]
                style = STYLES[k % len(STYLES)]
                panel.lines.append((r[xname][rows], y, who, style, colour, lone_marker(y)))
        if any(np.any(np.isfinite(line[1])) for line in panel.lines):
            out.append(panel)
    if not out:  # every step at a toggle or failed: the members' panels, empty, and the note
        out = [Panel(_member_title(n), n, xlabel, marks=marks) for n in members]
    return out


def force_columns(results: list[ResultsFile]) -> tuple[list[str], list[str]]:
    """The members (the two-force members in the files' order, then the spring and the
    rack) and the joints (``load_<joint>_{x,y,z}`` → ``<joint>``) of forces files."""
    names = list(dict.fromkeys(n for r in results for n in r.columns))
    members = [n for n in names if n.startswith(("force_", "torque_"))]
    last = ("force_spring", "torque_spring", "force_rack")
    members = [n for n in members if n not in last] + [n for n in last if n in members]
    joints = [n[5:-2] for n in names if n.startswith("load_") and n.endswith("_x")]
    joints = [j for j in joints if all(f"load_{j}_{a}" in names for a in "yz")]
    return members, joints


def joint_load(r: ResultsFile, joint: str) -> np.ndarray | None:
    """|load_<joint>_{x,y,z}| at each row (N), or None when the file has no such joint."""
    names = [f"load_{joint}_{a}" for a in "xyz"]
    if not all(n in r.columns for n in names):
        return None
    return np.linalg.norm(np.column_stack([r[n] for n in names]), axis=1)


def _member_title(name: str) -> str:
    side = next((f" {s}" for s in ("left", "right") if name.endswith(f"_{s}")), "")
    base = name.removesuffix(side.replace(" ", "_"))
    if base == "force_spring":
        return f"Spring{side} (compression +)"
    if base == "torque_spring":
        return f"Torsion bar{side} torque"
    if base == "torque_arb":
        return "Anti-roll bar torque"
    if base == "force_rack":
        return "Rack (the trackrods' pull, + left)"
    return f"{base.removeprefix('force_').replace('_', ' ').capitalize()}{side} (tension +)"


def toggles(r: ResultsFile, xname: str) -> tuple[list[int], list[float]]:
    """The steps at a toggle (``loads_unbounded`` = 1: forces unbounded, blank) and their
    x values."""
    flag = r.columns.get("loads_unbounded")
    if flag is None:
        return [], []
    rows = np.flatnonzero(flag == 1.0)
    steps = dict.fromkeys(int(s) for s in r["step_index"][rows])
    xs = dict.fromkeys(float(x) for x in r[xname][rows] if np.isfinite(x))
    return list(steps), list(xs)


def toggle_note(r: ResultsFile, xname: str) -> str:
    """What the report says of a file's toggles and failed steps ('' when none)."""
    steps, xs = toggles(r, xname)
    parts = []
    if steps:
        at = ", ".join(f"{x:.4g}" for x in xs[:8]) + (" ..." if len(xs) > 8 else "")
        parts.append(
            f"forces unbounded (a toggle) at step(s) {_steps(steps)} "
            f"({xname.replace('_', ' ')} {at}): gaps, marked by dotted lines"
        )
    converged = r.columns.get("solver_converged")
    if converged is not None and np.any(converged != 1.0):
        failed = dict.fromkeys(int(s) for s in r["step_index"][converged != 1.0])
        parts.append(f"step(s) {_steps(list(failed))} did not converge: gaps")
    return f"{r.label}: " + "; ".join(parts) if parts else ""


def _steps(steps: list[int]) -> str:
    return ", ".join(map(str, steps[:10])) + (" ..." if len(steps) > 10 else "")


FRONT, SIDE = (1, 2), (0, 2)  # the world axes each view shows, in mm
IC_FAR = 20_000.0  # mm from the wheel centre: beyond this an instant centre is noted, not drawn
CONSTRUCTION = "#c2185b"  # instant-centre construction: a colour no body has
PARALLEL = "arms parallel: instant centre at infinity"


def drawing_figure(corner, labels: bool = False):
    """Front view (y–z) and side view (x–z) of the corner at its (as-set) design state.

    With the instant-centre construction of the as-set corner (see the module
    docstring); ``labels``: each hardpoint's name next to it and a legend.
    """
    fig, (front, side) = plt.subplots(1, 2, figsize=(14, 6.5))
    corners = [(corner, 1.0, "-")]
    if corner.geometry.drawn is not None:
        from .linkage import Linkage

        corners.insert(0, (Linkage(corner.geometry.drawn), 0.3, "--"))
    views = ((front, FRONT), (side, SIDE))
    for c, alpha, style in corners:
        _rods(views, c.tree.visuals, c.tree.materials, alpha, style)
        _draw_corner(views, c, alpha, style)
    ground = _mm(corner)["contact_patch_center"][2]
    for ax, title, xl in (
        (front, "Front view", "y [mm] (+ left)"),
        (side, "Side view", "x [mm] (+ forward)"),
    ):
        ax.axhline(ground, color="0.5", lw=0.8)
        _view_axes(ax, title, xl, centreline=ax is front)
    drawn, keep = _instant_centres(front, side, corner)
    _fit_view(views, [c for c, _, _ in corners], keep)
    if corner.geometry.sign < 0:
        front.invert_xaxis()  # a right corner seen from the front: outboard to the left
    note = " (dashed: as drawn)" if len(corners) > 1 else ""
    fig.suptitle(f"{corner.geometry.name}{note}")
    if labels:
        _legend(fig, corner, ghost=len(corners) > 1, construction=bool(drawn))
    fig.tight_layout(rect=(0, 0.06 if labels else 0, 1, 1))
    if labels:
        _label_points(fig, views, {n: _mm(corner)[n] for n in corner.geometry.hardpoints})
    return fig


def _view_axes(ax, title: str, xlabel: str, centreline: bool) -> None:
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.set_title(title)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("z [mm]")
    if centreline:  # the car's, in front view
        ax.axvline(0.0, color="0.5", lw=0.8, ls="-.")


def _mm(c) -> dict[str, np.ndarray]:
    return {k: v * 1e3 for k, v in c.design_positions.items()}


def _rods(views, visuals, materials, alpha, style) -> None:
    """The bodies: the URDF's rods (world positions, m), each in its material's colour."""
    colours = dict(materials)
    for v in visuals:
        if v.shape == "rod" and v.material != "tyre":
            colour = colours[v.material][:3]
            _segment(views, v.start, v.end, style, color=colour, alpha=alpha, lw=2)


def _draw_corner(views, c, alpha, style) -> None:
    """What a corner shows between its points (``c.design_positions``): links and
    steering axis, tyre, hardpoints, and in front view the wheel's centre plane."""
    from .viz import links, segments

    for name, (a, b) in segments(c, c.design_positions).items():
        axis = name == "steering_axis"
        colour = "goldenrod" if axis else f"#{links(c)[name][1]:06x}"
        _segment(views, a, b, ":" if axis else style, alpha=alpha, lw=1.5, color=colour)
    p = _mm(c)
    for ax, view in views:
        outline = tyre_outline(c, view)
        ax.plot(*outline.T, style, color="0.15", alpha=alpha, lw=1.2, gid="tyre")
        pts = np.array([p[n][list(view)] for n in c.geometry.hardpoints])
        ax.plot(*pts.T, "o", color="0.2", ms=3, alpha=alpha)
        ax.plot(*p["wheel_center"][list(view)], "+", color="0.2", ms=8, alpha=alpha)
        if view == FRONT:
            # the wheel's centre plane, top of the rim to the contact patch: camber at a glance
            down = unit(p["contact_patch_center"] - p["wheel_center"])
            top = p["wheel_center"] - down * c.geometry.wheel.radius * 1e3
            line = np.array([top, p["contact_patch_center"]])[:, list(FRONT)]
            ax.plot(*line.T, "-.", color="0.4", alpha=alpha, lw=0.6)


def _segment(views, a, b, style, **kwargs) -> None:
    """A segment between two points (m) in each (axes, view), in mm."""
    for ax, view in views:
        ends = np.array([a, b])[:, list(view)] * 1e3
        ax.plot(*ends.T, style, **kwargs)


def tyre_outline(c, view: tuple[int, int]) -> np.ndarray:
    """The tyre's silhouette in a view (mm, closed polygon): what the eye sees of it.

    The tyre is taken as the cylinder between its two rim-edge circles (radius
    R about wheel_inboard and wheel_outboard, in planes normal to the spin
    axis); its outline is the convex hull of their projections. A cambered
    tyre's lower edge circle dips below the contact patch (the lowest point of
    the centre plane's circle, the road): a real tyre deflects there, so the
    outline is cut at the road.
    """
    from scipy.spatial import ConvexHull

    p = _mm(c)
    spin = unit(p["axle_outboard"] - p["axle_inboard"])
    down, _ = wheel_down(spin)
    t = np.linspace(0.0, 2.0 * np.pi, 241)[:, None]
    ring = c.geometry.wheel.radius * 1e3 * (np.cos(t) * down + np.sin(t) * np.cross(spin, down))
    edges = np.vstack([p["wheel_inboard"] + ring, p["wheel_outboard"] + ring])[:, list(view)]
    hull = edges[ConvexHull(edges).vertices]
    return _above(hull, p["contact_patch_center"][2])


def _above(polygon: np.ndarray, ground: float) -> np.ndarray:
    """A convex polygon (k, 2) cut at z = ground, keeping what is above; closed."""
    out = []
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        if a[1] >= ground:
            out.append(a)
        if (a[1] - ground) * (b[1] - ground) < 0:  # this edge crosses the road
            out.append([a[0] + (ground - a[1]) * (b[0] - a[0]) / (b[1] - a[1]), ground])
    out = np.roll(out, -int(np.argmin(np.array(out)[:, 1])), axis=0)  # the seam at a corner
    return np.array([*out, out[0]])


def _instant_centres(front, side, corner) -> tuple[list[str], list[np.ndarray]]:
    """Draw the FVIC and SVIC constructions; which were drawn, and the points (mm) the
    view should keep."""
    design = {k: v[None] for k, v in corner.design_positions.items()}
    # with the rates at design: a mechanism's instant centres may come from its twist
    ps = PointSet(corner.motion([corner.q_design]), design, corner.geometry)
    rays = _kingpin_rays(ps, corner.geometry, lambda n: corner.body_of(n) == "chassis")
    p = _mm(corner)
    drawn, keep = [], []
    for ax, axis, view, name in ((front, X, FRONT, "FVIC"), (side, Y, SIDE, "SVIC")):
        ic = _instant_centre(ps, axis)
        problem = _too_far(ic, p["wheel_center"][list(view)], name)
        if problem is not None:
            _note(ax, problem)
        else:
            keep += _construction(ax, p, rays, view, ic, name)
            drawn.append(name)
    return drawn, keep


def _kingpin_rays(ps: PointSet, geometry, on_chassis) -> list[np.ndarray]:
    """Where the instant-centre construction starts (mm, upper first): the kingpin's
    ends (ball joints, virtual or the top mount); without a kingpin (a trailing arm),
    the chassis points of the wheel's body (``on_chassis(point)``)."""
    from .jet import value

    with np.errstate(invalid="ignore", divide="ignore"):
        ends = ps.kingpin()
    if ends is None:
        names = geometry.mechanism.upright_points(geometry)
        ends = [ps[n] for n in names if on_chassis(n)][:2]
    return [value(e)[0] * 1e3 for e in reversed(ends)]


def _instant_centre(ps: PointSet, axis: int) -> np.ndarray:
    """The instant axis ∩ the view plane through WC normal to ``axis`` (mm, the view's
    two coordinates); NaN when there is none."""
    from .jet import value

    with np.errstate(invalid="ignore", divide="ignore"):
        return np.array([value(x)[0] for x in ps.instant_axis_point(axis)], dtype=float) * 1e3


def _too_far(ic: np.ndarray, wheel_centre: np.ndarray, name: str) -> str | None:
    """Why an instant centre is not drawn (at infinity, or beyond IC_FAR), or None."""
    if not np.all(np.isfinite(ic)):
        return PARALLEL
    far = float(np.linalg.norm(ic - wheel_centre))
    if far > IC_FAR:
        return f"arms nearly parallel: {name} {far / 1e3:.0f} m away, not drawn"
    return None


def _arms_to(ax, rays, view, ic, name, tag: str = "") -> None:
    """The kingpin's ends to the IC (dashed) and the IC, named."""
    v = list(view)
    for end in rays:
        line = np.array([end[v], ic])
        ax.plot(*line.T, "--", color=CONSTRUCTION, lw=0.9, gid=f"{name.lower()}_arm{tag}")
    ax.plot(*ic, "o", color=CONSTRUCTION, ms=4, gid=f"{name.lower()}{tag}")
    ax.annotate(
        name, ic, xytext=(4, -9), textcoords="offset points", fontsize=7, color=CONSTRUCTION
    )


def _construction(ax, p, rays, view, ic, name) -> list[np.ndarray]:
    """From the kingpin's ends (ball joints, virtual or the top mount) to the IC
    (dashed), the contact patch through it; front view: on to the centreline, the roll
    centre of a symmetric axle. Returns the roll centre, if any."""
    v = list(view)
    _arms_to(ax, rays, view, ic, name)
    cp = p["contact_patch_center"][v]
    text = f"{name}: {'y' if name == 'FVIC' else 'x'} = {ic[0]:.0f} mm, z = {ic[1]:.0f} mm"
    ends, keep = [0.0, 1.0], []  # along the line from CP (0) through the IC (1)
    if name == "FVIC":
        t = _roll_centre(cp, ic)
        if t is None:
            text += "\nRC (symmetric axle): further than 20 m, not drawn"
        else:
            ends.append(t)
            keep.append(rc := cp + t * (ic - cp))
            ax.plot(*rc, "D", color=CONSTRUCTION, ms=5, gid="roll_centre")
            ax.annotate(
                "RC (symmetric axle)",
                rc,
                xytext=(5, 5),
                textcoords="offset points",
                fontsize=7,
                color=CONSTRUCTION,
            )
            text += f"\nRC (symmetric axle): z = {rc[1]:.0f} mm"
    line = np.array([cp + t * (ic - cp) for t in (min(ends), max(ends))])
    ax.plot(*line.T, "-.", color=CONSTRUCTION, lw=0.9, gid=f"{name.lower()}_contact_patch")
    _note(ax, text)
    return keep


def _roll_centre(cp: np.ndarray, ic: np.ndarray) -> float | None:
    """Where the line CP → FVIC meets the centreline y = 0, as a multiple of FVIC − CP;
    None when that is further than IC_FAR (an FVIC straight above the patch)."""
    run = ic[0] - cp[0]
    if abs(run) * IC_FAR <= abs(cp[0]) * float(np.linalg.norm(ic - cp)):
        return None
    return -cp[0] / run


def _note(ax, text: str) -> None:
    ax.text(
        0.02,
        0.98,
        text,
        transform=ax.transAxes,
        va="top",
        fontsize=8,
        gid="ic_note",
        bbox={"facecolor": "white", "edgecolor": "0.7", "alpha": 0.85},
    )


def _fit_view(views, corners, keep) -> None:
    """Limits: the corners (and the centreline in front view) plus a margin; construction
    lines to a far instant centre run off the edge instead of shrinking the corner."""
    ground = _mm(corners[-1])["contact_patch_center"][2]
    for ax, view in views:
        pts = [tyre_outline(c, view) for c in corners]
        pts += [np.array([q[list(view)] for q in _mm(c).values()]) for c in corners]
        if view == FRONT:
            near = [q for q in keep if abs(q[1] - ground) < 1000.0]  # a roll centre near the road
            pts.append(np.array([[0.0, ground], *near]))
        pts = np.vstack(pts)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = 0.06 * float(np.max(hi - lo)) + 30.0
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)


LABEL_PLACES = (  # offset (points), alignment: tried in this order, the first free one wins
    (4, 3, "left", "bottom"),
    (4, -3, "left", "top"),
    (-4, 3, "right", "bottom"),
    (-4, -3, "right", "top"),
    (0, 6, "center", "bottom"),
    (0, -6, "center", "top"),
    (4, 12, "left", "bottom"),  # a line further out, for crowded rows
    (4, -12, "left", "top"),
    (-4, 12, "right", "bottom"),
    (-4, -12, "right", "top"),
)


def _label_points(fig, views, points: dict[str, np.ndarray]) -> None:
    """Each point's name (points: name → position, mm) next to it, where it covers the
    fewest other labels and points; points that coincide in a view share one label.
    After the layout: it measures the labels on the page."""
    renderer = fig.canvas.get_renderer()
    for ax, view in views:
        ax.apply_aspect()  # the box the equal aspect gives it, as drawn, not the layout's
        xy = {n: p[list(view)] for n, p in points.items()}
        dots = ax.transData.transform(np.array(list(xy.values())))
        taken = [Bbox.from_bounds(x - 3, y - 3, 6, 6) for x, y in dots]
        for group in _coincident(xy, 0.012 * float(np.ptp(ax.get_xlim()))):
            taken.append(_place_label(ax, renderer, "\n".join(group), xy[group[0]], taken))


def _coincident(xy: dict[str, np.ndarray], close: float) -> list[list[str]]:
    """The names grouped by position: closer than ``close`` to a group's first point."""
    groups: list[list[str]] = []
    for name, q in xy.items():
        group = next((g for g in groups if np.linalg.norm(xy[g[0]] - q) < close), None)
        if group is None:
            groups.append([name])
        else:
            group.append(name)
    return groups


def _place_label(ax, renderer, text: str, xy, taken: list) -> Bbox:
    """Annotate ``xy`` at the first of LABEL_PLACES that overlaps nothing taken and stays
    in the axes (else the least bad one); returns the label's box on the page."""
    frame = ax.get_window_extent(renderer)
    options = []
    for dx, dy, ha, va in LABEL_PLACES:
        label = ax.annotate(
            text,
            xy,
            xytext=(dx, dy),
            textcoords="offset points",
            ha=ha,
            va=va,
            fontsize=6,
            color="0.1",
            gid="point_label",
            bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.6, "pad": 0.5},
        )
        box = label.get_window_extent(renderer)
        outside = box.width * box.height - _area(Bbox.intersection(box, frame))
        options.append((sum(_area(Bbox.intersection(box, b)) for b in taken) + outside, label))
    best = min(options, key=lambda o: o[0])[1]  # ties: the earlier, preferred place
    for _, label in options:
        if label is not best:
            label.remove()
    return best.get_window_extent(renderer).padded(2)  # a gap between neighbours


def _area(box) -> float:
    return 0.0 if box is None else box.width * box.height


def _legend(fig, corner, ghost: bool, construction: bool, tree=None, more=()) -> None:
    """The colours: bodies (of ``tree``, default the corner's), links, steering axis,
    tyre, construction; ``more``: other lines' handles."""
    from matplotlib.lines import Line2D

    from .viz import links, segments

    tree = corner.tree if tree is None else tree
    colours = dict(tree.materials)
    bodies = dict.fromkeys(
        v.material for v in tree.visuals if v.shape == "rod" and v.material != "tyre"
    )
    handles = [Line2D([], [], color=colours[m][:3], lw=2, label=m) for m in bodies]
    for name in segments(corner, corner.design_positions):
        if name != "steering_axis":
            colour = f"#{links(corner)[name][1]:06x}"
            handles.append(Line2D([], [], color=colour, lw=1.5, label=name.replace("_", " ")))
    handles += [
        Line2D([], [], color="goldenrod", ls=":", lw=1.5, label="steering axis"),
        Line2D([], [], color="0.15", lw=1.2, label="tyre"),
        Line2D([], [], color="0.2", marker="o", ms=3, ls="", label="hardpoint"),
    ]
    handles += list(more)
    if construction:
        handles.append(
            Line2D([], [], color=CONSTRUCTION, ls="--", lw=0.9, label="instant-centre construction")
        )
    if ghost:
        handles.append(Line2D([], [], color="0.5", ls="--", lw=1.2, label="as drawn"))
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 8), fontsize=8)


def axle_drawing_figure(model, q=None, labels: bool = False, caption: str = "design state"):
    """Front view of an axle (both corners, the bar) at configuration ``q`` (default:
    its as-set design state), seen from the front (+y, the car's left, to the right).

    The road is the line through both contact patches. Each side: its kingpin's
    ends to its FVIC (dashed) and its contact patch through the FVIC (dash-dot);
    where the two contact-patch lines cross, the roll centre (docs/axle.md's
    ``roll_center_y``, ``roll_center_z``). An FVIC at infinity or further than 20 m
    is not drawn but noted (its contact-patch line still is, towards it); so is a
    roll centre further than that. ``labels``: the left corner's hardpoints and the
    bar's points named (the right corner is its mirror image), and a legend.
    """
    from .axle import SIDES

    q = model.q_design if q is None else q
    positions = model.positions(q)
    sides = {s: _AxleSide(model, s, positions) for s in SIDES}
    fig, front = plt.subplots(figsize=(15, 7.5))
    views = ((front, FRONT),)
    _rods(views, _posed_visuals(model, q), model.tree.materials, 1.0, "-")
    for c in sides.values():
        _draw_corner(views, c, 1.0, "-")
    _axle_links(views, model, positions, sides)
    corner_points = {f"{s}_{n}" for s in SIDES for n in model.point_names[s]}
    extras = {n: positions[n] * 1e3 for n in model.output_points if n not in corner_points}
    if extras:  # the bar's and the heave link's points
        front.plot(*np.array([p[list(FRONT)] for p in extras.values()]).T, "o", color="0.2", ms=3)
    road = [_mm(c)["contact_patch_center"][list(FRONT)] for c in sides.values()]
    front.axline(*road, color="0.5", lw=0.8, gid="road")
    _view_axes(front, f"Front view: {caption}", "y [mm] (+ left, seen from the front)", True)
    drawn, keep = _roll_centre_construction(front, model, q, sides)
    _fit_view(views, list(sides.values()), keep)
    fig.suptitle(model.axle.name if model.axle is not None else model.tree.name)
    if labels:
        more = [h for h in front.get_lines() if h.get_gid() == "heave_link"][:1]
        _legend(fig, sides["left"], ghost=False, construction=drawn, tree=model.tree, more=more)
    fig.tight_layout(rect=(0, 0.06 if labels else 0, 1, 1))
    if labels:
        named = {n: _mm(sides["left"])[n] for n in sides["left"].geometry.hardpoints}
        named |= {n.removeprefix("left_"): p for n, p in extras.items() if n[:6] != "right_"}
        _label_points(fig, views, named)
    return fig


def _axle_links(views, model, positions, sides) -> None:
    """The axle's own links: the bar's droplinks (its distance closures that are no
    corner's), and the heave link between the rockers (thin: it only measures)."""
    from .viz import LINK

    own = {f"{s}_{c.name}" for s, side in sides.items() for c in side.tree.closures}
    bar = model.tree.materials.get("bar", (0.85, 0.75, 0.15, 1.0))[:3]
    for c in model.tree.closures:
        if c.kind == "distance" and c.name not in own:
            a, b = (positions[n] for n in c.points)
            _segment(views, a, b, "-", color=bar, lw=1.5, gid="droplink")
    ends = [f"{s}_heave_link_rocker" for s in sides]
    if all(n in positions for n in ends):
        colour = f"#{LINK[0]:06x}"
        a, b = (positions[n] for n in ends)
        _segment(views, a, b, "--", color=colour, lw=1.0, gid="heave_link", label="heave link")


class _AxleSide:
    """One corner of an axle at a pose, read as the drawing reads a corner: its
    geometry (as set), its own tree (the links drawn between its points) and, as
    ``design_positions``, the pose's points (m) by the corner's names."""

    def __init__(self, model, side: str, positions: dict[str, np.ndarray]):
        g = model.geometries[side]
        self.geometry, self.tree = g, g.mechanism.tree(g)
        self.design_positions = {n: positions[f"{side}_{n}"] for n in model.point_names[side]}


def _posed_visuals(model, q) -> list:
    """The axle's visuals (placed at design, m) carried by their bodies to ``q``."""
    import pinocchio as pin

    design, posed = model.model.createData(), model.model.createData()
    pin.framesForwardKinematics(model.model, design, model.q_design)
    pin.framesForwardKinematics(model.model, posed, q)
    out = []
    for v in model.tree.visuals:
        frame = model.model.getFrameId(v.body)
        move = posed.oMf[frame] * design.oMf[frame].inverse()
        end = None if v.end is None else move.act(v.end)
        out.append(replace(v, start=move.act(v.start), end=end))
    return out


def _roll_centre_construction(ax, model, q, sides) -> tuple[bool, list[np.ndarray]]:
    """Each side's FVIC construction and the crossing of the contact-patch lines, the
    roll centre; whether it was drawn, and the points (mm) the view should keep."""
    from .axle import roll_centre

    # with the rates (solved here): a mechanism's FVIC may come from its twist
    motion = model.motion([q])
    d = model.design_positions
    lines, notes = {}, []
    for s, c in sides.items():
        own = {k: motion[f"{s}_{k}"][s] for k in model.point_names[s]}
        ps = PointSet(own, {k: d[f"{s}_{k}"][None] for k in model.point_names[s]}, c.geometry)
        ic = _instant_centre(ps, X)
        p = _mm(c)
        problem = _too_far(ic, p["wheel_center"][list(FRONT)], "FVIC")
        if problem is None:
            on_chassis = lambda n, s=s: model.points[f"{s}_{n}"].body == "chassis"  # noqa: E731
            _arms_to(ax, _kingpin_rays(ps, c.geometry, on_chassis), FRONT, ic, "FVIC", f"_{s}")
            notes.append(f"FVIC {s}: y = {ic[0]:.0f} mm, z = {ic[1]:.0f} mm")
        else:
            notes.append(f"{s}: {problem}")
        if np.all(np.isfinite(ic)):
            lines[s] = (p["contact_patch_center"][list(FRONT)], ic, problem is None)
    rc = None
    if len(lines) == 2:
        with np.errstate(invalid="ignore", divide="ignore"):
            rc = np.array(roll_centre([(*cp, *ic) for cp, ic, _ in lines.values()]), dtype=float)
        middle = 0.5 * (lines["left"][0] + lines["right"][0])
        if not np.all(np.isfinite(rc)):
            notes.append("RC: the contact-patch lines are parallel")
            rc = None
        elif (far := float(np.linalg.norm(rc - middle))) > IC_FAR:
            notes.append(f"RC {far / 1e3:.0f} m away, not drawn")
            rc = None
        else:
            ax.plot(*rc, "D", color=CONSTRUCTION, ms=6, gid="roll_centre")
            ax.annotate(
                "RC", rc, xytext=(6, 5), textcoords="offset points", fontsize=8, color=CONSTRUCTION
            )
            y, z = np.round(rc) + 0.0  # a centre a hair left of the centreline: 0, not -0
            notes.insert(0, f"RC: y = {y:.0f} mm, z = {z:.0f} mm")
    else:
        missing = [s for s in sides if s not in lines]
        notes.append("RC: no front-view instant centre on " + " and ".join(missing))
    for s, (cp, ic, near) in lines.items():
        ends = [0.0, 1.0] if near else [0.0]  # along CP (0) → FVIC (1)
        if rc is not None:
            ends.append(float((rc - cp) @ (ic - cp) / ((ic - cp) @ (ic - cp))))
        if len(ends) == 1:  # a far FVIC, no roll centre: towards the FVIC, as long as CP_y
            ends.append(abs(cp[0]) / float(np.linalg.norm(ic - cp)))
        line = np.array([cp + t * (ic - cp) for t in (min(ends), max(ends))])
        ax.plot(*line.T, "-.", color=CONSTRUCTION, lw=0.9, gid=f"fvic_contact_patch_{s}")
    _note(ax, "\n".join(notes))
    return rc is not None or any(near for *_, near in lines.values()), [] if rc is None else [rc]


def axle_pose(model, results: ResultsFile, step: int) -> tuple[np.ndarray, str]:
    """The axle's configuration at a step of its results, and a caption: solved to that
    row's wheel-centre heights and rack, then checked against the row's points (they
    must be this axle's: results of another geometry are refused)."""
    from .axle import SIDES

    if not results.axle:
        raise InputError(
            results.source, "", "a corner's results: an axle is drawn at a step of its own"
        )
    rows = np.flatnonzero(results["step_index"] == step)
    if rows.size == 0:
        last = int(np.nanmax(results["step_index"]))
        raise InputError(results.source, f"step {step}", f"no such step (steps 0 to {last})")
    i = int(rows[0])
    if results.columns.get("solver_converged", np.ones(i + 1))[i] != 1.0:
        raise InputError(results.source, f"step {step}", "did not converge: it has no pose to draw")
    needed = [f"{s}_wheel_center_z" for s in SIDES]
    if model.model.existJointName("rack_slide"):
        needed.append("rack_displacement")
    for name in needed:
        if name not in results.columns or not np.isfinite(results[name][i]):
            raise InputError(results.source, name, f"no value at step {step}: the pose is unknown")
    z = {s: results[f"{s}_wheel_center_z"][i] * 1e-3 for s in SIDES}
    rack = results["rack_displacement"][i] * 1e-3 if "rack_displacement" in needed else 0.0
    solution = model.solve(z, rack)
    if not solution.converged:
        raise InputError(
            results.source, f"step {step}", f"this axle does not reach that pose ({solution.why})"
        )
    solved = model.positions(solution.q)
    names = [(n, k) for n in model.output_points for k in range(3)]
    names = [(n, k) for n, k in names if f"{n}_{'xyz'[k]}" in results.columns]
    offs = [abs(solved[n][k] * 1e3 - results[f"{n}_{'xyz'[k]}"][i]) for n, k in names]
    j = int(np.argmax(np.nan_to_num(offs, nan=np.inf)))
    off, worst = offs[j], f"{names[j][0]}_{'xyz'[names[j][1]]}"
    if not off <= 1e-3:  # mm; NaN too
        raise InputError(
            results.source,
            worst,
            f"{off:.3g} mm from this axle's point at step {step}: results of another geometry?",
        )
    shown = [("heave", "heave", "mm", 1), ("roll", "roll", "°", 2)]
    shown += [("rack", "rack_displacement", "mm", 1)] * ("rack_displacement" in results.columns)
    values = ", ".join(
        f"{word} {np.round(results[name][i], digits) + 0.0:.{digits}f} {unit}"
        for word, name, unit, digits in shown
    )
    return solution.q, f"step {step} of {results.label} ({values})"


def check_image_path(path: str | Path) -> None:
    """Raise PinSuspError unless matplotlib can write an image with this file's ending.

    Cheap, and the output path is not touched (nothing created, opened or
    checked): meant for every image output before any work starts. The
    formats are matplotlib's own list; the ending is matched case-insensitively
    (``OUT.PNG`` is a PNG). Only 'pgf' looks further: for its TeX program.
    """
    from matplotlib.backend_bases import FigureCanvasBase

    supported = FigureCanvasBase.get_supported_filetypes()
    ext = _extension(path)
    hint = f"(use {', '.join(f for f in ('png', 'pdf', 'svg') if f in supported)}, ...)"
    if not ext:
        raise PinSuspError(f"{path}: no file ending to tell the image format {hint}")
    if ext not in supported:
        raise PinSuspError(f"{path}: unsupported image format {ext!r} {hint}")
    if ext == "pgf":  # matplotlib lists it, but writes it only with a TeX installation
        import shutil

        tex = matplotlib.rcParams["pgf.texsystem"]
        if shutil.which(tex) is None:
            raise PinSuspError(f"{path}: image format 'pgf' needs {tex}, which is not installed")


def _extension(path: str | Path) -> str:
    return Path(path).suffix.removeprefix(".").lower()


def save_figure(fig, path: str | Path) -> None:
    """Write the figure whole or not at all (format from the file's ending)."""
    try:
        check_image_path(path)
        path = Path(path)
        with atomic_write(path, binary=True) as f:
            try:
                fig.savefig(f, format=_extension(path), dpi=110)
            except OSError as exc:
                if exc.errno in FULL:  # the disk, a quota, ulimit -f: as atomic_write says it
                    raise
                raise PinSuspError(f"{path}: cannot write ({exc.strerror or exc})") from None
            except (ValueError, OverflowError) as exc:  # e.g. a cell of 1e308: no axis scale
                raise PinSuspError(f"{path}: cannot draw these values ({exc})") from None
    finally:
        plt.close(fig)
