"""The attitude's inputs (docs/vehicle.md, "Attitude"): an accelerations file — a list
of steady (ax, ay) in g, or a grid of them — and what the attitude needs of a vehicle
file beyond its sweep's: ``vehicle_config.masses`` and the tyres' rates, each problem
one message naming the file and the key.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..io.yamlio import Reader, load_yaml

ENDS = {"front": ("fl", "fr"), "rear": ("rl", "rr")}
MOST = 20_000  # accelerations in one file


@dataclass(frozen=True)
class Accelerations:
    """A list of steady accelerations (ax, ay), g: ISO 8855, ax + forward, ay + left."""

    ax: np.ndarray
    ay: np.ndarray
    source: str = "<dict>"
    sha256: str | None = None

    def __len__(self) -> int:
        return len(self.ax)


def load_accelerations(source) -> Accelerations:
    """Read an accelerations file (docs/vehicle.md): ``accelerations:`` a list of
    ``{ax, ay}`` in g, and/or ``grid: {ax: {start, stop, steps}, ay: {...}}`` (every
    pair, ay the faster). Errors name the file and the key."""
    data, name, sha = load_yaml(source)
    r = Reader(name)
    r.mapping(data, "", optional=("version", "name", "accelerations", "grid"))
    if "accelerations" not in data and "grid" not in data:
        r.fail("accelerations", "give a list of {ax, ay} (g), or a grid of them")
    ax, ay = [], []
    given = data.get("accelerations", [])
    if not isinstance(given, list):
        r.fail("accelerations", "expected a list of {ax, ay} (g)")
    for i, a in enumerate(given):
        key = f"accelerations[{i}]"
        r.mapping(a, key, optional=("ax", "ay"))
        ax.append(_g(r, a.get("ax", 0.0), f"{key}.ax"))
        ay.append(_g(r, a.get("ay", 0.0), f"{key}.ay"))
    if "grid" in data:
        grid = r.mapping(data["grid"], "grid", required=("ax", "ay"))
        axes = []
        for axis in ("ax", "ay"):
            key = f"grid.{axis}"
            spec = r.mapping(grid[axis], key, required=("start", "stop", "steps"))
            steps = spec["steps"]
            if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= 1000:
                r.fail(f"{key}.steps", f"expected a whole number from 1 to 1000, got {steps!r}")
            start = _g(r, spec["start"], f"{key}.start")
            stop = _g(r, spec["stop"], f"{key}.stop")
            axes.append(np.linspace(start, stop, steps))
        X, Y = np.meshgrid(*axes, indexing="ij")
        ax += list(X.ravel())
        ay += list(Y.ravel())
    if not ax:
        r.fail("accelerations", "the list is empty")
    if len(ax) > MOST:
        r.fail(
            "grid" if "grid" in data else "accelerations",
            f"{len(ax):,} accelerations: at most {MOST:,} (about 10 ms each)",
        )
    return Accelerations(np.array(ax, dtype=float), np.array(ay, dtype=float), name, sha)


def _g(r: Reader, value, key: str) -> float:
    """An acceleration in g: a number within ±5 g."""
    v = r.number(value, key)
    if abs(v) > 5.0:
        r.fail(key, f"{v:g} g is beyond any car's grip (within ±5 g)")
    return v


def masses_of(v) -> dict:
    """The masses the attitude needs of ``vehicle_config.masses`` (their values checked
    as the file was read: vehicle_file.py): the sprung mass and each corner's unsprung
    one, kg (``unsprung``: corner → kg; ``total``), the roll inertia or None."""
    m, r, key = v.masses, Reader(v.source), "vehicle_config.masses"
    for name in ("sprung", *(f"unsprung_{end}" for end in ENDS)):
        if name not in m:
            r.fail(f"{key}.{name}", "missing key: the attitude needs the sprung mass and each "
                   "axle's unsprung mass per corner (kg)")  # fmt: skip
    out = {"sprung": float(m["sprung"]), "roll_inertia": m.get("sprung_roll_inertia")}
    out["unsprung"] = {c: float(m[f"unsprung_{end}"]) for end, cs in ENDS.items() for c in cs}
    out["total"] = out["sprung"] + sum(out["unsprung"].values())
    return out


def tyre_rates_of(v) -> np.ndarray | None:
    """``vehicle_config.tyres``: ``{vertical: N/mm}`` or per axle ``{front: {vertical},
    rear: {vertical}}``; N/m per corner, None for rigid tyres."""
    t = v.tyres
    if t is None:
        return None
    return np.array([t[c[0]] for c in ("fl", "fr", "rl", "rr")]) * 1e3


def check_splits(v, ax: np.ndarray) -> None:
    """Braking (ax < 0) needs the brakes' front share, driving (ax > 0) the drive's
    split (``v``: a VehicleGeometry): without them the tyres' longitudinal forces are
    unknown — an InputError naming the key, not a car that neither brakes nor drives."""
    if np.any(ax < 0) and v.front_bias is None:
        raise InputError(
            v.source,
            "vehicle_config.brakes.front_bias",
            "braking (ax < 0) needs the brakes' front share (0…1)",
        )
    if np.any(ax > 0) and v.drive_split is None:
        raise InputError(
            v.source,
            "vehicle_config.drive",
            "accelerating (ax > 0) needs the drive's split (front, rear: shares adding to 1)",
        )
