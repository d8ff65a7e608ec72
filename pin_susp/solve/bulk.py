"""A sweep's steps solved together: Pinocchio's model evaluated for every step at once.

Pinocchio's Python API evaluates one configuration per call; a sweep of
thousands of steps then spends its time in the calls around it, not in the
kinematics. This module takes the Pinocchio model's own tree — each joint's
parent, placement and motion subspace, each frame's joint and placement —
and evaluates it for n configurations at once with numpy: joint placements
(oMi), frame positions and their LOCAL_WORLD_ALIGNED Jacobians, the same
quantities ``pin.computeJointJacobians`` / ``getFrameJacobian`` give (a test
checks them against Pinocchio on every example to 1e-15 m).

A long sweep is then solved in two passes (march.solve_sweep):

1. Pinocchio's Newton solver (march.march) marches a coarse path — every
   s-th step, with its continuation and branch checks — and gives the exact
   tangent dq/dv at each coarse solution;
2. every step's configuration is predicted from its two coarse neighbours
   (cubic Hermite along the segment, exact to O(h⁴)) and all steps take
   Newton iterations together: one batched residual, Jacobian and linear
   solve per iteration.

Each step must meet the same tolerance and stay on every loop's design
branch; if any step does not, the sweep is solved step by step instead
(march.march), so a difficult sweep is never worse off than before.
Only joints with one degree of freedom (revolute or prismatic, aligned or
not) are handled here (a model with another kind goes step by step); every row
kind has its batched form (constraints/: Row.fill_many), stacked by ``Rows``.
"""

from __future__ import annotations

import weakref

import numpy as np
import pinocchio as pin

from ..constraints import ManyFrames
from ..maths.jet import cross
from .solver import MAX_STEP

# A sweep shorter than this is marched step by step (the coarse pass would be most of it).
MIN_STEPS = 200
COARSE_STEPS = 32  # about this many coarse steps, whatever the sweep's length
COARSE_GROUP = 4  # every this many-th coarse step marched, the others solved at once
MAX_ITERATIONS = 8

_TREES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_ROWS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def tree_of(kin):
    """A Kinematics' model tree as arrays (Tree), built when first asked for."""
    tree = _TREES.get(kin)
    if tree is None:
        tree = _TREES[kin] = Tree(kin.model)
    return tree


def seed_tree(kin, tree) -> None:
    """A Kinematics' model tree given (Tree.like) rather than built when first asked for."""
    _TREES[kin] = tree


def rows_of(solver):
    """A NewtonSolver's rows for many configurations at once (Rows), built when first
    asked for."""
    rows = _ROWS.get(solver)
    if rows is None:
        rows = _ROWS[solver] = Rows(tree_of(solver.kin), solver.rows, len(solver.targets))
    return rows


