"""A corner ready to solve: its linkage with the setup applied, sweeps and results.

``Corner(geometry)`` applies the camber shim and the length adjusters first
(``as_set.apply_setup``): the as-set state is the design state of every sweep.
The model itself — URDF, Pinocchio model, points, closures — is the
:class:`~pin_susp.linkage.Linkage`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .assembly import Assembly
from .constraints import PointTarget
from .errors import InputError
from .geometry import Geometry, load_geometry, summary_repr, warn_outside
from .linkage import Linkage
from .march import march
from .metrics import METRICS, TOE_LINK, Pose, metric_columns, point_columns
from .solver import NewtonSolver, Solution
from .sweep import Sweep, Target, check_held, load_sweep

CHUNK = 10_000  # steps solved and written at a time by a streamed sweep


class Corner(Linkage, Assembly):
    """One suspension corner: geometry (as set), URDF, Pinocchio model, sweeps.

    >>> corner = Corner("examples/double_wishbone.yaml")  # a path, a dict or a Geometry
    >>> corner
    <Corner 'double_wishbone.yaml' 'example corner': double_wishbone, left, rack, 2 inputs>
    >>> pose = corner.solve_pose([Target("wheel_center", "z", 25.0),
    ...                           Target("trackrod_inboard", "y", 0.0)])
    >>> pose.metrics["camber"]  # deg
    >>> results = corner.run_sweep("examples/bump_steer.yaml")
    >>> results.to_pandas()  # a DataFrame, a row per step; results.plot("report.png")

    ``corner.geometry`` is the as-set Geometry, in m (``geometry.hardpoints_mm`` in
    mm); ``corner.design_positions`` every point at design, in m. As an Assembly
    (assembly.py) it is one corner, labelled ``""``: its columns and points unsuffixed.
    """

    labels = ("",)
    streams = True  # run_sweep_chunks
    poses_at_steps = True  # urdf --at SWEEP:STEP

    @property
    def corners(self) -> dict[str, Geometry]:
        return {"": self.geometry}

    @property
    def source(self) -> str:
        return self.geometry.source

    @property
    def name(self) -> str:
        return self.geometry.name

    def __repr__(self) -> str:
        def parts():
            g = self.geometry
            return (g.source, g.name, *g.choices(), f"{self.mobility} inputs")

        return summary_repr(self, parts)

    def __init__(
        self,
        geometry: Geometry | str | dict,
        apply_setup: bool = True,
        warn: bool = True,
        visuals: bool = True,
    ):
        """``warn``: a PlausibilityWarning for each implausible design metric (a study's
        variants skip it: their design's was shown); ``visuals``: the URDF's shapes."""
        if not isinstance(geometry, Geometry):
            geometry = load_geometry(geometry)
        if apply_setup and geometry.needs_setup:  # shims and adjusters: the as-set
            from . import as_set  # state is the design state

            geometry = as_set.apply_setup(geometry)
        super().__init__(geometry, visuals)
        if warn:
            self._warn_implausible()

    def _warn_implausible(self) -> None:
        """A PlausibilityWarning for each design metric outside its plausible range."""
        design = {k: v[None] for k, v in self.design_positions.items()}
        columns = metric_columns(self.geometry, design, design)
        for m in METRICS:
            if m.plausible is None or m.name not in columns:
                continue
            value = columns[m.name][0][0]
            warn_outside(f"{self.geometry.source}: design {m.name}", value, *m.plausible, m.unit)

    def drive_order(self, targets: list[Target]) -> list[int] | None:
        """Which target is which driver, when the targets are exactly the drivers
        (wheel-centre z, then the rack along y, in any order); None otherwise."""
        if TOE_LINK in self.drivers:  # a driver no sweep target is: motion() solves it
            return None
        targets = self.held_targets(targets)
        wanted = [Target("wheel_center", "z").key]
        if self.geometry.steering == "rack":
            wanted.append(Target(self.geometry.steering_points[0], "y").key)
        have = [t.key for t in targets]
        if len(have) != len(wanted) or set(have) != set(wanted):
            return None
        return [have.index(w) for w in wanted]

    def solver_for(self, targets: list[Target], source: str = "<targets>") -> NewtonSolver:
        """Check targets against this mechanism and build the Newton solver (the rack
        held at design where a rack corner's sweep gives no rack target)."""
        targets = self.held_targets(targets)
        self._check_targets(targets, source)
        rows = [PointTarget(self.points[t.point], t.unit_direction) for t in targets]
        solver = NewtonSolver(self.kin, self.closures, rows, self.branches)
        # The targets must fix the pose: with the closures, a square Jacobian of full rank.
        solver.evaluate(self.q_design)
        if np.linalg.cond(solver.jacobian) > 1e10:
            held = ", ".join(f"{t.point} along {_along(t)}" for t in targets)
            raise InputError(
                source,
                "targets",
                f"{held} do not fix the pose of this mechanism at its design state (the "
                "targets' rows are dependent: a target along a direction its point cannot "
                "move in, e.g. the rack along x, or a design sitting at a lock-up)",
            )
        return solver

    def target_values(self, targets: list[Target]) -> np.ndarray:
        """Absolute target values (m), one row per step, one column per held target
        (``held_targets``)."""
        cols = []
        for t in self.held_targets(targets):
            values = np.asarray(t.values, dtype=float) * 1e-3
            if t.mode == "relative":
                values = values + self.design_positions[t.point] @ t.unit_direction
            cols.append(values)
        return np.column_stack(cols)

    def solve_pose(self, targets: list[Target], q_start: np.ndarray | None = None) -> Pose:
        """Solve one pose: each target holds a single value (mm)."""
        solver = self.solver_for(targets)
        values = self.target_values(targets)
        if values.shape[0] != 1:
            raise InputError("<targets>", "values", "solve_pose takes one value per target")
        q0 = self.q_design if q_start is None else q_start
        start = self.target_values([t.at_design() for t in targets])[0]
        solution = solver.solve(q0, start, values[0])
        return self._pose(solution)

    def run_sweep(self, sweep: Sweep | str | dict, progress=None) -> Results:
        """Solve every step of a sweep and compute every column (metrics, derivatives).

        >>> results = corner.run_sweep("examples/bump_steer.yaml")  # a path, dict or Sweep
        >>> results["camber"]  # deg, a numpy array, one value per step
        >>> results.to_pandas()  # the same columns as a DataFrame, as the CSV has them
        >>> results.to_csv("results.csv"); results.plot("report.png")

        ``progress(i, n)``: called after each step."""
        if not isinstance(sweep, Sweep):
            sweep = load_sweep(sweep)
        return self.solve_sweep(sweep, progress)[1]

    def solve_sweep(self, sweep: Sweep, progress=None) -> tuple[list[Solution], Results]:
        """Every step solved: the solutions and their results (run_sweep's)."""
        tangents = []
        solutions = self.solve_steps(sweep, progress, tangents=tangents)
        return solutions, Results.from_solutions(self, solutions, sweep, tangents or None)

    def check_sweep(self, sweep: Sweep) -> None:
        """The sweep's target errors, before any work (solver_for's)."""
        self.solver_for(sweep.targets, sweep.source)

    def run_sweep_chunks(self, sweep: Sweep | str | dict, rows: int = CHUNK, progress=None):
        """The sweep's Results ``rows`` steps at a time (each chunk's ``step_index``
        counts from the sweep's first step): the same values as run_sweep, in memory
        that does not grow with the sweep's length — for writing as it goes.

        Each chunk starts from the last converged pose before it (the design state for
        the first), as the sweep's march does.

        >>> for part in corner.run_sweep_chunks("examples/bump_steer.yaml", rows=20):
        ...     part.to_pandas()  # a DataFrame of these 20 rows (the last may be shorter)
        """
        if not isinstance(sweep, Sweep):
            sweep = load_sweep(sweep)
        self.solver_for(sweep.targets, sweep.source)  # the targets' errors before any work
        q = None
        for start in range(0, sweep.steps, rows):
            part = Sweep(
                [replace(t, values=t.values[start : start + rows]) for t in sweep.targets],
                sweep.source,
                sweep.sha256,
                sweep.data,
            )
            done = None
            if progress is not None:
                done = lambda i, n, start=start: progress(start + i, sweep.steps)  # noqa: E731
            tangents = []
            solutions = self.solve_steps(part, done, q_start=q, tangents=tangents)
            results = Results.from_solutions(self, solutions, part, tangents or None)
            results.columns["step_index"] = results.columns["step_index"] + start
            converged = [s for s in solutions if s.converged]
            if converged:
                q = converged[-1].q
            del solutions, tangents, converged
            yield results
            del results  # before the next chunk is solved: one chunk held at a time

    def solve_steps(
        self,
        sweep: Sweep,
        progress=None,
        q_start: np.ndarray | None = None,
        step_times=None,
        tangents: list | None = None,
    ) -> list[Solution]:
        """Solve the sweep's steps in order, each from a prediction off the last ones.

        ``q_start``: a solved configuration of the sweep's first step's predecessor
        (default: the design state); ``step_times``: a list that receives each
        step's solve time in seconds (for benchmarks); ``tangents``: a list that
        receives the exact drivers' tangent of each step, when the sweep's
        targets are the drivers (wheel-centre z, rack) — it stays empty otherwise.
        """
        check_held(sweep)
        solver = self.solver_for(sweep.targets, sweep.source)
        order = self.drive_order(sweep.targets) if tangents is not None else None
        solver.keep_jacobian = order is not None
        values = self.target_values(sweep.targets)
        q = self.q_design if q_start is None else q_start
        previous = self.target_values([t.at_design() for t in sweep.targets])[0]
        if q_start is not None:
            previous = self._values_at(solver, q_start)
        return march(
            solver,
            values,
            q,
            previous,
            progress=progress,
            step_times=step_times,
            tangents=tangents if order is not None else None,
            keep=None if order is None else lambda tangent: tangent[..., order],
            bulk=True,
        )

    def _values_at(self, solver: NewtonSolver, q: np.ndarray) -> np.ndarray:
        """The target values that q satisfies."""
        self.kin.update_positions(q)
        return np.array([t.point.position(self.kin) @ t.direction for t in solver.targets])

    def _pose(self, solution: Solution) -> Pose:
        points = self.motion([solution.q])
        design = {k: v[None] for k, v in self.design_positions.items()}
        columns = metric_columns(self.geometry, points, design, self.spring_sense)
        return Pose(
            q=solution.q,
            converged=solution.converged,
            iterations=solution.iterations,
            max_residual=solution.max_residual * 1e3,
            metrics={k: float(v[0]) for k, (v, _) in columns.items() if "deriv_" not in k},
            points={k: p.val[0] * 1e3 for k, p in points.items()},
            derivatives={k: float(v[0]) for k, (v, _) in columns.items() if "deriv_" in k},
        )

    def _check_targets(self, targets: list[Target], source: str) -> None:
        known = ", ".join(self.point_names)
        for i, t in enumerate(targets):
            if t.quantity is not None:
                raise InputError(
                    source,
                    f"targets[{i}].quantity",
                    f"{t.quantity} is an axle's quantity: this geometry is one corner",
                )
            if t.side is not None:
                raise InputError(
                    source,
                    f"targets[{i}].side",
                    "a side is for an axle's targets: this geometry is one corner",
                )
            key = f"targets[{i}].point"
            if t.point not in self.points:
                raise InputError(source, key, f"unknown point {t.point!r} (points: {known})")
            if self.body_of(t.point) == "chassis":
                raise InputError(
                    source, key, f"{t.point} is fixed to the chassis: a target on it cannot move"
                )
        moving_rack = [i for i, t in enumerate(targets) if self.body_of(t.point) == "rack"]
        if len(targets) != self.mobility:
            if self.actuators:
                what = (
                    "bump and steer: a wheel target and one trackrod_inboard target along y; "
                    "a wheel target alone holds the rack at design"
                )
            elif self.geometry.steering_points:
                what = "bump: one wheel target (the fixed toe link leaves no steer)"
            else:
                what = "bump: one wheel target (no steering)"
            raise InputError(
                source,
                "targets",
                f"{len(targets)} target(s) given, this corner needs exactly "
                f"{self.mobility} ({what})",
            )
        if self.actuators and len(moving_rack) != 1:
            raise InputError(
                source,
                "targets",
                "a rack-steered corner needs exactly one target on the rack "
                f"(trackrod_inboard along y), got {len(moving_rack)}",
            )

    # Assembly surface for loads, viz and drawing
    @property
    def spring_senses(self) -> dict[str, float]:
        return {"": self.spring_sense}

    def sweep_results(self, sweep: Sweep, solutions: list[Solution]) -> Results:
        return Results.from_solutions(self, solutions, sweep)

    def with_corners(self, corners: dict[str, Geometry]) -> Corner:
        return Corner(corners[""], warn=False)

    # Assembly surface for study
    def sweep_and_design(self, sweep: Sweep, only=None) -> tuple[Results, dict]:
        # one pass of the columns over the design state and the steps: the steps solved
        # as run_sweep solves them, the design row column-wise the same
        tangents = []
        solutions = self.solve_steps(sweep, tangents=tangents)
        design = Solution(self.q_design.copy(), True, 0, 0.0)
        both = Results.from_solutions(
            self, [design, *solutions], sweep, [None, *tangents] if tangents else None, only
        )
        columns = {k: v[1:] for k, v in both.columns.items()}
        columns["step_index"] = np.arange(len(solutions))
        meta = dict(both.meta, q=both.meta["q"][1:], why=both.meta["why"][1:])
        static = {k: v[:1] for k, v in both.columns.items()}
        return Results(columns, both.units, meta), static

    # Assembly surface for setup and sensitivity
    @classmethod
    def as_drawn(cls, path, label: str | None = None) -> Corner:
        if label is not None:  # before the file is read: named as typed
            raise cls._no_sides(path)
        drawn = cls.__new__(cls)  # no model built: the setup surface alone
        drawn.geometry = load_geometry(path)
        return drawn

    def setup_labels(self, label: str | None = None) -> tuple[str, ...]:
        if label is not None:
            raise self._no_sides(self.source)
        return self.labels

    def corner_linkage(self, label: str) -> Corner:
        return self  # its one corner's Linkage: itself

    @staticmethod
    def _no_sides(source) -> InputError:
        return InputError("--side", "", f"{source} is a corner (--side sets one side of an axle)")

    def setup_data(self, geometries: dict[str, Geometry]) -> dict:
        from .as_set import geometry_data

        return geometry_data(geometries[""])

    # Assembly surface for validate
    noun = "corner"

    def held_sweep(self, sweep: Sweep) -> Sweep:
        return replace(sweep, targets=self.held_targets(sweep.targets))

    def motion_points(self, by_label: dict) -> dict:
        return {name: p[""] for name, p in by_label.items()}


class Results:
    """Columns of a solved sweep, in output units (mm, deg); see docs/results.md.

    ``results["camber"]``: a column (numpy array, one value per step, NaN where a
    step failed or a metric is undefined); ``results.keys()``: the columns' names,
    in the CSV's order; ``results.units``: name → unit; ``results.to_pandas()``: a
    DataFrame; ``results.to_csv(path)``; ``results.plot(path)``: the standard
    report. ``pd.DataFrame(results.columns)`` is the DataFrame without the units.
    """

    def __init__(self, columns: dict[str, np.ndarray], units: dict[str, str], meta: dict):
        self.columns = columns
        self.units = units
        self.meta = meta

    def __repr__(self) -> str:
        """``<Results 'sweep.yaml' on 'geometry.yaml': 41 steps, 41 converged, 86 columns>``;
        never raises (an empty or failed sweep's too)."""
        kind = type(self).__name__
        try:
            steps = len(next(iter(self.columns.values()), ()))
            converged = self.columns.get("solver_converged")
            ok = steps if converged is None else int(np.count_nonzero(converged))
            parts = [f"{steps} steps", f"{ok} converged"]
            if ok < steps:
                failed = [str(int(i)) for i in self.columns["step_index"][self.failed_steps]]
                more = ", ..." if len(failed) > 5 else ""
                parts[-1] += f" (failed: {', '.join(failed[:5])}{more})"
            parts.append(f"{len(self.columns)} columns")
            where = ""
            names = [_file_name(self.meta.get(w, ("",))[0]) for w in ("sweep", "geometry")]
            if names[0]:
                where += f" {names[0]!r}"
            if names[1]:
                where += f" on {names[1]!r}"
            return f"<{kind}{where}: {', '.join(parts)}>"
        except Exception:  # a repr never raises
            return f"<{kind}>"

    @classmethod
    def from_solutions(
        cls, corner: Corner, solutions: list[Solution], sweep: Sweep, tangents=None, only=None
    ) -> Results:
        """``only``: the set of columns wanted (a study's summary), else every column."""
        columns, units = cls.solver_columns(solutions)
        # A step that did not converge has no trustworthy pose: its cells stay empty.
        points = corner.motion([s.q if s.converged else None for s in solutions], tangents)
        design = {k: v[None] for k, v in corner.design_positions.items()}
        metrics = metric_columns(corner.geometry, points, design, corner.spring_sense, only)
        for name, (values, column_unit) in metrics.items():
            columns[name], units[name] = values, column_unit
        qs = [s.q if s.converged else None for s in solutions]
        if corner.geometry.rated_spring:
            from .rates import RATE_COLUMNS, rate_columns  # a rated spring's columns

            if only is None or RATE_COLUMNS & set(only):
                for name, (values, column_unit) in rate_columns(corner, qs).items():
                    columns[name], units[name] = values, column_unit
        positions = {name: p.val for name, p in points.items()}
        for name, (values, column_unit) in point_columns(corner.point_names, positions).items():
            if only is None or name in only:
                columns[name], units[name] = values, column_unit
        geometry = (corner.geometry.source, corner.geometry.sha256)
        meta = cls.solver_meta(solutions, geometry, sweep, corner)
        meta["notes"] = corner.sweep_notes(sweep.targets)
        return cls(columns, units, meta)

    @staticmethod
    def solver_columns(solutions: list[Solution]) -> tuple[dict, dict]:
        """The first columns of every sweep's results: step index and the solver's flags."""
        columns = {
            "step_index": np.arange(len(solutions)),
            "solver_converged": np.array([s.converged for s in solutions]),
            "solver_max_residual": np.array([s.max_residual for s in solutions]) * 1e3,
            "solver_iterations": np.array([s.iterations for s in solutions]),
        }
        return columns, dict.fromkeys(columns, "") | {"solver_max_residual": "mm"}

    @staticmethod
    def solver_meta(solutions: list[Solution], geometry: tuple, sweep: Sweep, model=None) -> dict:
        """What the CSV's comments and the failure report need: sources, q, reasons, and
        the model's links near dead centre at design (a cause of steps out of reach)."""
        return {
            "geometry": geometry,
            "sweep": (sweep.source, sweep.sha256),
            "q": np.array([s.q for s in solutions]),
            "why": [s.why for s in solutions],  # '' where converged
            "dead_centres": list(getattr(model, "dead_centres", ())),
        }

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.columns[name]
        except KeyError:
            raise KeyError(f"no column {name!r} (results.keys() lists them)") from None

    def __contains__(self, name: object) -> bool:
        return name in self.columns

    def keys(self):
        """The columns' names, in the CSV's order (``dict(results)`` is the columns)."""
        return self.columns.keys()

    def __iter__(self):
        # Not rows nor names: `pd.DataFrame(results)` or `list(results)` says what to use.
        raise TypeError(
            f"{type(self).__name__} is a table of columns: use results.to_pandas() for a "
            "DataFrame, results.keys() for the columns' names, results[name] for one"
        )

    def __len__(self) -> int:
        """The number of steps (rows)."""
        return len(self.columns["step_index"])

    @property
    def failed_steps(self) -> np.ndarray:
        return np.flatnonzero(~self.columns["solver_converged"])

    def to_pandas(self):
        """The columns as a pandas DataFrame, one row per step, in the CSV's order and
        with its values; the units (mm, deg, ...) in ``.attrs["units"]``; an undefined
        value (a blank CSV cell) is NaN.

        >>> frame = results.to_pandas()
        >>> frame[["wheel_travel", "camber"]], frame.attrs["units"]["camber"]  # 'deg'
        """
        from .io.tables import results_frame

        return results_frame(self)

    def to_csv(self, path) -> None:
        """The CSV that ``pin-susp sweep -o`` writes (docs/results.md), whole or not at all."""
        from .io.tables import write_csv

        write_csv(self, path)

    def plot(self, path, label: str | None = None) -> None:
        """Draw the standard report — what ``pin-susp sweep --plot`` and ``pin-susp plot``
        draw: a panel per metric against wheel travel (or the rack, or an axle's roll or
        heave); of member_forces' table, the force report — into an image file, its
        format from its ending (.png, .pdf, .svg).

        ``label``: the name in the title (default: the sweep file's). Drawn from the
        CSV's text (as the CLI draws it); a PinSuspError when no step converged.

        >>> corner.run_sweep("examples/bump_steer.yaml").plot("report.png")
        """
        from .plots import plot_results  # drawn from the table alone: plots.py knows no model

        plot_results(self, path, label)


def _file_name(source) -> str:
    """A source's file name ('' for one that is no file: '<dict>', '<targets>')."""
    if not source or str(source).startswith("<"):
        return ""
    from pathlib import Path

    return Path(str(source)).name


def _along(t: Target) -> str:
    if isinstance(t.direction, str):
        return t.direction
    return "[" + ", ".join(f"{x:.3g}" for x in t.unit_direction) + "]"
