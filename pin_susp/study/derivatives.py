"""What the exact hardpoint sensitivities give a study (docs/studies.md): the
optimiser's Jacobian, and Monte Carlo's first-order prediction of each summary column.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .data import AXES, Variable, shares, term_miss
from .variants import Variant

if TYPE_CHECKING:
    from .spec import Study


def objective_jacobian(v: Variant, sweep, reuse: dict | None = None) -> np.ndarray:
    """d r / d variables from the exact hardpoint sensitivities at every step and at
    design (a relative term's reference moves too); a curve's target moves with its
    x column. A step without a number (see term_miss) has a zero row. ``reuse``: a
    dict the caller keeps between the variants of one job (see sensitivities)."""
    job = v.job
    k = len(job.variables)
    n = sweep.steps
    if v.results is None:
        return np.zeros((len(job.terms) * n, k))
    wanted = {t.metric for t in job.terms} | {t.curve_x for t in job.terms if t.curve_x}
    at_design, steps = sensitivities(v.subject, sweep, v.results, wanted, reuse)
    columns = _columns(at_design.hardpoints, job.variables)
    blocks = []
    for t, w in zip(job.terms, shares(job.terms, n), strict=True):
        counted = term_miss(t, v.results, v.static)[1]
        rows = np.zeros((n, k))
        ref = _pick(at_design, t.metric, columns) if t.relative else 0.0
        for i, s in steps.items():
            if not counted[i]:
                continue
            d = _pick(s, t.metric, columns) - ref
            if t.curve is not None and t.curve_x in s.values:
                d = d - t.slope(v.results[t.curve_x][i]) * _pick(s, t.curve_x, columns)
            rows[i] = d
        blocks.append(w * rows)
    return np.vstack(blocks)


def _columns(hardpoints: list[str], variables: list[Variable]) -> tuple:
    return (
        np.array([hardpoints.index(v.key) for v in variables]),
        np.array([AXES.index(v.axis) for v in variables]),
    )


def _pick(s, name: str, columns) -> np.ndarray:
    """d(column)/d(each variable) from a Sensitivity (per mm)."""
    if name not in s.values:
        return np.zeros(len(columns[0]))
    return np.nan_to_num(s.values[name][columns])


def sensitivities(subject, sweep, results, only=None, reuse: dict | None = None) -> tuple:
    """The exact hardpoint sensitivities at design and at each converged step, holding
    there what the subject holds (``Assembly.held_at``): (Sensitivity, {step:
    Sensitivity}), one-sided names (``left_…``) on labelled corners; no steps where the
    sweep holds other than they hold (``Assembly.sensitivities_hold``: an axle's roll or
    heave sweep); ``only``: the columns wanted (the objective's, the summary's).
    ``reuse``: a dict kept by the caller, holding the last subject's sensitivity model,
    whose frames and Pinocchio data the next one of its structure shares (an
    optimiser's evaluations: the variants differ only in their numbers)."""
    from ..analyses.sensitivity import SubjectSensitivity

    like = None if reuse is None else reuse.get("model")
    model = SubjectSensitivity(subject, one_sided=True, like=like)
    if reuse is not None:
        reuse["model"] = model
    states = [(None, 0, None)]  # the design state, then the steps: all in one pass
    if subject.sensitivities_hold(sweep):  # else the steps' would hold other quantities
        converged = results["solver_converged"]
        states += [
            (results.meta["q"][i], i, subject.held_at(sweep, i))
            for i in range(len(results))
            if converged[i]
        ]
    at_design, *steps = model.at_many(states, only)
    return at_design, {s.step: s for s in steps}


def linear_prediction(study: Study, variants) -> dict[str, np.ndarray] | None:
    """The first-order prediction of each summary column from the exact hardpoint
    sensitivities at design and at every step (no re-solve): name → values per
    variant, for ``<metric>_static``, ``_min`` and ``_max`` — the steps' only where the
    sweep holds what the sensitivities hold (``Assembly.sensitivities_hold``: an axle's
    roll or heave sweep, the static column alone); None for a vehicle (its design
    state is its body's on the road, held otherwise than its sensitivities are)."""
    from ..model.sweep import load_sweep

    job = study.job()
    sweep = load_sweep(study.sweep_data)
    design = Variant(job, np.zeros(len(study.variables)), sweep, every_column=True)
    if design.results is None or not design.converged:
        return None
    if design.subject.on_road:  # a vehicle's design state holds its body on the road, not
        return None  # each wheel centre's height in the chassis: no prediction of it
    at_design, steps = sensitivities(design.subject, sweep, design.results, set(study.summary))
    columns = _columns(at_design.hardpoints, study.variables)
    d = variants[study.names].to_numpy(dtype=float)
    out = {}
    for m in study.summary:
        if m not in at_design.values:
            continue
        out[f"{m}_static"] = float(design.static[m][0]) + d @ _pick(at_design, m, columns)
        if not steps:  # an axle's roll or heave sweep: the static column alone
            continue
        per_step = np.stack(
            [design.results[m][i] + d @ _pick(s, m, columns) for i, s in steps.items()], axis=1
        )
        out[f"{m}_min"] = per_step.min(axis=1)
        out[f"{m}_max"] = per_step.max(axis=1)
    return out
