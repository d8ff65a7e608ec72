"""A sweep's steps solved in order: marched one after another, or all at once.

``march`` solves each step from a prediction off the last solutions (Predictor:
one Newton iteration usually suffices), halving toward a step that fails
(NewtonSolver.solve's continuation) and explaining a step that stays unsolved.
A long sweep may instead be solved for all its steps at once (``solve_sweep``):
this march on a coarse path, every step predicted between its coarse neighbours,
then batched Newton iterations on the model evaluated in numpy (bulk.py). This
module chooses between the two; solver.py (one configuration) and bulk.py (many
at once) do not import each other's way back.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin

from .bulk import COARSE_GROUP, COARSE_STEPS, MIN_STEPS, newton_all, on_branches, rows_of, solve_all
from .solver import TOLERANCE, NewtonSolver, Solution, explained


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
    extra=None,
    guess=None,
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
    when that does not apply or any step fails there; ``extra``: more right-hand sides
    solved with each tangent there (newton_all's), its columns after the targets'.
    ``guess`` (n, nq): a configuration near each step's (a study's design variant's
    solutions): with ``bulk``, every step is first solved at once from it (solve_guessed);
    or (solutions, tangents (n, nv, k)): the steps already solved (stacked.py).
    """
    if isinstance(guess, tuple):  # the steps solved already (stacked.py), as solve_sweep's
        solutions, T = guess
        if tangents is not None:
            tangents.extend(T if keep is None else keep(T))
        return solutions
    if bulk and step_times is None:
        solved = None if guess is None else solve_guessed(solver, values, guess, extra)
        if solved is None:
            solved = solve_sweep(solver, values, q, previous, progress, extra)
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


