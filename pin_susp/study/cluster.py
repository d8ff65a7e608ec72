"""Where a study's batches run on Dask (docs/studies.md): a LocalCluster on 127.0.0.1
or an existing scheduler, checked to answer; the dashboard's address; the batches
submitted and gathered as they finish.

The LocalCluster's workers are forked from a server process that imports, once, what a
batch needs (Pinocchio, pyarrow, pandas, the package: about 2 s of a 2-core machine's
time, which every spawned worker spent again on its first batch), started before this
process builds the variants' table (``start_forkserver``) so that the two overlap; a
forked worker also ends at once at the cluster's close (spawned ones took a second).
"""

from __future__ import annotations

import os

from ..errors import PinSuspError

# What a worker imports for its first batch: imported once, in the server its workers
# are forked from (a name that is not there is skipped)
PRELOAD = (
    "distributed",
    "pin_susp.study.tasks",
    "pin_susp.study.together",  # (a corner's variants measured together)
    "pin_susp.solve.allocator",
    "pin_susp.solve.rates",
    "pin_susp.model.compliance",
    "pin_susp.model.mechanisms.double_wishbone",
    "pin_susp.model.mechanisms.macpherson",
    "pin_susp.model.mechanisms.multilink",
    "pin_susp.model.mechanisms.trailing_arm",
    "pin_susp.subjects.corner",
    "pin_susp.subjects.axle",
    "pin_susp.subjects.vehicle",
    "pin_susp.io.tables",
    "pandas",
    "pyarrow",
)
FORKSERVER = {"distributed.worker.multiprocessing-method": "forkserver"}
# The environment a worker's libraries load in (in the server, for a forked worker; in
# place of Dask's distributed.nanny.pre-spawn-environ, for a spawned one): one thread
# each (OpenBLAS reads it at import: set later, a forked worker's numpy would use every
# core). Not Dask's MALLOC_TRIM_THRESHOLD_ of 64 kB: set, glibc no longer raises its
# mmap threshold, every batch array over 128 kB is mapped and unmapped again, and a
# batch took 1.45x as long (0.77 against 0.53 ms a variant in one process)
ENVIRON = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
SPAWNED = {"distributed.nanny.pre-spawn-environ": ENVIRON}


def start_forkserver() -> bool:
    """Start the server that the local cluster's workers are forked from (with PRELOAD
    imported, in ENVIRON): at once, so that it imports while this process works on.
    False where there is no forkserver (the workers are spawned)."""
    import multiprocessing
    from multiprocessing import forkserver

    if "forkserver" not in multiprocessing.get_all_start_methods():
        return False
    multiprocessing.get_context("forkserver").set_forkserver_preload(list(PRELOAD))
    kept = {name: os.environ.get(name) for name in ENVIRON}
    os.environ.update(ENVIRON)
    try:
        forkserver.ensure_running()  # (one already running is kept: its imports are done)
    finally:
        for name, value in kept.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
    return True


def on_dask(client, task, job, cut, table, todo, steps, finished) -> None:
    from distributed import as_completed

    [remote] = client.scatter([job], broadcast=True, hash=False)
    futures = [
        client.submit(task, remote, i, cut[i], table[cut[i]], steps, pure=False, retries=2)
        for i in todo
    ]
    try:
        for future in as_completed(futures):
            finished(future.result())
            future.release()
    finally:
        client.cancel(futures)


