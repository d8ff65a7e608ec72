"""Newton's method on the joint manifold for closures plus targets.

(With more rows than unknowns, as in the camber-shim assembly, the step is
Gauss-Newton: the least-squares solution of J·dv = −r.)

The residual stacks every closure and target (metres). Each iteration
solves J·dv = −r and moves q ← integrate(q, dv). Where J is singular or
the step is wild (a toggle position, lock-up) it takes a damped
least-squares step instead, with λ = μ·|r|² so that convergence stays
quadratic near the solution. A step that does not converge is retried as
two half steps (continuation) before it is reported as failed.

Speed: every row (constraints/, one kind per module) is evaluated by its fast
form (``Row.fill``) from the frames it names — one Pinocchio call per frame the
rows need, read once for all of them — and the small square system goes to
LAPACK's gesv (numpy.linalg.solve). A sweep's steps are marched in
march.py (each predicted from the last solutions, so that one Newton iteration
usually suffices), or solved all at once on a long sweep (bulk.py's batched rows).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..constraints import WORLD, BranchGuard, Kinematics, StepFrames

try:  # numpy's LAPACK gesv kernels: one right-hand side, several (see _solve)
    from numpy.linalg import _umath_linalg

    _gesv = {1: _umath_linalg.solve1, 2: _umath_linalg.solve}
except (ImportError, AttributeError):
    _gesv = None

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
    # The loop whose design assembly branch the pose left (its residual may be tiny).
    branch: str | None = None
    # dq per unit of each driver (an axle's wheel-centre z per side, the rack) at q,
    # exact, when the sweep's solve had it: the columns' rates need no new solve
    drive_tangent: np.ndarray | None = None

    @property
    def why(self) -> str:
        """Why a step did not converge, in a user's words ('' when it did)."""
        if self.converged:
            return ""
        if self.branch is not None:
            return f"left the design assembly branch of {self.branch}"
        return f"residual {self.max_residual * 1e3:.3g} mm"


class NewtonSolver:
    """Solves r(q) = 0 for the stacked rows of ``closures`` and ``targets``.

    ``branches`` (constraints.LoopBranch): a converged pose off the design
    assembly of any of these loops is refused — not converged, ``branch``
    naming the loop — so that continuation halves the step and retries.
    """

    def __init__(self, kin: Kinematics, closures: list, targets: list, branches=()):
        self.kin = kin
        self.branches = BranchGuard(list(branches), kin)
        self.rows = list(closures) + list(targets)
        self.targets = list(targets)
        self.nrows = sum(row.size for row in self.rows)
        self.residual = np.empty(self.nrows)
        self.jacobian = np.empty((self.nrows, kin.model.nv))
        self.batch = _Batch(kin.model, self.rows)
        self.target_rows = np.arange(self.nrows - len(self.targets), self.nrows)
        # True: Newton ends on a full evaluation, so self.jacobian belongs to the solution
        # (its tangent is exact); False: it checks the last iterate's residual alone.
        self.keep_jacobian = False
        self.unit_rhs = np.zeros((self.nrows, len(self.targets)))
        self.unit_rhs[self.target_rows, np.arange(len(self.targets))] = 1.0

    def evaluate(self, q: np.ndarray, jacobian: bool = True) -> None:
        """Fill self.residual, and self.jacobian unless ``jacobian`` is False, at q."""
        if jacobian:
            self.kin.update(q)
        else:
            self.kin.update_positions(q)
        self.batch.fill(self.kin, q, self.residual, self.jacobian if jacobian else None)

    def tangent(self, rhs: np.ndarray | None = None) -> np.ndarray:
        """dq per unit of each target value, at the last evaluated state: J·T = [0; I]
        (or J·T = ``rhs``: a column per change of the rows' values, e.g. a link's length)."""
        rhs = self.unit_rhs if rhs is None else rhs
        if self.jacobian.shape[0] != self.jacobian.shape[1]:  # more rows than freedoms
            # a column whose system is consistent has its exact tangent (e.g. the rack of
            # an axle with a rigid bar); the others (a wheel moved alone) have none: NaN
            T = np.linalg.lstsq(self.jacobian, rhs, rcond=None)[0]
            miss = np.abs(self.jacobian @ T - rhs).max(axis=0)
            T[:, miss > 1e-9 * (1.0 + np.abs(T).max(axis=0))] = np.nan
            return T
        T = _solve(self.jacobian, rhs)
        return T if T is not None else np.full((self.jacobian.shape[1], rhs.shape[1]), np.nan)

    def newton(self, q: np.ndarray) -> Solution:
        """Iterate from q with the current target values."""
        model, r = self.kin.model, self.residual
        q = q.copy()
        full = True  # after a step, look at the residual alone first: often it has converged
        for iteration in range(MAX_ITERATIONS + 1):
            self.evaluate(q, jacobian=full)
            if r @ r <= TOLERANCE * TOLERANCE:  # |r|₂ bounds max |r|: one cheap call
                return self._accept(q, iteration, float(np.abs(r).max()))
            error = max(r.max(), -r.min())
            if iteration == MAX_ITERATIONS or not np.isfinite(error):
                break
            if not full:
                self.evaluate(q)
            q = pin.integrate(model, q, self._step())
            full = self.keep_jacobian
        if error <= ACCEPT:
            return self._accept(q, iteration, float(error))
        return Solution(q, False, iteration, float(error))

    def _accept(self, q: np.ndarray, iteration: int, error: float) -> Solution:
        """A pose that meets the residual: converged if on every loop's design branch
        (the frames in self.kin are those of q: the last evaluation was at q)."""
        flipped = self.branches.left(self.kin)
        if flipped is not None:
            return Solution(q, False, iteration, error, branch=flipped)
        return Solution(q, True, iteration, error)

    def _step(self) -> np.ndarray:
        J, r = self.jacobian, self.residual
        if J.shape[0] == J.shape[1]:
            dv = _solve(J, -r)
        else:  # consistent but redundant rows: Gauss-Newton
            dv = np.linalg.lstsq(J, -r, rcond=None)[0]
        if dv is not None and max(dv.max(), -dv.min()) <= MAX_STEP:  # False for NaN too
            return dv
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
        return explained(
            self._continuation(q, start, goal, SUBDIVISIONS, first.iterations, first), first
        )

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


