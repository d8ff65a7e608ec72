"""An independent formulation of a corner or an axle: points as unknowns, scipy least_squares.

It shares no kinematics with the Pinocchio path: the unknowns are the
coordinates of the moving hardpoints (and the rack's displacement), the
constraints are rigid-body distances between hardpoints of one part, the
derived points are written again from docs/geometry.md. ``pin-susp
validate`` and the tests solve every step with it and compare.

A subject's labelled corners and the elements they share are one formulation
(:func:`labelled`): each corner's with its names prefixed by its label (an
axle's ``left_``, ``right_``; a corner's ``""`` leaves them as they are), one
rack unknown that moves every trackrod's inboard end, and each shared element's
rows (:data:`ELEMENTS`): the anti-roll bar's parts, droplinks and plane rows
(:data:`ANTI_ROLL`), the heave link's ends on the rockers (docs/axle.md).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ..errors import PinSuspError
from ..model.geometry import Geometry, Wheel, wheel_points
from ..model.mechanisms import Pointwise
from ..model.packaging import placed_points
from ..subjects.assembly import Assembly
from ..subjects.elements import AntiRollBar, HeaveLink, elements_of

Y = np.array([0.0, 1.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])
WHEEL_POINTS = ("axle_midpoint", "wheel_center", "wheel_inboard", "wheel_outboard")
# Residual evaluations a solve may take. A reachable step from the design state takes
# at most 8 on every example (a closed pose is a root: Levenberg-Marquardt converges
# as Newton does); a step out of reach has no root, and with tolerances of 1e-15 scipy's
# own limit, 100 per unknown, made it run on for 6100 evaluations on an axle (8 s a step).
MAX_EVALUATIONS = 100


# ---------------------------------------------------------------- targets
# A target is a scalar function of the points held at a value: ``error(p)`` (its
# residual, SI) and ``gradient(p)`` (point → d error / d point, (3,) each).


@dataclass(frozen=True)
class Along:
    """A point's coordinate along a unit direction held at a value (m, absolute)."""

    point: str
    direction: np.ndarray
    value: float

    def error(self, p) -> float:
        return p[self.point] @ self.direction - self.value

    def gradient(self, p) -> dict[str, np.ndarray]:
        return {self.point: self.direction}


@dataclass(frozen=True)
class Heave:
    """½(ΔWC_z,L + ΔWC_z,R) held at a value (m); ``design``: ½(WC_z,L + WC_z,R) at design."""

    design: float
    value: float

    def error(self, p) -> float:
        z = p["left_wheel_center"][2] + p["right_wheel_center"][2]
        return 0.5 * z - self.design - self.value

    def gradient(self, p) -> dict[str, np.ndarray]:
        return {"left_wheel_center": 0.5 * Z, "right_wheel_center": 0.5 * Z}


@dataclass(frozen=True)
class Roll:
    """atan2(ΔWC_z,L − ΔWC_z,R, CP_y,L − CP_y,R) held at a value (rad; + = left wheel
    higher relative to the chassis); ``design``: WC_z,L − WC_z,R at design."""

    design: float
    value: float

    def _parts(self, p):
        a = p["left_wheel_center"][2] - p["right_wheel_center"][2] - self.design
        b = p["left_contact_patch_center"][1] - p["right_contact_patch_center"][1]
        return a, b

    def error(self, p) -> float:
        a, b = self._parts(p)
        return np.arctan2(a, b) - self.value

    def gradient(self, p) -> dict[str, np.ndarray]:
        a, b = self._parts(p)
        da, db = b / (a * a + b * b), -a / (a * a + b * b)  # d atan2 / da, / db
        return {
            "left_wheel_center": da * Z,
            "right_wheel_center": -da * Z,
            "left_contact_patch_center": db * Y,
            "right_contact_patch_center": -db * Y,
        }


@dataclass(frozen=True)
class Midpoint:
    """The midpoint of two points held in a plane: its coordinate along the plane's
    unit normal at a value (m, absolute)."""

    a: str
    b: str
    normal: np.ndarray
    value: float

    def error(self, p) -> float:
        return 0.5 * (p[self.a] + p[self.b]) @ self.normal - self.value

    def gradient(self, p) -> dict[str, np.ndarray]:
        return {self.a: 0.5 * self.normal, self.b: 0.5 * self.normal}


