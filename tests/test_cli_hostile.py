"""Issue 24, points 10 and 11: the console summary of failed steps, interrupts of
`view`, a study that cannot write, tracebacks, and good input refused."""

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import EXAMPLES, example

from pin_susp.cli import main

GEOMETRY = str(EXAMPLES / "double_wishbone.yaml")
BUMP_STEER = str(EXAMPLES / "bump_steer.yaml")


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out.splitlines(), err.splitlines()


def write_yaml(path: Path, data) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def cli(*argv, timeout=120, **kwargs):
    """The real command in a new process (its own stdin, stdout, stderr)."""
    return subprocess.run(
        [sys.executable, "-m", "pin_susp.cli", *map(str, argv)],
        capture_output=True,
        timeout=timeout,
        **kwargs,
    )


# -- 10. the summary of a sweep with failed steps -------------------------------------------


def _columns(line: str, header: str) -> dict:
    """A summary line's cells by the header's column ends (a blank cell is '')."""
    names = header.split()
    ends = [header.index(n) + len(n) for n in names]
    starts = [0, *ends[:-1]]
    return {n: line[a:b].strip() for n, a, b in zip(names, starts, ends, strict=True)}


def test_the_summary_prints_the_csv_blank_and_the_count_of_failed_steps(tmp_path, capsys):
    """Steps past the mechanism's reach: their cells are blank in the summary as in the
    CSV (never 'nan'), a column says at how many steps, min and max over the others."""
    sweep = example("bump_steer.yaml")
    sweep["steps"], sweep["targets"][0]["stop"] = 11, 800  # 800 mm of bump: out of reach
    path = write_yaml(tmp_path / "far.yaml", sweep)
    code, out, _ = run(["sweep", GEOMETRY, path, "-o", tmp_path / "r.csv"], capsys)
    assert code == 1
    rows = pd.read_csv(tmp_path / "r.csv", comment="#")
    failed = int((~rows["solver_converged"]).sum())
    assert 0 < failed < len(rows) and not rows["solver_converged"].iloc[-1]
    assert not any("nan" in line.lower().split() for line in out), out
    header = next(line for line in out if line.strip().startswith("metric"))
    assert header.split()[-1] == "blank"
    for name in ("camber", "roadwheel_angle", "half_track"):
        cells = _columns(next(x for x in out if x.split()[0] == name), header)
        column = rows[name].to_numpy()
        assert cells["last"] == ""  # the CSV's cell is empty: so is the summary's
        assert float(cells["first"]) == pytest.approx(column[0], rel=1e-5)
        assert float(cells["min"]) == pytest.approx(np.nanmin(column), rel=1e-5)
        assert float(cells["max"]) == pytest.approx(np.nanmax(column), rel=1e-5)
        assert int(cells["blank"]) == int(np.isnan(column).sum()) == failed
    assert any(f"{failed} of {len(rows)} steps did not converge" in line for line in out)


def test_an_axle_summary_prints_blanks_not_nan(tmp_path, capsys):
    sweep = yaml.safe_load((EXAMPLES / "roll.yaml").read_text())
    sweep["targets"][0].update(start=-30, stop=30)  # most of it beyond the axle's roll
    path = write_yaml(tmp_path / "roll.yaml", sweep)
    code, out, _ = run(
        ["sweep", EXAMPLES / "axle_front.yaml", path, "-o", tmp_path / "a.csv"], capsys
    )
    assert code == 1
    rows = pd.read_csv(tmp_path / "a.csv", comment="#")
    assert not any("nan" in line.lower().split() for line in out), out
    header = next(line for line in out if line.strip().startswith("column"))
    cells = _columns(next(x for x in out if x.split()[0] == "roll"), header)
    assert cells["first"] == cells["last"] == ""
    assert int(cells["blank"]) == int(np.isnan(rows["roll"]).sum()) > 0
    assert float(cells["max"]) == pytest.approx(np.nanmax(rows["roll"]), rel=1e-5)


# -- 11. good input refused -------------------------------------------------------------


@pytest.mark.parametrize("name", ["r.PARQUET", "r.Parquet"])
def test_a_parquet_output_is_told_by_its_suffix_in_any_case(tmp_path, capsys, name):
    import pyarrow.parquet as pq

    code, _, _ = run(["sweep", GEOMETRY, BUMP_STEER, "-o", tmp_path / name, "-q"], capsys)
    assert code == 0
    assert (tmp_path / name).read_bytes()[:4] == b"PAR1"
    table = pq.read_table(tmp_path / name).to_pandas()
    assert main(["sweep", GEOMETRY, BUMP_STEER, "-o", str(tmp_path / "r.csv"), "-q"]) == 0
    csv = pd.read_csv(tmp_path / "r.csv", comment="#")
    assert list(table.columns) == list(csv.columns)
    assert np.array_equal(table["camber"].to_numpy(), csv["camber"].to_numpy())


