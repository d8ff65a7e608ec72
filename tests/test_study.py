"""Studies (docs/studies.md): variants, their rows against direct sweeps, Monte Carlo
against the first-order prediction, the bump-steer optimisation, bad input."""

from __future__ import annotations

import io
import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
import yaml

from pin_susp import Corner, Target, load_sweep
from pin_susp.cli import main
from pin_susp.study import Variable, load_study, run_study, variant_data, variant_table

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
BUMP = EXAMPLES / "bump_rack_held.yaml"


def write_study(folder: Path, body: dict, name: str = "study.yaml") -> Path:
    """A study file in ``folder`` whose geometry and sweep are the examples (absolute)."""
    data = {"version": 1, "geometry": str(EXAMPLES / "double_wishbone.yaml"), "sweep": str(BUMP)}
    data.update(body)
    path = folder / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def run_cli(args: list[str], capsys) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def read_csv(path: Path) -> pd.DataFrame:
    return pd.read_csv(path, comment="#")


LHS = {
    "variables": [
        {"point": "trackrod_inboard", "axis": "z", "range": [-15, 15]},
        {"point": "upper_wishbone_outboard", "axis": "z", "range": [-10, 10]},
        {"point": "lower_wishbone_inboard_front", "axis": "y", "range": [-5, 5]},
    ],
    "kind": "doe",
    "doe": {"method": "latin_hypercube", "samples": 6, "seed": 3},
    "summary": ["camber", "roadwheel_angle", "deriv_roadwheel_angle_wrt_hub_z", "anti_dive"],
    "batch_size": 4,
}


# ---------------------------------------------------------------- the variants


def test_variants_of_each_method_fill_their_boxes(tmp_path):
    three = LHS["variables"]
    ff = load_study(
        write_study(
            tmp_path,
            {"variables": three, "kind": "doe", "doe": {"method": "full_factorial", "levels": 3}},
        )
    )
    table = variant_table(ff)
    assert table.shape == (27, 3)
    for j, v in enumerate(three):
        assert sorted(set(table[:, j])) == pytest.approx(list(np.linspace(*v["range"], 3)))
    assert len({tuple(r) for r in table}) == 27  # every combination once

    lhs = load_study(
        write_study(tmp_path, LHS | {"doe": {"method": "latin_hypercube", "samples": 50}})
    )
    table = variant_table(lhs)
    for j, v in enumerate(three):  # one sample in each of the 50 strata of every variable
        low, high = v["range"]
        strata = np.floor((table[:, j] - low) / (high - low) * 50).astype(int)
        assert sorted(strata) == list(range(50))
    assert np.array_equal(table, variant_table(lhs))  # the seed fixes them

    sobol = load_study(write_study(tmp_path, LHS | {"doe": {"method": "sobol", "samples": 64}}))
    table = variant_table(sobol)
    assert table.shape == (64, 3)
    assert (table >= [-15, -10, -5]).all() and (table <= [15, 10, 5]).all()

    mc = load_study(
        write_study(
            tmp_path,
            {
                "variables": three,
                "kind": "monte_carlo",
                "monte_carlo": {"samples": 20000, "seed": 7},
            },
        )
    )
    table = variant_table(mc)  # normal, range = ±3σ about its middle
    assert table.mean(axis=0) == pytest.approx([0, 0, 0], abs=0.05)
    assert table.std(axis=0) == pytest.approx([5, 10 / 3, 5 / 3], rel=0.02)


def test_all_hardpoints_varies_every_coordinate(tmp_path):
    study = load_study(
        write_study(
            tmp_path,
            {
                "variables": {"all_hardpoints": {"tolerance": 0.5}},
                "kind": "monte_carlo",
                "monte_carlo": {"samples": 10},
            },
        )
    )
    corner = Corner(EXAMPLES / "double_wishbone.yaml")
    assert len(study.variables) == 3 * len(corner.geometry.hardpoints)
    assert {(v.low, v.high) for v in study.variables} == {(-0.5, 0.5)}


