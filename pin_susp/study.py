"""Studies: many variants of one geometry through one sweep, on Dask (docs/studies.md).

A study file names a geometry, a sweep and the hardpoint coordinates that vary
(mm from design). Its variants come from a design of experiments (full
factorial, Latin hypercube, Sobol), from manufacturing tolerances (Monte
Carlo), or from an optimiser's starts (least squares to target values and
curves). They are cut into batches; each batch is one task that builds every
variant's corner (or axle) from the geometry's data and solves its sweep — no
state is shared between tasks, so a batch gives the same numbers wherever it
runs. The client writes each finished batch as its own Parquet part file
(atomically), so ``resume`` skips what is done and a lost worker costs only
its batch: Dask runs it again elsewhere.

Execution: ``scheduler=None`` runs in this process, one batch after another;
``"local"`` starts a ``LocalCluster`` on 127.0.0.1; an address
(``tcp://host:port``) uses an existing scheduler. The numbers are the same.
"""

from __future__ import annotations

import contextlib
import copy
import json
import math
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from . import __version__
from .errors import InputError, NoRoom, PinSuspError
from .study_summary import summary_lines
from .yamlio import Reader, load_yaml, read_once

KINDS = ("doe", "monte_carlo", "optimise")
DOE_METHODS = ("full_factorial", "latin_hypercube", "sobol")
DISTRIBUTIONS = ("normal", "uniform")
AXES = "xyz"
MAX_VARIANTS = 10_000_000  # a typo's 10^9 samples stops at the file, not in memory
MAX_VALUES = 50_000_000  # variants × variables: the variants' table, 400 MB
STUDY_KEYS = (
    "version",
    "name",
    "geometry",
    "sweep",
    "variables",
    "kind",
    "doe",
    "monte_carlo",
    "optimise",
    "summary",
    "batch_size",
)
MANIFEST = "study.json"
PARTS = ".parts"


# ------------------------------------------------------------------ the file


@dataclass(frozen=True)
class Variable:
    """One hardpoint coordinate that varies: mm from design within [low, high]."""

    point: str
    axis: str  # x | y | z
    low: float
    high: float
    side: str | None = None  # left | right on an axle

    @property
    def name(self) -> str:
        side = f"{self.side}_" if self.side else ""
        return f"d_{side}{self.point}_{self.axis}"

    @property
    def key(self) -> str:
        """The hardpoint's name in sensitivities (``left_…`` on an axle, one-sided)."""
        return f"{self.side}_{self.point}" if self.side else self.point