def test_a_streamed_sweep_onto_an_upper_case_parquet_name_is_parquet(tmp_path, capsys, monkeypatch):
    from pin_susp.cli.commands import sweep as sweep_command

    monkeypatch.setattr(sweep_command, "STREAM_STEPS", 20)  # the 41 steps go the streamed way
    code, _, _ = run(["sweep", GEOMETRY, BUMP_STEER, "-o", tmp_path / "r.PARQUET", "-q"], capsys)
    assert code == 0 and (tmp_path / "r.PARQUET").read_bytes()[:4] == b"PAR1"


def test_loads_onto_an_upper_case_parquet_name_is_parquet(tmp_path, capsys):
    code, _, _ = run(
        [
            "loads",
            EXAMPLES / "macpherson.yaml",
            BUMP_STEER,
            "--cases",
            EXAMPLES / "loads.yaml",
            "-o",
            tmp_path / "f.PARQUET",
            "-q",
        ],
        capsys,
    )
    assert code == 0 and (tmp_path / "f.PARQUET").read_bytes()[:4] == b"PAR1"


def test_top_states_its_real_limit(tmp_path, capsys):
    code, out, _ = run(["sensitivity", GEOMETRY, "--top", "999999", "-q"], capsys)
    assert code == 0
    code, _, err = run(["sensitivity", GEOMETRY, "--top", "1000000"], capsys)
    assert code == 2 and len(err) == 1
    assert "from 0 to 999999" in err[0] and "'1000000'" in err[0]


def _fifo(path: Path, data: bytes) -> threading.Thread:
    """A named pipe at ``path`` that a second thread fills once with ``data``."""
    os.mkfifo(path)

    def fill():
        with open(path, "wb") as f:
            f.write(data)

    writer = threading.Thread(target=fill, daemon=True)
    writer.start()
    return writer