def test_variant_data_moves_only_its_coordinates():
    base = yaml.safe_load((EXAMPLES / "double_wishbone.yaml").read_text())
    moved = variant_data(
        base,
        [Variable("trackrod_inboard", "z", -1, 1), Variable("axle_outboard", "x", -1, 1)],
        [2.5, -1.25],
        axle=False,
    )
    assert moved["hardpoints"]["trackrod_inboard"] == {"x": 50, "y": 200, "z": 252.5}
    assert moved["hardpoints"]["axle_outboard"]["x"] == -21.25
    assert base["hardpoints"]["trackrod_inboard"]["z"] == 250  # the design is untouched
    rest = {
        k: v
        for k, v in moved["hardpoints"].items()
        if k not in ("trackrod_inboard", "axle_outboard")
    }
    assert all(rest[k] == base["hardpoints"][k] for k in rest)


# ------------------------------------------------ rows against direct sweeps


def test_each_variant_equals_a_direct_sweep_of_its_geometry(tmp_path, capsys):
    """variants.parquet and steps.parquet against `pin-susp sweep` on each variant's
    geometry file, written out here; the static column against a one-step sweep at design."""
    study_path = write_study(tmp_path, LHS)
    out = tmp_path / "out"
    code, text, err = run_cli(
        ["study", study_path, "-o", out, "--scheduler", "none", "--steps"], capsys
    )
    assert code == 0, err
    variants = pd.read_parquet(out / "variants.parquet")
    steps = pd.read_parquet(out / "steps.parquet")
    assert list(variants["variant_id"]) == list(range(6))
    assert len(steps) == 6 * 21
    study = load_study(study_path)
    design_sweep = tmp_path / "design.yaml"
    sweep = yaml.safe_load(BUMP.read_text())
    sweep["steps"] = 1
    for t in sweep["targets"]:
        t["start"] = t["stop"] = 0
    design_sweep.write_text(yaml.safe_dump(sweep))
    for vid in (0, 5):
        row = variants.iloc[vid]
        deltas = [row[v.name] for v in study.variables]
        geometry = tmp_path / f"variant{vid}.yaml"
        geometry.write_text(
            yaml.safe_dump(variant_data(study.geometry_data, study.variables, deltas, False))
        )
        csv = tmp_path / f"variant{vid}.csv"
        assert run_cli(["sweep", geometry, BUMP, "-o", csv, "-q"], capsys)[0] == 0
        direct = read_csv(csv)
        mine = steps[steps["variant_id"] == vid].reset_index(drop=True)
        assert list(mine.columns) == ["variant_id", *direct.columns]
        for c in direct.columns:
            a, b = direct[c].to_numpy(), mine[c].to_numpy()
            if a.dtype.kind == "f" or b.dtype.kind == "f":
                a, b = a.astype(float), b.astype(float)
                assert np.array_equal(np.isnan(a), np.isnan(b)), c
                # a kinematic instant centre, a pole through infinity in bump (7.9 km
                # out here): its last digits relative to its size (validate/scopes.py)
                rtol = 1e-9 if "instant_center" in c else 0.0
                assert np.allclose(a, b, rtol=rtol, atol=1e-9, equal_nan=True), c
            else:
                assert (a == b).all(), c
        static_csv = tmp_path / f"static{vid}.csv"
        assert run_cli(["sweep", geometry, design_sweep, "-o", static_csv, "-q"], capsys)[0] == 0
        static = read_csv(static_csv)
        for m in ("camber", "roadwheel_angle", "deriv_roadwheel_angle_wrt_hub_z"):
            assert row[f"{m}_static"] == pytest.approx(static[m][0], abs=1e-9)
            assert row[f"{m}_min"] == pytest.approx(direct[m].min(), abs=1e-9)
            assert row[f"{m}_max"] == pytest.approx(direct[m].max(), abs=1e-9)
        assert row["converged"] and row["steps_failed"] == 0 and row["error"] == ""


