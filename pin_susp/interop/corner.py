"""From another tool's points to a pin_susp corner (docs/interop.md).

A reader gives a :class:`Source`: every named point of its file as a
:class:`Found` (its name and line as the file writes them, its position in ISO
axes and mm, the pin_susp point it stands for or ``None``), the mechanism and the
choices the file itself says (a Lotus type line), and the side its points are on.
:func:`build` picks the mechanism's points, mirrors them to the corner's side,
makes the axle points from the wheel centre, takes what the file does not carry
from a template geometry or the options (saying every default it uses), checks
the result with :func:`pin_susp.model.geometry.load_geometry` and returns the
geometry's data with the report of what was used and what was ignored.
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, PinSuspError

WHEEL_CENTER, SPINDLE = "wheel_center", "wheel_spindle"
SPINDLE_SPACING = 50.0  # mm between the axle points made from camber and toe
STEERING_PAIRS = {
    "rack": ("trackrod_inboard", "trackrod_outboard"),
    "none": ("toe_link_inboard", "toe_link_outboard"),
}


@dataclass
class Found:
    """One named point of the file: ``name`` and ``where`` (``line 12``) as the file
    has them, ``xyz`` in ISO axes and mm, ``role`` the pin_susp point it stands for
    (a hardpoint, ``wheel_center`` or ``wheel_spindle``; None: none), ``rank`` its
    precedence among points of one role (0 first), ``why`` the reason it has none."""

    name: str
    where: str
    xyz: np.ndarray
    role: str | None
    rank: int = 0
    why: str = "not a point pin_susp's corner has"


@dataclass
class Source:
    """A file's points and what it says of the corner (see the module's doc)."""

    path: str
    fmt: str  # "Lotus SHARK", ...
    points: list[Found]
    kind: str | None = None  # the mechanism the file names (None: from the points)
    said: dict = field(default_factory=dict)  # actuation, actuation_mount, spring it says
    described: str = ""  # e.g. the Lotus type line, for the report
    camber: float | None = None  # deg, ISO sign, from the file (Adams' parameters)
    toe: float | None = None  # deg, + toe-in
    label: dict = field(default_factory=dict)  # pin_susp point → the file's name for it

    def fail(self, problem: str):
        raise PinSuspError(f"{self.path}: {problem}")


@dataclass
class Wanted:
    """What the file does not carry, from the command line (None: not given)."""

    template: str | None = None
    side: str | None = None
    tyre: tuple[float, float, float] | None = None  # section_width mm, aspect, rim in
    offset: float | None = None  # mm
    steering: str | None = None
    kind: str | None = None
    camber: float | None = None
    toe: float | None = None
    name: str | None = None


def parse_tyre(text: str) -> tuple[float, float, float]:
    """``205/55R16`` (section width mm / aspect % R rim in) → (205, 0.55, 16)."""
    m = re.fullmatch(r"\s*(\d+(?:\.\d+)?)\s*/\s*(\d+(?:\.\d+)?)\s*Z?R\s*(\d+(?:\.\d+)?)\s*", text)
    if not m:
        raise ValueError(f"expected a tyre size such as 205/55R16, got {text!r}")
    return float(m.group(1)), float(m.group(2)) / 100.0, float(m.group(3))


def side_of(points: list[Found]) -> str:
    """The side the file's points are on: the wheel centre's (else the mean y's)."""
    ys = [p.xyz[1] for p in points if p.role == WHEEL_CENTER] or [
        p.xyz[1] for p in points if p.role is not None
    ]
    return "left" if (ys and float(np.mean(ys)) >= 0.0) else "right"


def build(src: Source, want: Wanted) -> tuple[dict, list[str]]:
    """The geometry data of the file's corner and the report's lines (used, ignored,
    defaults). Raises PinSuspError naming the file for a point a corner needs."""
    from ..model import mechanisms
    from ..model.geometry import Options

    notes: list[str] = []
    template = _template(want.template)
    tdata = template.data if template is not None else {}
    kind = _kind(src, want, template, notes)
    mech = mechanisms.get(kind)
    has = {p.role for p in src.points if p.role}
    steering = want.steering or (template.steering if template else None)
    if steering is None:
        steering = (
            "none" if "toe_link_outboard" in has and "trackrod_outboard" not in has else "rack"
        )
        if "none" in mech.STEERING and "rack" in mech.STEERING:
            notes.append(f"default   config.steering.type = {steering} (give --steering)")
    actuation, mount, spring = _choices(src, mech, template, has, notes)
    side = want.side or (template.side if template else None) or _file_side(src)
    file_side = _file_side(src)
    options = Options(kind, side, steering, actuation, mount, spring)
    names = mech.hardpoint_names(options)

    roles = _roles(src, steering)
    chosen: dict[str, Found] = {}
    for p in sorted(src.points, key=lambda p: p.rank):
        role = roles[id(p)]
        if role is None or (role not in names and role not in (WHEEL_CENTER, SPINDLE)):
            continue
        first = chosen.setdefault(role, p)
        if first is not p and first.rank == p.rank and not _same(first, p):
            src.fail(
                f"{p.name!r} ({p.where}) and {first.name!r} ({first.where}) are both "
                f"{role}, at different positions: keep one (or --map the other elsewhere)"
            )
    from_axle = "axle_inboard" in chosen and "axle_outboard" in chosen
    if from_axle:  # the file gives the axle points themselves (a pin_susp-named table)
        chosen.pop(WHEEL_CENTER, None)
        chosen.pop(SPINDLE, None)
    needed = [n for n in names if not (n.startswith("axle_") and not from_axle)]
    needed += [] if from_axle else [WHEEL_CENTER]
    missing = [n for n in needed if n not in chosen]
    if missing:
        said = ", ".join(_label(src, n) for n in missing)
        src.fail(
            f"missing point{'s' if len(missing) > 1 else ''} for a {kind} corner "
            f"({_describe(options)}): {said}"
        )
    _one_side(src, chosen, mech.wheel_side_points(options), file_side)
    flip = np.array([1.0, -1.0 if side != file_side else 1.0, 1.0])
    if side != file_side:
        notes.append(f"mirrored  the file's {file_side} corner to the {side} side (y → −y)")
    hard = {n: chosen[n].xyz * flip for n in names if n in chosen}
    given = [o for o in ("camber", "toe") if getattr(want, o) is not None]
    spin = chosen.get(SPINDLE) or chosen.get("axle_inboard")
    if given and (from_axle or spin is not None):
        src.fail(
            f"--{given[0]}: the file gives the spin axis ({spin.name!r}, {spin.where}): "
            "--camber and --toe are for a file without a spindle point"
        )
    offset = _offset(want, template, from_axle, notes)
    if not from_axle:
        hard.update(_axle(src, chosen, flip, offset, want, side, notes))

    data = {
        "type": kind,
        "scope": "corner",
        "side": side,
        "name": want.name or f"{Path(src.path).stem} (imported from {src.fmt})",
        "units": "millimeters",
    }
    if "actuation" not in mech.FORBIDDEN:
        data["actuation"] = {"type": actuation, "mount": mount}
    if "spring" not in mech.FORBIDDEN:
        data["spring"] = dict(tdata.get("spring") or {}, type=spring)
        if spring == "none":
            data["spring"] = {"type": "none"}
    data["hardpoints"] = {n: [float(v) + 0.0 for v in hard[n]] for n in names}  # no -0.0
    data["config"] = _config(tdata, want, steering, offset, src.path)
    used = {id(chosen[n]): n for n in chosen}
    report = [f"read      {src.path} ({src.fmt}{': ' + src.described if src.described else ''})"]
    report.append(f"corner    {kind}, {side}: {_describe(options)}")
    for p in src.points:
        if id(p) in used:
            report.append(f"used      {p.name} ({p.where}) as {used[id(p)]}")
        else:
            report.append(f"ignored   {p.name} ({p.where}): {_why(p, roles[id(p)], chosen, names)}")
    _check(data, src)
    return data, report + notes


def _same(a: Found, b: Found) -> bool:
    return bool(np.max(np.abs(a.xyz - b.xyz)) <= 1e-9)


def _one_side(src: Source, chosen: dict, wheel_side: tuple, file_side: str) -> None:
    """The points that ride with the wheel are on the file's side (its wheel
    centre's): a sign slip in the file is said in its own names."""
    sign = 1.0 if file_side == "left" else -1.0
    for role in (*wheel_side, SPINDLE):
        p = chosen.get(role)
        if p is not None and sign * p.xyz[1] < 0.0:
            by = chosen.get(WHEEL_CENTER)
            ref = f"its wheel centre {by.name!r} ({by.where})" if by else "most of its points"
            other = "right" if file_side == "left" else "left"
            src.fail(
                f"the file's points are on both sides of the car: {ref} on the {file_side} "
                f"(ISO y {'>' if sign > 0 else '<'} 0), {p.name!r} ({p.where}) on the {other}: "
                "check the signs of y in the file"
            )


def angle_problem(value: float) -> str | None:
    """What is wrong with a static camber or toe (deg), as the wheel-by-centre reader
    says it (pin_susp.model.forms), or None."""
    from ..model.forms import MAX_ANGLE

    if abs(value) > MAX_ANGLE:
        return f"{value:g}° is beyond ±{MAX_ANGLE:g}° (degrees, at design)"
    return None


def _template(path: str | None):
    if path is None:
        return None
    from ..model.geometry import load_geometry
    from ..subjects.subject import is_axle_file, is_vehicle_file

    for whose, test in (("an axle", is_axle_file), ("a car", is_vehicle_file)):
        if test(path):
            raise PinSuspError(
                f"--template {path}: is {whose}'s file; the template must be a corner file "
                "(a double_wishbone or macpherson corner, e.g. examples/double_wishbone.yaml)"
            )

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_geometry(path)


def _file_side(src: Source) -> str:
    return side_of(src.points)


def _kind(src: Source, want: Wanted, template, notes: list[str]) -> str:
    from ..model import mechanisms

    kind = want.kind or (template.type if template else None)
    if src.kind is not None:
        if kind is not None and kind != src.kind:
            by = f"--type {kind}" if want.kind else f"the template is a {kind} corner"
            src.fail(f"the file's type line says a {src.kind} corner ({src.described}); {by}")
        return src.kind
    if kind is None:
        has = {p.role for p in src.points}
        kind = (
            "macpherson"
            if "strut_top" in has and "upper_wishbone_outboard" not in has
            else "double_wishbone"
        )
        notes.append(f"default   type = {kind} (from the points; give --type)")
    if kind not in ("double_wishbone", "macpherson"):
        src.fail(f"--type {kind}: these files are read as double_wishbone or macpherson corners")
    assert kind in mechanisms.NAMES
    return kind


def _choices(src: Source, mech, template, has: set, notes: list[str]) -> tuple[str, str, str]:
    """actuation, its mount and the spring: the template's, else what the file says,
    else from the points it has."""
    if template is not None:
        return template.actuation, template.actuation_mount, template.spring
    said = src.said
    actuation = said.get("actuation") or (
        "pushrod_rocker"
        if "pushrod_outboard" in has and "pushrod_rocker" in mech.ACTUATION
        else "direct"
    )
    mount = said.get("actuation_mount")
    if mount is None:
        mount = mech.MOUNTS[0]
        if len(mech.MOUNTS) > 1 and ("pushrod_outboard" in has or "strut_bottom" in has):
            notes.append(f"default   actuation.mount = {mount} (give --template to choose)")
    spring = said.get("spring")
    if spring is None:
        spring = (
            "coilover"
            if {"strut_top", "strut_bottom"} <= has and "coilover" in mech.SPRINGS
            else mech.SPRINGS[0]
        )
    return actuation, mount, spring


def _roles(src: Source, steering: str) -> dict[int, str | None]:
    """Each point's pin_susp point for this corner: a trackrod's ends are a toe link's
    where the steering is none, and the other way round."""
    other = STEERING_PAIRS["none" if steering == "rack" else "rack"]
    rename = dict(zip(other, STEERING_PAIRS[steering], strict=True))
    return {id(p): rename.get(p.role, p.role) for p in src.points}


def _label(src: Source, name: str) -> str:
    theirs = src.label.get(name)
    return f"{theirs!r} ({name})" if theirs and theirs != name else name


def _describe(o) -> str:
    parts = [f"steering {o.steering}"]
    if o.type == "double_wishbone":
        parts += [f"actuation {o.actuation} on the {o.actuation_mount}", f"spring {o.spring}"]
    return ", ".join(parts)


def _why(p: Found, role: str | None, chosen: dict, names: tuple) -> str:
    if role is None:
        return p.why
    if role in chosen:
        same = " at the same position" if _same(p, chosen[role]) else ""
        return f"{role} is given by {chosen[role].name!r} ({chosen[role].where}){same}"
    if role.startswith("axle_") or role in (WHEEL_CENTER, SPINDLE):
        return "the axle points are given as axle_inboard/axle_outboard"
    return (
        f"{role} is not a point of this corner ({p.why})"
        if p.why != Found.why
        else (f"{role} is not a point of this corner")
    )


def _offset(want: Wanted, template, from_axle: bool, notes: list[str]) -> float:
    if want.offset is not None:
        return want.offset
    if template is not None:
        return template.wheel.offset * 1000.0
    if not from_axle:
        notes.append(
            "default   config.wheel.offset = 0 mm: axle_outboard (the hub face) is the "
            "wheel centre (the file has no hub face; give --offset)"
        )
    return 0.0


def _axle(src: Source, chosen: dict, flip, offset: float, want: Wanted, side: str, notes) -> dict:
    """axle_inboard/axle_outboard from the wheel centre and the spindle point, or
    from the static camber and toe where the file has no spindle point."""
    sign = 1.0 if side == "left" else -1.0
    wc = chosen[WHEEL_CENTER].xyz * flip
    if SPINDLE in chosen:
        spindle = chosen[SPINDLE].xyz * flip
        d = spindle - wc
        length = float(np.linalg.norm(d))
        if length < 1e-6 or abs(d[1]) < 1e-9:
            src.fail(
                f"{chosen[SPINDLE].name!r} ({chosen[SPINDLE].where}): coincides with the wheel "
                "centre or lies beside it in its plane: the spin axis needs a point along it"
            )
        axis = d / length if sign * d[1] > 0 else -d / length  # outboard
        outboard = wc + offset * axis
        inboard = spindle if np.dot(spindle - outboard, axis) < 0 else outboard - length * axis
        return {"axle_inboard": inboard, "axle_outboard": outboard}
    camber = want.camber if want.camber is not None else src.camber
    toe = want.toe if want.toe is not None else src.toe
    for what, value in (("camber", camber), ("toe", toe)):
        if value is None:
            notes.append(
                f"default   static {what} = 0 deg (the file has no spindle point; give --{what})"
            )
        elif getattr(want, what) is None:
            notes.append(
                f"from file static {what} = {value:g} deg (the spin axis: no spindle point)"
            )
    from ..model.forms import spin_axis  # the wheel-by-centre form's axis, the same camber

    axis = spin_axis(camber or 0.0, toe or 0.0, sign)
    outboard = wc + offset * axis
    return {"axle_inboard": outboard - SPINDLE_SPACING * axis, "axle_outboard": outboard}


def _config(tdata: dict, want: Wanted, steering: str, offset: float, path: str) -> dict:
    config = dict(tdata.get("config") or {})
    config["steering"] = dict(config.get("steering") or {}, type=steering)
    wheel = dict(config.get("wheel") or {})
    for key in ("center", "static_camber", "static_toe"):  # the axle points say the wheel
        wheel.pop(key, None)
    wheel["offset"] = offset
    if want.tyre is not None:
        section, aspect, rim = want.tyre
        wheel.pop("tire", None)
        old = dict(wheel.pop("tyre", None) or {})
        wheel["tyre"] = {"aspect_ratio": aspect, "section_width": section, "rim_diameter": rim}
        if "rate" in old:
            wheel["tyre"]["rate"] = old["rate"]
    elif "tyre" not in wheel and "tire" not in wheel:
        raise PinSuspError(
            f"{path}: the tyre: the file does not give its size; give --tyre 205/55R16 "
            "(section width mm / aspect % R rim in) or --template GEOMETRY.yaml"
        )
    config["wheel"] = wheel
    return config


def _check(data: dict, src: Source) -> None:
    """The corner loads as pin_susp reads it; a problem is said against the file."""
    from ..model.geometry import load_geometry

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            load_geometry(data)
    except InputError as exc:
        src.fail(f"its points make no corner pin_susp can use: {exc.key}: {exc.problem}")


def yaml_text(data: dict, report: list[str]) -> str:
    """The geometry file: a header saying where it came from, the hardpoints one
    line each as [x, y, z] (the shortest text that reads back as the same float)."""
    import yaml

    head = {k: v for k, v in data.items() if k not in ("hardpoints", "config")}
    lines = ["# written by pin-susp import (docs/interop.md); ISO 8855 axes, mm", f"# {report[0]}"]
    lines.append(
        yaml.safe_dump(head, sort_keys=False, default_flow_style=False, width=1000).rstrip()
    )
    lines.append("hardpoints:")
    for name, xyz in data["hardpoints"].items():
        lines.append(f"  {name}: [{', '.join(repr(float(v)) for v in xyz)}]")
    config = yaml.safe_dump(
        {"config": data["config"]}, sort_keys=False, default_flow_style=None, width=1000
    )
    return "\n".join(lines) + "\n" + config


def corner_points(g) -> dict[str, np.ndarray]:
    """What an export writes of the corner ``g`` (mm, ISO): its hardpoints but the
    axle points, then the spindle point (axle_inboard) and the wheel centre."""
    from ..model.geometry import to_mm

    if g.type not in ("double_wishbone", "macpherson"):
        raise PinSuspError(
            f"{g.source}: type {g.type}: these formats carry double_wishbone and macpherson corners"
        )
    hp = g.hardpoints_mm
    points = {n: hp[n] for n in g.mechanism.hardpoint_names(g) if not n.startswith("axle_")}
    points[SPINDLE] = hp["axle_inboard"]
    points[WHEEL_CENTER] = to_mm(g.design_points()["wheel_center"])
    return points
