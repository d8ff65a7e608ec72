"""Lotus SHARK / Lotus Suspension Analysis ``.shk`` files (docs/interop.md, "Lotus
SHARK").

The layout read (and written): optional heading lines up to a ``FRONT SUSPENSION``
or ``REAR SUSPENSION`` line (without one, the file starts at the type line); the
suspension type line (``Double Wishbone, damper to lower wishbone``, a ``TYPE n``
before it allowed); then one block per point — a name line, five definition lines
(skipped), a line ``x y z`` in mm — each block perhaps followed by lines of numbers
only (flags, skipped). The points end at the file's end or at a heading (a line in
capitals). Lotus axes: X rearward, Y outboard of the right wheel, Z up; in ISO
(x forward, y left, z up): x = −X, y = −Y, z = Z.
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import PinSuspError
from .corner import SPINDLE, WHEEL_CENTER, Found, Source

FORMAT = "Lotus SHARK"
TO_ISO = np.array([-1.0, -1.0, 1.0])  # Lotus (X rear, Y right, Z up) → ISO; its own inverse
DEFINITION_LINES = 5

# Lotus point name (as written, compared in lower case) → pin_susp point, and the
# rank among names of one point (0 used first). Names whose use depends on the
# type (the damper's and pushrod's ends) are in ACTUATION_NAMES.
NAMES = {
    "Lower wishbone front pivot": "lower_wishbone_inboard_front",
    "Lower wishbone rear pivot": "lower_wishbone_inboard_rear",
    "Lower wishbone outer ball joint": "lower_wishbone_outboard",
    "Upper wishbone front pivot": "upper_wishbone_inboard_front",
    "Upper wishbone rear pivot": "upper_wishbone_inboard_rear",
    "Upper wishbone outer ball joint": "upper_wishbone_outboard",
    "Inner track rod ball joint": "trackrod_inboard",
    "Outer track rod ball joint": "trackrod_outboard",
    "Wheel spindle point": SPINDLE,
    "Wheel centre point": WHEEL_CENTER,
    "Push rod rocker end": "pushrod_inboard",
    "Rocker axis 1st point": "rocker_axis_a",
    "Rocker axis 2nd point": "rocker_axis_b",
    "Damper to body point": "strut_top",
    "Damper to rocker point": "strut_bottom",
    "Damper body end": "strut_top",
    "Upper spring pivot point": "strut_top",
    # MacPherson strut
    "Strut top mount": "strut_top",
    "Top strut mount": "strut_top",
    "Damper upright end": "strut_bottom",
    "Strut lower mount": "strut_bottom",
}
# on the lower wishbone (pin_susp's mount lower_wishbone) or the upright
MOUNTED = {
    "Damper wishbone end": ("strut_bottom", "lower_wishbone"),
    "Lower spring pivot point": ("strut_bottom", "lower_wishbone"),
    "Push rod wishbone end": ("pushrod_outboard", "lower_wishbone"),
    "Push rod upright end": ("pushrod_outboard", "upright"),
    "Damper upright end": ("strut_bottom", "upright"),
}
SPRING = ("Upper spring pivot point", "Lower spring pivot point")  # after the damper's
LOWER = {k.lower(): v for k, v in NAMES.items()}
LOWER_MOUNTED = {k.lower(): v for k, v in MOUNTED.items()}
# the damper's, spring's, pushrod's and rocker's points (the actuation)
ACTUATION_POINTS = set(LOWER_MOUNTED) | {
    k for k, v in LOWER.items() if v.startswith(("strut_", "pushrod_", "rocker_"))
}


# a line of Lotus' printed report: "x y z POINT ( 1 ) = name" or "x y z POINT:1 name"
REPORT_LINE = re.compile(
    r"\s*(\S+)\s+(\S+)\s+(\S+)\s+POINT\s*(?:\(\s*\d+\s*\)\s*=|:\s*\d+)\s*(.*?)\s*$", re.I
)


def read(path: str, text: str, options) -> Source:
    lines = text.splitlines()
    if any(REPORT_LINE.fullmatch(t) for t in lines):
        return _read_report(path, lines)
    start = next(
        (
            i + 1
            for i, t in enumerate(lines)
            if t.strip().upper() in ("FRONT SUSPENSION", "REAR SUSPENSION")
        ),
        0,
    )
    i = _skip_blank(lines, start)
    if i >= len(lines):
        raise _error(
            path, None, "no suspension type line (e.g. 'Double Wishbone, damper to lower wishbone')"
        )
    type_line, type_no = re.sub(r"^TYPE\s+\d+\s+", "", lines[i].strip(), flags=re.I), i + 1
    if type_line.lower() in LOWER or type_line.lower() in LOWER_MOUNTED:
        raise _no_type(path, type_no, type_line)
    try:
        kind, said = _type(path, type_line, type_no)
    except PinSuspError:
        if _xyz(lines, i + 1 + DEFINITION_LINES):  # the line is a point's name after all
            raise _no_type(path, type_no, type_line) from None
        raise
    points = []
    i = _skip_blank(lines, i + 1)
    while i < len(lines) and not _heading(lines[i]):
        name = lines[i].strip()
        if not re.search(r"[A-Za-z]", name):
            raise _error(path, i + 1, f"expected a point's name, got {name!r}")
        at = i + 1 + DEFINITION_LINES
        if at >= len(lines):
            raise _error(path, i + 1, f"the block of {name!r} ends before its x y z line")
        points.append(_point(path, name, (i + 1, at + 1), lines[at], kind, said))
        i = at + 1
        while i < len(lines) and (not lines[i].strip() or not re.search(r"[A-Za-z]", lines[i])):
            i += 1
    if not points:
        raise _error(path, type_no, f"no point blocks after the type line {type_line!r}")
    return Source(
        path,
        FORMAT,
        points,
        kind=kind,
        said=said,
        described=repr(type_line),
        label=labels(kind, said),
    )


def _read_report(path: str, lines: list[str]) -> Source:
    """Lotus' printed report (``TYPE 1 Double Wishbone, ...`` then one line per point,
    its x y z before its name); its first table of points only (the static one)."""
    at = next((i for i, t in enumerate(lines) if re.match(r"\s*TYPE\s+\d+\s+\S", t, re.I)), None)
    if at is None:
        raise _error(path, None, "a Lotus report without its 'TYPE n ...' line")
    type_line = re.sub(r"^\s*TYPE\s+\d+\s+", "", lines[at], flags=re.I).strip()
    kind, said = _type(path, type_line, at + 1)
    points, seen = [], False
    for no, t in enumerate(lines[at + 1 :], start=at + 2):
        m = REPORT_LINE.fullmatch(t)
        if m is None:
            if seen and t.strip().upper().startswith("STATIC VALUES"):
                break
            continue
        seen = True
        if m.group(4):  # "POINT:0", unnamed, ends some reports' lists
            points.append(_point(path, m.group(4), (no, no), " ".join(m.groups()[:3]), kind, said))
    if not points:
        raise _error(path, at + 1, f"no points after the type line {type_line!r}")
    label = labels(kind, said)
    return Source(
        path, FORMAT, points, kind=kind, said=said, described=repr(type_line), label=label
    )


def _no_type(path: str, line: int, text: str):
    return _error(
        path,
        line,
        f"no suspension type line: {text!r} starts a point's block (give the type, e.g. "
        "'Double Wishbone, damper to lower wishbone', on the line before the points)",
    )


def _xyz(lines: list[str], i: int) -> bool:
    """Whether line ``i`` is a point's x y z line."""
    values = lines[i].split() if i < len(lines) else []
    try:
        return len(values) == 3 and all(np.isfinite([float(v) for v in values]))
    except ValueError:
        return False


