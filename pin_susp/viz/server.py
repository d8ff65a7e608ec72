"""meshcat's server for the 3D view: started on 127.0.0.1 as a child that ends with
this process (even on SIGKILL), stopped at once if it lingers; and the signals held
while code that must not lose one runs (an import that swallows Ctrl+C, a server
being stopped)."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading

# meshcat's own server, with its web server bound to loopback (meshcat 0.3.2's
# listens on every interface; its ZMQ socket is on 127.0.0.1 already). It asks
# Linux to end it when its parent (the pin-susp process, argv[1]) dies, even by
# SIGKILL: set here, after exec, not in a preexec_fn (unsafe in a threaded parent).
_SERVER = """
import os, signal, sys
if sys.platform.startswith("linux"):
    import ctypes
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    if os.getppid() != int(sys.argv[1]):  # the parent died before that: go now
        sys.exit(0)
import tornado.web
listen = tornado.web.Application.listen
tornado.web.Application.listen = lambda app, port, address="127.0.0.1", **kw: listen(
    app, port, address, **kw
)
sys.argv = ["meshcat-server"]
from meshcat.servers.zmqserver import main
main()
"""


@contextlib.contextmanager
def signals_held(signals=(signal.SIGINT, signal.SIGTERM, signal.SIGHUP)):
    """Inside, these signals wait; the first that came is handled once the block ends,
    as it would have been (Ctrl+C: KeyboardInterrupt). For code that must not lose one:
    an import that swallows KeyboardInterrupt (pinocchio.visualize imports trimesh,
    whose imports catch BaseException), a server being stopped. Main thread only."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    came = []
    previous = {}
    for s in signals:
        if signal.getsignal(s) is not None:  # None: a handler Python did not install
            previous[s] = signal.signal(s, lambda number, _: came.append(number))
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        if came:
            handler = previous[came[0]]
            if callable(handler):
                handler(came[0], None)  # raises, as it would have inside
            elif handler == signal.SIG_DFL:
                signal.raise_signal(came[0])


def meshcat_visualizer():
    """Pinocchio's MeshcatVisualizer, imported with Ctrl+C held: its package imports
    trimesh, which swallows an interrupt that comes while it loads."""
    with signals_held():
        from pinocchio.visualize import MeshcatVisualizer
    return MeshcatVisualizer


def start_server() -> tuple[subprocess.Popen, str]:
    """A meshcat server on 127.0.0.1 that ends with this process (even on SIGKILL).

    Returns the process and its ZMQ URL.
    """
    from meshcat.servers.zmqserver import match_zmq_url

    proc = subprocess.Popen(
        [sys.executable, "-u", "-c", _SERVER, str(os.getpid())],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # a Ctrl+C is ours to handle: we stop it in close()
    )
    try:
        line = ""
        while "zmq_url" not in line:
            line = proc.stdout.readline().decode("utf-8", "replace")
            if not line and proc.poll() is not None:
                raise RuntimeError(f"the meshcat server exited at start (code {proc.returncode})")
        proc.stdout.readline()  # its web URL: the viewer asks for it over ZMQ
    except BaseException:  # an interrupt while it starts: it goes with us
        stop_server(proc)
        raise
    return proc, match_zmq_url(line.strip())


def stop_server(proc: subprocess.Popen) -> None:
    """End a server process, at once if it does not end within 10 s."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
