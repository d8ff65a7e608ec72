"""Adams/Car property files: the hardpoint table (docs/interop.md, "Adams/Car").

Read: the ``[UNITS]`` block's ``LENGTH`` (mm, cm, m, inch, foot; default mm,
said); every row of a ``[HARDPOINT]`` / ``[HARDPOINTS]`` table (or of a block under a
``$---...HARDPOINT...`` divider): ``'hpl_name' x y z`` / ``'hpr_name' x y z``, or a
subsystem file's ``'name' 'left/right' x y z`` (the left's values; the right is its
mirror) and ``'name' 'single' x y z``; and a ``[PARAMETER]`` table's
``camber_angle`` and ``toe_angle`` for the spin axis (in the ``[UNITS]`` block's
``ANGLE``: degrees, or radians converted; within ±45°). Adams/Car axes: x
rearward, y to the right, z up; in ISO: x = −X, y = −Y, z = Z (its left corner has
Y < 0). One side is read, ``--side`` (default the left where the file has it).
"""

from __future__ import annotations

import re
import shlex

import numpy as np

from ..errors import PinSuspError
from .corner import WHEEL_CENTER, Found, Source, angle_problem

FORMAT = "Adams/Car property file"
TO_ISO = np.array([-1.0, -1.0, 1.0])
LENGTH = {
    "mm": 1.0,
    "millimeter": 1.0,
    "millimeters": 1.0,
    "cm": 10.0,
    "centimeter": 10.0,
    "m": 1000.0,
    "meter": 1000.0,
    "meters": 1000.0,
    "inch": 25.4,
    "in": 25.4,
    "foot": 304.8,
    "ft": 304.8,
}
# Adams/Car's template names (without hpl_/hpr_) → pin_susp point, rank
NAMES = {
    "lca_front": ("lower_wishbone_inboard_front", 0),
    "lca_rear": ("lower_wishbone_inboard_rear", 0),
    "lca_outer": ("lower_wishbone_outboard", 0),
    "uca_front": ("upper_wishbone_inboard_front", 0),
    "uca_rear": ("upper_wishbone_inboard_rear", 0),
    "uca_outer": ("upper_wishbone_outboard", 0),
    "tierod_inner": ("trackrod_inboard", 0),
    "tierod_outer": ("trackrod_outboard", 0),
    "wheel_center": (WHEEL_CENTER, 0),
    "top_mount": ("strut_top", 0),
    "strut_upper": ("strut_top", 0),
    "damper_upper": ("strut_top", 0),
    "spring_upper": ("strut_top", 1),
    "lower_strut": ("strut_bottom", 0),
    "strut_lower": ("strut_bottom", 0),
    "lwr_strut_mount": ("strut_bottom", 0),
    "damper_lower": ("strut_bottom", 0),
    "spring_lower": ("strut_bottom", 1),
    "prod_outer": ("pushrod_outboard", 0),
    "pushrod_outer": ("pushrod_outboard", 0),
    "prod_inner": ("pushrod_inboard", 0),
    "pushrod_inner": ("pushrod_inboard", 0),
    "bellcrank_pivot": ("rocker_axis_a", 0),
    "rocker_pivot": ("rocker_axis_a", 0),
    "bellcrank_pivot_orient": ("rocker_axis_b", 0),
    "rocker_axis": ("rocker_axis_b", 0),
}
ANGLE = {  # deg per unit
    "degrees": 1.0,
    "degree": 1.0,
    "deg": 1.0,
    "radians": 180.0 / np.pi,
    "radian": 180.0 / np.pi,
    "rad": 180.0 / np.pi,
}
SIDE = {"left": "hpl_", "right": "hpr_"}


