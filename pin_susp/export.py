"""Writing results and URDFs: whole files or nothing.

Every writer goes through :func:`atomic_write`, which writes a temporary
file beside the target and renames it into place, so an interrupted or
failed run never leaves a half-written file.
"""

from __future__ import annotations

import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from . import __version__
from .errors import PinSuspError


@contextmanager
def atomic_write(path: str | Path, binary: bool = False):
    """Open a file for writing that appears at ``path`` only when complete."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise PinSuspError(f"{path}: cannot write here ({exc.strerror})") from None
    try:
        with os.fdopen(fd, "wb") if binary else os.fdopen(fd, "w", newline="") as f:
            yield f
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes it private; files are not
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


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
    x = float(value)
    return "" if np.isnan(x) else repr(x)


def write_csv(results, path: str | Path) -> None:
    """Results as CSV: ``#`` comment lines, one header row, one row per step."""
    names = list(results.columns)
    columns = [results.columns[n] for n in names]
    with atomic_write(path) as f:
        f.write(f"# pin_susp {__version__}\n")
        for what in ("geometry", "sweep"):
            source, sha = results.meta[what]
            f.write(f"# {what}: {source}" + (f" sha256={sha}" if sha else "") + "\n")
        f.write("# units: " + json.dumps(results.units) + "\n")
        f.write(",".join(names) + "\n")
        for i in range(len(results)):
            f.write(",".join(format_cell(c[i]) for c in columns) + "\n")


def write_text(text: str, path: str | Path) -> None:
    with atomic_write(path) as f:
        f.write(text)
