"""A long sweep streamed to its file a chunk at a time: the rows, the summary and the
report of a sweep held whole; memory that does not grow with the sweep's length."""

import gc
import re
import weakref

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import EXAMPLES

import pin_susp
import pin_susp.subjects.corner
from pin_susp.cli import main
from pin_susp.cli.commands import sweep as sweep_command
from pin_susp.cli.report import Digest

GEOMETRY = EXAMPLES / "double_wishbone.yaml"


def sweep_file(tmp_path, steps: int, stop: float = 120.0):
    path = tmp_path / f"sweep_{steps}.yaml"
    targets = [
        {"point": "wheel_center", "direction": {"axis": "z"}, "start": -40, "stop": stop},
        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "start": -40, "stop": 40},
    ]
    path.write_text(yaml.safe_dump({"version": 1, "steps": steps, "targets": targets}))
    return path


@pytest.fixture
def small_chunks(monkeypatch):
    """Stream sweeps longer than 300 steps, 250 steps at a time (the real sizes are
    10 000: the same code, at a test's length)."""
    monkeypatch.setattr(sweep_command, "STREAM_STEPS", 300)
    monkeypatch.setattr(pin_susp.subjects.corner, "CHUNK", 250)
    monkeypatch.setattr(
        pin_susp.subjects.corner.Corner.run_sweep_chunks, "__defaults__", (250, None)
    )


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_a_streamed_sweep_writes_the_held_sweeps_rows_and_summary(tmp_path, capsys, monkeypatch):
    sweep = sweep_file(tmp_path, 700)
    code, held_out, _ = run(["sweep", GEOMETRY, sweep, "-o", tmp_path / "held.csv"], capsys)
    assert code == 0
    monkeypatch.setattr(sweep_command, "STREAM_STEPS", 300)
    monkeypatch.setattr(
        pin_susp.subjects.corner.Corner.run_sweep_chunks, "__defaults__", (250, None)
    )
    seen = []
    chunks = pin_susp.subjects.corner.Corner.run_sweep_chunks

    def counted(self, *args, **kwargs):
        for part in chunks(self, *args, **kwargs):
            seen.append(len(part))
            yield part

    monkeypatch.setattr(pin_susp.subjects.corner.Corner, "run_sweep_chunks", counted)
    code, out, _ = run(["sweep", GEOMETRY, sweep, "-o", tmp_path / "streamed.csv"], capsys)
    assert code == 0 and seen == [250, 250, 200]
    residual = re.compile(r"max residual \S+ mm")  # each path's own last digits
    assert residual.sub("", out.replace("streamed.csv", "held.csv")) == residual.sub("", held_out)
    held = pd.read_csv(tmp_path / "held.csv", comment="#")
    streamed = pd.read_csv(tmp_path / "streamed.csv", comment="#")
    assert list(streamed.columns) == list(held.columns)
    assert (streamed["step_index"] == np.arange(700)).all()
    for name in held.columns:
        if name in ("solver_iterations", "solver_max_residual"):
            continue
        a, b = streamed[name].to_numpy(), held[name].to_numpy()
        if a.dtype.kind == "f":
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9, err_msg=name)
        else:
            np.testing.assert_array_equal(a, b, err_msg=name)
    comments = [line for line in (tmp_path / "streamed.csv").read_text().splitlines()[:4]]
    assert comments == (tmp_path / "held.csv").read_text().splitlines()[:4]


def test_a_streamed_parquet_file_holds_the_streamed_csvs_values(tmp_path, capsys, small_chunks):
    sweep = sweep_file(tmp_path, 600)
    assert run(["sweep", GEOMETRY, sweep, "-o", tmp_path / "s.csv", "-q"], capsys)[0] == 0
    assert run(["sweep", GEOMETRY, sweep, "-o", tmp_path / "s.parquet", "-q"], capsys)[0] == 0
    csv = pd.read_csv(tmp_path / "s.csv", comment="#")
    parquet = pd.read_parquet(tmp_path / "s.parquet")
    pd.testing.assert_frame_equal(csv, parquet, check_dtype=False)


def test_steps_out_of_reach_are_reported_as_for_a_held_sweep(tmp_path, capsys, monkeypatch):
    """The failure report and the exit code: the same lines, streamed or held."""
    sweep = sweep_file(tmp_path, 700, stop=1000.0)
    code, out, held_err = run(["sweep", GEOMETRY, sweep, "-o", tmp_path / "held.csv"], capsys)
    assert code == 1 and "did not converge" in held_err
    monkeypatch.setattr(sweep_command, "STREAM_STEPS", 300)
    monkeypatch.setattr(
        pin_susp.subjects.corner.Corner.run_sweep_chunks, "__defaults__", (250, None)
    )
    code, _, err = run(["sweep", GEOMETRY, sweep, "-o", tmp_path / "streamed.csv"], capsys)
    assert code == 1 and err == held_err
    held = pd.read_csv(tmp_path / "held.csv", comment="#")
    streamed = pd.read_csv(tmp_path / "streamed.csv", comment="#")
    np.testing.assert_array_equal(streamed["solver_converged"], held["solver_converged"])


