"""Many variants of one linkage solved together (docs/studies.md, Speed).

The variants of a study share their model's structure (template.py): the same joints,
frames and rows, other joint origins, joint axes, frame offsets and link lengths. Their
sweeps' steps are then one set of configurations — every variant's every step — on
one tree whose numbers differ from configuration to configuration: bulk.Tree's
placements with each configuration's joint origins and axes, bulk.Frames' positions
with each one's frame offsets, each distance closure's length per configuration; one
batched residual, Jacobian and linear solve per Newton iteration for all of them
(bulk.newton_all's iterations, each configuration converging on its own).

A variant whose steps do not all converge, or leave a loop's design branch, is left to
be solved on its own (its sweep marched); so is every variant when the solvers' rows
differ other than in a length (``stack`` gives None).
"""

from __future__ import annotations

import copy

import numpy as np

from ..constraints.branch import MEASURES_MANY
from .bulk import MAX_ITERATIONS, Frames, Rows, Tree, rows_of, solve_all
from .solver import MAX_STEP, TOLERANCE


def _skew_many(a: np.ndarray) -> np.ndarray:
    K = np.zeros((len(a), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -a[:, 2], a[:, 1], -a[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = a[:, 2], -a[:, 1], a[:, 0]
    return K


def _apply_many(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """A·x for stacked A (n, 3, 3) and x (n, 3)."""
    return np.einsum("nij,nj->ni", A, x)


class StackedTree(Tree):
    """A bulk.Tree whose joint origins and axes are each configuration's own."""

    def __init__(self, base: Tree, axes: list, offsets: list):
        self.__dict__.update(base.__dict__)
        self.axis_n = axes  # per joint (1…): (N, 3)
        self.offset_n = offsets
        self.K_n = [None] + [
            _skew_many(a) if j[1] else None for a, j in zip(axes[1:], self.joints, strict=True)
        ]
        self.K2_n = [None] + [None if K is None else K @ K for K in self.K_n[1:]]

    def placements(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = q.shape[0]
        R = np.empty((len(self.joints) + 1, n, 3, 3))
        o = np.empty((len(self.joints) + 1, n, 3))
        R[0], o[0] = np.eye(3), 0.0
        eye = np.eye(3)
        for i, (parent, revolute, _, _, _, k) in enumerate(self.joints, start=1):
            base = R[parent]
            # (a joint on the universe: its parent's placement is the identity)
            origin = (
                self.offset_n[i] if parent == 0 else o[parent] + _apply_many(base, self.offset_n[i])
            )
            if revolute:  # base·(I + sin θ K + (1 − cos θ) K²), one stacked product
                s, c = np.sin(q[:, k])[:, None, None], np.cos(q[:, k])[:, None, None]
                turn = eye + s * self.K_n[i] + (1.0 - c) * self.K2_n[i]
                R[i] = turn if parent == 0 else base @ turn
                o[i] = origin
            else:
                R[i] = base
                o[i] = origin + _apply_many(base, self.axis_n[i]) * q[:, k, None]
        return R, o

    def axes(self, R: np.ndarray) -> np.ndarray:
        out = np.zeros((R.shape[0], R.shape[1], 3))
        for i in range(1, len(self.joints) + 1):
            out[i] = _apply_many(R[i], self.axis_n[i])
        return out


class StackedFrames(Frames):
    """bulk.Frames with each configuration's own frame offsets."""

    def __init__(self, base: Frames, tree: StackedTree, offsets: list):
        self.__dict__.update(base.__dict__)
        self.tree, self.offset = tree, offsets

    def positions(self, R: np.ndarray, o: np.ndarray) -> list[np.ndarray]:
        return [o[j] + _apply_many(R[j], x) for j, x in zip(self.joint, self.offset, strict=True)]


def _numbers(model, frame_ids) -> tuple:
    """A model's joint axes and origins (in their parents) and its frames' offsets."""
    axes, offsets = [None], [None]
    for i in range(1, model.njoints):
        joint = model.joints[i]
        name = joint.shortname()
        if name.endswith("Unaligned"):
            axes.append(np.asarray(joint.extract().axis, dtype=float))
        else:  # RX, RY, RZ, PX, PY, PZ
            axes.append(np.eye(3)["XYZ".index(name[-1])])
        offsets.append(model.jointPlacements[i].translation)
    frames = [model.frames[f].placement.translation for f in frame_ids]
    return axes, offsets, frames


class Stack:
    """The solvers of many variants (one per variant, the same structure) as one set of
    configurations, each variant's ``steps`` in a row: ``solve(guess, values)``,
    ``on_branches(q)`` (made by ``stack``)."""

    def __init__(self, base: Rows, numbers: dict, rows: list, lengths: list, loops: tuple):
        self._n = numbers  # "axes", "offsets", "frames", "guard": per configuration
        tree = StackedTree(base.tree, numbers["axes"], numbers["offsets"])
        self._n["K"], self._n["K2"] = tree.K_n, tree.K2_n
        self.rows = copy.copy(base)
        self.rows.tree = tree
        self.rows.frames = StackedFrames(base.frames, tree, numbers["frames"])
        self.rows.items = rows
        self._lengths = lengths
        self.loops, self.signs, guard_ids = loops
        self._guard_ids = guard_ids
        self._guard = None
        if self.loops:
            plain = Frames(base.tree, guard_ids)
            self._guard = StackedFrames(plain, tree, numbers["guard"])

    @classmethod
    def of(cls, base: Rows, numbers: dict, lengths: dict, loops=None) -> Stack:
        """A Stack of ``base``'s rows over configurations whose numbers are given: per
        configuration (arrays (N, 3) or (N,)) each joint's axis and origin in its parent
        (``numbers["axes"]``, ``["offsets"]``: lists over joints, None for the
        universe), each of base's frames' offset in its joint (``["frames"]``), the
        length of each distance closure (``lengths``: index in base.items → (N,)); with
        ``loops`` — (kind, frame ids) per loop guarded, their signs (N,) each, the
        guard's frame ids — each of those frames' offset (``["guard"]``)."""
        rows, by_length = [], []
        for index, (row, k, i) in enumerate(base.items):
            if index in lengths:
                row = copy.copy(row)
                by_length.append((row, lengths[index]))
            rows.append((row, k, i))
        return cls(base, dict(numbers), rows, by_length, loops or ((), (), []))

    def solve(self, guess: np.ndarray, values: np.ndarray):
        """Every configuration's Newton iterations (guess (N, nq), values (N, k)):
        q, tangents per target (N, nv, k), iterations, max |r| and whether each converged
        (a wild step or a singular Jacobian: not)."""
        rows = self.rows
        n = guess.shape[0]
        q = guess.copy()
        ok = np.zeros(n, dtype=bool)
        iterations = np.zeros(n, dtype=int)
        error = np.full(n, np.nan)
        rhs = np.zeros((rows.nrows, values.shape[1]))
        rhs[rows.first_target :] = np.eye(values.shape[1])
        tangents = np.full((n, rows.tree.nv, values.shape[1]), np.nan)
        active = np.arange(n)
        self._tree_slice(active)
        for iteration in range(MAX_ITERATIONS + 1):
            r, J = rows.evaluate(q[active], values[active])
            done = np.einsum("ni,ni->n", r, r) <= TOLERANCE * TOLERANCE
            if done.any():
                finished = active[done]
                T = _solve_each(J[done], rhs)
                good = np.isfinite(T).all(axis=(1, 2))
                tangents[finished] = T
                ok[finished] = good
                iterations[finished] = iteration
                error[finished] = np.abs(r[done]).max(axis=1)
                keep = ~done
                active, r, J = active[keep], r[keep], J[keep]
                self._tree_slice(active)
            if not active.size or iteration == MAX_ITERATIONS:
                break
            dv = _solve_each(J, -r[:, :, None])[:, :, 0]
            wild = ~(np.abs(dv) <= MAX_STEP).all(axis=1)  # (or NaN): that one stops
            if wild.any():
                active, dv = active[~wild], dv[~wild]
                self._tree_slice(active)
            q[active] += dv
        return q, tangents, iterations, error, ok

    def on_branches(self, q: np.ndarray) -> np.ndarray:
        """Whether each configuration keeps every loop's design sign (BranchGuard's)."""
        self._tree_slice(np.arange(len(q)))
        holds = np.ones(len(q), dtype=bool)
        if not self.loops:
            return holds
        R, o = self.rows.tree.placements(q)
        P = dict(zip(self._guard_ids, self._guard.positions(R, o), strict=True))
        for (kind, points), sign in zip(self.loops, self.signs, strict=True):
            holds &= MEASURES_MANY[kind](*(P[f] for f in points)) * sign > 0.0
        return holds

    def _tree_slice(self, which: np.ndarray) -> None:
        """Each configuration's numbers for the configurations ``which`` (in order)."""
        tree, n = self.rows.tree, self._n
        tree.axis_n = [None] + [a[which] for a in n["axes"][1:]]
        tree.offset_n = [None] + [x[which] for x in n["offsets"][1:]]
        tree.K_n = [None] + [None if K is None else K[which] for K in n["K"][1:]]
        tree.K2_n = [None] + [None if K is None else K[which] for K in n["K2"][1:]]
        self.rows.frames.offset = [x[which] for x in n["frames"]]
        if self._guard is not None:
            self._guard.offset = [x[which] for x in n["guard"]]
        for row, lengths in self._lengths:
            row.length = lengths[which]


def stack(solvers: list, steps: int) -> Stack | None:
    """One Stack of the variants' solvers (NewtonSolvers of models of one structure), or
    None where their rows differ other than in a distance closure's length, their loops'
    guards differ, or a joint placement turns (every link frame is world-aligned at
    design: none does)."""
    base = rows_of(solvers[0])
    tree = base.tree
    if not base.supported or not all(tree._identity) or base.nrows != tree.nv:
        return None

    def repeat(parts) -> np.ndarray:  # each variant's, once per step
        return np.repeat(np.array(parts), steps, axis=0)

    loops = [(lp.kind, tuple(p.frame_id for p in lp.points)) for lp in solvers[0].branches.loops]
    for s in solvers:
        if [(lp.kind, tuple(p.frame_id for p in lp.points)) for lp in s.branches.loops] != loops:
            return None
        if len(s.rows) != len(base.items):
            return None
    guard_ids = sorted({f for _, points in loops for f in points})
    each = [_numbers(s.kin.model, base.frames.ids) for s in solvers]
    guard = [_numbers(s.kin.model, guard_ids)[2] for s in solvers]
    joints = range(1, tree.model.njoints)
    numbers = {
        "axes": [None] + [repeat([e[0][i] for e in each]) for i in joints],
        "offsets": [None] + [repeat([e[1][i] for e in each]) for i in joints],
        "frames": [repeat([e[2][f] for e in each]) for f in range(len(base.frames.ids))],
        "guard": [repeat([g[f] for g in guard]) for f in range(len(guard_ids))],
    }
    signs = [repeat([s.branches.loops[j].sign for s in solvers]) for j in range(len(loops))]
    rows, lengths = [], []
    for index, (row, k, i) in enumerate(base.items):
        others = [s.rows[index] for s in solvers]
        if any(type(o) is not type(row) for o in others):
            return None
        mine = copy.copy(row)
        for key, value in vars(row).items():
            theirs = [vars(o)[key] for o in others]
            if key == "value" or not isinstance(value, np.ndarray | float):
                continue  # (a target's value: its column of the values, per step)
            if all(np.array_equal(t, value) for t in theirs):
                continue
            if key != "length" or not isinstance(value, float):
                return None  # a number other than a length differs: not stacked
            lengths.append((mine, repeat(theirs)))
        rows.append((mine, k, i))
    return Stack(base, numbers, rows, lengths, (loops, signs, guard_ids))


def _solve_each(J: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """J·x = rhs for each stacked J, NaN where one is singular (the others solved)."""
    x = solve_all(J, rhs)
    if x is not None:
        return x
    out = np.full((J.shape[0], J.shape[1], rhs.shape[-1]), np.nan)
    for i in range(J.shape[0]):
        one = solve_all(J[i : i + 1], rhs if rhs.ndim == 2 else rhs[i : i + 1])
        if one is not None:
            out[i] = one[0]
    return out
