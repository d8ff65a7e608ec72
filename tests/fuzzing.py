"""Property-based fuzzing of the ``pin-susp`` command line: strategies and invariants.

``cases()`` draws one command line with its input files: an example geometry
with perturbed hardpoints, wild values, dropped or unknown keys, changed
types and hand-made YAML text variations; a sweep with random targets (or a
broken one); and a command (mostly ``sweep``). ``run_case()`` runs it in
process through ``pin_susp.cli.main()`` in a fresh temporary directory, and
``check_case()`` asserts what must hold for every input:

1. exit 0 only when every written row converged on the design branch with
   ``solver_max_residual <= 1e-9`` mm (and, independently, the rows' points
   keep every rigid distance, meet the targets, keep every point-on-line
   condition and stay on the design side of every loop, per mechanism:
   double wishbone, MacPherson, multilink, trailing arm — ``bodies()``);
2. exit 1 only with the failing steps named on stderr (the steps flagged
   ``False`` in the CSV are the ones named, at least the first 10);
3. exit 2 with exactly one non-empty stderr line starting with ``pin-susp``
   and nothing written or touched;
4. never a traceback (an exception escaping main() propagates as itself);
5. nothing outside the declared outputs touched, no temporary file left, no
   ``MUJOCO_LOG.TXT``, the inputs unchanged.

The same hold for axles (each corner's rows checked as a corner's from its
``left_``/``right_`` columns, heave and roll from both wheel centres), for
``loads`` (one row per step and case), for Parquet outputs (read back with
pyarrow: the same cells) and for studies (variants.parquet's flags, the
steps' residuals; a ``--resume`` after an input changed is refused). A
degenerate linkage of any mechanism (``_degenerate_moves``) must be refused:
exit 2, one line naming its points.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import io
import json
import math
import os
import re
import tempfile
import time
import warnings
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import yaml
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
GEOMETRY_FILES = (
    "double_wishbone.yaml",
    "fixed_toe_link.yaml",
    "pushrod_rocker.yaml",
    "camber_shim.yaml",
    "macpherson.yaml",  # rack
    "multilink_rear.yaml",  # fixed toe link, coilover
    "multilink_front.yaml",  # rack, the upper links meeting in one ball joint
    "semi_trailing_arm.yaml",  # coilover, no steering
)
BASES = {name: yaml.safe_load((EXAMPLES / name).read_text()) for name in GEOMETRY_FILES}

# The geometry file's ``type:`` values (docs/geometry.md) and the steering each takes
# when config.steering is left out (the first of the mechanism's allowed values).
MECHANISMS = ("double_wishbone", "macpherson", "multilink", "trailing_arm")
DEFAULT_STEERING = {
    "double_wishbone": "rack",
    "macpherson": "rack",
    "multilink": "rack",
    "trailing_arm": "none",  # the only one it takes: no steering
}
LINKS = ("upper_front_link", "upper_rear_link", "lower_front_link", "lower_rear_link")

RESIDUAL_LIMIT = 1e-9  # mm: what a converged row promises
GEOMETRIC_TOLERANCE = 1e-7  # mm: rigid distances and targets checked from the CSV's points
SOLVER_COLUMNS = ("step_index", "solver_converged", "solver_max_residual", "solver_iterations")

# Per (command, exit code, or the exception's name): filled by run_case, printed by the test.
COUNTS: Counter = Counter()
# Per (mechanism of the drawn geometry, exit code): filled by run_case.
BY_MECHANISM: Counter = Counter()
# Per mechanism: converged rows checked independently from their points (bodies()).
ROWS_CHECKED: Counter = Counter()
# Per failure signature(), when failures are collected rather than raised.
FOUND: Counter = Counter()
# (seconds in main(), command line) of the slowest runs.
SLOWEST: list[tuple[float, str]] = []


# --------------------------------------------------------------------------- YAML text


class Raw(str):
    """A scalar written verbatim into the YAML text (``0250``, ``2e2``, ``.nan``, ...)."""


class Pairs(list):
    """A mapping written as its (key, value) pairs: it may repeat a key."""


_PLAIN = re.compile(r"[A-Za-z_][A-Za-z0-9_ .()-]*")
_YAML_WORDS = {"yes", "no", "on", "off", "true", "false", "null", "~"}


def scalar(value) -> str:
    if isinstance(value, Raw):
        return str(value)
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return ".nan"
        if math.isinf(value):
            return ".inf" if value > 0 else "-.inf"
        return repr(value)
    text = str(value)
    if _PLAIN.fullmatch(text) and text.lower() not in _YAML_WORDS and text == text.strip():
        return text
    return json.dumps(text)  # a JSON string is a YAML double-quoted scalar


def _items(node):
    return list(node) if isinstance(node, Pairs) else list(node.items())


def _is_map(node) -> bool:
    return isinstance(node, dict | Pairs)


def _flow(node) -> str | None:
    """A small mapping or list of scalars on one line, else None."""
    if _is_map(node):
        items = _items(node)
        if items and all(not _is_map(v) and not isinstance(v, list) for _, v in items):
            return "{" + ", ".join(f"{scalar(k)}: {scalar(v)}" for k, v in items) + "}"
        return "{}" if not items else None
    if isinstance(node, list):
        if all(not _is_map(v) and not isinstance(v, list) for v in node):
            return "[" + ", ".join(scalar(v) for v in node) + "]"
        if all(isinstance(v, list) for v in node):
            inner = [_flow(v) for v in node]
            if all(i is not None for i in inner):
                return "[" + ", ".join(inner) + "]"
    return None


def to_yaml(node, indent: int = 0) -> str:
    """Block-style YAML of dicts, Pairs, lists and scalars (Raw verbatim)."""
    pad = " " * indent
    if _is_map(node):
        lines = []
        for key, value in _items(node):
            flow = _flow(value) if (_is_map(value) or isinstance(value, list)) else None
            if _is_map(value) or isinstance(value, list):
                if flow is not None and (not _is_map(value) or len(_items(value)) <= 6):
                    lines.append(f"{pad}{scalar(key)}: {flow}")
                else:
                    lines.append(f"{pad}{scalar(key)}:")
                    lines.append(to_yaml(value, indent + 2).rstrip("\n"))
            else:
                lines.append(f"{pad}{scalar(key)}: {scalar(value)}")
        return "\n".join(lines) + "\n"
    if isinstance(node, list):
        lines = []
        for value in node:
            if _is_map(value) and _items(value):
                text = to_yaml(value, indent + 2).rstrip("\n")
                lines.append(pad + "- " + text[indent + 2 :])
            else:
                flow = _flow(value) if isinstance(value, list) or _is_map(value) else None
                lines.append(f"{pad}- {flow if flow is not None else scalar(value)}")
        return "\n".join(lines) + "\n"
    return pad + scalar(node) + "\n"


# --------------------------------------------------------------------------- data paths


def paths(node, want, prefix=()):
    """Paths (tuples of keys and indices) to the nodes for which want(node) holds."""
    found = [prefix] if prefix and want(node) else []
    if isinstance(node, dict):
        for k, v in node.items():
            found += paths(v, want, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            found += paths(v, want, prefix + (i,))
    return found


def get(node, path):
    for k in path:
        node = node[k]
    return node


def put(node, path, value):
    get(node, path[:-1])[path[-1]] = value


def _is_leaf(node) -> bool:
    return not isinstance(node, dict | list)


def _is_number(node) -> bool:
    return isinstance(node, int | float) and not isinstance(node, bool)


# --------------------------------------------------------------------------- values

# A coordinate or config value set to something no car has.
# fmt: off
WILD = (
    0, 0.0, -0.0, 1e6, -1e20, 10**30, 2**64, 10**400, 1e-300, 99_999.0, 100_001.0, float("nan"),
    float("inf"), float("-inf"), Raw(".NaN"), Raw("1e999"), Raw("-1e400"), "ten", "", None,
    True, False, [1.0, 2.0], [1.0, 2.0, 3.0, 4.0], [1.0, 2.0, 3.0], [], {}, {"x": 1.0},
    Raw("0250"), Raw("0259"), Raw("-0250"), Raw("2e2"), Raw("1.e5"), Raw("+5"), Raw("5."),
    Raw("0x1F"), Raw("0o17"), Raw("1_000"), Raw("1:30"), Raw("2020-01-01"), Raw("!!float abc"),
    Raw("!!int 1e3"), Raw("!!binary aGVsbG8="), Raw("'250'"), Raw("~"), Raw("*nowhere"),
    Raw("&anchor 5"), Raw('"\\u0000"'), Raw("!!python/object/apply:os.getcwd []"),
    Raw("9" * 400), Raw("1" + "0" * 25 + ".5"), "a\nb",
)
# fmt: on

# Unknown keys, some of them hostile.
UNKNOWN_KEYS = ("colour", "wheel_centre", "x2", "notes", "a\nb", "", 12, "Hardpoints")


def chance(draw, percent: int) -> bool:
    """True with about this probability; False is the simplest choice (it shrinks there)."""
    return draw(st.integers(0, 99)) >= 100 - percent


def wild() -> st.SearchStrategy:
    return st.sampled_from(WILD)


def small(limit: float) -> st.SearchStrategy:
    """A round number in [-limit, limit] mm (three decimals: short texts, good shrinking)."""
    k = int(limit * 1000)
    return st.integers(-k, k).map(lambda i: i / 1000)


def restyled(x) -> list[str]:
    """Ways engineers write the number x that must read back as x (or fail cleanly)."""
    out = []
    if isinstance(x, bool) or not _is_number(x) or abs(x) > 1e300 or not math.isfinite(x):
        return out
    if float(x).is_integer() and abs(x) < 1e15:
        n = int(x)
        if n != 0:
            mantissa, exponent = abs(n), 0
            while mantissa % 10 == 0:
                mantissa, exponent = mantissa // 10, exponent + 1
            sign = "-" if n < 0 else ""
            out += [f"{sign}{mantissa}e{exponent}", f"{sign}0{abs(n)}", f"{n}."]
            if abs(n) >= 1000:
                out.append(f"{n:_}")
            if abs(n) >= 60:
                out.append(f"{sign}{abs(n) // 60}:{abs(n) % 60:02d}")
        else:
            out += ["00", "-0", "0e0"]
    else:
        out += [f"{x:e}", f"{x:.6E}".replace("E+0", "E"), "+" + repr(x) if x > 0 else repr(x)]
    out.append(f"'{x}'")
    return out


# --------------------------------------------------------------------------- geometry


@dataclass
class Inputs:
    """What was drawn for a file: the data, its text, and what was done to it."""

    data: object
    text: bytes
    changes: list[str] = field(default_factory=list)


def _kind(data) -> str | None:
    """The mechanism a geometry's data names (``type:``, double_wishbone when left out),
    or None when it names none."""
    if not isinstance(data, dict):
        return None
    kind = data.get("type", "double_wishbone")
    return str(kind) if isinstance(kind, str) and kind in MECHANISMS else None


def _hardpoint_names(data) -> list[str]:
    hp = data.get("hardpoints") if isinstance(data, dict) else None
    return list(hp) if isinstance(hp, dict) else []


def _numeric_point(point) -> list[float] | None:
    """[x, y, z] of a point written {x, y, z} or [x, y, z] with plain numbers, else None."""
    if isinstance(point, dict) and set(point) == set("xyz"):
        point = [point[a] for a in "xyz"]
    if isinstance(point, list) and len(point) == 3:
        if all(_is_number(v) and abs(v) < 1e300 for v in point):
            return [float(v) for v in point]
    return None


def _coordinate_paths(data) -> list[tuple]:
    out = []
    for name in _hardpoint_names(data):
        point = data["hardpoints"][name]
        if isinstance(point, dict):
            out += [("hardpoints", name, a) for a in "xyz" if _is_number(point.get(a))]
        elif isinstance(point, list):
            out += [("hardpoints", name, i) for i, v in enumerate(point) if _is_number(v)]
    return out


def _mirror(data) -> None:
    """Mirror a geometry through Y = 0 (a valid corner on the other side)."""
    data["side"] = "right" if data.get("side", "left") == "left" else "left"

    def flip(point):
        if isinstance(point, dict) and _is_number(point.get("y")):
            point["y"] = -point["y"]

    for p in (data.get("hardpoints") or {}).values():
        flip(p)
    config = data.get("config") or {}
    flip(config.get("cg_position"))
    shim = config.get("camber_shim") or {}
    for key in ("shim_face_point_a", "shim_face_point_b", "shim_face_normal"):
        flip(shim.get(key))


def _steering_to(data, kind: str, rename: bool) -> None:
    config = data.setdefault("config", {})
    config["steering"] = {"type": kind}
    hp = data.get("hardpoints")
    if not rename or not isinstance(hp, dict):
        return
    old, new = ("trackrod", "toe_link") if kind == "none" else ("toe_link", "trackrod")
    for end in ("inboard", "outboard"):
        if f"{old}_{end}" in hp:
            hp[f"{new}_{end}"] = hp.pop(f"{old}_{end}")


ROCKER_POINTS = {k: BASES["pushrod_rocker.yaml"]["hardpoints"][k] for k in (
    "pushrod_outboard", "pushrod_inboard", "rocker_axis_a", "rocker_axis_b"
)}  # fmt: skip
STRUT_POINTS = {k: BASES["pushrod_rocker.yaml"]["hardpoints"][k] for k in (
    "strut_bottom", "strut_top"
)}  # fmt: skip


def _as_multilink(data) -> str:
    """A double wishbone rewritten as the multilink it is: each wishbone two links that
    meet in its ball joint (docs/geometry.md: a valid corner, the same motion)."""
    hp = data.get("hardpoints")
    if not isinstance(hp, dict):
        return "as multilink (no hardpoints)"
    data["type"] = "multilink"
    for level in ("upper", "lower"):
        outboard = hp.pop(f"{level}_wishbone_outboard", None)
        for end in ("front", "rear"):
            inboard = hp.pop(f"{level}_wishbone_inboard_{end}", None)
            if inboard is not None:
                hp[f"{level}_{end}_link_inboard"] = inboard
            if outboard is not None:
                hp[f"{level}_{end}_link_outboard"] = copy.deepcopy(outboard)
    act = data.get("actuation")
    if isinstance(act, dict) and act.get("type", "direct") == "direct":
        del data["actuation"]  # a coilover on the lower wishbone now sits on the upright
    return "as multilink (wishbones as link pairs)"


def _onto_strut_line(data) -> str:
    """A MacPherson's strut_bottom put back on its strut line LBJ→strut_top (the foot of
    its perpendicular), after the points moved."""
    hp = data["hardpoints"]
    a, b, c = (
        _numeric_point(hp.get(n)) for n in ("lower_wishbone_outboard", "strut_top", "strut_bottom")
    )
    if a is None or b is None or c is None or a == b:
        return "strut_bottom (no strut line)"
    u = _unit([b[i] - a[i] for i in range(3)])
    along = sum((c[i] - a[i]) * u[i] for i in range(3))
    hp["strut_bottom"] = dict(
        zip("xyz", (round(a[i] + along * u[i], 9) for i in range(3)), strict=True)
    )
    return "strut_bottom onto the strut line"


def _clamp(draw, data) -> str:
    """A MacPherson's strut_bottom moved along its strut line LBJ→strut_top (maybe
    outside the two ends) and off it (the file may put it up to 1 mm off)."""
    hp = data.get("hardpoints")
    hp = hp if isinstance(hp, dict) else {}
    a = _numeric_point(hp.get("lower_wishbone_outboard"))
    b = _numeric_point(hp.get("strut_top"))
    if a is None or b is None:
        return "clamp (no strut line)"
    t = draw(st.sampled_from((0.3, 0.5, 0.9, 0.0, 1.0, -0.2, 1.2, 1e-6, 0.999999)))
    off = draw(st.sampled_from((0.0, 1e-6, 0.5, 0.999, 1.001, 3.0)))
    d = [b[i] - a[i] for i in range(3)]
    normal = _unit((d[1], -d[0], 0.0)) if abs(d[0]) + abs(d[1]) > 0 else (1.0, 0.0, 0.0)
    new = [round(a[i] + t * d[i] + off * normal[i], 9) for i in range(3)]
    hp["strut_bottom"] = dict(zip("xyz", new, strict=True))
    return f"strut_bottom at {t:g} of LBJ→strut_top, {off:g} mm off the line"


@st.composite
def _mutate_geometry(draw, data) -> str:
    """One structural change to a geometry dict, in place; its label."""
    kinds = (
        "drop_key drop_hardpoint unknown_key retype wild_coordinate wild_point mirror "
        "side_only steering actuation mount spring shim adjuster wheel restyle_number "
        "points_as_lists degenerate degenerate scale translate mechanism clamp as_multilink "
        "degenerate_named degenerate_named"
    ).split()
    kind = draw(st.sampled_from(kinds))
    if kind == "drop_hardpoint" and _hardpoint_names(data):
        name = draw(st.sampled_from(_hardpoint_names(data)))
        del data["hardpoints"][name]
        return f"drop hardpoints.{name}"
    generic = _mutate_keys(draw, data, kind, UNKNOWN_KEYS)
    if generic is not None:
        return generic
    if kind == "wild_coordinate" and _coordinate_paths(data):
        path = draw(st.sampled_from(_coordinate_paths(data)))
        value = draw(wild())
        put(data, path, value)
        return f"{'.'.join(map(str, path))} = {value!r}"
    if kind == "wild_point" and _hardpoint_names(data):
        name = draw(st.sampled_from(_hardpoint_names(data)))
        value = draw(
            st.sampled_from(
                (
                    [1.0, 2.0],
                    [1.0, 2.0, 3.0, 4.0],
                    [[1.0, 2.0, 3.0]],
                    "origin",
                    None,
                    {},
                    {"x": 1.0, "y": 2.0},
                    {"x": 1.0, "y": 2.0, "z": 3.0, "w": 4.0},
                    {"X": 1.0, "Y": 2.0, "Z": 3.0},
                    Raw("{x: 1, y: 2, z: }"),
                )
            )
        )
        data["hardpoints"][name] = value
        return f"hardpoints.{name} = {value!r}"
    if kind == "mirror":
        _mirror(data)
        return "mirrored"
    if kind == "side_only":
        value = draw(st.sampled_from(("right", "left", "both", "Left", None)))
        data["side"] = value
        return f"side = {value!r}"
    if kind == "steering":
        value = draw(st.sampled_from(("none", "rack", "pinion")))
        rename = draw(st.booleans())
        _steering_to(data, value, rename)
        return f"steering {value}" + (" (points renamed)" if rename else "")
    if kind == "actuation":
        value = draw(st.sampled_from(("pushrod_rocker", "direct", "pullrod")))
        mount = draw(st.sampled_from(("lower_wishbone", "upright")))
        data["actuation"] = {"type": value, "mount": mount}
        hp = data.get("hardpoints")
        if isinstance(hp, dict) and draw(st.booleans()):
            if value == "pushrod_rocker":
                for k, v in ROCKER_POINTS.items():
                    hp.setdefault(k, dict(v))
            else:
                for k in ROCKER_POINTS:
                    hp.pop(k, None)
            return f"actuation {value} on {mount} (points fitted)"
        return f"actuation {value} on {mount}"
    if kind == "mount":
        act = data.get("actuation")
        if isinstance(act, dict):
            act["mount"] = "upright" if act.get("mount") == "lower_wishbone" else "lower_wishbone"
            return f"mount {act['mount']}"
        return "mount (no actuation)"
    if kind == "spring":
        value = draw(st.sampled_from(("coilover", "torsion_bar", "none", "leaf")))
        data["spring"] = {"type": value}
        hp = data.get("hardpoints")
        if isinstance(hp, dict) and draw(st.booleans()):
            if value == "coilover":
                for k, v in STRUT_POINTS.items():
                    hp.setdefault(k, dict(v))
            else:
                for k in STRUT_POINTS:
                    hp.pop(k, None)
            return f"spring {value} (points fitted)"
        return f"spring {value}"
    if kind == "shim":
        config = data.setdefault("config", {})
        if not isinstance(config, dict):
            return "shim (config not a mapping)"
        shim = config.get("camber_shim")
        if not isinstance(shim, dict):
            shim = copy.deepcopy(BASES["camber_shim.yaml"]["config"]["camber_shim"])
            config["camber_shim"] = shim
        key = draw(
            st.sampled_from(
                (
                    "setup_thickness",
                    "setup_thickness",
                    "design_thickness",
                    "shim_face_normal",
                    "shim_face_point_b",
                )
            )
        )
        if key.endswith("thickness"):
            value = draw(st.one_of(small(60).map(abs), small(100), wild()))
        elif key == "shim_face_normal":
            value = draw(
                st.sampled_from(
                    (
                        {"x": 0.0, "y": 0.0, "z": 0.0},
                        {"x": 0.0, "y": -1.0, "z": 0.0},
                        {"x": 0.1, "y": 1.0, "z": 0.05},
                        {"x": 0.0, "y": 0.0, "z": 1.0},
                    )
                )
            )
        else:
            value = copy.deepcopy(shim.get("shim_face_point_a"))
        shim[key] = value
        return f"camber_shim.{key} = {value!r}"
    if kind == "adjuster":
        config = data.setdefault("config", {})
        if not isinstance(config, dict):
            return "adjuster (config not a mapping)"
        key = draw(st.sampled_from(("trackrod_length_delta", "pushrod_length_delta")))
        value = draw(st.one_of(small(20), small(20), wild()))
        setup = config.get("setup")
        if not isinstance(setup, dict):
            setup = config["setup"] = {}
        setup[key] = value
        return f"setup.{key} = {value!r}"
    if kind == "wheel":
        key = draw(st.sampled_from(("offset", "aspect_ratio", "section_width", "rim_diameter")))
        value = draw(st.one_of(small(60), wild()))
        wheel = (data.get("config") or {}).get("wheel") if isinstance(data, dict) else None
        if isinstance(wheel, dict):
            target = wheel if key == "offset" else wheel.get("tire")
            if isinstance(target, dict):
                target[key] = value
                return f"wheel {key} = {value!r}"
        return "wheel (missing)"
    if kind == "restyle_number":
        numbers = [p for p in paths(data, _is_number) if restyled(get(data, p))]
        if numbers:
            path = draw(st.sampled_from(numbers))
            text = draw(st.sampled_from(restyled(get(data, path))))
            put(data, path, Raw(text))
            return f"{'.'.join(map(str, path))} written {text}"
        return "restyle (no number)"
    if kind == "degenerate":  # a point on (or a hair off) the line of two others
        names = [n for n in _hardpoint_names(data) if _numeric_point(data["hardpoints"][n])]
        if len(names) >= 3:
            p, a, b = draw(st.permutations(names))[:3]
            t = draw(st.sampled_from((0.0, 1.0, 0.5, 2.0, -1.0)))
            eps = draw(st.sampled_from((0.0, 1e-9, 1e-6, 1e-3, 0.1)))
            pa, pb = _numeric_point(data["hardpoints"][a]), _numeric_point(data["hardpoints"][b])
            new = [pa[i] + t * (pb[i] - pa[i]) + (eps if i == 0 else 0.0) for i in range(3)]
            data["hardpoints"][p] = dict(zip("xyz", new, strict=True))
            return f"{p} = {a} + {t:g}·({b} - {a}) + {eps:g} x"
        return "degenerate (too few points)"
    if kind in ("scale", "translate"):  # the whole corner, its hardpoints only
        if kind == "scale":
            k = draw(st.sampled_from((0.001, 0.1, 10.0, 100.0, -1.0)))
            move = lambda v, i: v * k  # noqa: E731
        else:
            d = draw(st.sampled_from(((1e4, 0, 0), (0, 5e4, 0), (0, 0, -3e4), (0, -2e3, 0))))
            move = lambda v, i: v + d[i]  # noqa: E731
        for name in _hardpoint_names(data):
            point = _numeric_point(data["hardpoints"][name])
            if point is not None:
                data["hardpoints"][name] = dict(
                    zip("xyz", (round(move(v, i), 9) for i, v in enumerate(point)), strict=True)
                )
        return f"{kind} {k if kind == 'scale' else d}"
    if kind == "mechanism":  # another type: (mostly) points it does not have, one error
        value = draw(st.sampled_from(MECHANISMS + ("Multilink", "strut", "")))
        data["type"] = value
        return f"type = {value!r}"
    if kind == "degenerate_named":
        return draw(_degenerate(data))
    if kind == "as_multilink" and _kind(data) == "double_wishbone":
        return _as_multilink(data)
    if kind == "clamp" and _kind(data) == "macpherson":
        return _clamp(draw, data)
    if kind == "points_as_lists":
        for name in _hardpoint_names(data):
            point = data["hardpoints"][name]
            if isinstance(point, dict) and set(point) == set("xyz"):
                data["hardpoints"][name] = [point[a] for a in "xyz"]
        return "points as [x, y, z]"
    return f"{kind} (not applicable)"


# Whole files that are not a geometry at all.
GARBAGE = (
    b"",
    b"\n# only a comment\n",
    b"[]\n",
    b"42\n",
    b"hardpoints: [\n",
    b"\tside: left\n",
    b"---\nside: left\n---\nside: right\n",
    b"\xff\xfe\x00junk",
    b"\xef\xbb\xbfside: left\n",
    b"key: \x07bell\n",
    b"[" * 400 + b"]" * 400,
    b"a: &a [1, 2]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a]\nc: [*b, *b, *b, *b, *b, *b, *b]\n",
    b"? [1, 2]\n: complex key\n",
    b"<<: {side: left}\n",
    b"!!python/object/apply:os.system ['true']\n",
    b"name: '" + b"x" * 100_000 + b"'\n",
)


def _duplicate(draw, data):
    """The data with one key of one mapping written twice (Pairs), as the last change."""
    maps = [()] + paths(data, lambda n: isinstance(n, dict) and len(n) > 0)
    path = draw(st.sampled_from(sorted(maps, key=repr)))
    node = get(data, path)
    if not node:
        return data, "duplicate (empty mapping)"
    key = draw(st.sampled_from(sorted(node, key=repr)))
    twin = Pairs(node.items())
    again = draw(st.sampled_from(("same", "other")))
    twin.insert(draw(st.integers(0, len(twin))), (key, node[key] if again == "same" else 1.0))
    if not path:
        return twin, f"duplicate top-level key {key} ({again} value)"
    put(data, path, twin)
    return data, f"duplicate key {'.'.join(map(str, path + (key,)))} ({again} value)"


def _render(data, draw, changes) -> bytes:
    if chance(draw, 5):
        data, change = _duplicate(draw, data)
        changes.append(change)
    text = to_yaml(data) if (_is_map(data) or isinstance(data, list)) else scalar(data) + "\n"
    variant = draw(st.sampled_from(("plain",) * 12 + ("crlf", "bom", "comment", "end")))
    if variant == "crlf":
        text = text.replace("\n", "\r\n")
    elif variant == "bom":
        text = "\ufeff" + text
    elif variant == "comment":
        text = "# fuzzed geometry\n" + text.replace("\n", "  # note\n", 1)
    elif variant == "end":
        text += "...\n"
    if variant != "plain":
        changes.append(f"text {variant}")
    return text.encode("utf-8")


@st.composite
def geometries(draw) -> Inputs:
    """A geometry file: an example, perturbed, maybe broken; its data and YAML text."""
    base = draw(st.sampled_from(GEOMETRY_FILES))
    data = copy.deepcopy(BASES[base])
    changes = [base]
    if chance(draw, 2):
        text = draw(st.sampled_from(GARBAGE))
        return Inputs(None, text, [*changes, f"garbage {text[:30]!r}"])
    mode = draw(st.sampled_from(("none", "small", "small", "small", "some", "large")))
    coordinates = _coordinate_paths(data)
    if mode == "small":  # every coordinate within ±5 mm
        deltas = draw(st.lists(small(5), min_size=len(coordinates), max_size=len(coordinates)))
        for path, d in zip(coordinates, deltas, strict=True):
            put(data, path, round(get(data, path) + d, 6))
        changes.append("all ±5 mm")
    elif mode in ("some", "large"):
        limit = 5 if mode == "some" else 100
        moves = draw(
            st.lists(st.tuples(st.sampled_from(coordinates), small(limit)), min_size=1, max_size=4)
        )
        for path, d in moves:
            put(data, path, round(get(data, path) + d, 6))
            changes.append(f"{'.'.join(map(str, path))} {d:+g}")
    if mode != "none" and _kind(data) == "macpherson" and not chance(draw, 15):
        changes.append(_onto_strut_line(data))  # else mostly > 1 mm off it: an error
    count = draw(st.sampled_from((0, 0, 0, 0, 0, 0, 1, 1, 2, 3)))
    for _ in range(count):
        changes.append(draw(_mutate_geometry(data)))
    return Inputs(data, _render(data, draw, changes), changes)


# --------------------------------------------------------------------------- sweep


@dataclass
class Plan:
    """A target as meant (when the sweep text was not broken on purpose)."""

    point: str  # or an axle's quantity: heave, roll (mode "quantity")
    direction: tuple[float, float, float]  # unit
    mode: str
    values: list[float]
    side: str | None = None  # an axle's corner


def _design_point(geometry, name: str):
    """Roughly where a point is in the geometry data (mm), for absolute targets."""
    hp = geometry.get("hardpoints") if isinstance(geometry, dict) else None
    if not isinstance(hp, dict):
        return None
    alias = {"wheel_center": "axle_outboard", "axle_midpoint": "axle_outboard"}
    return _numeric_point(hp.get(alias.get(name, name)))


def _is_rack(geometry) -> bool | None:
    """Whether the corner is steered by a rack (a sweep then takes a wheel and a rack
    target) or not (a fixed toe link, a trailing arm: one wheel target); None when the
    data does not say (broken on purpose)."""
    mechanism = _kind(geometry)
    if mechanism is None:
        return None
    if mechanism == "trailing_arm":
        return False  # no rack whatever the file says (a rack there is an error)
    config = geometry.get("config")
    if not isinstance(config, dict):
        return None
    steering = config.get("steering", {"type": DEFAULT_STEERING[mechanism]})
    if not isinstance(steering, dict):
        return None
    kind = steering.get("type", DEFAULT_STEERING[mechanism])
    return {"rack": True, "none": False}.get(kind) if isinstance(kind, str) else None


# Bump targets: mostly the wheel centre, sometimes another point that rides with the wheel.
WHEEL_POINTS = ("wheel_center",) * 6 + ("contact_patch_center", "axle_outboard", "axle_midpoint")
UPRIGHT_POINTS = {  # per mechanism: its lower and upper points on the wheel's body
    "double_wishbone": ("lower_wishbone_outboard", "upper_wishbone_outboard"),
    "macpherson": ("lower_wishbone_outboard", "strut_bottom"),
    "multilink": ("lower_front_link_outboard", "upper_rear_link_outboard"),
    "trailing_arm": ("axle_inboard", "axle_inboard"),
}
CHASSIS_POINTS = {  # a target on one of these cannot move: an error
    "double_wishbone": (
        "lower_wishbone_inboard_front",
        "upper_wishbone_inboard_rear",
        "rocker_axis_a",
    ),
    "macpherson": ("lower_wishbone_inboard_front", "strut_top", "lower_wishbone_inboard_rear"),
    "multilink": ("upper_front_link_inboard", "lower_rear_link_inboard", "toe_link_inboard"),
    "trailing_arm": ("arm_pivot_inboard", "arm_pivot_outboard", "strut_top"),
}
UNKNOWN_POINTS = ("wheel_centre", "hub", "", "trackrod_inboard_y", "Wheel_Center")


def _unit(v) -> tuple[float, float, float]:
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


@st.composite
def _target(draw, geometry, steps: int, rack: bool):
    """One target dict and its Plan: the wheel (bump) or the rack (steer)."""
    if rack:
        point, limit = "trackrod_inboard", 15
        axis = (0.0, 1.0, 0.0)
        form = draw(st.sampled_from(("axis",) * 8 + ("vector", "minus")))
        direction = {
            "axis": {"axis": "y"},
            "vector": {"vector": [0.0, 1.0, 0.0]},
            "minus": {"vector": [0, -2, 0]},
        }[form]
        if form == "minus":
            axis = (0.0, -1.0, 0.0)
    else:
        upright = UPRIGHT_POINTS[_kind(geometry) or "double_wishbone"]
        point = draw(st.sampled_from(WHEEL_POINTS + upright))
        limit = 600 if chance(draw, 10) else 60  # sometimes beyond the mechanism's reach
        form = draw(st.sampled_from(("axis",) * 6 + ("vector", "tilted", "sideways")))
        if form == "axis":
            direction, axis = {"axis": "z"}, (0.0, 0.0, 1.0)
        elif form == "vector":
            k = draw(st.sampled_from((1, 2, 0.5, -1)))
            direction, axis = {"vector": [0, 0, k]}, _unit((0, 0, k))
        elif form == "tilted":
            v = [draw(small(0.5)), draw(small(0.5)), 1.0]
            direction, axis = {"vector": v}, _unit(v)
        else:
            v = draw(st.sampled_from(([1, 0, 0], [0, 1, 0], [1, 1, 1])))
            direction, axis = {"vector": v}, _unit(v)
    mode = draw(st.sampled_from(("relative",) * 5 + ("absolute",)))
    target = {"point": point, "direction": direction}
    offset = 0.0
    if mode == "absolute":
        target["mode"] = "absolute"
        p = _design_point(geometry, point)
        offset = sum(a * b for a, b in zip(axis, p, strict=True)) if p else draw(small(600))
    elif draw(st.booleans()):
        target["mode"] = "relative"
    if chance(draw, 20):
        values = draw(st.lists(small(limit), min_size=steps, max_size=steps))
        values = [round(v + offset, 6) for v in values]
        target["values"] = values
    else:
        start, stop = draw(small(limit)), draw(small(limit))
        start, stop = round(start + offset, 6), round(stop + offset, 6)
        target["start"], target["stop"] = start, stop
        values = (
            [start + (stop - start) * i / (steps - 1) for i in range(steps)]
            if steps > 1
            else [start]
        )
    return target, Plan(point, axis, mode, values)


@st.composite
def _mutate_sweep(draw, data, steps: int, geometry=None) -> str:
    targets = data.get("targets")
    mechanism = _kind(geometry) or "double_wishbone"
    kinds = (
        "drop_target extra_target chassis_point unknown_point lengths wild_value "
        "wild_steps no_steps direction mode unknown_key drop_key targets restyle_number "
        "duplicate_key"
    ).split()
    kind = draw(st.sampled_from(kinds))
    pool = [x for x in targets if isinstance(x, dict)] if isinstance(targets, list) else []
    t = draw(st.sampled_from(pool)) if pool else None
    if kind == "drop_target" and t is not None:
        targets.remove(t)
        return "dropped a target"
    if kind == "extra_target" and t is not None:
        twin = copy.deepcopy(t)
        if draw(st.booleans()):
            twin["point"] = draw(st.sampled_from(("axle_outboard", UPRIGHT_POINTS[mechanism][1])))
        targets.append(twin)
        return f"extra target on {twin['point']}"
    if kind == "chassis_point" and t:
        t["point"] = draw(st.sampled_from(CHASSIS_POINTS[mechanism]))
        return f"target on {t['point']}"
    if kind == "unknown_point" and t:
        t["point"] = draw(st.sampled_from(UNKNOWN_POINTS + (None, 5, ["wheel_center"])))
        return f"target on {t['point']!r}"
    if kind == "lengths" and t:
        n = draw(st.integers(1, 8).filter(lambda n: n != steps))
        t.pop("start", None)
        t.pop("stop", None)
        t["values"] = draw(st.lists(small(30), min_size=n, max_size=n))
        return f"a target with {n} values"
    if kind == "wild_value" and t:
        keys = [k for k in ("start", "stop") if k in t] or ["values"]
        key = draw(st.sampled_from(keys))
        value = draw(wild())
        if key == "values" and isinstance(t.get("values"), list) and draw(st.booleans()):
            t["values"][draw(st.integers(0, len(t["values"]) - 1))] = value
            return f"a value = {value!r}"
        t[key] = value
        return f"{key} = {value!r}"
    if kind == "wild_steps":
        value = draw(
            st.sampled_from((0, -1, 1.5, "ten", True, 10**12, 2**70, None, "", [], Raw("0x10")))
        )
        data["steps"] = value
        return f"steps = {value!r}"
    if kind == "no_steps":
        data.pop("steps", None)
        return "no steps"
    if kind == "direction" and t:
        value = draw(
            st.sampled_from(
                (
                    {"axis": "w"},
                    {"axis": "Z"},
                    {"vector": [0, 0, 0]},
                    {"vector": [0, 1]},
                    {"vector": [float("nan"), 0, 1]},
                    {"vector": [1e-300, 0, 0]},
                    {"vector": [1e300, 1e300, 0]},
                    {"axis": "z", "vector": [0, 0, 1]},
                    {},
                    "z",
                    None,
                )
            )
        )
        t["direction"] = value
        return f"direction = {value!r}"
    if kind == "mode" and t:
        t["mode"] = draw(st.sampled_from(("relativ", "Absolute", None, 1)))
        return f"mode = {t['mode']!r}"
    if kind == "unknown_key":
        where = t if t is not None and draw(st.booleans()) else data
        key = draw(st.sampled_from(UNKNOWN_KEYS))
        where[key] = 1
        return f"unknown key {key!r}"
    if kind == "drop_key":
        where = t if t is not None and draw(st.booleans()) else data
        if where:
            key = draw(st.sampled_from(sorted(where, key=repr)))
            del where[key]
            return f"dropped {key!r}"
    if kind == "targets":
        data["targets"] = draw(st.sampled_from(([], None, "wheel_center", {}, [None], [[]])))
        return f"targets = {data['targets']!r}"
    if kind == "restyle_number":
        numbers = [p for p in paths(data, _is_number) if restyled(get(data, p))]
        if numbers:
            path = draw(st.sampled_from(numbers))
            text = draw(st.sampled_from(restyled(get(data, path))))
            put(data, path, Raw(text))
            return f"{'.'.join(map(str, path))} written {text}"
    if kind == "duplicate_key":
        node = t if t is not None and draw(st.booleans()) else None
        if node:
            key = draw(st.sampled_from(sorted(node, key=repr)))
            i = data["targets"].index(node)
            data["targets"][i] = Pairs([*node.items(), (key, node[key])])
            return f"duplicate key {key!r} in a target"
    return f"{kind} (not applicable)"


@st.composite
def sweeps(draw, geometry, max_steps: int = 60):
    """A sweep file for the drawn geometry: (Inputs, plans or None when broken on purpose)."""
    rack = _is_rack(geometry)
    if rack is None:
        rack = draw(st.booleans())
    steps = draw(st.one_of(st.integers(1, min(12, max_steps)), st.integers(1, max_steps)))
    targets, plans = [], []
    wheel, plan = draw(_target(geometry, steps, rack=False))
    targets.append(wheel)
    plans.append(plan)
    if rack:
        steer, plan = draw(_target(geometry, steps, rack=True))
        targets.append(steer)
        plans.append(plan)
    if len(targets) > 1 and chance(draw, 20):
        targets.reverse()
        plans.reverse()
    data = {"version": 1, "steps": steps, "targets": targets}
    if draw(st.booleans()) and all("values" in t for t in targets):
        del data["steps"]
    changes = [f"{steps} steps"]
    if chance(draw, 2):
        text = draw(st.sampled_from(GARBAGE))
        return Inputs(None, text, [*changes, f"garbage {text[:30]!r}"]), None
    if chance(draw, 20):
        for _ in range(draw(st.integers(1, 2))):
            changes.append(draw(_mutate_sweep(data, steps, geometry)))
        plans = None
    text = to_yaml(data).encode()
    return Inputs(data, text, changes), plans


# --------------------------------------------------------------------------- commands


@dataclass
class Case:
    """One command line, its input files and what it may write."""

    command: str  # sweep, sensitivity, urdf, urdf-at, mjcf, setup, draw
    argv: list[str]
    files: dict[str, bytes]  # input files, relative to the run directory
    outputs: list[str]  # declared output paths (the only files it may create)
    geometry: Inputs
    sweep: Inputs | None = None
    plans: list[Plan] | None = None
    stale: list[str] = field(default_factory=list)  # outputs that exist before the run
    quiet: bool = False
    links: dict[str, str] = field(default_factory=dict)  # output -> input it links to
    extra: dict[str, Inputs] = field(default_factory=dict)  # c.yaml (loads), study.yaml
    before: list[str] | None = None  # a command line run first (a study to --resume)
    edits: dict[str, bytes] = field(default_factory=dict)  # inputs changed after it

    def _repr_pretty_(self, printer, cycle) -> None:  # how Hypothesis prints a failing case
        printer.text(repr(self))

    def __repr__(self) -> str:
        parts = [f"Case({self.command}): pin-susp {' '.join(map(_quote, self.argv))}"]
        parts.append(f"  geometry changes: {self.geometry.changes}")
        parts.append(_indent("g.yaml", self.geometry.text))
        if self.sweep is not None:
            parts.append(f"  sweep changes: {self.sweep.changes}")
            parts.append(_indent("s.yaml", self.sweep.text))
        for name, inputs in self.extra.items():
            parts.append(f"  {name} changes: {inputs.changes}")
            parts.append(_indent(name, inputs.text))
        if self.before is not None:
            parts.append(f"  run first: pin-susp {' '.join(map(_quote, self.before))}")
            for name, text in self.edits.items():
                parts.append(_indent(f"{name}, then changed to", text))
        if self.stale:
            parts.append(f"  existing outputs: {self.stale}")
        if self.links:
            parts.append(f"  outputs that are symlinks to inputs: {self.links}")
        return "\n".join(parts)


def _quote(arg: str) -> str:
    return arg if re.fullmatch(r"[A-Za-z0-9_./:,=+-]+", arg) else repr(arg)


def _indent(name: str, text: bytes) -> str:
    body = text.decode("utf-8", "backslashreplace")
    if len(body) > 4000:
        body = body[:4000] + f"\n... ({len(body)} characters)"
    return f"  --- {name}\n" + "\n".join("    " + line for line in body.splitlines())


def _numbers_argument(values) -> str:
    return ",".join(v if isinstance(v, str) else f"{v:g}" for v in values)


def _output(draw, name: str, inputs=()) -> str:
    """Mostly the plain name; sometimes a new folder, spaces, no valid file at all, or
    (rarely) one of the input files."""
    if inputs and chance(draw, 1):
        return draw(st.sampled_from(sorted(inputs)))
    return draw(
        st.sampled_from(
            (name,) * 60 + (f"new/{name}", f"with space {name}", ".", "", "g.yaml/x", "new/")
        )
    )


def _pictures_available() -> bool:
    try:
        from pin_susp.plots import check_image_path  # noqa: F401
    except ImportError:
        return False
    return True


COMMANDS = ("sweep",) * 50 + ("sensitivity",) * 10 + ("urdf",) * 5 + ("urdf-at",) * 7
COMMANDS += ("mjcf",) * 5 + ("setup",) * 13 + ("loads",) * 12 + ("study",) * 2
# Commands that take an axle (scope: axle) as well as a corner; validate is drawn apart.
AXLE_COMMANDS = {"sweep", "sensitivity", "urdf", "mjcf", "setup", "loads", "draw"}
AXLE_COMMANDS |= {"validate", "study"}
STREAM_STEPS = 10_000  # cli.commands.sweep.STREAM_STEPS: a longer corner sweep is streamed


def _long_sweep(geometry) -> tuple[Inputs, list[Plan]]:
    """A corner sweep of 10 001 steps: streamed to its file a chunk at a time."""
    steps = STREAM_STEPS + 1
    ramp = lambda a, b: [a + (b - a) * i / (steps - 1) for i in range(steps)]  # noqa: E731
    targets = [{"point": "wheel_center", "direction": {"axis": "z"}, "start": -20, "stop": 20}]
    plans = [Plan("wheel_center", (0.0, 0.0, 1.0), "relative", ramp(-20.0, 20.0))]
    if _is_rack(geometry):
        targets.append({"point": "trackrod_inboard", "direction": {"axis": "y"}, "start": -5,
                        "stop": 5})  # fmt: skip
        plans.append(Plan("trackrod_inboard", (0.0, 1.0, 0.0), "relative", ramp(-5.0, 5.0)))
    data = {"version": 1, "steps": steps, "targets": targets}
    return Inputs(data, to_yaml(data).encode(), [f"{steps} steps (streamed)"]), plans


@st.composite
def cases(draw, pictures: bool | None = None) -> Case:
    """A command line with its files; ``pictures`` (default: when pin_susp.plots is ready)
    adds the slow matplotlib outputs, rarely: ``draw`` and ``sweep --plot``."""
    if pictures is None:
        pictures = _pictures_available()
    commands = COMMANDS + (("draw",) if pictures else ())
    command = draw(st.sampled_from(commands))
    if command == "sensitivity" and chance(draw, 5):
        command = "validate"  # slow (a point-based solve per step, MuJoCo): rare
    axle = command in AXLE_COMMANDS and chance(draw, 20 if command != "study" else 10)
    geometry = draw(axle_geometries() if axle else geometries())
    files = {"g.yaml": geometry.text}
    extra: dict[str, Inputs] = {}
    before = None
    edits: dict[str, bytes] = {}
    g_arg = "g.yaml"
    if chance(draw, 1):
        g_arg = draw(st.sampled_from(("missing.yaml", ".", "g.yaml/")))
    sweep = plans = None
    outputs: list[str] = []
    quiet = False
    if command in ("sweep", "sensitivity", "urdf-at", "loads", "validate", "study"):
        with_sweep = command != "sensitivity" or not chance(draw, 25)
        longest = {"sensitivity": 20, "loads": 20, "validate": 4, "study": 5}.get(command, 60)
        if with_sweep and axle:
            sweep, plans = draw(axle_sweeps(geometry.data, min(longest, 30)))
        elif with_sweep:
            sweep, plans = draw(sweeps(geometry.data, longest))
        if command == "sweep" and not axle and chance(draw, 1) and chance(draw, 30):
            sweep, plans = _long_sweep(geometry.data)
        if sweep is not None:
            files["s.yaml"] = sweep.text
    s_arg = "s.yaml"
    if sweep is not None and chance(draw, 1):
        s_arg = draw(st.sampled_from(("missing.yaml", "g.yaml", ".")))
    table = "out.parquet" if chance(draw, 15) else "out.csv"
    if command == "sweep":
        out = _output(draw, table, files)
        quiet = not chance(draw, 30)
        argv = ["sweep", g_arg, s_arg, "-o", out] + (["-q"] if quiet else [])
        outputs.append(out)
        if pictures and chance(draw, 2):
            image = draw(st.sampled_from(("p.png", "p.png", "p.svg", "p.txt", "new/p.png", "")))
            if not image:  # the results and the report on one path
                image = outputs[0] = argv[4] = "r.png"
            argv += ["--plot", image]
            outputs.append(image)
    elif command == "sensitivity":
        argv = ["sensitivity", g_arg]
        if sweep is not None:
            argv += ["--sweep", s_arg]
        if not chance(draw, 10):
            out = _output(draw, "sens.csv", files)
            argv += ["-o", out]
            outputs.append(out)
        quiet = not chance(draw, 30)
        if quiet:
            argv.append("-q")
        if chance(draw, 10):
            argv += ["--top", draw(st.sampled_from(("0", "1", "5", "-1", "x", "1e3")))]
    elif command in ("urdf", "urdf-at"):
        argv = ["urdf", g_arg]
        if command == "urdf" and chance(draw, 10):
            pass  # to standard output
        else:
            out = _output(draw, "o.urdf", files)
            argv += ["-o", out]
            outputs.append(out)
        if command == "urdf-at":
            steps = len(plans[0].values) if plans else 5
            step = str(draw(st.integers(0, steps - 1)))
            if chance(draw, 15):
                step = draw(st.sampled_from((str(steps), "-1", "x", "", "99999999999", "1.5")))
            argv += ["--at", f"{s_arg}:{step}"]
            if outputs and Path(outputs[0]).name:
                outputs.append(str(Path(outputs[0]).with_suffix(".pose.yaml")))
    elif command == "mjcf":
        out = _output(draw, "o.xml", files)
        argv = ["mjcf", g_arg, "-o", out]
        outputs.append(out)
    elif command == "draw":
        out = _output(draw, draw(st.sampled_from(("d.png", "d.svg", "d.txt"))), files)
        argv = ["draw", g_arg, "-o", out]
        outputs.append(out)
    elif command == "loads":
        loads = draw(load_cases(axle))
        files["c.yaml"] = loads.text
        extra["c.yaml"] = loads
        out = _output(draw, table, files)
        quiet = not chance(draw, 30)
        argv = ["loads", g_arg, s_arg, "--cases", "c.yaml", "-o", out] + (["-q"] if quiet else [])
        outputs.append(out)
    elif command == "validate":
        engine = draw(st.sampled_from(("pointwise",) * 4 + ("mujoco",)))
        argv = ["validate", g_arg, s_arg, "--engine", engine]
        if chance(draw, 10):
            argv += ["--tolerance", draw(st.sampled_from(("1e-6", "0", "-1", "x", "1e-12")))]
    elif command == "study":
        study = draw(studies(geometry.data))
        files["study.yaml"] = study.text
        extra["study.yaml"] = study
        out = draw(st.sampled_from(("res",) * 12 + ("res/", "new/res", "g.yaml", ".")))
        argv = ["study", "study.yaml", "-o", out, "--scheduler", "none"]
        if chance(draw, 30):
            argv.append("--steps")
        quiet = not chance(draw, 30)
        argv += ["-q"] if quiet else []
        if chance(draw, 30):  # run it, maybe change an input, then --resume
            before = list(argv)
            argv.append("--resume")
            edit = draw(st.sampled_from(("none", "g.yaml", "s.yaml", "study.yaml", "parts")))
            if edit in files:
                edits[edit] = files[edit] + b"# changed after the run\n"
            elif edit == "parts":
                edits[os.path.join(out, "variants.parquet")] = b""  # a stranger's file
        outputs.append(out)
    else:  # setup
        argv = ["setup", g_arg]
        argv += draw(_setup_arguments(geometry.data))
        if axle and chance(draw, 40):
            argv += ["--side", draw(st.sampled_from(("left", "right")))]
        if chance(draw, 35):
            out = _output(draw, "set.yaml", files)
            argv += ["-o", out]
            outputs.append(out)
        if chance(draw, 25):
            out = _output(draw, "sheet.csv", files)
            if outputs and chance(draw, 20):
                out = outputs[0]  # the sheet onto the solved geometry
            argv += ["--csv", out]
            outputs.append(out)
    stale, links = [], {}
    for out in outputs:
        if _plain_file(out) and out not in files and out not in stale + list(links):
            if chance(draw, 1):  # a symlink to an input in the output's place
                links[out] = draw(st.sampled_from(sorted(files)))
            elif chance(draw, 20):
                stale.append(out)
    return Case(
        command, argv, files, outputs, geometry, sweep, plans, stale, quiet, links, extra,
        before, edits,
    )  # fmt: skip


def _has(geometry, what: str) -> bool:
    """Whether the geometry data (as drawn, maybe broken) has a shim, a trackrod or fixed
    toe link (every mechanism but the trailing arm: the ``--trackrod`` adjuster), or a
    pushrod."""
    if not isinstance(geometry, dict):
        return False
    if _is_axle_data(geometry):
        ac = geometry.get("axle_config") if isinstance(geometry.get("axle_config"), dict) else {}
        setup = ac.get("left_setup") if isinstance(ac.get("left_setup"), dict) else {}
        actuation = ac.get("actuation") if isinstance(ac.get("actuation"), dict) else {}
        return {
            "shim": isinstance(setup.get("camber_shim"), dict),
            "link": _kind(geometry) not in (None, "trailing_arm"),
            "pushrod": actuation.get("type") == "pushrod_rocker",
        }[what]
    config = geometry.get("config") if isinstance(geometry.get("config"), dict) else {}
    if what == "shim":
        return isinstance(config.get("camber_shim"), dict)
    if what == "link":
        return _kind(geometry) != "trailing_arm" and _is_rack(geometry) is not None
    actuation = geometry.get("actuation")
    return isinstance(actuation, dict) and actuation.get("type") == "pushrod_rocker"


@st.composite
def _setup_arguments(draw, geometry) -> list[str]:
    """Rows (--shim, --trackrod, --pushrod, --sensitivities) or targets (--camber, ...),
    mostly for the parts the corner has."""
    argv = []
    anything = chance(draw, 15)  # also flags for parts the corner lacks
    wild_number = st.sampled_from(("nan", "inf", "abc", "1e9", "-1e300", "", ",", "5,,6"))
    if draw(st.booleans()):  # rows
        for flag, low, high, part in (
            ("--shim", 0, 60, "shim"),
            ("--trackrod", -10, 10, "link"),
            ("--pushrod", -10, 10, "pushrod"),
        ):
            if (anything or _has(geometry, part)) and chance(draw, 50):
                number = st.one_of(st.integers(low, high), small(max(-low, high)))
                if chance(draw, 10):
                    number = st.one_of(number, wild_number)
                values = _numbers_argument(draw(st.lists(number, min_size=1, max_size=4)))
                # "--trackrod -1,1" reads as an option to argparse: "--trackrod=-1,1" works
                argv += [f"{flag}={values}"] if draw(st.booleans()) else [flag, values]
        if draw(st.booleans()):
            argv.append("--sensitivities")
            if draw(st.booleans()):
                pitch = draw(st.sampled_from(("1.5", "1", "0", "-1", "nan")))
                argv += ["--thread-pitch", pitch]
    else:  # targets
        for flag, low, high, part in (
            ("--camber", -6, 2, "shim"),
            ("--toe", -1, 1, "link"),
            ("--ride-height-change", -20, 20, "pushrod"),
        ):
            if (anything or _has(geometry, part)) and chance(draw, 60):
                value = draw(st.integers(1000 * low, 1000 * high).map(lambda i: i / 1000))
                if chance(draw, 10):
                    value = draw(st.sampled_from(("nan", "100", "-45", "x", "1e400")))
                argv += [flag, value if isinstance(value, str) else f"{value:g}"]
    return argv


def _plain_file(out: str) -> bool:
    return out not in ("", ".", "new/") and not out.startswith(("g.yaml/", "new/"))


# --------------------------------------------------------------------------- running


STALE = b"stale contents from an earlier run\n"


@dataclass
class Outcome:
    code: int
    stdout: str
    stderr: str
    new: set[str]  # paths created (files and folders), relative
    changed: set[str]  # files that existed and changed
    removed: set[str]
    texts: dict[str, bytes]  # contents of every file afterwards, by relative path
    directory: str  # the run directory (removed after the checks)
    mujoco_log: bool


def _snapshot(root: Path) -> dict[str, tuple]:
    out = {}
    for folder, dirs, names in os.walk(root):
        for d in dirs:
            path = Path(folder, d)
            out[str(path.relative_to(root))] = ("dir",)
        for n in names:
            path = Path(folder, n)
            st_ = path.lstat()
            digest = hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else ""
            out[str(path.relative_to(root))] = (st_.st_mode, st_.st_size, st_.st_mtime_ns, digest)
    return out


@contextlib.contextmanager
def run_case(case: Case):
    """Run the case in a fresh folder in process; yield its Outcome, then remove the folder.

    An exception escaping main() propagates as itself (invariant 4), with the
    case attached as a note.
    """
    from pin_susp.cli import main

    root_log = (ROOT / "MUJOCO_LOG.TXT").exists()
    with tempfile.TemporaryDirectory(prefix="pin_susp_fuzz-") as tmp:
        run_dir = Path(tmp)
        for name, text in case.files.items():
            (run_dir / name).write_bytes(text)
        for name in case.stale:
            path = run_dir / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(STALE)
        for name, target in case.links.items():
            (run_dir / name).symlink_to(target)
        cwd = os.getcwd()
        if case.before is not None:  # its own invariants are another case's
            os.chdir(run_dir)
            try:
                with (
                    contextlib.redirect_stdout(io.StringIO()),
                    contextlib.redirect_stderr(io.StringIO()),
                ):
                    main(list(case.before))
            finally:
                os.chdir(cwd)
            for name, text in case.edits.items():
                if (run_dir / name).parent.is_dir():  # (the first run may have written none)
                    (run_dir / name).write_bytes(text)
        before = _snapshot(run_dir)
        out, err = io.StringIO(), io.StringIO()
        os.chdir(run_dir)
        start = time.perf_counter()
        try:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = main(list(case.argv))
        except Exception as exc:
            COUNTS[case.command, type(exc).__name__] += 1
            BY_MECHANISM[label(case.geometry.data), type(exc).__name__] += 1
            exc.add_note(f"escaped pin_susp.cli.main() (invariant 4, never a traceback)\n{case!r}")
            exc.add_note(f"stderr: {err.getvalue()!r}")
            raise
        finally:
            os.chdir(cwd)
            SLOWEST.append((time.perf_counter() - start, " ".join(map(_quote, case.argv))))
            SLOWEST.sort(reverse=True)
            del SLOWEST[3:]
        COUNTS[case.command, code] += 1
        BY_MECHANISM[label(case.geometry.data), code] += 1
        after = _snapshot(run_dir)
        texts = {
            name: (run_dir / name).read_bytes()
            for name, info in after.items()
            if info[0] != "dir" and (run_dir / name).is_file()
        }
        yield Outcome(
            code=code,
            stdout=out.getvalue(),
            stderr=err.getvalue(),
            new=set(after) - set(before),
            changed={k for k in set(after) & set(before) if after[k] != before[k]},
            removed=set(before) - set(after),
            texts=texts,
            directory=tmp,
            mujoco_log=any(Path(k).name == "MUJOCO_LOG.TXT" for k in after)
            or (not root_log and (ROOT / "MUJOCO_LOG.TXT").exists()),
        )


# --------------------------------------------------------------------------- invariants

EXIT_CODES = {
    "sweep": {0, 1, 2},
    "sensitivity": {0, 1, 2},
    "urdf": {0, 2},
    "urdf-at": {0, 2},
    "mjcf": {0, 2},
    "setup": {0, 2},
    "draw": {0, 2},
    "loads": {0, 1, 2},
    "validate": {0, 1, 2},
    "study": {0, 1, 2},
}
_WARNING = re.compile(r"pin-susp: warning: (\d+) of (\d+) steps did not converge")
_STEPS = re.compile(r"\bsteps? (\d+(?:, \d+)*)")


def check_case(case: Case, o: Outcome) -> None:
    """Assert the invariants of one run; each assert is its own line (one bug per line)."""
    context = f"\n{case!r}\nexit {o.code}\nstdout: {o.stdout[-2000:]!r}\nstderr: {o.stderr!r}"
    # 4. never a traceback
    assert "Traceback" not in o.stderr and "Traceback" not in o.stdout, "traceback" + context
    # exit codes the command documents
    expected = EXIT_CODES[case.command]
    if case.command == "sensitivity" and "--sweep" not in case.argv:
        expected = {0, 2}
    assert isinstance(o.code, int) and o.code in expected, "unexpected exit code" + context
    lines = [line for line in o.stderr.splitlines() if line.strip()]
    named = expected_refusal(case)
    if named is not None and case.command != "study":
        # a degenerate mechanism: refused at load, on one line naming its points
        assert o.code == 2, f"a degenerate geometry ({named}) not refused" + context
        if len(lines) == 1 and "g.yaml: " in lines[0]:
            assert any(n in lines[0] for n in named), f"the refusal names none of {named}" + context
    # 5. nothing outside the declared outputs; no temporary file; no MuJoCo log
    leftovers = [p for p in o.new | o.changed if Path(p).name.startswith(".pin_susp-")]
    assert not leftovers, f"temporary files left: {leftovers}" + context
    assert not o.mujoco_log, "MUJOCO_LOG.TXT written" + context
    assert not o.removed, f"files removed: {sorted(o.removed)}" + context
    inputs_changed = sorted(set(case.files) & o.changed)
    assert not inputs_changed, f"input files changed: {inputs_changed}" + context
    paths_out = [os.path.normpath(out) for out in case.outputs]
    if len(set(paths_out)) < len(paths_out):
        assert o.code == 2, "two outputs on one path: one of them lost, not refused" + context
    if o.code == 2:
        # 3. one line naming the problem, nothing written
        assert len(lines) == 1, f"exit 2 with {len(lines)} stderr lines" + context
        assert lines[0].startswith("pin-susp"), "exit 2 line not from pin-susp" + context
        assert not o.new, f"exit 2 but created {sorted(o.new)}" + context
        assert not o.changed, f"exit 2 but changed {sorted(o.changed)}" + context
        return
    allowed = _declared(case)
    trees = [os.path.normpath(out) + os.sep for out in case.outputs if case.command == "study"]
    stray = sorted(p for p in o.new | o.changed if p not in allowed
                   and not any(p.startswith(t) for t in trees))  # fmt: skip
    assert not stray, f"wrote outside the declared outputs: {stray}" + context
    errors = [line for line in lines if line.startswith("pin-susp: error")]
    assert not errors, f"exit {o.code} with an error line" + context
    for out in case.outputs:
        written = o.texts.get(os.path.normpath(out), STALE) != STALE
        if case.command == "study":
            written = os.path.normpath(os.path.join(out, "variants.parquet")) in o.texts
        # a report of a sweep where no step converged has nothing to draw: exit 1, said so
        skipped = o.code == 1 and f"{out} not drawn" in o.stderr
        assert written or skipped, f"exit {o.code} but {out} not written" + context
    if case.quiet and o.code == 0:
        assert o.stdout == "", "-q printed on stdout" + context
    if case.command in ("sweep", "loads"):
        _check_sweep(case, o, lines, context)
    elif case.command == "study":
        _check_study(case, o, context)
    elif case.command == "sensitivity":
        _check_sensitivity(case, o, lines, context)
    elif case.command == "setup":
        _check_setup(case, o, context)
    elif case.command == "urdf-at" and len(case.outputs) == 2:
        pose = yaml.safe_load(o.texts[os.path.normpath(case.outputs[1])])
        values = list(pose["joints"].values())
        assert all(math.isfinite(v) for v in values), "pose sidecar not finite" + context


def _declared(case: Case) -> set[str]:
    allowed = set()
    for out in case.outputs:
        path = Path(os.path.normpath(out))
        allowed.add(str(path))
        allowed.update(str(p) for p in path.parents if str(p) != ".")
    return allowed


def parse_csv(text: str) -> tuple[list[str], list[list[str]]]:
    """A pin_susp CSV: '#' comment lines, a header, rows (no quoting in pin_susp output)."""
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    assert lines, "no header"
    header = lines[0].split(",")
    return header, [line.split(",") for line in lines[1:]]


def _finite_or_empty(cell: str) -> bool:
    if cell == "":
        return True
    try:
        return math.isfinite(float(cell)) and cell.strip().lower() not in ("nan", "inf")
    except ValueError:
        return False


def _warning(lines, context) -> tuple[int, int, set[int], list[str]]:
    warnings = [line for line in lines if _WARNING.match(line)]
    assert len(warnings) == 1, "exit 1 without one 'steps did not converge' line" + context
    m = _WARNING.match(warnings[0])
    named = {int(x) for group in _STEPS.findall(warnings[0]) for x in group.split(", ")}
    return int(m.group(1)), int(m.group(2)), named, warnings


def _check_sweep(case: Case, o: Outcome, lines, context) -> None:
    """A sweep's or a loads run's table (CSV, or Parquet read back with pyarrow): the
    sources' hashes, one row per step (and load case), the flags, and the rows."""
    raw = o.texts[os.path.normpath(case.outputs[0])]
    if case.outputs[0].endswith(".parquet"):
        assert raw[:4] == b"PAR1", "a .parquet output that is not Parquet" + context
        header, rows, meta = parquet_rows(raw)
        shas = {k: json.loads(meta[k])["sha256"] for k in ("geometry", "sweep") if k in meta}
    else:
        text = raw.decode()
        shas = {}
        for what in ("geometry", "sweep"):
            line = next((x for x in text.splitlines() if x.startswith(f"# {what}: ")), "")
            sha = re.search(r"sha256=([0-9a-f]{64})", line)
            if sha:
                shas[what] = sha.group(1)
        header, rows = parse_csv(text)
    for what, name in (("geometry", case.argv[1]), ("sweep", case.argv[2])):
        assert what in shas, f"no sha256 of the {what} in the output" + context
        digest = hashlib.sha256(case.files[os.path.normpath(name)]).hexdigest()
        assert shas[what] == digest, f"the output's sha256 of {name} is not its bytes'" + context
    for name in SOLVER_COLUMNS:
        assert name in header, f"no {name} column" + context
    col = {name: i for i, name in enumerate(header)}
    assert all(len(r) == len(header) for r in rows), "a row with a wrong cell count" + context
    per_step = 1
    if case.command == "loads":
        names = list(dict.fromkeys(r[col["load_case"]] for r in rows))
        per_step = max(len(names), 1)
        expected_cases = [r[col["load_case"]] for r in rows[:per_step]] * (len(rows) // per_step)
        assert [r[col["load_case"]] for r in rows] == expected_cases, "load case order" + context
    steps_of = [str(i // per_step) for i in range(len(rows))]
    assert [r[0] for r in rows] == steps_of, "step_index" + context
    if case.plans:
        n = len(case.plans[0].values) * per_step
        assert len(rows) == n, "not one row per step (and load case)" + context
    flags = [r[col["solver_converged"]] for r in rows]
    assert set(flags) <= {"True", "False"}, f"solver_converged cells {set(flags)}" + context
    failed = sorted({i // per_step for i, f in enumerate(flags) if f == "False"})
    for i in range(0, len(rows), per_step):  # a step's flag is every case's
        assert len(set(flags[i : i + per_step])) == 1, (
            f"step {i // per_step}: mixed flags" + context
        )
    solver = {col[n] for n in SOLVER_COLUMNS}
    text = {col["solver_converged"]}
    if case.command == "loads":  # every row names its case, and whether it is at a toggle
        solver |= {col["load_case"], col["loads_unbounded"]}
        text.add(col["load_case"])
    for i, r in enumerate(rows):
        if flags[i] == "True":
            residual = float(r[col["solver_max_residual"]])
            assert math.isfinite(residual), f"row {i}: residual {residual}" + context
            assert residual <= RESIDUAL_LIMIT, f"row {i}: residual {residual}" + context
            bad = [header[j] for j, c in enumerate(r) if j not in text
                   and not _finite_or_empty(c)]  # fmt: skip
            assert not bad, f"row {i}: non-finite cells {bad[:5]}" + context
        else:
            filled = [header[j] for j, c in enumerate(r) if j not in solver and c != ""]
            assert not filled, f"failed row {i} has cells {filled[:5]}" + context
    if o.code == 0:
        # 1. exit 0 only when every row converged
        assert not failed, f"exit 0 with steps {failed[:10]} flagged False" + context
        assert not any(_WARNING.match(line) for line in lines), "exit 0 with a warning" + context
    else:
        # 2. exit 1 only with the failing steps named
        assert failed, "exit 1 but every row converged" + context
        n, total, named, _ = _warning(lines, context)
        assert n == len(failed) and total == len(rows) // per_step, "warning counts" + context
        assert named <= set(failed), f"named {sorted(named - set(failed))} converged" + context
        assert set(failed[:10]) <= named, f"failed {failed[:10]}, named {sorted(named)}" + context
    if "scope: axle" in case.geometry.text.decode("utf-8", "replace"):
        _check_axle_rows(case, o, header, rows[::per_step], context)
    else:
        _check_geometry_of_rows(case, o, header, rows[::per_step], context)


def _check_sensitivity(case: Case, o: Outcome, lines, context) -> None:
    states = set()
    if case.outputs:
        header, rows = parse_csv(o.texts[os.path.normpath(case.outputs[0])].decode())
        assert header[:5] == ["step_index", "metric", "hardpoint", "axis", "value"], (
            "sensitivity header" + context
        )
        bad = [r for r in rows if len(r) != len(header) or not _finite_or_empty(r[4])]
        assert not bad, f"sensitivity rows {bad[:3]}" + context
        states = {int(r[0]) for r in rows if r[4] != ""}
    if o.code == 1:
        n, total, named, _ = _warning(lines, context)
        if case.plans:
            assert total == len(case.plans[0].values), "warning step count" + context
        assert not named & states, f"steps {sorted(named & states)} named but solved" + context
    elif case.plans and case.outputs:
        assert states == set(range(len(case.plans[0].values))), "a step missing" + context


def _check_setup(case: Case, o: Outcome, context) -> None:
    for out in case.outputs:
        text = o.texts[os.path.normpath(out)]
        if out.endswith(".csv"):
            _, rows = parse_csv(text.decode())
            bad = [c for r in rows for c in r[1:] if not _finite_or_empty(c)]
            assert not bad, f"setup sheet cells {bad[:5]}" + context
        else:
            from pin_susp import load_geometry
            from pin_susp.subjects.axle import load_axle

            load = load_axle if b"scope: axle" in text else load_geometry
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                load(Path(o.directory) / os.path.normpath(out))  # reads back


def _check_study(case: Case, o: Outcome, context) -> None:
    """variants.parquet: exit 0 only with every variant converged at every step, exit 1
    only with some flagged (steps_failed > 0, or an error saying why); steps.parquet
    (--steps): a converged step's residual within 1e-9 mm, a failed one's blank."""
    import pyarrow.parquet as pq

    out = Path(o.directory) / os.path.normpath(case.outputs[0])
    variants = pq.read_table(out / "variants.parquet").to_pylist()
    assert variants, "no variant rows" + context
    flagged = [v["variant_id"] for v in variants if not v["converged"]]
    for v in variants:
        if v["converged"]:
            assert v["steps_failed"] == 0 and not v["error"], f"variant {v}" + context
        else:
            assert v["steps_failed"] > 0 or v["error"], f"variant {v} flagged, no cause" + context
    if o.code == 0:
        assert not flagged, f"exit 0 with variants {flagged[:10]} flagged" + context
    else:
        assert flagged, "exit 1 but every variant converged" + context
    if "--steps" in case.argv:
        import pyarrow.dataset as ds

        steps = ds.dataset(out / "steps.parquet").to_table().to_pylist()
        failed: Counter = Counter()
        for row in steps:
            if row["solver_converged"]:
                r = row["solver_max_residual"]
                assert r is not None and r <= RESIDUAL_LIMIT, f"a step's residual {r}" + context
            else:
                failed[row["variant_id"]] += 1
        for v in variants:
            if not v["error"]:
                assert failed[v["variant_id"]] == v["steps_failed"], "steps_failed" + context


# ------------------------------------------------- independent check of converged rows


def chirality(a, b, c, d) -> float:
    u, v, w = ([q[i] - a[i] for i in range(3)] for q in (b, c, d))
    det = (
        u[0] * (v[1] * w[2] - v[2] * w[1])
        - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0])
    )
    scale = math.sqrt(sum(x * x for x in u) * sum(x * x for x in v) * sum(x * x for x in w))
    return det / scale if scale > 0 else 0.0


Loop = tuple[str, str, str, str]
Line = tuple[str, str, str]
WHEEL_MOUNTED = ("axle_inboard", "axle_outboard", "wheel_center", "axle_midpoint")
WHEEL_MOUNTED += ("wheel_inboard", "wheel_outboard")


def bodies(g) -> tuple[list[str], list[list[str]], list[Loop], list[Line]]:
    """(chassis points, rigid groups incl. rods, branch loops, point-on-line conditions)
    of an as-set Geometry, per mechanism as docs/geometry.md describes it (written
    here, not read from pin_susp.model.mechanisms: an independent check). A loop's four
    points keep the sign of their chirality; a line (p, a, b) keeps p on the line
    through a and b, on a's design side."""
    kind = getattr(g, "type", "double_wishbone")
    if kind == "macpherson":
        return _macpherson(g)
    if kind == "multilink":
        return _multilink(g)
    if kind == "trailing_arm":
        return _trailing_arm(g)
    return (*_double_wishbone(g), [])


def _double_wishbone(g) -> tuple[list[str], list[list[str]], list[Loop]]:
    inner, outer = g.steering_points
    pushrod = g.has_pushrod
    mount = g.actuation_mount
    chassis = [
        "lower_wishbone_inboard_front",
        "lower_wishbone_inboard_rear",
        "upper_wishbone_inboard_front",
        "upper_wishbone_inboard_rear",
    ]
    lower = chassis[:2] + ["lower_wishbone_outboard"]
    upper = chassis[2:] + ["upper_wishbone_outboard"]
    upright = ["lower_wishbone_outboard", "upper_wishbone_outboard", "axle_inboard"]
    upright += ["axle_outboard", outer, "wheel_center", "axle_midpoint"]
    upright += ["wheel_inboard", "wheel_outboard"]
    groups = [lower, upper, upright, [inner, outer]]
    rocker: list[str] = []
    on = {"lower_wishbone": lower, "upright": upright}[mount]
    if g.steering == "none":
        chassis.append(inner)
    if pushrod:
        chassis += ["rocker_axis_a", "rocker_axis_b"]
        rocker = ["rocker_axis_a", "rocker_axis_b", "pushrod_inboard"]
        on.append("pushrod_outboard")
        groups += [rocker, ["pushrod_outboard", "pushrod_inboard"]]
    if g.spring == "coilover":
        chassis.append("strut_top")
        (rocker if pushrod else on).append("strut_bottom")
    loops = [
        (
            "upper_wishbone_inboard_front",
            "upper_wishbone_inboard_rear",
            "lower_wishbone_outboard",
            "upper_wishbone_outboard",
        ),
        ("lower_wishbone_outboard", "upper_wishbone_outboard", inner, outer),
    ]
    if pushrod:
        loops.append(("rocker_axis_a", "rocker_axis_b", "pushrod_outboard", "pushrod_inboard"))
    return chassis, groups, loops


def _macpherson(g) -> tuple[list[str], list[list[str]], list[Loop], list[Line]]:
    """Lower arm on two chassis pivots, the upright on its ball joint carrying the strut
    (clamped at strut_bottom) whose axis passes through the top mount; the trackrod or
    fixed toe link."""
    inner, outer = g.steering_points
    lbj = "lower_wishbone_outboard"
    chassis = ["lower_wishbone_inboard_front", "lower_wishbone_inboard_rear", "strut_top"]
    lower = chassis[:2] + [lbj]
    upright = [lbj, "strut_bottom", outer, *WHEEL_MOUNTED]
    if g.steering == "none":
        chassis.append(inner)
    loops = [(lbj, "strut_top", inner, outer)]
    return chassis, [lower, upright, [inner, outer]], loops, [("strut_top", lbj, "strut_bottom")]


def _multilink(g) -> tuple[list[str], list[list[str]], list[Loop], list[Line]]:
    """Five rods (four links and the trackrod or fixed toe link) between the chassis (or
    the rack) and the upright."""
    inner, outer = g.steering_points
    uf, ur, lf, lr = ((f"{link}_inboard", f"{link}_outboard") for link in LINKS)
    chassis = [uf[0], ur[0], lf[0], lr[0]]
    upright = [uf[1], ur[1], lf[1], lr[1], outer, *WHEEL_MOUNTED]
    if g.spring == "coilover":
        chassis.append("strut_top")
        upright.append("strut_bottom")
    if g.steering == "none":
        chassis.append(inner)
    groups = [list(uf), list(ur), list(lf), list(lr), [inner, outer], upright]
    # the tree's declared branches (pin_susp/mechanisms/multilink.py, the file's contract)
    loops = [
        (ur[0], uf[0], lf[1], uf[1]),
        (uf[0], ur[0], lf[1], ur[1]),
        (lf[0], lr[0], uf[1], lr[1]),
        (lf[1], uf[1], inner, outer),
    ]
    return chassis, groups, loops, []


def _trailing_arm(g) -> tuple[list[str], list[list[str]], list[Loop], list[Line]]:
    """One arm turning about its two chassis pivots, carrying the spindle (and the
    coilover's bottom)."""
    pivots = ["arm_pivot_inboard", "arm_pivot_outboard"]
    chassis = list(pivots)
    arm = pivots + list(WHEEL_MOUNTED)
    if g.spring == "coilover":
        chassis.append("strut_top")
        arm.append("strut_bottom")
    return chassis, [arm], [], []


def design_points(g) -> dict[str, list[float]]:
    """Every point of the as-set geometry at its design state, mm (docs/geometry.md)."""
    p = {name: [1000.0 * x for x in v] for name, v in g.hardpoints.items()}
    ai, ao = p["axle_inboard"], p["axle_outboard"]
    a = _unit([ao[i] - ai[i] for i in range(3)])
    offset, half = 1000.0 * g.wheel.offset, 500.0 * g.wheel.section_width
    wc = [ao[i] - offset * a[i] for i in range(3)]
    p["wheel_center"] = wc
    p["axle_midpoint"] = [(ai[i] + ao[i]) / 2 for i in range(3)]
    p["wheel_inboard"] = [wc[i] - half * a[i] for i in range(3)]
    p["wheel_outboard"] = [wc[i] + half * a[i] for i in range(3)]
    down = [a[2] * a[0], a[2] * a[1], -1.0 + a[2] * a[2]]  # −Ẑ minus its part along â
    n = math.sqrt(sum(x * x for x in down))
    if n > 1e-12:
        r = 1000.0 * g.wheel.radius
        p["contact_patch_center"] = [wc[i] + r * down[i] / n for i in range(3)]
    return p


def _dist(a, b) -> float:
    return math.sqrt(sum((a[i] - b[i]) ** 2 for i in range(3)))


def _off_line(p, a, b) -> tuple[float, float, float]:
    """(distance of p from the line through a and b, |p − a| / |b − a|: how much an
    error in a or b grows at p, (p − a)·(b − a)/|b − a|: where along the line p is)."""
    d = [b[i] - a[i] for i in range(3)]
    n = math.sqrt(sum(x * x for x in d))
    if n == 0.0:
        return _dist(p, a), math.inf, 0.0
    w, u = [p[i] - a[i] for i in range(3)], [x / n for x in d]
    cross = (w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2], w[0] * u[1] - w[1] * u[0])
    along = sum(w[i] * u[i] for i in range(3))
    return math.sqrt(sum(x * x for x in cross)), _dist(p, a) / n, along


def _check_geometry_of_rows(case: Case, o: Outcome, header, rows, context) -> None:
    """Independently of the solver's own flags: converged rows close the loops, meet the
    targets and stay on the design branch, read from the CSV's point columns."""
    converged = [r for r in rows if r[header.index("solver_converged")] == "True"]
    if not converged:
        return
    from pin_susp import Corner

    with warnings.catch_warnings():  # implausible values: the run has reported them
        warnings.simplefilter("ignore")
        g = Corner(str(Path(o.directory) / "g.yaml")).geometry
    ROWS_CHECKED[g.type] += len(converged)
    _check_rows_of(g, case.plans, header, converged, context)


def _check_axle_rows(case: Case, o: Outcome, header, rows, context) -> None:
    """An axle's converged rows, each corner as a corner from its own columns (left_…,
    right_…: every rigid distance, the chassis, the rack's line, the branches, its
    targets), and the heave and roll targets from both wheel centres."""
    converged = [r for r in rows if r[header.index("solver_converged")] == "True"]
    if not converged:
        return
    from pin_susp.subjects.axle import load_axle

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        axle = load_axle(str(Path(o.directory) / "g.yaml"))
    ROWS_CHECKED[f"{axle.left.type} axle"] += len(converged)
    design = {}
    from pin_susp.analyses.setup import apply_setup

    for side in ("left", "right"):
        g = apply_setup(axle.corner(side))  # as set, as AxleModel solves it
        design[side] = design_points(g)
        prefix = f"{side}_"
        renamed = [
            h[len(prefix) :]
            if h.startswith(prefix)
            else ("other " + h if h.startswith(("left_", "right_")) else h)
            for h in header
        ]
        plans = [p for p in case.plans or () if p.side == side and p.mode != "quantity"]
        _check_rows_of(g, plans, renamed, converged, context)
    col = {name: i for i, name in enumerate(header)}
    scale = max(abs(x) for v in design["left"].values() for x in v)
    tol = GEOMETRIC_TOLERANCE + 1e-12 * scale
    for r in converged:
        step = int(r[0])

        def at(side, name, r=r):
            return [float(r[col[f"{side}_{name}_{a}"]]) for a in "xyz"]

        rise = {s: at(s, "wheel_center")[2] - design[s]["wheel_center"][2] for s in design}
        for plan in case.plans or ():
            if plan.mode != "quantity":
                continue
            if plan.point == "heave":
                err = abs((rise["left"] + rise["right"]) / 2 - plan.values[step])
            else:
                across = (
                    at("left", "contact_patch_center")[1] - at("right", "contact_patch_center")[1]
                )
                roll = math.atan2(rise["left"] - rise["right"], across)
                err = abs(roll - math.radians(plan.values[step])) * abs(across)
            assert err <= tol, f"step {step}: the axle's {plan.point} off by {err} mm" + context


def _check_rows_of(g, plans, header, converged, context) -> None:
    """The rows of one corner ``g`` (as set): from the columns named as a corner's."""
    design = design_points(g)
    col = {name: i for i, name in enumerate(header)}
    chassis, groups, loops, lines = bodies(g)
    scale = max(abs(x) for v in design.values() for x in v)
    tol = GEOMETRIC_TOLERANCE + 1e-12 * scale
    signs = {}
    for loop in loops:
        c = chirality(*(design[n] for n in loop))
        if abs(c) >= 1e-6:
            signs[loop] = math.copysign(1.0, c)
    for r in converged:
        step = r[0]

        def at(name, r=r):
            cells = [col.get(f"{name}_{a}") for a in "xyz"]
            if None in cells:
                return None
            return [float(r[i]) for i in cells]

        for point, a, b in lines:  # before the chassis: a strut_top moved off its line
            p, pa, pb = at(point), at(a), at(b)
            if None in (p, pa, pb):
                continue
            off, lever, along = _off_line(p, pa, pb)
            err = tol * max(1.0, lever)  # the line's direction from two CSV points
            assert off <= err, f"step {step}: {point} {off} mm off the line {a}→{b}" + context
            # and on the design side of a along it (the other side: the strut end for end)
            side = _off_line(design[point], design[a], design[b])[2]
            assert along * side > 0.0, f"step {step}: {point} crossed {a} on {a}→{b}" + context
        for name in chassis:
            p = at(name)
            if p is not None:
                moved = _dist(p, design[name])
                assert moved <= tol, f"step {step}: chassis point {name} moved {moved}" + context
        if g.steering == "rack":
            p, d = at("trackrod_inboard"), design["trackrod_inboard"]
            off = max(abs(p[0] - d[0]), abs(p[2] - d[2]))
            assert off <= tol, f"step {step}: the rack left its line by {off} mm" + context
        for group in groups:
            present = [n for n in group if at(n) is not None and n in design]
            for i, a in enumerate(present):
                for b in present[i + 1 :]:
                    err = abs(_dist(at(a), at(b)) - _dist(design[a], design[b]))
                    assert err <= tol, f"step {step}: |{a} - {b}| off by {err} mm" + context
        for loop, sign in signs.items():
            points = [at(n) for n in loop]
            c = chirality(*points)
            assert c * sign > -1e-9, f"step {step}: off the design branch of {loop}" + context
        if "wheel_travel" in col and r[col["wheel_travel"]] != "":
            travel = float(r[col["wheel_travel"]])
            err = abs(travel - (at("wheel_center")[2] - design["wheel_center"][2]))
            assert err <= tol, f"step {step}: wheel_travel off by {err} mm" + context
        for plan in plans or ():
            p = at(plan.point)
            if p is None or plan.point not in design:
                continue
            value = plan.values[int(step)]
            reached = sum(p[i] * plan.direction[i] for i in range(3))
            if plan.mode == "relative":
                reached -= sum(design[plan.point][i] * plan.direction[i] for i in range(3))
            err = abs(reached - value)
            assert err <= tol, f"step {step}: target {plan.point} off by {err} mm" + context


def summary() -> str:
    """Counts per exit code, per command and per mechanism (as the geometry file names
    it, before it is read: a file that names none is "(none)")."""
    by_code: Counter = Counter()
    by_command: dict[str, Counter] = {}
    for (command, code), n in COUNTS.items():
        by_code[code] += n
        by_command.setdefault(command, Counter())[code] += n
    total = sum(by_code.values())
    lines = [f"pin-susp fuzz: {total} runs"]
    lines.append(
        "  by exit code: " + ", ".join(f"{k}: {v}" for k, v in sorted(by_code.items(), key=str))
    )
    for command in sorted(by_command):
        c = by_command[command]
        counts = ", ".join(f"exit {k}: {v}" for k, v in sorted(c.items(), key=str))
        lines.append(f"  {command:<12} {sum(c.values()):>6}  ({counts})")
    by_mechanism: dict[str, Counter] = {}
    for (mechanism, code), n in BY_MECHANISM.items():
        by_mechanism.setdefault(mechanism, Counter())[code] += n
    for mechanism in sorted(by_mechanism):
        c = by_mechanism[mechanism]
        counts = ", ".join(f"exit {k}: {v}" for k, v in sorted(c.items(), key=str))
        rows = (
            f"; {ROWS_CHECKED[mechanism]} converged rows checked"
            if mechanism.removesuffix(" axle") in MECHANISMS
            else ""
        )
        lines.append(f"  {mechanism:<16} {sum(c.values()):>6}  ({counts}{rows})")
    if SLOWEST:
        slow = ", ".join(f"{t:.2f} s ({argv[:60]})" for t, argv in SLOWEST)
        lines.append(f"  slowest: {slow}")
    if FOUND:
        lines.append(f"  failures collected ({sum(FOUND.values())}):")
        lines += [f"    {n:>6}  {name}" for name, n in FOUND.most_common()]
    return "\n".join(lines)


def signature(exc: BaseException) -> str:
    """A short name for a failure: the broken assert, or where the exception came from."""
    import traceback

    frames = traceback.extract_tb(exc.__traceback__)
    if isinstance(exc, AssertionError) and frames:
        first = str(exc).split("\n", 1)[0]
        words = re.sub(r"[^A-Za-z0-9]+", "_", re.sub(r"\d+(\.\d+)?(e-?\d+)?", "N", first))
        return f"invariant-{frames[-1].lineno}-{words.strip('_')[:60]}"
    inner = [f for f in frames if "pin_susp" in f.filename and "tests" not in f.filename]
    where = inner[-1] if inner else (frames[-1] if frames else None)
    place = f"{Path(where.filename).stem}-{where.lineno}" if where else "unknown"
    return f"crash-{type(exc).__name__}-{place}"


def size(case: Case) -> tuple[int, int]:
    """How big a case is: its changes, then its text (to keep the smallest of a kind)."""
    changes = len(case.geometry.changes) + (len(case.sweep.changes) if case.sweep else 0)
    return changes, sum(len(t) for t in case.files.values()) + len(" ".join(case.argv))


def save_case(case: Case, exc: BaseException, folder: Path, keep_smaller: bool = False) -> Path:
    """Write the case as files to run by hand: g.yaml, s.yaml, command.txt, problem.txt.

    One folder per signature(); it holds the last case saved, or with
    ``keep_smaller`` the smallest.
    """
    import traceback

    where = folder / signature(exc)
    sized = where / "size.json"
    if keep_smaller and sized.exists() and tuple(json.loads(sized.read_text())) <= size(case):
        return where
    if where.exists():
        for old in where.iterdir():
            if old.is_file():
                old.unlink()
    where.mkdir(parents=True, exist_ok=True)
    for name, text in case.files.items():
        (where / name).write_bytes(text)
    command = "pin-susp " + " ".join(map(_quote, case.argv))
    (where / "command.txt").write_text(
        f"# run in this folder (outputs existing before the run: {case.stale}; "
        f"symlinks: {case.links})\n{command}\n"
    )
    problem = "".join(traceback.format_exception(exc))
    (where / "problem.txt").write_text(f"{problem}\n{case!r}\n")
    sized.write_text(json.dumps(size(case)))
    return where


# ------------------------------------------------- degenerate input, per mechanism


def _degenerate_moves(data) -> list[tuple[str, str, str, float, tuple[str, ...]]]:
    """(label, point, a, t, names): point := a + t·(b − a) makes the mechanism
    degenerate (coincident pivots, a pivot on a spindle point, a zero-length arm);
    the refusal must name one of ``names``. ``b`` is names[-1] (t = 0: onto a)."""
    kind = _kind(data)
    hp = data.get("hardpoints") if isinstance(data, dict) else None
    if kind is None or not isinstance(hp, dict):
        return []
    have = {n for n in hp if _numeric_point(hp[n]) is not None}
    moves = []

    def add(label, point, a, b, t):
        if {point, a, b} <= have:
            moves.append((label, point, a, t, (point, a, b)))

    moves_for_steering = []
    for inner, outer in (
        ("trackrod_inboard", "trackrod_outboard"),
        ("toe_link_inboard", "toe_link_outboard"),
    ):
        moves_for_steering.append(("a link of no length", outer, inner, inner, 0.0))
    add("the spin axis of no length", "axle_outboard", "axle_inboard", "axle_inboard", 0.0)
    add("a coilover of no length", "strut_bottom", "strut_top", "strut_top", 0.0)
    for args in moves_for_steering:
        add(*args)
    if kind in ("double_wishbone", "macpherson"):
        for arm in ("lower_wishbone", "upper_wishbone"):
            front, rear = f"{arm}_inboard_front", f"{arm}_inboard_rear"
            add("coincident pivots", rear, front, front, 0.0)
            for t in (0.0, 0.5, 2.0):  # the ball joint on the pivot axis: no arm
                add("a zero-length arm", f"{arm}_outboard", front, rear, t)
        if kind == "double_wishbone":
            add(
                "coincident ball joints",
                "upper_wishbone_outboard",
                "lower_wishbone_outboard",
                "lower_wishbone_outboard",
                0.0,
            )
            add("coincident rocker pivots", "rocker_axis_b", "rocker_axis_a", "rocker_axis_a", 0.0)
            add(
                "a pushrod of no length",
                "pushrod_inboard",
                "pushrod_outboard",
                "pushrod_outboard",
                0.0,
            )
            add(
                "the pushrod on the rocker axis",
                "pushrod_inboard",
                "rocker_axis_a",
                "rocker_axis_b",
                0.5,
            )
        else:
            add(
                "the strut axis of no length",
                "strut_top",
                "lower_wishbone_outboard",
                "lower_wishbone_outboard",
                0.0,
            )
            add(
                "the clamp on the ball joint",
                "strut_bottom",
                "lower_wishbone_outboard",
                "lower_wishbone_outboard",
                0.0,
            )
    elif kind == "multilink":
        for link in LINKS:
            add(
                "a link of no length", f"{link}_outboard", f"{link}_inboard", f"{link}_inboard", 0.0
            )
    elif kind == "trailing_arm":
        add(
            "coincident pivots", "arm_pivot_outboard", "arm_pivot_inboard", "arm_pivot_inboard", 0.0
        )
        for t in (0.0, 0.5, 2.0):  # the spindle on the pivot axis: an arm of no length
            add(
                "the spindle on the pivot axis",
                "axle_outboard",
                "arm_pivot_inboard",
                "arm_pivot_outboard",
                t,
            )
    return moves


@st.composite
def _degenerate(draw, data) -> str:
    """One degenerate move of the mechanism, exactly (or within a fraction of the 1e-3 mm
    that counts as one point); the expected refusal is recorded on the data."""
    moves = _degenerate_moves(data)
    if not moves:
        return "degenerate_named (not applicable)"
    label, point, a, t, names = draw(st.sampled_from(moves))
    b = names[-1]
    eps = draw(st.sampled_from((0.0, 0.0, 1e-5, 2e-4)))  # mm: all below 1e-3 mm
    hp = data["hardpoints"]
    pa, pb = _numeric_point(hp[a]), _numeric_point(hp[b])
    new = [round(pa[i] + t * (pb[i] - pa[i]), 9) + (eps if i == 2 else 0.0) for i in range(3)]
    hp[point] = dict(zip("xyz", new, strict=True))
    move = f"{point} = {a} + {t:g}·({b} − {a}) + {eps:g} mm z"
    return f"degenerate: {label}: {move} ({', '.join(names)})"


_NAMES = re.compile(r"\(([a-z_]+(?:, [a-z_]+)+)\)$")


def expected_refusal(case: Case) -> tuple[str, ...] | None:
    """The points a degenerate geometry's refusal must name, when the degenerate move
    was the geometry's only change besides small perturbations."""
    changes = case.geometry.changes
    marked = [c for c in changes if c.startswith("degenerate: ")]
    others = [c for c in changes[1:] if not c.startswith(("degenerate: ", "all ±5", "text "))]
    if len(marked) != 1 or others or re.search(r" [+-]\d", " ".join(changes[1:])):
        return None
    m = _NAMES.search(marked[0])
    return tuple(m.group(1).split(", ")) if m else None


# --------------------------------------------------------------------------- axles

AXLE_FILES = (
    "examples/axle_front.yaml",  # U-bar on the rockers, coilovers, rack
    "tests/data/axle_t_bar.yaml",  # T-bar
    "tests/data/open_kinematics_axle_geometry.yaml",  # no bar, no spring
    "tests/data/open_kinematics_axle_geometry_rocker.yaml",
)
AXLE_BASES = {name: yaml.safe_load((ROOT / name).read_text()) for name in AXLE_FILES}


def as_axle(corner: dict) -> dict:
    """A corner example as the axle of two of it (its right side mirrored): an axle of
    every mechanism (docs/axle.md)."""
    d = copy.deepcopy(corner)
    config = d.pop("config", {}) or {}
    vehicle = {
        k: config.pop(k) for k in ("cg_position", "wheelbase", "front_brake_bias") if k in config
    }
    for k in ("driven_axle", "opposite_axle_axis_height", "strut"):
        config.pop(k, None)
    left = {k: config.pop(k) for k in ("camber_shim",) if k in config}
    left |= config.pop("setup", None) or {}
    axle = {"axle_position": "front", **config}
    for k in ("actuation", "spring"):
        if k in d:
            axle[k] = d[k]
    axle |= {"anti_roll": {"type": "none"}, "heave_link": {"type": "none"}}
    if left:
        axle["left_setup"] = left
    out = {"type": d.get("type", "double_wishbone"), "scope": "axle", "name": "axle"}
    out |= {"units": "millimeters", "vehicle_config": vehicle} if vehicle else {}
    out |= {"axle_config": axle, "hardpoints": {"left": d["hardpoints"]}}
    return out


for _name in ("macpherson.yaml", "multilink_rear.yaml", "semi_trailing_arm.yaml"):
    AXLE_BASES[f"{_name} as an axle"] = as_axle(BASES[_name])


def _is_axle_data(data) -> bool:
    return isinstance(data, dict) and data.get("scope") == "axle"


def label(data) -> str:
    """The mechanism a geometry names, as counted: 'multilink', 'multilink axle'."""
    kind = _kind(data) or "(none)"
    return f"{kind} axle" if _is_axle_data(data) and kind != "(none)" else kind


def _axle_coordinate_paths(data) -> list[tuple]:
    hp = data.get("hardpoints")
    out = []
    if isinstance(hp, dict):
        for section, points in hp.items():
            if isinstance(points, dict):
                for name, point in points.items():
                    if isinstance(point, dict):
                        out += [
                            ("hardpoints", section, name, a)
                            for a in "xyz"
                            if _is_number(point.get(a))
                        ]
    return out


def _mirrored(points: dict) -> dict:
    out = copy.deepcopy(points)
    for p in out.values():
        if isinstance(p, dict) and _is_number(p.get("y")):
            p["y"] = -p["y"]
    return out


def _mutate_keys(draw, data: dict, kind: str, unknown_keys: tuple) -> str | None:
    """The moves every input file takes alike — a key dropped, an unknown key added
    (from ``unknown_keys``), a leaf outside the hardpoints given another type — or None
    when ``kind`` is none of them. (A corner's and an axle's mutations both use it.)"""
    if kind == "drop_key":
        path = draw(st.sampled_from(sorted(paths(data, lambda n: True), key=repr)))
        del get(data, path[:-1])[path[-1]]
        return f"drop {'.'.join(map(str, path))}"
    if kind == "unknown_key":
        maps = [()] + paths(data, lambda n: isinstance(n, dict))
        path = draw(st.sampled_from(sorted(maps, key=repr)))
        key = draw(st.sampled_from(unknown_keys))
        get(data, path)[key] = draw(st.one_of(small(100), wild()))
        return f"unknown key {key!r} in {'.'.join(map(str, path)) or 'top'}"
    if kind == "retype":
        leaves = [p for p in paths(data, _is_leaf) if p[0] != "hardpoints"] or [("name",)]
        path = draw(st.sampled_from(sorted(leaves, key=repr)))
        value = draw(st.one_of(wild(), small(100)))
        put(data, path, value)
        return f"{'.'.join(map(str, path))} = {value!r}"
    return None


@st.composite
def _mutate_axle(draw, data) -> str:
    kinds = (
        "drop_key unknown_key retype wild_coordinate anti_roll anti_roll stiffness heave_link "
        "right_side right_side setup mount type restyle_number drop_point"
    ).split()
    kind = draw(st.sampled_from(kinds))
    ac = data.get("axle_config") if isinstance(data.get("axle_config"), dict) else None
    hp = data.get("hardpoints") if isinstance(data.get("hardpoints"), dict) else {}
    generic = _mutate_keys(draw, data, kind, UNKNOWN_KEYS + ("config", "side", "droplink"))
    if generic is not None:
        return generic
    if kind == "wild_coordinate" and _axle_coordinate_paths(data):
        path = draw(st.sampled_from(_axle_coordinate_paths(data)))
        value = draw(st.one_of(wild(), small(600)))
        put(data, path, value)
        return f"{'.'.join(map(str, path))} = {value!r}"
    if kind == "drop_point" and _axle_coordinate_paths(data):
        path = draw(st.sampled_from(_axle_coordinate_paths(data)))[:3]
        del get(data, path[:-1])[path[-1]]
        return f"drop {'.'.join(path)}"
    if ac is None:
        return f"{kind} (no axle_config)"
    if kind == "anti_roll":
        value = draw(st.sampled_from(("none", "u_bar", "t_bar", "x_bar", None)))
        ac["anti_roll"] = {"type": value}
        left = hp.get("left") if isinstance(hp.get("left"), dict) else {}
        center = hp.setdefault("center", {}) if isinstance(hp.get("center", {}), dict) else {}
        if value in ("u_bar", "t_bar") and draw(st.booleans()) and "droplink_rocker" not in left:
            # a droplink from the lower wishbone (or the wheel's body) to the bar
            ac["anti_roll"]["mount"] = draw(st.sampled_from(("lower_wishbone", "upright", "arm")))
            lbj = _numeric_point(left.get("lower_wishbone_outboard")) or [0.0, 700.0, 200.0]
            left["droplink_lower"] = {"x": lbj[0] + 60, "y": lbj[1] - 120, "z": lbj[2] + 20}
            end = "droplink_u_bar" if value == "u_bar" else "droplink_t_bar"
            left[end] = {"x": lbj[0] + 60, "y": 300.0, "z": lbj[2] + 10}
            if value == "u_bar":
                center["arb_u_bar_axis_a"] = {"x": lbj[0] - 40, "y": 300.0, "z": lbj[2] + 10}
                center["arb_u_bar_axis_b"] = {"x": lbj[0] - 40, "y": -300.0, "z": lbj[2] + 10}
            else:
                left[end]["y"] = 300.0
                center["arb_t_bar_pivot"] = {"x": lbj[0] - 200, "y": 0.0, "z": lbj[2] + 10}
            return f"anti_roll {value} on the {ac['anti_roll']['mount']} (points fitted)"
        return f"anti_roll {value!r}"
    if kind == "stiffness":
        anti = ac.get("anti_roll")
        if isinstance(anti, dict):
            anti["stiffness"] = draw(st.sampled_from(("rigid", 10.0, 250, 0, -5, "stiff", 1e300)))
            return f"anti_roll.stiffness = {anti['stiffness']!r}"
        return "stiffness (no anti_roll)"
    if kind == "heave_link":
        value = draw(st.sampled_from(("rocker_to_rocker", "none", "spring")))
        ac["heave_link"] = {"type": value}
        left = hp.get("left")
        if value == "rocker_to_rocker" and isinstance(left, dict) and draw(st.booleans()):
            left["heave_link_rocker"] = {"x": 0, "y": 320, "z": 480}
            return "heave_link rocker_to_rocker (point fitted)"
        return f"heave_link {value}"
    if kind == "right_side":
        left = hp.get("left")
        if isinstance(left, dict):
            hp["right"] = _mirrored(left)
            if draw(st.booleans()):  # an asymmetric axle
                paths_ = _axle_coordinate_paths({"hardpoints": {"right": hp["right"]}})
                path = draw(st.sampled_from(paths_))
                put(data, path, round(get(data, path) + draw(small(3)), 6))
                return f"hardpoints.right: the mirror of left, {'.'.join(path[2:])} moved"
            return "hardpoints.right: the mirror of left"
        return "right_side (no left)"
    if kind == "setup":
        side = draw(st.sampled_from(("left_setup", "right_setup")))
        key = draw(st.sampled_from(("trackrod_length_delta", "pushrod_length_delta", "colour")))
        ac.setdefault(side, {})
        if isinstance(ac[side], dict):
            ac[side][key] = draw(st.one_of(small(5), wild()))
            return f"axle_config.{side}.{key} = {ac[side][key]!r}"
        return "setup (not a mapping)"
    if kind == "mount":
        anti = ac.get("anti_roll")
        if isinstance(anti, dict):
            anti["mount"] = draw(st.sampled_from(("upright", "lower_wishbone", "rocker", "arm")))
            return f"anti_roll.mount = {anti['mount']}"
        return "mount (no anti_roll)"
    if kind == "type":
        data["type"] = draw(st.sampled_from(MECHANISMS + ("double_wishbone_axle",)))
        return f"type = {data['type']}"
    if kind == "restyle_number":
        numbers = [p for p in paths(data, _is_number) if restyled(get(data, p))]
        if numbers:
            path = draw(st.sampled_from(numbers))
            text = draw(st.sampled_from(restyled(get(data, path))))
            put(data, path, Raw(text))
            return f"{'.'.join(map(str, path))} written {text}"
    return f"{kind} (not applicable)"


@st.composite
def axle_geometries(draw) -> Inputs:
    """An axle file: an example axle or a corner example as an axle, perturbed, maybe
    broken."""
    base = draw(st.sampled_from(sorted(AXLE_BASES)))
    data = copy.deepcopy(AXLE_BASES[base])
    changes = [base]
    if chance(draw, 2):
        text = draw(st.sampled_from(GARBAGE))
        return Inputs(None, text, [*changes, f"garbage {text[:30]!r}"])
    coordinates = _axle_coordinate_paths(data)
    mode = draw(st.sampled_from(("none", "small", "small", "some")))
    if mode == "small":  # every coordinate within ±2 mm (the T-bar's ends stay mirrored)
        deltas = draw(st.lists(small(2), min_size=len(coordinates), max_size=len(coordinates)))
        for path, d in zip(coordinates, deltas, strict=True):
            if path[1] != "center" and path[2] != "droplink_t_bar":
                put(data, path, round(get(data, path) + d, 6))
        changes.append("all ±2 mm")
    elif mode == "some":
        for path, d in draw(
            st.lists(st.tuples(st.sampled_from(coordinates), small(20)), min_size=1, max_size=3)
        ):
            put(data, path, round(get(data, path) + d, 6))
            changes.append(f"{'.'.join(map(str, path))} {d:+g}")
    if mode != "none" and _kind(data) == "macpherson":
        changes.append(_onto_strut_line({"hardpoints": data["hardpoints"]["left"]}))
    for _ in range(draw(st.sampled_from((0, 0, 0, 1, 1, 2)))):
        changes.append(draw(_mutate_axle(data)))
    return Inputs(data, _render(data, draw, changes), changes)


def _axle_rack(data) -> bool | None:
    if not _is_axle_data(data) or _kind(data) is None:
        return None
    if _kind(data) == "trailing_arm":
        return False
    ac = data.get("axle_config")
    steering = ac.get("steering", {"type": "rack"}) if isinstance(ac, dict) else None
    kind = steering.get("type", "rack") if isinstance(steering, dict) else None
    return {"rack": True, "none": False}.get(kind) if isinstance(kind, str) else None


@st.composite
def axle_sweeps(draw, geometry, max_steps: int = 40):
    """An axle's sweep: roll and heave (the roll.yaml / heave_roll.yaml kind), or a
    wheel height per side; and the rack once: (Inputs, plans or None when broken)."""
    rack = _axle_rack(geometry)
    if rack is None:
        rack = draw(st.booleans())
    steps = draw(st.one_of(st.integers(1, min(8, max_steps)), st.integers(1, max_steps)))
    targets, plans = [], []

    def ramp(limit, offset=0.0):
        start, stop = draw(small(limit)), draw(small(limit))
        values = (
            [start + (stop - start) * i / (steps - 1) for i in range(steps)]
            if steps > 1
            else [start]
        )
        return {"start": start, "stop": stop}, values

    if draw(st.booleans()):  # roll and heave
        spread, values = ramp(draw(st.sampled_from((4, 4, 4, 30, 120))))
        targets.append({"quantity": "roll", **spread})
        plans.append(Plan("roll", (0.0, 0.0, 1.0), "quantity", values))
        spread, values = ramp(25)
        targets.append({"quantity": "heave", **spread})
        plans.append(Plan("heave", (0.0, 0.0, 1.0), "quantity", values))
    else:
        for side in ("left", "right"):
            spread, values = ramp(draw(st.sampled_from((40, 40, 40, 400))))
            targets.append(
                {"point": "wheel_center", "side": side, "direction": {"axis": "z"}, **spread}
            )
            plans.append(Plan("wheel_center", (0.0, 0.0, 1.0), "relative", values, side))
    if rack:
        side = draw(st.sampled_from(("left", "right")))
        spread, values = ramp(10)
        targets.append(
            {"point": "trackrod_inboard", "side": side, "direction": {"axis": "y"}, **spread}
        )
        plans.append(Plan("trackrod_inboard", (0.0, 1.0, 0.0), "relative", values, side))
    if chance(draw, 20):
        order = draw(st.permutations(range(len(targets))))
        targets, plans = [targets[i] for i in order], [plans[i] for i in order]
    data = {"version": 1, "steps": steps, "targets": targets}
    changes = [f"{steps} steps (axle)"]
    if chance(draw, 15):
        for _ in range(draw(st.integers(1, 2))):
            changes.append(draw(_mutate_axle_sweep(data)))
        plans = None
    return Inputs(data, to_yaml(data).encode(), changes), plans


@st.composite
def _mutate_axle_sweep(draw, data) -> str:
    targets = data["targets"]
    t = draw(st.sampled_from(targets)) if targets else None
    kind = draw(
        st.sampled_from(
            (
                "no_side",
                "bad_side",
                "repeat",
                "quantity",
                "drop",
                "steps",
                "point_target_without_side",
                "unknown_key",
            )
        )
    )
    if t is None:
        return "no target"
    if kind == "no_side":
        t.pop("side", None)
        return "a target without side"
    if kind == "bad_side":
        t["side"] = draw(st.sampled_from(("centre", "both", None, 1, "Left")))
        return f"side = {t['side']!r}"
    if kind == "repeat":
        targets.append(copy.deepcopy(t))
        return "a target repeated"
    if kind == "quantity":
        t.pop("point", None)
        t["quantity"] = draw(st.sampled_from(("roll", "heave", "pitch", "", None)))
        return f"quantity = {t['quantity']!r}"
    if kind == "drop":
        targets.remove(t)
        return "a target dropped"
    if kind == "steps":
        data["steps"] = draw(st.sampled_from((0, -3, "x", 2**70, None)))
        return f"steps = {data['steps']!r}"
    if kind == "point_target_without_side":
        targets.append({"point": "wheel_center", "direction": {"axis": "z"}, "start": 0, "stop": 1})
        return "a wheel target without side"
    t[draw(st.sampled_from(UNKNOWN_KEYS))] = 1
    return "an unknown key"


# --------------------------------------------------------------------------- loads


LOAD_BASE = yaml.safe_load((EXAMPLES / "loads.yaml").read_text())


@st.composite
def load_cases(draw, axle: bool) -> Inputs:
    """A loads file (examples/loads.yaml), per wheel for an axle, maybe broken."""
    data = copy.deepcopy(LOAD_BASE)
    cases_ = data["cases"][: draw(st.integers(1, 3))]
    for case in cases_:
        if chance(draw, 30):
            case["wheel_center"] = {"fx": draw(small(500)), "fy": 0.0, "fz": draw(small(500))}
        if chance(draw, 30):
            case["moment"] = {"mx": 0.0, "my": draw(small(300)), "mz": draw(small(300))}
        if axle:
            blocks = {
                k: case.pop(k) for k in ("contact_patch", "wheel_center", "moment") if k in case
            }
            case["left"] = blocks
            case["right"] = {k: dict(v) for k, v in blocks.items()} if chance(draw, 80) else {}
    data["cases"] = cases_
    changes = [f"{len(cases_)} load cases" + (" per wheel" if axle else "")]
    if chance(draw, 20):
        kind = draw(
            st.sampled_from(
                ("drop_key", "wild", "unknown", "empty", "duplicate_name", "retype", "no_cases")
            )
        )
        if kind == "drop_key":
            path = draw(st.sampled_from(sorted(paths(data, lambda n: True), key=repr)))
            del get(data, path[:-1])[path[-1]]
            changes.append(f"drop {'.'.join(map(str, path))}")
        elif kind == "wild":
            numbers = paths(data, _is_number)
            if numbers:
                path = draw(st.sampled_from(numbers))
                put(data, path, draw(wild()))
                changes.append(f"{'.'.join(map(str, path))} = {get(data, path)!r}")
        elif kind == "unknown":
            maps = [()] + paths(data, lambda n: isinstance(n, dict))
            path = draw(st.sampled_from(sorted(maps, key=repr)))
            get(data, path)[draw(st.sampled_from(UNKNOWN_KEYS + ("fw", "left")))] = 1.0
            changes.append(f"an unknown key in {'.'.join(map(str, path)) or 'top'}")
        elif kind == "empty":
            data["cases"] = draw(st.sampled_from(([], None, [{}], [{"name": "x"}])))
            changes.append(f"cases = {data['cases']!r}")
        elif kind == "duplicate_name":
            data["cases"].append(copy.deepcopy(data["cases"][0]))
            changes.append("a case name twice")
        elif kind == "retype":
            path = draw(st.sampled_from(sorted(paths(data, _is_leaf), key=repr)))
            put(data, path, draw(wild()))
            changes.append(f"{'.'.join(map(str, path))} = {get(data, path)!r}")
        else:
            data = {"version": 1}
            changes.append("no cases")
    if chance(draw, 2):
        text = draw(st.sampled_from(GARBAGE))
        return Inputs(None, text, [*changes, f"garbage {text[:30]!r}"])
    return Inputs(data, _render(data, draw, changes), changes)


# --------------------------------------------------------------------------- studies


@st.composite
def studies(draw, geometry) -> Inputs:
    """A tiny study of g.yaml through s.yaml (a handful of variants), maybe malformed."""
    axle = _is_axle_data(geometry)
    hp = geometry.get("hardpoints") if isinstance(geometry, dict) else None
    points = []
    if isinstance(hp, dict):
        section = hp.get("left") if axle else hp
        if isinstance(section, dict):
            points = sorted(n for n in section if _numeric_point(section[n]) is not None)
    points = points or ["trackrod_inboard"]
    variables = []
    if chance(draw, 15):
        variables = {"all_hardpoints": {"tolerance": draw(st.sampled_from((0.1, 0.5)))}}
    else:
        for _ in range(draw(st.integers(1, 2))):
            r = draw(st.sampled_from((0.2, 1.0, 3.0)))
            v = {
                "point": draw(st.sampled_from(points)),
                "axis": draw(st.sampled_from("xyz")),
                "range": [-r, r],
            }
            if axle:
                v["side"] = "left"
            variables.append(v)
    kind = draw(st.sampled_from(("doe", "doe", "monte_carlo", "optimise")))
    data = {
        "version": 1,
        "geometry": "g.yaml",
        "sweep": "s.yaml",
        "variables": variables,
        "kind": kind,
    }
    if kind == "doe":
        method = draw(st.sampled_from(("full_factorial", "latin_hypercube", "sobol")))
        data["doe"] = (
            {"method": method, "levels": 2}
            if method == "full_factorial" and isinstance(variables, list)
            else {
                "method": method if method != "full_factorial" else "sobol",
                "samples": 2,
                "seed": 1,
            }
        )
    elif kind == "monte_carlo":
        data["monte_carlo"] = {
            "samples": draw(st.integers(2, 3)),
            "seed": 1,
            "distribution": draw(st.sampled_from(("normal", "uniform"))),
        }
    else:
        metric = "camber_left" if axle else "camber"
        data["optimise"] = {
            "objective": [{"metric": metric, "relative": True, "target": 0.0, "weight": 1}],
            "starts": 1,
            "evaluations": 2,
        }
    if chance(draw, 30):
        data["summary"] = ["camber_left", "roll"] if axle else ["camber", "roadwheel_angle"]
    changes = [f"{kind} study"]
    if chance(draw, 25):  # malformed
        for _ in range(draw(st.integers(1, 2))):
            what = draw(
                st.sampled_from(
                    ("drop_key", "unknown_key", "retype", "variable", "count", "files", "kind")
                )
            )
            if what == "drop_key":
                path = draw(st.sampled_from(sorted(paths(data, lambda n: True), key=repr)))
                del get(data, path[:-1])[path[-1]]
                changes.append(f"drop {'.'.join(map(str, path))}")
            elif what == "unknown_key":
                maps = [()] + paths(data, lambda n: isinstance(n, dict))
                path = draw(st.sampled_from(sorted(maps, key=repr)))
                get(data, path)[draw(st.sampled_from(UNKNOWN_KEYS))] = 1
                changes.append(f"unknown key in {'.'.join(map(str, path)) or 'top'}")
            elif what == "retype":
                path = draw(st.sampled_from(sorted(paths(data, _is_leaf), key=repr)))
                value = draw(wild())
                put(data, path, value)
                changes.append(f"{'.'.join(map(str, path))} = {value!r}")
            elif what == "variable" and isinstance(variables, list) and variables:
                v = variables[0]
                change = draw(st.sampled_from(("point", "axis", "range", "range", "side")))
                v.update(
                    {
                        "point": {"point": draw(st.sampled_from(("hub", "wheel_center", "")))},
                        "axis": {"axis": draw(st.sampled_from(("w", "X", None)))},
                        "range": {
                            "range": draw(
                                st.sampled_from(([1, -1], [0, 0], [1], [0, 1e300], ["a", 1], None))
                            )
                        },
                        "side": {"side": draw(st.sampled_from(("centre", "right", None)))},
                    }[change]
                )
                changes.append(f"variable {change} = {v.get(change)!r}")
            elif what == "count":
                block = data.get(kind) if isinstance(data.get(kind), dict) else None
                if block is not None:
                    key = {"doe": "samples", "monte_carlo": "samples", "optimise": "starts"}[kind]
                    if "levels" in block:
                        key = "levels"
                    block[key] = draw(st.sampled_from((0, -1, 1, 2.5, "many", 10**30, 2**64)))
                    changes.append(f"{kind}.{key} = {block[key]!r}")
            elif what == "files":
                key = draw(st.sampled_from(("geometry", "sweep")))
                data[key] = draw(
                    st.sampled_from(("missing.yaml", "study.yaml", "", ".", "../g.yaml"))
                )
                changes.append(f"{key} = {data[key]!r}")
            else:
                data["kind"] = draw(st.sampled_from(("DOE", "grid", None, "optimize")))
                changes.append(f"kind = {data['kind']!r}")
    if chance(draw, 2):
        text = draw(st.sampled_from(GARBAGE))
        return Inputs(None, text, [*changes, f"garbage {text[:30]!r}"])
    return Inputs(data, to_yaml(data).encode(), changes)


# ---------------------------------------------------------------- reading the outputs


def parquet_rows(raw: bytes) -> tuple[list[str], list[list[str]], dict]:
    """A pin_susp Parquet file as the CSV's header and cells (a null as a blank cell, a
    bool as True/False, a float by repr: a NaN reads 'nan' and fails as in the CSV),
    and its schema metadata."""
    import pyarrow.parquet as pq

    table = pq.read_table(io.BytesIO(raw))
    header = table.column_names
    columns = []
    for name in header:
        cells = []
        for v in table.column(name).to_pylist():
            if v is None:
                cells.append("")
            elif isinstance(v, bool):
                cells.append(str(v))
            elif isinstance(v, float):
                cells.append(repr(v))
            else:
                cells.append(str(v))
        columns.append(cells)
    rows = [list(r) for r in zip(*columns, strict=True)] if columns else []
    meta = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    return header, rows, meta
