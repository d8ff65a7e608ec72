"""study.png: the figure of a study (docs/studies.md).

``study_figure`` draws, by the study's kind:

- Monte Carlo: a histogram (density) per summary column — a row per summary
  metric: its value at the variant's design state (``_static``), its least and
  its greatest over the sweep — with the first-order prediction from the
  hardpoint sensitivities overlaid as a step histogram on the same bins and,
  for a normal distribution, the Gaussian of the prediction's mean and standard
  deviation. Each panel notes the sampled and the predicted standard deviation.
- DOE: the main effects on every summary column (the same grid): per variable
  the column's mean over the variants in each slice of its range
  (``study_summary.main_effects``), against the variable (mm from design). With more
  than ``TOP`` variables each panel shows the ``TOP`` largest effects (the
  spread of the means) and says so; the legend lists them largest first.
- Optimise: a panel per objective term: the metric over the sweep for the
  design (before) and for the best start (after), and the target, against the
  sweep's x column; the legend gives each curve's RMS miss of the target, a
  note under the panels the best start's objective and variables.

Variants that did not converge may have NaN in their columns: NaN is skipped.
The figure is a plain ``matplotlib.figure.Figure`` (no pyplot state); write it
with ``plots.save_figure``.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from ..columns.metrics import METRIC_BY_NAME, Derivative
from ..errors import PinSuspError
from ..plots import lone_marker
from .summary import main_effects

TOP = 8  # main effects drawn per panel: the largest
STATS = (
    ("static", "at design"),
    ("min", "least over the sweep"),
    ("max", "greatest over the sweep"),
)
SAMPLED = "C0"
LINEAR = "C3"
KIND = {"doe": "design of experiments", "monte_carlo": "Monte Carlo", "optimise": "optimisation"}
PANEL_W, PANEL_H = 4.8, 3.3  # inches per panel
MIN_WIDTH = 7.5


def study_figure(study, variants, linear=None, curves=None) -> Figure:
    """The study's figure (see the module's docstring): ``variants`` the variants'
    table; ``linear`` (Monte Carlo) column → the first-order prediction per variant;
    ``curves`` (optimise) ``study.curves``'s list, one per objective term."""
    heading = _heading(study, variants)
    if study.kind == "monte_carlo":
        return _histograms(study, variants, linear, heading)
    if study.kind == "doe":
        return _main_effects(study, variants, heading)
    return _curves(study, variants, curves or [], heading)


def _heading(study, variants) -> str:
    n = len(variants)
    bad = int((~variants["converged"].astype(bool)).sum())
    what = "start" if study.kind == "optimise" else "variant"
    text = (
        f"pin_susp study, {KIND[study.kind]}: {n} {what}{'s' * (n != 1)} of "
        f"{Path(study.geometry_path).name} through {Path(study.sweep_path).name}, "
        f"{len(study.variables)} variable{'s' * (len(study.variables) != 1)}"
    )
    if study.kind == "monte_carlo":
        spread = "range = ±3σ" if study.distribution == "normal" else "uniform in range"
        text += f" ({study.distribution}: {spread})"
    if bad:
        text += f"\n{bad} did not converge at every step: their missing values are left out"
    return text


# ------------------------------------------------------------------- names


CORNERS = {"_left": "left", "_right": "right", "_fl": "front left", "_fr": "front right"}
CORNERS |= {"_rl": "rear left", "_rr": "rear right"}


def describe(column: str) -> tuple[str, str]:
    """A column's label and unit: from the metric registry (derivatives: the metric's
    unit per mm), a point's coordinate in mm, an axle's ``_left``/``_right`` and a
    vehicle's ``_fl`` ... ``_rr`` as its corner's column; else the name and no unit."""
    name, side = column, ""
    for s, corner in CORNERS.items():
        if column.endswith(s):
            name, side = column.removesuffix(s), f" ({corner})"
            break
    if name in METRIC_BY_NAME:
        m = METRIC_BY_NAME[name]
        return m.label + side, m.unit
    if name.startswith("deriv_") and "_wrt_" in name:
        metric, driver = name.removeprefix("deriv_").split("_wrt_", 1)
        if metric in METRIC_BY_NAME:
            d = Derivative(METRIC_BY_NAME[metric], driver)
            return d.label + side, d.unit
    if name == "motion_ratio":
        return "Motion ratio" + side, ""
    if name == "step_index":
        return "Step", ""
    if name[-2:] in ("_x", "_y", "_z"):
        return f"{name[:-2].replace('_', ' ')} {name[-1]}{side}", "mm"
    return column.replace("_", " "), ""