def test_parquet_outputs_read_everywhere_with_nulls_and_units(tmp_path):
    import dask.dataframe as dd
    import pyarrow.dataset as ds

    out = tmp_path / "out"
    outcome = run_study(load_study(write_study(tmp_path, LHS)), out, scheduler=None, steps=True)
    assert outcome.computed == outcome.batches == 2
    steps_pandas = pd.read_parquet(out / "steps.parquet")
    steps_arrow = ds.dataset(out / "steps.parquet", format="parquet").to_table()
    steps_dask = dd.read_parquet(out / "steps.parquet").compute()
    assert len(steps_pandas) == steps_arrow.num_rows == len(steps_dask) == 6 * 21
    # anti_dive is blank in this corner's CSV (no brake bias): a null in Parquet, not NaN
    column = steps_arrow.column("anti_dive")
    assert column.null_count == len(column)
    assert pq.read_table(out / "variants.parquet").column("anti_dive_static").null_count == 6
    units = pq.read_schema(next((out / "steps.parquet").iterdir())).metadata[b"units"]
    assert b'"camber": "deg"' in units
    assert not (out / ".parts").exists()


def test_results_convert_to_pandas():
    corner = Corner(EXAMPLES / "double_wishbone.yaml")
    results = corner.run_sweep(BUMP)
    frame = results.to_pandas()
    assert list(frame.columns) == list(results.columns)
    assert np.array_equal(frame["camber"].to_numpy(), results["camber"])
    assert frame.attrs["units"]["camber"] == "deg"
    assert frame["solver_converged"].dtype == bool


def test_a_local_cluster_gives_the_serial_numbers(tmp_path, monkeypatch):
    import dask
    import psutil

    # the workers' scratch space (and any temporary file) inside tmp_path
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    for name in ("DASK_TEMPORARY_DIRECTORY", "TMPDIR"):
        monkeypatch.setenv(name, str(scratch))
    study = load_study(write_study(tmp_path, LHS))
    serial = run_study(study, tmp_path / "serial", scheduler=None).variants
    with dask.config.set({"temporary-directory": str(scratch)}):
        outcome = run_study(study, tmp_path / "local", scheduler="local", workers=2)
    pd.testing.assert_frame_equal(serial, outcome.variants, check_exact=True)
    assert any(scratch.iterdir())  # the workers wrote here, not in the system's /tmp
    # the cluster is gone: no process of ours still listens
    mine = {p.pid for p in psutil.Process().children(recursive=True)}
    listening = [c for c in psutil.net_connections("tcp") if c.status == "LISTEN" and c.pid in mine]
    assert not listening


def test_an_axle_study_moves_one_side_and_equals_its_direct_sweep(tmp_path, capsys):
    body = {
        "geometry": str(EXAMPLES / "axle_front.yaml"),
        "sweep": str(EXAMPLES / "roll.yaml"),
        "variables": [
            {"point": "trackrod_outboard", "axis": "z", "side": "left", "range": [-5, 5]},
        ],
        "kind": "doe",
        "doe": {"method": "full_factorial", "levels": 2},
        "summary": ["roadwheel_angle_left", "roadwheel_angle_right", "roll_center_z"],
    }
    study_path = write_study(tmp_path, body)
    out = tmp_path / "out"
    code, _, err = run_cli(["study", study_path, "-o", out, "--scheduler", "none"], capsys)
    assert code == 0, err
    variants = pd.read_parquet(out / "variants.parquet")
    assert list(variants["d_left_trackrod_outboard_z"]) == [-5.0, 5.0]
    study = load_study(study_path)
    for vid in (0, 1):
        data = variant_data(study.geometry_data, study.variables, [variants.iloc[vid, 1]], True)
        assert (
            data["hardpoints"]["right"]["trackrod_outboard"]["z"]
            != (data["hardpoints"]["left"]["trackrod_outboard"]["z"])
        )
        geometry = tmp_path / f"axle{vid}.yaml"
        geometry.write_text(yaml.safe_dump(data))
        csv = tmp_path / f"axle{vid}.csv"
        assert run_cli(["sweep", geometry, EXAMPLES / "roll.yaml", "-o", csv, "-q"], capsys)[0] == 0
        direct = read_csv(csv)
        # its design state: a sweep of one step with every target at its design value
        sweep = yaml.safe_load((EXAMPLES / "roll.yaml").read_text())
        sweep["steps"] = 1
        for t in sweep["targets"]:
            t["start"] = t["stop"] = 0
        design_sweep = tmp_path / "design_roll.yaml"
        design_sweep.write_text(yaml.safe_dump(sweep))
        at_design = tmp_path / f"axle{vid}_design.csv"
        command = ["sweep", geometry, design_sweep, "-o", at_design, "-q"]
        assert run_cli(command, capsys)[0] == 0
        design = read_csv(at_design)
        for m in body["summary"]:
            assert variants.iloc[vid][f"{m}_min"] == pytest.approx(direct[m].min(), abs=1e-9)
            assert variants.iloc[vid][f"{m}_max"] == pytest.approx(direct[m].max(), abs=1e-9)
            assert variants.iloc[vid][f"{m}_static"] == pytest.approx(
                design[m][0], abs=1e-9, nan_ok=True
            )
    # the design pose is as drawn (a moved trackrod end changes the rod's length, not the
    # static toe); in roll the left side's toe moves with it, the right one's does not
    left = variants["roadwheel_angle_left_min"]
    right = variants["roadwheel_angle_right_min"]
    assert abs(left[0] - left[1]) > 0.05
    # the right side moves only through the roll target's contact patches (the left
    # wheel's camber moves its patch): a hundredth of the left's change at most
    assert abs(right[0] - right[1]) < 0.01 * abs(left[0] - left[1])
    assert variants["roadwheel_angle_left_static"][0] == variants["roadwheel_angle_left_static"][1]


