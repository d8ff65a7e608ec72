"""A rigid link between two ball joints: its ends keep their distance."""

from __future__ import annotations

import math

import numpy as np

from .row import Row


class DistanceClosure(Row):
    """r = |p_b − p_a| − L (1 row, m): positive when the link's ends a, b are further
    apart than its length L. With u = (p_b − p_a)/|p_b − p_a|, J = uᵀ·(J_b − J_a);
    r̈ = |d|″ (length_rates)."""

    size = 1

    def __init__(self, name: str, a, b, length: float):
        self.name, self.a, self.b, self.length = name, a, b, length
        self.frames = (a, b)

    def residual(self, kin) -> np.ndarray:
        return np.array([np.linalg.norm(self.b.position(kin) - self.a.position(kin)) - self.length])

    def jacobian(self, kin) -> np.ndarray:
        d = self.b.position(kin) - self.a.position(kin)
        return (d / np.linalg.norm(d)) @ (self.b.jacobian(kin) - self.a.jacobian(kin))[None]

    def fill(self, at, k, r, J, i) -> None:
        a, b = k
        d = at.P[b] - at.P[a]
        n = math.sqrt(d @ d)
        r[i] = n - self.length
        if J is not None:  # an end on the chassis adds nothing to the row
            Jp, fixed = at.Jp, at.fixed
            J[i] = (d / n) @ (Jp[b] if fixed[a] else Jp[b] - Jp[a] if not fixed[b] else -Jp[a])

    def fill_many(self, at, k, value, r, J, i) -> None:
        a, b = k
        d = at.P[b] - at.P[a]
        length = np.sqrt(np.einsum("ni,ni->n", d, d))
        r[:, i] = length - self.length
        if J is not None:
            u = d / length[:, None]
            at.add(J, i, b, u)
            at.add(J, i, a, u, sign=-1.0)

    def drift_many(self, at, k, V, A, qdd, out, i) -> None:
        a, b = k
        out[:, i] = length_rates(at.P[b] - at.P[a], V[b] - V[a], A[b] - A[a])[2]


def length_rates(d: np.ndarray, dv: np.ndarray, da: np.ndarray) -> tuple:
    """|d| and its first and second time derivatives (each (n,)) from d, d′, d″ (n, 3):
    |d|′ = u·d′ and |d|″ = u·d″ + (|d′|² − (u·d′)²)/|d|, u = d/|d|."""
    length = np.sqrt(np.einsum("ni,ni->n", d, d))
    u = d / length[:, None]
    along = np.einsum("ni,ni->n", u, dv)
    second = np.einsum("ni,ni->n", u, da) + (np.einsum("ni,ni->n", dv, dv) - along * along) / length
    return length, along, second
