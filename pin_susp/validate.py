"""Cross-validation: every step re-solved by engines that share no kinematics with ours.

- ``mujoco``: the exported MJCF in MuJoCo — its own forward kinematics,
  equality-constraint Jacobians (``efc_J``/``efc_pos``), site Jacobians and
  ``mj_integratePos``, driven by Newton to the same targets;
- ``pointwise``: hardpoints as unknowns, rigid distances, scipy least_squares.

Each engine starts every step from the design state (no warm start), so a
step is checked on its own. The rates along the drivers (hub z, rack, a toe
link's length) come from each engine's own Jacobian at its pose: with them
the derivative columns, the steer screw axis and the instant centres of a
bump twist are checked too.
The metrics are then computed from each engine's points and compared with
pin_susp's, metric by metric and point by point.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np

from .closures import ContactPatchPoint
from .errors import PinSuspError
from .jet import Dual
from .jet import value as plain
from .metrics import METRICS, metric_columns
from .pointwise import PointwiseCorner

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
    not_compared: set[str] = field(default_factory=set)  # the engine could not compute them
    note: str = ""
    warnings: int = 0  # how many warnings the engine raised (MuJoCo's: silenced, counted)
    first_warning: str = ""

    @property
    def worst(self) -> float:
        return max(self.differences.values(), default=0.0)

    @property
    def agrees(self) -> bool:
        return not self.note and not self.failed_steps and not self.disagree


def compare(
    corner, results, points_per_step: list[dict | None], engine: str, tolerance: float = TOLERANCE
) -> EngineReport:
    """Metric columns of an engine's points against pin_susp's results."""
    report = EngineReport(engine, tolerance)
    design = {k: v[None] for k, v in corner.design_positions.items()}
    for i, points in enumerate(points_per_step):
        if points is None:
            report.failed_steps.append(i)
            continue
        if not results["solver_converged"][i]:
            continue
        columns = metric_columns(corner.geometry, points, design, corner.spring_sense)
        for name, (values, unit) in columns.items():
            if (
                np.isnan(values[0])
                and name in RATE_METRICS
                and np.isnan(plain(points["wheel_center"].der)).any()
            ):
                report.not_compared.add(name)  # the engine cannot move one of the drivers
                continue
            _record(report, name, unit, values[0], results[name][i])
        for name in corner.point_names:
            for a, axis in enumerate("xyz"):
                position = points[name].val[0, a] * 1e3
                _record(report, "points", "mm", position, results[f"{name}_{axis}"][i])
    return report


def _record(report, name, unit, theirs, ours) -> None:
    if np.isnan(ours) and np.isnan(theirs):
        return
    diff = abs(ours - theirs) if not (np.isnan(ours) or np.isnan(theirs)) else np.inf
    report.differences[name] = max(report.differences.get(name, 0.0), float(diff))
    report.units[name] = unit
    if not diff <= report.tolerance + RELATIVE * abs(ours):
        report.disagree.add(name)


def step_targets(corner, sweep) -> list[list[tuple[str, np.ndarray, float]]]:
    """(point, unit direction, absolute value m) for every target of every step."""
    values = corner.target_values(sweep.targets)
    return [
        [(t.point, t.unit_direction, float(values[i, k])) for k, t in enumerate(sweep.targets)]
        for i in range(len(values))
    ]


def held_drivers(corner, points: dict) -> list[tuple[str, np.ndarray, float]]:
    """The drivers as targets held where the engine's pose is: wheel-centre z, and the
    rack (trackrod_inboard y) on a rack corner."""
    held = [("wheel_center", np.array([0.0, 0.0, 1.0]), float(points["wheel_center"][2]))]
    g = corner.geometry
    if g.steering == "rack":
        inner = g.steering_points[0]
        held.append((inner, np.array([0.0, 1.0, 0.0]), float(points[inner][1])))
    return held


def with_rates(corner, points: dict | None, rates) -> dict[str, Dual] | None:
    """An engine's points at one step as Duals: position (1, 3), rates (k, 1, 3) along
    the corner's drivers, ``rates``: name → (k, 3), from the engine's own Jacobian."""
    if points is None:
        return None
    return {name: Dual(p[None], rates[name][:, None]) for name, p in points.items()}


def pointwise_points(corner, sweep) -> list[dict | None]:
    """The point-based formulation's points at every step, with their rates along the
    drivers; None where it did not converge.

    The rates: the tangent of its own equations, J·dx = e for the driver's row
    (the held target's, or the toe link's distance), solved in the least-squares
    sense (its rigid-part distances are redundant, the system is consistent);
    the points then move along dx (Richardson differences of the explicit point
    formulas, error ~1e-12).
    """
    model = PointwiseCorner(corner.geometry)
    g = corner.geometry
    out = []
    for targets in step_targets(corner, sweep):
        x, residual = model.solve(targets)
        if not residual < 1e-12:
            out.append(None)
            continue
        points = model.points(x)
        held = held_drivers(corner, points)
        J = model.jacobian(x, held)
        rhs = np.zeros((len(J), len(corner.drivers)))
        first = len(model.pairs)
        for j in range(len(held)):
            rhs[first + j, j] = 1.0
        if len(held) < len(corner.drivers):  # the toe link's length
            a, b = g.steering_points
            row = next(i for i, (p, q, _) in enumerate(model.pairs) if {p, q} == {a, b})
            rhs[row, len(held)] = 1.0
        dx = np.linalg.lstsq(J, rhs, rcond=None)[0]
        rates = {name: np.zeros((len(corner.drivers), 3)) for name in points}
        h = 1e-4
        for j in range(len(corner.drivers)):
            at = {s: model.points(x + s * h * dx[:, j]) for s in (-2, -1, 1, 2)}
            for name in points:
                d1, d2 = at[1][name] - at[-1][name], at[2][name] - at[-2][name]
                rates[name][j] = (8.0 * d1 - d2) / (12.0 * h)
        out.append(with_rates(corner, points, rates))
    return out


class MujocoCorner:
    """The exported MJCF in MuJoCo, solved to targets by Newton on its own Jacobians.

    Build and use it inside :func:`quiet_mujoco`: MuJoCo otherwise prints its
    warnings and appends them to ``MUJOCO_LOG.TXT`` in the working directory.
    """

    def __init__(self, mjcf_text: str, corner, source: str = "the MJCF"):
        import mujoco

        self.mj = mujoco
        try:
            self.model = mujoco.MjModel.from_xml_string(mjcf_text)
        except ValueError as exc:
            detail = " ".join(str(exc).split())
            raise PinSuspError(f"{source}: MuJoCo cannot load it: {detail}") from None
        self.data = mujoco.MjData(self.model)
        self.sites = {
            name: _Site(self, name, source)
            for name in corner.point_names
            if name != "contact_patch_center"
        }
        self.sites["contact_patch_center"] = ContactPatchPoint(
            "contact_patch_center",
            self.sites["wheel_center"],
            self.sites["axle_inboard"],
            self.sites["axle_outboard"],
            corner.geometry.wheel.radius,
            corner.mechanism.WHEEL_BODY,
        )

    def solve(self, targets, iterations: int = 30) -> dict | None:
        """Newton from the design state to the targets."""
        m, d, mj = self.model, self.data, self.mj
        d.qpos[:] = m.qpos0
        for _ in range(iterations + 1):
            mj.mj_forward(m, d)
            eq = d.efc_type[: d.nefc] == mj.mjtConstraint.mjCNSTR_EQUALITY
            rows = [d.efc_pos[: d.nefc][eq]]
            jac = [d.efc_J.reshape(d.nefc, m.nv)[eq]] if d.nefc else []
            for name, direction, value in targets:
                site = self.sites[name]
                rows.append([site.position(self) @ direction - value])
                jac.append(direction @ site.jacobian(self))
            r = np.concatenate(rows)
            if not np.all(np.isfinite(r)):
                return None  # diverged, or a NaN in the MJCF: lstsq would fail on it
            if np.max(np.abs(r)) < 1e-13:
                return {name: s.position(self).copy() for name, s in self.sites.items()}
            J = np.vstack(jac)
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
        jac += [direction @ self.sites[name].jacobian(self) for name, direction, _ in held]
        J = np.vstack(jac)
        rhs = np.zeros((len(J), len(held)))
        rhs[len(J) - len(held) :] = np.eye(len(held))
        dv = np.linalg.lstsq(J, rhs, rcond=None)[0]
        out = {}
        for name, site in self.sites.items():
            out[name] = np.full((k, 3), np.nan)
            out[name][: len(held)] = (site.jacobian(self) @ dv).T
        return out


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
            raise PinSuspError(f"{source}: is not the MJCF of this corner: missing site {name}")

    def position(self, engine: MujocoCorner) -> np.ndarray:
        return engine.data.site_xpos[self.id]

    def jacobian(self, engine: MujocoCorner) -> np.ndarray:
        jacp = np.zeros((3, engine.model.nv))
        engine.mj.mj_jacSite(engine.model, engine.data, jacp, None, self.id)
        return jacp


def mujoco_points(corner, sweep, mjcf_text: str, source: str = "the MJCF") -> list[dict | None]:
    """MuJoCo's points at every step (None where it did not converge), quietly."""
    return _mujoco_points(corner, sweep, mjcf_text, source)[0]


