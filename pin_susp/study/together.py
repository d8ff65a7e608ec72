"""A batch of a study's corner variants solved and measured together, from the numbers
of their trees alone (docs/studies.md, Speed).

Every variant of one corner has the design's tree with other numbers: its joints at
other origins along other axes, its points and closure anchors elsewhere, its
distance closures of other lengths (solve/template.py). Those numbers are read here
straight from each variant's tree — no model, solver or URDF built per variant — or,
where each is one of its design points, a unit vector between two or a constant,
gathered for the batch at once from its variants' design points (tree_numbers.py),
their hardpoints checked as a file's are (model/hardpoint_checks.py). The batch is
then one set of configurations (every variant's design state and every step of its
sweep) on the design model's tree with each configuration's own numbers
(solve/stacked.py):

- the sweep's steps by Newton iterations together from the design variant's
  solutions, each kept on its own loops' design branches;
- each configuration's tangent per driver (the drivers' rows, solved at once);
- every point's position and rates along the drivers, the contact patch by the chain
  rule, and the summary's metric columns over all of them in one call of
  ``metric_columns``, each variant's design positions its own.

A variant is measured so only where that is the row it would have alone: its tree
of the design's structure, its geometry needing no setup solve, its loops' branches
told apart at design by the same points as the design's, its closures independent
and its wheel free in bump at design, every step converged on its branches. Any
other variant (and every variant of a job this cannot serve: ``Together.ok``) is
built and solved on its own, as before (batch.py).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ..columns.metrics import metric_columns
from ..constraints.branch import MEASURES_MANY, LoopBranch
from ..errors import PinSuspError
from ..io.yamlio import MAX_LENGTH_MM, Reader
from ..maths.jet import Dual, cross
from ..model.geometry import parse_geometry, unit
from ..model.hardpoint_checks import checked, with_points
from ..model.tree import joint_steps
from ..model.units import MM
from ..model.wheel import contact_patch
from ..solve.bulk import rows_of, solve_all
from ..solve.linkage import twist
from ..solve.stacked import Stack, StackedTree
from ..solve.template import signature
from .data import AXES
from .tree_numbers import TreeNumbers, design_points_many
from .variants import summary_figures, variant_data


class Measured:
    """A variant measured together with its batch: its summary row, every step converged
    (the Variant interface run_batch reads)."""

    converged = True
    error = ""
    steps_failed = 0

    def __init__(self, row: dict):
        self._row = row

    def summary_row(self) -> dict:
        return dict(self._row)


def _world(tree, steps) -> dict:
    """name → world position at design of every frame a model of the tree has: each
    point (and its fixed joint), each link and joint frame, each closure's anchors."""
    world = {}
    for s in steps:
        world[s.child] = world[s.name] = s.origin
    for name, (body, position) in tree.points.items():
        world[name] = world[f"{body}_to_{name}"] = position
    for c in tree.closures:
        for i, (_, p) in enumerate(c.anchors):
            world[f"{c.name}/{i}"] = p
    return world


