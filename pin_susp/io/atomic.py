"""Writing a file: whole or nothing, and never onto the wrong thing.

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
import errno
import os
import re
import stat
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

from ..errors import NoRoom, PinSuspError

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


def check_folder(path: str | Path, what: str = "output folder") -> Path:
    """Refuse an output folder whose path cannot be made (a name too long for the
    file system, a file on the way), before any work; the path."""
    text = os.fspath(path)
    if text.strip() == "":
        raise PinSuspError(f"the {what}'s path is empty: give a folder")
    folder = Path(text)
    _names_fit(folder, text)
    try:
        folder.exists()
    except OSError as exc:
        raise PinSuspError(f"{text}: cannot write here ({exc.strerror})") from None
    return folder


def _names_fit(folder: Path, text: str) -> None:
    """Each name in a folder's path within the file system's limit (a missing folder
    hides a longer name below it from the kernel's checks, until it is made)."""
    for part in reversed((folder, *folder.parents)):  # from the top: none stat'd past one
        if len(part.name.encode()) > _name_max(existing_ancestor(part.parent)):
            name = _short_name(part.name)
            raise PinSuspError(f"{text}: the name {name} is too long for this file system")


def _short_name(name: str) -> str:
    return repr(name) if len(name) <= 40 else repr(name[:20] + "..." + name[-10:])


def _checked(path: Path, text: str, what: str) -> Path:
    if len(path.name.encode()) > _name_max(existing_ancestor(path.parent)):
        raise PinSuspError(f"{text}: the file name is too long for this file system")
    _names_fit(path.parent, text)  # and every folder's on the way (made before the write)
    if text.endswith(os.sep) or path.is_dir():
        raise PinSuspError(f"{text}: is a directory; the {what} needs a file name")
    if is_stream(path):  # /dev/stdout and friends: write through the link, never rename
        return path
    target = _target(path)
    if is_stream(target):
        return target
    folder = existing_ancestor(target.parent)
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


def existing_ancestor(folder: Path) -> Path:
    """The nearest folder of ``folder`` (itself or a parent) that exists: where a
    name's length limit and the free room are measured before it is made."""
    folder = folder if str(folder) else Path(".")
    while not _exists(folder) and folder != folder.parent:
        folder = folder.parent
    return folder


def _exists(path: Path) -> bool:
    try:
        return path.exists()
    except OSError:  # a name too long, a loop of links: not a folder to write in
        return False


def _name_max(folder: Path) -> int:
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


# A write that fails for want of room: the disk, a quota, a file-size limit.
FULL = _FULL = {errno.ENOSPC, errno.EFBIG, errno.EDQUOT}


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
        except OSError as exc:
            if exc.errno not in _FULL:
                raise
            raise NoRoom(path, exc.strerror, "what was sent to it is incomplete") from None
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
    except BaseException as exc:
        os.unlink(tmp)
        if isinstance(exc, OSError) and exc.errno in _FULL:  # the disk, a quota, ulimit -f
            raise NoRoom(path, exc.strerror) from None
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


def write_text(text: str, path: str | Path) -> None:
    with atomic_write(path) as f:
        f.write(text)
