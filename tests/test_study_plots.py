"""study.png (docs/studies.md "Outputs"): Monte Carlo histograms with the first-order
prediction, DOE main effects, the optimiser's curves before and after; drawn from
synthetic variants whose numbers are known, and once from a real run of the CLI."""

from __future__ import annotations

import dataclasses
import struct
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from pin_susp.cli import main
from pin_susp.plots import save_figure
from pin_susp.study import Variable, load_study
from pin_susp.study.plots import TOP, describe, study_figure
from pin_susp.study.summary import main_effects

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
SUMMARY = ["camber", "roadwheel_angle", "deriv_roadwheel_angle_wrt_hub_z"]
STATS = ("static", "min", "max")


def write_study(folder: Path, body: dict) -> Path:
    data = {
        "version": 1,
        "geometry": str(EXAMPLES / "double_wishbone.yaml"),
        "sweep": str(EXAMPLES / "bump_rack_held.yaml"),
        "variables": [
            {"point": "trackrod_inboard", "axis": "z", "range": [-15, 15]},
            {"point": "upper_wishbone_outboard", "axis": "z", "range": [-10, 10]},
            {"point": "lower_wishbone_outboard", "axis": "y", "range": [-5, 5]},
        ],
        "summary": SUMMARY,
    }
    data.update(body)
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def doe(tmp_path_factory):
    """A DOE study of three variables, read from a file (the other kinds: replaced)."""
    folder = tmp_path_factory.mktemp("study")
    body = {"kind": "doe", "doe": {"method": "latin_hypercube", "samples": 8}}
    return load_study(write_study(folder, body))


def panels(fig) -> list:
    return [ax for ax in fig.axes if ax.get_visible()]


def footnote(fig) -> str:
    """The note under the panels."""
    (text,) = fig.findobj(lambda a: a.get_gid() == "footnote")
    return text.get_text()


def synthetic(study, n: int, seed: int = 0) -> pd.DataFrame:
    """Variants with random variables and summary columns; the first two did not
    converge (NaN in every summary column)."""
    rng = np.random.default_rng(seed)
    table = {"variant_id": np.arange(n)}
    for v in study.variables:
        table[v.name] = rng.uniform(v.low, v.high, n)
    table["converged"] = np.r_[False, False, np.ones(n - 2, bool)]
    for k, m in enumerate(study.summary):
        for j, stat in enumerate(STATS):
            x = rng.normal(k + 0.1 * j, 0.05 * (k + 1), n)
            x[:2] = np.nan
            table[f"{m}_{stat}"] = x
    return pd.DataFrame(table)


# ------------------------------------------------------------------ Monte Carlo


