"""Hardpoint sensitivities: d(metric)/d(hardpoint coordinate), exact, at design or
along a sweep; an axle's (each side's corner lifted onto the axle's moves, and its own
columns of both sides together); the tables' ranking and point groups.

The model — a corner rebuilt with virtual joints that move each hardpoint, and the
implicit differentiation through its closures — is ``sensitivity_model.py``.
"""

from __future__ import annotations

import numpy as np

from ..columns.metrics import METRIC_BY_NAME, PointSet
from ..errors import InputError
from ..maths.jet import Dual
from ..subjects.axle_file import AXLE_COLUMNS as AXLE_COLUMNS  # the axle's own, by its old address
from .sensitivity_model import AXES, HardpointSensitivity, Sensitivity, of_state
from .sensitivity_model import V as V  # the model's names, by their old address


def hardpoint_sensitivities(corner, sweep=None, progress=None, with_results: bool = False):
    """Sensitivities at the design state, or at every converged step of ``sweep``.

    A list of Sensitivity; with ``with_results``, (that list, the sweep's
    Results or None) so that a caller can name the steps that have none.
    (:func:`subject_sensitivities` of the corner.)
    """
    from ..model.sweep import load_sweep

    if sweep is not None and not hasattr(sweep, "targets"):
        sweep = load_sweep(sweep)
    states, results = subject_sensitivities(SubjectSensitivity(corner), sweep, progress)
    return (states, results) if with_results else states


# How much of a change is worth talking about, per unit, for the terminal table.
STEP = {"deg": 0.1, "mm": 1.0, "%": 1.0, "deg/mm": 0.01, "mm/mm": 0.01}


