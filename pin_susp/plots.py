"""The standard kinematics report, drawn from results, with matplotlib (Agg, no display).

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

An axle's results (per-side columns, ``roll``, ``heave``) give the axle report
(``axle_panels``): a line per side (the right dashed) against roll, heave or
rack travel — what the sweep varied, the step when it varied several — and
Ackermann against the mean steer angle when the rack moved.

A forces CSV (``pin-susp loads``: a ``load_case`` column, a row per step and
case) gives the force report (``force_figure``): a panel per member (the
two-force members, the spring, the rack) and per joint (the magnitude of its
load vector) on the same grid, a line per load case; a step at a toggle
(``loads_unbounded`` = 1, its forces blank) is a gap, marked by a dotted line
and noted under the panels. Forces and a sweep's results are refused together.

Everything here is drawn from a results table (its CSV text): no model is built or
imported, so ``Results.plot`` (corner.py) draws through this module and nothing here
reaches back. The drawings of a corner or an axle — front and side views with the
instant-centre construction — are ``drawing.py``.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .errors import InputError, PinSuspError  # noqa: E402
from .io.atomic import FULL, atomic_write  # noqa: E402
from .metrics import (  # noqa: E402
    HUB_Z,
    METRIC_BY_NAME,
    RACK,
    STANDARD,
    Derivative,
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


def plot_results(results, path, label: str | None = None) -> None:
    """``Results.plot``: the standard report of a results table (a sweep's, an axle's or
    member_forces') drawn from its CSV text, as ``pin-susp plot`` draws the file, into
    an image file (format from its ending). ``label``: the name in the title (default:
    the sweep file's). A PinSuspError when no step converged, before any drawing."""
    from .io.tables import csv_text

    check_image_path(path)  # before any work
    if len(results) == 0 or not np.any(results.columns["solver_converged"]):
        raise PinSuspError(f"{path}: no step converged: nothing to plot")
    source = str(results.meta.get("sweep", ("",))[0] or "")
    name = "" if source.startswith("<") else Path(source).name
    written = ResultsFile(name or "results", raw=csv_text(results).encode())
    if label is not None:
        written.label = label
    save_figure(report_figure([written]), path)


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