def test_monte_carlo_histograms_are_densities_with_the_prediction_overlaid(doe):
    study = dataclasses.replace(doe, kind="monte_carlo", distribution="normal")
    variants = synthetic(study, 400)
    rng = np.random.default_rng(7)
    columns = [f"{m}_{s}" for m in SUMMARY for s in STATS]
    # a prediction near the samples, for every variant (the failed ones too)
    linear = {
        c: np.nan_to_num(variants[c].to_numpy(), nan=float(np.nanmean(variants[c])))
        + rng.normal(0.0, 0.01, 400)
        for c in columns
    }
    fig = study_figure(study, variants, linear)
    axes = panels(fig)
    assert len(axes) == 9  # a row per summary metric: static, min, max
    for ax, column in zip(axes, columns, strict=True):
        unit = "deg/mm" if column.startswith("deriv_") else "deg"
        assert ax.get_title() == f"{column} [{unit}]"
        sampled = variants[column].to_numpy()[2:]  # the NaN rows skipped
        # one filled outline: up the first bin's left edge, along the bins' tops (a
        # corner each side of each bin), down and back along the base
        (filled,) = [p for p in ax.patches if p.get_gid() == "sampled"]
        xy = filled.get_xy()
        bins = (len(xy) - 1) // 4
        edges, heights = xy[0 : 2 * bins + 1 : 2, 0], xy[1 : 2 * bins : 2, 1]
        widths = np.diff(edges)
        assert np.sum(widths * heights) == pytest.approx(1.0, rel=1e-12)
        # the bins span the sampled and the predicted values (to rounding)
        both = np.r_[sampled, linear[column]]
        assert edges[[0, -1]] == pytest.approx([both.min(), both.max()], rel=1e-12, abs=1e-15)
        edges[[0, -1]] = both.min(), both.max()
        counts, _ = np.histogram(sampled, edges)
        assert counts.sum() == 398  # every sampled value in a bar
        assert heights == pytest.approx(counts / (398 * widths), rel=1e-12)
        # the prediction's step histogram on the same bins, a density too
        (step,) = [p for p in ax.patches if p.get_gid() == "linear"]
        tops = step.get_xy()[1:-1:2, 1]  # the polygon's top left corners, bin by bin
        predicted, _ = np.histogram(linear[column], edges, density=True)
        assert tops == pytest.approx(predicted, rel=1e-12)
        # the Gaussian: log y is a parabola, -(x - μ)² / 2σ² + const
        (gauss,) = [line for line in ax.get_lines() if line.get_gid() == "gaussian"]
        x, y = gauss.get_xydata().T
        a, b, _ = np.polyfit(x, np.log(y), 2)
        sigma, mu = np.sqrt(-1.0 / (2.0 * a)), -b / (2.0 * a)
        assert mu == pytest.approx(np.mean(linear[column]), rel=1e-9, abs=1e-12)
        assert sigma == pytest.approx(np.std(linear[column], ddof=1), rel=1e-9)
        assert np.trapezoid(y, x) == pytest.approx(1.0, abs=1e-3)  # ±4σ at least
        # the note: the sampled and the predicted spread
        (note,) = [t for t in ax.texts if t.get_gid() == "note"]
        assert f"σ sampled {np.std(sampled, ddof=1):.3g} {unit}" in note.get_text()
        assert f"σ linear {np.std(linear[column], ddof=1):.3g} {unit}" in note.get_text()
        assert "n = 398" in note.get_text()
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == ["sampled (solved)", "first-order prediction", "normal (prediction's mean, σ)"]
    assert "2 did not converge" in fig.get_suptitle()


