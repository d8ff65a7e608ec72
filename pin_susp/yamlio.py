"""Reading user YAML with error messages that name the file and the key.

Every check a geometry or sweep file needs (a mapping with known keys, a
finite number, one of a few words, a point) lives here once, so each loader
reads like the format it accepts.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from .errors import InputError


def load_yaml(source: str | Path | dict) -> tuple[dict, str, str | None]:
    """Return (mapping, name for messages, sha256 of the file or None)."""
    if isinstance(source, dict):
        return source, "<dict>", None
    path = Path(source)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise InputError(str(path), "", "file not found") from None
    except IsADirectoryError:
        raise InputError(str(path), "", "is a directory, not a YAML file") from None
    except OSError as exc:
        raise InputError(str(path), "", f"cannot be read ({exc.strerror})") from None
    try:
        data = yaml.safe_load(raw)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or "syntax error"
        raise InputError(str(path), "", f"not valid YAML{where}: {problem}") from None
    if not isinstance(data, dict):
        raise InputError(str(path), "", "expected a YAML mapping (key: value) at the top level")
    return data, str(path), hashlib.sha256(raw).hexdigest()


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

    def number(self, value: Any, key: str, minimum: float | None = None) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            self.fail(key, f"expected a number, got {_kind(value)}")
        x = float(value)
        if not math.isfinite(x):
            self.fail(key, f"expected a finite number, got {value}")
        if minimum is not None and x < minimum:
            self.fail(key, f"must be >= {minimum:g}, got {x:g}")
        return x

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
            self.fail(key, f"expected one of {', '.join(options)}, got {value!r}")
        return value

    def vector(self, value: Any, key: str) -> np.ndarray:
        """A point or vector as {x, y, z} or [x, y, z], in the file's units."""
        if isinstance(value, dict):
            self.mapping(value, key, required=("x", "y", "z"))
            items = [(_join(key, a), value[a]) for a in "xyz"]
        elif isinstance(value, list | tuple):
            if len(value) != 3:
                self.fail(key, f"expected 3 coordinates [x, y, z], got {len(value)}")
            items = [(f"{key}[{i}]", v) for i, v in enumerate(value)]
        else:
            self.fail(key, f"expected {{x, y, z}} or [x, y, z], got {_kind(value)}")
        return np.array([self.number(v, k) for k, v in items])


def _join(key: str, name: str) -> str:
    return f"{key}.{name}" if key else name


def _kind(value: Any) -> str:
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return f"a boolean ({value})"
    if isinstance(value, str):
        return f"text {value!r}"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return f"{type(value).__name__} {value!r}"