def explained(failed: Solution, attempt: Solution | None) -> Solution:
    """A step that did not converge, explained: when an ``attempt`` at the same targets
    met the residual on another assembly branch, that is the reason (the continuation's
    own failure, a residual part-way, says less); its iterations are the step's total."""
    if failed.converged or failed.branch is not None or attempt is None or attempt.branch is None:
        return failed
    return Solution(attempt.q, False, failed.iterations, attempt.max_residual, attempt.branch)


def _solve(J: np.ndarray, b: np.ndarray) -> np.ndarray | None:
    """J·x = b for a square J (LAPACK's gesv through numpy); None if J is singular.

    A small system is solved several times a step, so the call goes to numpy's gesv
    kernel itself (numpy.linalg.solve's checks and np.errstate cost more than the
    solve: measured 80 against 94 µs a step); a singular J gives NaN there (a sweep's
    march silences numpy's "invalid value" for it; a lone call may show it). Without
    that kernel (another numpy), numpy.linalg.solve.
    """
    if _gesv is None:
        try:
            return np.linalg.solve(J, b)
        except np.linalg.LinAlgError:
            return None
    x = _gesv[b.ndim](J, b)
    return x if math.isfinite(x.sum()) else None


class _Batch:
    """The rows' fast forms (Row.fill), each frame they read fetched once per evaluation.

    With a handful of rows, plain per-row numpy beats stacking and fancy
    indexing (tried: slower): the cost is numpy's and the bindings' per-call
    overhead, so every row does as few calls as it can (an axis-aligned
    target reads one coordinate). The batch knows no row kind: each row names its
    frames (``frames``) and whether it reads their rotations (``angular``).
    """

    def __init__(self, model: pin.Model, rows: list):
        self.model = model
        self.frames: list[int] = []
        index = {}
        self.rows = []  # (row, its frames' indices in self.frames, its first row)
        i = 0
        for row in rows:
            k = []
            for point in row.frames:
                if point.frame_id not in index:
                    index[point.frame_id] = len(self.frames)
                    self.frames.append(point.frame_id)
                k.append(index[point.frame_id])
            self.rows.append((row, tuple(k), i))
            i += row.size
        self.angular = any(row.angular for row in rows)
        self.fixed = [model.frames[f].parentJoint == 0 for f in self.frames]
        self.zero6 = np.zeros((6, model.nv))
        self.one_freedom = model.nv == 1
        self.at = StepFrames(self.fixed)

    def fill(self, kin: Kinematics, q: np.ndarray, r: np.ndarray, J: np.ndarray | None) -> None:
        """Residual rows, and their Jacobian rows unless J is None."""
        model, data, at = self.model, kin.data, self.at
        oMf = data.oMf
        at.q, at.kin = q, kin
        at.P = [oMf[f].translation for f in self.frames]  # fresh arrays: no copy needed
        if self.angular:
            at.M = [oMf[f] for f in self.frames]
        if J is not None:  # a frame on the chassis does not move: its Jacobian is zero
            J6 = [
                self.zero6 if fixed else pin.getFrameJacobian(model, data, f, WORLD)
                for f, fixed in zip(self.frames, self.fixed, strict=True)
            ]
            if self.one_freedom:  # Pinocchio gives a 6-vector when nv = 1: one column
                J6 = [j.reshape(6, 1) for j in J6]
            at.J6 = J6
            at.Jp = [j[:3] for j in J6]
        for row, k, i in self.rows:
            row.fill(at, k, r, J, i)
