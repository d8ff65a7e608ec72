"""A results file read back for the reports (a sweep's, an axle's, a vehicle's, a forces
CSV): its columns, units and what it is; anything pin_susp could not have written refused.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io.yamlio import read_input

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
TEXT_STEMS = ("limit_exceeded",)  # such columns of each corner (limit_exceeded_left)
# beyond this a value cannot be drawn: an axis spanning it overflows a float in
# matplotlib's tick arithmetic (±8e307 already does); pin_susp's own columns stay far
# below (an instant centre is blank, not huge, when the arms are parallel)
DRAWABLE = 1e300
# a whole car's corners (docs/vehicle.md, "The file"): its results carry their suffixes
VEHICLE_CORNERS = ("fl", "fr", "rl", "rr")
# the columns of pin-susp attitude's results (docs/vehicle.md, "Attitude under acceleration")
ATTITUDE = {"ax", "ay", "equilibrium_residual"}


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
            if line.startswith("# convention:"):  # io.conventions.Output.header
                raise InputError(
                    source,
                    "# convention",
                    f"written in convention {_form(line)} (--convention/--units): the "
                    "report's panels and labels are ISO 8855's in mm; plot the file the "
                    "command writes without those options",
                )
            if line.startswith("# units:"):
                self.units = _units(source, line.removeprefix("# units:"))
        self.columns = {}
        for j, name in enumerate(header):
            if name in TEXT or name.startswith(TEXT_STEMS):
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
        # the corners' labels its columns carry, as the subject wrote them: a corner
        # column's suffix (camber_left, camber_right), none for a corner's one ("")
        self.labels = corner_labels(self.columns)
        # a whole car's (docs/vehicle.md): its four corners fl, fr, rl, rr, the body's
        # heave, pitch and roll; else several corners' (an axle's): heave and roll
        self.vehicle = set(self.labels) == set(VEHICLE_CORNERS)
        self.axle = self.labels != ("",) and not self.vehicle
        self.kind = "a vehicle's" if self.vehicle else "an axle's" if self.axle else "a corner's"
        if self.vehicle and ATTITUDE <= set(self.columns):
            raise InputError(
                source,
                "",
                "an attitude's results (a row per acceleration, not a sweep): its g-g plot "
                "is pin-susp attitude --plot",
            )
        if self.vehicle:
            travel, shape = "heave", ("pitch", "roll")
        elif self.axle:
            travel, shape = "heave", ("roll",)
        else:
            travel, shape = "wheel_travel", ("camber",)
        for needed in (travel, *shape):
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


def corner_labels(columns) -> tuple[str, ...]:
    """The corners' labels a results table's columns carry, in their order: the suffix
    of each camber column (``camber_left`` → ``left``; ``camber_to_ground_left`` is the
    axle's, not a corner's, and ``camber_spatial`` another metric), ``""`` for an
    unsuffixed one (and for a table with no camber: a corner's, read as such)."""
    labels = tuple(
        name.removeprefix("camber").removeprefix("_")
        for name in columns
        if name == "camber" or (name.startswith("camber_") and not name.startswith(NOT_LABELS))
    )
    return labels or ("",)


GROUND = "camber_to_ground"  # an axle's or a vehicle's column, not a corner's camber
NOT_LABELS = (GROUND, "camber_spatial")  # camber_…: not a corner's camber suffixed


def _cell(text: str) -> float:
    """A CSV cell as written by pin_susp: a number, empty (NaN), True or False."""
    text = text.strip()
    if text == "":
        return np.nan
    if text in ("True", "False"):
        return float(text == "True")
    return float(text)


def _form(line: str) -> str:
    """``iso, lengths in, forces lbf`` from a ``# convention:`` line."""
    name = line.removeprefix("# convention:").split()[0]
    units = line.partition("; units: ")[2].partition(" (")[0]
    return f"{name}, {units}" if units else name


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
