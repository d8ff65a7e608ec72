"""A study's variants (docs/studies.md): their table (a design of experiments, Monte
Carlo, an optimiser's starts), each variant's geometry data, its subject built and
solved through the sweep.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError, PinSuspError
from ..subjects.subject import kind_of
from .data import AXES, Job, Variable, missed, objective_residuals

if TYPE_CHECKING:
    from .spec import Study


def variant_table(study: Study) -> np.ndarray:
    """Every variant's variables (n, k), mm from design; deterministic for a seed."""
    low, high = study.low, study.high
    k = len(study.variables)
    if study.kind == "doe" and study.method == "full_factorial":
        axes = [np.linspace(a, b, study.levels) for a, b in zip(low, high, strict=True)]
        grid = np.meshgrid(*axes, indexing="ij")
        return np.stack([g.ravel() for g in grid], axis=1)
    if study.kind == "monte_carlo":  # (before scipy.stats, a second to import)
        rng = np.random.default_rng(study.seed)
        if study.distribution == "uniform":
            return rng.uniform(low, high, size=(study.samples, k))
        mean, sigma = 0.5 * (low + high), (high - low) / 6.0  # range = ±3σ
        return mean + sigma * rng.standard_normal((study.samples, k))
    from scipy.stats import qmc

    if study.kind == "doe":
        if study.method == "latin_hypercube":
            unit = qmc.LatinHypercube(d=k, seed=study.seed).random(study.samples)
        else:
            unit = _sobol(k, study.samples, study.seed)
        return qmc.scale(unit, low, high)
    # optimise: the first start at design (or the box's centre), then a Sobol spread
    first = np.clip(np.zeros(k), low, high)
    if study.starts == 1:
        return first[None]
    unit = _sobol(k, study.starts - 1, study.seed)
    return np.vstack([first, qmc.scale(unit, low, high)])


def _sobol(k: int, n: int, seed: int) -> np.ndarray:
    """n scrambled Sobol points in the unit cube of k dimensions."""
    from scipy.stats import qmc

    with warnings.catch_warnings():  # "balance properties": n not a power of 2
        warnings.simplefilter("ignore")
        return qmc.Sobol(d=k, scramble=True, seed=seed).random(n)


def variant_data(base: dict, variables: list[Variable], deltas, axle=None) -> dict:
    """The geometry file's data with each variable's delta (mm) added to its point (its
    corner's by the variable's side: every corner's points its own, an axle's mirrored
    right side written out; subject.kind_of). ``axle``: unused, the kind is the data's."""
    kind = kind_of(base)
    data = kind.variant_data(base)
    for v, d in zip(variables, deltas, strict=True):
        if d == 0.0:
            continue
        p = kind.hardpoints(data, v.side)[v.point]
        i = AXES.index(v.axis)
        if isinstance(p, dict):
            p[v.axis] = float(p[v.axis]) + float(d)
        else:
            p[i] = float(p[i]) + float(d)
    return data


def build(data: dict, source: str, variant: bool = False):
    """The subject of a geometry file's data, a corner or an axle (subject.kind_of;
    errors name ``source``). A ``variant``'s goes without the plausibility warnings (the
    design's were shown) and the URDF's shapes (never drawn)."""
    try:
        return kind_of(data).build(data, source, variant)
    except InputError as exc:
        if exc.source == "<dict>":
            raise InputError(source, exc.key, exc.problem) from None
        raise


def at_design(sweep):
    """A one-step sweep holding every target at its design value."""
    from ..model.sweep import Sweep

    return Sweep([t.at_design() for t in sweep.targets], sweep.source, sweep.sha256)


