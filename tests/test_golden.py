"""Every command on every example writes what it wrote before the code was reorganised.

The files under tests/data/golden/ come from the commit in its COMMIT file (regenerate:
``.venv/bin/python tests/golden.py tests/data/golden``). A file must be the same bytes,
or — where a number differs in its last bits — every number within 1e-12 relative
(1e-12 absolute near zero: a closure residual of roundoff size), every other token equal.
"""

import math
import re
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from golden import run

GOLDEN = Path(__file__).resolve().parent / "data" / "golden"
TOKENS = re.compile(r"([,\s:;={}\[\]()\"']+)")  # a text's separators, kept
TOLERANCE = 1e-12


def _close(a: float, b: float) -> bool:
    if a == b or (math.isnan(a) and math.isnan(b)):
        return True
    return abs(a - b) <= TOLERANCE * max(abs(a), abs(b)) + TOLERANCE


def _number(token: str) -> float | None:
    try:
        return float(token)
    except ValueError:
        return None


def _same_text(old: str, new: str, name: str) -> None:
    """Equal but for numbers within the tolerance: token by token (split at the
    separators of CSV, YAML, JSON and XML text), a differing pair must be two numbers."""
    old_tokens, new_tokens = TOKENS.split(old), TOKENS.split(new)
    assert len(old_tokens) == len(new_tokens), f"{name}: a different number of tokens"
    for a, b in zip(old_tokens, new_tokens, strict=True):
        if a == b:
            continue
        x, y = _number(a), _number(b)
        assert x is not None and y is not None, f"{name}: {a!r} became {b!r}"
        assert _close(x, y), f"{name}: {a} became {b}"


def _same_parquet(old: Path, new: Path, name: str) -> None:
    a, b = pq.read_table(old), pq.read_table(new)
    assert a.schema.equals(b.schema, check_metadata=True), f"{name}: schema or metadata"
    for column in a.column_names:
        x, y = a[column].to_pylist(), b[column].to_pylist()
        if x == y:
            continue
        for u, v in zip(x, y, strict=True):
            if isinstance(u, float) and isinstance(v, float):
                assert _close(u, v), f"{name}: {column}: {u} became {v}"
            else:
                assert u == v, f"{name}: {column}: {u!r} became {v!r}"


def test_golden_files_are_kept_with_the_command_that_wrote_them():
    commit, how = (GOLDEN / "COMMIT").read_text().splitlines()
    assert re.fullmatch(r"[0-9a-f]{40}", commit) and "tests/golden.py" in how


@pytest.fixture(scope="module")
def today(tmp_path_factory):
    out = tmp_path_factory.mktemp("golden_today")
    files = run(out / "out", out / "work")
    return out / "out", files


def test_every_job_writes_the_files_it_wrote(today):
    _, files = today
    kept = sorted(
        str(p.relative_to(GOLDEN)) for p in GOLDEN.rglob("*") if p.is_file() and p.name != "COMMIT"
    )
    assert files == kept


def test_every_file_is_the_same(today):
    out, files = today
    for name in files:
        old, new = GOLDEN / name, out / name
        if old.read_bytes() == new.read_bytes():
            continue
        if name.endswith(".parquet"):
            _same_parquet(old, new, name)
        else:
            _same_text(old.read_text(), new.read_text(), name)
