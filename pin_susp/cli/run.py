"""How a command runs and ends: its exit codes, an input error as one line, Ctrl+C,
SIGTERM and SIGHUP as an interrupt (temporary files and servers removed), what an
interrupt leaves, and the warnings printed after a run that went through.

Exit codes: 0 success; 1 the run finished but some steps did not converge (their
rows are written, flagged ``solver_converged = False`` with empty metric cells); 2 a
problem with the input (one line on stderr, nothing written); 128 + N a signal N.
"""

from __future__ import annotations

import contextlib
import errno
import signal
import sys
import threading
import warnings
from pathlib import Path

from ..errors import EXIT_INPUT, PinSuspError, PlausibilityWarning


def execute(args) -> int:
    """Run a parsed command: its exit code; an input error as one line (exit 2), an
    interrupt or SIGTERM/SIGHUP as 128 + the signal, a closed pipe as success."""
    import numpy as np

    from ..io.yamlio import read_once
    from .report import print_warnings

    with (
        terminate_as_exit(),
        read_once(),  # each input read once: a pipe or a FIFO cannot be read twice
        warnings.catch_warnings(record=True) as caught,
        np.errstate(all="ignore"),
    ):
        # Undefined values (parallel arms, a toggle) are NaN by design and flagged
        # where they matter; numpy's warnings about them would only be noise.
        warnings.simplefilter("ignore")
        warnings.simplefilter("always", PlausibilityWarning)
        args.warnings = caught
        try:
            refuse_unbuilt(args)
            code = args.run(args)
            print_warnings(args)  # only for a run that went through: exit 2 is one line
            return code
        except PinSuspError as exc:  # one line, whatever the file's keys hold
            message = str(exc).replace("\r", "\\r").replace("\n", "\\n")
            print(f"pin-susp: error: {message}", file=sys.stderr)
            return EXIT_INPUT
        except (KeyboardInterrupt, Terminated) as exc:
            signal_number = exc.signal if isinstance(exc, Terminated) else signal.SIGINT
            print(f"pin-susp: interrupted, {unwritten(args)}", file=sys.stderr)
            return 128 + signal_number
        except BrokenPipeError:  # output piped into `head` and the like
            sys.stderr.close()
            return 0
        except OSError as exc:  # a safety net: each output path is checked before any work
            if exc.errno != errno.ENAMETOOLONG:
                raise
            name = exc.filename if exc.filename is not None else "a path"
            print(f"pin-susp: error: {name}: a name too long for the file system", file=sys.stderr)
            return EXIT_INPUT


def refuse_unbuilt(args) -> None:
    """A command its subject does not take yet (Assembly.commands: a vehicle's sweep
    alone) refused with one line, before any work; a file that cannot be read is left to
    the command's own message."""
    geometry, name = vars(args).get("geometry"), vars(args).get("command_name")
    if geometry is None or name is None:
        return
    from ..errors import InputError
    from ..subjects.subject import subject_class

    try:
        kind = subject_class(geometry)
    except PinSuspError:
        return
    if kind.commands is not None and name not in kind.commands:
        takes = ", ".join(f"pin-susp {c}" for c in kind.commands)
        raise InputError(
            str(geometry),
            "scope",
            f"{'an' if kind.noun[0] in 'aeiou' else 'a'} {kind.noun} takes {takes} so far: "
            f"{name} is not built yet",
        )


def unwritten(args) -> str:
    """What an interrupt leaves: no file; but what went into a stream (-o /dev/stdout, a
    pipe) is out, and a streamed sweep may have sent some of its rows."""
    output = getattr(args, "output", None)
    if isinstance(output, str) and output:
        from ..io.atomic import is_stream

        if is_stream(Path(output)):
            return f"{output} is a stream: what was already sent to it is incomplete"
    return "nothing written"


class Terminated(BaseException):
    """SIGTERM or SIGHUP: unwinds like Ctrl+C, so temporary files and servers are removed."""

    def __init__(self, signal_number: int):
        super().__init__(signal_number)
        self.signal = signal_number


@contextlib.contextmanager
def terminate_as_exit():
    """While a command runs, SIGTERM and SIGHUP raise Terminated (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signal_number, _frame):
        raise Terminated(signal_number)

    previous = {s: signal.signal(s, handler) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