def solve_sweep(
    solver, values: np.ndarray, q: np.ndarray, previous: np.ndarray, progress=None, extra=None
):
    """Every step of a sweep, or None when it must be marched step by step.

    Returns (solutions, tangents (n, nv, ntargets)) with every step converged and on
    its design branches; None when the solver's rows or the model are not of the
    kinds handled here, the sweep is short, or any step fails here. ``extra``: more
    right-hand sides (nrows, e), their solutions after the tangents' (newton_all).
    """
    n = values.shape[0]
    if n < MIN_STEPS:
        return None
    rows = rows_of(solver)
    if not rows.supported:
        return None
    if len(solver.targets) != values.shape[1] or rows.nrows != solver.kin.model.nv:
        return None
    stride = max(2, n // COARSE_STEPS)
    coarse = np.unique(np.r_[np.arange(stride - 1, n, stride), n - 1])
    start_tangent = tangent_at(solver, q, previous)
    if start_tangent is None:
        return None
    solved = coarse_path(solver, rows, values[coarse], q, previous, start_tangent)
    if solved is None:
        return None
    # the predictions: cubic Hermite between coarse neighbours (the design state, or the
    # given start, before the first)
    q0 = np.vstack([q[None], solved[0]])
    v0 = np.vstack([previous[None], values[coarse]])
    T0 = np.concatenate([start_tangent[None], solved[1]])  # (m + 1, nv, k)
    segment = np.searchsorted(coarse, np.arange(n))  # step i lies in (coarse[s-1], coarse[s]]
    guess = hermite(q0, v0, T0, segment, values)
    qs, T, iterations, error = newton_all(rows, guess, values, TOLERANCE, extra)
    if qs is None:
        return None
    if not on_branches(solver, qs):
        return None
    solutions = list(map(Solution, qs, [True] * n, iterations.tolist(), error.tolist()))
    if progress is not None:
        progress(n, n)
    return solutions, T


def solve_guessed(solver: NewtonSolver, values: np.ndarray, guess: np.ndarray, extra=None):
    """Every step solved at once from a guess of its configuration (a study's variant
    from its design variant's solutions): (solutions, tangents (n, nv, k)) as
    solve_sweep's, or None where that does not apply, or any step does not converge to
    the tolerance or leaves a loop's design branch (then the sweep is marched)."""
    n = values.shape[0]
    rows = rows_of(solver)
    if not rows.supported or guess.shape != (n, solver.kin.model.nq):
        return None
    if len(solver.targets) != values.shape[1] or rows.nrows != solver.kin.model.nv:
        return None
    qs, T, iterations, error = newton_all(rows, guess, values, TOLERANCE, extra)
    if qs is None or not on_branches(solver, qs):
        return None
    return list(map(Solution, qs, [True] * n, iterations.tolist(), error.tolist())), T


def coarse_path(solver, rows, values: np.ndarray, q, previous, start_tangent):
    """The coarse steps solved with their exact tangents, (q (m, nq), T (m, nv, k)), or
    None: every COARSE_GROUP-th one marched (``march``: its continuation and branch
    checks), the others all at once from their Hermite predictions between those
    (``newton_all``, each on its design branches); all of them marched when that
    fails. (Pinocchio's march costs a Python evaluation per iteration; a batched one
    costs about as much for all the coarse steps at once.)"""
    m = len(values)
    sparse = np.unique(np.r_[np.arange(COARSE_GROUP - 1, m, COARSE_GROUP), m - 1])
    if len(sparse) < m:
        marched = _march_exact(solver, values[sparse], q, previous)
        if marched is None:
            return None
        q0 = np.vstack([q[None], marched[0]])
        v0 = np.vstack([previous[None], values[sparse]])
        T0 = np.concatenate([start_tangent[None], marched[1]])
        guess = hermite(q0, v0, T0, np.searchsorted(sparse, np.arange(m)), values)
        qs, T, _, _ = newton_all(rows, guess, values, TOLERANCE)
        if qs is not None and on_branches(solver, qs):
            return qs, T
    return _march_exact(solver, values, q, previous)


def _march_exact(solver, values: np.ndarray, q, previous):
    """``values``' steps marched with exact tangents: (q (m, nq), T (m, nv, k)), or None
    if any step does not converge."""
    keep = solver.keep_jacobian
    solver.keep_jacobian = True  # exact tangents at the solutions
    try:
        tangents: list = []
        marched = march(solver, values, q, previous, tangents=tangents)
    finally:
        solver.keep_jacobian = keep
    if not all(s.converged for s in marched):
        return None
    return np.array([s.q for s in marched]), np.array(tangents)


def tangent_at(solver, q: np.ndarray, values: np.ndarray) -> np.ndarray | None:
    """The exact tangent at a solved q (its targets' values ``values``)."""
    r, J = rows_of(solver).evaluate(q[None], values[None])
    T = solve_all(J, solver.unit_rhs)
    return None if T is None else T[0]


def hermite(q0, v0, T0, segment, values) -> np.ndarray:
    """Each step's configuration predicted along its coarse segment: t is where its
    values project onto the segment; the cubic Hermite curve through both ends with
    their slopes, plus the near end's tangent times any part off the segment's line."""
    qa, qb = q0[segment], q0[segment + 1]
    va, vb = v0[segment], v0[segment + 1]
    Ta, Tb = T0[segment], T0[segment + 1]
    step = vb - va
    length2 = np.einsum("ni,ni->n", step, step)
    t = np.where(
        length2 > 0,
        np.einsum("ni,ni->n", values - va, step) / np.where(length2 > 0, length2, 1.0),
        1.0,
    )
    t2, t3 = t * t, t * t * t
    h00, h10 = 2 * t3 - 3 * t2 + 1, t3 - 2 * t2 + t
    h01, h11 = -2 * t3 + 3 * t2, t3 - t2
    slope_a = np.einsum("nvk,nk->nv", Ta, step)
    slope_b = np.einsum("nvk,nk->nv", Tb, step)
    guess = h00[:, None] * qa + h10[:, None] * slope_a + h01[:, None] * qb + h11[:, None] * slope_b
    off = values - (va + t[:, None] * step)
    near = np.where((t < 0.5)[:, None, None], Ta, Tb)
    return guess + np.einsum("nvk,nk->nv", near, off)