def _skip_blank(lines: list[str], i: int) -> int:
    while i < len(lines) and not lines[i].strip():
        i += 1
    return i


def _heading(line: str) -> bool:
    letters = re.sub(r"[^A-Za-z]", "", line)
    return len(letters) >= 2 and letters.isupper()


def _error(path: str, line: int | None, problem: str):
    return PinSuspError(f"{path}: {'' if line is None else f'line {line}: '}{problem}")


def _type(path: str, text: str, line: int) -> tuple[str, dict]:
    """The mechanism and choices a type line says; other types are refused."""
    t = " ".join(text.lower().replace("-", " ").split())
    if t.startswith("double wishbone"):
        rod = any(w in t for w in ("push rod", "pushrod", "pull rod", "pullrod", "rocker"))
        said = {"actuation": "pushrod_rocker" if rod else "direct"}
        if "upright" in t:
            said["actuation_mount"] = "upright"
        elif "upper wishbone" in t:
            said["upper"] = True  # pin_susp mounts nothing on the upper wishbone
            said["actuation"], said["spring"] = "direct", "none"
        else:
            said["actuation_mount"] = "lower_wishbone"
        return "double_wishbone", said
    if "mcpherson" in t or "macpherson" in t:
        return "macpherson", {}
    raise _error(
        path,
        line,
        f"suspension type {text!r}: pin_susp imports the Double Wishbone and McPherson "
        "strut types (this one has no pin_susp mechanism to read it as)",
    )