def largest(s: Sensitivity, name: str, top: int = 3, points=None) -> list[tuple[str, str, float]]:
    """The ``top`` hardpoint coordinates that move metric ``name`` most (among ``points``)."""
    v = s.values[name].copy()
    if points is not None:
        v[[h not in points for h in s.hardpoints]] = np.nan
    order = np.argsort(-np.nan_to_num(np.abs(v)).ravel())[:top]
    return [
        (s.hardpoints[i // 3], AXES[i % 3], float(v.flat[i]))
        for i in order
        if np.isfinite(v.flat[i]) and abs(v.flat[i]) > 1e-12
    ]


SPINDLE = ("axle_inboard", "axle_outboard")  # set by the hub and upright, not moved to tune
POINT_GROUPS = {
    "designer": "chassis pickups and link ends (not the spindle points axle_inboard/outboard)",
    "chassis": "the chassis pickups",
    "upright": "the points that ride with the upright, its ball joints included",
    "all": "every hardpoint",
}


def select_points(corner, spec: str = "designer") -> list[str]:
    """Hardpoints by group (POINT_GROUPS) or names, several separated by commas."""
    items = [item.strip() for item in spec.split(",") if item.strip()]
    if len(items) > 1:
        chosen = [n for item in items for n in select_points(corner, item)]
        return list(dict.fromkeys(chosen))
    names = list(corner.geometry.hardpoints)
    if spec == "all":
        return names
    if spec == "designer":
        return [n for n in names if n not in SPINDLE]
    if spec == "chassis":
        return [n for n in names if corner.body_of(n) == "chassis"]
    if spec == "upright":
        wheel = corner.mechanism.WHEEL_BODY
        joints = {
            p for b in corner.tree.bodies if b.name == wheel and b.joint for p in b.joint.defined_by
        }
        on_upright = {
            point
            for c in corner.tree.closures
            if any(link == wheel for link, _ in c.anchors)
            for point in c.points
        }
        return [n for n in names if corner.body_of(n) == wheel or n in joints | on_upright]
    wanted = [n.strip() for n in spec.split(",") if n.strip()]
    unknown = [n for n in wanted if n not in names]
    if unknown or not wanted:
        groups = ", ".join(POINT_GROUPS)
        raise InputError(
            "--points",
            "",
            f"unknown hardpoint {', '.join(unknown) or repr(spec)} (give groups — {groups} — "
            f"or names of this corner's hardpoints, separated by commas: {', '.join(names)})",
        )
    return wanted


# ---------------------------------------------------------------- a subject

SYMMETRIC_MOVE = (
    "a symmetric move: hardpoint P moves the left P by (dx, dy, dz) and the right P by "
    "(dx, -dy, dz)"
)
ONE_SIDED_MOVE = "a one-sided move: left_P and right_P each move alone"


class SubjectSensitivity:
    """d(column)/d(hardpoint coordinate) of a subject (an Assembly), exact.

    Each labelled corner is its HardpointSensitivity (the as-set corner's Linkage,
    ``Assembly.corner_linkage``); a corner's one, unlabelled, gives its columns as they
    are. An axle's (docs/axle.md) or a vehicle's (docs/vehicle.md): with each wheel
    centre's height and the rack held (a vehicle's in its chassis frame, the body
    still), the corners share nothing else, so a corner's columns (suffixed ``_left``,
    ``_fl``) move with its own points only. The subject's own columns of a pair of its
    corners (``Assembly.sensitivity_pairs``: an axle's track, roll centre, body roll,
    the roll rates, a vehicle's per axle) are plain functions of both corners' contact
    patches, instant centres, wheel heights and rates, run on the corners' nested Duals
    lifted onto the subject's directions; a vehicle's of the whole car
    (``Assembly.car_sensitivities``: the pitch centre, the anti %, the roll axis)
    follow from those. The directions (``Assembly.sensitivity_move``):

    - symmetric (default): one direction per corner point and axis, the left
      point moved by (dx, dy, dz) and the right one by (dx, −dy, dz) (a vehicle's per
      axle: ``front_P``, ``rear_P``);
    - one-sided: the left's points (``left_…``), then the right's, each alone (a
      vehicle's: ``fl_…``, …, ``rr_…``).

    Inside, the one driver is roll's tangent — the left hub z up, the right one
    down, equally, the rack held — so d(column)/d roll and its sensitivities
    follow as the axle's sweep columns do (axle._roll_rates). The bar's and the
    heave link's own points are not among the hardpoints: they move no column here.
    """

    def __init__(self, model, one_sided: bool = False, like: SubjectSensitivity | None = None):
        """``like``: the SubjectSensitivity of another subject of this one's structure (a
        study's variant), whose corners' models lend theirs their frames and Pinocchio
        data (HardpointSensitivity's ``like``)."""
        self.model, self.one_sided = model, one_sided
        labels = model.labels
        self.sides = {
            s: HardpointSensitivity(model.corner_linkage(s), like and like.sides.get(s))
            for s in labels
        }
        names = {s: h.hardpoints for s, h in self.sides.items()}
        self.moves = {s: model.sensitivity_move(s, one_sided) for s in labels}
        self.hardpoints = list(
            dict.fromkeys(self.moves[s][0] + n for s in labels for n in names[s])
        )
        # lift[side] (3 subject points, 3 side points): d/d(subject coordinate) from
        # d/d(side's); None for a corner's one (its coordinates as they are)
        self.lift = {}
        for s in labels:
            if not s:
                self.lift[s] = None
                continue
            prefix, mirrored = self.moves[s]
            flip = np.diag([1.0, -1.0 if mirrored else 1.0, 1.0])
            lift = np.zeros((3 * len(self.hardpoints), 3 * len(names[s])))
            for j, n in enumerate(names[s]):
                i = self.hardpoints.index(prefix + n)
                lift[3 * i : 3 * i + 3, 3 * j : 3 * j + 3] = flip
            self.lift[s] = lift
        # each side's corner joints in the subject's configuration
        whole = model.model
        self.joints = {}
        for s, h in self.sides.items():
            c = h.corner.model
            pairs = [
                (c.joints[j].idx_q, whole.joints[whole.getJointId(_joint(c.names[j], s))].idx_q)
                for j in range(1, c.njoints)
            ]
            self.joints[s] = tuple(np.array(x) for x in zip(*pairs, strict=True))

    def name_of(self, label: str, point: str) -> str:
        """A corner's hardpoint as the subject's direction names it (``P``, ``left_P``,
        ``front_P``, ``fl_P``)."""
        return self.moves[label][0] + point

    def side_q(self, q: np.ndarray, side: str) -> np.ndarray:
        """The side's corner configuration within the subject's q."""
        corner, whole = self.joints[side]
        out = np.empty(self.sides[side].corner.model.nq)
        out[corner] = q[whole]
        return out

    def at(
        self, q: np.ndarray | None = None, step: int = 0, targets=None, only=None
    ) -> Sensitivity:
        """At the subject's solved configuration q (default: its design state), holding
        ``targets`` (``Assembly.held_at``; default: each wheel centre's height and the
        rack where q has them)."""
        return self.at_many([(q, step, targets)], only)[0]

    def at_many(self, states: list[tuple], only=None) -> list[Sensitivity]:
        """``at`` at each state (q, step, targets), each corner's metric functions run
        once for all; the drivers' rates only where the columns ``only`` read them."""
        own = [n for n in self.model.sensitivity_columns if only is None or n in only]
        steps = [step for _, step, _ in states]
        jets, per_side = {}, {}
        for s, h in self.sides.items():
            suffix = self.model.suffix(s)
            mine = None if only is None else {_unsuffixed(n, suffix) for n in only}
            side_states = [
                (h.corner.q_design if q is None else self.side_q(q, s), targets)
                for q, _, targets in states
            ]
            jets[s], per_side[s] = h.evaluated(side_states, steps, mine, rates=bool(own))
        n = len(self.hardpoints)
        if own:
            with np.errstate(invalid="ignore", divide="ignore"):
                columns = self._own_columns(jets)
        out = []
        for i, step in enumerate(steps):
            values, units, metrics = {}, {}, {}
            for s, sides in per_side.items():
                lift, side = self.lift[s], sides[i]
                for name, v in side.values.items():
                    key = name + self.model.suffix(s)
                    values[key] = v if lift is None else (lift @ v.ravel()).reshape(n, 3)
                    units[key], metrics[key] = side.units[name], side.metrics[name]
            for name in own:
                x, unit_ = columns[name]
                metrics[name] = float(of_state(x.val, i))
                values[name] = of_state(x.der, i).reshape(n, 3) * 1e-3  # per mm
                units[name] = f"{unit_}/mm"
            out.append(Sensitivity(step, self.hardpoints, values, units, metrics))
        return out

    def _lifted(self, side: str, x, sign: float = 1.0) -> Dual:
        """A side's nested scalar on the subject's directions: outside, the subject's
        hardpoint coordinates; inside, roll's tangent (this side's hub z, + ``sign``: the
        pair's left +, its right −)."""
        lift = self.lift[side]
        return Dual(
            Dual(x.val.val, sign * x.val.der[:1]),
            Dual(
                np.tensordot(lift, x.der.val, axes=1),
                sign * np.tensordot(lift, x.der.der[:, :1], axes=1),
            ),
        )

    def _own_columns(self, jets: dict) -> dict:
        """The subject's own columns (``Assembly.sensitivity_columns``): each pair's, as
        the subject names an axle's (``Assembly.pair_column``), then the car's
        (``Assembly.car_sensitivities``); name → (Dual over the subject's hardpoint
        coordinates (per m), unit)."""
        out, pairs, corners = {}, {}, {}
        for pair in self.model.sensitivity_pairs:
            pairs[pair] = self._axle_columns(jets, *pair)
            for name, column in pairs[pair].items():
                named = self.model.pair_column(pair, name)
                if named is not None:
                    out[named] = column
        if self.model.car_sensitivity_columns:
            for s, (points, design) in jets.items():
                ps = PointSet(points, design, self.sides[s].corner.geometry)
                parts = {
                    f"{point}_{a}": points[point][..., i] * 1e3
                    for point in ("contact_patch_center", "wheel_center")
                    for i, a in enumerate("xyz")
                }
                for name in ("svic_x", "svic_z"):
                    m = METRIC_BY_NAME[name]
                    parts[name] = m.function(ps) * m.scale
                corners[s] = {k: _value(self._lifted(s, v)) for k, v in parts.items()}
            out |= self.model.car_sensitivities(corners, pairs)
        return out

    def _axle_columns(self, jets: dict, first: str = "left", second: str = "right") -> dict:
        """name → (Dual over the subject's hardpoint coordinates (per m), unit): an
        axle's columns of the pair of corners ``first`` (its left) and ``second``."""
        from ..columns.metrics import fvic_y, fvic_z
        from ..subjects.axle import roll_centre

        sides = {}
        for s, sign in ((first, 1.0), (second, -1.0)):
            points, design = jets[s]
            ps = PointSet(points, design, self.sides[s].corner.geometry)
            cp, wc = points["contact_patch_center"], points["wheel_center"]
            parts = {
                "cp_y": cp[..., 1] * 1e3,
                "cp_z": cp[..., 2] * 1e3,
                "fvic_y": fvic_y(ps) * 1e3,
                "fvic_z": fvic_z(ps) * 1e3,
                "dz": (wc[..., 2] - design["wheel_center"][..., 2]) * 1e3,
            }
            for name in ("camber", "roadwheel_angle"):
                m = METRIC_BY_NAME[name]
                parts[name] = m.function(ps) * m.scale
            sides[s] = {k: self._lifted(s, v, sign) for k, v in parts.items()}
        left, right = sides[first], sides[second]
        deg = 180.0 / np.pi
        b = left["cp_y"] - right["cp_y"]
        roll = np.arctan2(left["dz"] - right["dz"], b)  # rad
        body_roll = np.arctan2(right["cp_z"] - left["cp_z"], b) * deg
        ends = ("cp_y", "cp_z", "fvic_y", "fvic_z")  # each side's line CP → FVIC
        rc = roll_centre([tuple(side[k] for k in ends) for side in (left, right)])
        nested = {
            "body_roll": (body_roll, "deg"),
            "camber_to_ground_left": (left["camber"] - body_roll, "deg"),
            "camber_to_ground_right": (right["camber"] + body_roll, "deg"),
            "track": (np.abs(b), "mm"),
            "roll_center_y": (rc[0], "mm"),
            "roll_center_z": (rc[1], "mm"),
        }
        out = {name: (_value(x), unit_) for name, (x, unit_) in nested.items()}
        per_roll = _rate(roll) * deg  # deg of roll per m along the tangent
        for name in ("camber", "roadwheel_angle"):
            for s, side in zip(("left", "right"), (left, right), strict=True):
                out[f"deriv_{name}_wrt_roll_{s}"] = (_rate(side[name]) / per_roll, "deg/deg")
        for axis, x in zip("yz", rc, strict=True):
            out[f"deriv_roll_center_{axis}_wrt_roll"] = (_rate(x) / per_roll, "mm/deg")
        return out


def _joint(name: str, label: str) -> str:
    """A corner joint's name in the subject's model (an axle's rack is shared)."""
    return name if name == "rack_slide" else f"{label}_{name}" if label else name


def _value(x) -> Dual:
    """A nested scalar's value, with its hardpoint derivatives (outside)."""
    return Dual(x.val.val, x.der.val[:, 0])


def _rate(x) -> Dual:
    """A nested scalar's rate along the (one) driver, with its hardpoint derivatives."""
    return Dual(x.val.der[0], x.der.der[:, 0])


def subject_sensitivities(sens: SubjectSensitivity, sweep=None, progress=None):
    """A subject's sensitivities (``SubjectSensitivity(subject)``) at its design state,
    or at every converged step of ``sweep``, holding there what the subject holds
    (``Assembly.held_at``: a corner's, the sweep's targets; an axle's, each wheel
    centre's height and the rack as solved — a roll or heave target too: the roll angle
    then moves with the track). (A list of Sensitivity, the results the failure report
    reads, ``Assembly.sensitivity_sweep``, or None.)"""
    subject = sens.model
    if sweep is None:
        return [sens.at()], None
    solutions, results = subject.sensitivity_sweep(sweep)
    out = []
    for i, solution in enumerate(solutions):
        if solution.converged:
            out.append(sens.at(solution.q, step=i, targets=subject.held_at(sweep, i)))
        if progress is not None:
            progress(i + 1, len(solutions))
    return out, results


AxleSensitivity = SubjectSensitivity  # an axle's, by its old name
axle_sensitivities = subject_sensitivities  # (sens, sweep, progress), by its old name


def _unsuffixed(name: str, suffix: str) -> str:
    """A side's column's name without its side's suffix (``camber_left`` → ``camber``)."""
    return name[: -len(suffix)] if suffix and name.endswith(suffix) else name
