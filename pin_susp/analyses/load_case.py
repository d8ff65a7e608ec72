"""Load-case files (docs/loads.md): the loads on each wheel, world (chassis) axes —
a force at the contact patch, a force at the wheel centre, a moment — one case a
row of ``pin-susp loads``' table; a corner's at each case's top, each of an axle's
or a vehicle's corners in a block of its label's name (``left:``, ``right:``; ``fl:``,
...). A subject on the road (a vehicle) also takes a steady acceleration, ``{ax, ay}``
in g: the attitude's forces at that acceleration (docs/vehicle.md, "Loads")."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..io.yamlio import Reader, load_yaml
from ..model.units import Units, read_units

CASE_KEYS = ("contact_patch", "wheel_center", "moment")
SIDES = ("left", "right")  # an axle's corners: a block of loads each
ACCELERATION_KEYS = ("ax", "ay")  # g: a vehicle's case as a steady acceleration
MAX_ACCELERATION = 10.0  # g: beyond any car's steady acceleration (a unit mistake)


@dataclass(frozen=True)
class LoadCase:
    """Loads on one wheel, world (chassis) axes: force at the contact patch (N, the
    road on the tyre), force at the wheel centre (N) and a moment (N·m)."""

    name: str
    contact_patch: np.ndarray
    wheel_center: np.ndarray
    moment: np.ndarray

    def wheel(self, label: str) -> LoadCase:
        """The loads on a corner's wheel by its label: a corner's one (``""``)."""
        return self


@dataclass(frozen=True)
class AxleLoadCase:
    """An axle's load case: one LoadCase per wheel (a side not given: no load)."""

    name: str
    left: LoadCase
    right: LoadCase

    def wheel(self, label: str) -> LoadCase:
        """The loads on the wheel of the corner labelled ``left`` or ``right``."""
        return getattr(self, label)


@dataclass(frozen=True)
class CornersLoadCase:
    """A load case of a subject with more labelled corners than an axle's two (a
    vehicle's ``fl``, ``fr``, ``rl``, ``rr``): one LoadCase per wheel (a corner not
    given: no load)."""

    name: str
    wheels: dict

    def wheel(self, label: str) -> LoadCase:
        """The loads on the wheel of the corner labelled ``label``."""
        return self.wheels[label]


@dataclass(frozen=True)
class AccelerationCase:
    """A vehicle's load case given as a steady acceleration (g, ISO 8855: ax + forward,
    ay + left): at each step, the forces of the attitude's equilibrium at (ax, ay) on
    each wheel (analyses/road_loads.py, docs/vehicle.md)."""

    name: str
    ax: float
    ay: float