def _point(path: str, name: str, nos: tuple[int, int], line: str, kind: str, said: dict) -> Found:
    """The block of ``name`` (its line and its x y z line ``nos``)."""
    no = nos[1]
    values = line.split()
    try:
        if len(values) != 3:
            raise ValueError
        xyz = np.array([float(v) for v in values])
        if not np.all(np.isfinite(xyz)):
            raise ValueError
    except ValueError:
        raise _error(
            path, no, f"{name!r}: expected x y z (three numbers, mm), got {line.strip()!r}"
        ) from None
    key = name.lower()
    where, iso = f"line {nos[0]}", xyz * TO_ISO
    rank = 1 if key in (s.lower() for s in SPRING) else 0
    if said.get("upper") and key in ACTUATION_POINTS:
        return Found(
            name, where, iso, None, why="pin_susp has no damper or pushrod on the upper wishbone"
        )
    if kind == "macpherson" and key in ("damper upright end", "damper body end"):
        return Found(name, where, iso, LOWER[key], rank)
    if key in LOWER_MOUNTED:
        role, mount = LOWER_MOUNTED[key]
        if kind == "double_wishbone" and said.get("actuation_mount", mount) != mount:
            return Found(
                name,
                where,
                iso,
                None,
                why=f"a point on the {mount}, the type's is on the {said['actuation_mount']}",
            )
        return Found(name, where, iso, role, rank)
    if key in LOWER:
        return Found(name, where, iso, LOWER[key], rank)
    return Found(name, where, iso, None)


def labels(kind: str, said: dict) -> dict:
    """pin_susp point → the Lotus name this module writes for it."""
    out = {role: name for name, role in NAMES.items() if name not in SPRING}
    mount = said.get("actuation_mount", "lower_wishbone")
    for name, (role, on) in MOUNTED.items():
        if on == mount and name not in SPRING:
            out[role] = name
    out["toe_link_inboard"], out["toe_link_outboard"] = (
        out["trackrod_inboard"],
        out["trackrod_outboard"],
    )
    if kind == "macpherson":
        out["strut_top"], out["strut_bottom"] = "Damper body end", "Damper upright end"
    else:
        out["strut_top"] = (
            "Damper to body point"
            if said.get("actuation") == "pushrod_rocker"
            else "Damper body end"
        )
        if said.get("actuation") == "pushrod_rocker":
            out["strut_bottom"] = "Damper to rocker point"
    return out


def type_line(g) -> str:
    """The Lotus type line of a pin_susp corner (double wishbone or MacPherson)."""
    if g.type == "macpherson":
        return "McPherson Strut"
    on = "lower wishbone" if g.actuation_mount == "lower_wishbone" else "upright"
    if g.actuation == "pushrod_rocker":
        return f"Double Wishbone, push rod to {on}, damper to rocker"
    return f"Double Wishbone, damper to {on}"


def write(g, points: dict[str, np.ndarray]) -> str:
    """The .shk text of the corner ``g``: ``points`` its hardpoints and its wheel
    centre and spindle point (pin_susp names, ISO mm)."""
    said = {"actuation": g.actuation, "actuation_mount": g.actuation_mount}
    label = labels(g.type, said)
    out = [
        "LOTUS SUSPENSION ANALYSIS point file written by pin_susp (docs/interop.md)",
        "FRONT SUSPENSION" if g.axle_position != "rear" else "REAR SUSPENSION",
        type_line(g),
    ]
    for role, xyz in points.items():
        out.append(label[role])
        out.extend(["0"] * DEFINITION_LINES)
        out.append(" ".join(repr(float(v) + 0.0) for v in np.asarray(xyz) * TO_ISO))
    return "\n".join(out) + "\n"
