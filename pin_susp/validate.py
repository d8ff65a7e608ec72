"""Cross-validation: every step re-solved by engines that share no kinematics with ours.

- ``mujoco``: the exported MJCF in MuJoCo — its own forward kinematics,
  equality-constraint Jacobians (``efc_J``/``efc_pos``), site Jacobians and
  ``mj_integratePos``, driven by Newton to the same targets;
- ``drake``: the exported URDF parsed by Drake's own parser into a
  ``MultibodyPlant``, the loop closures and the targets as constraints of
  Drake's ``InverseKinematics``, solved by IPOPT; points and Jacobians from
  the plant (``CalcPointsPositions``, ``CalcJacobianTranslationalVelocity``);
- ``pointwise``: hardpoints as unknowns, rigid distances, scipy least_squares.

Each engine starts every step from the design state (no warm start), so a
step is checked on its own. The rates along the drivers (hub z, rack, a toe
link's length) come from each engine's own Jacobian at its pose: with them
the derivative columns, the steer screw axis and the instant centres of a
bump twist are checked too.
The metrics are then computed from each engine's points and compared with
pin_susp's, metric by metric and point by point.

A corner or an axle (docs/axle.md) alike: what differs between them — their
points, drivers, targets and columns — is a scope (:class:`CornerScope`,
:class:`AxleScope`); the engines only see points and targets.
"""

from __future__ import annotations

import itertools
import logging
import xml.etree.ElementTree as ET
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from .axle import (
    SIDES,
    AxleModel,
    axle_metric_columns,
    axle_results,
    solve_axle_sweep,
    target_values,
)
from .constraints import ContactPatchPoint
from .errors import PinSuspError
from .jet import Dual
from .jet import value as plain
from .metrics import METRICS, TOE_LINK, metric_columns
from .pointwise import Along, PointwiseAxle, PointwiseCorner, Y, Z, as_target, axle_targets
from .urdf import NAMESPACE, read_closures, tree_to_urdf

TOLERANCE = 1e-6  # mm and deg
# Instant centres of nearly parallel wishbones lie kilometres away, where a
# difference of 1e-13 m in a ball joint moves them by micrometres: besides the
# absolute tolerance, a column may differ by this fraction of its value.
RELATIVE = 1e-9
RATE_METRICS = {m.name for m in METRICS if m.rates}
STEP = 1e-3  # m: the drivers' step for the engines' rates (±STEP, ±2·STEP)


@dataclass
class EngineReport:
    """max |difference| to pin_susp per column, over every step the engine solved."""

    engine: str
    tolerance: float = TOLERANCE
    differences: dict[str, float] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    failed_steps: list[int] = field(default_factory=list)
    disagree: set[str] = field(default_factory=set)
    # steps it solved on another assembly branch than pin_susp's (not compared), and
    # what flipped; ``other_branch``: such steps where pin_susp found no pose either
    branch_steps: list[int] = field(default_factory=list)
    other_branch: list[int] = field(default_factory=list)
    flipped: set[str] = field(default_factory=set)
    not_compared: set[str] = field(default_factory=set)  # the engine could not compute them
    note: str = ""
    warnings: int = 0  # how many warnings the engine raised (MuJoCo's, Drake's: silenced, counted)
    first_warning: str = ""

    @property
    def worst(self) -> float:
        return max(self.differences.values(), default=0.0)

    @property
    def agrees(self) -> bool:
        return not (self.note or self.failed_steps or self.disagree or self.branch_steps)


def compare(
    subject, results, points_per_step: list | None, engine: str, tolerance: float = TOLERANCE
) -> EngineReport:
    """Metric columns of an engine's points against pin_susp's results (a corner's or
    an axle's: ``subject`` is a Corner or an AxleModel)."""
    scope = _scope(subject)
    report = EngineReport(engine, tolerance)
    branches = Branches(scope.tree)
    for i, points in enumerate(points_per_step):
        if points is None:
            report.failed_steps.append(i)
            continue
        flipped = branches.flipped(scope.positions(points))
        if flipped is not None:  # another assembly: its differences mean nothing
            report.flipped.add(flipped)
            converged = results["solver_converged"][i]
            (report.branch_steps if converged else report.other_branch).append(i)
            continue
        if not results["solver_converged"][i]:
            continue
        stalled = scope.stalled(points)  # a driver the engine cannot move
        for name, (values, unit) in scope.columns(points).items():
            if np.isnan(values[0]) and stalled and scope.from_rates(name):
                report.not_compared.add(name)
                continue
            _record(report, name, unit, values[0], results[name][i], scope.size(name, results, i))
        for name, position in scope.positions(points).items():
            for a, axis in enumerate("xyz"):
                _record(report, "points", "mm", position[a] * 1e3, results[f"{name}_{axis}"][i])
    return report


