"""Studies on a real Dask cluster (docs/studies.md, behaviour): a scheduler and two workers
started here as processes on 127.0.0.1, a worker killed mid-study, a run interrupted and
resumed, and a scheduler that is not there. The reference is always the serial run
(``--scheduler none``, in this process): every other run must equal it bit for bit."""

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import psutil
import pyarrow.parquet as pq
import pytest
import yaml
from conftest import EXAMPLES

from pin_susp import study as studies
from pin_susp.cli import main

BIN = Path(sys.executable).parent  # the venv's executables: dask, pin-susp
SAMPLES, BATCH, STEPS = 80, 5, 21  # 16 batches of 5 variants, 21 sweep steps each
BATCHES = SAMPLES // BATCH
VARIABLES = [
    ("trackrod_inboard", "z", -15.0, 15.0),
    ("upper_wishbone_outboard", "z", -10.0, 10.0),
    ("trackrod_outboard", "x", -5.0, 5.0),
]
SEED = 3
WAIT = 60.0  # s: the most any wait here may take before the test fails (not hangs)


# ------------------------------------------------------------------ helpers


def _env(home: Path) -> dict:
    """The environment of every process started here: nothing written outside ``home``."""
    env = dict(os.environ)
    env.update(
        HOME=str(home),
        DASK_TEMPORARY_DIRECTORY=str(home / "dask-tmp"),
        MPLCONFIGDIR=str(home / "mpl"),
        XDG_CACHE_HOME=str(home / ".cache"),
        XDG_CONFIG_HOME=str(home / ".config"),
        PYTHONDONTWRITEBYTECODE="1",
    )
    return env


def _stop(proc: subprocess.Popen, timeout: float = 10.0) -> None:
    """Terminate a process started here (its own session: its group too), then kill it."""
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout)


def _wait_for(condition, what: str, proc: subprocess.Popen | None = None, log: Path | None = None):
    """Poll ``condition`` until it is true; fail (never hang) after WAIT seconds, or at
    once if ``proc`` ended."""
    deadline = time.monotonic() + WAIT
    while not condition():
        if proc is not None and proc.poll() is not None:
            text = log.read_text() if log is not None and log.exists() else ""
            pytest.fail(f"{what}: the process ended first (exit {proc.returncode})\n{text}")
        if time.monotonic() > deadline:
            pytest.fail(f"{what}: not within {WAIT:.0f} s")
        time.sleep(0.01)


def _refuses(address: str) -> bool:
    """Whether nothing listens at tcp://host:port any more."""
    host, port = address.removeprefix("tcp://").rsplit(":", 1)
    try:
        with socket.create_connection((host, int(port)), timeout=2.0):
            return False
    except OSError:
        return True