def _with_unit(text: str, unit: str) -> str:
    return f"{text} [{unit}]" if unit else text


def _grid(fig: Figure, rows: int, cols: int) -> list:
    """The panels; on each axis a few round ticks (AutoLocator's steps, fewer of them:
    the ticks, their labels and grid lines were most of the cost of the figure)."""
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=8)
        for axis, bins in ((ax.xaxis, 6), (ax.yaxis, 5)):
            axis.set_major_locator(MaxNLocator(nbins=bins, steps=[1, 2, 2.5, 5, 10]))
    return list(axes)


def _title(ax, text: str) -> None:
    """A panel's title, high enough above it for the y axis's multiplier (1e7), if any
    (placed, not moved at each save to clear the tick labels: a sixth of the cost)."""
    ax.set_title(text, fontsize=10, y=1.0, pad=13.0)


def _finite(x) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    return x[np.isfinite(x)]


def _std(x: np.ndarray) -> float:
    return float(x.std(ddof=1)) if x.size > 1 else 0.0


def _summary_columns(study, variants) -> list[list[str]]:
    """A row per summary metric: its _static, _min and _max columns (those present)."""
    rows = []
    for m in study.summary:
        row = [f"{m}_{s}" for s, _ in STATS if f"{m}_{s}" in variants.columns]
        if row:
            rows.append(row)
    if not rows:
        raise PinSuspError("the variants' table has none of the study's summary columns")
    return rows


def _column_texts(column: str, units: dict) -> tuple[str, str, str]:
    """Title (column [unit]), axis label (label, what the column is [unit]), unit: the
    study's own (``units``: Study.column_units) where it has one."""
    metric, _, stat = column.rpartition("_")
    label, unit = describe(metric)
    unit = units.get(metric, unit)
    what = dict(STATS).get(stat, stat)
    return _with_unit(column, unit), _with_unit(f"{label}, {what}", unit), unit


def _layout(fig: Figure, rows: list[list[str]]) -> tuple[list, list]:
    """The panels of a summary grid (a row per metric) and the columns they show;
    unused panels removed."""
    cols = max(len(r) for r in rows)
    axes = _grid(fig, len(rows), cols)
    pairs = []
    for i, row in enumerate(rows):
        for j in range(cols):
            ax = axes[i * cols + j]
            if j < len(row):
                pairs.append((ax, row[j]))
            else:
                fig.delaxes(ax)
    return [a for a, _ in pairs], [c for _, c in pairs]


def _figure(
    rows: int,
    cols: int,
    heading: str,
    width: float = PANEL_W,
    extra_height: float = 0.9,
    height: float = PANEL_H,
) -> Figure:
    """A figure for a grid of panels, at least MIN_WIDTH wide, with the heading wrapped
    to its width; no layout engine: ``_place`` puts everything in its place, once."""
    inches = max(width * cols, MIN_WIDTH)
    fig = Figure(figsize=(inches, height * rows + extra_height))
    lines = [textwrap.fill(line, int(inches * 10)) for line in heading.splitlines()]
    fig.suptitle("\n".join(lines), fontsize=12, va="top", gid="heading")
    return fig


# The layout, in inches, set once rather than found at every save by a layout engine
# (a constrained layout was half of the cost of drawing the figure): the panels'
# texts have the same sizes in every study, only their numbers change.
LEFT = 0.8  # left of a panel: its y tick labels and label
RIGHT = 0.15  # right of a panel
TITLE = 0.38  # above a panel: its title
BELOW = 0.55  # under a panel: its x tick labels and label
EDGE = 0.1  # the figure's edge to the heading, and to the footnote
HEAD_LINE = 0.21  # a line of the heading (12 pt)
LEGEND_ROW = 0.22  # a row of the figure's legend (9 pt), and LEGEND_PAD around it
LEGEND_PAD = 0.12
LEGEND_COLUMNS = 4  # the figure's legend: its keys in rows of (at most) this many
FOOT_LINE = 0.15  # a line of the footnote (8 pt)
MIN_PANEL = 1.5  # the least a panel's axes may span either way


