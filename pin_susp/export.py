"""Writing outputs: whole files or nothing, and never onto the wrong thing.

Every output goes through :func:`atomic_write`, the one place that renames:

- a regular file, or a new path, is written to a temporary file beside it
  and renamed into place, so an interrupted or failed run never leaves a
  half-written file;
- a symlink is followed: its target is replaced the same way, the link stays;
- a character device or a FIFO (``/dev/null``, ``/dev/stdout``, a pipe) is
  written as a stream: renaming over it would replace the device;
- a directory, ``''`` or ``.`` is refused by :func:`check_output` before any
  work starts.

A command with several outputs writes them inside :func:`all_or_none`: each
file goes to its temporary name, and the renames happen together at the end,
so a failure part-way leaves none of them.
"""

from __future__ import annotations

import contextvars
import json
import os
import re
import stat
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from . import __version__
from .errors import PinSuspError

# The renames a running all_or_none() block has put off: (temporary, final) pairs.
_PENDING: contextvars.ContextVar[list | None] = contextvars.ContextVar("pending", default=None)


def check_output(path: str | Path, what: str = "output") -> Path:
    """Refuse an output path that cannot be written as a file, before any work.

    Returns the path to write: a symlink's target, or the path itself.
    """
    text = os.fspath(path)
    if text.strip() == "":
        raise PinSuspError(f"the {what} path is empty: give a file name")
    try:
        return _checked(Path(text), text, what)
    except OSError as exc:
        raise PinSuspError(f"{text}: cannot write here ({exc.strerror})") from None


def _checked(path: Path, text: str, what: str) -> Path:
    if len(path.name.encode()) > _name_max(_existing_ancestor(path.parent)):
        raise PinSuspError(f"{text}: the file name is too long for this file system")
    if text.endswith(os.sep) or path.is_dir():
        raise PinSuspError(f"{text}: is a directory; the {what} needs a file name")
    if is_stream(path):  # /dev/stdout and friends: write through the link, never rename
        return path
    target = _target(path)
    if is_stream(target):
        return target
    folder = _existing_ancestor(target.parent)
    if not folder.is_dir():
        raise PinSuspError(f"{text}: cannot write here ({folder} is not a directory)")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PinSuspError(f"{text}: cannot write here (no permission in {folder})")
    if target.exists() and not target.is_file():
        raise PinSuspError(f"{text}: exists and is not a regular file, a device or a pipe")
    return target


def _target(path: Path) -> Path:
    """A symlink's final target (followed however deep), else the path itself."""
    return Path(os.path.realpath(path)) if path.is_symlink() else path


def is_stream(path: Path) -> bool:
    """A device, pipe or socket — or an existing name for one of this process's open
    files (/dev/stdout → /proc/self/fd/1, even where that is a regular file)."""
    try:
        mode = path.stat().st_mode
    except OSError:
        return False
    if stat.S_ISCHR(mode) or stat.S_ISFIFO(mode) or stat.S_ISSOCK(mode):
        return True
    return _open_fd(path) is not None


def _open_fd(path: Path) -> int | None:
    """The file descriptor a path names when it is one of this process's open files
    (/dev/stdout → /proc/self/fd/1, /dev/fd/3), followed one link at a time."""
    text = os.fspath(path)
    for _ in range(8):
        found = re.fullmatch(r"/(?:proc/(self|\d+)/fd|dev/fd)/(\d+)", text)
        if found and found.group(1) in (None, "self", str(os.getpid())):
            return int(found.group(2))
        if not os.path.islink(text):
            return None
        text = os.path.join(os.path.dirname(text), os.readlink(text))
    return None


def _existing_ancestor(folder: Path) -> Path:
    folder = folder if str(folder) else Path(".")
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    return folder


def _name_max(folder: Path) -> int:
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


@contextmanager
def atomic_write(path: str | Path, binary: bool = False):
    """Open a file for writing that appears at ``path`` only when complete."""
    target = check_output(path)
    mode = "wb" if binary else "w"
    newline = None if binary else ""
    if is_stream(target):
        fd = _open_fd(target)
        sys.stdout.flush()  # what we printed before comes first
        try:
            if fd is None:
                stream = open(target, mode, newline=newline)
            else:  # the open file itself (its offset), not the name reopened from 0
                stream = os.fdopen(os.dup(fd), mode, newline=newline)
            with stream as f:
                yield f
        except BrokenPipeError:
            raise PinSuspError(f"{path}: the reader closed it before the end") from None
        return
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        # A short temporary name: the final name may be as long as the file system allows.
        fd, tmp = tempfile.mkstemp(prefix=".pin_susp-", suffix=".tmp", dir=target.parent)
    except OSError as exc:
        raise PinSuspError(f"{path}: cannot write here ({exc.strerror})") from None
    try:
        with os.fdopen(fd, mode, newline=newline) as f:
            yield f
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes it private; outputs are not
    except BaseException:
        os.unlink(tmp)
        raise
    pending = _PENDING.get()
    if pending is None:
        _rename(tmp, target)
    else:
        pending.append((tmp, target))