class Tree:
    """A Pinocchio model's kinematic tree as arrays: joints with one degree of freedom.

    ``supported`` is False when the model has another kind of joint.
    """

    def __init__(self, model: pin.Model):
        self.model = model
        self.nq, self.nv = model.nq, model.nv
        self.supported = model.nq == model.nv
        self.joints = []  # (parent, revolute?, axis (3,), placement R, placement p, idx)
        for i in range(1, model.njoints):
            joint = model.joints[i]
            if joint.nq != 1 or joint.nv != 1:
                self.supported = False
                break
            data = joint.createData()
            joint.calc(data, np.zeros(model.nq))
            s = np.array(data.S).ravel()
            revolute = bool(np.any(s[3:]))
            if revolute == bool(np.any(s[:3])):  # a helical joint, or none at all
                self.supported = False
                break
            axis = s[3:] if revolute else s[:3]
            placement = model.jointPlacements[i]
            self.joints.append(
                (
                    model.parents[i],
                    revolute,
                    axis.copy(),
                    placement.rotation.copy(),
                    placement.translation.copy(),
                    joint.idx_q,
                )
            )
        if not self.supported:
            return
        # per joint: whether its placement turns nothing, and [axis]× and its square
        self._identity = [True] + [np.array_equal(j[3], np.eye(3)) for j in self.joints]
        self._skew = [None] + [_skew(j[2]) for j in self.joints]
        # the joints that move each joint (its supports, the universe excluded): the
        # revolute ones and the prismatic ones, each as (joint indices, indices in v)
        self._moves = []
        for i in range(model.njoints):
            support = list(model.supports[i])[1:]
            kinds = []
            for revolute in (True, False):
                ks = [k for k in support if self.joints[k - 1][1] == revolute]
                kinds.append((ks, [self.joints[k - 1][5] for k in ks]))
            self._moves.append(tuple(kinds))

    @classmethod
    def like(cls, base: Tree, model: pin.Model) -> Tree:
        """The tree of a model of ``base``'s structure (a study's variant: template.py)
        with its own joint axes and placements, without evaluating its joints again."""
        tree = cls.__new__(cls)
        tree.__dict__.update(base.__dict__)
        tree.model = model
        tree.joints = []
        for i, (parent, revolute, axis, _, _, k) in enumerate(base.joints, start=1):
            joint = model.joints[i]
            if joint.shortname().endswith("Unaligned"):  # its motion subspace: its axis
                axis = np.array(joint.extract().axis, dtype=float)
            placement = model.jointPlacements[i]
            R, p = placement.rotation.copy(), placement.translation.copy()
            tree.joints.append((parent, revolute, axis, R, p, k))
        tree._identity = [True] + [np.array_equal(j[3], np.eye(3)) for j in tree.joints]
        tree._skew = [None] + [_skew(j[2]) for j in tree.joints]
        return tree

    def moved_by(self, joint: int) -> list[int]:
        """The indices in v of the joints that move a joint (its supports, the universe
        excluded): revolute, then prismatic."""
        revolute, prismatic = self._moves[joint]
        return list(revolute[1]) + list(prismatic[1])

    def placements(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World rotation (njoints, n, 3, 3) and origin (njoints, n, 3) of every joint
        at the n configurations q (n, nq); joint 0 is the universe. (A product with a
        constant matrix is one (3n × 3)·(3 × 3) product: numpy's stacked 3 × 3 products
        are slower.)"""
        n = q.shape[0]
        R = np.empty((len(self.joints) + 1, n, 3, 3))
        o = np.empty((len(self.joints) + 1, n, 3))
        R[0], o[0] = np.eye(3), 0.0
        for i, (parent, revolute, axis, Rp, pp, k) in enumerate(self.joints, start=1):
            base = R[parent] if self._identity[i] else _times(R[parent], Rp)
            origin = o[parent] + _apply(R[parent], pp)
            if revolute:  # base·(I + sin θ K + (1 − cos θ) K²), K = [axis]×
                K, K2 = self._skew[i]
                s, c = np.sin(q[:, k])[:, None, None], np.cos(q[:, k])[:, None, None]
                R[i] = base + s * _times(base, K) + (1.0 - c) * _times(base, K2)
                o[i] = origin
            else:
                R[i] = base
                o[i] = origin + _apply(base, axis) * q[:, k, None]
        return R, o

    def axes(self, R: np.ndarray) -> np.ndarray:
        """World axis of every joint (njoints, n, 3) from its world rotation (a joint's own
        motion turns about, or slides along, its axis: the axis is the same before it)."""
        out = np.zeros((R.shape[0], R.shape[1], 3))
        for i, (_, _, axis, _, _, _) in enumerate(self.joints, start=1):
            out[i] = _apply(R[i], axis)
        return out

    def twist_jacobian(self, joint: int, o: np.ndarray, a: np.ndarray) -> np.ndarray:
        """The joint frame's LOCAL_WORLD_ALIGNED Jacobian (n, 6, nv): the velocity of its
        origin, then its angular velocity."""
        J = np.zeros((o.shape[1], 6, self.nv))
        revolute, prismatic = self._moves[joint]
        if revolute[0]:
            ks, vs = revolute
            J[:, :3, vs] = cross(a[ks], o[joint] - o[ks]).transpose(1, 2, 0)
            J[:, 3:, vs] = a[ks].transpose(1, 2, 0)
        if prismatic[0]:
            ks, vs = prismatic
            J[:, :3, vs] = a[ks].transpose(1, 2, 0)
        return J

    def motion(self, o: np.ndarray, a: np.ndarray, qd: np.ndarray, qdd: np.ndarray):
        """Every joint's body at velocity qd and acceleration qdd (n, nv): angular velocity
        ω, angular acceleration α, and the velocity and classical acceleration of the
        joint's origin, each (njoints, n, 3), from the root outward (Pinocchio's
        forwardKinematics(q, v, a) with frame velocities and classical accelerations).

        A joint's origin is a point of its parent body (a prismatic joint's slides along
        the axis, which turns with the parent: the Coriolis term 2·q̇·ω × a); a joint's
        axis turns with its parent body: d(a)/dt = ω_parent × a.
        """
        n = qd.shape[0]
        w, dw = np.zeros((len(o), n, 3)), np.zeros((len(o), n, 3))
        v, dv = np.zeros((len(o), n, 3)), np.zeros((len(o), n, 3))
        for i, (parent, revolute, _, _, _, k) in enumerate(self.joints, start=1):
            wp, dwp = w[parent], dw[parent]
            r = o[i] - o[parent]
            wr = cross(wp, r)
            v[i] = v[parent] + wr
            dv[i] = dv[parent] + cross(dwp, r) + cross(wp, wr)
            rate, accel = qd[:, k, None], qdd[:, k, None]
            turn = cross(wp, a[i])  # the axis's own rate
            if revolute:
                w[i] = wp + rate * a[i]
                dw[i] = dwp + accel * a[i] + rate * turn
            else:
                w[i], dw[i] = wp, dwp
                v[i] += rate * a[i]
                dv[i] += accel * a[i] + 2.0 * rate * turn
        return w, dw, v, dv


def point_motion(joint: int, p: np.ndarray, o: np.ndarray, state) -> tuple:
    """Velocity and classical acceleration (n, 3) of points p (n, 3) fixed to ``joint``'s
    body, from Tree.motion's state (ω, α, v, a of each joint)."""
    w, dw, v, dv = (x[joint] for x in state)
    r = p - o[joint]
    wr = cross(w, r)
    return v + wr, dv + cross(dw, r) + cross(w, wr)


