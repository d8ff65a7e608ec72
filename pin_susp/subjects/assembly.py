"""What every subject answers alike, a corner or an axle (README, How it works).

A subject is labelled corners and the elements they share (an axle's rack, anti-roll
bar, heave link). ``labels`` names its corners — a corner's one, ``""``; an axle's,
``"left"`` and ``"right"`` — and ``corners`` maps each label to its as-set Geometry.
A column of one corner takes its label as a suffix (``camber_left``), a point as a
prefix (``left_wheel_center``); a corner's empty label adds neither. Code that takes
a subject asks these, never which kind it holds (tests/test_one_subject.py counts the
places that still do).
"""

from __future__ import annotations

import operator as eq
from dataclasses import replace

import numpy as np
import pinocchio as pin

from ..columns.metrics import metric_columns, point_columns
from ..constraints import WORLD, JointTarget, PointTarget
from ..errors import InputError
from ..model.sweep import Sweep, Target, check_held, load_sweep
from ..solve.bulk import Frames, tree_of
from ..solve.linkage import Composed, Linkage
from ..solve.march import march
from ..solve.solver import NewtonSolver, Solution
from .analyses_surface import AnalysesSurface
from .elements import rack
from .steering_surface import SteeringSurface

CHUNK = 10_000  # steps solved and written at a time by a streamed sweep
Z = np.array([0.0, 0.0, 1.0])

VEHICLE_QUANTITIES = ("pitch", "road_z", "steering_wheel", "rack")  # a body on the road's alone