class Together:
    """What every variant of a job's corner shares, read once from the design corner
    (its model, its sweep's solver and its drivers' rows): ``ok`` where its variants can
    be measured together; ``measure(table)`` → per variant a Measured, or None (that
    variant to be built and solved on its own)."""

    def __init__(self, job, design, sweep, guess: np.ndarray):
        self.ok = False
        self.points = None  # the design's hardpoints (mm) where a variant's are its own (_own)
        self.recipe = None  # where each tree number comes from (tree_numbers.py)
        self.slots = [(v.point, AXES.index(v.axis)) for v in job.variables]  # (name, axis)
        self.job, self.design, self.sweep, self.guess = job, design, sweep, guess
        self.needs = set(job.needs)
        g = design.geometry
        if self._tree(np.zeros(len(job.variables)), None) is None:
            return  # (its setup solved per variant, or no tree of its own)
        if "motion_ratio" in self.needs and g.spring == "torsion_bar":
            return  # (a setup solve per variant; a bar's sense read per variant)
        if set(design.corner_points) != {""} or design.shared:
            return
        model = design.model
        self.solver = design.solver_for(sweep.targets, sweep.source)
        self.rows, self.drive = rows_of(self.solver), rows_of(design._drive)
        for rows in (self.rows, self.drive):
            tree = rows.tree
            if not rows.supported or not all(tree._identity) or rows.nrows != tree.nv:
                return
        self.held = design.held_targets(sweep.targets)
        if any(t.quantity is not None for t in self.held):
            return
        if guess.shape != (len(self.held[0].values), model.nq):
            return
        steps = joint_steps(design.tree)
        self.signature = signature(design.tree, steps)
        self.parents = [0] + [model.parents[i] for i in range(1, model.njoints)]
        # the loops: each one's candidate points (the primary, the fallback) and which
        # the design picked; the guard (solve_steps') holds the non-degenerate ones
        self.loops = []
        by_name = {c.name: c for c in design.tree.closures}
        for loop in design.branches:
            c = by_name[loop.name]
            sets = [[design.points[n] for n in c.branch]]
            if c.branch_fallback:
                sets.append([design.points[n] for n in c.branch_fallback])
            pick = [p.frame_id for p in loop.points]
            chosen = next(i for i, s in enumerate(sets) if [p.frame_id for p in s] == pick)
            self.loops.append((loop, sets, chosen))
        guarded = [lp.name for lp in self.solver.branches.loops]
        self.guarded = [i for i, (lp, _, _) in enumerate(self.loops) if lp.name in guarded]
        if [self.loops[i][0].name for i in self.guarded] != guarded:
            return
        # the frames read: the rows', the loops', every output point's
        motion_names = [n for n in design.output_points if "contact_patch_center" not in n]
        self.motion = [(n, design.points[n].frame_id) for n in motion_names]
        ids = set(self.rows.frames.ids) | set(self.drive.frames.ids)
        ids |= {p.frame_id for _, sets, _ in self.loops for s in sets for p in s}
        ids |= {f for _, f in self.motion}
        self.ids = sorted(ids)
        self.names = [model.frames[f].name for f in self.ids]
        self.column = {f: i for i, f in enumerate(self.ids)}
        self.joint_of = np.array([model.frames[f].parentJoint for f in self.ids])
        self.joint_names = [model.names[i] for i in range(1, model.njoints)]
        # a distance closure's length: |its anchors' distance| at design
        self.lengths = {}
        for rows in (self.rows, self.drive):
            self.lengths[id(rows)] = [
                (index, self.column[row.frames[0].frame_id], self.column[row.frames[1].frame_id])
                for index, (row, _, _) in enumerate(rows.items)
                if isinstance(vars(row).get("length"), float)
            ]
        # the summary's columns must be the metric functions' (not a rated spring's,
        # nor a solver's): seen on the design's own state
        given = design.metric_columns(design.label_motion([design.q_design]), self.needs)
        if any(m not in given for m in job.summary):
            return
        self.ok = self._same(design, self.rows, self.drive) and self._probe()
        if self.ok:
            self.points = self._own_points()
            self.recipe = self._recipe() if self.points is not None else None

    # ---------------------------------------------------------------- numbers

    def numbers(self, tree) -> tuple | None:
        """A variant tree's frame positions (F, 3), joint origins and axes (nj, 3) at
        design, or None where its structure is not the design's."""
        steps = joint_steps(tree)
        if signature(tree, steps) != self.signature:
            return None
        world = _world(tree, steps)
        by_name = {s.name: s for s in steps}
        try:
            E = np.array([world[n] if n in world else np.zeros(3) for n in self.names])
            J = np.array([np.zeros(3)] + [by_name[n].origin for n in self.joint_names])
            A = np.array([np.zeros(3)] + [by_name[n].axis for n in self.joint_names])
        except KeyError:
            return None
        A[1:] /= np.linalg.norm(A[1:], axis=1, keepdims=True)
        return E, J, A

    def _same(self, subject, rows, drive) -> bool:
        """Whether a subject's numbers, read from its tree as a variant's are, give its
        model's joint placements and axes, its frames' offsets and its closures' lengths
        (``rows``, ``drive``: its solver's and its drivers' Rows)."""
        got = self.numbers(subject.tree)
        if got is None:
            return False
        E, J, A = (x[None] for x in got)
        model = subject.model
        axes, offsets, frames = self._placed(E, J, A)
        for i in range(1, model.njoints):
            if not np.allclose(offsets[i][0], model.jointPlacements[i].translation, 0, 1e-15):
                return False
            if not np.allclose(axes[i][0], rows.tree.joints[i - 1][2], 0, 1e-15):
                return False
        for c, f in enumerate(self.ids):
            if not np.allclose(frames[c][0], model.frames[f].placement.translation, 0, 1e-15):
                return False
        for mine, theirs in ((self.rows, rows), (self.drive, drive)):
            for index, a, b in self.lengths[id(mine)]:
                length = theirs.items[index][0].length
                if not math.isclose(np.linalg.norm(E[0, b] - E[0, a]), length, rel_tol=1e-14):
                    return False
        return True

    def _probe(self) -> bool:
        """One variant (every variable moved by 1 µm) built as its own corner: its rows
        differ from the design's in their lengths alone (stacked.stack's test), and its
        numbers read from its tree are its model's (else no variant is measured
        together: some number of its rows would be the design's)."""
        from ..solve.stacked import stack
        from .variants import build

        deltas = np.full(len(self.job.variables), 1e-3)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                data = variant_data(self.job.geometry, self.job.variables, deltas)
                probe = build(data, "probe", variant=True)
                solver = probe.solver_for(self.sweep.targets, self.sweep.source)
        except (PinSuspError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            return False
        if stack([self.solver, solver], 1) is None:
            return False
        if stack([self.design._drive, probe._drive], 1) is None:
            return False
        return self._same(probe, rows_of(solver), rows_of(probe._drive))

    def _placed(self, E, J, A) -> tuple:
        """Per joint its axis and its origin in its parent (lists over joints of
        (n, 3)), per read frame its offset in its joint (list over frames of (n, 3))."""
        nj = J.shape[1]
        axes = [None] + [A[:, i] for i in range(1, nj)]
        offsets = [None] + [J[:, i] - J[:, self.parents[i]] for i in range(1, nj)]
        frames = [E[:, c] - J[:, j] for c, j in enumerate(self.joint_of)]
        return axes, offsets, frames

    # ---------------------------------------------------------------- measuring

    def measure(self, table: np.ndarray) -> list:
        """Per variant of the batch (its variables' rows) a Measured, or None."""
        out = [None] * len(table)
        got, which = self._numbers_many(table)
        if not which:
            return out
        E, J, A = got
        keep, signs = self._branches(E)
        if not keep.any():
            return out
        E, J, A, signs = E[keep], J[keep], A[keep], signs[:, keep]
        which = [w for w, k in zip(which, keep, strict=True) if k]
        rows = self._measured(E, J, A, signs)
        for w, row in zip(which, rows, strict=True):
            out[w] = None if row is None else Measured(row)
        return out

    def _numbers_many(self, table: np.ndarray) -> tuple:
        """(E, J, A) of the batch's variants that are not refused, and their indices:
        gathered from their design points (``recipe``), else read from each one's tree."""
        if self.recipe is not None:
            settled, which = self._checked_many(table)
            return (None if not which else self.recipe(self._design_points(settled))), which
        which, got = [], []
        for i, deltas in enumerate(table):
            x = self._numbers_of(deltas, self.points)
            if x is not None:
                which.append(i)
                got.append(x)
        if not which:
            return None, which
        return tuple(np.array([t[k] for t in got]) for k in range(3)), which

    def _with_deltas(self, table: np.ndarray, points: dict) -> tuple:
        """Variants' hardpoints (mm, (n, names, 3) in ``points``' order): the design's
        ``points`` plus each one's deltas — variant_data's numbers (the file's number
        plus a delta that is not 0) — and whether each is within the file limit (else
        its own build says why)."""
        rows = [list(points).index(n) for n, _ in self.slots]
        axes = [i for _, i in self.slots]
        H = np.repeat(np.array(list(points.values()))[None], len(table), axis=0)
        moved = H[:, rows, axes] + table
        H[:, rows, axes] = np.where(table != 0.0, moved, H[:, rows, axes])
        return H, (np.abs(moved) <= MAX_LENGTH_MM).all(axis=1)

    def _checked_many(self, table: np.ndarray) -> tuple:
        """The variants' hardpoints (m, (k, names, 3), as the mechanism settles them) of
        those that are not refused, each checked as a file's are (hardpoint_checks),
        and their indices."""
        names = list(self.points)
        H, inside = self._with_deltas(table, self.points)
        H *= MM
        g, r = self.design.geometry, Reader("<dict>")
        which, got = [], []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for v in np.flatnonzero(inside):
                hardpoints = dict(zip(names, H[v], strict=True))
                try:
                    checked(hardpoints, g, r)
                except (PinSuspError, ArithmeticError, ValueError, np.linalg.LinAlgError):
                    continue
                which.append(int(v))
                got.append([hardpoints[n] for n in names])
        return np.array(got), which

    def _design_points(self, settled: np.ndarray) -> dict:
        """name → (k, 3) of every design point of k variants, their hardpoints settled."""
        by_name = dict(zip(self.points, settled.swapaxes(0, 1), strict=True))
        return design_points_many(self.design.geometry, by_name)

    def _recipe(self) -> TreeNumbers | None:
        """Where each of the trees' numbers comes from, read off the design's and two
        probe variants' (their deltas small and all different), and checked on them."""
        rng = np.random.default_rng(0)
        samples = np.vstack(
            [np.zeros(len(self.job.variables))]
            + [rng.uniform(-1e-2, 1e-2, len(self.job.variables)) for _ in range(2)]
        )
        settled, which = self._checked_many(samples)
        numbers = [self._numbers_of(deltas, self.points) for deltas in samples]
        if len(which) != len(samples) or any(n is None for n in numbers):
            return None
        return TreeNumbers.found(self._design_points(settled), numbers)

    def _tree(self, deltas, points):
        """A variant's tree, or None where its geometry is refused or needs a setup
        solve (its own build then says why, or solves it)."""
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                g = self._geometry(deltas, points)
                return None if g is None else g.mechanism.tree(g, shapes=False)
        except (PinSuspError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            return None

    def _geometry(self, deltas, points):
        """A variant's Geometry: the design's with its own hardpoints, checked as a file's
        are (hardpoint_checks.with_points), from the design's ``points`` (mm); without
        them its geometry data read whole. None where it needs a setup solve."""
        if points is None:
            data = variant_data(self.job.geometry, self.job.variables, deltas)
            g = parse_geometry(data, Reader("<dict>"), None)
            return None if g.needs_setup else g
        H, inside = self._with_deltas(np.asarray(deltas)[None], points)
        if not inside[0]:
            return None
        own = dict(zip(points, H[0], strict=True))
        return with_points(self.design.geometry, own, Reader("<dict>"))

    def _own_points(self) -> dict | None:
        """The design's hardpoints (mm) as its canonical data gives them, where every
        variable is a coordinate of one of them that the file gives as is (so that a
        variant's hardpoints are these with its deltas: variant_data's numbers; another
        unit or form of the file's differs here or in the probe) and the probe variant's
        tree numbers come out the same either way; else None."""
        g, r = self.design.geometry, Reader("<dict>")
        canonical, given = g.data.get("hardpoints", {}), self.job.geometry.get("hardpoints", {})
        if not isinstance(given, dict):
            return None
        points = {name: r.point(canonical[name], name) for name in g.hardpoints}
        for v in self.job.variables:
            if v.side or v.point not in points or v.point not in given:
                return None
            if not np.array_equal(r.point(given[v.point], v.point), points[v.point]):
                return None
        deltas = np.full(len(self.job.variables), 1e-3)
        own, whole = self._numbers_of(deltas, points), self._numbers_of(deltas, None)
        if own is None or whole is None:
            return None
        if not all(np.array_equal(a, b) for a, b in zip(own, whole, strict=True)):
            return None
        return points

    def _numbers_of(self, deltas, points):
        """A variant's (E, J, A) read from its tree (``points``: as _geometry's)."""
        tree = self._tree(deltas, points)
        return None if tree is None else self.numbers(tree)

    def _branches(self, E: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Which variants tell each loop's branches apart at design by the design's own
        points (so that their guards are the design's), and each guarded loop's sign."""
        n = len(E)
        keep = np.ones(n, dtype=bool)
        degenerate = LoopBranch.DEGENERATE
        signs = np.ones((len(self.guarded), n))
        for k, (loop, sets, chosen) in enumerate(self.loops):
            values = [
                MEASURES_MANY[loop.kind](*(E[:, self.column[p.frame_id]] for p in s)) for s in sets
            ]
            clear = [np.abs(v) >= degenerate * (1 + 1e-9) for v in values]
            blurred = [np.abs(np.abs(v) - degenerate) <= 1e-9 * degenerate for v in values]
            pick = np.where(clear[0], 0, np.where(clear[-1], len(sets) - 1, 0))
            keep &= pick == chosen
            keep &= ~np.any(blurred, axis=0)
            keep &= clear[chosen] != loop.degenerate
            if k in self.guarded:
                signs[self.guarded.index(k)] = np.copysign(1.0, values[chosen])
        return keep, signs

    def _stack(self, rows, which, E, J, A, signs=None) -> Stack:
        """A Stack of ``rows`` (the sweep's or the drivers') over configurations, each
        configuration ``which[c]``'s variant numbers."""
        axes, offsets, frames = self._placed(E[which], J[which], A[which])
        col = [self.column[f] for f in rows.frames.ids]
        numbers = {"axes": axes, "offsets": offsets, "frames": [frames[c] for c in col]}
        lengths = {
            index: np.linalg.norm(E[which, b] - E[which, a], axis=1)
            for index, a, b in self.lengths[id(rows)]
        }
        loops = None
        if signs is not None and self.guarded:
            kinds = []
            for k in self.guarded:
                loop, sets, chosen = self.loops[k]
                kinds.append((loop.kind, tuple(p.frame_id for p in sets[chosen])))
            loops = (kinds, [s[which] for s in signs], self.ids)
            numbers["guard"] = frames
        return Stack.of(rows, numbers, lengths, loops)

    def _measured(self, E, J, A, signs) -> list:
        """Each variant's summary row, or None where some step did not converge on its
        branches or its design state is singular."""
        n, steps = len(E), len(self.held[0].values)
        design = self._design_positions(E)
        values = np.column_stack([self._values(t, design) for t in self.held])  # (n·steps, k)
        on = np.repeat(np.arange(n), steps)
        solve = self._stack(self.rows, on, E, J, A, signs)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            q, _, _, _, ok = solve.solve(np.tile(self.guess, (n, 1)), values)
            ok &= solve.on_branches(q)
        good = ok.reshape(n, steps).all(axis=1)
        # every configuration measured: each variant's design state, then its steps
        every = np.repeat(np.arange(n), steps + 1)
        Q = np.zeros((n, steps + 1, q.shape[1]))
        Q[:, 1:] = q.reshape(n, steps, -1)
        Q = Q.reshape(-1, q.shape[1])
        drive = self._stack(self.drive, every, E, J, A)
        tree = drive.rows.tree
        placed = tree.placements(Q)
        zero = np.zeros((len(Q), len(self.design._drive.targets)))
        _, Jd = drive.rows.evaluate(Q, zero, placed=placed)
        good &= self._free(Jd.reshape(n, steps + 1, *Jd.shape[1:])[:, 0])
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            T = solve_all(Jd, self.design.drive_rhs)
            if T is None:
                return [None] * n
            columns = self._columns(tree, placed, T, E, J, every, design)
        out = []
        for v in range(n):
            if not good[v]:
                out.append(None)
                continue
            mine = slice(v * (steps + 1), (v + 1) * (steps + 1))
            out.append(_summary(self.job.summary, {m: columns[m][0][mine] for m in columns}))
        return out

    def _free(self, J0: np.ndarray) -> np.ndarray:
        """Whether each variant's closures are independent and its wheel moves in bump at
        design (Linkage._check_mobility's tests: else its own build refuses it)."""
        closures = len(J0[0]) - len(self.design._drive.targets)
        ok = np.ones(len(J0), dtype=bool)
        for rows in (J0[:, :closures], J0):
            if rows.shape[1]:
                s = np.linalg.svd(rows, compute_uv=False)
                ok &= s[:, -1] > 1e-9 * s[:, 0]
        return ok

    def _design_positions(self, E: np.ndarray) -> dict:
        """name → each variant's design position (n, 3) of every corner point."""
        out = {name: E[:, self.column[f]] for name, f in self.motion}
        radius = self.design.geometry.wheel.radius
        spin = unit(out["axle_outboard"] - out["axle_inboard"])
        out["contact_patch_center"] = contact_patch(out["wheel_center"], spin, radius)
        return out

    def _values(self, t, design: dict) -> np.ndarray:
        """A held target's values at every variant's every step (target_values')."""
        values = np.asarray(t.values, dtype=float) * 1e-3
        n = len(next(iter(design.values())))
        if t.mode != "relative":
            return np.tile(values, n)
        along = design[self.design.point_of(t)] @ t.unit_direction
        return (values[None, :] + along[:, None]).ravel()

    def _columns(self, tree: StackedTree, placed, T, E, J, every, design) -> dict:
        """The summary's metric columns at every configuration (label_motion's points,
        then metric_columns)."""
        R, o = placed
        a = tree.axes(R)
        k = self.design.driver_columns[""]
        T = T[:, :, k]
        points = {}
        for name, f in self.motion:
            c = self.column[f]
            j = self.joint_of[c]
            if j == 0:
                pos = E[every, c]
                points[name] = {"": Dual(pos, np.zeros((len(k), *pos.shape)))}
                continue
            arm = np.einsum("nij,nj->ni", R[j], E[every, c] - J[every, j])
            v, w = twist(tree, j, o, a, T)
            points[name] = {"": Dual(arm + o[j], v + cross(w, arm[None]))}
        g = self.design.geometry
        wheel, inboard, outboard = (
            points[n][""] for n in ("wheel_center", "axle_inboard", "axle_outboard")
        )
        points["contact_patch_center"] = {
            "": contact_patch(wheel, unit(outboard - inboard), g.wheel.radius)
        }
        names = self.design.corner_points[""]
        own = {name: points[name][""] for name in names}
        at = {name: design[name][every] for name in names}
        return metric_columns(g, own, at, self.design.spring_sense, self.needs)


def _summary(summary: list, columns: dict) -> dict:
    """Variant.summary_row's figures from a variant's columns (its design state first,
    then its steps, every one converged)."""
    row = {}
    for m in summary:
        row |= summary_figures(m, float(columns[m][0]), columns[m][1:])
    return row
