"""What a study's table says, as printed and drawn: the summary lines and the
main effects (docs/studies.md).

These read the variants' table (a DataFrame: the variables, the summary columns,
``converged``, ``error``; an optimisation's objectives) and the study's
description; they solve nothing. :mod:`pin_susp.study` runs the study and prints
these lines; :mod:`pin_susp.study.plots` draws the main effects — both from here,
so that neither needs the other for them.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from . import Study


def summary_lines(study: Study, variants, linear=None, curves=None) -> list[str]:
    """The study's summary as printed: counts, and per summary column its spread
    (and, from Monte Carlo, beside the first-order prediction); an optimisation's
    starts, and with ``curves`` (see curves()) each term's miss at the best."""
    ok = variants["converged"].to_numpy()
    lines = [
        f"{len(variants)} variants of {Path(study.geometry_path).name} through "
        f"{Path(study.sweep_path).name}: {int(ok.sum())} converged at every step"
        + (f", {int((~ok).sum())} not (converged = False)" if (~ok).any() else "")
    ]
    failed = variants.loc[variants["error"] != "", "error"]
    if len(failed):
        lines.append(f"  {len(failed)} variants could not be built, e.g.: {failed.iloc[0]}")
    if study.kind == "optimise":
        return lines + _optimise_lines(study, variants, curves)
    head = f"  {'column':44s} {'mean':>10s} {'std':>9s} {'min':>10s} {'max':>10s}"
    if linear is not None:
        head += f" {'linear std':>10s} {'max |diff|':>10s}"
    lines.append(head)
    for m in study.summary:
        for stat in ("static", "min", "max"):
            name = f"{m}_{stat}"
            x = variants[name].to_numpy(dtype=float)
            x = x[np.isfinite(x)]
            if not x.size:
                lines.append(f"  {name:44s} {'(no value)':>10s}")
                continue
            std = 0.0 if x.size < 2 or _constant(x) else x.std(ddof=1)
            line = f"  {name:44s} {x.mean():10.4g} {std:9.3g} {x.min():10.4g} {x.max():10.4g}"
            if linear is not None and name in linear:
                both = np.isfinite(variants[name].to_numpy(dtype=float))
                diff = np.abs(variants[name].to_numpy(dtype=float) - linear[name])[both]
                line += f" {linear[name].std(ddof=1):10.3g} {diff.max():10.3g}"
            lines.append(line)
    if study.kind == "doe":
        lines += _effect_lines(study, variants)
    return lines


def main_effects(study: Study, variants, column: str, bins: int = 5) -> dict[str, tuple]:
    """Per variable: (level centres, the column's mean at each) — the variants sorted
    into ``bins`` equal slices of the variable's range (a factorial's levels as they are)."""
    y = variants[column].to_numpy(dtype=float)
    out = {}
    for v in study.variables:
        x = variants[v.name].to_numpy(dtype=float)
        levels = np.unique(x)
        if len(levels) <= bins:
            centres = levels
            means = np.array([np.nanmean(y[x == c]) for c in levels])
        else:
            edges = np.linspace(v.low, v.high, bins + 1)
            which = np.clip(np.digitize(x, edges) - 1, 0, bins - 1)
            centres = 0.5 * (edges[:-1] + edges[1:])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                means = np.array([np.nanmean(y[which == b]) for b in range(bins)])
        out[v.name] = (centres, means)
    return out


def _effect_lines(study: Study, variants) -> list[str]:
    lines = ["  main effects (the spread of each column's mean over each variable's range):"]
    for m in study.summary:
        for stat in ("static", "min", "max"):
            column = f"{m}_{stat}"
            if _constant(variants[column].to_numpy(dtype=float)):
                lines.append(f"    {column}: the same for every variant")
                continue
            effects = main_effects(study, variants, column)
            spread = {k: float(np.nanmax(v[1]) - np.nanmin(v[1])) for k, v in effects.items()}
            top = sorted(spread.items(), key=lambda kv: -abs(kv[1]))[:4]
            text = ", ".join(f"{k} {s:.3g}" for k, s in top)
            lines.append(f"    {column}: {text}")
    return lines


def _constant(x: np.ndarray) -> bool:
    """All finite values equal to rounding (a column the variables do not move)."""
    x = x[np.isfinite(x)]
    return x.size == 0 or x.max() - x.min() <= 1e-12 * max(1.0, abs(float(x.mean())))


def _optimise_lines(study: Study, variants, curves=None) -> list[str]:
    order = variants.sort_values(["converged", "objective"], ascending=[False, True])
    lines = ["  start  objective at start -> found  evaluations"]
    for _, row in variants.iterrows():
        lines.append(
            f"  {int(row['variant_id']):5d}  {row['start_objective']:17.4g} -> "
            f"{row['objective']:.4g}  {int(row['evaluations']):11d}"
        )
    best = order.iloc[0]
    moves = ", ".join(f"{v.name} = {best[v.name]:+.3f} mm" for v in study.variables)
    lines.append(f"  best: start {int(best['variant_id'])}, objective {best['objective']:.4g}")
    lines.append(f"    {moves}")
    for term, curve in zip(study.terms, curves or [], strict=False):
        if curve.get("after") is None:
            continue
        miss = np.abs(curve["after"][1] - curve["after_target"])
        what = f"{term.metric} (change from design)" if term.relative else term.metric
        unit = _unit(term.metric)
        lines.append(
            f"    {what}: misses its target by {np.sqrt(np.mean(miss**2)):.3g} {unit} RMS, "
            f"{np.nanmax(miss):.3g} {unit} at most over the sweep"
        )
    return lines


def _unit(column: str) -> str:
    from ..columns.metrics import METRIC_BY_NAME

    for name, m in METRIC_BY_NAME.items():
        if column == name or column.startswith(f"{name}_"):
            return m.unit
    return ""