class Assembly(SteeringSurface, Composed, AnalysesSurface):
    """The surface :class:`~pin_susp.subjects.corner.Corner` and
    :class:`~pin_susp.subjects.axle.AxleModel` share.

    ``labels``: the corners' labels, in the order their columns are written;
    ``corners``: label → the as-set Geometry; ``source``: the file it was read from;
    ``name``: its name in the file; ``anti_roll_rigid``: whether an anti-roll bar locks
    the corners together (then each wheel's own height is no driver); ``streams``:
    whether a long sweep can be solved and written a chunk at a time
    (``run_sweep_chunks``); ``poses_at_steps``: whether ``pin-susp urdf --at`` can write
    the joint values of one of its sweep's steps; ``summary_columns``: the columns a
    sweep's printed summary shows, in order (None: every metric column);
    ``spring_senses``: label → the sense of its corner's spring
    (``Linkage.spring_sense``); ``shared_springs``: the elastic elements its corners
    share, each (the joints whose turn twists it, its stiffness in N·m/deg or None) — an
    axle's anti-roll bar, unless rigid; ``markers``: what the 3D view marks from its
    results' columns (an axle's ``roll_centre``); ``static_columns``: the columns of its
    corners together a setup sheet adds to each row (an axle's track and roll centre);
    ``elements``: the elements its corners share (pin_susp/elements/: an axle's
    anti-roll bar and heave link; none for a corner), the point-based formulation's too
    (pointwise.ELEMENTS); ``noun``: what a message calls it (``corner``, ``axle``).

    Both are a :class:`~pin_susp.solve.linkage.Composed` too: ``tree``, ``urdf``,
    ``output_points`` (every point written, each prefixed by its label),
    ``design_positions``, ``corner_points`` (label → its corner's point names,
    unprefixed), ``driver_columns`` (label → the columns of its drivers: its hub z, the
    rack, its toe link).

    One model (linkage.Composed) and one sweep path for every subject: its targets
    read per label (a point target names its corner by ``side``, none for a corner's
    ``""``; a quantity, ``heave`` or ``roll``, is a row of the shared element that has
    it, ``shared``), the rack held at design where a sweep gives every target but its
    (``held_targets``), the counts and the determinacy checked (``solver_for``), the
    steps marched or solved at once (``solve_steps``, march.py), streamed a chunk at a
    time (``run_sweep_chunks``). What a subject says of its targets is its constructor's
    (``noun``, ``needs``, ``undetermined``); ``refuses``: what its targets' reading has
    always refused besides (``"repeats"``: a target given twice, the rack on both
    sides; ``"fixed points"``: a target on the chassis; ``"one rack target"``: a rack
    corner's sweep without its one rack target); ``checks_counts_first``: whether
    ``check_sweep`` checks the counts and the determinacy too (else they are checked
    when it is solved, as an axle's always were); ``tangents_by_drivers``: every
    step's tangent kept per driver, T·(J_drive·T)⁻¹, whatever the targets (an axle's:
    the numbers it always had, to the last bit; a corner keeps them only when its
    targets are its drivers); ``tangents_by_targets``: the tangent per target (dq per
    unit of each held target), then each closure driver's (a toe link's length, the
    targets held: ``closure_drivers``), kept where the sweep is solved at once
    (bulk.newton_all has them at each solution: a vehicle's rates along its body and
    its drivers' tangents, Vehicle.measured_at), None per step otherwise.
    """

    labels: tuple[str, ...]
    corners: dict
    source: str
    name: str
    anti_roll_rigid: bool = False
    summary_columns: tuple[str, ...] | None = None
    streams: bool = False
    poses_at_steps: bool = False
    spring_senses: dict
    shared_springs: tuple = ()
    markers: tuple[str, ...] = ()
    shared: tuple = ()
    refuses: tuple[str, ...] = ()
    checks_counts_first: bool = True
    tangents_by_drivers: bool = False
    tangents_by_targets: bool = False
    results_class: type = None  # the class of its sweep's Results
    # setup and sensitivity: the subject's own static columns of its corners set
    # together, (column, heading) in mm (an axle's track and roll centre; a corner: none)
    static_columns: tuple[tuple[str, str], ...] = ()
    elements: tuple = ()
    noun: str = "assembly"
    commands: tuple[str, ...] | None = None  # the commands that take it (None: every one)
    reports: bool = True  # whether ``pin-susp sweep --plot`` draws its report
    on_road: bool = False  # a body on the road: ``pin-susp attitude`` takes it (a vehicle)

    @property
    def article(self) -> str:
        """ "an" before its noun (an axle), else "a"."""
        return "an" if self.noun[0] in "aeiou" else "a"

    tree: object
    urdf: str
    output_points: list[str]
    design_positions: dict
    corner_points: dict
    driver_columns: dict

    @staticmethod
    def suffix(label: str) -> str:
        """A column's suffix for a corner's label: ``"_left"``; none for ``""``."""
        return f"_{label}" if label else ""

    @staticmethod
    def prefix(label: str) -> str:
        """A point's prefix for a corner's label: ``"left_"``; none for ``""``."""
        return f"{label}_" if label else ""

    @property
    def blocks(self) -> tuple[str, ...]:
        """The blocks an input given per corner is in (a load case's ``left:``,
        ``right:``): one per labelled corner; none for a corner's one, unlabelled (its
        inputs at the top)."""
        return tuple(label for label in self.labels if label)

    def held_sweep(self, sweep: Sweep) -> Sweep:
        """The sweep as its steps hold it (``held_targets``): its targets, and the rack's
        at design where it gives every other (``sweep_notes`` says so); the sweep
        itself where nothing is held."""
        targets = self.held_targets(sweep.targets)  # a steering wheel's: the rack's
        same = len(targets) == len(sweep.targets) and all(map(eq.is_, targets, sweep.targets))
        return sweep if same else replace(sweep, targets=targets)

    def metric_columns_of(self, points: dict) -> dict:
        """Every metric column (name → (values, unit)) from its points with their rates
        along the drivers (name → {label: jet.Dual}, as ``label_motion`` gives them, or
        an engine's): ``metric_columns``, and the steering's from them (steering_surface.py)."""
        return self.with_steering(self.metric_columns(points))

    def motion_points(self, by_label: dict) -> dict:
        """Points with a Dual per label (name → {label: Dual}, ``label_motion``'s) in the
        form its ``motion`` gives them: as they are (a corner's: its one Dual each)."""
        return by_label

    def with_corners(self, corners: dict):
        """The same subject on other corners' Geometries, by label (its shared elements
        kept; each corner set up as its Geometry says): the drawings' and the 3D view's
        ghost, as drawn, under the as-set one."""
        raise NotImplementedError

    # ------------------------------------------------------------ targets

    @property
    def quantities(self) -> dict:
        """quantity → the shared element whose row it is (an axle's heave, roll)."""
        return {q: e for e in self.shared for q in e.quantities}

    def target_rows(self, targets: list, source: str = "<targets>") -> list:
        """The solver's rows for a sweep's targets (one value each, set later), each
        read by its corner's label or its quantity's element: an InputError naming the
        file and the target otherwise."""
        rows, seen = [], {}
        quantities = self.quantities
        for i, t in enumerate(targets):
            if "repeats" in self.refuses:
                if t.quantity is not None:
                    what = t.quantity
                elif t.point == rack.INBOARD:
                    what = "the rack"  # one freedom, whichever side names it
                else:
                    what = (t.side, t.point, tuple(np.round(t.unit_direction, 12)))
                if what in seen:
                    also = ""
                    if what == "the rack":
                        also = " (the rack is one freedom: target it on one side)"
                    raise InputError(
                        source, f"targets[{i}]", f"repeats targets[{seen[what]}]{also}"
                    )
                seen[what] = i
            if t.quantity is not None:
                if t.quantity not in quantities:
                    self.refuse_steering(t, i, source)  # steering_surface.py
                    owner = "a vehicle's" if t.quantity in VEHICLE_QUANTITIES else "an axle's"
                    takes = ", ".join(quantities) if quantities else "no quantity, only points"
                    raise InputError(
                        source,
                        f"targets[{i}].quantity",
                        f"{t.quantity} is {owner} quantity: this geometry is {self.article} "
                        f"{self.noun} (it takes {takes})",
                    )
                rows.append(quantities[t.quantity].row(self, i, t, source))
                continue
            label = t.side or ""
            if label not in self.labels:
                raise InputError(
                    source,
                    f"targets[{i}].side",
                    "missing: an axle's point targets name their corner (side: left|right)"
                    if t.side is None
                    else "a side is for an axle's targets: this geometry is one corner",
                )
            name, key = self.point_of(t), f"targets[{i}].point"
            if name not in self.points:
                known = ", ".join(self.corner_points[label])
                raise InputError(source, key, f"unknown point {t.point!r} (points: {known})")
            if "fixed points" in self.refuses and self.points[name].body == "chassis":
                raise InputError(
                    source, key, f"{t.point} is fixed to the chassis: a target on it cannot move"
                )
            rows.append(PointTarget(self.points[name], t.unit_direction))
        return rows

    def check_counts(self, targets: list, source: str) -> None:
        """As many targets as the subject's freedoms (``needs`` says which), and a rack
        corner's one on the rack (where it ``refuses`` otherwise)."""
        for element in self.shared:
            element.check_targets(targets, source)
        if len(targets) != self.mobility:
            raise InputError(
                source,
                "targets",
                f"{len(targets)} target(s) given, this {self.noun} needs exactly "
                f"{self.mobility} ({self.needs})",
            )
        if "one rack target" in self.refuses and self.model.existJointName(rack.JOINT):
            on_rack = [t for t in targets if self.points[self.point_of(t)].body == "rack"]
            if len(on_rack) != 1:
                raise InputError(
                    source,
                    "targets",
                    "a rack-steered corner needs exactly one target on the rack "
                    f"(trackrod_inboard along y, rack or steering_wheel), got {len(on_rack)}",
                )

    def solver_for(self, targets: list, source: str = "<targets>") -> NewtonSolver:
        """Check targets against this subject and build the Newton solver (the rack held
        at design where a rack-steered subject's sweep gives no rack target): the
        targets with the closures must fix the pose, a square Jacobian of full rank."""
        targets = self.held_targets(targets)
        rows = self.target_rows(targets, source)
        self.check_counts(targets, source)
        solver = NewtonSolver(self.kin, self.closures, rows, self.branches)
        solver.evaluate(self.q_design)
        if np.linalg.cond(solver.jacobian) > 1e10:
            raise InputError(source, "targets", self.undetermined(targets))
        return solver

    def target_values(self, targets: list) -> np.ndarray:
        """Each step's target values in SI, one row per step, one column per held target
        (``held_targets``): points m (absolute), a quantity as its element reads it."""
        cols, quantities = [], self.quantities
        for t in self.held_targets(targets):
            if t.quantity is not None:
                cols.append(quantities[t.quantity].value(t))
                continue
            values = np.asarray(t.values, dtype=float) * 1e-3
            if t.mode == "relative":
                values = values + self.design_positions[self.point_of(t)] @ t.unit_direction
            cols.append(values)
        return np.column_stack(cols)

    def values_at(self, solver: NewtonSolver, q: np.ndarray) -> np.ndarray:
        """The target values that q satisfies (each row's residual plus its value)."""
        self.kin.update_positions(q)
        residual = np.array([row.residual(self.kin)[0] for row in solver.targets])
        return residual + np.array([getattr(row, "value", 0.0) for row in solver.targets])

    def drive_order(self, targets: list) -> list[int] | None:
        """Which target is which driver, when the targets are exactly the drivers (each
        corner's wheel-centre z, then the rack along y, in any order); None otherwise
        (and where a driver is no sweep target: a toe link's length)."""
        if self.drive_rhs.shape[1] > len(self._drive.targets):  # a toe link drives
            return None
        targets = self.held_targets(targets)
        wanted = [Target("wheel_center", "z", side=label or None).key for label in self.labels]
        if self.model.existJointName(rack.JOINT):
            first = self.labels[0]
            inboard = self.corners[first].steering_points[0]
            wanted.append(Target(inboard, "y", side=first or None).key)
        have = [t.key for t in targets]
        if len(have) != len(wanted) or set(have) != set(wanted):
            return None
        return [have.index(w) for w in wanted]

    def check_sweep(self, sweep: Sweep) -> None:
        """The sweep's target errors, before any work (a sweep it cannot stream held in
        memory first; the counts too where ``checks_counts_first``)."""
        if not self.streams:
            check_held(sweep)
        if self.checks_counts_first:
            self.solver_for(sweep.targets, sweep.source)
        else:
            self.target_rows(self.held_targets(sweep.targets), sweep.source)

    # ------------------------------------------------------------ sweeps

    def run_sweep(self, sweep: Sweep | str | dict, progress=None):
        """Solve every step of a sweep (a path, a dict or a Sweep) and compute every
        column; ``progress(done, total)``: called after each step."""
        if not isinstance(sweep, Sweep):
            sweep = load_sweep(sweep)
        return self.solve_sweep(sweep, progress)[1]

    def solve_sweep(self, sweep: Sweep, progress=None) -> tuple[list[Solution], object]:
        """Every step solved: the solutions and their results (run_sweep's)."""
        tangents = []
        solutions = self.solve_steps(sweep, progress, tangents=tangents)
        return solutions, self.sweep_results(sweep, solutions, tangents or None)

    def solve_steps(
        self,
        sweep: Sweep,
        progress=None,
        q_start: np.ndarray | None = None,
        step_times=None,
        tangents: list | None = None,
        guess=None,
    ) -> list[Solution]:
        """Solve the sweep's steps in order, each from a prediction off the last ones
        (march.py: marched, a long sweep solved at once, or every step from ``guess``).
        ``q_start``: a solved configuration of the sweep's first step's predecessor
        (default: the design state); ``step_times``: a list that receives each step's
        solve time in seconds (benchmarks); ``tangents``: a list that receives each step's
        exact tangent per driver (dq per unit of each corner's hub z, the rack) where the
        solve has it (``tangents_by_drivers``, or the targets are the drivers) — it stays
        empty otherwise. Each solution keeps its own (``drive_tangent``). Where
        ``tangents_by_targets`` instead: each step's tangent per target, then each closure
        driver's, where the sweep is solved at once (None per step marched: its Jacobian
        there is the last iterate's), for its measured_at and own_columns alone."""
        check_held(sweep)
        solver = self.solver_for(sweep.targets, sweep.source)
        values = self.target_values(sweep.targets)
        q = self.q_design if q_start is None else q_start
        previous = self.values_at(solver, q)
        found = []
        by_targets = self.tangents_by_targets and tangents is not None
        if self.tangents_by_drivers:
            solver.keep_jacobian = True  # exact tangents: better predictions, the rates
            keep = self._per_driver()
            by_targets = False
        elif by_targets:  # every step's at once (newton_all's, at each solution), then
            # each closure driver's; a marched step's not (keep_jacobian off: the march
            # as it was, its Jacobian the last iterate's)
            keep = lambda tangent: tangent if tangent.ndim == 3 else None  # noqa: E731
        else:
            order = self.drive_order(sweep.targets) if tangents is not None else None
            solver.keep_jacobian = order is not None
            keep = None if order is None else lambda tangent: tangent[..., order]
            found = None if order is None else found
        extra = self.closure_drivers(solver) if by_targets else None
        solutions = march(
            solver,
            values,
            q,
            previous,
            progress=progress,
            step_times=step_times,
            tangents=found,
            keep=keep,
            bulk=True,
            extra=extra,
            guess=guess,
        )
        if found is None:
            return solutions
        if by_targets:
            tangents.extend(found)
            return solutions
        if self.tangents_by_drivers:
            found = self._through_drivers(solutions, found)
        for solution, tangent in zip(solutions, found, strict=True):
            solution.drive_tangent = tangent
        if tangents is not None:
            tangents.extend(found)
        return solutions

    def _drive_frames(self) -> tuple[list, int | None]:
        wheels = [f"{self.prefix(label)}wheel_center" for label in self.labels]
        frames = [self.points[name].frame_id for name in wheels]
        joint = self.model.getJointId(rack.JOINT) if self.model.existJointName(rack.JOINT) else None
        return frames, None if joint is None else self.model.joints[joint].idx_v

    def _per_driver(self):
        """The march's ``keep``: the drivers' rows times the tangent at the solution,
        J_drive·T (each wheel centre's z and the rack; the inverse is taken for all steps
        at once in _through_drivers). A rigid bar has fewer freedoms than drivers: its
        per-side rates stay blank. Every step's tangent at once (the sweep solved at
        once): J_drive·T left to _through_drivers."""
        frames, rack_v = self._drive_frames()
        drivers = len(frames) + (rack_v is not None)
        model, data = self.model, self.kin.data

        def per_driver(tangent: np.ndarray) -> tuple | list | None:
            if tangent.shape[-1] != drivers:
                return None if tangent.ndim == 2 else [None] * len(tangent)
            if tangent.ndim == 3:
                return [(t, None) for t in tangent]
            rows = [pin.getFrameJacobian(model, data, f, WORLD)[2] @ tangent for f in frames]
            if rack_v is not None:
                rows.append(tangent[rack_v])
            return tangent, np.array(rows)

        return per_driver

    def _through_drivers(self, solutions: list, found: list) -> list:
        """dq per driver from dq per target, T·(J_drive·T)⁻¹, every step's in one call
        (J_drive·T of the steps solved at once evaluated here, on the model's tree)."""
        frames, rack_v = self._drive_frames()
        at_once = [i for i, f in enumerate(found) if f is not None and f[1] is None]
        kept = [i for i, f in enumerate(found) if f is not None]
        if not kept:
            return found
        if at_once:  # each wheel centre's z row in the columns that move it, times T
            tree = tree_of(self.kin)
            Q = np.array([solutions[i].q for i in at_once])
            many = Frames(tree, frames)
            R, o = tree.placements(Q)
            Jc, _ = many.compact(many.positions(R, o), o, tree.axes(R))
            T = np.array([found[i][0] for i in at_once])
            rows = [
                np.einsum("sn,nsk->nk", Jf[:, :, 2], T[:, cols])
                for Jf, cols in zip(Jc, many.cols, strict=True)
            ]
            if rack_v is not None:
                rows.append(T[:, rack_v])
            ready = np.stack(rows, axis=1)
        if len(at_once) == len(kept):  # every step's at once: no step's own
            per_target, across = T, ready
        else:
            if at_once:
                for i, t, a in zip(at_once, T, ready, strict=True):
                    found[i] = (t, a)
            per_target = np.array([found[i][0] for i in kept])
            across = np.array([found[i][1] for i in kept])
        ok = np.abs(np.linalg.det(across)) > 0.0
        inverse = np.full_like(across, np.nan)
        inverse[ok] = np.linalg.inv(across[ok])
        for i, tangent in zip(kept, per_target @ inverse, strict=True):
            found[i] = tangent
        return found

    # ------------------------------------------------------------ columns

    def metric_columns(self, points: dict, only=None) -> dict:
        """name → (values, unit): each corner's metric columns (metrics.METRICS, with its
        label's suffix), then the shared elements' (an axle's pair of corners: heave,
        roll, the roll centre, ..., and its rates), from ``points`` (name → {label:
        jet.Dual}, label_motion's or any engine's points in that form). ``only``: a lone
        corner's columns wanted (a study's), else every one (shared elements read them)."""
        out, sides = {}, {}
        only = only if list(self.corners) == [""] and not self.shared else None
        for label, g in self.corners.items():
            p, names = self.prefix(label), self.corner_points[label]
            design = {k: self.design_positions[p + k][None] for k in names}
            own = {k: points[p + k][label] for k in names}
            sides[label] = metric_columns(g, own, design, self.spring_senses[label], only)
            suffix = self.suffix(label)
            out |= {f"{name}{suffix}": c for name, c in sides[label].items()}
        for element in self.shared:
            out |= element.columns_of(self, points, sides)
        return out

    def label_corner(self, label: str, plain: dict, qs: list) -> tuple:
        """A corner of its own for one label's rated spring, and its configurations at
        ``qs``: a lone unlabelled corner is the model itself; a labelled one its own
        Linkage posed at its wheel centre's height and the rack's travel at each step
        (rates.SpringRates along its own hub z with the rack held). ``plain``: every
        point's positions (n, 3) m."""
        if not label:
            return self, qs
        g = self.corners[label]
        corner = Linkage(g)
        # (a corner on a toe link has no rack of its own: a vehicle's rear)
        with_rack = self.model.existJointName(rack.JOINT) and corner.model.existJointName(
            rack.JOINT
        )
        index = self.model.joints[self.model.getJointId(rack.JOINT)].idx_q if with_rack else None
        targets = [PointTarget(corner.points["wheel_center"], Z)]
        if with_rack:
            targets.append(JointTarget(corner.model, rack.JOINT))
        solver = NewtonSolver(corner.kin, corner.closures, targets, corner.branches)
        poses, q = [], corner.q_design
        for i, at in enumerate(qs):
            if at is None:
                poses.append(None)
                continue
            goal = [plain[f"{label}_wheel_center"][i, 2]] + ([at[index]] if with_rack else [])
            corner.kin.update_positions(q)
            start = np.array([t.residual(corner.kin)[0] + t.value for t in targets])
            solution = solver.solve(q, start, np.array(goal))
            q = solution.q if solution.converged else q
            poses.append(solution.q if solution.converged else None)
        return corner, poses

    def sweep_results(self, sweep: Sweep, solutions: list, tangents=None, only=None):
        """The results (every column, docs/results.md) of a sweep's solved steps: the
        solver's columns, every metric column (``metric_columns``), each rated spring's
        columns (rates.py, with its label's suffix), then every point's ``_x/_y/_z``.
        ``tangents``: each step's dq per driver (default: each solution's own);
        ``only``: the set of columns wanted (a study's summary), else every one."""
        from ..solve.rates import RATE_COLUMNS, rate_columns  # a rated spring's columns

        kind = self.results_class
        columns, units = kind.solver_columns(solutions)
        # A step that did not converge has no trustworthy pose: its cells stay empty.
        solved = [s.q if s.converged else None for s in solutions]
        if tangents is None:
            tangents = [s.drive_tangent for s in solutions]
        given = tangents
        qs, tangents = self.measured_at(solved, tangents)
        points = self.label_motion(qs, tangents)
        for name, (values, column_unit) in self.metric_columns(points, only).items():
            columns[name], units[name] = values, column_unit
        first = self.labels[0]
        plain = {name: p[first].val for name, p in points.items()}
        for label, g in self.corners.items():
            wanted = only is None or {f"{r}{self.suffix(label)}" for r in RATE_COLUMNS} & {*only}
            if not g.rated_spring or not wanted:
                continue
            corner, poses = self.label_corner(label, plain, qs)
            for name, (values, column_unit) in rate_columns(corner, poses).items():
                columns[name + self.suffix(label)] = values
                units[name + self.suffix(label)] = column_unit
        for name, (values, column_unit) in self.own_columns(
            sweep, solved, plain, columns, given
        ).items():
            columns[name], units[name] = values, column_unit
        for name, (values, column_unit) in point_columns(self.output_points, plain).items():
            if only is None or name in only:
                columns[name], units[name] = values, column_unit
        meta = kind.solver_meta(solutions, (self.source, self.sha256), sweep, self)
        meta["notes"] = self.sweep_notes(sweep.targets)
        return kind(columns, units, meta)

    def measured_at(self, qs: list, tangents: list) -> tuple[list, list | None]:
        """The configurations its corners' columns and points are measured at, with their
        tangents per driver: the solved ones (a vehicle's: its chassis frame)."""
        return qs, tangents

    def own_columns(
        self, sweep: Sweep, qs: list, plain: dict, columns: dict, tangents=None
    ) -> dict:
        """Its columns beyond its corners' and elements' (name → (values, unit)), from the
        solved configurations ``qs``, the points as measured (``plain``, m), the columns
        so far and the sweep's tangents per step (sweep_results', or None): the steering
        wheel's angle and ratio where a c-factor is given (steering_surface.py)."""
        return self.steering_columns(columns)

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
            results = self.sweep_results(part, solutions, tangents or None)
            results.columns["step_index"] = results.columns["step_index"] + start
            converged = [s for s in solutions if s.converged]
            if converged:
                q = converged[-1].q
            del solutions, tangents, converged
            yield results
            del results  # before the next chunk is solved: one chunk held at a time