def read(path: str, text: str, options) -> Source:
    lines = text.splitlines()
    scale, unit_note, degrees = _units(path, lines)
    rows, params = [], {}
    block = None
    for no, line in enumerate(lines, start=1):
        t = line.strip()
        if t.startswith("["):
            block = t.strip("[] ").upper()
            continue
        if t.startswith("$") and re.search(r"-{3,}", t):
            block = re.sub(r"[$\-\s]", "", t).upper() or block
            continue
        if not t or t.startswith(("$", "{", "!")):
            continue
        if block in ("HARDPOINT", "HARDPOINTS"):
            rows.append((no, _tokens(path, no, t)))
        elif block in ("PARAMETER", "PARAMETERS"):
            tokens = _tokens(path, no, t)
            params[tokens[0].lower()] = (no, tokens)
    if not rows:
        raise PinSuspError(f"{path}: no [HARDPOINT] table (rows 'hpl_name' x y z)")
    has = {s for s, prefix in SIDE.items() if any(r[0].lower().startswith(prefix) for _, r in rows)}
    side = (
        options.side if options.side in has else ("left" if "left" in has or not has else "right")
    )
    points = [_point(path, no, tokens, scale, side) for no, tokens in rows]
    src = Source(
        path,
        FORMAT,
        points,
        described=f"lengths in {unit_note}, the {side} side",
        label=labels(side),
    )
    for what in ("camber", "toe"):
        found = params.get(f"{what}_angle") or params.get(f"pv{side[0]}_{what}_angle")
        if found is not None:
            no, tokens = found
            value = _number(path, no, tokens[0], tokens[-1]) * degrees
            problem = angle_problem(value)
            if problem:
                raise PinSuspError(f"{path}: line {no} ({tokens[0]!r}): {problem}")
            setattr(src, what, value)
    return src


def _tokens(path: str, no: int, text: str) -> list[str]:
    try:
        return shlex.split(text.replace(",", " "))
    except ValueError as exc:
        raise PinSuspError(f"{path}: line {no}: {exc}") from None


def _units(path: str, lines: list[str]) -> tuple[float, str, float]:
    """The ``[UNITS]`` block's LENGTH (mm per unit, said) and ANGLE (deg per unit)."""
    inside, found = False, {}
    for no, line in enumerate(lines, start=1):
        t = line.strip()
        if t.startswith("["):
            inside = t.strip("[] ").upper() == "UNITS"
            continue
        m = re.fullmatch(r"(LENGTH|ANGLE)\s*=\s*'?([A-Za-z]+)'?", t, re.I) if inside else None
        if m:
            what, unit = m.group(1).upper(), m.group(2).lower()
            table = LENGTH if what == "LENGTH" else ANGLE
            if unit not in table:
                raise PinSuspError(
                    f"{path}: line {no}: [UNITS] {what} {unit!r}: "
                    f"expected one of {', '.join(table)}"
                )
            found.setdefault(what, (table[unit], unit))
    scale, unit = found.get("LENGTH", (1.0, "mm (the file has no [UNITS] LENGTH)"))
    return scale, unit, found.get("ANGLE", (1.0, ""))[0]


def _number(path: str, no: int, name: str, value: str) -> float:
    try:
        x = float(value)
        if not np.isfinite(x):
            raise ValueError
        return x
    except ValueError:
        raise PinSuspError(
            f"{path}: line {no} ({name!r}): expected a number, got {value!r}"
        ) from None


def _point(path: str, no: int, tokens: list[str], scale: float, side: str) -> Found:
    name = tokens[0]
    numbers = tokens[-3:]
    if len(tokens) < 4:
        raise PinSuspError(
            f"{path}: line {no}: {name!r}: expected a name and x y z, got {' '.join(tokens)!r}"
        )
    xyz = np.array([_number(path, no, name, v) for v in numbers]) * scale
    symmetry = tokens[1].lower() if len(tokens) >= 5 else ""
    base, where = name.lower(), f"line {no}"
    for s, prefix in SIDE.items():
        if base.startswith(prefix):
            if s != side:
                return Found(
                    name,
                    where,
                    xyz * TO_ISO,
                    None,
                    why=f"the {s} side's (reading the {side}: --side)",
                )
            base = base.removeprefix(prefix)
            break
    else:
        if base.startswith("hps_") or symmetry == "single":
            return Found(name, where, xyz * TO_ISO, None, why="a single (centreline) point")
    role, rank = NAMES.get(base, (None, 0))  # a subsystem file's left/right: the left's values
    return Found(name, where, xyz * TO_ISO, role, rank)


def labels(side: str) -> dict:
    prefix = SIDE[side]
    out = {}
    for name, (role, rank) in NAMES.items():
        if rank == 0 and role not in out:
            out[role] = prefix + name
    return out
