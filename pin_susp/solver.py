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
LAPACK's gesv (numpy.linalg.solve). A sweep (``march``) also predicts each step
from the last two solutions and the tangent (see ``predict``), so that one
Newton iteration usually suffices. A long sweep can instead be solved for all its
steps at once (``march(..., bulk=True)``, see bulk.py): this march on a coarse
path, then batched Newton iterations on Pinocchio's model evaluated in numpy.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .constraints import WORLD, BranchGuard, Kinematics, StepFrames

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
        self._unit_rhs = np.zeros((self.nrows, len(self.targets)))
        self._unit_rhs[self.target_rows, np.arange(len(self.targets))] = 1.0
        self._bulk = None

    @property
    def bulk(self):
        """The rows for many configurations at once (bulk.Rows), built when first used."""
        if self._bulk is None:
            from .bulk import Rows

            self._bulk = Rows(self.kin.tree, self.rows, len(self.targets))
        return self._bulk

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
        rhs = self._unit_rhs if rhs is None else rhs
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


def march(
    solver: NewtonSolver,
    values: np.ndarray,
    q: np.ndarray,
    previous: np.ndarray,
    progress=None,
    step_times=None,
    tangents: list | None = None,
    keep=None,
    bulk: bool = False,
) -> list[Solution]:
    """Solve a sweep's steps (``values``: a row of target values each) in order, each
    from a prediction off the last solutions (halving toward it on failure).

    ``q``, ``previous``: a solved configuration and its target values to start from;
    ``progress(done, total)`` after each step; ``step_times``: a list that receives
    each step's solve time (s); ``tangents``: a list that receives each step's exact
    tangent (solver.keep_jacobian must be set), or ``keep(tangent)`` if given — called
    with the kinematics (Jacobians too) at the solution. ``bulk``: a long sweep may be
    solved for all its steps at once (bulk.solve_sweep: the same solutions, to the
    tolerance), and ``keep`` is then called once with every step's tangent stacked
    (n, nv, k): it must act on the last axes alone; the sweep is marched step by step
    when that does not apply or any step fails there.
    """
    if bulk and step_times is None:
        from .bulk import solve_sweep

        solved = solve_sweep(solver, values, q, previous, progress)
        if solved is not None:
            solutions, T = solved
            if tangents is not None:
                tangents.extend(T if keep is None else keep(T))
            return solutions
    predictor = Predictor(solver.kin.model)
    # which steps repeat the one before (a uniform sweep): worked out once for all
    steps = np.diff(np.vstack([previous, values]), axis=0)
    repeats = np.r_[False, np.abs(np.diff(steps, axis=0)).max(axis=1) <= 1e-15]
    n = values.shape[0]
    solutions = []
    clock = time.perf_counter
    with np.errstate(invalid="ignore", divide="ignore"):  # a singular J: NaN, handled
        for i in range(n):
            started = clock()
            solution = guessed = None
            # After a failed step the predictor's last solution is not the step before:
            # its step is no repeat (the parabola would assume one), and the guess is
            # checked like any other solution — on the design branch or refused.
            follows = i == 0 or solutions[-1].converged
            repeat = follows and bool(repeats[i]) and predictor.before is not None
            guess = predictor.guess(values[i], repeat)
            if guess is not None:  # one Newton iteration from a good guess, usually
                solver.set_targets(values[i])
                solution = guessed = solver.newton(guess)
            if solution is None or not solution.converged:
                solution = explained(solver.solve(q, previous, values[i]), guessed)
                if guessed is not None:
                    solution.iterations += guessed.iterations
            tangent = None
            if solution.converged:
                q, previous = solution.q, values[i]
                # exact when keep_jacobian; else J of the last iterate: good enough to predict
                tangent = solver.tangent()
                predictor.add(q, previous, tangent, exact=solver.keep_jacobian)
            if tangents is not None:
                tangents.append(tangent if keep is None or tangent is None else keep(tangent))
            if step_times is not None:
                step_times.append(clock() - started)
            solutions.append(solution)
            if progress is not None:
                progress(i + 1, n)
    return solutions


class Predictor:
    """The next step's starting configuration from the last solutions and the tangent.

    q(v) along the sweep is smooth in the target values v. From the last
    solution q₁ (at v₁, with tangent T = dq/dv there) the first-order guess
    is q₁ + T·Δv. When the step repeats the last one (a uniform sweep), the
    parabola through q₀ and q₁ with slope T·Δv at q₁ gives q₀ + 2·T·Δv,
    accurate to O(Δv³): one Newton iteration then meets the tolerance. When
    both tangents are exact (J at each solution), the cubic Hermite curve
    through q₀, q₁ with slopes T₀·Δv, T₁·Δv, extended one step, gives
    5·q₀ − 4·q₁ + (2·T₀ + 4·T₁)·Δv, accurate to O(Δv⁴).
    (q is a vector space here: every joint has one degree of freedom.)
    """

    def __init__(self, model: pin.Model):
        self.model = model
        self.last = None  # (q, values, tangent)
        self.before = None  # (q, values)

    def add(
        self, q: np.ndarray, values: np.ndarray, tangent: np.ndarray, exact: bool = False
    ) -> None:
        if not np.isfinite(tangent).all():  # a singular state: no prediction from here
            self.last = self.before = None
            return
        self.before = self.last
        self.last = (q, values, tangent, exact)

    def guess(self, values: np.ndarray, repeats: bool | None = None) -> np.ndarray | None:
        """``repeats``: whether this step repeats the last one (worked out here if None)."""
        if self.last is None:
            return None
        q, v, T, exact = self.last
        step = values - v
        if self.before is not None:
            if repeats is None:
                repeat = v - self.before[1] - step
                repeats = max(repeat.max(), -repeat.min()) <= 1e-15
            if repeats:
                q0, _, T0, exact0 = self.before
                if exact and exact0:
                    return 5.0 * q0 - 4.0 * q + (2.0 * T0 + 4.0 * T) @ step
                return pin.integrate(self.model, q0, 2.0 * (T @ step))
        return pin.integrate(self.model, q, T @ step)


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
            at.J6 = J6
            at.Jp = [j[:3] for j in J6]
        for row, k, i in self.rows:
            row.fill(at, k, r, J, i)