def test_a_uniform_study_has_no_gaussian_and_no_prediction_is_said(doe, tmp_path):
    study = dataclasses.replace(doe, kind="monte_carlo", distribution="uniform", summary=["camber"])
    variants = synthetic(study, 50)
    linear = {f"camber_{s}": variants[f"camber_{s}"].fillna(0.0).to_numpy() for s in STATS}
    fig = study_figure(study, variants, linear)
    assert len(panels(fig)) == 3
    for ax in panels(fig):
        assert not [line for line in ax.get_lines() if line.get_gid() == "gaussian"]
        assert [p for p in ax.patches if p.get_gid() == "linear"]
    # a column the variables do not move (to rounding): its value, not a histogram
    variants["camber_static"] = -1.5 + np.r_[np.nan, np.nan, np.zeros(48)]
    variants.loc[5, "camber_static"] += 2e-16
    linear["camber_static"] = np.full(50, -1.49)
    ax = panels(study_figure(study, variants, linear))[0]
    assert not ax.patches  # no bars
    (note,) = [t for t in ax.texts if t.get_gid() == "note"]
    assert note.get_text() == (
        "n = 48\nthe same at every variant: -1.5 deg\nfirst-order prediction: -1.49 deg"
    )
    assert ax.get_lines()[0].get_xdata()[0] == pytest.approx(-1.5)
    fig = study_figure(study, variants, None)  # an axle: no first-order prediction
    for ax in panels(fig):
        assert not [p for p in ax.patches if p.get_gid() == "linear"]
    assert "no first-order prediction" in footnote(fig)
    save_figure(fig, tmp_path / "study.png")
    assert (tmp_path / "study.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ----------------------------------------------------------------------- DOE


def test_main_effects_are_the_means_per_level(doe):
    levels = np.array([-1.0, 0.0, 1.0])
    grid = np.stack(np.meshgrid(levels * 15, levels * 10, levels * 5, indexing="ij"), -1)
    grid = grid.reshape(-1, 3)
    variants = pd.DataFrame(grid, columns=doe.names)
    variants.insert(0, "variant_id", np.arange(len(grid)))
    variants["converged"] = True
    d1, d2, d3 = grid.T
    for k, m in enumerate(SUMMARY):
        for s in STATS:
            variants[f"{m}_{s}"] = (k + 1) * (0.02 * d1 - 0.05 * d2) + 0.001 * d3**2
    variants.loc[0, "camber_static"] = np.nan  # a failed variant: skipped
    fig = study_figure(doe, variants)
    axes = panels(fig)
    assert len(axes) == 9
    for ax in axes:
        column = ax.get_title().split(" [")[0]
        assert ax.get_ylabel() == f"mean [{describe(column.rpartition('_')[0])[1]}]"
        for v in doe.variables:
            (line,) = [ln for ln in ax.get_lines() if ln.get_gid() == v.name]
            x, y = line.get_xydata().T
            assert x == pytest.approx(levels * v.high)
            # independent: pandas' group means (NaN skipped)
            expected = variants.groupby(v.name)[column].mean().to_numpy()
            assert y == pytest.approx(expected, rel=1e-12)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == doe.names  # one legend, every variable, its colour in every panel
    colours = {ln.get_gid(): ln.get_color() for ln in axes[0].get_lines()}
    assert all(colours[ln.get_gid()] == ln.get_color() for ax in axes for ln in ax.get_lines())
    # a column the variables do not move (to rounding) says so
    variants["roadwheel_angle_static"] = 0.25 + 1e-17 * np.arange(len(variants))
    ax = panels(study_figure(doe, variants))[3]
    assert ax.get_title() == "roadwheel_angle_static [deg]"
    (note,) = [t for t in ax.texts if t.get_gid() == "note"]
    assert note.get_text() == "the same at every variant: 0.25 deg"
    assert not [t for t in panels(fig)[3].texts if t.get_gid() == "note"]


def test_many_variables_show_the_largest_effects(doe):
    k = 12
    variables = [Variable(f"point_{i}", "x", -1.0, 1.0) for i in range(k)]
    study = dataclasses.replace(doe, variables=variables, summary=["camber"])
    rng = np.random.default_rng(3)
    d = rng.uniform(-1.0, 1.0, (600, k))
    weights = np.array([0.3, -2.0, 0.1, 1.5, -0.7, 0.05, 3.0, -0.2, 1.1, 0.6, -0.9, 0.01])
    variants = pd.DataFrame(d, columns=study.names)
    variants["converged"] = True
    for s in STATS:
        variants[f"camber_{s}"] = d @ weights
    fig = study_figure(study, variants)
    axes = panels(fig)
    assert len(axes) == 3
    # independent: the spread of each variable's bin means, from main_effects' own bins
    effects = main_effects(study, variants, "camber_static")
    spread = {n: np.ptp(means) for n, (_, means) in effects.items()}
    expected = sorted(spread, key=lambda n: -spread[n])[:TOP]
    assert expected[:3] == ["d_point_6_x", "d_point_1_x", "d_point_3_x"]  # the largest weights
    drawn = [ln.get_gid() for ln in axes[0].get_lines()]
    assert drawn == expected
    legend = axes[0].get_legend()
    assert legend.get_title().get_text().startswith(f"the {TOP} largest of {k} effects")
    assert [t.get_text() for t in legend.get_texts()] == [
        f"{n} ({spread[n]:.2g})" for n in expected
    ]


# ------------------------------------------------------------------- optimise


def test_optimise_draws_each_term_before_and_after(doe, tmp_path):
    study = dataclasses.replace(doe, kind="optimise")
    x = np.linspace(-30.0, 30.0, 7)
    toe = {"before": (x, 0.013 * x), "after": (x, 0.001 * x**2 / 30.0)}
    camber = {"before": (x, -0.02 * x - 1.0), "after": (x + 0.5, -0.025 * x - 1.2)}
    curve_target = {"before": -1.25 - 0.025 * x, "after": -1.25 - 0.025 * (x + 0.5)}
    curves = [
        {"metric": "roadwheel_angle", "relative": True, "x": "wheel_travel", **toe}
        | {"before_target": np.zeros(7), "after_target": np.zeros(7)},
        {"metric": "camber", "relative": False, "x": "wheel_travel", **camber}
        | {f"{k}_target": v for k, v in curve_target.items()},
    ]
    variants = pd.DataFrame(
        {
            "variant_id": [0, 1],
            "d_trackrod_inboard_z": [4.0, 1.25],
            "d_upper_wishbone_outboard_z": [-3.0, 0.5],
            "d_lower_wishbone_outboard_y": [0.0, -2.0],
            "converged": [True, True],
            "objective": [0.3, 0.02],
            "start_objective": [0.9, 0.4],
        }
    )
    fig = study_figure(study, variants, curves=curves)
    axes = panels(fig)
    assert len(axes) == 2
    for ax, entry in zip(axes, curves, strict=True):
        assert ax.get_xlabel() == "Wheel travel (+ bump) [mm]"
        lines = {ln.get_gid(): ln for ln in ax.get_lines()}
        for which in ("before", "after"):
            assert np.array_equal(lines[which].get_xdata(), entry[which][0])
            assert np.array_equal(lines[which].get_ydata(), entry[which][1])
            miss = np.sqrt(np.mean((entry[which][1] - entry[f"{which}_target"]) ** 2))
            assert f"RMS miss {miss:.3g} deg" in lines[which].get_label()
        tx, ty = lines["target"].get_xydata().T
        assert np.all(np.diff(tx) >= 0.0)
        assert ty == pytest.approx(
            (-1.25 - 0.025 * tx) if entry["metric"] == "camber" else np.zeros(14)
        )
    assert axes[0].get_ylabel() == "Δ roadwheel_angle [deg]"
    assert axes[1].get_ylabel() == "camber [deg]"
    note = footnote(fig)
    assert "best: start 1 of 2, objective 0.02" in note
    assert "d_trackrod_inboard_z = +1.250 mm" in note
    assert "d_lower_wishbone_outboard_y = -2.000 mm" in note
    # a design that did not solve: the best alone, and it says so
    curves[0]["before"] = None
    fig = study_figure(study, variants, curves=curves)
    ax = panels(fig)[0]
    assert [ln.get_gid() for ln in ax.get_lines()] == ["after", "target"]
    assert any("did not solve" in t.get_text() for t in ax.texts)
    save_figure(fig, tmp_path / "study.png")
    assert (tmp_path / "study.png").stat().st_size > 10_000


# ----------------------------------------------------------------------- CLI


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_the_cli_writes_study_png(tmp_path, capsys):
    source = write_study(
        tmp_path, {"kind": "doe", "doe": {"method": "latin_hypercube", "samples": 8, "seed": 2}}
    )
    out = tmp_path / "out"
    assert main(["study", str(source), "-o", str(out), "--scheduler", "none", "-q"]) == 0
    assert capsys.readouterr().err == ""
    width, height = png_size(out / "study.png")
    # three panels a row (static, min, max), a row per summary metric, at 110 dpi
    assert 1400 < width < 1800 and 1000 < height < 1400
    assert (out / "study.png").stat().st_size > 50_000
