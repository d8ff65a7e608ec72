"""yamlio against hostile input: every bad file is one clean InputError."""

import math
import random

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES

from pin_susp.cli import main
from pin_susp.errors import InputError
from pin_susp.io.yamlio import MAX_DEPTH, MAX_LENGTH_MM, Reader, load_yaml


def write(tmp_path, content: str | bytes, name: str = "corner.yaml"):
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return path


def error(path) -> InputError:
    with pytest.raises(InputError) as info:
        load_yaml(path)
    return info.value


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.yaml")), ids=lambda p: p.name)
def test_examples_read_as_safe_load_reads_them(path):
    assert load_yaml(path)[0] == yaml.safe_load(path.read_text())


DUPLICATES = {
    "coordinate": (
        "hardpoints:\n  lower_wishbone_outboard:\n    x: 0\n    y: 900\n    x: 5\n",
        "hardpoints.lower_wishbone_outboard.x: duplicate key at line 5",
    ),
    "point": (
        "hardpoints:\n  lower_wishbone_outboard: {x: 0, y: 900, z: 200}\n"
        "  lower_wishbone_outboard: {x: 1, y: 900, z: 200}\n",
        "hardpoints.lower_wishbone_outboard: duplicate key at line 3",
    ),
    "top level": ("side: left\nname: a\nside: right\n", "side: duplicate key at line 3"),
    "in a list": (
        "targets:\n  - {point: a, point: b}\n",
        "targets[0].point: duplicate key at line 2",
    ),
}


@pytest.mark.parametrize("case", DUPLICATES)
def test_duplicate_keys_name_the_key_path_and_line(tmp_path, case):
    text, message = DUPLICATES[case]
    path = write(tmp_path, text)
    assert str(error(path)) == f"{path}: {message} (each key may appear once)"


def test_merge_keys_may_be_overridden(tmp_path):
    path = write(tmp_path, "base: &b {x: 1, y: 2}\np: {<<: *b, x: 5}\n")
    assert load_yaml(path)[0]["p"] == {"x": 5, "y": 2}


def test_cli_prints_a_duplicate_key_on_one_line(tmp_path, capsys):
    path = write(tmp_path, "type: double_wishbone\nhardpoints: {}\ntype: macpherson\n")
    code = main(["sweep", str(path), str(EXAMPLES / "bump_steer.yaml"), "-o", str(tmp_path / "o")])
    line = f"pin-susp: error: {path}: type: duplicate key at line 3 (each key may appear once)\n"
    assert (code, capsys.readouterr().err) == (2, line)


NUMBERS = {
    "0250": 250,  # decimal, not YAML 1.1 octal 168
    "0259": 259,  # not text
    "-0250": -250,
    "007": 7,
    "0": 0,
    "250": 250,
    "1_000": 1000,
    "2e2": 200.0,
    "1e9": 1e9,
    "-3E-2": -0.03,
    "1.e5": 1e5,
    "1.0e5": 1e5,
    "+.5e1": 5.0,
    "12.5": 12.5,
    "0x1F": 31,  # hex stays as YAML reads it
    "0o17": "0o17",  # not a YAML 1.1 number: stays text
    "yes": True,  # booleans stay
    "1e400": math.inf,
}


@pytest.mark.parametrize("text", NUMBERS)
def test_numbers_as_an_engineer_writes_them(tmp_path, text):
    value = load_yaml(write(tmp_path, f"x: {text}\n"))[0]["x"]
    assert (value, type(value)) == (NUMBERS[text], type(NUMBERS[text]))


def test_inf_and_nan_are_read_then_rejected(tmp_path):
    path = write(tmp_path, "a: .inf\nb: -.inf\nc: .nan\n")
    data, name, _ = load_yaml(path)
    assert data["a"] == math.inf and data["b"] == -math.inf and math.isnan(data["c"])
    with pytest.raises(InputError, match=r": a: expected a finite number, got inf$"):
        Reader(name).number(data["a"], "a")


def test_the_global_safe_loader_is_untouched(tmp_path):
    load_yaml(write(tmp_path, "x: 1\n"))
    assert yaml.safe_load("a: 0250\nb: 2e2\nc: {x: 1, x: 2}") == {
        "a": 168,
        "b": "2e2",
        "c": {"x": 2},
    }


def test_nesting_thousands_deep_is_one_clean_error(tmp_path):
    path = write(tmp_path, "[" * 5000)
    assert str(error(path)) == f"{path}: nested too deeply (more than {MAX_DEPTH} levels) at line 1"
    deep = "a:\n" + "".join(" " * i + "b:\n" for i in range(1, 3 * MAX_DEPTH))
    assert "nested too deeply" in str(error(write(tmp_path, deep)))


