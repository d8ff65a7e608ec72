"""What the engines share (README, How it works): the point-based engine's points and
rates, a target's rows through an engine's sites, the engines' contact patches, the
counter of their warnings.
"""

from __future__ import annotations

import numpy as np

from ..analyses.pointwise import as_target
from ..constraints import ContactPatchPoint
from .scopes import scope_of

STEP = 1e-3  # m: the drivers' step for the engines' rates (±STEP, ±2·STEP)


def pointwise_points(subject, sweep) -> list[dict | None]:
    """The point-based formulation's points at every step, with their rates along the
    drivers, as the subject's motion gives them (a corner's a Dual each, an axle's a
    Dual per side); None where it did not converge (:func:`pointwise_run`)."""
    scope = scope_of(subject)
    return scope.as_motion(pointwise_run(scope, sweep))


def pointwise_run(scope, sweep) -> list[dict | None]:
    """The point-based formulation's points at every step, a Dual per label (the
    scope's form); None where it did not converge.

    Where the root floats (a vehicle's body), the points are solved in the body's frame,
    the targets turned into it (Scope.fixed_root_targets), and placed on the road by the
    step's pose. The rates: the tangent of its own equations, J·dx = e for the driver's row
    (the held target's, or the toe link's distance), solved in the least-squares
    sense (its rigid-part distances are redundant, the system is consistent);
    the points then move along dx (Richardson differences of the explicit point
    formulas, error ~1e-12). Along a floating body's heave, pitch and roll, the same
    tangent with the change of its targets' residuals as the body moves (Richardson
    differences of its targets at the step's moved poses, Scope.step_moves).
    """
    model = scope.pointwise()
    out = []
    for targets, moves in zip(scope.step_targets(sweep), scope.step_moves(sweep), strict=True):
        targets, pose = scope.fixed_root_targets(targets)  # a floating body's: its frame
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
        along = {}
        J = model.jacobian(x, targets) if moves else None
        for quantity, (step, moved) in moves.items():  # a vehicle's body: its own tangent
            r = [model.residual(x, scope.fixed_root_targets(m)[0]) for m in moved]
            dx = np.linalg.lstsq(J, -richardson(r, step), rcond=None)[0]
            at = [model.points(x + s * h * dx) for s in (-2, -1, 1, 2)]
            along[quantity] = {
                label: float(richardson([a[hub][2] for a in at], h))
                for label, hub in scope.hubs.items()
            }
        road = None if pose is None else pose.to_road(points)
        out.append(scope.duals(points, rates, road, along))
    return out


def richardson(values: list, h: float) -> np.ndarray:
    """d/ds from the values at s − 2h, s − h, s + h, s + 2h: (8(f₁ − f₋₁) − (f₂ − f₋₂))/12h."""
    f_2, f_1, f1, f2 = (np.asarray(v, dtype=float) for v in values)
    return (8.0 * (f1 - f_1) - (f2 - f_2)) / (12.0 * h)


def target_rows(engine, p, targets) -> tuple[list, list]:
    """Each target's residual at the positions ``p`` and its row (the chain rule through
    the engine's sites' Jacobians): one rule for the MuJoCo and the Drake engines."""
    errors, rows = [], []
    for t in map(as_target, targets):
        errors.append(t.error(p))
        rows.append(
            sum(g @ engine.sites[name].jacobian(engine) for name, g in t.gradient(p).items())
        )
    return errors, rows


def with_contact_patches(sites: dict, scope) -> dict:
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


class Warnings:
    """A MuJoCo warning handler that only counts (and keeps the first)."""

    def __init__(self):
        self.count = 0
        self.first = ""

    def __call__(self, message: str) -> None:
        if not self.count:
            self.first = " ".join(str(message).split())
        self.count += 1