# ------------------------------------------------ Monte Carlo and its prediction


def _monte_carlo(tmp_path, tolerance: float, samples: int = 24) -> tuple:
    body = {
        "variables": {"all_hardpoints": {"tolerance": tolerance}},
        "kind": "monte_carlo",
        "monte_carlo": {"samples": samples, "seed": 2},
        "summary": ["camber", "roadwheel_angle", "deriv_roadwheel_angle_wrt_hub_z"],
    }
    folder = tmp_path / f"mc{tolerance}"
    folder.mkdir()
    outcome = run_study(load_study(write_study(folder, body)), folder / "out", scheduler=None)
    return outcome, pq.read_table(folder / "out" / "variants.parquet").to_pandas()


def test_tiny_tolerances_match_the_linear_prediction(tmp_path):
    outcome, variants = _monte_carlo(tmp_path, 1e-3)
    for name in ("camber_static", "roadwheel_angle_max", "deriv_roadwheel_angle_wrt_hub_z_min"):
        sampled = variants[name].to_numpy()
        linear = variants[f"{name}_linear"].to_numpy()
        change = np.abs(sampled - sampled.mean()).max()
        assert change > 1e-7  # the tolerances move it
        # second order in 1e-3 mm: the prediction agrees to far below the change
        assert np.abs(sampled - linear).max() < 1e-3 * change


def test_large_tolerances_report_the_difference(tmp_path):
    from pin_susp.study import summary_lines

    outcome, variants = _monte_carlo(tmp_path, 5.0, samples=16)
    diff = np.abs(variants["roadwheel_angle_max"] - variants["roadwheel_angle_max_linear"]).max()
    assert diff > 1e-3  # nonlinear at ±5 mm
    lines = summary_lines(outcome.study, variants, outcome.linear)
    assert "max |diff|" in lines[1]
    row = next(line for line in lines if line.strip().startswith("roadwheel_angle_max"))
    assert float(row.split()[-1]) == pytest.approx(diff, rel=1e-2)


# ------------------------------------------------ the optimisation