HOSTILE = {
    "empty": (b"", "is empty (expected a YAML mapping of key: value)"),
    "only ---": (b"---\n", "is empty (expected a YAML mapping of key: value)"),
    "bare scalar": (
        b"hello",
        "expected a YAML mapping (key: value) at the top level, got text 'hello'",
    ),
    "list": (b"- 1\n", "expected a YAML mapping (key: value) at the top level, got a list"),
    "binary": (b"a: \x80\x81", "not valid YAML: not utf-8 text (byte 0x80 at byte 3)"),
    "control character": (b"a: b\x01", "not valid YAML: control character #x0001 at character 4"),
    "syntax": (
        b"a: [1, 2\n",
        "not valid YAML at line 2, column 1: expected ',' or ']', but got '<stream end>'",
    ),
    "two documents": (
        b"a: 1\n---\nb: 2\n",
        "not valid YAML at line 2, column 1: but found another document",
    ),
    "impossible date": (
        b"x: 2020-13-45\n",
        "not valid YAML at line 1, column 4: cannot read '2020-13-45' as timestamp",
    ),
    "bad explicit tag": (
        b"x: !!float abc\n",
        "not valid YAML at line 1, column 4: cannot read 'abc' as float",
    ),
    "unknown tag": (
        b"x: !foo bar\n",
        "not valid YAML at line 1, column 4: could not determine a constructor for the tag '!foo'",
    ),
    "5000 digits": (
        b"x: 1" + b"0" * 5000,
        "not valid YAML at line 1, column 4: cannot read '1" + "0" * 48 + "...0000' as int",
    ),
}


@pytest.mark.parametrize("case", HOSTILE)
def test_hostile_files_give_one_clean_input_error(tmp_path, case):
    content, message = HOSTILE[case]
    path = write(tmp_path, content)
    assert str(error(path)) == f"{path}: {message}"


def test_random_bytes_give_a_mapping_or_an_input_error(tmp_path):
    rng = random.Random(0)
    for i in range(300):
        blob = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 200)))
        path = write(tmp_path, blob, f"{i}.yaml")
        try:
            assert isinstance(load_yaml(path)[0], dict)
        except InputError as exc:
            assert str(exc).startswith(f"{path}: ") and "\n" not in str(exc)


def test_an_integer_too_large_for_a_float_is_not_finite(tmp_path):
    path = write(tmp_path, "x: 1" + "0" * 400 + "\n")
    data, name, _ = load_yaml(path)
    assert data["x"] == 10**400
    with pytest.raises(InputError) as info:
        Reader(name).number(data["x"], "hardpoints.p.x")
    assert str(info.value) == (
        f"{path}: hardpoints.p.x: expected a finite number, got an integer too large for a float"
    )


def test_lengths_beyond_100_m_are_rejected():
    r = Reader("corner.yaml")
    key = "hardpoints.lower_wishbone_outboard"
    assert MAX_LENGTH_MM == 100_000.0
    assert r.length(-100_000, "config.wheel.offset") == -100_000.0
    assert r.point({"x": 1, "y": 2e2, "z": -100_000}, key).tolist() == [1.0, 200.0, -100_000.0]
    beyond = "mm is beyond the 100 m limit of any car (lengths are in mm)"
    with pytest.raises(InputError) as info:
        r.point({"x": 1e20, "y": 0, "z": 0}, key)
    assert str(info.value) == f"corner.yaml: {key}.x: 1e+20 {beyond}"
    with pytest.raises(InputError) as info:
        r.point([0, -100_001, 0], key)
    assert str(info.value) == f"corner.yaml: {key}[1]: -100001 {beyond}"
    with pytest.raises(InputError, match=r"^corner.yaml: w: 200001 mm is beyond"):
        r.length(200_001, "w")
    with pytest.raises(InputError, match=r"^corner.yaml: w: 6 mm is beyond the 0.005 m limit"):
        r.number(6, "w", limit=5.0)


def test_readers_without_a_limit_work_as_before():
    r = Reader("corner.yaml")
    assert r.number(1e20, "k") == 1e20
    assert r.number(3, "k", 0.0) == 3.0
    assert np.array_equal(r.vector([1e20, 0, 0], "k"), [1e20, 0, 0])
    with pytest.raises(InputError, match=r"^corner.yaml: k: must be >= 0, got -1$"):
        r.number(-1, "k", 0.0, limit=MAX_LENGTH_MM)


def test_base_60_numbers_stay_text(tmp_path):
    """YAML 1.1 reads 3:20 as 200 (sexagesimal): a length written so is a mistake."""
    path = tmp_path / "g.yaml"
    path.write_text("a: 3:20\nb: 1:30.5\n")
    data, _, _ = load_yaml(path)
    assert data == {"a": "3:20", "b": "1:30.5"}