@contextmanager
def all_or_none():
    """Outputs written inside appear together at the end, or not at all."""
    pending: list = []
    token = _PENDING.set(pending)
    try:
        yield
    except BaseException:
        for tmp, _ in pending:
            _unlink(tmp)
        raise
    finally:
        _PENDING.reset(token)
    for i, (tmp, target) in enumerate(pending):
        try:
            _rename(tmp, target)
        except BaseException:
            for later, _ in pending[i + 1 :]:
                _unlink(later)
            raise


def _rename(tmp: str, target: Path) -> None:
    try:
        os.replace(tmp, target)
    except OSError as exc:
        _unlink(tmp)
        raise PinSuspError(f"{target}: cannot write here ({exc.strerror})") from None


def _unlink(path: str) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def format_cell(value) -> str:
    """Full precision (repr); an undefined value (NaN) is an empty cell."""
    if isinstance(value, bool | np.bool_):
        return "True" if value else "False"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, str):  # a name (a load case's): quoted as CSV quotes
        quote = any(c in value for c in ',"\n\r')
        return '"' + value.replace('"', '""') + '"' if quote else value
    x = float(value)
    return "" if np.isnan(x) else repr(x)


def csv_text(results) -> str:
    """Results as CSV text: ``#`` comment lines, one header row, one row per step."""
    names = list(results.columns)
    columns = [results.columns[n] for n in names]
    lines = [f"# pin_susp {__version__}"]
    for what in ("geometry", "sweep"):
        source, sha = results.meta[what]
        lines.append(f"# {what}: {source}" + (f" sha256={sha}" if sha else ""))
    lines.append("# units: " + json.dumps(results.units))
    lines.append(",".join(names))
    cells = [_column_cells(c) for c in columns]
    lines.extend(",".join(row) for row in zip(*cells, strict=True))
    return "\n".join(lines) + "\n"


def _column_cells(values) -> list[str]:
    """format_cell for a whole column at once (numpy's str of a float64 is the same
    shortest round-trip text as repr): a column of numbers or flags in one call."""
    v = np.asarray(values)
    if v.dtype.kind == "b":
        return np.where(v, "True", "False").tolist()
    if v.dtype.kind in "iu":
        return v.astype(str).tolist()
    if v.dtype.kind == "f":
        text = v.astype(str)
        text[np.isnan(v)] = ""
        return text.tolist()
    return [format_cell(x) for x in v]  # names and mixed columns, one by one


def write_csv(results, path: str | Path) -> None:
    """Results as a CSV file (csv_text), whole or not at all."""
    write_text(csv_text(results), path)


def write_parquet(results, path: str | Path) -> None:
    """Results as a Parquet file (pyarrow), whole or not at all: the CSV's columns, an
    undefined value (a blank CSV cell) as a null, the units, the sources and the
    pin_susp version in the schema's metadata."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    columns = arrow_columns(results)
    meta = {"pin_susp": __version__, "units": json.dumps(results.units)}
    for what in ("geometry", "sweep"):
        source, sha = results.meta[what]
        meta[what] = json.dumps({"source": str(source), "sha256": sha})
    table = pa.table(columns).replace_schema_metadata(meta)
    with atomic_write(path, binary=True) as f:
        pq.write_table(table, f)


def arrow_column(values):
    """A column for Arrow (Parquet): an undefined value (NaN, a blank CSV cell) is null."""
    import pyarrow as pa

    values = np.asarray(values)
    return pa.array(values, from_pandas=values.dtype.kind == "f")


def arrow_columns(results) -> dict:
    """Every column of results for Arrow, in the CSV's order (arrow_column)."""
    return {name: arrow_column(values) for name, values in results.columns.items()}


def results_frame(results):
    """Results as a pandas DataFrame, one row per step (units in ``.attrs['units']``)."""
    import pandas as pd

    frame = pd.DataFrame({k: np.asarray(v) for k, v in results.columns.items()})
    frame.attrs["units"] = {k: u for k, u in results.units.items() if u}
    return frame


def write_text(text: str, path: str | Path) -> None:
    with atomic_write(path) as f:
        f.write(text)