def load_cases(
    source,
    axle: bool = False,
    labels: tuple[str, ...] | None = None,
    accelerations: bool = False,
) -> list:
    """Read a load-case file (docs/loads.md): ``cases:`` a list of {name,
    contact_patch: {fx, fy, fz}, wheel_center: {…}, moment: {mx, my, mz}}. The loads
    are per corner of the subject whose ``labels`` are given (default: an axle's
    ``left``, ``right`` with ``axle``, else a corner's ``""``): a corner labelled ``""``
    has them at the case's top, each labelled one in a block of its label's name.
    ``accelerations``: a case may instead be ``{name, ax, ay}`` (g; a vehicle's, a
    subject on the road: an AccelerationCase)."""
    labels = (SIDES if axle else ("",)) if labels is None else tuple(labels)
    blocks = tuple(label for label in labels if label)  # the corners named in the file
    who = "an axle's" if blocks == SIDES else "a vehicle's"  # whose cases name blocks
    listed = " and ".join(", ".join(f"{b}:" for b in blocks).rsplit(", ", 1))
    steady = ACCELERATION_KEYS if accelerations else ()
    data, name, _ = load_yaml(source)
    r = Reader(name)
    r.mapping(data, "", required=("cases",), optional=("version", "units", "force_units"))
    u = read_units(data, r)  # forces N or lbf, moments N·m or lbf·in (no lengths yet)
    if "version" in data and data["version"] != 1:
        r.fail("version", f"expected 1 (this file format's version), got {data['version']!r}")
    cases = data["cases"]
    if not isinstance(cases, list) or not cases:
        r.fail("cases", "expected a list of load cases")
    out, seen = [], set()
    for i, case in enumerate(cases):
        key = f"cases[{i}]"
        if not blocks and isinstance(case, dict):
            for side in SIDES:
                if side in case:
                    r.fail(f"{key}.{side}", "a side block is for an axle's load cases")
        r.mapping(case, key, required=("name",), optional=(*CASE_KEYS, *blocks, *steady))
        title = str(r.text(case["name"], f"{key}.name")).strip()
        if not title:
            r.fail(f"{key}.name", "empty: name the case")
        if title in seen:
            r.fail(f"{key}.name", f"{title!r} names two cases")
        seen.add(title)
        if any(k in case for k in steady):
            out.append(_acceleration(case, key, title, (*CASE_KEYS, *blocks), r))
            continue
        if not blocks:
            out.append(_wheel_loads(case, key, title, r, u))
            continue
        for part in CASE_KEYS:
            if part in case:
                r.fail(f"{key}.{part}", f"{who} loads go in {listed} blocks")
        if not any(b in case for b in blocks):
            either = " or ".join(", ".join(f"{b}:" for b in blocks).rsplit(", ", 1))
            also = " (or ax and ay, g: a steady acceleration)" if steady else ""
            r.fail(key, f"{who} case needs a {either} block of loads{also}")
        wheels = {
            b: _wheel_loads(r.mapping(case.get(b, {}), f"{key}.{b}", optional=CASE_KEYS),
                            f"{key}.{b}", str(title), r, u)
            for b in blocks
        }  # fmt: skip
        if blocks == SIDES:
            out.append(AxleLoadCase(str(title), **wheels))
        else:
            out.append(CornersLoadCase(str(title), wheels))
    return out


def _acceleration(case: dict, key: str, title: str, others: tuple, r: Reader) -> AccelerationCase:
    """A steady acceleration's case: ax and ay (g, each 0 unless given), no wheel's loads."""
    for part in others:
        if part in case:
            r.fail(
                f"{key}.{part}",
                "a case is either a steady acceleration (ax, ay) or loads on the wheels, not both",
            )
    values = []
    for name in ACCELERATION_KEYS:
        x = r.number(case.get(name, 0.0), f"{key}.{name}")
        if abs(x) > MAX_ACCELERATION:
            r.fail(f"{key}.{name}", f"{x:g} g is beyond {MAX_ACCELERATION:g} g: no car holds that")
        values.append(float(x))
    return AccelerationCase(title, *values)


def _wheel_loads(case: dict, key: str, title: str, r: Reader, u: Units) -> LoadCase:
    """One wheel's loads: each block given in full (a block left out: no such load)."""
    vectors = {}
    for part, axes in (("contact_patch", "f"), ("wheel_center", "f"), ("moment", "m")):
        names = tuple(f"{axes}{a}" for a in "xyz")
        given = part in case
        block = r.mapping(
            case.get(part, {}), f"{key}.{part}", required=names if given else (), optional=names
        )
        vectors[part] = np.array([_load(block.get(n, 0.0), f"{key}.{part}.{n}", r) for n in names])
        vectors[part] = vectors[part] * (u.moment if axes == "m" else u.force)  # N, N·m
    return LoadCase(title, **vectors)


MAX_LOAD = 1e7  # N and N·m: far beyond any wheel's (a unit mistake, or a typo)


def _load(value, key: str, r: Reader) -> float:
    x = r.number(value, key)
    if abs(x) > MAX_LOAD:
        r.fail(key, f"{x:g} is beyond {MAX_LOAD:g} (N, N·m): no wheel carries that")
    return x