def test_bump_steer_optimisation_flattens_toe_and_best_yaml_reproduces_it(tmp_path, capsys):
    """examples/study_bump_steer.yaml: ≤ 0.01° of toe change over ±30 mm, checked by a
    direct sweep of best.yaml; the objective re-computed from that sweep."""
    folder = tmp_path / "ex"
    folder.mkdir()
    for name in ("study_bump_steer.yaml", "macpherson.yaml", "bump_rack_held.yaml"):
        shutil.copy(EXAMPLES / name, folder / name)
    data = yaml.safe_load((folder / "study_bump_steer.yaml").read_text())
    data["optimise"]["starts"] = 2  # the example's 4, halved for the suite's time
    (folder / "study_bump_steer.yaml").write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    code, text, err = run_cli(
        ["study", folder / "study_bump_steer.yaml", "-o", out, "--scheduler", "none"], capsys
    )
    assert code == 0, err
    variants = pd.read_parquet(out / "variants.parquet")
    best = variants.sort_values("objective").iloc[0]
    assert (variants["objective"] <= variants["start_objective"]).all()
    csv = tmp_path / "best.csv"
    assert run_cli(["sweep", out / "best.yaml", BUMP, "-o", csv, "-q"], capsys)[0] == 0
    direct = read_csv(csv)
    design = Corner(out / "best.yaml").solve_pose(
        [Target("wheel_center", "z", 0.0), Target("trackrod_inboard", "y", 0.0)]
    )
    toe_change = direct["roadwheel_angle"] - design.metrics["roadwheel_angle"]
    assert np.abs(toe_change).max() <= 0.01
    rms = math.sqrt(np.mean(toe_change**2))
    assert best["objective"] == pytest.approx(rms, rel=1e-9, abs=1e-12)
    assert f"{best['objective']:.4g}" in text
    # the design's bump steer was far from flat: the optimiser did the work
    assert best["start_objective"] > 20 * best["objective"]


def assert_exact_jacobian(study, sweep, x: np.ndarray, h: float = 1e-4) -> None:
    """The optimiser's Jacobian against central differences of full solves, each
    objective term's block of rows against its own scale."""
    from pin_susp.study import Variant, objective_jacobian

    job = study.job()
    exact = objective_jacobian(Variant(job, x, sweep), sweep)

    def residuals(at):
        return Variant(job, at, sweep).residuals()

    central = np.stack(
        [(residuals(x + h * e) - residuals(x - h * e)) / (2 * h) for e in np.eye(len(x))], axis=1
    )
    n = sweep.steps
    for k in range(len(study.terms)):
        rows = slice(n * k, n * k + n)
        scale = np.abs(central[rows]).max()
        assert scale > 0 and np.abs(exact[rows] - central[rows]).max() < 1e-6 * scale, k


def test_objective_jacobian_is_the_derivative_of_the_residuals(tmp_path):

    body = {
        "variables": [
            {"point": "trackrod_inboard", "axis": "z", "range": [-20, 20]},
            {"point": "trackrod_outboard", "axis": "x", "range": [-20, 20]},
        ],
        "kind": "optimise",
        "optimise": {
            "objective": [
                {"metric": "roadwheel_angle", "relative": True, "target": 0.0},
                {
                    "metric": "camber",
                    "curve": {"x": "wheel_travel", "points": [[-30, -1.5], [30, -2.5]]},
                    "weight": 2,
                },
                # over a column that the hardpoints move, with points inside the sweep's
                # range: three segments and both ends extended
                {
                    "metric": "scrub_radius",
                    "curve": {
                        "x": "half_track",
                        "points": [[959.6, -39], [959.9, -40], [960.1, -38]],
                    },
                    "weight": 0.5,
                },
            ]
        },
    }
    study = load_study(write_study(tmp_path, body))
    assert_exact_jacobian(study, load_sweep(BUMP), np.array([3.0, -2.0]))


# ---------------------------------------------------------------- bad input


