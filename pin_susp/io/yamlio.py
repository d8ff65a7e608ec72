"""Reading user YAML with error messages that name the file and the key.

Every check a geometry or sweep file needs (a mapping with known keys, a
finite number, one of a few words, a point) lives here once, so each loader
reads like the format it accepts.
"""

from __future__ import annotations

import contextlib
import contextvars
import copy
import functools
import hashlib
import math
import os
import re
import stat
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..errors import InputError

MAX_LENGTH_MM = 100_000.0
"""Largest coordinate or length accepted, in mm: 100 m is far outside any car,
so a bigger value is a typo or a unit mix-up, not a design."""

MAX_DEPTH = 100
"""Deepest nesting accepted; real files need fewer than ten levels, and
PyYAML's composer recurses once per level (thousands overflow the stack)."""

_MERGE = "tag:yaml.org,2002:merge"
_LEADING_ZERO = re.compile(r"[-+]?0[0-9]+")


class _Problem(Exception):
    """Raised inside the loader; load_yaml adds the file name."""

    def __init__(self, key: str, problem: str):
        super().__init__(problem)
        self.key = key
        self.problem = problem


class _Loader(yaml.SafeLoader):
    """SafeLoader that rejects duplicate keys and reads numbers as engineers write them.

    ``0250`` is decimal 250 (YAML 1.1 would say octal 168, and ``0259`` text);
    ``2e2`` and ``1.e5`` are floats (YAML 1.1 needs a dot and a signed exponent).
    """

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0
        self._paths: dict[yaml.Node, str] = {}  # node -> key path, for messages

    def compose_node(self, parent, index):
        # Bound the recursion here rather than let RecursionError escape.
        if self._depth >= MAX_DEPTH:
            line = self.peek_event().start_mark.line + 1
            raise _Problem("", f"nested too deeply (more than {MAX_DEPTH} levels) at line {line}")
        self._depth += 1
        try:
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_object(self, node, deep=False):
        # Bad values behind explicit tags or date-like text ("!!float abc",
        # "2020-13-45", 5000 digits) raise plain Python errors inside PyYAML.
        try:
            return super().construct_object(node, deep)
        except (ValueError, TypeError, AttributeError, OverflowError):
            kind = node.tag.rsplit(":", 1)[-1]
            problem = f"cannot read {short_repr(node.value)} as {kind}"
            raise yaml.constructor.ConstructorError(None, None, problem, node.start_mark) from None

    def construct_sequence(self, node, deep=False):
        path = self._paths.get(node, "")
        for i, child in enumerate(node.value):
            self._paths.setdefault(child, f"{path}[{i}]")
        return super().construct_sequence(node, deep)

    def construct_mapping(self, node, deep=False):
        # Check the keys as written: "<<" merges may legitimately repeat keys.
        path = self._paths.get(node, "")
        seen = set()
        for key_node, value_node in node.value:
            if key_node.tag == _MERGE:
                continue
            key = self.construct_object(key_node)
            try:
                duplicate = key in seen
                seen.add(key)
            except TypeError:  # unhashable: SafeConstructor reports it below
                continue
            if duplicate:
                line = key_node.start_mark.line + 1
                raise _Problem(
                    _join(path, str(key)),
                    f"duplicate key at line {line} (each key may appear once)",
                )
            self._paths.setdefault(value_node, _join(path, str(key)))
        return super().construct_mapping(node, deep)

    def construct_decimal_int(self, node):
        value = self.construct_scalar(node).replace("_", "")
        if ":" in value:  # YAML 1.1 base 60 (3:20 = 200): a time, not a length; keep the text
            return self.construct_scalar(node)
        if _LEADING_ZERO.fullmatch(value):
            return int(value, 10)
        return self.construct_yaml_int(node)

    def construct_decimal_float(self, node):
        if ":" in self.construct_scalar(node):  # base 60, as for ints
            return self.construct_scalar(node)
        return self.construct_yaml_float(node)


