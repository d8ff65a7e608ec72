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

A corner or an axle (docs/axle.md) alike: the engines' view of a subject — its
points, drivers, targets and columns — is one :class:`Scope` over the Assembly's
labelled corners; the engines only see points and targets.

The package: ``scopes`` (the subject's view for the engines), ``engines``
(their shared pieces and the point-based engine), ``mujoco_engine``, ``drake_engine``
(its URDF check too), ``report`` (the comparison); :func:`validate` runs them.
"""

# ruff: noqa: F401 (the package's names, importable from pin_susp.validate as before)
from __future__ import annotations

from ..errors import PinSuspError
from .drake_engine import (
    DRAKE_RESIDUAL,
    FAR,
    IPOPT_OPTIONS,
    DrakeCorner,
    check_urdf,
    drake_points,
    drake_run,
    quiet_drake,
)
from .engines import STEP, pointwise_points, pointwise_run
from .mujoco_engine import MujocoCorner, mujoco_points, mujoco_run, quiet_mujoco
from .report import RELATIVE, TOLERANCE, Branches, EngineReport, compare
from .scopes import (
    RATE_METRICS,
    AxleScope,
    CornerScope,
    Scope,
    held_drivers,
    scope_of,
    step_targets,
)

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

    ``subject``: an Assembly (a Corner, an AxleModel). Returns (results, reports), the reports
    in the order of ENGINES. ``mjcf_text`` (MuJoCo's) and ``urdf_text`` (Drake's)
    default to the subject's own export; given, each must be that export
    (:func:`pin_susp.model.mjcf.check_mjcf`, :func:`check_urdf`, checked before any
    solving) and ``mjcf_source`` / ``urdf_source`` name it in errors (the file's
    path). A file that is not this corner's (axle's) model, or that its engine
    cannot load, raises PinSuspError; the engines' warnings are counted in the
    report's ``warnings``, never printed (nor, MuJoCo's, written to
    MUJOCO_LOG.TXT). An engine that is not installed, or cannot model the
    subject, gets a report with a ``note`` saying why.
    """
    from ..model.mjcf import check_mjcf

    unknown = [e for e in engines if e not in ENGINES]
    if unknown:
        raise PinSuspError(f"unknown engine {unknown[0]!r}: expected one of {', '.join(ENGINES)}")
    scope = scope_of(subject)
    if mjcf_text is not None:
        check_mjcf(mjcf_text, scope.tree, mjcf_source)
    if urdf_text is not None:
        check_urdf(urdf_text, scope.tree, urdf_source)
    results = scope.results(sweep)
    reports = []
    if "pointwise" in engines:
        try:
            points = pointwise_run(scope, sweep)
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
    from ..model.mjcf import tree_to_mjcf

    module, points_of, fmt = {
        "mujoco": ("mujoco", mujoco_run, "MJCF"),
        "drake": ("pydrake.multibody.inverse_kinematics", drake_run, "URDF"),
    }[engine]
    missing = _not_installed(engine, module)
    if missing:
        return missing
    if text is None:
        text = tree_to_mjcf(scope.tree) if engine == "mujoco" else scope.subject.export_urdf
        source = f"the {scope.kind}'s exported {fmt}"
    points, warnings = points_of(scope, sweep, text, source)
    report = compare(scope, results, points, engine, tolerance)
    report.warnings, report.first_warning = warnings.count, warnings.first
    return report