def _place(fig: Figure, rows: int, cols: int, right: float = RIGHT) -> None:
    """Place the parts of a figure: the heading at the top, the figure's legend and then
    the footnote at the bottom, and the grid of panels between, each with room for
    its title and axis labels (and ``right`` inches right of it: a panel's legend)."""
    w, h = fig.get_size_inches()
    heading = [t for t in fig.texts if t.get_gid() == "heading"]
    footnote = [t for t in fig.texts if t.get_gid() == "footnote"]
    head = EDGE + HEAD_LINE * (fig.get_suptitle().count("\n") + 1)
    foot = EDGE + FOOT_LINE * (footnote[0].get_text().count("\n") + 1) if footnote else EDGE
    legend = 0.0
    for lg in fig.legends:
        legend = LEGEND_PAD + LEGEND_ROW * -(-len(lg.get_texts()) // LEGEND_COLUMNS)
    # (a long heading, footnote or legend: the figure grows rather than its panels shrink)
    w = max(w, cols * (LEFT + right + MIN_PANEL))
    h = max(h, head + legend + foot + rows * (TITLE + BELOW + MIN_PANEL))
    fig.set_size_inches(w, h)
    panel_w = w / cols - LEFT - right
    panel_h = (h - head - legend - foot) / rows - TITLE - BELOW
    fig.subplots_adjust(
        left=LEFT / w,
        right=1.0 - right / w,
        top=1.0 - (head + TITLE) / h,
        bottom=(foot + legend + BELOW) / h,
        wspace=(LEFT + right) / panel_w,
        hspace=(TITLE + BELOW) / panel_h,
    )
    for text in heading:
        text.set_y(1.0 - EDGE / h)
    for lg in fig.legends:
        lg.set_bbox_to_anchor((0.5, (foot + 0.5 * LEGEND_PAD) / h), fig.transFigure)
    for text in footnote:
        text.set_y(0.5 * EDGE / h)


def _footnote(fig: Figure, text: str) -> None:
    """A note under the panels (room made for it by ``_place``)."""
    fig.supxlabel(text, x=0.01, ha="left", va="bottom", fontsize=8, gid="footnote")


def _note(ax, text: str, where: str = "upper right") -> None:
    x, ha = (0.98, "right") if "right" in where else (0.02, "left")
    y, va = (0.97, "top") if "upper" in where else (0.03, "bottom")
    ax.text(
        x,
        y,
        text,
        transform=ax.transAxes,
        ha=ha,
        va=va,
        fontsize=7.5,
        multialignment="left",
        bbox={"boxstyle": "round,pad=0.3", "fc": "white", "ec": "0.75", "alpha": 0.85},
        gid="note",
    )


# ------------------------------------------------------------------ Monte Carlo


def _histograms(study, variants, linear, heading: str) -> Figure:
    rows = _summary_columns(study, variants)
    cols = max(len(r) for r in rows)
    fig = _figure(len(rows), cols, heading, extra_height=1.2)
    axes, columns = _layout(fig, rows)
    gaussian = study.distribution == "normal"
    for ax, column in zip(axes, columns, strict=True):
        predicted = None if linear is None else linear.get(column)
        _histogram(ax, column, variants[column], predicted, gaussian, study.column_units)
    # the legend's keys as drawn in a histogram (a panel of one value draws lines)
    drawn = {name for ax in axes for name in ax.get_legend_handles_labels()[1]}
    keys = {
        "sampled (solved)": Patch(color=SAMPLED, alpha=0.55),
        "first-order prediction": Patch(fill=False, edgecolor=LINEAR, lw=1.3),
        "normal (prediction's mean, σ)": Line2D([], [], color="k", lw=1.1),
    }
    keys = {name: h for name, h in keys.items() if name in drawn}
    if keys:
        fig.legend(keys.values(), keys.keys(), loc="lower center", ncol=LEGEND_COLUMNS, fontsize=9)
    if linear is None:
        why = "the design did not solve"
        if study.on_road:
            why = "a vehicle's design state holds its body on the road"
        _footnote(fig, f"no first-order prediction ({why})")
    _place(fig, len(rows), cols)
    return fig


def bin_edges(sampled: np.ndarray, predicted: np.ndarray | None) -> np.ndarray:
    """Common bins for the sampled and predicted values: the sampled values' 'auto'
    count (10 to 60), over the range of both."""
    both = sampled if predicted is None else np.concatenate([sampled, predicted])
    lo, hi = float(both.min()), float(both.max())
    if not hi > lo:  # one value: a narrow bin around it
        half = max(abs(lo) * 1e-6, 1e-12)
        return np.array([lo - half, hi + half])
    count = len(np.histogram_bin_edges(sampled, bins="auto")) - 1 if sampled.size > 1 else 10
    return np.linspace(lo, hi, int(np.clip(count, 10, 60)) + 1)


def _flat(x: np.ndarray, scale: float) -> bool:
    """Whether x is one value, to rounding (a column the variables do not move)."""
    return not float(np.ptp(x)) > 1e-9 * max(1.0, scale)


def _histogram(ax, column: str, values, predicted, gaussian: bool, units: dict) -> None:
    title, xlabel, unit = _column_texts(column, units)
    _title(ax, title)
    ax.set_xlabel(xlabel, fontsize=8)
    ax.set_ylabel(_with_unit("density", f"1/{unit}" if unit else ""), fontsize=8)
    sampled = _finite(values)
    line = _finite(predicted) if predicted is not None else None
    if line is not None and not line.size:
        line = None
    if not sampled.size:
        _note(ax, "no value: no variant converged here", "upper left")
        return
    scale = float(np.abs(sampled if line is None else np.r_[sampled, line]).max())
    if _flat(sampled, scale) and (line is None or _flat(line, scale)):
        _one_value(ax, sampled, line, unit)
        return
    edges = bin_edges(sampled, line)
    ax.hist(
        sampled,
        bins=edges,
        density=True,
        histtype="stepfilled",  # one patch, not a bar per bin
        color=SAMPLED,
        alpha=0.55,
        label="sampled (solved)",
        gid="sampled",
    )
    notes = [f"n = {sampled.size}", f"σ sampled {_std(sampled):.3g} {unit}".rstrip()]
    if line is not None:
        ax.hist(
            line,
            bins=edges,
            density=True,
            histtype="step",
            color=LINEAR,
            lw=1.3,
            label="first-order prediction",
            gid="linear",
        )
        mean, std = float(line.mean()), _std(line)
        notes.append(f"σ linear {std:.3g} {unit}".rstrip())
        if not _flat(sampled, scale):
            notes[-1] += f" ({std / _std(sampled) - 1.0:+.2%})"
        if gaussian and not _flat(line, scale):
            lo, hi = edges[0], edges[-1]
            x = np.linspace(min(lo, mean - 4 * std), max(hi, mean + 4 * std), 241)
            y = np.exp(-0.5 * ((x - mean) / std) ** 2) / (std * np.sqrt(2.0 * np.pi))
            ax.plot(
                x, y, "-", color="k", lw=1.1, label="normal (prediction's mean, σ)", gid="gaussian"
            )
            ax.set_xlim(lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
    _note(ax, "\n".join(notes), "upper left" if _skew_right(sampled) else "upper right")
    ax.ticklabel_format(axis="x", useOffset=False)
    ax.set_ylim(0.0, ax.get_ylim()[1] * 1.25)  # room for the note


def _one_value(ax, sampled: np.ndarray, line: np.ndarray | None, unit: str) -> None:
    """A column with one value (and one predicted): no spread to draw, a line at each."""
    value = float(np.mean(sampled))
    ax.axvline(value, color=SAMPLED, lw=2.5, alpha=0.7, label="sampled (solved)", gid="sampled")
    notes = [f"n = {sampled.size}", f"the same at every variant: {value:.6g} {unit}".rstrip()]
    if line is not None:
        predicted = float(np.mean(line))
        ax.axvline(predicted, color=LINEAR, lw=1.3, ls="--", label="first-order prediction")
        notes.append(f"first-order prediction: {predicted:.6g} {unit}".rstrip())
    ends = [value] if line is None else [value, predicted]
    middle, half = 0.5 * (min(ends) + max(ends)), 0.5 * (max(ends) - min(ends))
    half = 1.5 * max(half, 0.01 * max(abs(middle), 1.0))
    ax.set_xlim(middle - half, middle + half)
    ax.set_yticks([])
    ax.ticklabel_format(axis="x", useOffset=False)
    _note(ax, "\n".join(notes), "upper left")


def _skew_right(x: np.ndarray) -> bool:
    """Whether the bulk of x lies right of the middle of its range (the note goes left)."""
    return bool(np.median(x) > 0.5 * (x.min() + x.max()))


# ----------------------------------------------------------------------- DOE


def _main_effects(study, variants, heading: str) -> Figure:
    rows = _summary_columns(study, variants)
    cols = max(len(r) for r in rows)
    names = study.names
    shared = len(names) <= TOP  # every variable in every panel: one legend, a colour each
    fig = _figure(len(rows), cols, heading, width=PANEL_W + (0.0 if shared else 1.6))
    axes, columns = _layout(fig, rows)
    colours = {name: f"C{k}" for k, name in enumerate(names)} if shared else None
    for ax, column in zip(axes, columns, strict=True):
        effects = main_effects(study, variants, column)
        _effects_panel(ax, column, effects, len(names), colours, study.column_units)
    if shared:
        handles = {}
        for ax in axes:
            for h, name in zip(*ax.get_legend_handles_labels(), strict=True):
                handles.setdefault(name, h)
        order = [n for n in names if n in handles]
        fig.legend(
            [handles[n] for n in order],
            order,
            loc="lower center",
            ncol=min(len(order), LEGEND_COLUMNS) or 1,
            fontsize=9,
        )
    # many variables: each panel's own legend, right of it
    _place(fig, len(rows), cols, RIGHT + (0.0 if shared else _widest_legend(fig, axes) + 0.1))
    return fig


def _widest_legend(fig: Figure, axes) -> float:
    """The widest of the panels' own legends, in inches (measured: the names vary)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    legends = [ax.get_legend() for ax in axes if ax.get_legend() is not None]
    return max((lg.get_window_extent(renderer).width / fig.dpi for lg in legends), default=0.0)


def effect_sizes(effects: dict[str, tuple]) -> dict[str, float]:
    """Per variable: the spread (max − min) of the column's means over its slices,
    NaN when no slice has a mean; largest first (NaN last)."""
    out = {}
    for name, (_, means) in effects.items():
        finite = _finite(means)
        out[name] = float(finite.max() - finite.min()) if finite.size else np.nan
    return dict(sorted(out.items(), key=lambda kv: -kv[1] if np.isfinite(kv[1]) else np.inf))


def _effects_panel(
    ax, column: str, effects: dict, count: int, colours: dict | None, units: dict
) -> None:
    """The main effects on one column: a line per variable (``colours``: a colour each,
    the figure's legend) or, of many, the TOP largest (ranked colours, a legend here)."""
    title, _, unit = _column_texts(column, units)
    sizes = effect_sizes(effects)
    drawn = [k for k in sizes if np.isfinite(sizes[k])]
    if colours is None:
        drawn = drawn[:TOP]
    _title(ax, title)
    ax.set_ylabel(_with_unit("mean", unit), fontsize=8)
    ax.set_xlabel("variable, from design [mm]", fontsize=8)
    for k, name in enumerate(drawn):
        centres, means = effects[name]
        ax.plot(
            centres,
            means,
            "-",
            marker=".",
            color=colours[name] if colours else f"C{k % 10}",
            lw=1.4,
            label=name if colours else f"{name} ({sizes[name]:.2g})",
            gid=name,
        )
    if not drawn:
        _note(ax, "no value: no variant converged here", "upper left")
        return
    levels = np.concatenate([_finite(effects[name][1]) for name in drawn])
    if levels.size and np.ptp(levels) > 1e-4 * np.abs(levels).max():
        ax.ticklabel_format(axis="y", useOffset=False)  # (a spread far finer: an offset,
    # not tick labels of nine digits that the panel cannot hold)
    if _flat(levels, float(np.abs(levels).max())):
        level = levels[0]
        _note(ax, f"the same at every variant: {level:.6g} {unit}".rstrip())
    elif colours is None:
        ax.legend(
            fontsize=6.5,
            title=f"the {len(drawn)} largest of {count} effects\n"
            + _with_unit("(spread of the means", unit)
            + ")",
            title_fontsize=6.5,
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            borderaxespad=0.0,
            handlelength=1.5,
        )


# ------------------------------------------------------------------- optimise


def _curves(study, variants, curves: list[dict], heading: str) -> Figure:
    n = max(len(curves), 1)
    cols = min(n, 3)
    rows = -(-n // cols)
    fig = _figure(rows, cols, heading, PANEL_W + 0.6, 1.2, PANEL_H + 0.7)
    axes = _grid(fig, rows, cols)
    for ax in axes[len(curves) :]:
        fig.delaxes(ax)
    for ax, entry in zip(axes, curves, strict=False):
        _curve_panel(ax, entry)
    if not curves:
        _note(axes[0], "no objective term to draw", "upper left")
    _footnote(fig, _best_text(study, variants, int(fig.get_figwidth() * 13)))
    _place(fig, rows, cols)
    return fig


def _best_text(study, variants, width: int) -> str:
    """The best start, its objective, and its variables, ``width`` characters to a line."""
    if "objective" not in variants.columns or not np.isfinite(variants["objective"]).any():
        return "no start found an objective"
    row = variants.sort_values("objective").iloc[0]
    moves = [f"{v.name} = {row[v.name]:+.3f} mm" for v in study.variables]
    lines, line = [], ""
    for m in moves:  # a few to a line: ~30 variables stay readable
        if line and len(line) + len(m) + 2 > width:
            lines.append(line)
            line = ""
        line += (", " if line else "") + m
    lines.append(line)
    head = (
        f"best: start {int(row['variant_id'])} of {len(variants)}, objective "
        f"{row['objective']:.4g} (weighted RMS; {row['start_objective']:.4g} at its start)"
    )
    return "\n".join([head, *lines])


def rms_miss(y, target) -> float:
    """The RMS of (y − target) over the steps where y has a value."""
    y, target = np.asarray(y, dtype=float), np.asarray(target, dtype=float)
    ok = np.isfinite(y) & np.isfinite(target)
    return float(np.sqrt(np.mean((y[ok] - target[ok]) ** 2))) if ok.any() else np.nan


def _curve_panel(ax, entry: dict) -> None:
    metric, relative = entry["metric"], entry.get("relative", False)
    label, unit = describe(metric)
    x_name = entry.get("x", "step_index")
    x_label, x_unit = describe(x_name)
    _title(ax, label + (": change from design state" if relative else ""))
    ax.set_ylabel(_with_unit(("Δ " if relative else "") + metric, unit), fontsize=8)
    ax.set_xlabel(_with_unit(x_label, x_unit), fontsize=8)
    notes, targets = [], []
    # the design's line wider, under the best's: both show where they coincide
    for which, name, colour, lw in (
        ("before", "design (before)", "0.6", 3.0),
        ("after", "best (after)", "C0", 1.5),
    ):
        curve = entry.get(which)
        if curve is None:
            notes.append(f"{name}: did not solve")
            continue
        x, y = (np.asarray(a, dtype=float) for a in curve)
        target = entry.get(f"{which}_target")
        if target is not None:
            targets.append((x, np.asarray(target, dtype=float)))
            name += f", RMS miss {rms_miss(y, target):.3g} {unit}".rstrip()
        ax.plot(x, y, "-", color=colour, lw=lw, marker=lone_marker(y), label=name, gid=which)
    if targets:
        x = np.concatenate([t[0] for t in targets])
        t = np.concatenate([t[1] for t in targets])
        ok = np.isfinite(x) & np.isfinite(t)
        order = np.argsort(x[ok], kind="stable")
        ax.plot(x[ok][order], t[ok][order], "--", color="k", lw=1.1, label="target", gid="target")
    if notes:
        _note(ax, "\n".join(notes), "lower right")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8, loc="best")
    ax.ticklabel_format(axis="y", useOffset=False)