@dataclass(frozen=True)
class Term:
    """One objective term: a metric held at a value, or along a curve, every step."""

    metric: str
    weight: float = 1.0
    relative: bool = False  # the change from the variant's own design state
    target: float | None = None
    curve_x: str | None = None  # the column the curve is over (e.g. wheel_travel)
    curve: np.ndarray | None = None  # (k, 2): x, metric, sorted by x

    def goal(self, x) -> np.ndarray | float:
        """The target at the curve's x: linear between its points, and beyond them
        along the first and last segments."""
        if self.curve is None:
            return self.target
        x = np.asarray(x, dtype=float)
        k, slope = self._segment(x)
        return self.curve[k, 1] + slope * (x - self.curve[k, 0])

    def slope(self, x) -> np.ndarray:
        """d goal / d x: the slope of the segment that x falls in (the end ones beyond)."""
        return self._segment(np.asarray(x, dtype=float))[1]

    def _segment(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The segment that x falls in (its first point's index) and its slope."""
        c = self.curve
        k = np.searchsorted(c[1:-1, 0], np.nan_to_num(x), side="right")
        return k, (c[k + 1, 1] - c[k, 1]) / (c[k + 1, 0] - c[k, 0])


@dataclass
class Study:
    """A study file, read and checked (docs/studies.md)."""

    source: str
    sha256: str | None
    geometry_path: str
    geometry_data: dict
    sweep_path: str
    sweep_data: dict
    axle: bool
    variables: list[Variable]
    kind: str
    samples: int
    seed: int
    method: str | None = None  # doe
    levels: int | None = None  # doe full_factorial
    distribution: str | None = None  # monte_carlo
    terms: list[Term] = field(default_factory=list)  # optimise
    starts: int = 1
    summary: list[str] = field(default_factory=list)
    batch_size: int | None = None
    max_evaluations: int = 60
    geometry_sha256: str | None = None  # of the files as read
    sweep_sha256: str | None = None

    @property
    def names(self) -> list[str]:
        return [v.name for v in self.variables]

    @property
    def low(self) -> np.ndarray:
        return np.array([v.low for v in self.variables])

    @property
    def high(self) -> np.ndarray:
        return np.array([v.high for v in self.variables])

    def job(self) -> Job:
        """What a task needs to solve a batch: plain data, pickled to the workers."""
        return Job(
            geometry=self.geometry_data,
            geometry_path=self.geometry_path,
            sweep=self.sweep_data,
            sweep_path=self.sweep_path,
            axle=self.axle,
            variables=self.variables,
            summary=self.summary,
            terms=self.terms,
            bounds=(self.low, self.high),
            max_evaluations=self.max_evaluations,
        )


def load_study(source: str | Path) -> Study:
    """Read and check a study file; its geometry and sweep are read (and solved at
    design) too, so that every mistake is found before any work."""
    with read_once():  # each file read once: a FIFO or a pipe can be
        return _load_study(source)


def _load_study(source: str | Path) -> Study:
    data, name, sha = load_yaml(source)
    r = Reader(name)
    r.mapping(data, "", required=("geometry", "sweep", "kind"), optional=STUDY_KEYS)
    if "version" in data and r.number(data["version"], "version") != 1:
        r.fail("version", f"this pin_susp reads study files of version 1, got {data['version']}")
    kind = r.choice(data["kind"], "kind", KINDS)
    here = Path(name).parent if name != "<dict>" else Path.cwd()
    geometry_path = str(here / r.text(data["geometry"], "geometry"))
    sweep_path = str(here / r.text(data["sweep"], "sweep"))
    geometry_data, _, geometry_sha = load_yaml(geometry_path)
    sweep_data, _, sweep_sha = load_yaml(sweep_path)
    axle = geometry_data.get("scope") == "axle"
    design = _Design(geometry_data, geometry_path, sweep_path, axle)
    variables = _variables(data, design, r)
    study = Study(
        source=name,
        sha256=sha,
        geometry_path=geometry_path,
        geometry_data=geometry_data,
        sweep_path=sweep_path,
        sweep_data=sweep_data,
        axle=axle,
        variables=variables,
        kind=kind,
        samples=0,
        seed=0,
        geometry_sha256=geometry_sha,
        sweep_sha256=sweep_sha,
    )
    if kind not in data:
        r.fail(kind, f"missing key (kind: {kind} needs its block)")
    for other in KINDS:
        if other != kind and other in data:
            r.fail(other, f"a block for kind {other}, but kind is {kind}")
    block = data[kind]
    if kind == "doe":
        b = r.mapping(block, "doe", required=("method",), optional=("samples", "levels", "seed"))
        study.method = r.choice(b["method"], "doe.method", DOE_METHODS)
        study.seed = _seed(b, "doe", r)
        if study.method == "full_factorial":
            if "samples" in b:
                r.fail("doe.samples", "full_factorial takes levels (per variable), not samples")
            study.levels = _count(b.get("levels", 3), "doe.levels", r, minimum=2)
            study.samples = study.levels ** len(variables)
            if study.samples > MAX_VARIANTS:
                r.fail(
                    "doe.levels",
                    f"{study.levels}^{len(variables)} = {study.samples:.3g} variants is beyond "
                    f"the {MAX_VARIANTS:.0e} limit: fewer levels, or latin_hypercube",
                )
        else:
            if "levels" in b:
                r.fail("doe.levels", f"{study.method} takes samples, not levels")
            if "samples" not in b:
                r.fail("doe.samples", "missing key")
            study.samples = _count(b["samples"], "doe.samples", r)
    elif kind == "monte_carlo":
        b = r.mapping(
            block, "monte_carlo", required=("samples",), optional=("seed", "distribution")
        )
        study.samples = _count(b["samples"], "monte_carlo.samples", r)
        study.seed = _seed(b, "monte_carlo", r)
        study.distribution = r.choice(
            b.get("distribution", "normal"), "monte_carlo.distribution", DISTRIBUTIONS
        )
    else:
        b = r.mapping(
            block, "optimise", required=("objective",), optional=("starts", "seed", "evaluations")
        )
        study.starts = _count(b.get("starts", 1), "optimise.starts", r)
        if study.starts > 10_000:
            r.fail("optimise.starts", f"at most 10000 starts, got {study.starts}")
        study.samples = study.starts
        study.seed = _seed(b, "optimise", r)
        study.max_evaluations = _count(b.get("evaluations", 60), "optimise.evaluations", r)
        study.terms = _terms(b["objective"], design, r)
        if axle and not holds_wheels(design.sweep):
            r.fail(
                "optimise",
                "on an axle the optimiser's exact Jacobian holds each wheel centre's height "
                "and the rack: give a sweep of those targets (roll and heave sweeps: kind doe)",
            )
    summary = data.get("summary", ["camber", "roadwheel_angle"])
    if not isinstance(summary, list) or not summary:
        r.fail("summary", "expected a list of column names (e.g. [camber, roadwheel_angle])")
    for i, m in enumerate(summary):
        design.check_column(r.text(m, f"summary[{i}]"), f"summary[{i}]", r)
    study.summary = list(dict.fromkeys(summary))
    if "batch_size" in data:
        if kind == "optimise":
            r.fail("batch_size", "an optimisation runs one start per task: no batch_size")
        study.batch_size = _count(data["batch_size"], "batch_size", r)
    size = study.samples * max(1, len(variables))
    if size > MAX_VALUES:
        r.fail(
            kind,
            f"{study.samples} variants x {len(variables)} variables is beyond the "
            f"{MAX_VALUES:.0e} values a study holds in memory: fewer samples or variables",
        )
    return study


def _count(value, key: str, r: Reader, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        r.fail(key, f"expected a whole number, got {value!r}")
    if value < minimum:
        r.fail(key, f"must be >= {minimum}, got {value}")
    if value > MAX_VARIANTS:
        r.fail(key, f"{value} is beyond the limit of {MAX_VARIANTS:.0e}")
    return int(value)


def _seed(block: dict, key: str, r: Reader) -> int:
    value = block.get("seed", 1)
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < 2**32:
        r.fail(f"{key}.seed", f"expected a whole number from 0 to 2^32 - 1, got {value!r}")
    return value


class _Design:
    """The study's geometry and sweep solved at design: names to check the file against."""

    def __init__(self, geometry: dict, geometry_path: str, sweep_path: str, axle: bool):
        self.axle = axle
        # errors name the files, as `pin-susp sweep` would
        subject = build(geometry, geometry_path, axle)
        from .sweep import load_sweep

        self.sweep = load_sweep(sweep_path)
        design = _at_design(self.sweep)
        if axle:
            from .axle import axle_results, solve_axle_sweep

            self.results = axle_results(subject, design, solve_axle_sweep(subject, design))
            self.points = {s: list(subject.geometries[s].hardpoints) for s in ("left", "right")}
        else:
            subject.solver_for(self.sweep.targets, self.sweep.source)
            self.results = subject.run_sweep(design)
            self.points = {None: list(subject.geometry.hardpoints)}
        self.columns = [c for c in self.results.columns if c != "step_index"]

    def check_defined(self, name: str, key: str, r: Reader) -> None:
        """A target's column must have a value at the design state (not a blank cell)."""
        if not np.isfinite(np.asarray(self.results[name], dtype=float)[0]):
            r.fail(
                key,
                f"{name} is undefined at this geometry's design state (a blank cell in "
                "the sweep's CSV): it cannot be a target",
            )

    def check_column(self, name: str, key: str, r: Reader) -> None:
        if name not in self.columns:
            near = [c for c in self.columns if name.split("_")[0] in c][:8]
            hint = f" (e.g. {', '.join(near)})" if near else ""
            r.fail(key, f"unknown column {name!r}: not among the sweep's results{hint}")


def _variables(data: dict, design: _Design, r: Reader) -> list[Variable]:
    raw = data.get("variables")
    if raw is None:
        r.fail("variables", "missing key (a list of {point, axis, range}, or all_hardpoints)")
    if isinstance(raw, dict):
        r.mapping(raw, "variables", required=("all_hardpoints",))
        block = r.mapping(raw["all_hardpoints"], "variables.all_hardpoints", ("tolerance",))
        tol = r.positive(block["tolerance"], "variables.all_hardpoints.tolerance")
        return [
            Variable(p, a, -tol, tol, side)
            for side, names in design.points.items()
            for p in names
            for a in AXES
        ]
    if not isinstance(raw, list) or not raw:
        r.fail("variables", "expected a list of {point, axis, range} (or all_hardpoints)")
    out = []
    for i, item in enumerate(raw):
        key = f"variables[{i}]"
        v = r.mapping(item, key, required=("point", "axis", "range"), optional=("side",))
        side = None
        if design.axle:
            if "side" not in v:
                r.fail(f"{key}.side", "missing key: on an axle each variable names its side")
            side = r.choice(v["side"], f"{key}.side", ("left", "right"))
        elif "side" in v:
            r.fail(f"{key}.side", "a corner has one side: side is for an axle's variables")
        point = r.text(v["point"], f"{key}.point")
        names = design.points[side]
        if point not in names:
            r.fail(f"{key}.point", f"unknown hardpoint {point!r} (known: {', '.join(names)})")
        axis = r.choice(v["axis"], f"{key}.axis", tuple(AXES))
        span = v["range"]
        if not isinstance(span, list) or len(span) != 2:
            r.fail(f"{key}.range", "expected [low, high] in mm from design")
        low = r.length(span[0], f"{key}.range[0]")
        high = r.length(span[1], f"{key}.range[1]")
        if not high > low:
            r.fail(f"{key}.range", f"empty range [{low:g}, {high:g}]: low must be below high")
        variable = Variable(point, axis, low, high, side)
        if variable.name in [o.name for o in out]:
            r.fail(key, f"{variable.name} is already a variable")
        out.append(variable)
    return out


def _terms(raw, design: _Design, r: Reader) -> list[Term]:
    if not isinstance(raw, list) or not raw:
        r.fail("optimise.objective", "expected a list of {metric, target | curve, weight}")
    out = []
    for i, item in enumerate(raw):
        key = f"optimise.objective[{i}]"
        t = r.mapping(
            item, key, required=("metric",), optional=("target", "curve", "weight", "relative")
        )
        metric = r.text(t["metric"], f"{key}.metric")
        design.check_column(metric, f"{key}.metric", r)
        design.check_defined(metric, f"{key}.metric", r)
        weight = r.positive(t.get("weight", 1.0), f"{key}.weight")
        relative = t.get("relative", False)
        if not isinstance(relative, bool):
            r.fail(f"{key}.relative", f"expected true or false, got {relative!r}")
        if ("target" in t) == ("curve" in t):
            r.fail(key, "give one of target (a value) or curve ({x, points})")
        if "target" in t:
            out.append(
                Term(metric, weight, relative, target=r.number(t["target"], f"{key}.target"))
            )
            continue
        c = r.mapping(t["curve"], f"{key}.curve", required=("x", "points"))
        x = r.text(c["x"], f"{key}.curve.x")
        design.check_column(x, f"{key}.curve.x", r)
        design.check_defined(x, f"{key}.curve.x", r)
        pts = c["points"]
        if not isinstance(pts, list) or len(pts) < 2:
            r.fail(f"{key}.curve.points", "expected two or more [x, value] pairs")
        rows = []
        for j, p in enumerate(pts):
            if not isinstance(p, list) or len(p) != 2:
                r.fail(f"{key}.curve.points[{j}]", "expected [x, value]")
            rows.append([r.number(p[k], f"{key}.curve.points[{j}][{k}]") for k in (0, 1)])
        curve = np.array(sorted(rows))
        if np.any(np.diff(curve[:, 0]) <= 0.0):
            r.fail(f"{key}.curve.points", "the x values must differ")
        out.append(Term(metric, weight, relative, curve_x=x, curve=curve))
    return out


# --------------------------------------------------------------- the variants


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
            from .axle import mirror_corner

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
            from .axle import AxleModel, load_axle

            return AxleModel(load_axle(data, None if variant else source))
        from .corner import Corner
        from .geometry import parse_geometry, warn_dead_centres

        geometry = parse_geometry(data, Reader("<dict>"), None)
        if not variant:  # a link near dead centre, as every command says
            warn_dead_centres(geometry, source)
        return Corner(geometry, warn=not variant, visuals=not variant)
    except InputError as exc:
        if exc.source == "<dict>":
            raise InputError(source, exc.key, exc.problem) from None
        raise


def _at_design(sweep):
    """A one-step sweep holding every target at its design value."""
    from .sweep import Sweep

    return Sweep([t.at_design() for t in sweep.targets], sweep.source, sweep.sha256)


# ------------------------------------------------------------- one batch


@dataclass
class Job:
    """Plain data for a task: each task builds its corners from it."""

    geometry: dict
    geometry_path: str
    sweep: dict
    sweep_path: str
    axle: bool
    variables: list[Variable]
    summary: list[str]
    terms: list[Term]
    bounds: tuple
    max_evaluations: int = 60

    @property
    def needs(self) -> set[str]:
        """The columns that the summary and the objective read."""
        out = set(self.summary)
        for t in self.terms:
            out |= {t.metric} | ({t.curve_x} if t.curve_x else set())
        return out


class Variant:
    """One variant's geometry solved through the sweep: its results and design state."""

    def __init__(self, job: Job, deltas: np.ndarray, sweep=None, every_column: bool = True):
        from .sweep import load_sweep

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
            return _missed(self.job.terms, len(self.sweep.targets[0].values))
        return objective_residuals(self.job.terms, self.results, self.static)


def _solve(subject, sweep, axle: bool, only=None):
    """The sweep's results and the design state's columns (a one-step row); ``only``:
    the columns wanted (a corner's; an axle's has all)."""
    if axle:
        from .axle import axle_results, solve_axle_sweep

        results = axle_results(subject, sweep, solve_axle_sweep(subject, sweep))
        design = _at_design(sweep)
        static = axle_results(subject, design, solve_axle_sweep(subject, design))
        return results, static.columns
    # one pass of the columns over the design state and the steps: the steps are solved
    # exactly as `pin-susp sweep` solves them, the design row is column-wise the same
    from .corner import Results
    from .solver import Solution

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


def objective_residuals(terms: list[Term], results, static) -> np.ndarray:
    """r with ‖r‖² = Σ_terms w·Σ_steps (m − target)² / Σ_terms w·n: the objective is ‖r‖,
    a weighted RMS in the metrics' units. A step that did not converge counts as a
    miss of 1000 units (no number is made up for it)."""
    n = len(results)
    parts = []
    for t, w in zip(terms, _shares(terms, n), strict=True):
        miss, counted = _miss(t, results, static)
        parts.append(w * np.where(counted, miss, MISS))
    return np.concatenate(parts)


MISS = 1000.0  # a step's miss where it has no value (did not converge, undefined)


def _shares(terms: list[Term], n: int) -> list[float]:
    """√(w / Σw·n) per term: the residuals' weights (Σw taken in ratios: no overflow)."""
    largest = max(t.weight for t in terms)
    total = sum(t.weight / largest for t in terms) * n
    return [math.sqrt(t.weight / largest / total) for t in terms]


def _miss(t: Term, results, static) -> tuple[np.ndarray, np.ndarray]:
    """A term's miss at every step (the metric, from the design state's if relative,
    less its target), and the steps where that is a number: converged, the metric and
    the target defined."""
    m = np.asarray(results[t.metric], dtype=float)
    if t.relative:
        m = m - float(static[t.metric][0])
    goal = t.goal(results[t.curve_x]) if t.curve is not None else t.target
    counted = results["solver_converged"] & np.isfinite(m) & np.isfinite(goal)
    return m - goal, counted


def _missed(terms: list[Term], n: int) -> np.ndarray:
    """The residuals of a variant that could not be built: every step missed."""
    return np.concatenate([np.full(n, w * MISS) for w in _shares(terms, n)])


def run_batch(job: Job, index: int, ids: np.ndarray, table: np.ndarray, steps: bool) -> dict:
    """Solve one batch of variants: its summary rows and, with ``steps``, every step.

    Returns plain data (Arrow IPC bytes) so that any scheduler can carry it."""
    from .sweep import load_sweep

    sweep = load_sweep(job.sweep)
    rows, frames = [], []
    for vid, deltas in zip(ids, table, strict=True):
        v = Variant(job, deltas, sweep, every_column=steps)
        rows.append(_row(job, int(vid), deltas, v))
        if steps and v.results is not None:
            frames.append(_steps_table(v.results, int(vid)))
    return {"index": index, "variants": _ipc(_variants_table(rows)), "steps": _ipc_many(frames)}


def run_start(job: Job, index: int, ids: np.ndarray, table: np.ndarray, steps: bool) -> dict:
    """One optimiser start (a batch of one): scipy least_squares from ``table[0]``, with
    the exact hardpoint sensitivities as its Jacobian; the optimum's row."""
    from scipy.optimize import least_squares

    from .sweep import load_sweep

    sweep = load_sweep(job.sweep)
    low, high = job.bounds
    cache = {}

    def solved(x: np.ndarray) -> Variant:
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = Variant(job, x, sweep, every_column=steps)
        return cache[key]

    def fun(x):
        return solved(x).residuals()

    def jac(x):
        return objective_jacobian(solved(x), sweep)

    x0 = np.clip(table[0], low, high)
    fit = least_squares(
        fun,
        x0,
        jac=jac,
        bounds=(low, high),
        method="trf",
        x_scale=1.0,
        xtol=1e-10,
        ftol=1e-12,
        gtol=1e-10,
        max_nfev=job.max_evaluations,
    )
    best = solved(fit.x)
    row = _row(job, int(ids[0]), fit.x, best)
    row["objective"] = float(np.linalg.norm(fun(fit.x)))
    row["start_objective"] = float(np.linalg.norm(fun(x0)))
    row["evaluations"] = int(fit.nfev)
    frames = [_steps_table(best.results, int(ids[0]))] if steps and best.results else []
    return {"index": index, "variants": _ipc(_variants_table([row])), "steps": _ipc_many(frames)}


def objective_jacobian(v: Variant, sweep) -> np.ndarray:
    """d r / d variables from the exact hardpoint sensitivities at every step and at
    design (a relative term's reference moves too); a curve's target moves with its
    x column. A step without a number (see _miss) has a zero row."""
    job = v.job
    k = len(job.variables)
    n = sweep.steps
    if v.results is None:
        return np.zeros((len(job.terms) * n, k))
    at_design, steps = sensitivities(v.subject, sweep, v.results, job.axle)
    columns = _columns(at_design.hardpoints, job.variables)
    blocks = []
    for t, w in zip(job.terms, _shares(job.terms, n), strict=True):
        counted = _miss(t, v.results, v.static)[1]
        rows = np.zeros((n, k))
        ref = _pick(at_design, t.metric, columns) if t.relative else 0.0
        for i, s in steps.items():
            if not counted[i]:
                continue
            d = _pick(s, t.metric, columns) - ref
            if t.curve is not None and t.curve_x in s.values:
                d = d - t.slope(v.results[t.curve_x][i]) * _pick(s, t.curve_x, columns)
            rows[i] = d
        blocks.append(w * rows)
    return np.vstack(blocks)


def _columns(hardpoints: list[str], variables: list[Variable]) -> tuple:
    return (
        np.array([hardpoints.index(v.key) for v in variables]),
        np.array([AXES.index(v.axis) for v in variables]),
    )


def _pick(s, name: str, columns) -> np.ndarray:
    """d(column)/d(each variable) from a Sensitivity (per mm)."""
    if name not in s.values:
        return np.zeros(len(columns[0]))
    return np.nan_to_num(s.values[name][columns])


def sensitivities(subject, sweep, results, axle: bool) -> tuple:
    """The exact hardpoint sensitivities at design and at each converged step:
    (Sensitivity, {step: Sensitivity}), one-sided names on an axle."""
    from dataclasses import replace

    if axle:
        from .sensitivity import AxleSensitivity

        model = AxleSensitivity(subject, one_sided=True)
        at_design = model.at()
        steps = {}
        if holds_wheels(sweep):  # else the steps' sensitivities hold other quantities
            steps = {
                i: model.at(results.meta["q"][i], step=i)
                for i in range(len(results))
                if results["solver_converged"][i]
            }
        return at_design, steps
    from .sensitivity import HardpointSensitivity

    model = HardpointSensitivity(subject)
    at_design = model.at(subject.q_design)
    steps = {}
    for i in range(len(results)):
        if results["solver_converged"][i]:
            targets = [replace(t, values=t.values[i]) for t in sweep.targets]
            steps[i] = model.at(results.meta["q"][i], targets, step=i)
    return at_design, steps


def holds_wheels(sweep) -> bool:
    """Whether an axle's sweep holds what its sensitivities hold: each wheel centre's
    height and the rack (its roll and heave targets hold other quantities)."""
    keys = set()
    for t in sweep.targets:
        if t.quantity is not None:
            return False
        d = tuple(t.unit_direction.tolist())
        if (t.point, d) == ("wheel_center", (0.0, 0.0, 1.0)):
            keys.add(t.side)
        elif t.point != "trackrod_inboard":
            return False
    return keys == {"left", "right"}


def _row(job: Job, vid: int, deltas, v: Variant) -> dict:
    row = {"variant_id": vid}
    row.update({var.name: float(d) for var, d in zip(job.variables, deltas, strict=True)})
    row["converged"] = v.converged
    row["steps_failed"] = (
        len(v.sweep.targets[0].values)
        if v.results is None
        else int((~v.results["solver_converged"]).sum())
    )
    row.update(v.summary_row())
    row["error"] = v.error
    return row


# ---------------------------------------------------------------- tables


def _steps_table(results, vid: int):
    import pyarrow as pa

    from .io.tables import arrow_columns

    arrays = {"variant_id": pa.array(np.full(len(results), vid, dtype=np.int64))}
    arrays |= arrow_columns(results)
    units = {k: u for k, u in results.units.items() if u}
    return pa.table(arrays).replace_schema_metadata({"units": json.dumps(units)})


def _variants_table(rows: list[dict]):
    import pyarrow as pa

    from .io.tables import arrow_column

    names = list(rows[0])
    return pa.table({k: arrow_column(np.array([r[k] for r in rows])) for k in names})


def _ipc(table) -> bytes:
    import pyarrow as pa

    sink = pa.BufferOutputStream()
    with pa.ipc.new_stream(sink, table.schema) as writer:
        writer.write_table(table)
    return sink.getvalue().to_pybytes()


def _ipc_many(tables: list) -> bytes | None:
    if not tables:
        return None
    import pyarrow as pa

    return _ipc(pa.concat_tables(tables, promote_options="permissive"))


def _from_ipc(data: bytes):
    import pyarrow as pa

    return pa.ipc.open_stream(data).read_all()


# ---------------------------------------------------------------- running


@dataclass
class Outcome:
    """What a study run produced (paths in OUTDIR) and the figures for its summary."""

    study: Study
    outdir: Path
    variants: object  # pandas DataFrame
    computed: int  # batches solved in this run (the rest were resumed)
    batches: int
    lines: list[str] = field(default_factory=list)  # the summary printed
    best: Path | None = None  # best.yaml (optimise)
    figure: Path | None = None  # study.png (None when no variant converged)
    dashboard: str | None = None
    linear: dict | None = None  # Monte Carlo: the first-order prediction per column


def batches(study: Study) -> list[np.ndarray]:
    """The variants' ids cut into batches (fixed by the study alone, so that a
    resumed run cuts them the same)."""
    n = study.samples
    if study.kind == "optimise":
        size = 1
    else:
        size = study.batch_size or max(1, min(200, math.ceil(n / 64)))
    return [np.arange(i, min(i + size, n)) for i in range(0, n, size)]


def run_study(
    study: Study | str | Path,
    outdir: str | Path,
    scheduler: str | None = "local",
    workers: int | None = None,
    steps: bool = False,
    resume: bool = False,
    progress=None,
    announce=None,
    warn=None,
) -> Outcome:
    """Run a study into ``outdir`` (docs/studies.md); see the module's docstring.

    ``progress(done, total)`` after each batch; ``announce(text)`` for a line worth
    printing before the work (the Dask dashboard's address); ``warn(text)`` for a
    damaged part file that a resumed run solves again (default: warnings.warn).

    A run that stops (an interrupt, an error, a write that runs out of room) leaves
    OUTDIR with what ``resume`` needs — its study.json and the part files of the
    batches finished, each whole — or, before any batch is finished, as it found it
    (a new run's study.json and part folder removed). A write that runs out of room
    raises NoRoom saying which (docs/studies.md).
    """
    if not isinstance(study, Study):
        study = load_study(study)
    outdir = Path(outdir)
    _check_outdir(study, outdir, steps, resume)  # before any connection or file
    fresh = not outdir.exists()
    try:
        if scheduler is None or scheduler == "none":
            return _run(study, outdir, None, steps, resume, progress, None, warn)
        with _client(scheduler, workers) as client:  # a scheduler that answers, before any file
            dashboard = _dashboard(client, local=scheduler == "local")
            if announce is not None and dashboard:
                announce(f"Dask dashboard: {dashboard}")
            return _run(study, outdir, client, steps, resume, progress, dashboard, warn)
    except BaseException as exc:
        kept = _left(outdir, fresh, resume)
        if isinstance(exc, NoRoom):
            total = len(batches(study))
            left = (
                f"{kept} of {total} batches are kept in {outdir}: the same command with "
                "--resume continues (once there is room)"
                if kept
                else "nothing written"
            )
            raise NoRoom(exc.path, exc.why, left) from None
        raise


def _left(outdir: Path, fresh: bool, resume: bool) -> int:
    """After a run that stopped: the batches kept for --resume; with none, a new run's
    study.json and part folder go (and OUTDIR, made by it)."""
    kept = finished_batches(outdir) or 0
    if kept or resume:  # a resumed run leaves the directory at least as it found it
        return kept
    parts = outdir / PARTS
    with contextlib.suppress(OSError):
        if parts.is_dir():
            for p in parts.iterdir():  # a batch's steps part, without its variants part
                p.unlink()
            parts.rmdir()
        (outdir / MANIFEST).unlink(missing_ok=True)
        if fresh:
            outdir.rmdir()  # only if empty
    return 0


def _run(study, outdir, client, steps, resume, progress, dashboard, warn=None) -> Outcome:
    table = variant_table(study)
    parts = _prepare(study, outdir, steps, resume)
    cut = batches(study)
    if resume:  # a part cut short or damaged since (a disk error, an editor): solved again
        for i in range(len(cut)):
            why = _damaged(parts, i, cut[i], steps)
            if why is not None:
                for what in ("variants", "steps"):
                    (parts / f"{what}-{i:06d}.parquet").unlink(missing_ok=True)
                message = f"{why}: batch {i} is solved again"
                warnings.warn(message, stacklevel=2) if warn is None else warn(message)
    todo = [i for i in range(len(cut)) if not (parts / f"variants-{i:06d}.parquet").exists()]
    job = study.job()
    task = run_start if study.kind == "optimise" else run_batch
    done = len(cut) - len(todo)
    if progress is not None and done:
        progress(done, len(cut))

    def finished(result: dict) -> None:
        nonlocal done
        _write_part(parts, result)
        done += 1
        if progress is not None:
            progress(done, len(cut))

    if todo and client is None:
        for i in todo:
            finished(task(job, i, cut[i], table[cut[i]], steps))
    elif todo:
        _on_dask(client, task, job, cut, table, todo, steps, finished)
    table = _assemble(study, outdir, parts, len(cut), steps)
    variants = table.to_pandas()
    outcome = Outcome(study, outdir, variants, len(todo), len(cut), dashboard=dashboard)
    outcome.linear = linear_prediction(study, variants) if study.kind == "monte_carlo" else None
    if outcome.linear:  # beside each sampled column, its first-order prediction
        import pyarrow as pa

        for name, values in outcome.linear.items():
            table = table.append_column(f"{name}_linear", pa.array(values, from_pandas=True))
        outcome.variants = variants = table.to_pandas()
    curves = comment = None
    if study.kind == "optimise" and variants["converged"].any():
        row = best_row(variants)
        best = np.array([row[v.name] for v in study.variables], dtype=float)
        comment = (
            f"generated by pin_susp {__version__}: the best of {len(variants)} starts of "
            f"{Path(study.source).name} (objective {float(row['objective']):.6g}, start "
            f"{int(row['variant_id'])})\n"
            + "".join(f"{v.name} = {float(row[v.name])!r} mm\n" for v in study.variables)
        )
        outcome.best = outdir / "best.yaml"
        curves = curves_of(study, best)
    outcome.lines = summary_lines(study, variants, outcome.linear, curves)
    from .io.atomic import all_or_none

    with all_or_none():  # best.yaml, study.png, variants.parquet: together, or none of them
        if outcome.best is not None:
            write_geometry(study, best, outcome.best, comment.rstrip())
        if variants["converged"].any():
            from .plots import save_figure
            from .study_plots import study_figure

            outcome.figure = outdir / "study.png"
            save_figure(study_figure(study, variants, outcome.linear, curves), outcome.figure)
        _write_parquet(table, outdir / "variants.parquet")  # last: it marks the run finished
    _drop_parts(parts)
    return outcome


def _on_dask(client, task, job, cut, table, todo, steps, finished) -> None:
    from distributed import as_completed

    [remote] = client.scatter([job], broadcast=True, hash=False)
    futures = [
        client.submit(task, remote, i, cut[i], table[cut[i]], steps, pure=False, retries=2)
        for i in todo
    ]
    try:
        for future in as_completed(futures):
            finished(future.result())
            future.release()
    finally:
        client.cancel(futures)


class _client:
    """A Dask client: on a LocalCluster (127.0.0.1) or an existing scheduler."""

    def __init__(self, scheduler: str, workers: int | None):
        self.scheduler, self.workers = scheduler, workers
        self.cluster = self.client = None

    def __enter__(self):
        import logging

        from distributed import Client, LocalCluster

        for name in ("distributed", "distributed.worker", "distributed.scheduler"):
            logging.getLogger(name).setLevel(logging.ERROR)
        if self.scheduler == "local":
            n = self.workers or os.cpu_count() or 1
            self.cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address="127.0.0.1:0",  # its HTTP server runs even without bokeh
                silence_logs=logging.ERROR,
            )
            self.client = Client(self.cluster)
            return self.client
        if not self.scheduler.startswith("tcp://"):
            raise PinSuspError(
                f"--scheduler {self.scheduler}: expected an address like tcp://HOST:PORT, "
                "'local' or 'none'"
            )
        _reachable(self.scheduler)
        self.client = _connect(Client, self.scheduler, seconds=8.0)  # an answer in < 10 s
        if self.workers is not None:
            raise PinSuspError("--workers is for the local cluster; a scheduler has its own")
        return self.client

    def __exit__(self, *exc):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _connect(client_class, address: str, seconds: float):
    """A Client of the scheduler at ``address``, or one clear error within ``seconds``
    (a port that accepts and never speaks Dask would otherwise hold the handshake)."""
    import threading

    box = {}

    def connect() -> None:
        try:
            box["client"] = client_class(address, timeout=f"{seconds:g}s")
        except BaseException as exc:  # reported below, in the caller's thread
            box["error"] = exc

    thread = threading.Thread(target=connect, daemon=True, name="pin-susp-connect")
    thread.start()
    thread.join(seconds + 1.0)
    if "client" in box:
        return box["client"]
    why = "no answer" if thread.is_alive() else type(box.get("error")).__name__
    raise PinSuspError(
        f"--scheduler {address}: no Dask scheduler answered within {seconds:g} s ({why}): "
        "is it a Dask scheduler's address?"
    )


def _reachable(address: str) -> None:
    """A TCP scheduler's port must take a connection (Dask would retry a refusal until
    its timeout): one clear line at once, or after 5 s of silence."""
    import socket
    from urllib.parse import urlsplit

    if not address.startswith("tcp://"):
        return
    try:
        parts = urlsplit(address)
        host, port = parts.hostname, parts.port
    except ValueError:
        host = port = None
    if not host or not port:
        raise PinSuspError(f"--scheduler {address}: expected tcp://HOST:PORT")
    try:
        socket.create_connection((host, port), timeout=5.0).close()
    except OSError as exc:
        why = "timed out" if isinstance(exc, TimeoutError) else exc.strerror or str(exc)
        raise PinSuspError(
            f"--scheduler {address}: no Dask scheduler answers there ({why})"
        ) from None


def _has_dashboard() -> bool:
    import importlib.util

    return importlib.util.find_spec("bokeh") is not None


def _dashboard(client, local: bool) -> str | None:
    """The dashboard's address, when it has one to show (on this machine: with bokeh)."""
    if local and not _has_dashboard():
        return None
    try:
        if "dashboard" not in client.scheduler_info().get("services", {}):
            return None
        if not local and not client.run_on_scheduler(_has_dashboard):  # pages need bokeh
            return None
        return client.dashboard_link
    except Exception:  # the link is a courtesy: never a reason to fail
        return None
    return None


# ---------------------------------------------------------------- the directory


def _fingerprint(study: Study, steps: bool) -> dict:
    """What makes a run this study's: the files' hashes, the variants, --steps (the
    study's path is kept for information: the same file may be typed differently)."""
    return {
        "pin_susp": __version__,
        "study": study.source,
        "study_sha256": study.sha256,
        "geometry_sha256": study.geometry_sha256,
        "sweep_sha256": study.sweep_sha256,
        "kind": study.kind,
        "variants": study.samples,
        "batches": len(batches(study)),
        "steps": steps,
    }


INFORMATION = ("pin_susp", "study")  # manifest entries that do not decide sameness


def _prepare(study: Study, outdir: Path, steps: bool, resume: bool) -> Path:
    """Check OUTDIR again and write its manifest; the parts' folder."""
    from .io.atomic import write_text

    mine = _check_outdir(study, outdir, steps, resume)
    manifest = outdir / MANIFEST
    for stale in (outdir / PARTS).glob(".*.tmp"):  # a part cut short by an interruption
        stale.unlink()
    try:
        (outdir / PARTS).mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise PinSuspError(f"{outdir}: cannot write here ({exc.strerror})") from None
    write_text(json.dumps(mine, indent=2) + "\n", manifest)
    return outdir / PARTS


def _check_outdir(study: Study, outdir: Path, steps: bool, resume: bool) -> dict:
    """OUTDIR must be new or empty, or hold this study's unfinished run (``resume``);
    nothing is written. The manifest that the run will write."""
    from .io.atomic import check_folder

    mine = _fingerprint(study, steps)
    check_folder(outdir)  # a name too long for the file system: one line, not a traceback
    manifest = outdir / MANIFEST
    if outdir.exists() and not outdir.is_dir():
        raise PinSuspError(f"{outdir}: exists and is not a directory")
    if outdir.exists() and any(outdir.iterdir()):
        if not manifest.is_file():
            raise PinSuspError(
                f"{outdir}: is not empty and holds no study: give a new or empty directory"
            )
        try:
            theirs = json.loads(manifest.read_text())
        except (OSError, ValueError):
            theirs = None
        if not isinstance(theirs, dict):
            raise PinSuspError(f"{manifest}: unreadable: not a study's directory")
        differs = [k for k in mine if k not in INFORMATION and theirs.get(k) != mine[k]]
        if differs == ["steps"]:
            how = "with" if theirs.get("steps") else "without"
            raise PinSuspError(
                f"{outdir}: holds a run of this study made {how} --steps: run it {how} "
                "--steps, or give a new or empty directory"
            )
        if differs:
            what = theirs.get("study", "another study")
            raise PinSuspError(
                f"{outdir}: holds the data of another study ({what}; differs in "
                f"{', '.join(differs)}): give a new or empty directory"
            )
        if (outdir / "variants.parquet").exists():
            raise PinSuspError(
                f"{outdir}: this study has already finished here: give a new or empty directory"
            )
        if not resume:
            raise PinSuspError(
                f"{outdir}: holds an unfinished run of this study: --resume to finish it, or "
                "give a new or empty directory"
            )
    elif resume:
        raise PinSuspError(f"{outdir}: no unfinished run of this study to resume")
    else:
        from .io.atomic import existing_ancestor

        folder = existing_ancestor(outdir.absolute())
        if not folder.is_dir():
            raise PinSuspError(f"{outdir}: cannot write here ({folder} is not a directory)")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise PinSuspError(f"{outdir}: cannot write here (no permission in {folder})")
    return mine


def finished_batches(outdir: str | Path) -> int | None:
    """How many batches an unfinished run in ``outdir`` has written (None: no run there)."""
    outdir = Path(outdir)
    if not (outdir / MANIFEST).is_file() or (outdir / "variants.parquet").exists():
        return None
    return len(list((outdir / PARTS).glob("variants-*.parquet")))


def _write_part(parts: Path, result: dict) -> None:
    """A batch's part files, each written whole; the variants' part last: its
    presence marks the batch done (a steps part without it goes)."""
    i = result["index"]
    parts.mkdir(exist_ok=True)
    order = [("steps", result["steps"]), ("variants", result["variants"])]
    try:
        for what, data in order:
            if data is not None:
                _write_parquet(_from_ipc(data), parts / f"{what}-{i:06d}.parquet")
    except BaseException:
        (parts / f"steps-{i:06d}.parquet").unlink(missing_ok=True)
        raise


def _damaged(parts: Path, i: int, ids: np.ndarray, steps: bool) -> str | None:
    """What is wrong with batch ``i``'s part files (None: nothing, or not written):
    each must read whole, its variants part holding the batch's variants."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = parts / f"variants-{i:06d}.parquet"
    if not path.exists():
        return None
    names = [path] + [parts / f"steps-{i:06d}.parquet"] * steps
    for name in names:
        if not name.exists():
            continue  # a batch none of whose variants converged has no steps
        try:
            table = pq.read_table(name)
        except (pa.ArrowException, OSError, ValueError) as exc:
            return f"{name}: damaged ({_first_line(exc)})"
        if name == path:
            got = (
                np.sort(table.column("variant_id").to_numpy())
                if "variant_id" in (table.column_names)
                else None
            )
            if got is None or not np.array_equal(got, ids):
                return f"{name}: does not hold batch {i}'s variants"
    return None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0][:200] if text else type(exc).__name__


def _write_parquet(table, path: Path) -> None:
    """A table as Parquet, whole or not at all (io.atomic.atomic_write)."""
    import pyarrow.parquet as pq

    from .io.atomic import atomic_write

    with atomic_write(path, binary=True) as f:
        pq.write_table(table, f)


def _assemble(study: Study, outdir: Path, parts: Path, n: int, steps: bool):
    """The variants' table (by variant_id) from the parts, and steps.parquet (a
    dataset: a folder of part files) moved into place."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    missing = [i for i in range(n) if not (parts / f"variants-{i:06d}.parquet").is_file()]
    if missing:  # removed under a running study: never a table with holes
        raise PinSuspError(
            f"{parts}: the part files of {len(missing)} batches went missing while the study "
            "ran (removed by another program?): --resume solves them again"
        )
    tables = []
    for i in range(n):
        path = parts / f"variants-{i:06d}.parquet"
        try:
            tables.append(pq.read_table(path))
        except (pa.ArrowException, OSError, ValueError) as exc:  # damaged while the run ran
            raise PinSuspError(
                f"{path}: damaged ({_first_line(exc)}): --resume solves its batch again"
            ) from None
    variants = pa.concat_tables(tables, promote_options="permissive").sort_by("variant_id")
    units = {v.name: "mm" for v in study.variables}
    meta = {
        "units": json.dumps(units),
        "pin_susp": __version__,
        "study": json.dumps(_fingerprint(study, steps)),
        "variables": json.dumps([v.__dict__ for v in study.variables]),
    }
    variants = variants.replace_schema_metadata(meta)
    if steps and any(parts.glob("steps-*.parquet")):  # (no variant solved: no steps)
        folder = outdir / "steps.parquet"
        folder.mkdir(exist_ok=True)
        for i in range(n):
            part = parts / f"steps-{i:06d}.parquet"
            if part.exists():
                os.replace(part, folder / f"part-{i:06d}.parquet")
    return variants


def _drop_parts(parts: Path) -> None:
    for p in parts.iterdir():
        p.unlink()
    parts.rmdir()


def read_steps(outdir: str | Path):
    """A finished study's steps.parquet as one pandas DataFrame."""
    import pandas as pd

    return pd.read_parquet(Path(outdir) / "steps.parquet")


def write_geometry(study: Study, deltas, path: str | Path, comment: str) -> None:
    """The study's geometry file with the deltas applied (best.yaml), whole or not at all."""
    from .io.atomic import write_text

    data = variant_data(study.geometry_data, study.variables, deltas, study.axle)
    lines = "".join(f"# {line}\n" for line in comment.splitlines())
    write_text(lines + yaml.safe_dump(data, sort_keys=False), path)


__all__ = [
    "InputError",
    "Outcome",
    "Study",
    "Variable",
    "load_study",
    "read_steps",
    "run_study",
    "variant_data",
    "variant_table",
]


# ---------------------------------------------------------------- after the run


def linear_prediction(study: Study, variants) -> dict[str, np.ndarray] | None:
    """The first-order prediction of each summary column from the exact hardpoint
    sensitivities at design and at every step (no re-solve): name → values per
    variant, for ``<metric>_static``, ``_min`` and ``_max`` — on an axle the steps'
    only where its sweep holds what the sensitivities hold (holds_wheels)."""
    from .sweep import load_sweep

    job = study.job()
    sweep = load_sweep(study.sweep_data)
    design = Variant(job, np.zeros(len(study.variables)), sweep, every_column=True)
    if design.results is None or not design.converged:
        return None
    at_design, steps = sensitivities(design.subject, sweep, design.results, study.axle)
    columns = _columns(at_design.hardpoints, study.variables)
    d = variants[study.names].to_numpy(dtype=float)
    out = {}
    for m in study.summary:
        if m not in at_design.values:
            continue
        out[f"{m}_static"] = float(design.static[m][0]) + d @ _pick(at_design, m, columns)
        if not steps:  # an axle's roll or heave sweep: the static column alone
            continue
        per_step = np.stack(
            [design.results[m][i] + d @ _pick(s, m, columns) for i, s in steps.items()], axis=1
        )
        out[f"{m}_min"] = per_step.min(axis=1)
        out[f"{m}_max"] = per_step.max(axis=1)
    return out


def best_row(variants):
    """The converged start with the least objective."""
    return variants[variants["converged"]].sort_values("objective").iloc[0]


def curves_of(study: Study, deltas) -> list[dict]:
    """Per objective term: the metric over the sweep before (design) and after (the
    variables at ``deltas``), and the target — for the figure."""
    from .sweep import load_sweep

    job = study.job()
    sweep = load_sweep(study.sweep_data)
    before = Variant(job, np.zeros(len(study.variables)), sweep)
    after = Variant(job, deltas, sweep)
    out = []
    lead = sweep.targets[0]
    for t in study.terms:
        entry = {"metric": t.metric, "relative": t.relative}
        for label, v in (("before", before), ("after", after)):
            if v.results is None:
                entry[label] = None
                continue
            y = np.asarray(v.results[t.metric], dtype=float)
            if t.relative:
                y = y - float(v.static[t.metric][0])
            x_name = t.curve_x or _x_column(lead, v.results)
            entry[label] = (np.asarray(v.results[x_name], dtype=float), y)
            entry["x"] = x_name
            entry[f"{label}_target"] = (
                np.full(len(y), t.target)
                if t.curve is None
                else t.goal(np.asarray(v.results[x_name], dtype=float))
            )
        out.append(entry)
    return out


def _x_column(target, results) -> str:
    """The column that the sweep's first target drives, for a curve's x axis."""
    if target.quantity is not None:
        return target.quantity if target.quantity in results.columns else "step_index"
    if target.point == "wheel_center" and "wheel_travel" in results.columns:
        return "wheel_travel"
    name = f"{target.point}_{target.direction}" if isinstance(target.direction, str) else ""
    return name if name in results.columns else "step_index"