class Branches:
    """pin_susp's assembly at design, to tell an engine's pose on another branch of the
    mechanism: each loop's side (the chirality of its closure's branch points, which
    pin_susp's solver keeps, constraints.LoopBranch) and each body's handedness (four of
    its points, its joint's among them: a rigid body turns but is never mirrored — a
    point-based solve, which only keeps distances, can mirror one)."""

    def __init__(self, tree):
        from .constraints import MEASURES, LoopBranch, chirality, pick_branch
        from .deadcentre import tree_point_name

        design = {name: p.tolist() for name, (_, p) in tree.points.items()}
        self.checks = []  # (what flipped, measure, four point names, sign at design)
        for c in tree.closures:
            candidates = [b for b in c.branch_candidates if all(n in design for n in b)]
            if candidates:  # the solver's own choice of points (its fallback included)
                measure = MEASURES[c.branch_kind]
                names, v = pick_branch(candidates, measure, design.__getitem__)
                if abs(v) >= LoopBranch.DEGENERATE:
                    self.checks.append((f"the {c.name} loop", measure, names, np.sign(v)))
        on = {}
        for name, (body, _) in tree.points.items():
            on.setdefault(body, []).append(name)
        for b in tree.bodies:
            if b.joint is None:
                continue
            own = [tree_point_name(n, b.name, tree) for n in b.joint.defined_by]
            names = list(dict.fromkeys([n for n in own if n in design] + on.get(b.name, [])))
            quads = list(itertools.combinations(names[:8], 4))
            if not quads:
                continue
            best = max(quads, key=lambda q: abs(chirality(*(design[n] for n in q))))
            v = chirality(*(design[n] for n in best))
            if abs(v) > 1e-3:  # well clear of flat
                what = f"the {b.name.replace('_', ' ')} mirrored"
                self.checks.append((what, chirality, best, np.sign(v)))

    def flipped(self, positions: dict) -> str | None:
        """What is on another branch at these positions (name → (3,) m), or None."""
        for what, measure, names, sign in self.checks:
            if all(n in positions for n in names):
                if measure(*(np.asarray(positions[n]).tolist() for n in names)) * sign <= 0:
                    return what
        return None


def _record(report, name, unit, theirs, ours, size=None) -> None:
    """Keep the largest difference; beyond the tolerance plus RELATIVE·size (default
    |ours|), the column disagrees."""
    if np.isnan(ours) and np.isnan(theirs):
        return
    diff = abs(ours - theirs) if not (np.isnan(ours) or np.isnan(theirs)) else np.inf
    report.differences[name] = max(report.differences.get(name, 0.0), float(diff))
    report.units[name] = unit
    size = abs(ours) if size is None or np.isnan(size) else size
    if not diff <= report.tolerance + RELATIVE * size:
        report.disagree.add(name)


def step_targets(subject, sweep) -> list[list]:
    """Every step's targets: (point, unit direction, absolute value m) for a corner;
    point-based targets (:mod:`pin_susp.pointwise`) for an axle."""
    return _scope(subject).step_targets(sweep)


def held_drivers(corner, points: dict) -> list[tuple[str, np.ndarray, float]]:
    """The drivers as targets held where the engine's pose is: wheel-centre z, and the
    rack (trackrod_inboard y) on a rack corner."""
    held = [("wheel_center", Z, float(points["wheel_center"][2]))]
    g = corner.geometry
    if g.steering == "rack":
        inner = g.steering_points[0]
        held.append((inner, Y, float(points[inner][1])))
    return held


class CornerScope:
    """What the engines need from a corner: its points and drivers, the sweep as
    targets, the columns computed from an engine's points (name → Dual)."""

    kind = "corner"

    def __init__(self, corner):
        self.subject = corner
        self.tree = corner.tree
        self.drivers = len(corner.drivers)
        g = corner.geometry
        # a driver no target holds: the fixed toe link's length (a link of the engine)
        self.links = [g.steering_points] if TOE_LINK in corner.drivers else []
        self.wheels = {"": (g.wheel.radius, corner.mechanism.WHEEL_BODY)}
        self.sites = [n for n in corner.point_names if n != "contact_patch_center"]

    def results(self, sweep):
        return self.subject.run_sweep(sweep)

    def pointwise(self) -> PointwiseCorner:
        return PointwiseCorner(self.subject.geometry)

    def step_targets(self, sweep) -> list[list]:
        held = self.subject.held_targets(sweep.targets)  # the rack at design if not given
        values = self.subject.target_values(held)
        return [
            [(t.point, t.unit_direction, float(v[k])) for k, t in enumerate(held)] for v in values
        ]

    def held(self, points: dict) -> list:
        return held_drivers(self.subject, points)

    def duals(self, points: dict, rates: dict) -> dict[str, Dual]:
        return {name: Dual(p[None], rates[name][:, None]) for name, p in points.items()}

    def columns(self, points: dict) -> dict:
        c = self.subject
        design = {k: v[None] for k, v in c.design_positions.items()}
        return metric_columns(c.geometry, points, design, c.spring_sense)

    def positions(self, points: dict) -> dict[str, np.ndarray]:
        return {name: points[name].val[0] for name in self.subject.point_names}

    def stalled(self, points: dict) -> bool:
        return bool(np.isnan(plain(points["wheel_center"].der)).any())

    def from_rates(self, name: str) -> bool:
        return name in RATE_METRICS

    def size(self, name: str, results, i: int) -> float:
        """What the column's RELATIVE tolerance is a fraction of: its own value."""
        return abs(results[name][i])


