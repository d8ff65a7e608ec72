"""Output sign conventions and units, applied where a table is written (io.tables):
the Results in memory stay ISO 8855 (x forward, y left, z up) in mm, deg and N.

One table (docs/results.md, "Output conventions and units"): each convention is its
axes (each of its x, y, z as a sign of ISO's: none of the four permutes the axes) and
its own sign for toe and for the axles' steer angle. A column's sign is the product of
the factors its name carries, by rule, never by a list of literal names:

- a coordinate or a component along an axis: a name ending ``_x``, ``_y``, ``_z``
  (before a side or axle suffix ``_left``, ``_right``, ``_fl`` … ``_front``, ``_rear``):
  every point, instant centre, roll centre, a force's components; the axis' sign;
- an angle about an axis (roll, pitch, yaw: the steer and steering-wheel angles): the
  sign of that axis (every map here is a proper rotation, det +1, so an angle vector
  turns as a vector);
- a displacement named for its axis (``heave``, ``wheel_travel``, ``rack_displacement``…):
  that axis' sign (NAMED below);
- ``roadwheel_angle`` (toe): the convention's toe sign; ``steer_angle``: about z, or for
  OptimumK + outward on each side;
- ``deriv_<column>_wrt_<driver>``: sign(column) · sign(driver);
- anything else (camber, caster, KPI, scrub, trail, the kingpin offsets, anti-dive,
  lengths between points, members' tensions, rates): defined by a physical sense
  (+ top outboard, + inboard, + tension …) that every convention here shares: +1.

``--units in`` converts every column by its unit: mm → in, N → lbf, N·m → lbf·in, any
product or quotient of them (deg/mm → deg/in, N/mm → lbf/in); deg, %, g, Hz stay.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

INCH = 25.4  # mm
POUND_FORCE = 4.4482216152605  # N (exact: 0.45359237 kg · 9.80665 m/s²)


@dataclass(frozen=True)
class Convention:
    name: str
    axes: tuple  # each of its x, y, z: (the ISO axis, its sign)
    toe: int  # + toe-in (1) or + toe-out (-1)
    steer_outward: bool  # the steer angle + outward on each side (else: about z)
    text: str  # what the file's header says
    # columns this tool defines with the opposite physical sense (by stem, any side)
    negated: frozenset = frozenset()

    def axis_sign(self, axis: str) -> int:
        return dict(zip("xyz", (s for _, s in self.axes), strict=True))[axis]


CONVENTIONS = {
    "iso": Convention(
        "iso", (("x", 1), ("y", 1), ("z", 1)), 1, False, "ISO 8855: x forward, y left, z up"
    ),
    "sae": Convention(
        "sae", (("x", 1), ("y", -1), ("z", -1)), 1, False, "SAE J670: x forward, y right, z down"
    ),
    "lotus": Convention(
        "lotus",
        (("x", -1), ("y", -1), ("z", 1)),
        1,
        False,
        "Lotus SHARK: x rearward, y to the right, z up",
        # Lotus' castor trail (hub) reads + with the axis behind the wheel centre: two
        # Lotus reports' hub trail against their own hardpoints (docs/results.md)
        frozenset({"caster_trail_at_hub"}),
    ),
    "optimumk": Convention(
        "optimumk",
        (("x", 1), ("y", 1), ("z", 1)),
        -1,
        True,
        "OptimumK: x forward, y left, z up; toe + out, steer angle + outward",
    ),
}
DEFAULT = "iso"
UNITS = ("mm", "in")

# the side or axle a name ends with (or starts with: left_P, fl_P), outermost first
SUFFIX = re.compile(r"_(left|right|fl|fr|rl|rr|front|rear)$")
LEFT, RIGHT = ("left", "fl", "rl"), ("right", "fr", "rr")
# a column named for its axis (the factors its sign is the product of); drivers too
NAMED = {
    "roadwheel_angle": ("toe",),
    "steer_angle": ("steer",),
    "rack_displacement": ("y",),  # TRI_y − design: + rack to the left
    "force_rack": ("y",),  # along +y
    "rack_force": ("rz",),  # + where the loads push the rack the way that steers left
    "heave": ("z",),
    "wheel_travel": ("z",),  # WC_z − design
    "ride_height_change": ("z",),
    "hub_z": ("z",),  # the derivatives' driver: the wheel centre's z
    "roll": ("rx",),
    "axle_roll": ("rx",),
    "body_roll": ("rx",),
    "pitch": ("ry",),
    "steering_wheel_angle": ("rz",),
    "steering_wheel": ("rz",),
    "steering_wheel_torque": ("rz",),
    "ax": ("x",),
    "ay": ("y",),
    "roll_gradient": ("rx", "y"),  # d roll / d ay
}

# columns whose sense one of the tools defines the other way (Convention.negated)
DEFINED = ("caster_trail_at_hub",)


def stem(name: str) -> tuple[str, str | None]:
    """The name without its side or axle suffixes, and the side it names (left, right,
    or None): ``camber_fl`` → (camber, left); ``left_wheel_center_x`` → (…, left)."""
    side = None
    while True:
        m = SUFFIX.search(name)
        if not m:
            break
        side = side or ("left" if m.group(1) in LEFT else "right" if m.group(1) in RIGHT else None)
        name = name[: m.start()]
    head = name.split("_", 1)[0]
    if side is None and head in LEFT + RIGHT:
        side = "left" if head in LEFT else "right"
    return name, side


def factors(name: str) -> tuple:
    """What a column's sign is made of (module docstring): () for a sign no
    convention changes."""
    base, _ = stem(name)
    if base.startswith("deriv_") and "_wrt_" in base:
        column, _, driver = base.removeprefix("deriv_").rpartition("_wrt_")
        return factors(column) + factors(driver)
    if base in NAMED:
        return NAMED[base]
    if base in DEFINED:
        return (base,)
    if re.search(r"(^|_)[xyz]$", base):
        return (base[-1],)
    return ()


def sign(name: str, convention: Convention) -> int:
    """The column's sign in ``convention`` (+1 or −1): its values there are sign × ISO's."""
    _, side = stem(name)
    out = 1
    for f in factors(name):
        if f in "xyz":
            out *= convention.axis_sign(f)
        elif f in ("rx", "ry", "rz"):
            out *= convention.axis_sign(f[1])
        elif f in DEFINED:
            out *= -1 if f in convention.negated else 1
        elif f == "toe":
            out *= convention.toe
        elif f == "steer":
            out *= (
                (-1 if side == "right" else 1)
                if convention.steer_outward
                else (convention.axis_sign("z"))
            )
    return out


# -- units ---------------------------------------------------------------------------

_INCH_UNITS = {"mm": ("in", INCH, 1), "m": ("in", INCH, 1e-3), "N": ("lbf", POUND_FORCE, 1)}


def unit_conversion(unit: str, units: str) -> tuple[str, float, float]:
    """The unit in ``units`` (mm: as it is; in: lengths in inches, forces in lbf) and
    the (multiplier, divisor) that turn a value in ``unit`` into it: value · m / d.
    ``deg/mm`` → (deg/in, 25.4, 1); ``N·m`` → (lbf·in, 1000, 4.448…·25.4)."""
    if units == "mm" or not unit:
        return unit, 1.0, 1.0
    multiply, divide = 1.0, 1.0
    parts = unit.split("/")
    out = []
    for k, part in enumerate(parts):
        names = []
        for token in part.split("·"):
            if token in _INCH_UNITS:
                new, size, scale = _INCH_UNITS[token]  # 1 token = scale·size new
                if k == 0:
                    multiply, divide = multiply / scale, divide * size
                else:
                    multiply, divide = multiply * size, divide / scale
                names.append(new)
            else:
                names.append(token)
        out.append("·".join(names))
    if multiply == divide:  # mm/mm, N·m/(N·m): the same number
        multiply = divide = 1.0
    return "/".join(out), multiply, divide


@dataclass(frozen=True)
class Output:
    """How a table is written: its sign convention and units (``iso``, ``mm``: as the
    Results hold it, the file byte for byte as before)."""

    convention: str = DEFAULT
    units: str = "mm"

    def __post_init__(self):
        if self.convention not in CONVENTIONS:
            known = ", ".join(CONVENTIONS)
            raise ValueError(f"unknown convention {self.convention!r} (known: {known})")
        if self.units not in UNITS:
            raise ValueError(f"unknown units {self.units!r} (known: {', '.join(UNITS)})")

    @property
    def identity(self) -> bool:
        return self.convention == DEFAULT and self.units == "mm"

    def unit(self, unit: str) -> str:
        return unit_conversion(unit, self.units)[0]

    def column_units(self, units: dict) -> dict:
        return {n: self.unit(u) for n, u in units.items()}

    def values(self, name: str, values, unit: str | None):
        """A column's values in this form: sign × ISO's, in these units (a new array;
        names, flags and unitless counts as they are)."""
        if self.identity:
            return values
        import numpy as np

        v = np.asarray(values)
        if v.dtype.kind not in "fiu" or (not unit and not factors(name)):
            return values
        s = sign(name, CONVENTIONS[self.convention])
        _, multiply, divide = unit_conversion(unit or "", self.units)
        if s == 1 and multiply == 1.0 and divide == 1.0:
            return values
        out = v.astype(float)
        if multiply != 1.0:
            out = out * multiply
        if divide != 1.0:
            out = out / divide
        return -out if s < 0 else out

    def header(self) -> str | None:
        """The header comment that names the form (None for iso, mm: the file as before)."""
        if self.identity:
            return None
        c = CONVENTIONS[self.convention]
        units = "lengths in, forces lbf" if self.units == "in" else "lengths mm, forces N"
        return (
            f"# convention: {c.name} ({c.text}); units: {units} "
            "(docs/results.md, Output conventions and units)"
        )

    def metadata(self) -> dict:
        """Parquet schema metadata that names the form ({} for iso, mm)."""
        if self.identity:
            return {}
        return {"convention": self.convention, "output_units": self.units}


ISO_MM = Output()