BAD = [
    (
        {"variables": [{"point": "nowhere", "axis": "z", "range": [-1, 1]}]},
        "variables[0].point: unknown hardpoint 'nowhere'",
    ),
    (
        {"variables": [{"point": "trackrod_inboard", "axis": "w", "range": [-1, 1]}]},
        "variables[0].axis: expected one of x, y, z",
    ),
    (
        {"variables": [{"point": "trackrod_inboard", "axis": "z", "range": [1, 1]}]},
        "variables[0].range: empty range [1, 1]",
    ),
    (
        {
            "variables": [
                {"point": "trackrod_inboard", "axis": "z", "range": [-1, 1], "side": "left"}
            ]
        },
        "variables[0].side: a corner has one side",
    ),
    ({"doe": {"method": "latin_hypercube", "samples": 0}}, "doe.samples: must be >= 1, got 0"),
    ({"doe": {"method": "latin_hypercube", "samples": -3}}, "doe.samples: must be >= 1, got -3"),
    ({"doe": {"method": "grid", "samples": 3}}, "doe.method: expected one of full_factorial"),
    ({"summary": ["camberr"]}, "summary[0]: unknown column 'camberr'"),
    ({"kind": "monte_carlo"}, "monte_carlo: missing key"),
    ({"sweep": "/nonexistent/sweep.yaml"}, "/nonexistent/sweep.yaml: file not found"),
]


@pytest.mark.parametrize(("change", "message"), BAD)
def test_bad_study_files_get_one_line_and_nothing_written(tmp_path, capsys, change, message):
    body = dict(LHS) | change
    path = write_study(tmp_path, body)
    out = tmp_path / "out"
    code, text, err = run_cli(["study", path, "-o", out, "--scheduler", "none"], capsys)
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("pin-susp: error: ")
    assert message in err, err
    assert "Traceback" not in err
    assert not out.exists()


def test_an_axle_variable_needs_its_side(tmp_path, capsys):
    body = dict(LHS) | {
        "geometry": str(EXAMPLES / "axle_front.yaml"),
        "sweep": str(EXAMPLES / "roll.yaml"),
        "summary": ["roll_center_z"],
    }
    code, _, err = run_cli(["study", write_study(tmp_path, body), "-o", tmp_path / "o"], capsys)
    assert code == 2 and "variables[0].side: missing key" in err


def test_an_output_directory_with_other_data_is_refused(tmp_path, capsys):
    first = write_study(tmp_path, LHS, "first.yaml")
    other = write_study(tmp_path, LHS | {"doe": {"method": "sobol", "samples": 4}}, "other.yaml")
    out = tmp_path / "out"
    assert run_cli(["study", first, "-o", out, "--scheduler", "none", "-q"], capsys)[0] == 0
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*")}
    code, _, err = run_cli(["study", other, "-o", out, "--scheduler", "none"], capsys)
    assert code == 2 and "holds the data of another study" in err
    code, _, err = run_cli(["study", first, "-o", out, "--scheduler", "none"], capsys)
    assert code == 2 and "already finished here" in err
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*")} == before
    stranger = tmp_path / "stranger"
    stranger.mkdir()
    (stranger / "notes.txt").write_text("mine")
    code, _, err = run_cli(["study", first, "-o", stranger, "--scheduler", "none"], capsys)
    assert code == 2 and "holds no study" in err
    assert [p.name for p in stranger.iterdir()] == ["notes.txt"]


def test_workers_and_scheduler_flags_are_checked(tmp_path, capsys):
    path = write_study(tmp_path, LHS)
    code, _, err = run_cli(["study", path, "-o", tmp_path / "a", "--workers", "0"], capsys)
    assert code == 2 and "--workers must be 1 or more" in err
    code, _, err = run_cli(["study", path, "-o", tmp_path / "b", "--scheduler", "bogus"], capsys)
    assert code == 2 and "expected an address like tcp://HOST:PORT" in err
    code, _, err = run_cli(
        ["study", path, "-o", tmp_path / "c", "--scheduler", "none", "--workers", "2"], capsys
    )
    assert code == 2 and "--workers sizes the local cluster" in err
    assert not any((tmp_path / d).exists() for d in "abc")