def _times(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """A·B for stacked A (n, 3, 3) and one B (3, 3)."""
    return (A.reshape(-1, 3) @ B).reshape(A.shape)


def _apply(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """A·x for stacked A (n, 3, 3) and one vector x (3,): (n, 3)."""
    return (A.reshape(-1, 3) @ x).reshape(A.shape[:-1])


def _skew(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return K, K @ K


class Frames:
    """Frame positions and Jacobians over many configurations: each frame as its joint
    and its offset in that joint's frame (frames on the chassis stay where they are)."""

    def __init__(self, tree: Tree, frame_ids: list[int]):
        model = tree.model
        self.tree = tree
        self.ids = list(frame_ids)
        self.joint = [model.frames[f].parentJoint for f in self.ids]
        self.offset = [model.frames[f].placement.translation.copy() for f in self.ids]
        self.turn = [model.frames[f].placement.rotation.copy() for f in self.ids]
        # every frame's Jacobian terms, all frames' in one array: term t is the motion of
        # frame term_frame[t] by joint term_joint[t] (its column cols[f] in v), the
        # revolute terms first (a × (p − o)), then the prismatic ones (a)
        revolute, prismatic = [], []
        for f, j in enumerate(self.joint):
            (rk, rv), (pk, pv) = tree._moves[j]
            revolute += [(f, k, v) for k, v in zip(rk, rv, strict=True)]
            prismatic += [(f, k, v) for k, v in zip(pk, pv, strict=True)]
        terms = revolute + prismatic
        self._revolute = len(revolute)
        self._term_frame = np.array([f for f, _, _ in terms], dtype=int)
        self._term_joint = np.array([k for _, k, _ in terms], dtype=int)
        self.cols, self._terms = [], []  # per frame: its columns in v, its terms' indices
        for f in range(len(self.ids)):
            mine = [t for t, (g, _, _) in enumerate(terms) if g == f]
            self.cols.append(np.array([terms[t][2] for t in mine], dtype=int))
            self._terms.append(np.array(mine, dtype=int))
        # a frame's terms are one slice when they are all revolute or all prismatic
        self._slices = [
            slice(int(t[0]), int(t[-1]) + 1) if len(t) and np.all(np.diff(t) == 1) else t
            for t in self._terms
        ]

    def evaluate(self, q: np.ndarray, jacobians: bool = True, placed=None, angular=False):
        """Positions (list of (n, 3)) and Jacobians (list of (n, 3, nv), or None);
        ``placed``: Tree.placements(q) when the caller has it already; ``angular``: the
        angular Jacobians too, a third list (n, 3, nv)."""
        R, o = self.tree.placements(q) if placed is None else placed
        P = self.positions(R, o)
        if not jacobians:
            return P, None
        Jc, Wc = self.compact(P, o, self.tree.axes(R), angular=angular)
        J = self._dense(Jc, q.shape[0])
        return (P, J, self._dense(Wc, q.shape[0])) if angular else (P, J)

    def _dense(self, compact: list, n: int) -> list[np.ndarray]:
        """Each frame's rows from its columns that move it (``compact``'s) into all nv."""
        out = []
        for cols, terms in zip(self.cols, compact, strict=True):
            dense = np.zeros((n, 3, self.tree.nv))
            if len(cols):
                dense[:, :, cols] = terms.transpose(1, 2, 0)
            out.append(dense)
        return out

    def compact(self, P: list, o: np.ndarray, a: np.ndarray, angular: bool = False):
        """Every frame's Jacobian in the columns that move it (``cols``), all frames' in
        one pass: linear rows (s, n, 3) per frame, and the angular ones too if
        ``angular`` (else None). A revolute joint k moves a point p at a_k × (p − o_k), a
        prismatic one at a_k; the angular rows are a_k, or zero."""
        joints, frames = self._term_joint, self._term_frame
        axes = a[joints]  # (T, n, 3)
        linear = axes.copy()
        r = self._revolute
        if r:
            where = np.stack(P)[frames[:r]] - o[joints[:r]]
            linear[:r] = cross(axes[:r], where)
        turning = None
        if angular:
            turning = axes
            turning[r:] = 0.0
        pick = self._slices
        Jc = [linear[t] for t in pick]
        return Jc, None if turning is None else [turning[t] for t in pick]

    def positions(self, R: np.ndarray, o: np.ndarray) -> list[np.ndarray]:
        """Each frame's position (n, 3) from the joints' placements (Tree.placements)."""
        return [o[j] + _apply(R[j], x) for j, x in zip(self.joint, self.offset, strict=True)]

    def rotations(self, R: np.ndarray, only=None) -> list:
        """Each frame's world rotation (n, 3, 3) from the joints' (Tree.placements);
        ``only``: the indices of the frames wanted (the others None)."""
        return [
            _times(R[j], t) if only is None or f in only else None
            for f, (j, t) in enumerate(zip(self.joint, self.turn, strict=True))
        ]

    def motion(self, P: list, o: np.ndarray, state) -> tuple[list, list]:
        """Each frame's velocity and classical acceleration (n, 3) in a Tree.motion state."""
        out = [point_motion(j, p, o, state) for j, p in zip(self.joint, P, strict=True)]
        return [v for v, _ in out], [acc for _, acc in out]


class Rows:
    """A solver's stacked rows (closures, then one row per target) for many steps: each
    row's batched form (Row.fill_many) on the frames it names, every frame evaluated
    once for all rows. Knows no row kind."""

    def __init__(self, tree: Tree, rows: list, ntargets: int):
        self.tree = tree
        self.supported = tree.supported and all(row.batched for row in rows)
        frames: list[int] = []
        self.items = []  # (row, its frames' indices, its first row)
        i = 0
        for row in rows:
            k = []
            for point in row.frames:
                if point.frame_id not in frames:
                    frames.append(point.frame_id)
                k.append(frames.index(point.frame_id))
            self.items.append((row, tuple(k), i))
            i += row.size
        self.nrows = i
        self.first_target = i - ntargets
        self.angular = any(row.angular for row in rows)
        # the frames whose rotations and angular Jacobians the angular rows read
        self.turning = {f for row, k, _ in self.items if row.angular for f in k}
        self.frames = Frames(tree, frames)

    def _at(self, q, P, o, R, jacobian: bool) -> ManyFrames:
        """The frames' data for the rows (rotations and angular Jacobians if any row
        reads them); R, o: the joints' world placements (Tree.placements)."""
        rotations = None
        Jc = Wc = None
        if self.angular:
            rotations = self.frames.rotations(R, self.turning)
        if jacobian:
            Jc, Wc = self.frames.compact(P, o, self.tree.axes(R), self.angular)
        return ManyFrames(P, self.frames.cols, Jc, Wc, rotations, q, self.tree.nv)

    def evaluate(self, q: np.ndarray, values: np.ndarray, jacobian: bool = True, placed=None):
        """Residuals (n, nrows) and Jacobians (n, nrows, nv) at q (n, nq) with the target
        values (n, ntargets); a target row's value is its column of ``values``;
        ``placed``: Tree.placements(q) when the caller has it already."""
        n = q.shape[0]
        placed = self.tree.placements(q) if placed is None else placed
        P = self.frames.positions(*placed)
        at = self._at(q, P, placed[1], placed[0], jacobian)
        r = np.empty((n, self.nrows))
        J = np.zeros((n, self.nrows, self.tree.nv)) if jacobian else None
        first = self.first_target
        for row, k, i in self.items:
            value = values[:, i - first] if i >= first else None
            row.fill_many(at, k, value, r, J, i)
        return r, J

    def second(self, R, o, P, state, qdd: np.ndarray) -> np.ndarray:
        """Every row's second time derivative (n, nrows) in a Tree.motion state (at q with
        velocity q̇ and acceleration ``qdd``; P: the frames' positions): with q̈ = 0, the
        drift J̇·q̇ of the second-order closure solve J·q̈ = −J̇·q̇ (Row.drift_many)."""
        V, A = self.frames.motion(P, o, state)
        at = self._at(None, P, o, R, False)
        out = np.empty((len(qdd), self.nrows))
        for row, k, i in self.items:
            row.drift_many(at, k, V, A, qdd, out, i)
        return out


def newton_all(rows: Rows, q: np.ndarray, values: np.ndarray, tolerance: float, extra=None):
    """Newton iterations for every step at once: (q, tangents, iterations, max |r|) or
    (None, ...) if any step does not converge to ``tolerance`` (or takes a wild step).
    ``extra``: more right-hand sides (nrows, e) solved at each solution with the
    tangents, their columns after the targets' (J·x = e: a closure's value changed by
    one, the targets held)."""
    n = q.shape[0]
    q = q.copy()
    iterations = np.zeros(n, dtype=int)
    error = np.zeros(n)
    rhs = np.zeros((rows.nrows, values.shape[1]))
    rhs[rows.first_target :] = np.eye(values.shape[1])
    if extra is not None:
        rhs = np.hstack([rhs, extra])
    tangents = np.empty((n, rows.tree.nv, rhs.shape[1]))
    active = np.arange(n)
    for iteration in range(MAX_ITERATIONS + 1):
        r, J = rows.evaluate(q[active], values[active])
        done = np.einsum("ni,ni->n", r, r) <= tolerance * tolerance
        if done.any():
            finished = active[done]
            T = solve_all(J[done], rhs)
            if T is None:
                return None, None, None, None
            tangents[finished] = T
            iterations[finished] = iteration
            error[finished] = np.abs(r[done]).max(axis=1)
            active, r, J = active[~done], r[~done], J[~done]
        if not active.size:
            return q, tangents, iterations, error
        if iteration == MAX_ITERATIONS:
            break
        dv = solve_all(J, -r[:, :, None])
        if dv is None:
            return None, None, None, None
        dv = dv[:, :, 0]
        if not np.all(np.abs(dv) <= MAX_STEP):  # a wild step (or NaN): step by step
            return None, None, None, None
        q[active] += dv
    return None, None, None, None


def solve_all(J: np.ndarray, rhs: np.ndarray) -> np.ndarray | None:
    """J·x = rhs for stacked J (n, m, m) and rhs (m, k) or (n, m, k); None if any J is
    singular."""
    try:
        if rhs.ndim == 2:
            rhs = np.broadcast_to(rhs, (J.shape[0], *rhs.shape))
        x = np.linalg.solve(J, rhs)
    except np.linalg.LinAlgError:
        return None
    return x if np.isfinite(x).all() else None


def on_branches(solver, qs: np.ndarray) -> bool:
    """Every step on every loop's design assembly (constraints.BranchGuard, all steps)."""
    guard = solver.branches
    if not guard.loops:
        return True
    ids = guard.frame_ids
    P, _ = Frames(tree_of(solver.kin), ids).evaluate(qs, jacobians=False)
    return guard.holds_many(dict(zip(ids, P, strict=True)))
