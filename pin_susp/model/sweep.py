"""Sweep file → targets per step (docs/sweep.md).

A sweep speaks the file's units: target values in mm. Targets are paired by
index (step i uses value i of every target), not a Cartesian product.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..io.yamlio import Reader, load_yaml, short_repr
from .geometry import direction
from .units import read_units

# Memory a solved step holds while a sweep is held whole (configuration, tangents,
# every column, the CSV's text), bytes: measured 12.5 KB on a 200 000-step sweep.
BYTES_PER_STEP = 12_500
# A streamed sweep (pin-susp sweep to a file, Corner.run_sweep_chunks) holds only its
# targets' values and what its summary needs, per step.
STREAMED_BYTES_PER_STEP = 100

AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
QUANTITIES = ("heave", "roll")  # an axle's own targets: heave mm, roll deg
# a vehicle's (docs/vehicle.md): the body's pitch (deg), a corner's road height (mm,
# ``corner:``), the steering wheel (deg)
VEHICLE_QUANTITIES = ("pitch", "road_z", "steering_wheel", "rack")
CORNERS = ("fl", "fr", "rl", "rr")  # a vehicle's corners
LENGTH_TARGETS = (None, "heave", "road_z", "rack")  # a point's (None) and these: mm


@dataclass(frozen=True)
class Target:
    """Hold ``point`` at ``values`` (mm) along ``direction`` ("x", "y", "z" or a vector).

    ``mode="relative"`` adds each value to the point's design position along
    the direction; ``"absolute"`` takes it as a world coordinate.
    """

    point: str | None
    direction: str | Sequence[float] | None
    values: float | Sequence[float] = 0.0
    mode: str = "relative"
    side: str | None = None  # left | right: which corner of an axle
    quantity: str | None = None  # heave (mm) | roll (deg): an axle quantity, not a point

    def __post_init__(self):
        object.__setattr__(self, "values", np.atleast_1d(np.asarray(self.values, dtype=float)))

    @property
    def unit_direction(self) -> np.ndarray:
        if self.direction is None:
            return np.zeros(3)
        if isinstance(self.direction, str):
            return np.array(AXES[self.direction])
        return direction(self.direction)

    @property
    def key(self) -> tuple:
        """(point, unit direction[, side]) or the quantity: what the target holds,
        however it was written."""
        if self.quantity is not None:
            return (self.quantity,) if self.side is None else (self.quantity, self.side)
        key = (self.point, tuple(self.unit_direction.tolist()))
        return key if self.side is None else (*key, self.side)

    def at_design(self) -> Target:
        """The same target holding the point where it is at the design state."""
        return replace(self, values=0.0, mode="relative")


@dataclass(frozen=True)
class Sweep:
    targets: list[Target]
    source: str = "<dict>"
    sha256: str | None = None
    data: dict = field(default_factory=dict, repr=False)

    @property
    def steps(self) -> int:
        return len(self.targets[0].values)


def load_sweep(source: str | Path | dict) -> Sweep:
    """Read and validate a sweep file (path) or an already-loaded dict."""
    data, name, sha = load_yaml(source)
    r = Reader(name)
    r.mapping(data, "", required=("targets",), optional=("version", "steps", "name", "units"))
    length = read_units(data, r).length  # mm per unit of the file's lengths
    steps = None
    if "steps" in data:
        steps = data["steps"]
        if isinstance(steps, float) and steps.is_integer():  # 1e3 written for 1000
            steps = int(steps)
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            r.fail("steps", f"expected a whole number >= 1, got {short_repr(steps)}")
        _check_memory(steps, r)
    raw_targets = data["targets"]
    if not isinstance(raw_targets, list) or not raw_targets:
        r.fail("targets", "expected a non-empty list of targets")
    targets = [_target(t, f"targets[{i}]", steps, r) for i, t in enumerate(raw_targets)]
    if length != 1.0:  # a point's or a length quantity's values in mm (angles stay deg)
        targets = [
            replace(t, values=t.values * length) if t.quantity in LENGTH_TARGETS else t
            for t in targets
        ]
    lengths = {len(t.values) for t in targets}
    if len(lengths) > 1:
        detail = ", ".join(f"targets[{i}]: {len(t.values)}" for i, t in enumerate(targets))
        r.fail("targets", f"every target needs the same number of values ({detail})")
    return Sweep(targets, name, sha, data)


def _target(value, key: str, steps: int | None, r: Reader) -> Target:
    if isinstance(value, dict) and "quantity" in value:  # an axle's heave or roll
        t = r.mapping(
            value, key, required=("quantity",), optional=("start", "stop", "values", "corner")
        )
        quantity = r.choice(t["quantity"], f"{key}.quantity", QUANTITIES + VEHICLE_QUANTITIES)
        corner = None
        if quantity == "road_z":
            if "corner" not in t:
                r.fail(f"{key}.corner", "missing: road_z names its corner (fl, fr, rl, rr)")
            corner = r.choice(t["corner"], f"{key}.corner", CORNERS)
        elif "corner" in t:
            r.fail(f"{key}.corner", f"only road_z names a corner, not {quantity}")
        values = _values(t, key, steps, r)
        return Target(None, None, values, "relative", side=corner, quantity=quantity)
    t = r.mapping(
        value,
        key,
        required=("point", "direction"),
        optional=("mode", "start", "stop", "values", "side"),
    )
    point = r.text(t["point"], f"{key}.point")
    sides = ("left", "right", *CORNERS)
    side = None if "side" not in t else r.choice(t["side"], f"{key}.side", sides)
    d = r.mapping(t["direction"], f"{key}.direction", optional=("axis", "vector"))
    if ("axis" in d) == ("vector" in d):
        r.fail(f"{key}.direction", "give exactly one of axis: x|y|z or vector: [x, y, z]")
    if "axis" in d:
        along = r.choice(d["axis"], f"{key}.direction.axis", tuple(AXES))
    else:
        along = r.vector(d["vector"], f"{key}.direction.vector")
        if direction(along) is None:
            r.fail(f"{key}.direction.vector", "is the zero vector (it needs a direction)")
        along = tuple(along.tolist())
    mode = r.choice(t.get("mode", "relative"), f"{key}.mode", ("relative", "absolute"))
    return Target(point, along, _values(t, key, steps, r), mode, side)


def _values(t: dict, key: str, steps: int | None, r: Reader):
    """A target's values: a list, or start/stop over the sweep's steps (mm, or deg for
    roll)."""
    if "values" in t:
        if "start" in t or "stop" in t:
            r.fail(key, "give either values or start/stop, not both")
        raw = t["values"]
        if not isinstance(raw, list) or not raw:
            r.fail(f"{key}.values", "expected a non-empty list of numbers (mm)")
        values = [r.length(v, f"{key}.values[{i}]") for i, v in enumerate(raw)]
        if steps is not None and len(values) != steps:
            r.fail(f"{key}.values", f"has {len(values)} values but steps is {steps}")
    else:
        for end in ("start", "stop"):
            if end not in t:
                r.fail(f"{key}.{end}", "missing key (or give values: [...])")
        if steps is None:
            r.fail("steps", "missing key (start/stop targets need the number of steps)")
        start = r.length(t["start"], f"{key}.start")
        stop = r.length(t["stop"], f"{key}.stop")
        values = np.linspace(start, stop, steps)
    return values


def _check_memory(steps: int, r: Reader) -> None:
    """Refuse a sweep that cannot be run even streamed, before allocating any."""
    problem = _too_big(steps, STREAMED_BYTES_PER_STEP)
    if problem:
        r.fail("steps", problem + ": split the sweep into several files")


def check_held(sweep: Sweep) -> None:
    """Refuse a sweep whose results cannot be held whole in memory (one clear message
    instead of running out of memory part-way): a long one is streamed instead."""
    problem = _too_big(sweep.steps, BYTES_PER_STEP)
    if problem:
        raise InputError(
            sweep.source,
            "steps",
            f"{problem} to hold every step at once: split the sweep into several files "
            "(a corner's `pin-susp sweep` without --plot writes it as it goes)",
        )


def _too_big(steps: int, per_step: int) -> str:
    need = float(min(steps, 10**30)) * per_step
    have = _available_memory()
    if need <= 0.5 * have:
        return ""
    return (
        f"{steps} steps need about {_bytes(need)} of memory, more than half of the "
        f"{_bytes(have)} available here"
    )


def _available_memory() -> int:
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # not on Linux: assume a small machine
        return 8 << 30


def _bytes(n: float) -> str:
    for unit in ("B", "KB", "MB", "GB", "TB"):
        if n < 1000:
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"