def test_summary_prints_spread_and_files(tmp_path, capsys):
    code, text, _ = run_cli(
        ["study", write_study(tmp_path, LHS), "-o", tmp_path / "o", "--scheduler", "none"], capsys
    )
    assert code == 0
    assert "6 variants of double_wishbone.yaml through bump_rack_held.yaml: 6 converged" in text
    variants = pd.read_parquet(tmp_path / "o" / "variants.parquet")
    line = next(x for x in io.StringIO(text) if x.strip().startswith("camber_static"))
    mean, std = map(float, line.split()[1:3])
    assert mean == pytest.approx(variants["camber_static"].mean(), rel=1e-3)
    assert std == pytest.approx(variants["camber_static"].std(), rel=1e-2)
    assert f"wrote {tmp_path / 'o' / 'study.png'}" in text


def test_an_axle_objective_jacobian_is_exact_and_roll_sweeps_are_refused(tmp_path, capsys):
    """On an axle's sweep of both wheel heights and the rack, the optimiser's Jacobian
    (one-sided sensitivities) against central differences of full solves."""

    sweep = {
        "version": 1,
        "steps": 5,
        "targets": [
            {
                "point": "wheel_center",
                "side": "left",
                "direction": {"axis": "z"},
                "start": -20,
                "stop": 20,
            },
            {
                "point": "wheel_center",
                "side": "right",
                "direction": {"axis": "z"},
                "start": 20,
                "stop": -20,
            },
            {
                "point": "trackrod_inboard",
                "side": "left",
                "direction": {"axis": "y"},
                "start": 0,
                "stop": 0,
            },
        ],
    }
    (tmp_path / "sweep.yaml").write_text(yaml.safe_dump(sweep))
    body = {
        "geometry": str(EXAMPLES / "axle_front.yaml"),
        "sweep": str(tmp_path / "sweep.yaml"),
        "variables": [
            {"point": "trackrod_outboard", "axis": "z", "side": "left", "range": [-5, 5]},
            {"point": "upper_wishbone_outboard", "axis": "y", "side": "right", "range": [-5, 5]},
        ],
        "kind": "optimise",
        "optimise": {
            "objective": [
                {"metric": "roadwheel_angle_left", "relative": True, "target": 0},
                {"metric": "track", "target": 1500},
                {
                    "metric": "camber_right",
                    "curve": {"x": "wheel_travel_right", "points": [[-20, -1], [20, -2]]},
                },
            ]
        },
        "summary": ["roadwheel_angle_left"],
    }
    study = load_study(write_study(tmp_path, body))
    assert_exact_jacobian(study, load_sweep(tmp_path / "sweep.yaml"), np.array([1.0, -2.0]))
    roll = body | {"sweep": str(EXAMPLES / "roll.yaml")}
    code, _, err = run_cli(
        ["study", write_study(tmp_path, roll, "roll.yaml"), "-o", tmp_path / "o"], capsys
    )
    assert code == 2 and "optimise: on an axle" in err


def cut_short(path, outdir) -> None:
    """The study run into ``outdir`` and interrupted after its first batch."""

    def interrupt(done, total):
        if done == 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_study(load_study(path), outdir, scheduler=None, progress=interrupt)


def test_resume_finishes_a_run_cut_short_whatever_the_path_spelling(tmp_path, monkeypatch):
    from pin_susp.study import finished_batches

    path = write_study(tmp_path, LHS)  # 6 variants in 2 batches
    cut_short(path, tmp_path / "o")
    assert finished_batches(tmp_path / "o") == 1
    assert not (tmp_path / "o" / "variants.parquet").exists()
    monkeypatch.chdir(tmp_path)  # the same file, typed relative to another folder
    resumed = run_study(load_study("study.yaml"), "o", scheduler=None, resume=True)
    assert (resumed.computed, resumed.batches) == (1, 2)
    reference = run_study(load_study(path), tmp_path / "reference", scheduler=None)
    pd.testing.assert_frame_equal(resumed.variants, reference.variants, check_exact=True)
    assert finished_batches(tmp_path / "o") is None  # finished: nothing left to resume


