"""A corner ready to solve: its linkage with the setup applied, sweeps and results.

``Corner(geometry)`` applies the camber shim and the length adjusters first
(``as_set.apply_setup``): the as-set state is the design state of every sweep.
The model itself — URDF, Pinocchio model, points, closures — is the
:class:`~pin_susp.solve.linkage.Linkage`.
"""

from __future__ import annotations

import numpy as np

from ..columns.metrics import METRICS, Pose, metric_columns
from ..errors import InputError
from ..model.geometry import Geometry, load_geometry, summary_repr, warn_outside
from ..model.steering import track_of
from ..model.sweep import Sweep, Target
from ..solve.linkage import Linkage
from ..solve.solver import Solution
from .assembly import CHUNK, Assembly  # noqa: F401 (CHUNK: as it was)


class Corner(Assembly, Linkage):
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
    refuses = ("fixed points", "one rack target")

    @property
    def results_class(self) -> type:
        return Results

    @property
    def needs(self) -> str:
        """What its sweep's targets must be, as its count's error says."""
        if self.actuators:
            return (
                "bump and steer: a wheel target and one trackrod_inboard target along y; "
                "a wheel target alone holds the rack at design"
            )
        if self.geometry.steering_points:
            return "bump: one wheel target (the fixed toe link leaves no steer)"
        return "bump: one wheel target (no steering)"

    def undetermined(self, targets: list[Target]) -> str:
        """The error of targets that do not fix its pose at design."""
        held = ", ".join(f"{t.point} along {_along(t)}" for t in targets)
        return (
            f"{held} do not fix the pose of this mechanism at its design state (the "
            "targets' rows are dependent: a target along a direction its point cannot "
            "move in, e.g. the rack along x, or a design sitting at a lock-up)"
        )

    @property
    def corners(self) -> dict[str, Geometry]:
        return {"": self.geometry}

    @property
    def source(self) -> str:
        return self.geometry.source

    @property
    def name(self) -> str:
        return self.geometry.name

    @property
    def sha256(self) -> str:
        return self.geometry.sha256

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
        """``warn``: a PlausibilityWarning for each implausible design metric, and its
        ``config.track`` checked against its mirrored partner (a study's variants skip
        both: their design's were); ``visuals``: the URDF's shapes."""
        if not isinstance(geometry, Geometry):
            geometry = load_geometry(geometry)
        if apply_setup and geometry.needs_setup:  # shims and adjusters: the as-set
            from ..solve import as_set  # state is the design state

            geometry = as_set.apply_setup(geometry)
        super().__init__(geometry, visuals)
        self.steering  # noqa: B018 (its c-factor checked as its file is read)
        self.mirrored_track = track_of(geometry, warn)  # config.track: its mirrored partner
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

    def _pose(self, solution: Solution) -> Pose:
        points = self.motion([solution.q])
        design = {k: v[None] for k, v in self.design_positions.items()}
        columns = metric_columns(self.geometry, points, design, self.spring_sense)
        return Pose(
            q=solution.q,
            converged=solution.converged,
            iterations=solution.iterations,
            max_residual=solution.max_residual * 1e3,
            metrics={  # limit_exceeded is text: the limits a pose is past
                k: v[0] if isinstance(v[0], str) else float(v[0])
                for k, (v, _) in columns.items()
                if "deriv_" not in k
            },
            points={k: p.val[0] * 1e3 for k, p in points.items()},
            derivatives={k: float(v[0]) for k, (v, _) in columns.items() if "deriv_" in k},
        )

    def own_columns(self, sweep: Sweep, qs: list, plain: dict, columns: dict, tangents=None):
        """The steering wheel's angle and ratio (Assembly's), then with config.wheelbase and
        config.track its steering with its mirrored partner (``partner_columns``,
        steering_surface.py)."""
        out = super().own_columns(sweep, qs, plain, columns, tangents)
        return out | self.partner_columns(qs, plain, columns)

    # Assembly surface for loads, viz and drawing
    @property
    def spring_senses(self) -> dict[str, float]:
        return {"": self.spring_sense}

    def with_corners(self, corners: dict[str, Geometry]) -> Corner:
        return Corner(corners[""], warn=False)

    # Assembly surface for study
    solves_stacked = True

    def keep_solver(self, targets: list, solver) -> None:
        """The solver built for ``targets`` (this very list, a study's sweep's) handed back
        by solver_for instead of building it again (a study's variant, solved together
        first: study/batch.py)."""
        self._kept_solver = (targets, solver)

    def solver_for(self, targets: list, source: str = "<targets>"):
        kept = self.__dict__.get("_kept_solver")
        if kept is not None and kept[0] is targets:
            return kept[1]
        return super().solver_for(targets, source)

    def sweep_and_design(self, sweep: Sweep, only=None, guess=None) -> tuple[Results, dict]:
        # one pass of the columns over the design state and the steps: the steps solved
        # as run_sweep solves them, the design row column-wise the same
        tangents = []
        solutions = self.solve_steps(sweep, tangents=tangents, guess=guess)
        design = Solution(self.q_design.copy(), True, 0, 0.0)
        if tangents:  # the design state's too (else every step's would be worked out again)
            self._drive.evaluate(self.q_design)
            tangents = [self._drive.tangent(self.drive_rhs), *tangents]
        both = Results.from_solutions(self, [design, *solutions], sweep, tangents or None, only)
        return self._design_and_steps(both)

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
        from ..solve.as_set import geometry_data

        return geometry_data(geometries[""])

    # Assembly surface for validate
    noun = "corner"

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
        """``only``: the set of columns wanted (a study's summary), else every column
        (``corner.sweep_results``, assembly.py)."""
        return corner.sweep_results(sweep, solutions, tangents, only)

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

    @property
    def solved_configurations(self) -> list:
        """Each step's configuration q, None where the step did not converge (no
        trustworthy pose: what the replays, the clearance and the envelope skip)."""
        converged = self.columns["solver_converged"]
        return [q if ok else None for q, ok in zip(self.meta["q"], converged, strict=True)]

    def to_pandas(self):
        """The columns as a pandas DataFrame, one row per step, in the CSV's order and
        with its values; the units (mm, deg, ...) in ``.attrs["units"]``; an undefined
        value (a blank CSV cell) is NaN.

        >>> frame = results.to_pandas()
        >>> frame[["wheel_travel", "camber"]], frame.attrs["units"]["camber"]  # 'deg'
        """
        from ..io.tables import results_frame

        return results_frame(self)

    def to_csv(self, path) -> None:
        """The CSV that ``pin-susp sweep -o`` writes (docs/results.md), whole or not at all."""
        from ..io.tables import write_csv

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
        from ..plots import plot_results  # drawn from the table alone: plots.py knows no model

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
