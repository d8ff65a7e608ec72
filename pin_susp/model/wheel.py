"""The wheel: its tyre and offset read from ``config.wheel`` (docs/geometry.md, "The
tyre: one key"), and the points it derives from the spindle (wheel centre, wheel
planes, contact patch: docs/geometry.md, "Derived points"). SI units (m) once read.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..io.yamlio import MAX_LENGTH_MM, Reader
from ..maths.vectors import unit
from .units import INCH, MM

TYRE_SIZE = ("aspect_ratio", "section_width", "rim_diameter")  # the sidewall's code
TYRE_DIAMETER = ("diameter", "width")  # or the tyre by its diameter and width (mm)
TYRE_KEYS = (*TYRE_SIZE, *TYRE_DIAMETER, "loaded_radius", "rate")
# the wheel-centre form's keys (pin_susp.model.forms), gone once it is read
CENTRE_KEYS = ("center", "static_camber", "static_toe")


@dataclass(frozen=True)
class Wheel:
    """Wheel offset and tyre, in metres: the tyre's size (section width, aspect ratio,
    rim diameter) or its ``diameter`` (then aspect ratio and rim diameter are None), and
    its ``loaded_radius`` (None: the unloaded radius)."""

    offset: float
    section_width: float
    aspect_ratio: float | None
    rim_diameter: float | None
    tyre_rate: float | None = None  # N/mm (config.wheel.tyre.rate), for the ride rate
    # each size's key as the file wrote it (tyre: or its synonym tire:), for warnings
    keys: dict = field(default_factory=dict, compare=False, repr=False)
    diameter: float | None = None
    loaded_radius: float | None = None

    def key(self, name: str) -> str:
        alias = "width" if name == "section_width" and "width" in self.keys else name
        return self.keys.get(alias, f"config.wheel.tyre.{name}")

    @property
    def unloaded_radius(self) -> float:
        """diameter / 2, or from the size: (rim + 2·aspect·section) / 2."""
        if self.diameter is not None:
            return 0.5 * self.diameter
        return 0.5 * self.rim_diameter + self.aspect_ratio * self.section_width

    @property
    def radius(self) -> float:
        """The contact patch's distance from the wheel centre in the wheel plane: the
        loaded radius where given, else the unloaded one."""
        return self.unloaded_radius if self.loaded_radius is None else self.loaded_radius


def wheel_points(
    axle_inboard: np.ndarray, axle_outboard: np.ndarray, wheel: Wheel
) -> dict[str, np.ndarray]:
    """Derived points fixed to the upright: works on (3,) or (n, 3) arrays.

    â = unit(axle_outboard − axle_inboard); wheel_center = axle_outboard − offset·â;
    wheel_inboard/outboard = wheel_center ∓ (section_width/2)·â; the contact
    patch centre is added too (it is not fixed to the upright).
    """
    a = unit(axle_outboard - axle_inboard)
    center = axle_outboard - wheel.offset * a
    half = 0.5 * wheel.section_width * a
    return {
        "axle_midpoint": 0.5 * (axle_inboard + axle_outboard),
        "wheel_center": center,
        "wheel_inboard": center - half,
        "wheel_outboard": center + half,
        "contact_patch_center": contact_patch(center, a, wheel.radius),
    }


def wheel_down(spin_axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """d̂ = unit(−Ẑ − ((−Ẑ)·â)â) and the length of the vector before normalising.

    World down projected into the wheel plane; the contact patch is R·d̂ from
    the wheel centre. Works on (3,) or (n, 3), and on jet.Dual points.
    """
    a = spin_axis
    u = a * a[..., 2:3] - np.array([0.0, 0.0, 1.0])
    norm = np.linalg.norm(u, axis=-1, keepdims=True)
    return u / norm, norm


def contact_patch(wheel_center: np.ndarray, spin_axis: np.ndarray, radius: float) -> np.ndarray:
    """Lowest point of a thin disc of radius R in the wheel plane."""
    down, _ = wheel_down(spin_axis)
    return wheel_center + radius * down


def read_wheel(value, r: Reader) -> Wheel:
    """config.wheel: its offset and the tyre — one key, ``tyre:`` (``tire:`` read as its
    synonym) with the size or the diameter and width, the loaded radius and the rate.
    A file may still split them between the two (the size under tire:, the rate under
    tyre:, as before): they are read as one, and a value given under both is an error
    that names each."""
    w = r.mapping(value, "config.wheel", optional=("offset", "tyre", "tire"))
    given = [k for k in ("tyre", "tire") if k in w]
    if not given:
        r.fail(
            "config.wheel.tire",
            "missing key: the tyre, as tire: or tyre: (one key, either spelling) with its "
            "size {aspect_ratio, section_width, rim_diameter} or {diameter, width} and, for "
            "the ride rate, its rate",
        )
    tyre, keys = {}, {}
    for name in given:
        block = r.mapping(w[name], f"config.wheel.{name}", optional=TYRE_KEYS)
        for k, v in block.items():
            if k in tyre:
                r.fail(
                    f"config.wheel.{name}.{k}",
                    f"given also as {keys[k]}: tire: is a synonym of tyre:, one tyre — "
                    "give each value once (best all under tyre:)",
                )
            tyre[k], keys[k] = v, f"config.wheel.{name}.{k}"
    by_diameter = any(k in tyre for k in TYRE_DIAMETER)
    sizes = TYRE_DIAMETER if by_diameter else TYRE_SIZE
    if by_diameter and any(k in tyre for k in TYRE_SIZE):
        k = next(k for k in TYRE_SIZE if k in tyre)
        r.fail(
            keys[k],
            f"given with {keys[next(d for d in TYRE_DIAMETER if d in tyre)]}: the tyre is "
            f"either its size ({', '.join(TYRE_SIZE)}) or its diameter and width, not both",
        )
    for k in sizes:
        if k not in tyre:
            holder = next((n for n in given if any(s in w[n] for s in sizes)), given[0])
            other = {"tyre": "tire", "tire": "tyre"}[holder]
            r.fail(
                f"config.wheel.{holder}.{k}",
                f"missing key (the tyre's {'diameter and width' if by_diameter else 'size'}: "
                f"{', '.join(sizes)}; {other}: is the same key, read as one with {holder}:)",
            )
    tyre_rate = None if "rate" not in tyre else r.positive(tyre["rate"], keys["rate"])
    if by_diameter:
        shape = {
            "section_width": size(tyre["width"], keys["width"], r) * MM,
            "aspect_ratio": None,
            "rim_diameter": None,
            "diameter": size(tyre["diameter"], keys["diameter"], r) * MM,
        }
    else:
        shape = {
            "section_width": size(tyre["section_width"], keys["section_width"], r) * MM,
            "aspect_ratio": size(tyre["aspect_ratio"], keys["aspect_ratio"], r, limit=100.0),
            "rim_diameter": size(tyre["rim_diameter"], keys["rim_diameter"], r, INCH / MM) * INCH,
        }
    wheel = Wheel(
        offset=r.length(w.get("offset", 0.0), "config.wheel.offset") * MM,
        tyre_rate=tyre_rate,
        keys=keys,
        **shape,
    )
    if "loaded_radius" not in tyre:
        return wheel
    key = keys["loaded_radius"]
    loaded = size(tyre["loaded_radius"], key, r) * MM
    if loaded > wheel.unloaded_radius:
        r.fail(
            key,
            f"{loaded / MM:g} mm is more than the unloaded radius, "
            f"{wheel.unloaded_radius / MM:g} mm (a loaded tyre is squashed, not stretched)",
        )
    return Wheel(**{**wheel.__dict__, "loaded_radius": loaded})


def size(value, key: str, r: Reader, per_mm: float = 1.0, limit: float | None = None) -> float:
    """A size > 0 within the hard limit on lengths (``per_mm``: mm per unit of the value)."""
    x = r.positive(value, key)
    limit = MAX_LENGTH_MM / per_mm if limit is None else limit
    if x > limit:
        r.fail(key, f"{x:g} is beyond the hard limit of {limit:g} for any car")
    return x