def test_a_geometry_piped_into_stdin_is_read_once(tmp_path):
    """`cat g.yaml | pin-susp sweep /dev/stdin ...`: the CLI asks the file's scope, then
    loads it; a pipe gives its bytes once. The same results as from the file."""
    geometry = (EXAMPLES / "double_wishbone.yaml").read_bytes()
    proc = cli("sweep", "/dev/stdin", BUMP_STEER, "-o", "p.csv", "-q", input=geometry, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert main(["sweep", GEOMETRY, BUMP_STEER, "-o", str(tmp_path / "f.csv"), "-q"]) == 0
    piped = pd.read_csv(tmp_path / "p.csv", comment="#")
    filed = pd.read_csv(tmp_path / "f.csv", comment="#")
    assert piped.equals(filed)
    import hashlib

    sha = hashlib.sha256(geometry).hexdigest()  # the hash of what was piped, not of nothing
    assert f"# geometry: /dev/stdin sha256={sha}" in (tmp_path / "p.csv").read_text()


@pytest.mark.parametrize(
    "command",
    [
        ["setup", "{g}", "--toe", "0.1"],
        ["sensitivity", "{g}", "-q"],
        ["urdf", "{g}", "-o", "u.urdf"],
        ["view", "{g}", BUMP_STEER, "--html", "v.html"],
        ["loads", "{r}", BUMP_STEER, "--cases", "{c}", "-o", "l.csv", "-q"],
        ["sweep", "{a}", "{s}", "-o", "a.csv", "-q"],
    ],
    ids=["setup", "sensitivity", "urdf", "view", "loads cases", "axle sweep"],
)
def test_every_input_kind_is_read_once_from_a_fifo(tmp_path, command):
    """A named pipe can be read once: each command reads each of its inputs once."""
    sources = {
        "{g}": EXAMPLES / "double_wishbone.yaml",
        "{r}": EXAMPLES / "pushrod_rocker.yaml",
        "{c}": EXAMPLES / "loads.yaml",
        "{a}": EXAMPLES / "axle_front.yaml",
        "{s}": EXAMPLES / "roll.yaml",
    }
    argv, writers = [], []
    for a in command:
        if a in sources:
            path = tmp_path / f"in-{len(writers)}.yaml"
            writers.append(_fifo(path, sources[a].read_bytes()))
            a = path
        argv.append(a)
    proc = cli(*argv, cwd=tmp_path, stdin=subprocess.DEVNULL, timeout=60)  # else: it waits
    assert proc.returncode == 0, proc.stderr
    assert b"error" not in proc.stderr
    for writer in writers:
        writer.join(timeout=10)
        assert not writer.is_alive()


def three_variants(geometry: str, sweep: str, **more) -> dict:
    """A 3-variant DOE of the example corner's trackrod end height (±2 mm)."""
    return {
        "version": 1,
        "geometry": geometry,
        "sweep": sweep,
        "variables": [{"point": "trackrod_outboard", "axis": "z", "range": [-2, 2]}],
        "kind": "doe",
        "doe": {"method": "full_factorial", "levels": 3},
        "summary": ["roadwheel_angle"],
        **more,
    }


def test_a_study_reads_its_geometry_and_sweep_once_from_fifos(tmp_path):
    """A study's geometry and sweep through named pipes: the study is checked, solved and
    written as from the files."""
    _fifo(tmp_path / "g.yaml", (EXAMPLES / "double_wishbone.yaml").read_bytes())
    _fifo(tmp_path / "s.yaml", (EXAMPLES / "bump_rack_held.yaml").read_bytes())
    write_yaml(tmp_path / "study.yaml", three_variants("g.yaml", "s.yaml"))
    proc = cli(
        "study", "study.yaml", "-o", "out", "--scheduler", "none", "-q", cwd=tmp_path, timeout=60
    )
    assert proc.returncode == 0, proc.stderr
    import pyarrow.parquet as pq

    variants = pq.read_table(tmp_path / "out" / "variants.parquet").to_pandas()
    assert len(variants) == 3 and variants["converged"].all()


# -- 11. tracebacks: a name too long for the file system ---------------------------------

LONG = "n" * 300  # beyond the 255 bytes of a name on Linux file systems


@pytest.fixture
def small_study(tmp_path):
    """A 3-variant study of the example corner (its files copied beside it)."""
    for name in ("double_wishbone.yaml", "bump_rack_held.yaml"):
        (tmp_path / name).write_bytes((EXAMPLES / name).read_bytes())
    study = three_variants("double_wishbone.yaml", "bump_rack_held.yaml", batch_size=1)
    return write_yaml(tmp_path / "study.yaml", study)


WRITERS = {
    "sweep": ["sweep", GEOMETRY, BUMP_STEER, "-o", "{o}.csv"],
    "sweep --plot": ["sweep", GEOMETRY, BUMP_STEER, "-o", "r.csv", "--plot", "{o}.png"],
    "loads": ["loads", EXAMPLES / "macpherson.yaml", BUMP_STEER, "--cases",
              EXAMPLES / "loads.yaml", "-o", "{o}.csv"],
    "urdf": ["urdf", GEOMETRY, "-o", "{o}.urdf"],
    "mjcf": ["mjcf", GEOMETRY, "-o", "{o}.xml"],
    "setup": ["setup", GEOMETRY, "--csv", "{o}.csv"],
    "sensitivity": ["sensitivity", GEOMETRY, "-o", "{o}.csv"],
    "draw": ["draw", GEOMETRY, "-o", "{o}.png"],
    "view": ["view", GEOMETRY, "--html", "{o}.html"],
    "demo": ["demo", "-o", "{o}"],
    "study": ["study", "{study}", "-o", "{o}", "--scheduler", "none"],
}  # fmt: skip


@pytest.mark.parametrize("where", ["name", "folder"])
@pytest.mark.parametrize("command", list(WRITERS))
def test_a_name_too_long_is_one_line_and_leaves_nothing(
    tmp_path, capsys, small_study, command, where
):
    """An output whose file name, or a folder on its way, is longer than the file system
    allows: one line naming it, exit 2, nothing made (not even the folders before it)."""
    out = tmp_path / "out"
    out.mkdir()
    target = out / LONG if where == "name" else out / "a" / LONG / "b"
    argv = [
        str(a).replace("{o}", str(target)).replace("{study}", str(small_study))
        for a in WRITERS[command]
    ]
    code, _, err = run(argv, capsys)
    assert code == 2 and len(err) == 1, err
    assert err[0].startswith("pin-susp: error: ") and "too long" in err[0], err
    assert list(out.iterdir()) == []


# -- 11. a study that cannot write; a damaged part file on --resume ----------------------


def _room_for(monkeypatch, parts: int):
    """Writes run out of room (ENOSPC, a full disk) after ``parts`` part files."""
    import errno

    from pin_susp.io.atomic import atomic_write
    from pin_susp.study import folder

    real, written = folder.write_parquet, []

    def write(table, path):
        if len(written) >= parts:
            with atomic_write(path, binary=True) as f:  # the write itself fails part-way
                f.write(b"PAR1")
                raise OSError(errno.ENOSPC, "No space left on device")
        written.append(path)
        real(table, path)

    monkeypatch.setattr(folder, "write_parquet", write)
    return written


def test_a_study_that_runs_out_of_room_keeps_its_finished_batches_and_says_so(
    tmp_path, capsys, monkeypatch, small_study
):
    """A full disk after two of three batches: study.json and the two whole part files
    stay, the message says so, and --resume (once there is room) finishes the run with the
    variants an uninterrupted run gives."""
    import pyarrow.parquet as pq

    written = _room_for(monkeypatch, 2)
    code, _, err = run(["study", small_study, "-o", tmp_path / "a", "--scheduler", "none"], capsys)
    assert code == 2 and len(err) == 1, err
    assert "No space left on device" in err[0], err
    assert "2 of 3 batches are kept in" in err[0] and "--resume continues" in err[0], err
    parts = sorted(p.name for p in (tmp_path / "a" / ".parts").iterdir())
    assert parts == ["variants-000000.parquet", "variants-000001.parquet"]
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == [".parts", "study.json"]
    for p in written:
        assert pq.read_table(p).num_rows == 1  # whole
    monkeypatch.undo()
    code, _, err = run(
        ["study", small_study, "-o", tmp_path / "a", "--scheduler", "none", "--resume", "-q"],
        capsys,
    )
    assert code == 0, err
    code, _, _ = run(
        ["study", small_study, "-o", tmp_path / "b", "--scheduler", "none", "-q"], capsys
    )
    resumed = pq.read_table(tmp_path / "a" / "variants.parquet").to_pandas()
    whole = pq.read_table(tmp_path / "b" / "variants.parquet").to_pandas()
    assert resumed.drop(columns="seconds", errors="ignore").equals(
        whole.drop(columns="seconds", errors="ignore")
    )


@pytest.mark.parametrize("folder", ["new", "empty"])
def test_a_study_that_cannot_write_its_first_batch_leaves_nothing(
    tmp_path, capsys, monkeypatch, small_study, folder
):
    """No batch written: nothing left (the run's study.json and part folder go, and the
    folder when the run made it), and the message says nothing was written."""
    out = tmp_path / "a"
    if folder == "empty":
        out.mkdir()
    _room_for(monkeypatch, 0)
    code, _, err = run(["study", small_study, "-o", out, "--scheduler", "none"], capsys)
    assert code == 2 and len(err) == 1 and err[0].endswith(": nothing written"), err
    assert "No space left on device" in err[0]
    if folder == "new":
        assert not out.exists()
    else:
        assert list(out.iterdir()) == []


def test_a_damaged_part_file_is_named_and_its_batch_solved_again_on_resume(
    tmp_path, capsys, monkeypatch, small_study
):
    """--resume over part files cut short, overwritten or holding another batch: each is
    named on stderr, its batch is solved again, and the variants are those of a whole run."""
    import shutil

    import pyarrow.parquet as pq

    from pin_susp.study import folder

    def stop(*args):  # every batch written, then Ctrl+C
        raise KeyboardInterrupt

    monkeypatch.setattr(folder, "assemble", stop)
    argv = ["study", small_study, "-o", tmp_path / "a", "--scheduler", "none", "--steps"]
    assert run(argv, capsys)[0] == 128 + signal.SIGINT
    monkeypatch.undo()
    parts = tmp_path / "a" / ".parts"
    names = sorted(p.name for p in parts.iterdir())
    assert names == [f"{w}-{i:06d}.parquet" for w in ("steps", "variants") for i in range(3)]
    with open(parts / "variants-000000.parquet", "r+b") as f:
        f.truncate(300)  # cut short
    (parts / "steps-000001.parquet").write_bytes(b"not parquet")  # overwritten
    shutil.copy(parts / "variants-000001.parquet", parts / "variants-000002.parquet")  # batch 1's
    code, _, err = run(
        ["study", small_study, "-o", tmp_path / "a", "--scheduler", "none", "--resume"]
        + ["--steps"],
        capsys,
    )
    assert code == 0, err
    assert "Traceback" not in "".join(err)
    for i, name in enumerate(["variants-000000", "steps-000001", "variants-000002"]):
        line = next(x for x in err if f"{name}.parquet" in x)
        assert line.startswith("pin-susp: warning: ") and f"batch {i} is solved again" in line
    code, _, _ = run(
        ["study", small_study, "-o", tmp_path / "b", "--scheduler", "none", "-q", "--steps"],
        capsys,
    )
    resumed = pq.read_table(tmp_path / "a" / "variants.parquet").to_pandas()
    whole = pq.read_table(tmp_path / "b" / "variants.parquet").to_pandas()
    assert resumed.drop(columns="seconds", errors="ignore").equals(
        whole.drop(columns="seconds", errors="ignore")
    )
    steps_a = pd.read_parquet(tmp_path / "a" / "steps.parquet").sort_values(
        ["variant_id", "step_index"], ignore_index=True
    )
    steps_b = pd.read_parquet(tmp_path / "b" / "steps.parquet").sort_values(
        ["variant_id", "step_index"], ignore_index=True
    )
    assert steps_a.equals(steps_b)


# -- 11. Ctrl+C and SIGTERM in `view --html` --------------------------------------------

# `pin-susp view` in a new process, with a signal raised at one moment of its run:
# import of scipy.optimize (inside trimesh's imports, which swallow an interrupt), the
# animation being recorded, the page being made, the HTML being written.
_AT = """
import importlib.abc, signal, sys
from pin_susp import cli
from pin_susp.viz import scene as viz
from pin_susp.io import atomic
number = getattr(signal, sys.argv[2])

def fire():
    signal.raise_signal(number)

class Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name == "scipy.optimize":
            sys.meta_path.remove(self)
            fire()
        return None

def before(cls, name):
    real = getattr(cls, name)
    def wrapped(*args, **kwargs):
        fire()
        return real(*args, **kwargs)
    setattr(cls, name, wrapped)

moment = sys.argv[1]
if moment == "import":
    sys.meta_path.insert(0, Finder())
elif moment == "write":
    real = atomic.write_text
    def write_text(text, path):
        with atomic.atomic_write(path) as f:
            f.write(text[: len(text) // 2])
            fire()
            f.write(text[len(text) // 2 :])
    atomic.write_text = write_text
else:
    before(viz.Scene, moment)
sys.exit(cli.main(sys.argv[3:]))
"""


def _ctrl_c_as_on_a_terminal() -> None:
    """In the child, before exec: SIGINT as a terminal's shell starts a command, not
    ignored — a suite run as a background job (``make test &`` in a script) hands its
    children SIGINT ignored, and Python then never turns Ctrl+C into an interrupt."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _servers_of(pid: int) -> list[int]:
    """Processes still running meshcat's server for the process ``pid``."""
    found = []
    for proc in Path("/proc").iterdir():
        try:
            argv = (proc / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if any(b"zmqserver" in a for a in argv) and str(pid).encode() in argv:
            found.append(int(proc.name))
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc")
@pytest.mark.parametrize(
    "moment, sig",
    [
        ("import", "SIGINT"),
        ("animate", "SIGINT"),
        ("html", "SIGINT"),
        ("write", "SIGINT"),
        ("animate", "SIGTERM"),
        ("write", "SIGTERM"),
    ],
)
def test_view_html_interrupted_at_any_moment_exits_130_or_143_and_leaves_nothing(
    tmp_path, moment, sig
):
    proc = subprocess.Popen(
        [sys.executable, "-c", _AT, moment, sig, "view", GEOMETRY, BUMP_STEER, "--html", "v.html"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=_ctrl_c_as_on_a_terminal,
    )
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 128 + getattr(signal, sig), (out, err)
    assert "stopped" not in out and "wrote" not in out
    assert err.strip().splitlines() == ["pin-susp: interrupted, nothing written"], err
    assert list(tmp_path.iterdir()) == []  # no HTML, no temporary
    deadline = time.time() + 10
    while _servers_of(proc.pid) and time.time() < deadline:
        time.sleep(0.1)
    assert _servers_of(proc.pid) == []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc")
@pytest.mark.parametrize("delay", [0.7, 1.5, 3.0])
def test_ctrl_c_sent_to_a_long_view_html_exits_130_and_leaves_nothing(tmp_path, delay):
    """The real signal from outside, at moments of a long replay's run (~10 s here)."""
    sweep = example("bump_steer.yaml")
    sweep["steps"] = 3000
    write_yaml(tmp_path / "long.yaml", sweep)
    proc = subprocess.Popen(
        [sys.executable, "-m", "pin_susp.cli", "view", GEOMETRY, "long.yaml", "--html", "v.html"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=_ctrl_c_as_on_a_terminal,
    )
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (out, err)
    assert "stopped" not in out and "wrote" not in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.yaml"]
