"""An engine's comparison with pin_susp's results (README, How it works): each column's
largest difference against the tolerance, the steps an engine failed or solved on
another branch of the mechanism.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from .scopes import scope_of

TOLERANCE = 1e-6  # mm and deg
# Instant centres of nearly parallel wishbones lie kilometres away, where a
# difference of 1e-13 m in a ball joint moves them by micrometres: besides the
# absolute tolerance, a column may differ by this fraction of its value.
RELATIVE = 1e-9


@dataclass
class EngineReport:
    """max |difference| to pin_susp per column, over every step the engine solved."""

    engine: str
    tolerance: float = TOLERANCE
    differences: dict[str, float] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    failed_steps: list[int] = field(default_factory=list)
    disagree: set[str] = field(default_factory=set)
    # steps it solved on another assembly branch than pin_susp's (not compared), and
    # what flipped; ``other_branch``: such steps where pin_susp found no pose either
    branch_steps: list[int] = field(default_factory=list)
    other_branch: list[int] = field(default_factory=list)
    flipped: set[str] = field(default_factory=set)
    not_compared: set[str] = field(default_factory=set)  # the engine could not compute them
    note: str = ""
    warnings: int = 0  # how many warnings the engine raised (MuJoCo's, Drake's: silenced, counted)
    first_warning: str = ""

    @property
    def worst(self) -> float:
        return max(self.differences.values(), default=0.0)

    @property
    def agrees(self) -> bool:
        return not (self.note or self.failed_steps or self.disagree or self.branch_steps)


def compare(
    subject, results, points_per_step: list | None, engine: str, tolerance: float = TOLERANCE
) -> EngineReport:
    """Metric columns of an engine's points against pin_susp's results (``subject``: an
    Assembly — a Corner, an AxleModel — or its Scope)."""
    scope = scope_of(subject)
    report = EngineReport(engine, tolerance)
    branches = Branches(scope.tree)
    for i, points in enumerate(points_per_step):
        if points is None:
            report.failed_steps.append(i)
            continue
        flipped = branches.flipped(scope.positions(points))
        if flipped is not None:  # another assembly: its differences mean nothing
            report.flipped.add(flipped)
            converged = results["solver_converged"][i]
            (report.branch_steps if converged else report.other_branch).append(i)
            continue
        if not results["solver_converged"][i]:
            continue
        stalled = scope.stalled(points)  # a driver the engine cannot move
        for name, (values, unit) in scope.columns(points).items():
            if np.asarray(values).dtype.kind == "O":  # text (limit_exceeded): of numbers
                continue  # that are compared
            if np.isnan(values[0]) and stalled and scope.from_rates(name):
                report.not_compared.add(name)
                continue
            record(report, name, unit, values[0], results[name][i], scope.size(name, results, i))
        for name, position in scope.positions(points).items():
            for a, axis in enumerate("xyz"):
                record(report, "points", "mm", position[a] * 1e3, results[f"{name}_{axis}"][i])
    return report


class Branches:
    """pin_susp's assembly at design, to tell an engine's pose on another branch of the
    mechanism: each loop's side (the chirality of its closure's branch points, which
    pin_susp's solver keeps, constraints.LoopBranch) and each body's handedness (four of
    its points, its joint's among them: a rigid body turns but is never mirrored — a
    point-based solve, which only keeps distances, can mirror one)."""

    def __init__(self, tree):
        from ..constraints import MEASURES, LoopBranch, chirality, pick_branch
        from ..model.deadcentre import tree_point_name

        design = {name: p.tolist() for name, (_, p) in tree.points.items()}
        self.checks = []  # (what flipped, measure, four point names, sign at design)
        for c in tree.closures:
            candidates = [b for b in c.branch_candidates if all(n in design for n in b)]
            if candidates:  # the solver's own choice of points (its fallback included)
                measure = MEASURES[c.branch_kind]
                names, v = pick_branch(candidates, measure, design.__getitem__)
                if abs(v) >= LoopBranch.DEGENERATE:
                    self.checks.append((f"the {c.name} loop", measure, names, np.sign(v)))
        on = {}
        for name, (body, _) in tree.points.items():
            on.setdefault(body, []).append(name)
        for b in tree.bodies:
            if b.joint is None:
                continue
            own = [tree_point_name(n, b.name, tree) for n in b.joint.defined_by]
            names = list(dict.fromkeys([n for n in own if n in design] + on.get(b.name, [])))
            quads = list(itertools.combinations(names[:8], 4))
            if not quads:
                continue
            best = max(quads, key=lambda q: abs(chirality(*(design[n] for n in q))))
            v = chirality(*(design[n] for n in best))
            if abs(v) > 1e-3:  # well clear of flat
                what = f"the {b.name.replace('_', ' ')} mirrored"
                self.checks.append((what, chirality, best, np.sign(v)))

    def flipped(self, positions: dict) -> str | None:
        """What is on another branch at these positions (name → (3,) m), or None."""
        for what, measure, names, sign in self.checks:
            if all(n in positions for n in names):
                if measure(*(np.asarray(positions[n]).tolist() for n in names)) * sign <= 0:
                    return what
        return None


def record(report, name, unit, theirs, ours, size=None) -> None:
    """Keep the largest difference; beyond the tolerance plus RELATIVE·size (default
    |ours|), the column disagrees."""
    if np.isnan(ours) and np.isnan(theirs):
        return
    diff = abs(ours - theirs) if not (np.isnan(ours) or np.isnan(theirs)) else np.inf
    report.differences[name] = max(report.differences.get(name, 0.0), float(diff))
    report.units[name] = unit
    size = abs(ours) if size is None or np.isnan(size) else size
    if not diff <= report.tolerance + RELATIVE * size:
        report.disagree.add(name)