class AxleScope:
    """An axle's (docs/axle.md): the drivers are each wheel centre's z and the rack
    (or each side's fixed toe link); a point is a Dual per side (its rates along
    that side's hub z, the other wheel and the rack held, and along the rack or its
    toe link's length), as axle_results takes them."""

    kind = "axle"
    # the roll centre's columns: name → the vector it is a coordinate of
    ROLL_CENTRE = {
        name: pair
        for pair in (
            ("roll_center_y", "roll_center_z"),
            ("deriv_roll_center_y_wrt_roll", "deriv_roll_center_z_wrt_roll"),
        )
        for name in pair
    }

    def __init__(self, model: AxleModel):
        self.subject = model
        self.tree = model.tree
        self.rack = model.geometries["left"].steering == "rack"
        held = len(SIDES) + self.rack
        # each side's drivers: its hub z, the rack, or its fixed toe link's length
        # (a driver no target holds: a link of the engine), as axle_results orders them
        self.side_drivers, self.links = {}, []
        for c, (side, g) in enumerate(model.geometries.items()):
            self.side_drivers[side] = [c, len(SIDES)] if self.rack else [c]
            if g.steering == "none" and g.steering_points:
                self.side_drivers[side].append(held + len(self.links))
                self.links.append(tuple(f"{side}_{n}" for n in g.steering_points))
        self.drivers = held + len(self.links)
        self.wheels = {
            f"{side}_": (g.wheel.radius, f"{side}_{g.mechanism.WHEEL_BODY}")
            for side, g in model.geometries.items()
        }
        self.sites = [n for n in model.output_points if not n.endswith("contact_patch_center")]

    def results(self, sweep):
        model = self.subject
        return axle_results(model, sweep, solve_axle_sweep(model, sweep))

    def pointwise(self) -> PointwiseAxle:
        return PointwiseAxle(self.subject.axle, self.subject.geometries)

    def step_targets(self, sweep) -> list[list]:
        model = self.subject
        targets = model.held_sweep(sweep).targets  # the rack at design if not given
        values = target_values(model, targets)
        return [axle_targets(targets, v, model.design_positions) for v in values]

    def held(self, points: dict) -> list:
        held = [Along(f"{s}_wheel_center", Z, float(points[f"{s}_wheel_center"][2])) for s in SIDES]
        if self.rack:
            inner = f"left_{self.subject.geometries['left'].steering_points[0]}"
            held.append(Along(inner, Y, float(points[inner][1])))
        return held

    def duals(self, points: dict, rates: dict) -> dict[str, dict[str, Dual]]:
        """Each side's rates; for a rigid bar none along a wheel's own height, as the
        sweep writes none (one wheel cannot move with the other held)."""
        axle = self.subject.axle
        hub = np.array([np.nan if axle is not None and axle.anti_roll_rigid else 1.0])
        scale = {s: np.r_[hub, np.ones(len(self.side_drivers[s]) - 1)][:, None] for s in SIDES}
        return {
            name: {
                s: Dual(p[None], rates[name][self.side_drivers[s]][:, None] * scale[s])
                for s in SIDES
            }
            for name, p in points.items()
        }

    def columns(self, points: dict) -> dict:
        """Every metric column, computed from the points as axle_results computes them
        (with its own pieces: the per-side columns, the axle's, the roll rates)."""
        return axle_metric_columns(self.subject, points)

    def positions(self, points: dict) -> dict[str, np.ndarray]:
        return {name: points[name]["left"].val[0] for name in self.subject.output_points}

    def stalled(self, points: dict) -> bool:
        if self.subject.axle is not None and self.subject.axle.anti_roll_rigid:
            return False  # no rates by design (duals): compared as blank, like the sweep's
        return any(np.isnan(plain(points[f"{s}_wheel_center"][s].der)).any() for s in SIDES)

    def from_rates(self, name: str) -> bool:
        return name.removesuffix("_left").removesuffix("_right") in RATE_METRICS

    def size(self, name: str, results, i: int) -> float:
        """What the column's RELATIVE tolerance is a fraction of: its own value; for the
        roll centre and its rates, the vector's length times |RC| / track at least 1.

        The roll centre crosses two lines from contact patches a track apart; when
        they are nearly parallel (instant centres a hundred metres out) it lies at
        |RC| ≫ track, and a rounding δ in a line's slope moves it by (|RC|²/track)·δ:
        a relative error |RC|/track times larger than its inputs', in either
        coordinate and in its rates alike.
        """
        if name not in self.ROLL_CENTRE:
            return abs(results[name][i])
        rc = np.hypot(results["roll_center_y"][i], results["roll_center_z"][i])
        lever = max(1.0, rc / results["track"][i])
        return np.hypot(*(results[n][i] for n in self.ROLL_CENTRE[name])) * lever


def _scope(subject) -> CornerScope | AxleScope:
    if isinstance(subject, CornerScope | AxleScope):
        return subject
    return AxleScope(subject) if isinstance(subject, AxleModel) else CornerScope(subject)


