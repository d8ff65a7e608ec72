"""A study's variants (docs/studies.md): their table (a design of experiments, Monte
Carlo, an optimiser's starts), each variant's geometry data, its subject built and
solved through the sweep.
"""

from __future__ import annotations

import copy
import math
import warnings
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError, PinSuspError
from ..yamlio import Reader
from .data import AXES, Job, Variable, missed, objective_residuals

if TYPE_CHECKING:
    from .spec import Study


def variant_table(study: Study) -> np.ndarray:
    """Every variant's variables (n, k), mm from design; deterministic for a seed."""
    from scipy.stats import qmc

    low, high = study.low, study.high
    k = len(study.variables)
    if study.kind == "doe" and study.method == "full_factorial":
        axes = [np.linspace(a, b, study.levels) for a, b in zip(low, high, strict=True)]
        grid = np.meshgrid(*axes, indexing="ij")
        return np.stack([g.ravel() for g in grid], axis=1)
    if study.kind == "doe":
        if study.method == "latin_hypercube":
            unit = qmc.LatinHypercube(d=k, seed=study.seed).random(study.samples)
        else:
            unit = _sobol(k, study.samples, study.seed)
        return qmc.scale(unit, low, high)
    if study.kind == "monte_carlo":
        rng = np.random.default_rng(study.seed)
        if study.distribution == "uniform":
            return rng.uniform(low, high, size=(study.samples, k))
        mean, sigma = 0.5 * (low + high), (high - low) / 6.0  # range = ±3σ
        return mean + sigma * rng.standard_normal((study.samples, k))
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


def variant_data(base: dict, variables: list[Variable], deltas, axle: bool) -> dict:
    """The geometry file's data with each variable's delta (mm) added to its point."""
    data = copy.deepcopy(base)
    if axle:
        points = data["hardpoints"]
        if "right" not in points or points["right"] is None:  # mirrored: made explicit
            from ..axle import mirror_corner

            points["right"] = mirror_corner({"hardpoints": points["left"]})["hardpoints"]
    for v, d in zip(variables, deltas, strict=True):
        if d == 0.0:
            continue
        table = data["hardpoints"][v.side] if v.side else data["hardpoints"]
        p = table[v.point]
        i = AXES.index(v.axis)
        if isinstance(p, dict):
            p[v.axis] = float(p[v.axis]) + float(d)
        else:
            p[i] = float(p[i]) + float(d)
    return data


def build(data: dict, source: str, axle: bool, variant: bool = False):
    """A corner or an axle from a geometry file's data (errors name ``source``). A
    ``variant``'s corner goes without the plausibility warnings (the design's were
    shown) and the URDF's shapes (never drawn)."""
    try:
        if axle:
            from ..axle import AxleModel, load_axle

            return AxleModel(load_axle(data, None if variant else source))
        from ..corner import Corner
        from ..geometry import parse_geometry, warn_dead_centres

        geometry = parse_geometry(data, Reader("<dict>"), None)
        if not variant:  # a link near dead centre, as every command says
            warn_dead_centres(geometry, source)
        return Corner(geometry, warn=not variant, visuals=not variant)
    except InputError as exc:
        if exc.source == "<dict>":
            raise InputError(source, exc.key, exc.problem) from None
        raise


def at_design(sweep):
    """A one-step sweep holding every target at its design value."""
    from ..sweep import Sweep

    return Sweep([t.at_design() for t in sweep.targets], sweep.source, sweep.sha256)


class Variant:
    """One variant's geometry solved through the sweep: its results and design state."""

    def __init__(self, job: Job, deltas: np.ndarray, sweep=None, every_column: bool = True):
        from ..sweep import load_sweep

        self.job = job
        self.deltas = np.asarray(deltas, dtype=float)
        self.sweep = sweep if sweep is not None else load_sweep(job.sweep)
        self.error = ""
        self.results = self.static = None
        data = variant_data(job.geometry, job.variables, self.deltas, job.axle)
        try:
            with warnings.catch_warnings():  # a variant's plausibility: the design's was shown
                warnings.simplefilter("ignore")
                self.subject = build(data, "variant", job.axle, variant=True)
                only = None if every_column else job.needs
                self.results, self.static = _solve(self.subject, self.sweep, job.axle, only)
        except PinSuspError as exc:
            self.subject = None
            self.error = str(exc)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
            # a degenerate variant (a link of zero length, a singular pose): reported in
            # its row, not allowed to stop the thousands of others
            self.subject = None
            self.error = f"variant: cannot be solved ({type(exc).__name__}: {exc})"

    @property
    def converged(self) -> bool:
        return self.results is not None and bool(self.results["solver_converged"].all())

    def summary_row(self) -> dict:
        row = {}
        n = len(self.sweep.targets[0].values)
        for m in self.job.summary:
            if self.results is None:
                static, values = math.nan, np.full(n, np.nan)
            else:
                static = float(self.static[m][0])
                values = np.where(self.results["solver_converged"], self.results[m], np.nan)
            finite = values[np.isfinite(values)]
            row[f"{m}_static"] = static
            row[f"{m}_min"] = float(finite.min()) if finite.size else math.nan
            row[f"{m}_max"] = float(finite.max()) if finite.size else math.nan
        return row

    def residuals(self) -> np.ndarray:
        """The objective's residual vector (see objective_residuals); a variant that
        could not be built misses at every step."""
        if self.results is None:
            return missed(self.job.terms, len(self.sweep.targets[0].values))
        return objective_residuals(self.job.terms, self.results, self.static)


def _solve(subject, sweep, axle: bool, only=None):
    """The sweep's results and the design state's columns (a one-step row); ``only``:
    the columns wanted (a corner's; an axle's has all)."""
    if axle:
        from ..axle import axle_results, solve_axle_sweep

        results = axle_results(subject, sweep, solve_axle_sweep(subject, sweep))
        design = at_design(sweep)
        static = axle_results(subject, design, solve_axle_sweep(subject, design))
        return results, static.columns
    # one pass of the columns over the design state and the steps: the steps are solved
    # exactly as `pin-susp sweep` solves them, the design row is column-wise the same
    from ..corner import Results
    from ..solver import Solution

    tangents = []
    solutions = subject.solve_steps(sweep, tangents=tangents)
    design = Solution(subject.q_design.copy(), True, 0, 0.0)
    both = Results.from_solutions(
        subject, [design, *solutions], sweep, [None, *tangents] if tangents else None, only
    )
    columns = {k: v[1:] for k, v in both.columns.items()}
    columns["step_index"] = np.arange(len(solutions))
    meta = dict(both.meta, q=both.meta["q"][1:], why=both.meta["why"][1:])
    static = {k: v[:1] for k, v in both.columns.items()}
    return Results(columns, both.units, meta), static
