"""The units an input file is written in (docs/geometry.md, "Units"): ``units:`` for its
lengths (``millimeters``, the default, ``meters``, ``inches``) and ``force_units:`` for
its forces, rates and moments (``N``: N, N/mm, N·m; ``lbf``: lbf, lbf/in, lbf·in).

A geometry file (a corner's, an axle's, a vehicle's) is turned into pin_susp's own
units (mm, N) as data, before anything reads it (``corner_in_mm``, ``axle_in_mm``,
``vehicle_in_mm``): every reader after it, and every file written back from it, speaks
mm and N. Sweep, load-case and study files take the same keys for their own numbers
(``read_units``; their readers scale what they read). Angles are degrees in every unit
system; masses kg; the tyre's size (section width mm, aspect ratio, rim diameter in) is
the sidewall's code, read as written.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

MM = 1e-3  # m per mm
INCH = 0.0254  # m per inch
LENGTH_UNITS = {  # mm per unit; the short names as the commands' --units take them
    "millimeters": 1.0,
    "meters": 1000.0,
    "inches": 25.4,
    "mm": 1.0,
    "m": 1000.0,
    "in": 25.4,
}
LBF = 4.4482216152605  # N per lbf (exact: 0.45359237 kg × 9.80665 m/s²)
# force_units → (N per unit force, N/mm per unit rate, N·m per unit moment)
FORCE_UNITS = {"N": (1.0, 1.0, 1.0), "lbf": (LBF, LBF / 25.4, LBF * INCH)}


@dataclass(frozen=True)
class Units:
    """What one unit of a file's number is in pin_susp's: mm, N, N/mm, N·m."""

    length: float = 1.0
    force: float = 1.0
    rate: float = 1.0
    moment: float = 1.0

    @property
    def own(self) -> bool:
        """Already pin_susp's units (mm, N): nothing to convert."""
        return self == Units()


def read_units(data: dict, r, key: str = "") -> Units:
    """The ``units:`` and ``force_units:`` of a file's mapping (``key``: where it is)."""
    where = f"{key}." if key else ""
    length = r.choice(data.get("units", "millimeters"), f"{where}units", tuple(LENGTH_UNITS))
    force = r.choice(data.get("force_units", "N"), f"{where}force_units", tuple(FORCE_UNITS))
    return Units(LENGTH_UNITS[length], *FORCE_UNITS[force])


def scaled(value, factor: float):
    """A number, or the numbers in a list or mapping (a point), times ``factor``; what
    is not a number is left as it is, for its reader to name."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int | float):
        try:
            return value * factor
        except OverflowError:  # an int beyond float range: its reader says so
            return value
    if isinstance(value, list | tuple):
        return [scaled(v, factor) for v in value]
    if isinstance(value, dict):
        return {k: scaled(v, factor) for k, v in value.items()}
    return value


def scale_at(data: dict, path: str, factor: float) -> None:
    """Scale the value at the dotted ``path`` of ``data`` in place, where it is there."""
    *parents, last = path.split(".")
    for name in parents:
        data = data.get(name) if isinstance(data, dict) else None
    if isinstance(data, dict) and last in data:
        data[last] = scaled(data[last], factor)


# A wheel's keys (config.wheel, axle_config.wheel) by what they are
WHEEL_LENGTHS = ("center", "offset") + tuple(
    f"{t}.{k}" for t in ("tyre", "tire") for k in ("diameter", "width", "loaded_radius")
)
WHEEL_RATES = ("tyre.rate", "tire.rate")
SETUP_LENGTHS = (
    "camber_shim.shim_face_point_a",
    "camber_shim.shim_face_point_b",
    "camber_shim.design_thickness",
    "camber_shim.setup_thickness",
    "trackrod_length_delta",
    "pushrod_length_delta",
)


def _spring(data: dict, spring: str, actuation: str, config: str, u: Units) -> None:
    """A spring's rate and preload (a coilover's N/mm and N, a torsion bar's N·m/deg and
    N·m) and a MacPherson strut's, and the rocker's bearing spacing."""
    block = data
    for name in spring.split("."):
        block = block.get(name) if isinstance(block, dict) else None
    torsion = isinstance(block, dict) and block.get("type") == "torsion_bar"
    scale_at(data, f"{spring}.rate", u.moment if torsion else u.rate)
    scale_at(data, f"{spring}.preload", u.moment if torsion else u.force)
    scale_at(data, f"{config}.strut.rate", u.rate)
    scale_at(data, f"{config}.strut.preload", u.force)
    scale_at(data, f"{actuation}.bearing_spacing", u.length)
    scale_at(data, f"{config}.steering.c_factor", u.length)
    for k in ("driveshaft.outboard_offset", "driveshaft.max_plunge", "limits.damper_stroke"):
        scale_at(data, f"{config}.{k}", u.length)  # docs/geometry.md, "Driveshaft", "Travel
    scale_at(data, f"{config}.limits.bump_stop.gap", u.length)  # limits"
    scale_at(data, f"{config}.limits.rebound", u.length)
    scale_at(data, f"{config}.limits.bump_stop.rate", u.rate)


def _compliance(data: dict, u: Units) -> None:
    """The ``compliance:`` block's rates (docs/compliance.md): a bushing's radial and
    axial (force per length) and torsional and conical (moment per degree) rates, or
    its 6×6 by block (force/length, force per radian, moment per radian); the links'
    and the tyre's rates (force per length)."""
    block = data.get("compliance")
    if not isinstance(block, dict):
        return
    for spec in (
        (block.get("bushings") or {}).values() if isinstance(block.get("bushings"), dict) else ()
    ):
        if not isinstance(spec, dict):
            continue
        for k in ("radial", "axial"):
            scale_at(spec, k, u.rate)
        for k in ("torsional", "conical"):
            scale_at(spec, k, u.moment)
        k = spec.get("k")
        if isinstance(k, list) and len(k) == 6 and all(isinstance(row, list) for row in k):
            spec["k"] = [
                [
                    scaled(
                        v, u.rate if i < 3 and j < 3 else u.moment if i >= 3 and j >= 3 else u.force
                    )
                    for j, v in enumerate(row)
                ]
                for i, row in enumerate(k)
            ]
    for part in ("links", "tyre"):
        if isinstance(block.get(part), dict):
            block[part] = scaled(block[part], u.rate)