def test_an_interrupt_part_way_leaves_no_file(tmp_path, monkeypatch, small_chunks):
    sweep = sweep_file(tmp_path, 700)
    chunks = pin_susp.subjects.corner.Corner.run_sweep_chunks

    def interrupted(self, *args, **kwargs):
        for i, part in enumerate(chunks(self, *args, **kwargs)):
            if i == 2:
                raise KeyboardInterrupt
            yield part

    monkeypatch.setattr(pin_susp.subjects.corner.Corner, "run_sweep_chunks", interrupted)
    before = set(tmp_path.iterdir())
    code = main(["sweep", str(GEOMETRY), str(sweep), "-o", str(tmp_path / "out.csv"), "-q"])
    assert code != 0
    assert set(tmp_path.iterdir()) == before


def test_no_more_than_two_chunks_are_alive(tmp_path, monkeypatch, small_chunks):
    """What keeps memory flat: when a chunk starts solving, the chunks before it are
    gone (garbage) but the one being written, so a sweep of any length holds two chunks
    of rows at most."""
    chunks = pin_susp.subjects.corner.Corner.run_sweep_chunks
    solve = pin_susp.subjects.corner.Corner.solve_steps
    refs, alive = [], []

    def watched(self, *args, **kwargs):
        for part in chunks(self, *args, **kwargs):
            refs.append(weakref.ref(part))
            yield part
            del part

    def solving(self, *args, **kwargs):
        gc.collect()
        alive.append(sum(ref() is not None for ref in refs))
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(pin_susp.subjects.corner.Corner, "run_sweep_chunks", watched)
    monkeypatch.setattr(pin_susp.subjects.corner.Corner, "solve_steps", solving)
    sweep = sweep_file(tmp_path, 2000)
    assert main(["sweep", str(GEOMETRY), str(sweep), "-o", str(tmp_path / "o.csv"), "-q"]) == 0
    assert len(refs) == 8 and max(alive) <= 1, alive


def test_a_sweep_too_long_to_hold_is_refused_where_it_would_be_held(tmp_path, capsys, monkeypatch):
    """--plot holds every step: a sweep too long for memory gets one clear line (exit 2);
    without --plot the same sweep is streamed."""
    from pin_susp.model import sweep as sweeps

    monkeypatch.setattr(sweeps, "_available_memory", lambda: 2 * 12_500 * 500)
    sweep = sweep_file(tmp_path, 600)
    code, _, err = run(
        ["sweep", GEOMETRY, sweep, "-o", tmp_path / "r.csv", "--plot", tmp_path / "r.png"], capsys
    )
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "steps" in err and "without --plot" in err
    assert not (tmp_path / "r.csv").exists() and not (tmp_path / "r.png").exists()


def test_a_digest_gathered_in_chunks_equals_the_whole():
    """Summary figures (first, last, min, max, a centre at infinity, the median number of
    iterations), flagged steps and the warnings' steps, chunk by chunk and whole."""

    class Part:
        def __init__(self, columns, why):
            self.columns, self.meta = columns, {"why": why}
            self.units = dict.fromkeys(columns, "u")

        def __getitem__(self, key):
            return self.columns[key]

    rng = np.random.default_rng(1)
    n = 1000
    columns = {
        "step_index": np.arange(n),
        "solver_converged": rng.random(n) > 0.1,
        "solver_max_residual": rng.random(n),
        "solver_iterations": rng.integers(0, 5, n),
        "camber": np.where(rng.random(n) < 0.3, np.nan, rng.normal(size=n)),
        "fvic_y": rng.normal(size=n) * 1e5,
        "rocker_transmission_angle": rng.uniform(0, 180, n),
        "spring_force": rng.normal(size=n),
    }
    why = ["" if ok else "residual 1 mm" for ok in columns["solver_converged"]]
    whole = Digest.of(Part(columns, why))
    parts = Digest()
    for start in range(0, n, 137):
        cut = slice(start, start + 137)
        parts.add(Part({k: v[cut] for k, v in columns.items()}, why[cut]))
    for d in (whole, parts):
        assert d.steps == n and d.converged == int(columns["solver_converged"].sum())
        assert d.iterations_median == np.median(columns["solver_iterations"])
        assert d.stats["camber"][2:4] == [
            np.nanmin(columns["camber"]),
            np.nanmax(columns["camber"]),
        ]
        assert d.stats["fvic_y"][4] == np.argmax(np.abs(columns["fvic_y"]))
        failed = np.flatnonzero(~columns["solver_converged"])
        assert d.short.first == list(failed[:11]) and d.short.count == d.failed == len(failed)
        assert d.worst_short == columns["solver_max_residual"][failed].max()
        angle = columns["rocker_transmission_angle"]
        outside = np.flatnonzero((angle < 30) | (angle > 150))
        assert d.band[""][0].first == list(outside[:11]) and d.band[""][0].count == len(outside)
        assert d.unseat[""][1] == columns["spring_force"].min()
    assert str(parts.stats) == str(whole.stats) and parts.band == whole.band
