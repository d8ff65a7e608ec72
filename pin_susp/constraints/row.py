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
    """The same for n configurations (bulk.Frames): ``P`` positions (n, 3), ``Jp``
    linear Jacobians (n, 3, nv) or None, ``R`` rotations (n, 3, 3) and ``W`` angular
    Jacobians (n, 3, nv) when a row is angular (else None), ``q`` (n, nq), ``nv``."""

    __slots__ = ("P", "Jp", "R", "W", "q", "nv")

    def __init__(self, P, Jp, R, W, q, nv):
        self.P, self.Jp, self.R, self.W, self.q, self.nv = P, Jp, R, W, q, nv


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
