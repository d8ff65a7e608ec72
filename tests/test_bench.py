"""The benchmark runs, and the solver's effort stays within bounds (no timing asserted)."""

import json
import os
import subprocess
import sys

from conftest import ROOT


def test_benchmark_quick_mode_runs_with_few_iterations_and_tiny_residuals(tmp_path):
    out = tmp_path / "bench.json"
    proc = subprocess.run(
        [
            sys.executable,
            str(ROOT / "benchmarks" / "bench_sweep.py"),
            "--quick",
            "--json",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        env=os.environ | {"TMPDIR": str(tmp_path)},  # its command-line runs' files in tmp_path
    )
    assert proc.returncode == 0, proc.stderr
    assert "baselines" in proc.stdout and "x (target" in proc.stdout
    report = json.loads(out.read_text())
    assert set(report["corners"]) == {
        "double_wishbone.yaml",
        "camber_shim.yaml",
        "pushrod_rocker.yaml",
        "macpherson.yaml",
        "multilink_front.yaml",
        "fixed_toe_link.yaml",
        "multilink_rear.yaml",
        "semi_trailing_arm.yaml",
    }
    for entry in report["corners"].values():
        step = entry["per_step"]
        assert step["converged"]
        assert step["max_residual_mm"] <= 1e-9
        assert step["iterations_median"] <= 2  # the predictor leaves one Newton step, mostly
        assert step["iterations_max"] <= 5
        assert step["iterations_first_step"] <= 5
        for baseline in ("a_fd_jacobian", "b_analytic_jacobian"):
            assert entry["baselines"][baseline]["max_residual_mm"] <= 1e-9
        # bump and steer: 15 or more exact derivative columns; bump alone: 9 or more
        rack = entry["sweep"] == "bump+steer"
        assert entry["sweep_101"]["derivative_columns"] >= (15 if rack else 9)
    for name in ("macpherson.yaml", "multilink_front.yaml", "multilink_rear.yaml"):
        assert report["corners"][name]["vs"]["ratio"] > 0  # measured, never asserted
    grid = report["corners"]["double_wishbone.yaml"]["grid"]
    assert grid["converged"] == grid["points"] and grid["max_residual_mm"] <= 1e-9
    long = report["long"]  # issue 17's sweep: every column, solved at once
    assert long["converged"] and long["max_residual_mm"] <= 1e-9 and long["columns"] >= 80
    for baseline in long["baselines"].values():
        assert baseline["max_residual_mm"] <= 1e-9
    assert [sorted(pair["wall_s"]) for pair in report["cli"]] == [["2001", "201"]]


def test_study_benchmark_runs_a_small_slice(tmp_path):
    """bench_study.py's quick slice: every way runs and reports every variant (no timing
    asserted; `make bench` has the figures). Its clusters listen on 127.0.0.1 only."""
    out = tmp_path / "study.json"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_study.py"), "--variants", "64"]
        + ["--doe", "64", "--optimise-runs", "1", "--assemblies", "3", "--cli-runs", "0"]
        + ["--json", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
        # its temporary folders and the workers' scratch space inside tmp_path
        env=os.environ | {"TMPDIR": str(tmp_path), "DASK_TEMPORARY_DIRECTORY": str(tmp_path)},
    )
    assert proc.returncode == 0, proc.stderr
    assert "2 workers over 1" in proc.stdout
    report = json.loads(out.read_text())
    assert set(report["ways"]) == {"serial", "local, 1 worker", "local, 2 workers"}
    for way in [*report["ways"].values(), *report["doe"].values()]:
        assert way["variants"] == 64 and way["running"] > 0
    assert set(report["assemblies"]) == {"axle", "vehicle"}
    for way in report["assemblies"].values():
        assert way["variants"] == 3 and way["scripted"] > 0
    assert report["doe_cli"] == {}  # (the DOE through the CLI: `make bench`)


def test_attitude_benchmark_quick_slice(tmp_path):
    """bench_attitude.py's quick slice (a list of 10 points, a 3 x 5 grid, two rounds):
    every point converges and every figure is reported (no timing asserted)."""
    out = tmp_path / "attitude.json"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_attitude.py"), "--quick"]
        + ["--json", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert "ms per point" in proc.stdout and "a sweep step" in proc.stdout
    report = json.loads(out.read_text())
    assert set(report["sets"]) == {"list of 10", "grid 3 x 5"}
    for s in report["sets"].values():
        assert s["converged"] == s["points"]
        assert s["max_equilibrium_residual_N"] <= 1e-7
        for kind in ("run", "equilibria"):
            assert s["ms_per_point"][kind] > 0 and s["ratio_to_sweep_step"][kind] > 0
    assert report["baseline_ms_per_step"] > 0 and report["constants_ms"] > 0


def test_kc_benchmark_quick_slice(tmp_path):
    """bench_kc.py's quick slice (two rounds, no nonlinear): every figure reported, each
    with its ratio to the sweep (no timing asserted)."""
    out = tmp_path / "kc.json"
    proc = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_kc.py"), "--quick", "--json", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert "x the sweep" in proc.stdout and "target <= 50 ms" in proc.stdout
    report = json.loads(out.read_text())
    assert report["steps"] == 41 and report["cases"] == 4
    assert set(report["ms"]) == {"baseline_sweep", "kc_linear", "kc_linear_with_sweep"}
    assert all(v > 0 for v in report["ms"].values())