def _wheel(data: dict, wheel: str, u: Units) -> None:
    for k in WHEEL_LENGTHS:
        scale_at(data, f"{wheel}.{k}", u.length)
    for k in WHEEL_RATES:
        scale_at(data, f"{wheel}.{k}", u.rate)


def corner_in_mm(data: dict, r) -> dict:
    """A corner file's data in mm and N (``data`` itself when it is already)."""
    u = read_units(data, r)
    if u.own:
        return data
    data = copy.deepcopy(data)
    scale_at(data, "hardpoints", u.length)
    _wheel(data, "config.wheel", u)
    for k in ("cg_position", "wheelbase", "opposite_axle_axis_height"):
        scale_at(data, f"config.{k}", u.length)
    for k in SETUP_LENGTHS:
        scale_at(data, f"config.{k}" if k.startswith("camber") else f"config.setup.{k}", u.length)
    _spring(data, "spring", "actuation", "config", u)
    _compliance(data, u)
    return data | {"units": "millimeters", "force_units": "N"}


def axle_in_mm(data: dict, r) -> dict:
    """An axle file's data in mm and N (``data`` itself when it is already)."""
    u = read_units(data, r)
    if u.own:
        return data
    data = copy.deepcopy(data)
    scale_at(data, "hardpoints", u.length)  # left, right and center
    _wheel(data, "axle_config.wheel", u)
    for k in ("cg_position", "wheelbase"):
        scale_at(data, f"vehicle_config.{k}", u.length)
    for side in ("left", "right"):
        for k in SETUP_LENGTHS:
            scale_at(data, f"axle_config.{side}_setup.{k}", u.length)
    _spring(data, "axle_config.spring", "axle_config.actuation", "axle_config", u)
    scale_at(data, "axle_config.anti_roll.stiffness", u.moment)  # N·m/deg ("rigid" stays)
    _compliance(data, u)
    return data | {"units": "millimeters", "force_units": "N"}


def vehicle_in_mm(data: dict, r) -> dict:
    """A vehicle file's data in mm and N (``data`` itself when it is already). An axle
    given inline without units of its own is written in the vehicle's."""
    u = read_units(data, r)
    if u.own:
        return data
    data = copy.deepcopy(data)
    for k in ("wheelbase", "cg.z", "cg.x_mm", "steering.c_factor"):
        scale_at(data, f"vehicle_config.{k}", u.length)
    for k in ("vertical", "front.vertical", "rear.vertical"):
        scale_at(data, f"vehicle_config.tyres.{k}", u.rate)
    for end in ("front", "rear"):
        axle = data.get(end)
        if isinstance(axle, dict):
            for k in ("units", "force_units"):
                axle.setdefault(k, data.get(k, "millimeters" if k == "units" else "N"))
    return data | {"units": "millimeters", "force_units": "N"}
