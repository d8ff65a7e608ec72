"""The interface every row kind implements, and the frame data its fast forms read.

A row kind (a closure or a target) is a small class. Its maths lives in it three
times over, each form for one caller, all giving the same numbers:

- ``residual(kin)`` and ``jacobian(kin)``: the plain form, from a
  :class:`~pin_susp.constraints.kinematics.Kinematics` at one configuration
  (``size`` rows; the Jacobian d(residual)/dv, v in the tangent space of q);
- ``fill(at, k, r, J, i)``: the Newton solver's fast form at one configuration,
  from each frame the solver's rows need read once (:class:`StepFrames`);
- ``fill_many(at, k, value, r, J, i)``: the same rows for n configurations at
  once, in numpy (:class:`ManyFrames`, from the model's tree: bulk.py);
- ``drift_many(at, k, V, A, qdd, out, i)``: each row's second time derivative for
  n configurations (the drift J̇·q̇ of a second-order solve: loads.py), where the
  kind has one.

The row names the frames its fast forms read in ``frames`` (FramePoints, in its own
order); ``k`` is their indices in the caller's lists. ``angular``: the fast forms
also read each frame's rotation and angular Jacobian. ``fill`` writes rows
``r[i : i + size]`` and, unless J is None, ``J[i : i + size]``; ``fill_many``
writes columns ``r[:, i : i + size]`` and ``J[:, i : i + size]`` (J zero on entry).
A target's ``value`` is its ``value`` attribute in the plain and the fast form, the
column ``value`` (n,) of the sweep's target values in ``fill_many`` (None for a
closure). The solver and the batched path only stack rows through these methods:
adding a kind touches neither.
"""

from __future__ import annotations

import numpy as np


class StepFrames:
    """The frames the solver's rows read at one configuration, each read once:
    ``P`` positions (3,), ``Jp`` their Jacobians' linear rows (3, nv) or None (residual
    only), ``M`` placements (pin.SE3) and ``J6`` 6-row Jacobians (when a row is
    angular), ``fixed`` whether each frame is on the chassis (its Jacobian is zero),
    ``q`` the configuration."""

    __slots__ = ("P", "Jp", "M", "J6", "fixed", "q", "kin")

    def __init__(self, fixed: list[bool]):
        self.fixed = fixed
        self.P = self.Jp = self.M = self.J6 = self.q = self.kin = None


class ManyFrames:
    """The same for n configurations (bulk.Frames): ``P`` positions (n, 3); each frame's
    Jacobian compact — ``cols[f]`` the columns of v that move it (its supporting joints),
    ``Jc[f]`` its linear rows in those columns (s, n, 3) and ``Wc[f]`` its angular ones
    (s, n, 3; when a row is angular, else None) — or ``Jc`` None (residual only); ``Jp``
    and ``W`` the same as dense (n, 3, nv) arrays per frame, built when first read;
    ``R`` rotations (n, 3, 3) when a row is angular (else None), ``q`` (n, nq), ``nv``.

    ``add(J, i, f, lin, ang=None, sign)`` adds sign·(lin·J_f + ang·W_f) to row i of J
    (n, nrows, nv): a row that is a weighted sum of frames' Jacobian rows writes only
    the columns that move its frames."""

    __slots__ = ("P", "cols", "Jc", "Wc", "R", "q", "nv", "_dense")

    def __init__(self, P, cols, Jc, Wc, R, q, nv):
        self.P, self.cols, self.Jc, self.Wc = P, cols, Jc, Wc
        self.R, self.q, self.nv = R, q, nv
        self._dense = {}

    def _expand(self, f: int, terms, key) -> np.ndarray:
        out = self._dense.get(key)
        if out is None:
            out = np.zeros((len(self.P[f]), 3, self.nv))
            if len(self.cols[f]):
                out[:, :, self.cols[f]] = terms[f].transpose(1, 2, 0)
            self._dense[key] = out
        return out

    @property
    def Jp(self):
        """Each frame's linear Jacobian rows, dense (n, 3, nv); None when residual only."""
        if self.Jc is None:
            return None
        return _Lazy(lambda f: self._expand(f, self.Jc, ("J", f)), len(self.P))

    @property
    def W(self):
        """Each frame's angular Jacobian rows, dense (n, 3, nv) (angular rows only)."""
        if self.Wc is None:
            return None
        return _Lazy(lambda f: self._expand(f, self.Wc, ("W", f)), len(self.P))

    def add(self, J: np.ndarray, i: int, f: int, lin, ang=None, sign: float = 1.0) -> None:
        """J[:, i] += sign·(lin·J_f + ang·W_f), lin and ang (n, 3) or None, in f's columns."""
        cols = self.cols[f]
        if not len(cols):
            return
        x = None if lin is None else np.einsum("snk,nk->ns", self.Jc[f], lin)
        if ang is not None:
            turn = np.einsum("snk,nk->ns", self.Wc[f], ang)
            x = turn if x is None else x + turn
        if sign > 0:
            J[:, i, cols] += x
        else:
            J[:, i, cols] -= x

    def add_rows(self, J: np.ndarray, i: int, f: int, sign: float = 1.0) -> None:
        """J[:, i : i + 3] += sign·J_f (its linear rows), in f's columns."""
        cols = self.cols[f]
        if not len(cols):
            return
        if sign > 0:
            J[:, i : i + 3, cols] += self.Jc[f].transpose(1, 2, 0)
        else:
            J[:, i : i + 3, cols] -= self.Jc[f].transpose(1, 2, 0)


class _Lazy:
    """A read-only list whose items are made when first read."""

    __slots__ = ("_make", "_n")

    def __init__(self, make, n: int):
        self._make, self._n = make, n

    def __getitem__(self, f: int):
        return self._make(f)

    def __len__(self) -> int:
        return self._n


class Row:
    """A row kind's interface (see the module's docstring); a kind sets ``size``,
    ``name`` and ``frames`` and implements the methods."""

    size = 1
    name = ""
    frames: tuple = ()
    angular = False

    def residual(self, kin) -> np.ndarray:
        raise NotImplementedError

    def jacobian(self, kin) -> np.ndarray:
        raise NotImplementedError

    def fill(self, at: StepFrames, k: tuple, r: np.ndarray, J, i: int) -> None:
        """By default the plain form (a kind without a fast form: a test's own row)."""
        r[i : i + self.size] = self.residual(at.kin)
        if J is not None:
            J[i : i + self.size] = self.jacobian(at.kin)

    def fill_many(self, at: ManyFrames, k: tuple, value, r: np.ndarray, J, i: int) -> None:
        raise NotImplementedError(f"{type(self).__name__} has no batched form")

    @property
    def batched(self) -> bool:
        """Whether the kind has its batched form (every kind in constraints/ has)."""
        return type(self).fill_many is not Row.fill_many

    def drift_many(self, at: ManyFrames, k: tuple, V, A, qdd, out: np.ndarray, i: int) -> None:
        """Second time derivatives (n, size) into out[:, i : i + size]; V, A: each frame's
        velocity and classical acceleration (n, 3)."""
        raise NotImplementedError(f"{type(self).__name__} has no second derivative")