def pointwise_points(subject, sweep) -> list[dict | None]:
    """The point-based formulation's points at every step, with their rates along the
    drivers; None where it did not converge.

    The rates: the tangent of its own equations, J·dx = e for the driver's row
    (the held target's, or the toe link's distance), solved in the least-squares
    sense (its rigid-part distances are redundant, the system is consistent);
    the points then move along dx (Richardson differences of the explicit point
    formulas, error ~1e-12).
    """
    scope = _scope(subject)
    model = scope.pointwise()
    out = []
    for targets in scope.step_targets(sweep):
        x, residual = model.solve(targets)
        if not residual < 1e-12:
            out.append(None)
            continue
        points = model.points(x)
        held = scope.held(points)
        J = model.jacobian(x, held)
        rhs = np.zeros((len(J), scope.drivers))
        first = len(model.pairs)
        for j in range(len(held)):
            rhs[first + j, j] = 1.0
        for j, (a, b) in enumerate(scope.links, start=len(held)):  # a link's length
            row = next(i for i, (p, q, _) in enumerate(model.pairs) if {p, q} == {a, b})
            rhs[row, j] = 1.0
        dx = np.linalg.lstsq(J, rhs, rcond=None)[0]
        rates = {name: np.zeros((scope.drivers, 3)) for name in points}
        h = 1e-4
        for j in range(scope.drivers):
            at = {s: model.points(x + s * h * dx[:, j]) for s in (-2, -1, 1, 2)}
            for name in points:
                d1, d2 = at[1][name] - at[-1][name], at[2][name] - at[-2][name]
                rates[name][j] = (8.0 * d1 - d2) / (12.0 * h)
        out.append(scope.duals(points, rates))
    return out


def _target_rows(engine, p, targets) -> tuple[list, list]:
    """Each target's residual at the positions ``p`` and its row (the chain rule through
    the engine's sites' Jacobians): one rule for the MuJoCo and the Drake engines."""
    errors, rows = [], []
    for t in map(as_target, targets):
        errors.append(t.error(p))
        rows.append(
            sum(g @ engine.sites[name].jacobian(engine) for name, g in t.gradient(p).items())
        )
    return errors, rows


