"""The mechanisms: one module each, looked up by the geometry file's ``type:``.

A mechanism module says everything that is particular to it; nothing else
in pin_susp branches on its name. Write a new one by copying a neighbour.
Each module has:

- ``NAME``, ``TITLE``: the ``type:`` value, and how docs and plots call it;
- ``STEERING``, ``ACTUATION``, ``MOUNTS``, ``SPRINGS``: the allowed
  ``config.steering.type``, ``actuation.type``, ``actuation.mount`` and
  ``spring.type`` values (the first is the default);
- ``FORBIDDEN``: file keys it does not take, each with the reason (an error);
- ``WHEEL_BODY``: the body that carries the wheel (spindle, wheel points);
- ``hardpoint_names(o)``: the hardpoints, in output order, for options ``o``;
- ``steering_points(o)``: (inboard, outboard) of the trackrod or toe link, or ();
- ``wheel_side_points(o)``: the hardpoints that ride with the wheel (y-side check);
- ``upright_points(o)``: hardpoints whose velocity is the wheel body's (its
  twist is found from their rates);
- ``prepare(p, o, r)``: check the points (one clear error each), then ``settle``;
- ``settle(p)``: hardpoints that others place (the MacPherson clamp on its
  strut line); runs on jet.Duals too;
- ``tree(g, shapes=True)``: bodies, joints, points, closures, visuals (none
  without ``shapes``: a study's variant, never drawn) (a tree.Tree), and
  what robotics tools read beside them (``robot(g)`` below);
- ``kingpin(ps)``: (lower, upper) points of the steering axis, or None;
- ``instant_planes(ps)``: two planes (normal, point) whose line is the instant
  axis, or None (then the bump twist gives the instant centres);
- ``pointwise(o)``: the independent point-based formulation: rigid parts,
  links, point-on-line conditions.

``o`` is a :class:`pin_susp.model.geometry.Options` (steering, actuation, mount,
spring, side); ``ps`` a :class:`pin_susp.columns.metrics.PointSet`. Shared point
names and helpers for trees and visuals are below. The mechanisms sit under the
geometry reader (it asks them which points a file must have) and import nothing
of it: their maths is :mod:`pin_susp.maths.vectors`.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from types import ModuleType

import numpy as np

from ...maths.vectors import unit
from ..tree import DAMPER, DENSITY, Joint, Spring, Visual

# Hardpoint names that more than one mechanism has (docs/geometry.md)
STEERING_POINTS = {  # by config.steering.type
    "rack": ("trackrod_inboard", "trackrod_outboard"),
    "none": ("toe_link_inboard", "toe_link_outboard"),
}
AXLE_POINTS = ("axle_inboard", "axle_outboard")
COILOVER_POINTS = ("strut_top", "strut_bottom")

MATERIALS = {
    "chassis": (0.35, 0.35, 0.38, 1.0),
    "wishbone": (0.12, 0.42, 0.85, 1.0),
    "upright": (0.90, 0.45, 0.10, 1.0),
    "rack": (0.20, 0.65, 0.30, 1.0),
    "rocker": (0.55, 0.25, 0.70, 1.0),
    "tyre": (0.08, 0.08, 0.08, 0.45),
    "strut": (0.80, 0.15, 0.15, 1.0),
}
ROD = 0.008  # m, visual radius of links
BALL = 0.014  # m, visual radius of joints
Y = np.array([0.0, 1.0, 0.0])
# sin² of the angle between two link lines below this: parallel, no virtual joint
# (1e-12: within 1e-6 rad, where the solver's own rounding moves the midpoint by metres)
PARALLEL_LINKS = 1e-12


@dataclass(frozen=True)
class Pointwise:
    """A mechanism as points and distances, for the independent formulation.

    ``parts``: lists of points that move as one rigid body (a point in two
    lists is a ball joint between them); ``links``: two-force members (a
    fixed distance between points of different parts); ``lines``: (point,
    a, b) — the point stays on the line through a and b (a telescopic
    strut); ``fixed``: points on the chassis; ``rack``: the rack's point (it
    slides along y), or None.
    """

    parts: dict[str, list[str]]
    links: list[tuple[str, str]] = field(default_factory=list)
    lines: list[tuple[str, str, str]] = field(default_factory=list)
    fixed: set[str] = field(default_factory=set)
    rack: str | None = None


NAMES = ("double_wishbone", "macpherson", "multilink", "trailing_arm")


def registry() -> dict[str, ModuleType]:
    return {name: get(name) for name in NAMES}


def get(name: str) -> ModuleType:
    """The mechanism module for a ``type:`` value, imported when first asked for (a
    double wishbone's sweep loads no other mechanism)."""
    if name not in NAMES:
        raise KeyError(name)
    __import__(f"{__name__}.{name}")  # (not importlib's: -X importtime shows this one)
    return sys.modules[f"{__name__}.{name}"]


def pivot(name: str, front: str, rear: str, p: dict[str, np.ndarray]) -> Joint:
    """A revolute joint about the line front → rear (two chassis pickups)."""
    return Joint(name, "revolute", p[front], unit(p[rear] - p[front]), (front, rear))


def robot(g) -> dict:
    """The Tree's fields beyond the kinematics: the masses' density and the wheel's
    mass (config.inertia), the spring and damper (SI: a coilover's N/m, N and N·s/m; a
    torsion bar, twisted by the rocker, N·m/rad, N·m and N·m·s/rad — its damper is a
    coilover's on the rocker's arm to the pushrod) and the corner's description for
    <pin_susp:corner>."""
    spring = None
    rate = g.spring_rate
    if g.spring == "coilover":
        rate = None if rate is None else rate * 1e3
        ends = ("strut_top", "strut_bottom")
        spring = Spring("coilover", ends, rate, g.spring_preload, DAMPER)
    elif g.spring == "torsion_bar":
        rate = None if rate is None else rate * 180.0 / np.pi
        p = g.hardpoints
        foot = axis_foot(p["rocker_axis_a"], p["rocker_axis_b"], p["pushrod_inboard"])
        arm = float(np.linalg.norm(p["pushrod_inboard"] - foot))
        spring = Spring("torsion_bar", ("rocker_pivot",), rate, g.spring_preload, DAMPER * arm**2)
    metadata = {
        "mechanism": g.type,
        "side": g.side,
        "wheel_link": g.mechanism.WHEEL_BODY,
        "tyre_radius": repr(g.wheel.radius),
        "tyre_width": repr(g.wheel.section_width),
        "design": "as_set" if g.drawn is not None else "as_drawn",
    }
    return {
        "density": DENSITY if g.density is None else g.density,
        "wheel_mass": g.wheel_mass,
        "spring": spring,
        "metadata": metadata,
    }


def rack_joint(p: dict[str, np.ndarray], inner: str) -> Joint:
    return Joint("rack_slide", "prismatic", p[inner], Y)


def rack_rod(p: dict[str, np.ndarray], inner: str) -> tuple:
    """The rack drawn from the trackrod's inboard end to the car's centre plane."""
    return ("rack", "rack", p[inner] * np.array([1.0, 0.0, 1.0]), p[inner])


def visuals(g, p, body_of: dict[str, str], rods: list[tuple], material=None) -> list[Visual]:
    """Rods (body, material, start, end), the tyre disc, and a ball at each hardpoint."""
    out = [Visual(body, "rod", mat, a, b, ROD) for body, mat, a, b in rods]
    wheel_body = body_of["wheel_center"]
    out.append(
        Visual(
            wheel_body,
            "rod",
            "tyre",
            p["wheel_inboard"],
            p["wheel_outboard"],
            g.wheel.unloaded_radius,
        )
    )
    for name, body in body_of.items():
        if name in g.hardpoints:
            mat = "strut" if name.startswith("strut") else (material or {}).get(body, body)
            out.append(
                Visual(body, "ball", mat if mat in MATERIALS else "upright", p[name], radius=BALL)
            )
    return out


def wheel_mounts(body: str, g=None) -> dict[str, str]:
    """The derived wheel points, on the body that carries the wheel, and the geometry
    ``g``'s driveshaft's outboard joint (docs/geometry.md, "Driveshaft")."""
    names = ("axle_midpoint", "wheel_center", "wheel_inboard", "wheel_outboard")
    shaft = () if g is None or g.driveshaft is None else ("cv_outboard",)
    return dict.fromkeys(names + shaft, body)


def chassis_mounts(g) -> dict[str, str]:
    """The optional points every mechanism may have on its chassis: a driveshaft's inboard
    joint (on the chassis or the diff, docs/geometry.md, "Driveshaft")."""
    return dict.fromkeys((n for n in ("cv_inboard",) if n in g.hardpoints), "chassis")


def axis_foot(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The point of the axis a → b nearest p: where an arm turning about it starts."""
    axis = unit(b - a)
    return a + axis * ((p - a) @ axis)


def xml_name(name: str, default: str = "corner") -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or default


def common_perpendicular_midpoint(a1, b1, a2, b2):
    """The midpoint of the common perpendicular of lines a1→b1 and a2→b2: where
    they meet, when they do (a virtual ball joint). Works on (n, 3) arrays and on
    jet.Duals; NaN for lines within 1e-6 rad of parallel."""
    d1, d2 = b1 - a1, b2 - a2
    w = a1 - a2
    a = np.sum(d1 * d1, axis=-1)
    b = np.sum(d1 * d2, axis=-1)
    c = np.sum(d2 * d2, axis=-1)
    d = np.sum(d1 * w, axis=-1)
    e = np.sum(d2 * w, axis=-1)
    den = a * c - b * b
    den = np.where(np.abs(den) > PARALLEL_LINKS * a * c, den, np.nan)
    s = (b * e - c * d) / den
    t = (a * e - b * d) / den
    return 0.5 * ((a1 + d1 * s[..., None]) + (a2 + d2 * t[..., None]))
