"""A batch of a study's variants solved together (docs/studies.md, Speed): a corner's
variants measured together from their trees' numbers where they can be (together.py);
every other variant built, then every step of every variant whose subject solves so
(``solves_stacked``: a corner's) in one set of batched Newton iterations from the
design variant's solutions (solve/stacked.py); each variant's results then follow from
its own steps, and a variant whose steps did not all converge there is marched on its
own, as a sweep — so that its row is the one it would have alone.
"""

from __future__ import annotations

import numpy as np

from ..errors import PinSuspError
from .data import Job
from .variants import Variant


def solve_batch(job: Job, table: np.ndarray, sweep, guess, every_column: bool) -> list:
    """The batch's Variants (``table``: each one's variables), each solved: a corner's
    measured together from their trees' numbers where they can be (together.py), the
    others built and solved as below."""
    measured = [None] * len(table)
    if guess is not None and not every_column:
        together = _together_of(job, sweep, guess)
        if together is not None:
            measured = together.measure(table)
    rest = [i for i, m in enumerate(measured) if m is None]
    for i, v in zip(rest, _built(job, table[rest], sweep, guess, every_column), strict=True):
        measured[i] = v
    return measured


_TOGETHER: dict = {}


def _together_of(job: Job, sweep, guess):
    """The job's Together (its design corner's structure, read once per process), or
    None where its variants cannot be measured so."""
    from .together import Together
    from .variants import design_of, per_job

    def make():
        design = design_of(job, sweep).subject
        if design is None or not design.solves_stacked:
            return None
        try:
            together = Together(job, design, sweep, guess)
        except (PinSuspError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            return None
        return together if together.ok else None

    return per_job(_TOGETHER, job, make)


def _built(job: Job, table: np.ndarray, sweep, guess, every_column: bool) -> list:
    """Variants built one by one, then solved together where they can be (below)."""
    variants = [Variant(job, d, sweep, every_column, later=True) for d in table]
    together = [v for v in variants if v.subject is not None and v.subject.solves_stacked]
    solved = _together(together, sweep, guess) if guess is not None and together else {}
    for i, v in enumerate(together):
        v.solve(solved.get(i, guess))
    for v in variants:
        if v.subject is not None and not v.subject.solves_stacked:
            v.solve(guess)
    return variants


def _together(variants: list, sweep, guess: np.ndarray) -> dict:
    """index → (solutions, tangents) of the variants whose every step converged on its
    design branches, solved together; {} where they cannot be (another structure)."""
    from ..solve.solver import Solution
    from ..solve.stacked import stack

    solvers, values = [], []
    for v in variants:
        try:
            solvers.append(v.subject.solver_for(sweep.targets, sweep.source))
            v.subject.keep_solver(sweep.targets, solvers[-1])  # for its own solve after
            values.append(v.subject.target_values(sweep.targets))
        except (PinSuspError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            return {}  # that variant's own solve says why
    steps = len(guess)
    if any(len(x) != steps for x in values) or guess.shape[1] != solvers[0].kin.model.nq:
        return {}
    together = stack(solvers, steps)
    if together is None:
        return {}
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        q, T, iterations, error, ok = together.solve(
            np.tile(guess, (len(variants), 1)), np.vstack(values)
        )
        ok &= together.on_branches(q)
    out = {}
    for i in range(len(variants)):
        mine = slice(i * steps, (i + 1) * steps)
        if ok[mine].all():
            solutions = list(
                map(
                    Solution,
                    q[mine],
                    [True] * steps,
                    iterations[mine].tolist(),
                    error[mine].tolist(),
                )
            )
            out[i] = (solutions, T[mine])
    return out
