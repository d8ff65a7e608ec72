"""A study's plain data (docs/studies.md): the variables, the objective's terms, the
job a task is given (pickled to the workers), and the objective's residuals.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

AXES = "xyz"


@dataclass(frozen=True)
class Variable:
    """One hardpoint coordinate that varies: mm from design within [low, high]."""

    point: str
    axis: str  # x | y | z
    low: float
    high: float
    side: str | None = None  # left | right on an axle

    @property
    def name(self) -> str:
        side = f"{self.side}_" if self.side else ""
        return f"d_{side}{self.point}_{self.axis}"

    @property
    def key(self) -> str:
        """The hardpoint's name in sensitivities (``left_…`` on an axle, one-sided)."""
        return f"{self.side}_{self.point}" if self.side else self.point


@dataclass(frozen=True)
class Term:
    """One objective term: a metric held at a value, or along a curve, every step."""

    metric: str
    weight: float = 1.0
    relative: bool = False  # the change from the variant's own design state
    target: float | None = None
    curve_x: str | None = None  # the column the curve is over (e.g. wheel_travel)
    curve: np.ndarray | None = None  # (k, 2): x, metric, sorted by x

    def goal(self, x) -> np.ndarray | float:
        """The target at the curve's x: linear between its points, and beyond them
        along the first and last segments."""
        if self.curve is None:
            return self.target
        x = np.asarray(x, dtype=float)
        k, slope = self._segment(x)
        return self.curve[k, 1] + slope * (x - self.curve[k, 0])

    def slope(self, x) -> np.ndarray:
        """d goal / d x: the slope of the segment that x falls in (the end ones beyond)."""
        return self._segment(np.asarray(x, dtype=float))[1]

    def _segment(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The segment that x falls in (its first point's index) and its slope."""
        c = self.curve
        k = np.searchsorted(c[1:-1, 0], np.nan_to_num(x), side="right")
        return k, (c[k + 1, 1] - c[k, 1]) / (c[k + 1, 0] - c[k, 0])


@dataclass
class Job:
    """Plain data for a task: each task builds its corners from it."""

    geometry: dict
    geometry_path: str
    sweep: dict
    sweep_path: str
    variables: list[Variable]
    summary: list[str]
    terms: list[Term]
    bounds: tuple
    max_evaluations: int = 60

    @property
    def needs(self) -> set[str]:
        """The columns that the summary and the objective read."""
        out = set(self.summary)
        for t in self.terms:
            out |= {t.metric} | ({t.curve_x} if t.curve_x else set())
        return out


def objective_residuals(terms: list[Term], results, static) -> np.ndarray:
    """r with ‖r‖² = Σ_terms w·Σ_steps (m − target)² / Σ_terms w·n: the objective is ‖r‖,
    a weighted RMS in the metrics' units. A step that did not converge counts as a
    miss of 1000 units (no number is made up for it)."""
    n = len(results)
    parts = []
    for t, w in zip(terms, shares(terms, n), strict=True):
        miss, counted = term_miss(t, results, static)
        parts.append(w * np.where(counted, miss, MISS))
    return np.concatenate(parts)


MISS = 1000.0  # a step's miss where it has no value (did not converge, undefined)


def shares(terms: list[Term], n: int) -> list[float]:
    """√(w / Σw·n) per term: the residuals' weights (Σw taken in ratios: no overflow)."""
    largest = max(t.weight for t in terms)
    total = sum(t.weight / largest for t in terms) * n
    return [math.sqrt(t.weight / largest / total) for t in terms]


def term_miss(t: Term, results, static) -> tuple[np.ndarray, np.ndarray]:
    """A term's miss at every step (the metric, from the design state's if relative,
    less its target), and the steps where that is a number: converged, the metric and
    the target defined."""
    m = np.asarray(results[t.metric], dtype=float)
    if t.relative:
        m = m - float(static[t.metric][0])
    goal = t.goal(results[t.curve_x]) if t.curve is not None else t.target
    counted = results["solver_converged"] & np.isfinite(m) & np.isfinite(goal)
    return m - goal, counted


def missed(terms: list[Term], n: int) -> np.ndarray:
    """The residuals of a variant that could not be built: every step missed."""
    return np.concatenate([np.full(n, w * MISS) for w in shares(terms, n)])