class dask_client:
    """A Dask client: on a LocalCluster (127.0.0.1) or an existing scheduler."""

    def __init__(self, scheduler: str, workers: int | None, forked: bool = False):
        self.scheduler, self.workers = scheduler, workers
        self.cluster = self.client = self.config = None
        self.forked = forked  # the local workers forked from start_forkserver's server

    def __enter__(self):
        import logging

        from distributed import Client, LocalCluster

        for name in ("distributed", "distributed.worker", "distributed.scheduler"):
            logging.getLogger(name).setLevel(logging.ERROR)
        if self.scheduler == "local":
            try:
                self._local(Client, LocalCluster)
            except BaseException:  # what was started goes (a context left is not exited)
                self.__exit__()
                raise
            return self.client
        if not self.scheduler.startswith("tcp://"):
            raise PinSuspError(
                f"--scheduler {self.scheduler}: expected an address like tcp://HOST:PORT, "
                "'local' or 'none'"
            )
        _reachable(self.scheduler)
        self.client = _connect(Client, self.scheduler, seconds=8.0)  # an answer in < 10 s
        if self.workers is not None:
            raise PinSuspError("--workers is for the local cluster; a scheduler has its own")
        return self.client

    def _local(self, client_class, cluster_class) -> None:
        import logging

        import dask

        # for the cluster's life: a worker restarted is forked (or spawned) the same way
        self.config = dask.config.set(SPAWNED | (FORKSERVER if self.forked else {}))
        self.config.__enter__()
        self.cluster = cluster_class(
            n_workers=self.workers or os.cpu_count() or 1,
            threads_per_worker=1,  # the solve is single-threaded Python: a process a core
            processes=True,
            host="127.0.0.1",
            # its pages need bokeh: without it, no dashboard is started (nor printed)
            dashboard_address="127.0.0.1:0" if _has_dashboard() else None,
            silence_logs=logging.ERROR,
        )
        self.client = client_class(self.cluster)

    def __exit__(self, *exc):
        try:
            if self.client is not None:
                self.client.close()
            if self.cluster is not None:
                self.cluster.close()
        finally:
            if self.config is not None:
                self.config.__exit__(None, None, None)
            self.client = self.cluster = self.config = None


def _connect(client_class, address: str, seconds: float):
    """A Client of the scheduler at ``address``, or one clear error within ``seconds``
    (a port that accepts and never speaks Dask would otherwise hold the handshake)."""
    import threading

    box = {}

    def connect() -> None:
        try:
            box["client"] = client_class(address, timeout=f"{seconds:g}s")
        except BaseException as exc:  # reported below, in the caller's thread
            box["error"] = exc

    thread = threading.Thread(target=connect, daemon=True, name="pin-susp-connect")
    thread.start()
    thread.join(seconds + 1.0)
    if "client" in box:
        return box["client"]
    why = "no answer" if thread.is_alive() else type(box.get("error")).__name__
    raise PinSuspError(
        f"--scheduler {address}: no Dask scheduler answered within {seconds:g} s ({why}): "
        "is it a Dask scheduler's address?"
    )


def _reachable(address: str) -> None:
    """A TCP scheduler's port must take a connection (Dask would retry a refusal until
    its timeout): one clear line at once, or after 5 s of silence."""
    import socket
    from urllib.parse import urlsplit

    if not address.startswith("tcp://"):
        return
    try:
        parts = urlsplit(address)
        host, port = parts.hostname, parts.port
    except ValueError:
        host = port = None
    if not host or not port:
        raise PinSuspError(f"--scheduler {address}: expected tcp://HOST:PORT")
    try:
        socket.create_connection((host, port), timeout=5.0).close()
    except OSError as exc:
        why = "timed out" if isinstance(exc, TimeoutError) else exc.strerror or str(exc)
        raise PinSuspError(
            f"--scheduler {address}: no Dask scheduler answers there ({why})"
        ) from None


def _has_dashboard() -> bool:
    import importlib.util

    return importlib.util.find_spec("bokeh") is not None


def dashboard(client, local: bool) -> str | None:
    """The dashboard's address, when it has one to show (on this machine: with bokeh)."""
    if local and not _has_dashboard():
        return None
    try:
        if "dashboard" not in client.scheduler_info().get("services", {}):
            return None
        if not local and not client.run_on_scheduler(_has_dashboard):  # pages need bokeh
            return None
        return client.dashboard_link
    except Exception:  # the link is a courtesy: never a reason to fail
        return None
    return None