class Variant:
    """One variant's geometry solved through the sweep: its results and design state."""

    def __init__(
        self,
        job: Job,
        deltas: np.ndarray,
        sweep=None,
        every_column: bool = True,
        guess=None,
        later: bool = False,
    ):
        """``guess``: each step's configuration near its own (the design variant's
        solutions: tasks.guess_of), every step of a corner's sweep then solved at once from
        it where that converges (else marched, as a sweep; an axle's and a vehicle's are
        marched: their roll centres, far out, would move in their last digits). ``later``:
        the subject built, its sweep left to ``solve`` (a batch's variants solved
        together first: batch.py)."""
        from ..model.sweep import load_sweep

        self.job = job
        self.deltas = np.asarray(deltas, dtype=float)
        self.sweep = sweep if sweep is not None else load_sweep(job.sweep)
        self.error = ""
        self.results = self.static = None
        self.every_column = every_column
        data = variant_data(job.geometry, job.variables, self.deltas)
        self.subject = self._guarded(lambda: build(data, "variant", variant=True))
        if not later:
            self.solve(guess)

    def solve(self, guess=None) -> None:
        """The sweep and the design state solved (``guess``: as the constructor's, or the
        steps solved already: (solutions, tangents), march's)."""
        if self.subject is None:
            return
        only = None if self.every_column else self.job.needs
        solved = self._guarded(lambda: self.subject.sweep_and_design(self.sweep, only, guess))
        if solved is not None:
            self.results, self.static = solved

    def _guarded(self, work):
        """``work()``, or None with the variant's error set (and no subject): a variant
        that cannot be built or solved is reported in its row, never allowed to stop the
        thousands of others."""
        try:
            with warnings.catch_warnings():  # a variant's plausibility: the design's was shown
                warnings.simplefilter("ignore")
                return work()
        except PinSuspError as exc:
            self.error = str(exc)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
            # a degenerate variant (a link of zero length, a singular pose)
            self.error = f"variant: cannot be solved ({type(exc).__name__}: {exc})"
        self.subject = None
        return None

    @property
    def solved(self) -> np.ndarray | None:
        """Each step's configuration (n, nq) where every step converged, else None: a
        guess for the next variants (the same tree)."""
        return self.results.meta["q"] if self.converged else None

    @property
    def converged(self) -> bool:
        return self.results is not None and bool(self.results["solver_converged"].all())

    @property
    def steps_failed(self) -> int:
        """How many of its sweep's steps did not converge (every one if none was solved)."""
        if self.results is None:
            return len(self.sweep.targets[0].values)
        return int((~self.results["solver_converged"]).sum())

    def summary_row(self) -> dict:
        row = {}
        n = len(self.sweep.targets[0].values)
        for m in self.job.summary:
            if self.results is None:
                static, values = math.nan, np.full(n, np.nan)
            else:
                static = float(self.static[m][0])
                values = np.where(self.results["solver_converged"], self.results[m], np.nan)
            row |= summary_figures(m, static, values)
        return row

    def residuals(self) -> np.ndarray:
        """The objective's residual vector (see objective_residuals); a variant that
        could not be built misses at every step."""
        if self.results is None:
            return missed(self.job.terms, len(self.sweep.targets[0].values))
        return objective_residuals(self.job.terms, self.results, self.static)


def summary_figures(m: str, static: float, values: np.ndarray) -> dict:
    """A summary column's figures: its value at design, its least and greatest over
    the steps (``values``: NaN where a step did not converge or the column is blank)."""
    finite = values[np.isfinite(values)]
    return {
        f"{m}_static": static,
        f"{m}_min": float(finite.min()) if finite.size else math.nan,
        f"{m}_max": float(finite.max()) if finite.size else math.nan,
    }


def per_job(cache: dict, job: Job, make):
    """``make()`` for a job, made once per process that runs the job's tasks (``cache``:
    id(job) → (job, what was made); a few jobs kept)."""
    kept = cache.get(id(job))
    if kept is None or kept[0] is not job:
        if len(cache) >= 4:
            cache.clear()
        kept = cache[id(job)] = (job, make())
    return kept[1]


_DESIGNS: dict = {}


def design_of(job: Job, sweep) -> Variant:
    """The job's design variant (every variable 0), solved through the sweep: built
    once per process that runs the job's tasks."""
    return per_job(_DESIGNS, job, lambda: Variant(job, np.zeros(len(job.variables)), sweep, False))