class MujocoCorner:
    """The exported MJCF (a corner's or an axle's) in MuJoCo, solved to targets by
    Newton on its own Jacobians.

    Build and use it inside :func:`quiet_mujoco`: MuJoCo otherwise prints its
    warnings and appends them to ``MUJOCO_LOG.TXT`` in the working directory.
    """

    def __init__(self, mjcf_text: str, subject, source: str = "the MJCF"):
        import mujoco

        scope = _scope(subject)
        self.mj = mujoco
        try:
            self.model = mujoco.MjModel.from_xml_string(mjcf_text)
        except ValueError as exc:
            detail = " ".join(str(exc).split())
            raise PinSuspError(f"{source}: MuJoCo cannot load it: {detail}") from None
        self.data = mujoco.MjData(self.model)
        self.sites = _with_contact_patches(
            {name: _Site(self, name, source) for name in scope.sites}, scope
        )

    def _rows(self, targets) -> tuple[list, list]:
        """Each target's residual and its row of d residual / dv (chain rule through
        the sites' Jacobians)."""
        p = {name: site.position(self) for name, site in self.sites.items()}
        return _target_rows(self, p, targets)

    def solve(self, targets, iterations: int = 30) -> dict | None:
        """Newton from the design state to the targets."""
        m, d, mj = self.model, self.data, self.mj
        d.qpos[:] = m.qpos0
        for _ in range(iterations + 1):
            mj.mj_forward(m, d)
            eq = d.efc_type[: d.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
            errors, rows = self._rows(targets)
            r = np.concatenate([d.efc_pos[: d.nefc][eq], errors])
            if not np.all(np.isfinite(r)):
                return None  # diverged, or a NaN in the MJCF: lstsq would fail on it
            if np.max(np.abs(r)) < 1e-13:
                return {name: s.position(self).copy() for name, s in self.sites.items()}
            jac = [d.efc_J.reshape(d.nefc, m.nv)[eq]] if d.nefc else []
            J = np.vstack(jac + rows)
            if not np.all(np.isfinite(J)):
                return None
            dv = np.linalg.lstsq(J, -r, rcond=None)[0]
            mj.mj_integratePos(m, d.qpos, dv, 1.0)
        return None

    def rates(self, held, k: int) -> dict[str, np.ndarray]:
        """At the solved pose: each point's rate along the first len(held) of k drivers,
        J·dv = e (equality rows and the held targets' rows, least squares), through
        the sites' Jacobians; NaN for a driver it cannot move (a toe link's length:
        its links are rigid bodies closed by connects)."""
        m, d, mj = self.model, self.data, self.mj
        mj.mj_forward(m, d)
        eq = d.efc_type[: d.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
        jac = [d.efc_J.reshape(d.nefc, m.nv)[eq]] if d.nefc else []
        J = np.vstack(jac + self._rows(held)[1])
        rhs = np.zeros((len(J), len(held)))
        rhs[len(J) - len(held) :] = np.eye(len(held))
        dv = np.linalg.lstsq(J, rhs, rcond=None)[0]
        out = {}
        for name, site in self.sites.items():
            out[name] = np.full((k, 3), np.nan)
            out[name][: len(held)] = (site.jacobian(self) @ dv).T
        return out


def _with_contact_patches(sites: dict, scope) -> dict:
    """An engine's points with each wheel's contact patch (from its wheel centre and
    spin axis, as pin_susp's), named ``<prefix>contact_patch_center``."""
    for prefix, (radius, body) in scope.wheels.items():
        sites[f"{prefix}contact_patch_center"] = ContactPatchPoint(
            f"{prefix}contact_patch_center",
            sites[f"{prefix}wheel_center"],
            sites[f"{prefix}axle_inboard"],
            sites[f"{prefix}axle_outboard"],
            radius,
            body,
        )
    return sites


class _Warnings:
    """A MuJoCo warning handler that only counts (and keeps the first)."""

    def __init__(self):
        self.count = 0
        self.first = ""

    def __call__(self, message: str) -> None:
        if not self.count:
            self.first = " ".join(str(message).split())
        self.count += 1


@contextmanager
def quiet_mujoco(mj):
    """MuJoCo's warnings counted instead of printed and logged to MUJOCO_LOG.TXT.

    Installs a counting ``mju_user_warning`` handler (MuJoCo then neither
    prints nor logs a warning) and, where MuJoCo has it (3.4+), switches the
    default log handler's console and file output off as well; both are
    restored on the way out. Yields the :class:`_Warnings` counter.
    """
    counter = _Warnings()
    set_warning = getattr(mj, "set_mju_user_warning", None)
    log_config = getattr(mj, "MjLogConfig", None)
    old_warning = mj.get_mju_user_warning() if set_warning else None
    old_config = log_config.get() if log_config else None
    try:
        if set_warning:
            set_warning(counter)
        if log_config:
            config = log_config.get()
            config.logto_console = False
            config.logto_file = False
            config.set()
        yield counter
    finally:
        if set_warning:
            set_warning(old_warning)
        if old_config is not None:
            old_config.set()


class _Site:
    """A MuJoCo site as a point: position and (3 × nv) Jacobian."""

    def __init__(self, engine: MujocoCorner, name: str, source: str = "the MJCF"):
        self.name = name
        self.id = engine.mj.mj_name2id(engine.model, engine.mj.mjtObj.mjOBJ_SITE, name)
        if self.id < 0:
            raise PinSuspError(f"{source}: is not the MJCF of this geometry: missing site {name}")

    def position(self, engine: MujocoCorner) -> np.ndarray:
        return engine.data.site_xpos[self.id]

    def jacobian(self, engine: MujocoCorner) -> np.ndarray:
        jacp = np.zeros((3, engine.model.nv))
        engine.mj.mj_jacSite(engine.model, engine.data, jacp, None, self.id)
        return jacp


def mujoco_points(subject, sweep, mjcf_text: str, source: str = "the MJCF") -> list:
    """MuJoCo's points at every step (None where it did not converge), quietly."""
    return _mujoco_points(_scope(subject), sweep, mjcf_text, source)[0]


def _mujoco_points(scope, sweep, mjcf_text: str, source: str):
    """(points, warnings counter); MuJoCo's errors as PinSuspError naming ``source``."""
    import mujoco

    with quiet_mujoco(mujoco) as counter:
        try:
            engine = MujocoCorner(mjcf_text, scope, source)
            points = []
            for targets in scope.step_targets(sweep):
                at = engine.solve(targets)
                if at is None:
                    points.append(None)
                    continue
                rates = engine.rates(scope.held(at), scope.drivers)
                points.append(scope.duals(at, rates))
        except (mujoco.FatalError, mujoco.UnexpectedError) as exc:
            detail = " ".join(str(exc).split())
            raise PinSuspError(f"{source}: MuJoCo failed on it: {detail}") from None
    return points, counter


# ---------------------------------------------------------------- Drake

# IPOPT's defaults stop near 1e-8 in its scaled error (SNOPT's near 1e-3 mm in
# the points): a validation at 1e-6 mm needs the constraints met to ~1e-14 m.
# Every example's steps converge within 8 iterations: 100 (not 3000) keeps a step
# that cannot converge (a target out of reach) from costing seconds.
IPOPT_OPTIONS = {"tol": 1e-14, "constr_viol_tol": 1e-14, "max_iter": 100, "print_level": 0}
# A pose is accepted when Drake's own plant has every closure and target this close
# (m, and rad for roll): what IPOPT's tight tolerance reaches, with margin.
DRAKE_RESIDUAL = 1e-12
# m: a frame this far from the origin is no suspension, and IPOPT's iterates on it
# overflow, where Drake aborts the whole process (a non-finite q): refused instead.
FAR = 1e6


class _DrakePoint:
    """A frame of Drake's plant as a point: position and (3 × nq) Jacobian in world."""

    def __init__(self, frame, offset=None):
        self.frame = frame
        self.offset = np.zeros(3) if offset is None else np.asarray(offset, dtype=float)

    def position(self, engine: DrakeCorner) -> np.ndarray:
        p = engine.plant.CalcPointsPositions(engine.context, self.frame, self.offset, engine.world)
        return p[:, 0]

    def jacobian(self, engine: DrakeCorner) -> np.ndarray:
        return engine.plant.CalcJacobianTranslationalVelocity(
            engine.context, engine.wrt, self.frame, self.offset, engine.world, engine.world
        )


@dataclass(frozen=True)
class _DrakeClosure:
    """A loop closure read back from the URDF, its anchors as points of Drake's plant;
    ``length``: a distance closure's, from Drake's design pose."""

    name: str
    kind: str
    a: _DrakePoint
    b: _DrakePoint
    links: frozenset
    length: float = 0.0


class _Positions(dict):
    """The points' world positions at the engine's pose, each computed when first asked."""

    def __init__(self, engine: DrakeCorner):
        super().__init__()
        self.engine = engine

    def __missing__(self, name: str) -> np.ndarray:
        self[name] = position = self.engine.sites[name].position(self.engine)
        return position


class DrakeCorner:
    """The exported URDF (a corner's or an axle's) in Drake, solved to targets by
    Drake's InverseKinematics.

    Drake's own URDF parser builds the ``MultibodyPlant`` (the root link welded
    to the world); the loop closures are read back from the same text
    (:func:`pin_susp.urdf.read_closures`): a ball closure is a position
    constraint (one anchor at the other, in its link's frame), a distance
    closure a point-to-point distance constraint at the length Drake's plant
    has at the design configuration (all joints 0). A target along a direction
    is a position constraint in a frame whose x axis is that direction; an
    axle's heave and roll are constraints evaluated on the plant's points and
    Jacobians. Build and use it inside :func:`quiet_drake`.
    """

    def __init__(self, urdf_text: str, subject, source: str = "the URDF"):
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant
        from pydrake.multibody.tree import FrameIndex, JacobianWrtVariable

        scope = _scope(subject)
        root = next(b.name for b in scope.tree.bodies if b.parent is None)
        self.plant = plant = MultibodyPlant(0.0)
        try:
            Parser(plant).AddModelsFromString(urdf_text, "urdf")
            plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(root))
            plant.Finalize()
        except (RuntimeError, ValueError) as exc:
            detail = " ".join(str(exc).replace("<literal-string>.urdf:", "line ").split())
            raise PinSuspError(f"{source}: Drake cannot load it: {detail}") from None
        self.world = plant.world_frame()
        self.wrt = JacobianWrtVariable.kQDot
        self.context = plant.CreateDefaultContext()
        self.q_design = np.zeros(plant.num_positions())
        plant.SetPositions(self.context, self.q_design)
        for i in range(plant.num_frames()):
            f = plant.get_frame(FrameIndex(i))
            where = f.CalcPoseInWorld(self.context).translation()
            if not np.all(np.abs(where) < FAR):
                raise PinSuspError(
                    f"{source}: frame {f.name()} is {np.max(np.abs(where)):g} m from the "
                    "origin at the design state: not a suspension"
                )

        def frame(name):
            if not plant.HasFrameNamed(name):
                raise PinSuspError(f"{source}: is not the URDF of this geometry: no link {name}")
            return plant.GetFrameByName(name)

        self.sites = _with_contact_patches(
            {name: _DrakePoint(frame(name)) for name in scope.sites}, scope
        )
        self.closures = []
        try:
            specs = read_closures(urdf_text)
        except ValueError as exc:
            raise PinSuspError(f"{source}: its loop closures cannot be read: {exc}") from None
        for spec in specs:
            (link_a, offset_a), (link_b, offset_b) = spec.anchors
            a = _DrakePoint(frame(link_a), offset_a)
            b = _DrakePoint(frame(link_b), offset_b)
            with np.errstate(over="ignore", invalid="ignore"):
                length = float(np.linalg.norm(a.position(self) - b.position(self)))
            if not np.isfinite(length):  # Drake aborts the process on a NaN bound
                raise PinSuspError(
                    f"{source}: loop closure {spec.name}: its anchors are not a finite "
                    "distance apart"
                )
            links = frozenset((link_a, link_b))
            self.closures.append(_DrakeClosure(spec.name, spec.kind, a, b, links, length))

    def _target_constraint(self, target):
        """A target as a function of q for Drake's MathematicalProgram: its error, and
        for IPOPT's AutoDiff its gradient by the chain rule through the plant's
        Jacobians."""
        from pydrake.autodiffutils import ExtractGradient, ExtractValue, InitializeAutoDiff

        def evaluate(q):
            values = q if q.dtype != object else ExtractValue(q)[:, 0]
            if not np.all(np.isfinite(values)):  # Drake aborts on a non-finite q
                errors, rows = [np.nan], np.full((1, len(values)), np.nan)
            else:
                self.plant.SetPositions(self.context, values)
                errors, rows = self._rows([target])
            if q.dtype != object:
                return np.array(errors)
            return InitializeAutoDiff(np.array(errors), np.array(rows) @ ExtractGradient(q))[:, 0]

        return evaluate

    def _rows(self, targets) -> tuple[list, list]:
        """Each target's residual and its row of d residual / dq (chain rule through
        the points' Jacobians), at the context's pose."""
        return _target_rows(self, _Positions(self), targets)

    def _closure_residuals(self) -> np.ndarray:
        out = []
        for c in self.closures:
            d = c.a.position(self) - c.b.position(self)
            out.append(np.linalg.norm(d) if c.kind == "ball" else np.linalg.norm(d) - c.length)
        return np.array(out)

    def program(self, targets):
        """Drake's InverseKinematics of one step: the closures and the targets as its
        constraints (no cost: the system is square), joint limits left out as
        pin_susp's solver has none."""
        from pydrake.math import RigidTransform, RotationMatrix
        from pydrake.multibody.inverse_kinematics import InverseKinematics

        ik = InverseKinematics(self.plant, with_joint_limits=False)
        for c in self.closures:
            if c.kind == "ball":
                # anchor a, seen from b's link, is at anchor b
                ik.AddPositionConstraint(c.a.frame, c.a.offset, c.b.frame, c.b.offset, c.b.offset)
            elif c.kind == "distance":
                ik.AddPointToPointDistanceConstraint(
                    c.a.frame, c.a.offset, c.b.frame, c.b.offset, c.length, c.length
                )
            else:
                raise PinSuspError(f"loop closure {c.name}: Drake has no {c.kind!r} closure")
        free = np.array([-np.inf, -np.inf])
        for t in map(as_target, targets):
            site = self.sites.get(getattr(t, "point", None))
            if isinstance(t, Along) and isinstance(site, _DrakePoint):
                # the point's coordinate along the direction: x of a frame A whose x it is
                along = RigidTransform(
                    RotationMatrix.MakeFromOneVector(t.direction, 0), np.zeros(3)
                )
                ik.AddPositionConstraint(
                    site.frame,
                    site.offset,
                    self.world,
                    along,
                    np.r_[t.value, free],
                    np.r_[t.value, -free],
                )
            else:
                ik.prog().AddConstraint(self._target_constraint(t), [0.0], [0.0], ik.q())
        return ik

    def solve(self, targets) -> dict | None:
        """IPOPT from the design configuration; None unless it succeeds and Drake's
        plant has every closure and target within DRAKE_RESIDUAL at its answer."""
        from pydrake.solvers import IpoptSolver, SolverOptions

        ik = self.program(targets)
        solver = IpoptSolver()
        options = SolverOptions()
        for key, value in IPOPT_OPTIONS.items():
            options.SetOption(solver.solver_id(), key, value)
        result = solver.Solve(ik.prog(), self.q_design, options)
        q = result.GetSolution(ik.q())
        if not (result.is_success() and np.all(np.isfinite(q))):
            return None
        self.plant.SetPositions(self.context, q)
        residual = np.r_[self._closure_residuals(), self._rows(targets)[0]]
        if not np.max(np.abs(residual), initial=0.0) < DRAKE_RESIDUAL:
            return None
        return {name: site.position(self).copy() for name, site in self.sites.items()}

    def rates(self, held, links, k: int) -> dict[str, np.ndarray]:
        """At the solved pose: each point's rate along the k drivers, J·dq = e: the
        closures' rows (a ball's three, a distance's one along the link) and the held
        targets' rows; a driver that is a link's length (``links``: its two points)
        is a 1 on its distance closure's row. NaN for a link no closure joins."""
        rows, link_row = [], {}
        for c in self.closures:
            Ja, Jb = c.a.jacobian(self), c.b.jacobian(self)
            if c.kind == "ball":
                rows += list(Ja - Jb)
            else:
                d = c.a.position(self) - c.b.position(self)
                link_row[c.links] = len(rows)
                rows.append(d @ (Ja - Jb) / np.linalg.norm(d))
        first = len(rows)
        rows += self._rows(held)[1]
        rhs = np.zeros((len(rows), k))
        rhs[first:, : len(held)] = np.eye(len(held))
        known = list(range(len(held)))
        for j, pair in enumerate(links, start=len(held)):
            if frozenset(pair) in link_row:
                rhs[link_row[frozenset(pair)], j] = 1.0
                known.append(j)
        dq = np.linalg.lstsq(np.array(rows), rhs, rcond=None)[0]
        out = {}
        for name, site in self.sites.items():
            out[name] = np.full((k, 3), np.nan)
            out[name][known] = (site.jacobian(self) @ dq[:, known]).T
        return out


class _DrakeLog(logging.Handler):
    """Drake's log records (pydrake sends them to the ``drake`` logger) to a counter."""

    def __init__(self, counter: _Warnings):
        super().__init__(logging.WARNING)
        self.counter = counter

    def emit(self, record) -> None:
        self.counter(record.getMessage())


@contextmanager
def quiet_drake():
    """Drake's warnings (its parser's, its solvers') counted instead of printed.

    pydrake routes Drake's log to Python's ``drake`` logger: a counting handler
    stands in for its handlers and propagation while the engine runs; both are
    restored on the way out. Yields the :class:`_Warnings` counter.
    """
    counter = _Warnings()
    logger = logging.getLogger("drake")
    handlers, propagate = logger.handlers[:], logger.propagate
    logger.handlers, logger.propagate = [_DrakeLog(counter)], False
    try:
        yield counter
    finally:
        logger.handlers, logger.propagate = handlers, propagate


def drake_points(subject, sweep, urdf_text: str | None = None, source: str = "the URDF") -> list:
    """Drake's points at every step (None where it did not converge), quietly;
    ``urdf_text`` defaults to the subject's own export."""
    scope = _scope(subject)
    text = scope.subject.urdf if urdf_text is None else urdf_text
    return _drake_points(scope, sweep, text, source)[0]


def _drake_points(scope, sweep, urdf_text: str, source: str):
    """(points, warnings counter); Drake's errors as PinSuspError naming ``source``."""
    with quiet_drake() as counter:
        engine = DrakeCorner(urdf_text, scope, source)
        points = []
        for targets in scope.step_targets(sweep):
            try:
                at = engine.solve(targets)
            except RuntimeError as exc:
                detail = " ".join(str(exc).split())
                raise PinSuspError(f"{source}: Drake failed on it: {detail}") from None
            if at is None:
                points.append(None)
                continue
            rates = engine.rates(scope.held(at), scope.links, scope.drivers)
            points.append(scope.duals(at, rates))
    return points, counter


def check_urdf(text: str, tree, source: str = "URDF") -> None:
    """Raise PinSuspError unless ``text`` is the URDF :func:`pin_susp.urdf.tree_to_urdf`
    writes for ``tree``: XML with a ``<robot>`` root holding the same links, the same
    joints (type, parent, child) and the same loop closures (type, the links of their
    frames). Positions and axes are not compared: the URDF of a corner whose hardpoints
    moved since the export passes, and the comparison of the solutions shows it."""
    problem = _urdf_problem(text, tree)
    if problem:
        raise PinSuspError(f"{source}: {problem}")


def _urdf_problem(text: str, tree) -> str | None:
    from .urdf import model_file_root, not_this_model

    root, problem = model_file_root(text, "URDF")
    if problem:
        return problem
    ours, theirs = _urdf_elements(ET.fromstring(tree_to_urdf(tree))), _urdf_elements(root)
    kinds = ("link", "joint", "loop closure")
    return not_this_model(
        "URDF",
        tree.name,
        {k: ours[k] for k in kinds},
        theirs,
        name=lambda n: n or "(unnamed)",
    )


def _urdf_elements(root) -> dict[str, dict[str, tuple[str, ...]]]:
    """Named elements by kind, each with what must match: a joint's type, parent and
    child; a loop closure's type and its frames' links."""
    ns = {"pin_susp": NAMESPACE}
    found = {
        "link": {el.get("name", ""): () for el in root.findall("link")},
        "joint": {},
        "loop closure": {},
    }
    for el in root.findall("joint"):
        ends = [
            (el.find(end).get("link", "") if el.find(end) is not None else "")
            for end in ("parent", "child")
        ]
        found["joint"].setdefault(
            el.get("name", ""), (el.get("type", "?"), "from", ends[0] or "?", "to", ends[1] or "?")
        )
    for el in root.findall("pin_susp:loop_closure", ns):
        links = [f.get("link", "?") for f in el.findall("pin_susp:frame", ns)]
        found["loop closure"].setdefault(
            el.get("name", ""), (el.get("type", "?"), "between", *links)
        )
    return found


ENGINES = ("pointwise", "mujoco", "drake")
INSTALL = {"mujoco": "MuJoCo", "drake": "Drake"}


def validate(
    subject,
    sweep,
    mjcf_text: str | None = None,
    tolerance: float = TOLERANCE,
    mjcf_source: str = "--mjcf",
    *,
    engines=("pointwise", "mujoco"),
    urdf_text: str | None = None,
    urdf_source: str = "--urdf",
):
    """Solve the sweep with pin_susp, then with each of ``engines`` (of :data:`ENGINES`)
    that is installed; compare.

    ``subject``: a Corner or an AxleModel. Returns (results, reports), the reports
    in the order of ENGINES. ``mjcf_text`` (MuJoCo's) and ``urdf_text`` (Drake's)
    default to the subject's own export; given, each must be that export
    (:func:`pin_susp.mjcf.check_mjcf`, :func:`check_urdf`, checked before any
    solving) and ``mjcf_source`` / ``urdf_source`` name it in errors (the file's
    path). A file that is not this corner's (axle's) model, or that its engine
    cannot load, raises PinSuspError; the engines' warnings are counted in the
    report's ``warnings``, never printed (nor, MuJoCo's, written to
    MUJOCO_LOG.TXT). An engine that is not installed, or cannot model the
    subject, gets a report with a ``note`` saying why.
    """
    from .mjcf import check_mjcf

    unknown = [e for e in engines if e not in ENGINES]
    if unknown:
        raise PinSuspError(f"unknown engine {unknown[0]!r}: expected one of {', '.join(ENGINES)}")
    scope = _scope(subject)
    if mjcf_text is not None:
        check_mjcf(mjcf_text, scope.tree, mjcf_source)
    if urdf_text is not None:
        check_urdf(urdf_text, scope.tree, urdf_source)
    results = scope.results(sweep)
    reports = []
    if "pointwise" in engines:
        try:
            points = pointwise_points(scope, sweep)
        except PinSuspError as exc:
            reports.append(EngineReport("pointwise", note=str(exc)))
        else:
            reports.append(compare(scope, results, points, "pointwise", tolerance))
    if "mujoco" in engines:
        reports.append(
            _engine_report("mujoco", scope, sweep, results, mjcf_text, mjcf_source, tolerance)
        )
    if "drake" in engines:
        reports.append(
            _engine_report("drake", scope, sweep, results, urdf_text, urdf_source, tolerance)
        )
    return results, reports


def _not_installed(engine: str, module: str) -> EngineReport | None:
    """A report saying how to install the engine when its module is missing."""
    try:
        __import__(module)
    except ImportError:
        return EngineReport(
            engine,
            note=f"{INSTALL[engine]} is not installed: "
            f"pip install 'pin_susp[validate]' (or pip install {engine})",
        )
    return None


def _engine_report(engine, scope, sweep, results, text, source, tolerance) -> EngineReport:
    """An engine's comparison (mujoco from the MJCF, drake from the URDF): the text
    given, else the subject's own export; a report saying how to install it if missing."""
    from .mjcf import tree_to_mjcf

    module, points_of, fmt = {
        "mujoco": ("mujoco", _mujoco_points, "MJCF"),
        "drake": ("pydrake.multibody.inverse_kinematics", _drake_points, "URDF"),
    }[engine]
    missing = _not_installed(engine, module)
    if missing:
        return missing
    if text is None:
        text = tree_to_mjcf(scope.tree) if engine == "mujoco" else scope.subject.urdf
        source = f"the {scope.kind}'s exported {fmt}"
    points, warnings = points_of(scope, sweep, text, source)
    report = compare(scope, results, points, engine, tolerance)
    report.warnings, report.first_warning = warnings.count, warnings.first
    return report