def as_target(t):
    """A target object; a tuple (point, unit direction, value m) is an :class:`Along`."""
    return t if hasattr(t, "error") else Along(*t)


# ---------------------------------------------------------------- the formulation


class PointwiseLinkage:
    """Rigid parts, links and lines as points and distances (SI units).

    ``spec`` says which points move as one rigid part, which are joined by
    links, which stay on a line (a :class:`~pin_susp.model.mechanisms.Pointwise`);
    here each part becomes every distance between its points, each link one
    distance, each line condition the cross product (p − a) × unit(b − a) = 0.
    ``racks``: points that slide along y together (one unknown, the rack's
    displacement); ``wheels``: name prefix → Wheel, whose derived points
    (wheel centre, contact patch, …) follow ``<prefix>axle_inboard/outboard``;
    ``planes``: conditions always held, written as targets (a :class:`Midpoint`),
    their rows after the line conditions'.
    """

    def __init__(self, spec: Pointwise, hp: dict, wheels: dict[str, Wheel], racks=(), planes=()):
        hp = dict(hp)
        fixed = set(spec.fixed)
        self.racks = tuple(racks)
        self.planes = list(planes)
        self.wheels = wheels
        # points of one part that coincide are one point (two links meeting in a ball)
        self.alias = {}
        for pts in spec.parts.values():
            for a, b in itertools.combinations(pts, 2):
                if b not in self.alias and np.linalg.norm(hp[a] - hp[b]) < 1e-12:
                    self.alias[b] = self.alias.get(a, a)
        parts = {
            k: list(dict.fromkeys(self.alias.get(n, n) for n in pts))
            for k, pts in spec.parts.items()
        }
        links = [(self.alias.get(a, a), self.alias.get(b, b)) for a, b in spec.links]
        self.lines = [tuple(self.alias.get(n, n) for n in line) for line in spec.lines]
        named = {n for pts in parts.values() for n in pts} | {n for ab in links for n in ab}
        self.moving = sorted(named - fixed - set(self.racks))
        self.column = {n: 3 * i for i, n in enumerate(self.moving)}
        self.rack = 3 * len(self.moving) if self.racks else None
        self.pairs = [
            (a, b, float(np.linalg.norm(hp[a] - hp[b])))
            for pts in parts.values()
            for a, b in itertools.combinations(pts, 2)
            if not (a in fixed and b in fixed)
        ]
        self.pairs += [(a, b, float(np.linalg.norm(hp[a] - hp[b]))) for a, b in links]
        self.hp = hp
        # derived point name → (wheel prefix, point)
        self.derived = {
            f"{prefix}{name}": (prefix, name)
            for prefix in wheels
            for name in (*WHEEL_POINTS, "contact_patch_center")
        }
        n = 3 * len(self.moving) + (1 if self.rack is not None else 0)
        self.x0 = np.zeros(n)
        for name, c in self.column.items():
            self.x0[c : c + 3] = hp[name]
        self.design = self.points(self.x0)

    def points(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """Every hardpoint and derived point for the unknowns x."""
        out = dict(self.hp)
        out.update({n: x[c : c + 3] for n, c in self.column.items()})
        out.update({b: out[a] for b, a in self.alias.items()})
        for inner in self.racks:
            out[inner] = self.hp[inner] + x[self.rack] * Y
        for prefix, wheel in self.wheels.items():
            inboard, outboard = out[f"{prefix}axle_inboard"], out[f"{prefix}axle_outboard"]
            a = outboard - inboard
            a = a / np.linalg.norm(a)
            center = outboard - wheel.offset * a
            down = np.array([0.0, 0.0, -1.0]) + a[2] * a
            out.update(
                {
                    f"{prefix}axle_midpoint": 0.5 * (inboard + outboard),
                    f"{prefix}wheel_center": center,
                    f"{prefix}wheel_inboard": center - 0.5 * wheel.section_width * a,
                    f"{prefix}wheel_outboard": center + 0.5 * wheel.section_width * a,
                    f"{prefix}contact_patch_center": center
                    + wheel.radius * down / np.linalg.norm(down),
                }
            )
        return out

    def residual(self, x: np.ndarray, targets) -> np.ndarray:
        p = self.points(x)
        rows = [np.linalg.norm(p[a] - p[b]) - d for a, b, d in self.pairs]
        rows += [as_target(t).error(p) for t in targets]
        for point, a, b in self.lines:
            rows += list(np.cross(p[point] - p[a], (p[b] - p[a]) / np.linalg.norm(p[b] - p[a])))
        rows += [t.error(p) for t in self.planes]
        return np.array(rows)

    def jacobian(self, x: np.ndarray, targets) -> np.ndarray:
        """Analytic: distance rows, targets and planes through the points they hold
        (derived points through â = unit(AO − AI)); the line conditions by central
        differences."""
        p = self.points(x)
        lines = len(self.pairs) + len(targets)  # the first line row
        J = np.zeros((lines + 3 * len(self.lines) + len(self.planes), len(x)))
        for row, (a, b, _) in enumerate(self.pairs):
            u = (p[a] - p[b]) / np.linalg.norm(p[a] - p[b])
            self._add(J[row], a, u)
            self._add(J[row], b, -u)
        held = [*map(as_target, targets), *([None] * (3 * len(self.lines))), *self.planes]
        for row, t in zip(J[len(self.pairs) :], held, strict=True):
            for name, gradient in t.gradient(p).items() if t is not None else ():
                if name in self.derived:
                    for end, d in self._derived(name, p).items():
                        self._add(row, end, d.T @ gradient)
                else:
                    self._add(row, name, gradient)
        if self.lines:
            end, h = lines + 3 * len(self.lines), 1e-7
            for i in range(len(x)):
                e = np.zeros(len(x))
                e[i] = h
                up, down = self.residual(x + e, targets), self.residual(x - e, targets)
                J[lines:end, i] = (up[lines:end] - down[lines:end]) / (2 * h)
        return J

    def _add(self, row: np.ndarray, name: str, gradient: np.ndarray) -> None:
        """Add d(row)/d(point) = gradient to the row's columns of that point."""
        if name in self.column:
            row[self.column[name] : self.column[name] + 3] += gradient
        elif name in self.alias:
            self._add(row, self.alias[name], gradient)
        elif name in self.racks:
            row[self.rack] += gradient[1]

    def _derived(self, name: str, p) -> dict[str, np.ndarray]:
        """d(derived point)/d(axle_inboard), d/d(axle_outboard) as 3×3 matrices."""
        prefix, point = self.derived[name]
        inboard, outboard = f"{prefix}axle_inboard", f"{prefix}axle_outboard"
        wheel = self.wheels[prefix]
        v = p[outboard] - p[inboard]
        a = v / np.linalg.norm(v)
        D = (np.eye(3) - np.outer(a, a)) / np.linalg.norm(v)  # dâ/d(AO − AI)
        if point == "axle_midpoint":
            return {inboard: 0.5 * np.eye(3), outboard: 0.5 * np.eye(3)}
        along = {
            "wheel_center": 0.0,
            "wheel_inboard": -0.5 * wheel.section_width,
            "wheel_outboard": 0.5 * wheel.section_width,
            "contact_patch_center": 0.0,
        }[point]
        dv = (along - wheel.offset) * D  # the point is AO + k·â (+ R·n̂ for the patch)
        if point == "contact_patch_center":
            # n̂ = unit(−ẑ + a_z·â): dn̂/dâ = (I − n̂n̂ᵀ)/|down| · (â ẑᵀ + a_z I)
            down = -Z + a[2] * a
            n = down / np.linalg.norm(down)
            dn = (np.eye(3) - np.outer(n, n)) / np.linalg.norm(down)
            dv = dv + wheel.radius * dn @ (np.outer(a, Z) + a[2] * np.eye(3)) @ D
        return {outboard: np.eye(3) + dv, inboard: -dv}

    def solve(
        self,
        targets,
        x0: np.ndarray | None = None,
        jacobian: str = "analytic",
        longer: tuple[tuple[str, str], float] | None = None,
    ) -> tuple[np.ndarray, float]:
        """Hold each target (an :class:`Along`, :class:`Heave`, :class:`Roll`, or a
        tuple (point, unit direction, absolute value m)); returns x and max |residual|.

        ``jacobian="2-point"`` lets scipy difference the residuals instead;
        ``longer`` = ((a, b), δ): the link between points a and b made δ (m) longer.
        """
        x0 = self.x0 if x0 is None else x0
        targets = [as_target(t) for t in targets]
        if longer is not None:
            (a, b), delta = longer
            saved = self.pairs
            self.pairs = [(p, q, d + delta if {p, q} == {a, b} else d) for p, q, d in saved]
            try:
                return self.solve(targets, x0, jacobian)
            finally:
                self.pairs = saved
        sol = least_squares(
            self.residual,
            x0,
            jac=self.jacobian if jacobian == "analytic" else jacobian,
            args=(targets,),
            method="lm",
            xtol=1e-15,
            ftol=1e-15,
            gtol=1e-15,
            max_nfev=MAX_EVALUATIONS,
        )
        return sol.x, float(np.max(np.abs(sol.fun)))


class PointwiseCorner(PointwiseLinkage):
    """A lone corner (labelled ``""``: its names as they are): its mechanism's parts,
    links and lines (``Mechanism.pointwise``); ``hardpoints``: its points to use instead
    of its Geometry's."""

    def __init__(self, geometry: Geometry, hardpoints: dict[str, np.ndarray] | None = None):
        super().__init__(*labelled({"": geometry}, (), {"": hardpoints} if hardpoints else None))
        self.geometry = geometry
        self.inner = self.racks[0] if self.racks else None


class PointwiseAxle(PointwiseLinkage):
    """An axle file's: both corners (``corners``: side → the Geometry to use instead of
    the file's, the as-set ones) and its shared elements (:func:`labelled`)."""

    def __init__(self, axle, corners: dict[str, Geometry] | None = None):
        corners = corners or {"left": axle.left, "right": axle.right}
        super().__init__(*labelled(corners, elements_of(axle)))
        self.axle = axle

    def targets(self, sweep_targets, values) -> list:
        """One step of a sweep's targets (its own design state for heave and roll)."""
        return targets_at(sweep_targets, values, self.design)


def labelled(corners: dict[str, Geometry], elements=(), hardpoints: dict | None = None):
    """Labelled corners and the elements they share as :class:`PointwiseLinkage`'s
    arguments (spec, hardpoints, wheels, racks, planes): each corner's formulation with
    its names prefixed by its label (``left_``; a corner's ``""`` leaves them as they
    are), one rack unknown for every trackrod's inboard end, then each element's parts,
    links and plane rows (:data:`ELEMENTS`); ``hardpoints``: label → a corner's points
    to use instead of its Geometry's.

    >>> PointwiseLinkage(*labelled(subject.corners, subject.elements))  # any Assembly
    """
    spec = Pointwise({}, [], [], set())
    hp, racks = {}, []
    for label, g in corners.items():
        own, p = g.mechanism.pointwise(g), Assembly.prefix(label)

        def name(n, p=p):
            return f"{p}{n}"

        spec.parts.update({name(k): [name(n) for n in v] for k, v in own.parts.items()})
        spec.links.extend((name(a), name(b)) for a, b in own.links)
        spec.lines.extend(tuple(map(name, line)) for line in own.lines)
        spec.fixed.update(map(name, own.fixed))
        if own.rack is not None:
            racks.append(name(own.rack))
        points = (hardpoints or {}).get(label) or g.hardpoints
        if g.driveshaft is not None:  # its outer joint rides on the part with the axle
            wheel = next(k for k, v in own.parts.items() if "axle_outboard" in v)
            spec.parts[name(wheel)].append(name("cv_outboard"))
            ends = wheel_points(points["axle_inboard"], points["axle_outboard"], g.wheel)
            points = placed_points(g.driveshaft, points | ends) | points
        hp.update({name(n): v for n, v in points.items()})
    planes = []
    for element in elements:
        planes += ELEMENTS[type(element)](element, corners, spec, hp)
    wheels = {Assembly.prefix(label): g.wheel for label, g in corners.items()}
    return spec, hp, wheels, racks, planes


def sweep_values(sweep_targets, design: dict) -> np.ndarray:
    """A sweep's target values in SI, a row per step: heave m, roll rad, a point's
    coordinate m (absolute: a relative one from ``design``, the design points, m, by
    their labelled names)."""
    columns = []
    for t in sweep_targets:
        v = np.asarray(t.values, dtype=float)
        if t.quantity == "roll":
            columns.append(np.radians(v))
        elif t.quantity == "heave":
            columns.append(v * 1e-3)
        else:
            v = v * 1e-3
            if t.mode == "relative":
                v = v + design[_named(t)] @ t.unit_direction
            columns.append(v)
    return np.column_stack(columns)


def targets_at(sweep_targets, values, design: dict) -> list:
    """One step of a sweep's targets as point-based targets: ``values`` in SI as
    :func:`sweep_values` gives them; ``design``: the design points (m), for heave's and
    roll's zero (an axle's). A point's target names it by its corner's label (``side``:
    ``left_wheel_center``; none: ``wheel_center``)."""
    out = []
    for t, value in zip(sweep_targets, values, strict=True):
        if t.quantity in ("heave", "roll"):
            left, right = design["left_wheel_center"][2], design["right_wheel_center"][2]
            if t.quantity == "heave":
                out.append(Heave(0.5 * (left + right), float(value)))
            else:
                out.append(Roll(left - right, float(value)))
        else:
            out.append(Along(_named(t), t.unit_direction, float(value)))
    return out


def _named(target) -> str:
    """A sweep target's point by its labelled name (its corner's ``side``, if any)."""
    return Assembly.prefix(target.side or "") + target.point


def _anti_roll_bar(bar: AntiRollBar, corners: dict[str, Geometry], spec, hp) -> list:
    """The anti-roll bar's rows (:data:`ANTI_ROLL`, by its type) and its points: its
    axis or pivot, each of its two corners' droplink ends (its names: its corners'
    labels and its own prefix — an axle's left/right and none, a vehicle's axle's
    fl/fr and ``front_``)."""
    axle = bar.axle
    if axle.anti_roll not in ANTI_ROLL:
        raise PinSuspError(
            f"the point-based formulation has no {axle.anti_roll} anti-roll bar yet "
            f"(it has: {', '.join(ANTI_ROLL)})"
        )
    hp.update(bar.center)
    own = {label: corners[label] for label in bar.labels}
    side_points = {label: axle.side_points[bar.sides[label]] for label in bar.labels}
    _side_points(side_points, own, "droplink_", hp)
    return ANTI_ROLL[axle.anti_roll](bar, own, spec, hp)


def _heave_link(link: HeaveLink, corners: dict[str, Geometry], spec, hp) -> list:
    """The heave link, measured only: its end on each of its corners' rockers (no rows)."""
    own = {label: corners[label] for label in link.labels}
    _side_points(link.side_points, own, "heave_link_", hp)
    if link.kind != "none":
        for label in own:
            p = Assembly.prefix(label)
            spec.parts[f"{p}rocker"].append(f"{p}heave_link_rocker")
    return []


def _side_points(side_points: dict, corners, start: str, hp) -> None:
    """An element's points on each corner (names beginning ``start``), prefixed."""
    for label in corners:
        p = Assembly.prefix(label)
        hp.update({p + n: v for n, v in side_points[label].items() if n.startswith(start)})


def _no_bar(bar, corners, spec, hp) -> list:
    """No anti-roll bar: nothing joins the sides but the rack."""
    return []


def _u_bar(bar, corners, spec, hp) -> list:
    """Each side's bar arm is a part of three points: the bar's axis ends, fixed on
    the chassis, and the arm's end, which keeps its distance to both (it turns on a
    circle about the axis). A rigid droplink joins each arm's end to
    ``droplink_rocker`` on the rocker or, without a rocker, to ``droplink_lower`` on
    the body named by ``anti_roll.mount`` (``arm``: the wheel's body).

    A rigid bar (``stiffness: rigid``) is one part on the axis (:func:`_rigid_bar`)."""
    axis = bar.u_axis
    sides = [Assembly.prefix(label) for label in corners]
    ends = [f"{p}droplink_u_bar" for p in sides]
    spec.fixed.update(axis)
    if bar.axle.anti_roll_rigid:
        _rigid_bar(bar.prefix, axis, ends, spec, hp)
    else:
        for p in sides:
            spec.parts[f"{p}arb_arm"] = [*axis, f"{p}droplink_u_bar"]
    _droplinks(bar, corners, "droplink_u_bar", spec)
    return []


def _t_bar(bar, corners, spec, hp) -> list:
    """The crossbar's ends and the pivot ``arb_t_bar_pivot`` (fixed: a ball) are one
    part, a rigid triangle; one plane row holds the crossbar's midpoint in y = 0 (at
    its design y, which the axle's check keeps within 0.02 mm of it); a rigid
    droplink from each end as for the U-bar.

    A rigid bar (``stiffness: rigid``) cannot twist: the crossbar only pitches about
    the chassis y axis through the pivot — the U-bar's rigid bar on that axis, its
    second point ``arb_t_bar_axis`` (the pivot moved along y as far as the left end
    is from it). Its midpoint then stays in its plane by itself."""
    pivot = bar.pivot
    ends = [f"{Assembly.prefix(label)}droplink_t_bar" for label in corners]
    spec.fixed.add(pivot)
    planes = []
    if bar.axle.anti_roll_rigid:
        second = f"{bar.prefix}arb_t_bar_axis"
        hp[second] = hp[pivot] + np.linalg.norm(hp[ends[0]] - hp[pivot]) * Y
        spec.fixed.add(second)
        _rigid_bar(bar.prefix, (pivot, second), ends, spec, hp)
    else:
        spec.parts[f"{bar.prefix}arb_t_bar"] = [pivot, *ends]
        planes.append(Midpoint(*ends, Y, 0.5 * (hp[ends[0]] + hp[ends[1]]) @ Y))
    _droplinks(bar, corners, "droplink_t_bar", spec)
    return planes


def _rigid_bar(prefix: str, axis, ends, spec, hp) -> None:
    """A rigid bar turning about the fixed ``axis`` (two point names): one part of the
    axis, ``arb_bar_quarter`` — a point a quarter turn round from the last end — and
    the ``ends`` (its names with the bar's ``prefix``). The distance between two ends
    alike placed about the axis is at its minimum, so alone it would not fix their
    relative turn (its gradient vanishes there)."""
    a, b = (hp[n] for n in axis)
    u = (b - a) / np.linalg.norm(b - a)
    end = hp[ends[-1]]
    foot = a + u * ((end - a) @ u)
    hp[f"{prefix}arb_bar_quarter"] = foot + np.cross(u, end - foot)
    spec.parts[f"{prefix}arb_bar"] = [*axis, f"{prefix}arb_bar_quarter", *ends]


def _droplinks(bar, corners: dict[str, Geometry], end: str, spec) -> None:
    """Per corner a rigid link from the rocker's ``droplink_rocker`` (or
    ``droplink_lower`` on the body ``anti_roll.mount`` names) to the bar's point
    ``<label>_<end>``."""
    axle = bar.axle
    for label, g in corners.items():
        side = Assembly.prefix(label)
        if "droplink_rocker" in axle.side_points[bar.sides[label]]:
            upper, body = "droplink_rocker", "rocker"
        else:
            mount = axle.anti_roll_mount
            upper, body = "droplink_lower", g.mechanism.WHEEL_BODY if mount == "arm" else mount
        if f"{side}{body}" not in spec.parts:
            own = [p.removeprefix(side) for p in spec.parts if p.startswith(side)]
            raise PinSuspError(
                f"the point-based formulation has no rigid part {body!r} to carry the "
                f"droplink (its parts: {', '.join(own)})"
            )
        spec.parts[f"{side}{body}"].append(f"{side}{upper}")
        spec.links.append((f"{side}{upper}", f"{side}{end}"))


# anti_roll.type → what it adds to the axle's parts, links, lines and fixed points;
# it returns its plane rows (conditions always held, as targets).
ANTI_ROLL = {"none": _no_bar, "u_bar": _u_bar, "t_bar": _t_bar}
# a shared element (pin_susp/elements/) → its point-based parts, links and plane rows
ELEMENTS = {AntiRollBar: _anti_roll_bar, HeaveLink: _heave_link}