def test_a_run_cut_into_other_batches_is_not_resumed_and_says_why(tmp_path, capsys):
    """A run cut short by an earlier version (its manifest: 64 batches where this one
    cuts the study into 2) is refused by --resume in one line naming both counts, and
    the directory is left as it was."""
    import json

    from pin_susp.study import MANIFEST

    path = write_study(tmp_path, LHS)  # 6 variants in 2 batches
    cut_short(path, tmp_path / "o")
    manifest = tmp_path / "o" / MANIFEST
    data = json.loads(manifest.read_text()) | {"batches": 64}
    manifest.write_text(json.dumps(data))
    before = sorted(p.name for p in (tmp_path / "o").rglob("*"))
    code, _, err = run_cli(["study", path, "-o", tmp_path / "o", "--resume"], capsys)
    assert code == 2 and err.count("\n") == 1, err
    assert "cut into 64 batches, where this pin_susp cuts it into 2" in err
    assert "cannot be resumed" in err
    assert sorted(p.name for p in (tmp_path / "o").rglob("*")) == before


def test_a_curve_target_extends_its_end_segments():
    from pin_susp.study import Term

    t = Term("camber", curve_x="wheel_travel", curve=np.array([[-10, -0.5], [0, -1.0], [25, -2.5]]))
    assert t.goal(np.array([-30.0, -10.0, -5.0, 0.0, 10.0, 25.0, 35.0])) == pytest.approx(
        [0.5, -0.5, -0.75, -1.0, -1.6, -2.5, -3.1]
    )
    assert t.slope(np.array([-30.0, 5.0, 40.0])) == pytest.approx([-0.05, -0.06, -0.06])


def test_a_silent_port_is_not_a_scheduler_and_says_so_within_10_s(tmp_path, capsys):
    import socket
    import threading
    import time

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    accepted = []
    threading.Thread(target=lambda: accepted.append(server.accept()), daemon=True).start()
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    try:
        started = time.monotonic()
        code, _, err = run_cli(
            ["study", write_study(tmp_path, LHS), "-o", tmp_path / "o", "--scheduler", address],
            capsys,
        )
        elapsed = time.monotonic() - started
    finally:
        for connection, _ in accepted:
            connection.close()
        server.close()
    assert code == 2 and err.count("\n") == 1
    assert f"--scheduler {address}: no Dask scheduler answered within 8 s" in err
    assert elapsed < 10.0
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            {
                "kind": "optimise",
                "optimise": {"objective": [{"metric": "anti_dive", "target": 0}]},
                "doe": None,
                "batch_size": None,
            },
            "optimise.objective[0].metric: anti_dive is undefined at this geometry's design",
        ),
        (
            {
                "kind": "optimise",
                "optimise": {"objective": [{"metric": "camber", "target": 0}]},
                "doe": None,
            },
            "batch_size: an optimisation runs one start per task",
        ),
        ({"doe": {"method": "sobol", "samples": 4, "seed": 2**32}}, "doe.seed: expected a whole"),
        (
            {
                "variables": {"all_hardpoints": {"tolerance": 1}},
                "doe": {"method": "sobol", "samples": 2_000_000},
            },
            "doe: 2000000 variants x 30 variables is beyond",
        ),
    ],
)
def test_more_bad_study_files(tmp_path, capsys, change, message):
    body = {k: v for k, v in (dict(LHS) | change).items() if v is not None}
    code, _, err = run_cli(["study", write_study(tmp_path, body), "-o", tmp_path / "o"], capsys)
    assert code == 2 and err.count("\n") == 1 and message in err, err
    assert not (tmp_path / "o").exists()


def test_a_large_seed_and_an_empty_output_path(tmp_path, capsys):
    body = dict(LHS) | {"doe": {"method": "latin_hypercube", "samples": 2, "seed": 123456789}}
    path = write_study(tmp_path, body)
    assert (
        run_cli(["study", path, "-o", tmp_path / "o", "--scheduler", "none", "-q"], capsys)[0] == 0
    )
    code, _, err = run_cli(["study", path, "-o", "", "--scheduler", "none"], capsys)
    assert code == 2 and "the output directory's path is empty" in err
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "study.json").write_text("[1, 2]")
    code, _, err = run_cli(["study", path, "-o", tmp_path / "bad", "--resume"], capsys)
    assert code == 2 and "study.json: unreadable: not a study's directory" in err