# Appended, so YAML 1.1's own int and float patterns still match first.
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:int", re.compile(r"^[-+]?[0-9]+$"), list("-+0123456789")
)
_Loader.add_implicit_resolver(  # the YAML 1.2 core schema float
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?$"),
    list("-+.0123456789"),
)
_Loader.add_constructor("tag:yaml.org,2002:int", _Loader.construct_decimal_int)
_Loader.add_constructor("tag:yaml.org,2002:float", _Loader.construct_decimal_float)


def load_yaml(source: str | Path | dict) -> tuple[dict, str, str | None]:
    """Return (mapping, name for messages, sha256 of the file or None).

    Every problem with the file (unreadable, not UTF-8, not YAML, a duplicate
    key, nested too deeply, not a mapping) raises InputError.
    """
    if isinstance(source, dict):
        return source, "<dict>", None
    path = Path(source)
    try:
        raw = read_input(path)
    except FileNotFoundError:
        raise InputError(str(path), "", "file not found") from None
    except IsADirectoryError:
        raise InputError(str(path), "", "is a directory, not a YAML file") from None
    except OSError as exc:
        raise InputError(str(path), "", f"cannot be read ({exc.strerror})") from None
    try:
        data = copy.deepcopy(_parse(raw))  # a copy: the caller may change it
    except _Problem as exc:
        raise InputError(str(path), exc.key, exc.problem) from None
    except RecursionError:  # a safety net: MAX_DEPTH should stop it first
        raise InputError(str(path), "", "nested too deeply") from None
    except yaml.reader.ReaderError as exc:
        if exc.encoding == "unicode":  # decoded, but a control character
            problem = f"control character #x{exc.character:04x} at character {exc.position}"
        else:
            problem = f"not {exc.encoding} text (byte 0x{exc.character:02x} at byte {exc.position})"
        raise InputError(str(path), "", f"not valid YAML: {problem}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or "syntax error"
        raise InputError(str(path), "", f"not valid YAML{where}: {problem}") from None
    if data is None:
        raise InputError(str(path), "", "is empty (expected a YAML mapping of key: value)")
    if not isinstance(data, dict):
        raise InputError(
            str(path),
            "",
            f"expected a YAML mapping (key: value) at the top level, got {_kind(data)}",
        )
    return data, str(path), hashlib.sha256(raw).hexdigest()


# Inside read_once(): the bytes of every input read so far, by what the file is.
_READ: contextvars.ContextVar[dict | None] = contextvars.ContextVar("read", default=None)


@contextlib.contextmanager
def read_once():
    """Inside, every input is read from its file once: a second read of it (the CLI asks
    a geometry's scope, then loads it; a study reads its sweep, then solves it) gets the
    same bytes. A pipe or a FIFO (``cat g.yaml | pin-susp sweep /dev/stdin ...``) can
    only be read once, and a file edited while a command runs is still one file to it.
    Nested blocks share the outer one's reads."""
    if _READ.get() is not None:
        yield
        return
    token = _READ.set({})
    try:
        yield
    finally:
        _READ.reset(token)


def read_input(path: str | Path) -> bytes:
    """The bytes of an input file (once per file inside read_once()). OSError as open()
    raises it; a directory: IsADirectoryError."""
    path = Path(path)
    cache = _READ.get()
    if cache is None:
        return path.read_bytes()
    st = os.stat(path)
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(21, "Is a directory", str(path))
    key = (st.st_dev, st.st_ino)
    if stat.S_ISREG(st.st_mode):  # a regular file: the same one unchanged
        key += (st.st_size, st.st_mtime_ns)
    if key not in cache:
        cache[key] = path.read_bytes()
    return cache[key]


@functools.lru_cache(maxsize=8)
def _parse(raw: bytes) -> Any:
    """A file's YAML, parsed once per content: pure-Python YAML is the slow part of
    reading a file, and a study's variants are built from the same text many times."""
    return yaml.load(raw, Loader=_Loader)  # _Loader is a SafeLoader: no arbitrary objects


class Reader:
    """Typed access to a user's mapping; every failure raises InputError."""

    def __init__(self, source: str):
        self.source = source

    def fail(self, key: str, problem: str):
        raise InputError(self.source, key, problem)

    def mapping(
        self,
        value: Any,
        key: str,
        required: tuple[str, ...] = (),
        optional: tuple[str, ...] = (),
    ) -> dict:
        if not isinstance(value, dict):
            self.fail(key, f"expected a mapping, got {_kind(value)}")
        allowed = set(required) | set(optional)
        for name in value:
            if name not in allowed:
                known = ", ".join(sorted(allowed))
                self.fail(_join(key, str(name)), f"unknown key (known keys here: {known})")
        for name in required:
            if name not in value:
                self.fail(_join(key, name), "missing key")
        return value

    def number(
        self, value: Any, key: str, minimum: float | None = None, *, limit: float | None = None
    ) -> float:
        """A finite int or float as a float; ``limit`` (mm) bounds its magnitude."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            self.fail(key, f"expected a number, got {_kind(value)}")
        try:
            x = float(value)
        except OverflowError:  # an int beyond float range
            self.fail(key, "expected a finite number, got an integer too large for a float")
        if not math.isfinite(x):
            self.fail(key, f"expected a finite number, got {value}")
        if minimum is not None and x < minimum:
            self.fail(key, f"must be >= {minimum:g}, got {x:g}")
        if limit is not None and abs(x) > limit:
            self.fail(
                key,
                f"{x:g} mm is beyond the {limit / 1000:g} m limit of any car (lengths are in mm)",
            )
        return x

    def length(self, value: Any, key: str) -> float:
        """A number in mm within MAX_LENGTH_MM of zero."""
        return self.number(value, key, limit=MAX_LENGTH_MM)

    def positive(self, value: Any, key: str) -> float:
        x = self.number(value, key)
        if x <= 0.0:
            self.fail(key, f"must be > 0, got {x:g}")
        return x

    def text(self, value: Any, key: str) -> str:
        if not isinstance(value, str | int | float) or isinstance(value, bool):
            self.fail(key, f"expected text, got {_kind(value)}")
        return str(value)

    def choice(self, value: Any, key: str, options: tuple[str, ...]) -> str:
        if not isinstance(value, str) or value not in options:
            self.fail(key, f"expected one of {', '.join(options)}, got {short_repr(value)}")
        return value

    def vector(self, value: Any, key: str, *, limit: float | None = None) -> np.ndarray:
        """A point or vector as {x, y, z} or [x, y, z], in the file's units.

        ``limit`` (mm) bounds each coordinate's magnitude, as in number().
        """
        if isinstance(value, dict):
            self.mapping(value, key, required=("x", "y", "z"))
            items = [(_join(key, a), value[a]) for a in "xyz"]
        elif isinstance(value, list | tuple):
            if len(value) != 3:
                self.fail(key, f"expected 3 coordinates [x, y, z], got {len(value)}")
            items = [(f"{key}[{i}]", v) for i, v in enumerate(value)]
        else:
            self.fail(key, f"expected {{x, y, z}} or [x, y, z], got {_kind(value)}")
        return np.array([self.number(v, k, limit=limit) for k, v in items])

    def point(self, value: Any, key: str) -> np.ndarray:
        """A point in mm, each coordinate within MAX_LENGTH_MM of zero."""
        return self.vector(value, key, limit=MAX_LENGTH_MM)


def _join(key: str, name: str) -> str:
    return f"{key}.{name}" if key else name


def _kind(value: Any) -> str:
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return f"a boolean ({value})"
    if isinstance(value, str):
        return f"text {short_repr(value)}"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return f"{type(value).__name__} {short_repr(value)}"


def short_repr(value: Any) -> str:
    """repr() cut to one readable line: hostile files hold megabyte strings."""
    text = repr(value)
    return text if len(text) <= 60 else text[:50] + "..." + text[-5:]
