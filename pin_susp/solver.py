"""Newton's method on the joint manifold for closures plus targets.

(With more rows than unknowns, as in the camber-shim assembly, the step is
Gauss-Newton: the least-squares solution of J·dv = −r.)

The residual stacks every closure and target (metres). Each iteration
solves J·dv = −r and moves q ← integrate(q, dv). Where J is singular or
the step is wild (a toggle position, lock-up) it takes a damped
least-squares step instead, with λ = μ·|r|² so that convergence stays
quadratic near the solution. A step that does not converge is retried as
two half steps (continuation) before it is reported as failed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .closures import Kinematics

TOLERANCE = 1e-13  # m: stop when max |residual| is below this (1e-10 mm)
ACCEPT = 1e-12  # m: the contract, max |residual| <= 1e-9 mm at every accepted step
MAX_ITERATIONS = 12
MAX_STEP = 0.25  # rad or m per iteration: larger Newton steps are damped
DAMPING = 1.0  # μ, 1/m²
SUBDIVISIONS = 6  # a failed step is halved up to this many times


@dataclass
class Solution:
    q: np.ndarray
    converged: bool
    iterations: int
    max_residual: float  # m


class NewtonSolver:
    """Solves r(q) = 0 for the stacked rows of ``closures`` and ``targets``."""

    def __init__(self, kin: Kinematics, closures: list, targets: list):
        self.kin = kin
        self.rows = list(closures) + list(targets)
        self.targets = list(targets)
        self.nrows = sum(row.size for row in self.rows)
        self.residual = np.empty(self.nrows)
        self.jacobian = np.empty((self.nrows, kin.model.nv))

    def evaluate(self, q: np.ndarray) -> None:
        """Fill self.residual and self.jacobian at q."""
        self.kin.update(q)
        i = 0
        for row in self.rows:
            self.residual[i : i + row.size] = row.residual(self.kin)
            self.jacobian[i : i + row.size] = row.jacobian(self.kin)
            i += row.size

    def newton(self, q: np.ndarray) -> Solution:
        """Iterate from q with the current target values."""
        model = self.kin.model
        q = q.copy()
        for iteration in range(MAX_ITERATIONS + 1):
            self.evaluate(q)
            error = float(np.max(np.abs(self.residual)))
            if error <= TOLERANCE:
                return Solution(q, True, iteration, error)
            if iteration == MAX_ITERATIONS or not np.isfinite(error):
                break
            q = pin.integrate(model, q, self._step())
        return Solution(q, error <= ACCEPT, iteration, error)

    def _step(self) -> np.ndarray:
        J, r = self.jacobian, self.residual
        try:
            if J.shape[0] == J.shape[1]:
                dv = np.linalg.solve(J, -r)
            else:  # consistent but redundant rows: Gauss-Newton
                dv = np.linalg.lstsq(J, -r, rcond=None)[0]
            if np.all(np.isfinite(dv)) and np.max(np.abs(dv)) <= MAX_STEP:
                return dv
        except np.linalg.LinAlgError:
            pass
        # Damped least squares: dv = −Jᵀ (J Jᵀ + λI)⁻¹ r, λ = μ|r|².
        lam = DAMPING * float(r @ r) + 1e-14
        dv = -J.T @ np.linalg.solve(J @ J.T + lam * np.eye(len(r)), r)
        scale = np.max(np.abs(dv)) / MAX_STEP
        return dv / scale if scale > 1.0 else dv

    def set_targets(self, values: np.ndarray) -> None:
        for target, value in zip(self.targets, values, strict=True):
            target.value = float(value)

    def solve(self, q: np.ndarray, start: np.ndarray, goal: np.ndarray) -> Solution:
        """Move the targets from ``start`` (solved at q) to ``goal``, halving on failure."""
        self.set_targets(goal)
        first = self.newton(q)
        if first.converged:
            return first
        return self._continuation(q, start, goal, SUBDIVISIONS, first.iterations, first)

    def _continuation(self, q, start, goal, depth, spent, fallback) -> Solution:
        if depth == 0:
            fallback.iterations = spent
            return fallback
        middle = 0.5 * (start + goal)
        self.set_targets(middle)
        half = self.newton(q)
        spent += half.iterations
        if not half.converged:
            half = self._continuation(q, start, middle, depth - 1, spent, fallback)
            spent = half.iterations
            if not half.converged:
                return half
        self.set_targets(goal)
        full = self.newton(half.q)
        spent += full.iterations
        if not full.converged:
            full = self._continuation(half.q, middle, goal, depth - 1, spent, full)
            spent = full.iterations
        full.iterations = spent
        return full
