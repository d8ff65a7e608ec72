"""A study file read and checked (docs/studies.md): its geometry and sweep read and
solved at design, its variables, its kind's block, its objective; its batches.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..io.yamlio import Reader, load_yaml, read_once
from ..model.units import read_units
from ..subjects.subject import kind_of, referenced_files
from .data import AXES, Job, Term, Variable
from .variants import at_design, build

KINDS = ("doe", "monte_carlo", "optimise")
DOE_METHODS = ("full_factorial", "latin_hypercube", "sobol")
DISTRIBUTIONS = ("normal", "uniform")


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
    "conventions",
    "units",
    "force_units",
)
MANIFEST = "study.json"
PARTS = ".parts"


@dataclass
class Study:
    """A study file, read and checked (docs/studies.md)."""

    source: str
    sha256: str | None
    geometry_path: str
    geometry_data: dict
    sweep_path: str
    sweep_data: dict
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
    convention: str = "iso"  # conventions: the outputs' sign convention (io.conventions)
    max_evaluations: int = 60
    geometry_sha256: str | None = None  # of the files as read
    sweep_sha256: str | None = None
    on_road: bool = False  # its subject's body stands on the road (a vehicle's: Assembly)
    # the files the geometry reads (a vehicle's axle files): path → sha256 as read
    referenced_sha256: dict[str, str] = field(default_factory=dict)
    # each summary column's unit, as the design's sweep gives it ("deg/deg": per degree
    # of roll); variants.parquet's units and study.png's labels
    column_units: dict[str, str] = field(default_factory=dict)

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
    geometry_data = kind_of(geometry_data).in_mm(geometry_data, geometry_path)  # variants' mm
    sweep_data, _, sweep_sha = load_yaml(sweep_path)
    design = _Design(geometry_data, geometry_path, sweep_path)
    design.units = read_units(data, r)  # the study's own lengths, forces and rates
    variables = _variables(data, design, r)
    study = Study(
        source=name,
        sha256=sha,
        geometry_path=geometry_path,
        geometry_data=geometry_data,
        sweep_path=sweep_path,
        sweep_data=sweep_data,
        variables=variables,
        kind=kind,
        samples=0,
        seed=0,
        geometry_sha256=geometry_sha,
        sweep_sha256=sweep_sha,
        referenced_sha256={
            str(path): load_yaml(path)[2] for path in referenced_files(geometry_path)
        },
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
        if design.subject.on_road:
            r.fail(
                "optimise",
                "a vehicle's sweep holds its body on the road, and the optimiser's exact "
                "Jacobian holds each wheel centre's height in the chassis: optimise one of "
                "its axle files (kind doe or monte_carlo take the vehicle)",
            )
        if not design.subject.sensitivities_hold(design.sweep):
            r.fail(
                "optimise",
                "on an axle the optimiser's exact Jacobian holds each wheel centre's height "
                "and the rack: give a sweep of those targets (roll and heave sweeps: kind doe)",
            )
    # (default: camber and toe, each corner's on an axle or a vehicle)
    summary = data.get("summary", design.default_summary(("camber", "roadwheel_angle")))
    if not isinstance(summary, list) or not summary:
        r.fail("summary", "expected a list of column names (e.g. [camber, roadwheel_angle])")
    for i, m in enumerate(summary):
        design.check_column(r.text(m, f"summary[{i}]"), f"summary[{i}]", r)
    study.summary = list(dict.fromkeys(summary))
    study.column_units = {m: design.results.units.get(m, "") for m in study.summary}
    study.on_road = design.subject.on_road
    if "conventions" in data:  # one name: the convention of variants.parquet, steps.parquet
        from ..io.conventions import CONVENTIONS

        study.convention = r.choice(data["conventions"], "conventions", tuple(CONVENTIONS))
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

    def __init__(self, geometry: dict, geometry_path: str, sweep_path: str):
        # errors name the files, as `pin-susp sweep` would
        from ..model.clearance_bodies import check_clearance

        check_clearance(geometry_path)  # its clearance bodies, as every command checks them
        self.subject = subject = build(geometry, geometry_path)
        from ..model.sweep import load_sweep

        self.sweep = load_sweep(sweep_path)
        subject.check_sweep(self.sweep)
        self.results = subject.solve_sweep(at_design(self.sweep))[1]
        # each corner's hardpoints by its label (None for a corner's one, unlabelled);
        # the labels a variable's side names (none on a corner)
        self.points = {label or None: list(g.hardpoints) for label, g in subject.corners.items()}
        self.sides = tuple(label for label in subject.labels if label)
        self.noun = f"{subject.article} {subject.noun}"  # (one with sides: an axle, a vehicle)
        self.columns = [c for c in self.results.columns if c != "step_index"]

    def default_summary(self, metrics: tuple[str, ...]) -> list[str]:
        """The metrics' columns: a corner's own, else each of its corners' (``_left``,
        ``_fl``, ...)."""
        return [
            column
            for m in metrics
            for column in ([m] if m in self.columns else [f"{m}_{s}" for s in self.sides])
            if column in self.columns
        ]

    def factor(self, column: str) -> float:
        """What one unit of the study's number on ``column`` is in the column's own unit
        (mm, N, N/mm; angles and the rest as they are)."""
        u, unit = self.units, self.results.units.get(column)
        return {"mm": u.length, "N": u.force, "N/mm": u.rate, "N·m": u.moment}.get(unit, 1.0)

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
        if self.results.columns[name].dtype.kind == "O":  # limit_exceeded: names, not numbers
            r.fail(key, f"{name} is a column of names, not numbers (its margins are numbers)")


def _variables(data: dict, design: _Design, r: Reader) -> list[Variable]:
    raw = data.get("variables")
    if raw is None:
        r.fail("variables", "missing key (a list of {point, axis, range}, or all_hardpoints)")
    if isinstance(raw, dict):
        r.mapping(raw, "variables", required=("all_hardpoints",))
        block = r.mapping(raw["all_hardpoints"], "variables.all_hardpoints", ("tolerance",))
        tol = r.positive(block["tolerance"], "variables.all_hardpoints.tolerance")
        tol *= design.units.length
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
        if design.sides:
            if "side" not in v:
                r.fail(
                    f"{key}.side",
                    f"missing key: on {design.noun} each variable names its corner "
                    f"({', '.join(design.sides)})",
                )
            side = r.choice(v["side"], f"{key}.side", design.sides)
        elif "side" in v:
            r.fail(
                f"{key}.side",
                "a corner has one side: side is for an axle's or a vehicle's variables",
            )
        point = r.text(v["point"], f"{key}.point")
        names = design.points[side]
        if point not in names:
            r.fail(f"{key}.point", f"unknown hardpoint {point!r} (known: {', '.join(names)})")
        axis = r.choice(v["axis"], f"{key}.axis", tuple(AXES))
        span = v["range"]
        if not isinstance(span, list) or len(span) != 2:
            r.fail(f"{key}.range", "expected [low, high] in mm from design")
        low = r.length(span[0], f"{key}.range[0]") * design.units.length
        high = r.length(span[1], f"{key}.range[1]") * design.units.length
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
            target = r.number(t["target"], f"{key}.target") * design.factor(metric)
            out.append(Term(metric, weight, relative, target=target))
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
        curve = np.array(sorted(rows)) * [design.factor(x), design.factor(metric)]
        if np.any(np.diff(curve[:, 0]) <= 0.0):
            r.fail(f"{key}.curve.points", "the x values must differ")
        out.append(Term(metric, weight, relative, curve_x=x, curve=curve))
    return out


def batches(study: Study) -> list[np.ndarray]:
    """The variants' ids cut into batches (fixed by the study alone, so that a
    resumed run cuts them the same): by default 16 (each a task, its part file: fewer,
    larger batches cost less to send, write and solve together), of 200 at most."""
    n = study.samples
    if study.kind == "optimise":
        size = 1
    else:
        size = study.batch_size or max(1, min(200, math.ceil(n / 16)))
    return [np.arange(i, min(i + size, n)) for i in range(0, n, size)]