def _cli(args: list[str], home: Path) -> subprocess.Popen:
    """``pin-susp ARGS`` as its own process (cwd and HOME: ``home``), output in files."""
    out = open(home / "cli.out", "w")  # closed by _finish
    err = open(home / "cli.err", "w")
    proc = subprocess.Popen(
        [str(BIN / "pin-susp"), *args],
        cwd=home,
        env=_env(home),
        stdin=subprocess.DEVNULL,
        stdout=out,
        stderr=err,
        start_new_session=True,
        # Ctrl+C's default action, even when this run inherited SIGINT ignored (a
        # background job): Python then turns it into KeyboardInterrupt as in a terminal
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    proc.files = (out, err)
    return proc


def _finish(proc: subprocess.Popen, timeout: float = WAIT) -> tuple[int, str, str]:
    """Wait for a CLI process (killed if it overruns): exit code, stdout, stderr."""
    try:
        code = proc.wait(timeout)
    except subprocess.TimeoutExpired:
        _stop(proc)
        pytest.fail(f"pin-susp did not end within {timeout:.0f} s")
    finally:
        for f in proc.files:
            f.close()
    home = Path(proc.files[0].name).parent
    return code, (home / "cli.out").read_text(), (home / "cli.err").read_text()


def _parts(outdir: Path, what: str = "variants") -> list[int]:
    """The batches whose part file is in OUTDIR/.parts (a finished batch)."""
    try:
        names = os.listdir(outdir / ".parts")
    except FileNotFoundError:
        return []
    return sorted(
        int(n[len(what) + 1 : -len(".parquet")])
        for n in names
        if n.startswith(f"{what}-") and n.endswith(".parquet")
    )


def _bits(frame: pd.DataFrame) -> dict:
    """Every column's values as bytes: floats by their bit patterns (NaN, -0.0 too)."""
    out = {}
    for name in frame.columns:
        values = frame[name].to_numpy()
        if values.dtype.kind == "f":
            out[name] = np.ascontiguousarray(values, dtype=np.float64).view(np.uint64).tobytes()
        else:
            out[name] = repr(values.tolist()).encode()
    return out


def assert_same_study(outdir: Path, reference: Path) -> None:
    """OUTDIR's variants.parquet and steps.parquet equal the reference's bit for bit."""
    parts = sorted(p.name for p in (outdir / "steps.parquet").iterdir())
    assert parts == sorted(p.name for p in (reference / "steps.parquet").iterdir())
    for name in ["variants.parquet", *(f"steps.parquet/{p}" for p in parts)]:
        got, want = pq.read_schema(outdir / name), pq.read_schema(reference / name)
        assert got == want and got.metadata == want.metadata, name  # units too
    got, want = (
        pd.read_parquet(outdir / "variants.parquet"),
        pd.read_parquet(reference / "variants.parquet"),
    )
    assert got["variant_id"].tolist() == list(range(SAMPLES))  # every variant exactly once
    pd.testing.assert_frame_equal(got, want, check_exact=True)
    assert _bits(got) == _bits(want)
    got, want = studies.read_steps(outdir), studies.read_steps(reference)
    assert len(got) == SAMPLES * STEPS
    assert (got.groupby("variant_id").size() == STEPS).all()
    assert sorted(got["variant_id"].unique()) == list(range(SAMPLES))
    pd.testing.assert_frame_equal(got, want, check_exact=True)
    assert _bits(got) == _bits(want)


# ------------------------------------------------------------------ fixtures


@pytest.fixture(scope="module")
def study_file(tmp_path_factory) -> Path:
    """A Latin hypercube of 80 variants of the example corner through the held-rack bump,
    in batches of 5 (many batches: a kill or an interrupt lands mid-study)."""
    folder = tmp_path_factory.mktemp("study")
    body = {
        "version": 1,
        "geometry": str(EXAMPLES / "double_wishbone.yaml"),
        "sweep": str(EXAMPLES / "bump_rack_held.yaml"),
        "variables": [{"point": p, "axis": a, "range": [lo, hi]} for p, a, lo, hi in VARIABLES],
        "kind": "doe",
        "doe": {"method": "latin_hypercube", "samples": SAMPLES, "seed": SEED},
        "summary": ["camber", "roadwheel_angle", "deriv_roadwheel_angle_wrt_hub_z"],
        "batch_size": BATCH,
    }
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(body, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def serial(study_file, tmp_path_factory) -> Path:
    """The serial run (``--scheduler none``, in this process, with --steps): the reference."""
    out = tmp_path_factory.mktemp("serial") / "out"
    assert (
        main(["study", str(study_file), "-o", str(out), "--scheduler", "none", "--steps", "-q"])
        == 0
    )
    return out


def test_serial_reference_is_the_latin_hypercube(serial):
    """The reference holds the intended variants: scipy's Latin hypercube for the seed,
    scaled to the ranges, one row each, ids in order; every step converged and each
    variant's min/max are its steps' min/max."""
    from scipy.stats import qmc

    variants = pd.read_parquet(serial / "variants.parquet")
    low = np.array([v[2] for v in VARIABLES])
    high = np.array([v[3] for v in VARIABLES])
    want = qmc.scale(qmc.LatinHypercube(d=len(VARIABLES), seed=SEED).random(SAMPLES), low, high)
    names = [f"d_{p}_{a}" for p, a, _, _ in VARIABLES]
    assert variants["variant_id"].tolist() == list(range(SAMPLES))
    np.testing.assert_array_equal(variants[names].to_numpy(), want)
    assert variants["converged"].all()
    steps = studies.read_steps(serial)
    spread = steps.groupby("variant_id")["roadwheel_angle"].agg(["min", "max"])
    np.testing.assert_array_equal(spread["min"].to_numpy(), variants["roadwheel_angle_min"])
    np.testing.assert_array_equal(spread["max"].to_numpy(), variants["roadwheel_angle_max"])
    assert variants["roadwheel_angle_max"].std() > 0.05  # the variants differ (deg)


class Cluster:
    """``dask scheduler`` and two ``dask worker`` processes on 127.0.0.1 (no nanny: the
    worker's process is the worker, so killing it loses it)."""

    def __init__(self, home: Path):
        self.home = home
        self.procs: list[subprocess.Popen] = []
        self.workers: dict[str, subprocess.Popen] = {}  # address → process
        self.client = None
        self.address = ""

    def _spawn(self, name: str, args: list[str]) -> subprocess.Popen:
        log = open(self.home / f"{name}.log", "w")
        proc = subprocess.Popen(
            [str(BIN / "dask"), *args],
            cwd=self.home,
            env=_env(self.home),
            stdin=subprocess.DEVNULL,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        log.close()
        self.procs.append(proc)
        return proc

    def start(self) -> None:
        from distributed import Client

        assert (BIN / "dask").exists(), f"{BIN / 'dask'}: dask's command line is missing"
        file = self.home / "scheduler.json"
        scheduler = self._spawn(
            "scheduler",
            [
                "scheduler",
                "--host",
                "127.0.0.1",
                "--port",
                "0",
                "--no-dashboard",
                "--dashboard-address",
                "127.0.0.1:0",
                "--scheduler-file",
                str(file),
            ],
        )

        def address() -> bool:
            try:
                self.address = json.loads(file.read_text())["address"]
            except (OSError, ValueError, KeyError):
                return False
            return True

        _wait_for(address, "the scheduler's address", scheduler, self.home / "scheduler.log")
        assert self.address.startswith("tcp://127.0.0.1:")
        workers = [
            self._spawn(
                f"worker{i}",
                [
                    "worker",
                    self.address,
                    "--host",
                    "127.0.0.1",
                    "--nthreads",
                    "1",
                    "--nworkers",
                    "1",
                    "--no-nanny",
                    "--no-dashboard",
                    "--dashboard-address",
                    "127.0.0.1:0",
                    "--local-directory",
                    str(self.home / f"worker{i}"),
                    "--name",
                    f"worker{i}",
                ],
            )
            for i in range(2)
        ]
        self.client = Client(self.address, timeout="20s", set_as_default=False)
        self.client.wait_for_workers(2, timeout=WAIT)
        info = self.client.scheduler_info(n_workers=-1)["workers"]
        by_name = {w["name"]: a for a, w in info.items()}
        self.workers = {by_name[f"worker{i}"]: p for i, p in enumerate(workers)}
        for proc in self.procs:  # every server listens on 127.0.0.1 only
            listening = [
                c.laddr
                for c in psutil.Process(proc.pid).net_connections(kind="inet")
                if c.status == psutil.CONN_LISTEN
            ]
            assert listening and all(a.ip == "127.0.0.1" for a in listening), listening

    def executed(self) -> dict[str, int]:
        """Tasks each live worker has run (its own count)."""
        return self.client.run(lambda dask_worker: dask_worker.state.executed_count)

    def held(self) -> int:
        """Tasks the live workers hold (a cancelled one runs on until it ends)."""
        return sum(self.client.run(lambda dask_worker: len(dask_worker.state.tasks)).values())

    def stop(self) -> None:
        addresses = [self.address, *self.workers]
        if self.client is not None:
            self.client.close()
        for proc in reversed(self.procs):  # workers first, the scheduler last
            _stop(proc)
        for address in addresses:
            if address:
                assert _refuses(address), f"{address}: still listening"


@pytest.fixture
def cluster(tmp_path):
    c = Cluster(tmp_path)
    try:
        c.start()
        yield c
    finally:
        c.stop()


# ------------------------------------------------------------------ the tests


def test_scheduler_address_equals_the_serial_run(cluster, study_file, serial, tmp_path):
    """--scheduler tcp://… on two worker processes: the same tables, bit for bit, and the
    batches were solved by the workers (each of them), once each."""
    before = cluster.executed()
    out = tmp_path / "out"
    proc = _cli(
        ["study", str(study_file), "-o", str(out), "--scheduler", cluster.address, "--steps"],
        tmp_path,
    )
    code, stdout, stderr = _finish(proc)
    assert code == 0, stderr
    assert f"wrote {out / 'variants.parquet'}" in stdout
    assert "already done" not in stdout
    after = cluster.executed()
    ran = {a: after[a] - before[a] for a in after}
    assert sum(ran.values()) == BATCHES, ran
    assert all(n >= 1 for n in ran.values()), ran
    assert not (out / ".parts").exists()
    assert_same_study(out, serial)


def test_a_worker_killed_mid_study_loses_no_variant(cluster, study_file, serial, tmp_path):
    """SIGKILL to a worker while it holds a batch, after some batches are written: Dask
    reruns what it held, every variant is there exactly once, equal to the serial run."""
    out = tmp_path / "out"
    proc = _cli(
        ["study", str(study_file), "-o", str(out), "--scheduler", cluster.address, "--steps"],
        tmp_path,
    )
    try:
        _wait_for(lambda: len(_parts(out)) >= 3, "three batches written", proc)

        def processing(dask_scheduler):
            return {a: len(w.processing) for a, w in dask_scheduler.workers.items()}

        victim = None

        def busy() -> bool:  # a worker with a batch in hand
            nonlocal victim
            held = cluster.client.run_on_scheduler(processing)
            victim = next((a for a, n in held.items() if n), None)
            return victim is not None

        _wait_for(busy, "a worker holding a batch", proc)
        cluster.workers[victim].send_signal(signal.SIGKILL)
        cluster.workers[victim].wait(10)
        done_at_kill = len(_parts(out))
        assert proc.poll() is None and 0 < done_at_kill < BATCHES, "killed too late"
        code, stdout, stderr = _finish(proc)
    finally:
        _stop(proc)
    assert cluster.workers[victim].returncode == -signal.SIGKILL
    assert code == 0, stderr
    assert list(cluster.client.scheduler_info(n_workers=-1)["workers"]) == [
        a for a in cluster.workers if a != victim
    ]
    assert not (out / ".parts").exists()
    assert_same_study(out, serial)


@pytest.mark.parametrize(
    "sig, on_dask", [(signal.SIGINT, False), (signal.SIGTERM, True)], ids=["SIGINT", "SIGTERM-dask"]
)
def test_resume_solves_only_the_missing_batches(
    study_file, serial, tmp_path, sig, on_dask, monkeypatch, capsys, request
):
    """A run stopped by a signal once some batches are written (serial: SIGINT; on the
    cluster: SIGTERM): it exits 128+signal, keeps the finished batches' part files and
    writes no variants.parquet; a rerun without --resume refuses (one line, exit 2);
    --resume solves exactly the missing batches, leaves the kept parts as they were, and
    equals the uninterrupted serial run bit for bit."""
    cluster = request.getfixturevalue("cluster") if on_dask else None
    scheduler = cluster.address if on_dask else "none"
    out = tmp_path / "out"
    args = ["study", str(study_file), "-o", str(out), "--scheduler", scheduler, "--steps"]
    proc = _cli([*args, "-q"], tmp_path)
    try:
        _wait_for(lambda: len(_parts(out)) >= 3, "three batches written", proc)
        proc.send_signal(sig)
        code, stdout, stderr = _finish(proc)
    finally:
        _stop(proc)
    assert code == 128 + sig
    done = _parts(out)
    said = [line for line in stderr.splitlines() if line.strip()]
    assert len(said) == 1 and said[0].startswith("pin-susp: interrupted"), stderr
    assert f"{len(done)} of {BATCHES} batches" in said[0] and "--resume" in said[0], said
    assert 3 <= len(done) < BATCHES, done
    if not on_dask:
        assert done == list(range(len(done)))  # serially: the first ones, in order
    assert set(done) <= set(_parts(out, "steps"))
    assert not (out / "variants.parquet").exists() and not (out / "steps.parquet").exists()
    kept = {}
    for i in done:
        s = (out / ".parts" / f"steps-{i:06d}.parquet").stat()
        kept[i] = (s.st_ino, s.st_mtime_ns, s.st_size)

    # without --resume: refused, one line, exit 2, nothing touched
    capsys.readouterr()
    assert main(args) == 2
    refused = capsys.readouterr()  # its stdout: checked last (the resume is the point)
    assert len(refused.err.splitlines()) == 1
    assert refused.err.startswith("pin-susp: error: ") and "--resume" in refused.err
    assert _parts(out) == done

    # --resume, in this process: the batches it solves are counted (serially, by their
    # index; on the cluster, by the workers' own counts once the cancelled ones are gone)
    solved = []
    original = studies.run_batch

    def counting(job, index, *rest):
        solved.append(index)
        return original(job, index, *rest)

    monkeypatch.setattr(studies.tasks, "run_batch", counting)
    if on_dask:
        _wait_for(lambda: cluster.held() == 0, "the cluster's workers idle")
        before = cluster.executed()
    assert main([*args, "--resume"]) == 0
    printed = capsys.readouterr().out
    missing = [i for i in range(BATCHES) if i not in done]
    if on_dask:
        after = cluster.executed()
        assert sum(after[a] - before[a] for a in after) == len(missing)
    else:
        assert solved == missing
    assert f"; {len(done)} of {BATCHES} batches were already done" in printed
    for i, before in kept.items():  # the kept parts moved into place, not rewritten
        s = (out / "steps.parquet" / f"part-{i:06d}.parquet").stat()
        assert (s.st_ino, s.st_mtime_ns, s.st_size) == before, i
    assert not (out / ".parts").exists()
    assert sorted(p.name for p in out.iterdir()) == [
        "steps.parquet",
        "study.json",
        "study.png",
        "variants.parquet",
    ]
    assert_same_study(out, serial)
    assert refused.out == "", "a refused run printed more than its one line"


@pytest.fixture(scope="module")
def unreachable(study_file, tmp_path_factory):
    """``--scheduler`` at a port of 127.0.0.1 that nobody listens on (held bound, not
    listening, for the run): exit code, stdout, stderr, seconds, OUTDIR."""
    home = tmp_path_factory.mktemp("unreachable")
    out = home / "out"
    with socket.socket() as held:
        held.bind(("127.0.0.1", 0))
        address = f"tcp://127.0.0.1:{held.getsockname()[1]}"
        started = time.monotonic()
        proc = _cli(["study", str(study_file), "-o", str(out), "--scheduler", address], home)
        code, stdout, stderr = _finish(proc, timeout=30.0)
        seconds = time.monotonic() - started
    return code, stdout, stderr, seconds, out, address


def test_an_unreachable_scheduler_is_one_line_within_10_s(unreachable):
    code, stdout, stderr, seconds, _, address = unreachable
    assert code == 2
    assert stdout == ""
    assert len(stderr.splitlines()) == 1 and stderr.startswith("pin-susp: error: "), stderr
    assert address in stderr and "Traceback" not in stderr
    assert seconds < 10.0, f"the error came after {seconds:.1f} s"


def test_an_unreachable_scheduler_leaves_no_run_to_resume(unreachable, study_file, tmp_path):
    """Nothing was solved: OUTDIR is not left as an unfinished run that a rerun (with a
    working scheduler, without --resume) would refuse."""
    *_, out, _ = unreachable
    assert not out.exists() or not any(out.iterdir()), sorted(os.listdir(out))