def _mujoco_points(corner, sweep, mjcf_text: str, source: str):
    """(points, warnings counter); MuJoCo's errors as PinSuspError naming ``source``."""
    import mujoco

    with quiet_mujoco(mujoco) as counter:
        try:
            engine = MujocoCorner(mjcf_text, corner, source)
            points = []
            for targets in step_targets(corner, sweep):
                at = engine.solve(targets)
                rates = None
                if at is not None:
                    rates = engine.rates(held_drivers(corner, at), len(corner.drivers))
                points.append(with_rates(corner, at, rates))
        except (mujoco.FatalError, mujoco.UnexpectedError) as exc:
            detail = " ".join(str(exc).split())
            raise PinSuspError(f"{source}: MuJoCo failed on it: {detail}") from None
    return points, counter


def validate(
    corner,
    sweep,
    mjcf_text: str | None = None,
    tolerance: float = TOLERANCE,
    mjcf_source: str = "--mjcf",
):
    """Solve the sweep with pin_susp, then with each available engine; compare.

    Returns (results, reports). ``mjcf_text`` defaults to the corner's own
    export; given, it must be that export (:func:`pin_susp.mjcf.check_mjcf`,
    checked before any solving) and ``mjcf_source`` names it in errors (the
    file's path). A file that is not this corner's MJCF, or that MuJoCo cannot
    load, raises PinSuspError; MuJoCo's warnings are counted in the report's
    ``warnings``, never printed nor written to MUJOCO_LOG.TXT.
    """
    from .mjcf import check_mjcf, tree_to_mjcf

    if mjcf_text is not None:
        check_mjcf(mjcf_text, corner.tree, mjcf_source)
    results = corner.run_sweep(sweep)
    points = pointwise_points(corner, sweep)
    reports = [compare(corner, results, points, "pointwise", tolerance)]
    try:
        import mujoco  # noqa: F401
    except ImportError:
        reports.append(
            EngineReport(
                "mujoco",
                note="MuJoCo is not installed: "
                "pip install 'pin_susp[validate]' (or pip install mujoco)",
            )
        )
        return results, reports
    if mjcf_text is None:
        text, source = tree_to_mjcf(corner.tree), "the corner's exported MJCF"
    else:
        text, source = mjcf_text, mjcf_source
    points, warnings = _mujoco_points(corner, sweep, text, source)
    report = compare(corner, results, points, "mujoco", tolerance)
    report.warnings, report.first_warning = warnings.count, warnings.first
    reports.append(report)
    return results, reports
