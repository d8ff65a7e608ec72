"""OptimumKinematics hardpoint tables, CSV or Excel (docs/interop.md, "OptimumK").

One row per point: a name column and X, Y, Z columns, found by their headers (the
first header starting with X, Y, Z — ``X``, ``X (mm)``, ``x [m]`` —, the name the
first other column); the unit from those headers' brackets (mm, m, in) or
``--units``, else mm (said). The axes are given by ``--axes``: where the file's X,
Y, Z point, default ``forward,left,up`` (ISO 8855).
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from ..errors import PinSuspError
from .corner import SPINDLE, WHEEL_CENTER, Found, Source

FORMAT = "OptimumK table"
UNITS = {"mm": 1.0, "m": 1000.0, "in": 25.4, "inch": 25.4, "cm": 10.0}
EXCEL = (".xlsx", ".xlsm")
AXLE = ("axle_inboard", "axle_outboard")  # pin_susp's own spindle points, read as they are

# The names written (first) and read, compared without case, spaces, '_' or '-'.
NAMES = {
    "lower_wishbone_inboard_front": ("Lower Wishbone Front Pivot", "Chassis Lower Fore"),
    "lower_wishbone_inboard_rear": ("Lower Wishbone Rear Pivot", "Chassis Lower Aft"),
    "lower_wishbone_outboard": ("Lower Ball Joint", "Upright Lower"),
    "upper_wishbone_inboard_front": ("Upper Wishbone Front Pivot", "Chassis Upper Fore"),
    "upper_wishbone_inboard_rear": ("Upper Wishbone Rear Pivot", "Chassis Upper Aft"),
    "upper_wishbone_outboard": ("Upper Ball Joint", "Upright Upper"),
    "trackrod_inboard": ("Tie Rod Inboard", "Tie Rod Chassis", "Tie Rod Rack"),
    "trackrod_outboard": ("Tie Rod Outboard", "Tie Rod Upright"),
    "toe_link_inboard": ("Toe Link Inboard", "Toe Link Chassis"),
    "toe_link_outboard": ("Toe Link Outboard", "Toe Link Upright"),
    "pushrod_outboard": ("Push Rod Outboard", "Pushrod Outboard"),
    "pushrod_inboard": ("Push Rod Inboard", "Pushrod Inboard", "Push Rod Rocker"),
    "rocker_axis_a": ("Rocker Axis Point 1", "Rocker Pivot"),
    "rocker_axis_b": ("Rocker Axis Point 2", "Rocker Axis"),
    "strut_top": ("Damper Inboard", "Damper Chassis", "Strut Top Mount"),
    "strut_bottom": ("Damper Outboard", "Strut Lower Mount"),
    WHEEL_CENTER: ("Wheel Center", "Wheel Centre"),
    SPINDLE: ("Spindle Point", "Wheel Spindle Point"),
}
MACPHERSON = {"strut_top": "Strut Top Mount", "strut_bottom": "Strut Lower Mount"}
# names that say where the pushrod or the damper picks up (pin_susp's actuation.mount)
MOUNTED = {
    "Push Rod Wishbone": ("pushrod_outboard", "lower_wishbone"),
    "Push Rod Upright": ("pushrod_outboard", "upright"),
    "Damper Wishbone": ("strut_bottom", "lower_wishbone"),
    "Damper Upright": ("strut_bottom", "upright"),
    "Damper Rocker": ("strut_bottom", None),
}


def key(name: str) -> str:
    return re.sub(r"[\s_\-]+", "", str(name)).lower()


def vocabulary(extra: dict | None = None) -> dict[str, str]:
    """Compared name → pin_susp point: this table's names, pin_susp's own, ``extra``."""
    from .lotus import NAMES as LOTUS

    out = {key(role): role for role in (*NAMES, *AXLE)}
    out.update({key(n): role for n, role in LOTUS.items()})
    out.update({key(n): role for role, names in NAMES.items() for n in names})
    out.update({key(n): role for n, (role, _) in MOUNTED.items()})
    out.update({key(n): role for n, role in (extra or {}).items()})
    return out


DIRECTIONS = {
    "forward": (0, 1.0),
    "rearward": (0, -1.0),
    "left": (1, 1.0),
    "right": (1, -1.0),
    "up": (2, 1.0),
    "down": (2, -1.0),
}


def parse_axes(text: str) -> tuple[np.ndarray, np.ndarray]:
    """``rearward,right,up`` (where the file's X, Y, Z point) → (ISO index, sign) of each."""
    parts = [p.strip().lower() for p in text.split(",")]
    if len(parts) != 3 or any(p not in DIRECTIONS for p in parts):
        raise ValueError(
            f"expected where X, Y, Z point, three of {', '.join(DIRECTIONS)} "
            f"(e.g. forward,left,up), got {text!r}"
        )
    index = np.array([DIRECTIONS[p][0] for p in parts])
    if sorted(index) != [0, 1, 2]:
        raise ValueError(f"X, Y, Z must point along three different axes, got {text!r}")
    sign = np.array([DIRECTIONS[p][1] for p in parts])
    frame = np.zeros((3, 3))
    frame[index, [0, 1, 2]] = sign  # column k: the file's axis k in ISO
    if np.linalg.det(frame) < 0:
        raise ValueError(
            f"{text} is a left-handed frame (a mirror image of the car): check the axes"
        )
    return index, sign


def to_iso(xyz: np.ndarray, axes) -> np.ndarray:
    index, sign = axes
    out = np.empty(3)
    out[index] = sign * xyz
    return out


def from_iso(xyz: np.ndarray, axes) -> np.ndarray:
    index, sign = axes
    return sign * np.asarray(xyz)[index]


def read(path: str, raw: bytes, options) -> Source:
    rows, first = _rows(path, raw)
    header = [str(h).strip() for h in rows[0]]
    columns = [_column(header, a) for a in "XYZ"]
    if None in columns:
        missing = ", ".join(a for a, c in zip("XYZ", columns, strict=True) if c is None)
        raise PinSuspError(f"{path}: row {first}: no {missing} column in the header {header}")
    name_col = next((i for i in range(len(header)) if i not in columns), None)
    if name_col is None:
        raise PinSuspError(f"{path}: row {first}: no column for the points' names")
    scale, unit_note = _scale(path, [header[c] for c in columns], options)
    axes = options.axes
    words = vocabulary(options.map)
    points, said = [], {}
    mounts = {key(n): on for n, (_, on) in MOUNTED.items() if on}
    for n, row in enumerate(rows[1:], start=first + 1):
        cells = list(row) + [""] * (len(header) - len(row))
        name = str(cells[name_col]).strip() if cells[name_col] is not None else ""
        if not name or name.lower() == "nan":
            continue
        xyz = np.array([_number(path, n, name, header[c], cells[c]) for c in columns]) * scale
        role = words.get(key(name))
        points.append(Found(name, f"row {n}", to_iso(xyz, axes), role))
        if key(name) in mounts and role not in {p.role for p in points[:-1]}:
            said["actuation_mount"] = mounts[key(name)]
    if not points:
        raise PinSuspError(f"{path}: no points under the header (row {first})")
    src = Source(path, FORMAT, points, said=said, label=labels())
    given = getattr(options, "axes_given", True)
    axes_note = "" if given else " (the default, ISO 8855: check OptimumK's options, give --axes)"
    src.described = f"lengths in {unit_note}; X, Y, Z point {options.axes_text}{axes_note}"
    return src


class Formula(str):
    """An Excel cell holding a formula whose value the workbook did not save."""


def _rows(path: str, raw: bytes) -> tuple[list[list], int]:
    """The table's rows from the header on (the header first) and the header's row
    number; the rows above it (a title) are skipped."""
    if not raw.strip():
        raise PinSuspError(f"{path}: the file is empty")
    if Path(path).suffix.lower() in EXCEL:
        rows = _excel_rows(path, raw)
        for i, row in enumerate(rows):  # the header: the first row with an X, a Y and a Z
            if all(_column([str(c) for c in row], a) is not None for a in "XYZ"):
                return rows[i:], i + 1
    else:
        lines = _text(path, raw).splitlines()
        for i, line in enumerate(lines):
            for sep in ",;\t":  # the header's separator is the table's
                cells = next(csv.reader([line], delimiter=sep), [])
                if all(_column(cells, a) is not None for a in "XYZ"):
                    return [list(r) for r in csv.reader(lines[i:], delimiter=sep)], i + 1
    raise PinSuspError(f"{path}: no header row with X, Y and Z columns")


def _text(path: str, raw: bytes) -> str:
    if b"\0" in raw:
        raise PinSuspError(f"{path}: not a text table (binary data): a CSV table is text")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def _excel_rows(path: str, raw: bytes) -> list[list]:
    """The first sheet's cells (None: ''); a formula the workbook saved no value of
    is a :class:`Formula`."""
    import io

    import openpyxl

    try:
        values, formulas = (
            openpyxl.load_workbook(io.BytesIO(raw), data_only=d).worksheets[0]
            for d in (True, False)
        )
        pairs = zip(
            values.iter_rows(values_only=True), formulas.iter_rows(values_only=True), strict=False
        )
        return [
            [
                Formula(f)
                if v is None and isinstance(f, str) and f.startswith("=")
                else ("" if v is None else v)
                for v, f in zip(vr, fr, strict=False)
            ]
            for vr, fr in pairs
        ]
    except Exception:  # not a workbook openpyxl opens (junk, an old .xls): said, no traceback
        raise PinSuspError(
            f"{path}: not an Excel workbook (.xlsx, .xlsm) openpyxl can open: save it as "
            ".xlsx or export the table as CSV"
        ) from None


def _column(header: list[str], axis: str) -> int | None:
    return next(
        (
            i
            for i, h in enumerate(header)
            if re.fullmatch(rf"{axis}(\s*[\(\[].*)?", h.strip(), re.I)
        ),
        None,
    )


def _scale(path: str, headers: list[str], options) -> tuple[float, str]:
    found = {m.group(1).lower() for h in headers if (m := re.search(r"[\(\[]\s*(\w+)\s*[\)\]]", h))}
    if options.units is not None:
        if any(UNITS.get(u) != UNITS[options.units] for u in found):
            raise PinSuspError(
                f"{path}: --units {options.units}: the X, Y, Z headers say "
                f"{', '.join(sorted(found))} ({', '.join(headers)}): give --units only for a "
                "table whose headers name no unit"
            )
        return UNITS[options.units], f"{options.units} (--units)"
    if len(found) > 1 or (found and not found <= set(UNITS)):
        raise PinSuspError(
            f"{path}: the X, Y, Z headers give units {sorted(found)}: give --units mm|m|in"
        )
    if found:
        unit = found.pop()
        return UNITS[unit], f"{unit} (from the header)"
    return 1.0, "mm (the header gives no unit; give --units)"


def _number(path: str, row: int, name: str, column: str, value) -> float:
    if isinstance(value, Formula):
        raise PinSuspError(
            f"{path}: row {row} ({name!r}): {column}: the cell is a formula ({value}) without a "
            "saved value: save the workbook in Excel (or LibreOffice) or give the values"
        )
    try:
        x = float(value)
        if not np.isfinite(x):
            raise ValueError
        return x
    except (TypeError, ValueError):
        raise PinSuspError(
            f"{path}: row {row} ({name!r}): {column}: expected a number, got {value!r}"
        ) from None


def labels(kind: str = "double_wishbone", actuation: str = "direct", mount: str = "") -> dict:
    """pin_susp point → the name written for it."""
    out = {role: names[0] for role, names in NAMES.items()}
    if kind == "macpherson":
        out.update(MACPHERSON)
    else:
        for name, (role, on) in MOUNTED.items():
            if on == mount and (actuation == "direct" or role == "pushrod_outboard"):
                out[role] = name
        if actuation == "pushrod_rocker":
            out["strut_bottom"] = "Damper Rocker"
    return out


def write(g, points: dict[str, np.ndarray], path: str, axes) -> bytes | str:
    """The table of the corner ``g`` (``points``: pin_susp names, ISO mm): CSV text,
    or an Excel workbook's bytes where ``path`` ends in .xlsx."""
    label = labels(g.type, g.actuation, g.actuation_mount)
    header = ["Point", *(f"{a} (mm)" for a in "XYZ")]
    rows = [[label[r], *(float(v) + 0.0 for v in from_iso(xyz, axes))] for r, xyz in points.items()]
    if Path(path).suffix.lower() in EXCEL:
        import io

        import openpyxl

        book = openpyxl.Workbook()
        sheet = book.active
        sheet.title = "Hardpoints"
        for row in [header, *rows]:
            sheet.append(row)
        buffer = io.BytesIO()
        book.save(buffer)
        return buffer.getvalue()
    lines = [",".join(header)] + [",".join([r[0], *(repr(v) for v in r[1:])]) for r in rows]
    return "\n".join(lines) + "\n"
