"""Property-based fuzzing of ``pin-susp`` in process (strategies and invariants: fuzzing.py).

``make test`` runs ``PIN_SUSP_FUZZ_EXAMPLES`` inputs (default 500, about 20 s of
CPU), derandomized: the same inputs every run, no example database and nothing
written into the repository. ``make fuzz`` runs 10 000 (about 10 min) with a
fresh seed, printed with the counts per exit code, command and mechanism
(corners and axles). Both draw every command that takes a geometry (sweep and
loads to CSV or Parquet, a 10 001-step sweep that streams, setup, sensitivity,
urdf, mjcf, draw, validate and studies: the slow ones rarely).
``PIN_SUSP_FUZZ_SEED=N`` repeats a run; ``PIN_SUSP_FUZZ_FINDINGS=DIR`` saves
each failing input as files to run by hand (the shrunk one last);
``PIN_SUSP_FUZZ_COLLECT=1`` counts failures instead of stopping at them (the
smallest of each kind saved), for triage while the code is being fixed.
"""

import copy
import dataclasses
import io
import os
import random
from pathlib import Path

import hypothesis.configuration
import pytest
import yaml
from fuzzing import (
    BASES,
    BY_MECHANISM,
    COUNTS,
    FOUND,
    GEOMETRY_FILES,
    ROOT,
    ROWS_CHECKED,
    SLOWEST,
    Case,
    Inputs,
    Plan,
    _degenerate_moves,
    bodies,
    cases,
    check_case,
    parse_csv,
    run_case,
    save_case,
    signature,
    summary,
)
from hypothesis import HealthCheck, Phase, given, seed, settings

EXAMPLES = int(os.environ.get("PIN_SUSP_FUZZ_EXAMPLES", "500"))
SEED = os.environ.get("PIN_SUSP_FUZZ_SEED", "").strip()
if SEED == "random":
    SEED = str(random.SystemRandom().randrange(2**32))
FINDINGS = os.environ.get("PIN_SUSP_FUZZ_FINDINGS")
# Triage: count and save every failure (the smallest of each kind) and keep going.
COLLECT = os.environ.get("PIN_SUSP_FUZZ_COLLECT", "") not in ("", "0")


@pytest.fixture(autouse=True)
def _hypothesis_home(tmp_path):
    """Anything Hypothesis keeps (even with no database it writes constants/) goes into
    the test's own temporary folder: never the repository, never a shared /tmp path."""
    hypothesis.configuration.set_hypothesis_home_dir(tmp_path / "hypothesis")


def _one(case: Case) -> None:
    try:
        with run_case(case) as outcome:
            check_case(case, outcome)
    except Exception as exc:
        if FINDINGS:
            save_case(case, exc, Path(FINDINGS), keep_smaller=COLLECT)
        if not COLLECT:
            raise
        FOUND[signature(exc)] += 1


_fuzz = settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.data_too_large,
        HealthCheck.filter_too_much,
        HealthCheck.large_base_example,
    ],
    derandomize=not SEED,
    database=None,
    report_multiple_bugs=True,
    print_blob=False,
    # no explain phase: tracing every shrink step makes a failing run ten times slower
    phases=[Phase.explicit, Phase.reuse, Phase.generate, Phase.target, Phase.shrink],
)(given(case=cases())(_one))
if SEED:
    _fuzz = seed(int(SEED))(_fuzz)


def test_cli_holds_its_invariants():
    for counter in (COUNTS, BY_MECHANISM, ROWS_CHECKED, FOUND):
        counter.clear()
    SLOWEST.clear()
    try:
        _fuzz()
    finally:
        print(
            "\n"
            + summary()
            + (f"\n  seed {SEED} (PIN_SUSP_FUZZ_SEED={SEED} repeats it)" if SEED else "")
        )


def _known_good_sweep() -> Case:
    geometry = (ROOT / "examples" / "double_wishbone.yaml").read_bytes()
    sweep = (
        b"version: 1\nsteps: 3\ntargets:\n"
        b"  - {point: wheel_center, direction: {axis: z}, start: -10, stop: 10}\n"
        b"  - {point: trackrod_inboard, direction: {axis: y}, start: 0, stop: 5}\n"
    )
    plans = [
        Plan("wheel_center", (0.0, 0.0, 1.0), "relative", [-10.0, 0.0, 10.0]),
        Plan("trackrod_inboard", (0.0, 1.0, 0.0), "relative", [0.0, 2.5, 5.0]),
    ]
    return _sweep_case(geometry, sweep, plans)


def _sweep_case(geometry: bytes, sweep: bytes, plans: list) -> Case:
    """``pin-susp sweep g.yaml s.yaml -o out.csv -q`` on these files, as a fuzz Case."""
    return Case(
        "sweep",
        ["sweep", "g.yaml", "s.yaml", "-o", "out.csv", "-q"],
        {"g.yaml": geometry, "s.yaml": sweep},
        ["out.csv"],
        Inputs(None, geometry, []),
        Inputs(None, sweep, []),
        plans,
        quiet=True,
    )


def _bump_sweep(geometry_file: str, rack: bool) -> Case:
    """A good 3-step sweep of an example: bump, and steer when it has a rack."""
    geometry = (ROOT / "examples" / geometry_file).read_bytes()
    sweep = b"version: 1\nsteps: 3\ntargets:\n"
    sweep += b"  - {point: wheel_center, direction: {axis: z}, start: -20, stop: 20}\n"
    plans = [Plan("wheel_center", (0.0, 0.0, 1.0), "relative", [-20.0, 0.0, 20.0])]
    if rack:
        sweep += b"  - {point: trackrod_inboard, direction: {axis: y}, start: -8, stop: 8}\n"
        plans.append(Plan("trackrod_inboard", (0.0, 1.0, 0.0), "relative", [-8.0, 0.0, 8.0]))
    return _sweep_case(geometry, sweep, plans)


def _shift(csv: bytes, row: int, column: str, delta: float) -> bytes:
    _, rows = parse_csv(csv.decode())
    header = next(line for line in csv.decode().splitlines() if not line.startswith("#"))
    value = float(rows[row][header.split(",").index(column)])
    return _edit(csv, row, column, repr(value + delta))


@pytest.mark.parametrize(
    "geometry_file, rack, column, broken",
    [
        ("macpherson.yaml", True, "strut_top_y", "off the line lower_wishbone_outboard"),
        ("macpherson.yaml", True, "strut_bottom_z", "strut_bottom"),
        ("macpherson.yaml", True, "lower_wishbone_outboard_x", "lower_wishbone_outboard"),
        ("multilink_rear.yaml", False, "upper_rear_link_outboard_x", "upper_rear_link"),
        ("multilink_rear.yaml", False, "toe_link_outboard_z", "toe_link_outboard"),
        ("multilink_rear.yaml", False, "strut_top_z", "chassis point strut_top"),
        ("multilink_front.yaml", True, "lower_rear_link_outboard_y", "lower_rear_link"),
        ("semi_trailing_arm.yaml", False, "strut_bottom_x", "strut_bottom"),
        ("semi_trailing_arm.yaml", False, "arm_pivot_inboard_z", "arm_pivot_inboard"),
    ],
)
def test_the_checker_knows_every_mechanism(geometry_file, rack, column, broken):
    """Each mechanism's bodies() names only points of its CSV (a misspelt name would skip
    its check), has loops to keep when it has closures, and a point moved 1 µm off its
    body (or its line) in one converged row is caught."""
    from pin_susp import Corner

    case = _bump_sweep(geometry_file, rack)
    with run_case(case) as good:
        check_case(case, good)
        assert good.code == 0
        csv = good.texts["out.csv"]
        header, _ = parse_csv(csv.decode())
        chassis, groups, loops, lines = bodies(Corner(ROOT / "examples" / geometry_file).geometry)
        names = set(chassis) | {n for g in groups for n in g} | {n for x in loops for n in x}
        names |= {n for x in lines for n in x}
        missing = sorted(n for n in names if f"{n}_x" not in header)
        assert not missing, f"bodies() names points the CSV does not have: {missing}"
        assert bool(loops) == ("trailing_arm" not in geometry_file)
        assert bool(lines) == ("macpherson" in geometry_file)
        tampered = dataclasses.replace(good, texts={"out.csv": _shift(csv, 2, column, 1e-6)})
        with pytest.raises(AssertionError, match=broken):
            check_case(case, tampered)


def _edit(csv: bytes, row: int, column: str, value: str) -> bytes:
    lines = csv.decode().splitlines()
    first = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    j = lines[first].split(",").index(column)
    cells = lines[first + 1 + row].split(",")
    cells[j] = value
    lines[first + 1 + row] = ",".join(cells)
    return ("\n".join(lines) + "\n").encode()


def test_the_checker_catches_broken_invariants():
    """The invariants are not vacuous: a good run passes, each tampered copy fails."""
    case = _known_good_sweep()
    with run_case(case) as good:
        check_case(case, good)
        assert good.code == 0
        csv = good.texts["out.csv"]
        tampered = {
            "exit 0 with a failed row": {
                "texts": {"out.csv": _edit(csv, 1, "solver_converged", "False")}
            },
            "residual above 1e-9 mm": {
                "texts": {"out.csv": _edit(csv, 2, "solver_max_residual", "2e-9")}
            },
            "nan text": {"texts": {"out.csv": _edit(csv, 0, "camber", "nan")}},
            "a point off its body": {
                "texts": {"out.csv": _edit(csv, 1, "axle_outboard_x", "-19.99")}
            },
            "the rack off its line": {
                "texts": {"out.csv": _edit(csv, 2, "trackrod_inboard_z", "250.001")}
            },
            "exit 1 naming nothing": {
                "code": 1,
                "texts": {"out.csv": _edit(csv, 1, "solver_converged", "False")},
            },
            "exit 2 on two lines": {"code": 2, "stderr": "pin-susp: error: a\nb\n", "new": set()},
            "exit 2 writing": {"code": 2, "stderr": "pin-susp: error: x\n"},
            "a traceback": {"stderr": "Traceback (most recent call last):\n"},
            "a temporary file left": {"new": {"out.csv", ".pin_susp-abc.tmp"}},
            "an input changed": {"changed": {"g.yaml"}},
            "a stray file": {"new": {"out.csv", "elsewhere.txt"}},
            "MuJoCo's log": {"mujoco_log": True},
            "exit 3": {"code": 3},
        }
        for what, changes in tampered.items():
            with pytest.raises(AssertionError):
                check_case(case, dataclasses.replace(good, **changes))
                pytest.fail(f"not caught: {what}")
        shifted = [dataclasses.replace(p, values=[v + 1e-3 for v in p.values]) for p in case.plans]
        with pytest.raises(AssertionError, match="target"):
            check_case(dataclasses.replace(case, plans=shifted), good)


def test_the_checker_reads_parquet_back():
    """A Parquet output is read back and row-checked as the CSV: a good one passes, one
    with a row flagged False (or a point off its body) under exit 0 fails."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    case = _known_good_sweep()
    case = dataclasses.replace(
        case,
        argv=[("out.parquet" if a == "out.csv" else a) for a in case.argv],
        outputs=["out.parquet"],
    )
    with run_case(case) as good:
        check_case(case, good)
        assert good.code == 0
        raw = good.texts["out.parquet"]
        table = pq.read_table(io.BytesIO(raw))

        def tampered(column, row, value):
            cells = table.column(column).to_pylist()
            cells[row] = value
            changed = table.set_column(
                table.column_names.index(column),
                column,
                pa.array(cells, table.schema.field(column).type),
            )
            sink = io.BytesIO()
            pq.write_table(changed, sink)
            return dataclasses.replace(good, texts={"out.parquet": sink.getvalue()})

        with pytest.raises(AssertionError, match="failed row 1 has cells|flagged False"):
            check_case(case, tampered("solver_converged", 1, False))
        with pytest.raises(AssertionError, match="axle_outboard"):
            check_case(case, tampered("axle_outboard_x", 1, -19.99))
        with pytest.raises(AssertionError, match="non-finite"):
            check_case(case, tampered("camber", 0, float("nan")))


@pytest.mark.parametrize("geometry_file", GEOMETRY_FILES)
def test_each_mechanism_refuses_its_degenerate_moves(tmp_path, capsys, geometry_file):
    """Every degenerate move the fuzzer makes of this mechanism (coincident pivots, a
    pivot on a spindle point, a zero-length arm) is refused at load: exit 2, one line
    naming one of its points, nothing written."""
    from pin_susp.cli import main

    data = BASES[geometry_file]
    moves = _degenerate_moves(data)
    assert moves, geometry_file
    for label, point, a, t, names in moves:
        moved = copy.deepcopy(data)
        pa_, pb = (moved["hardpoints"][n] for n in (a, names[-1]))
        moved["hardpoints"][point] = {k: pa_[k] + t * (pb[k] - pa_[k]) for k in "xyz"}
        g = tmp_path / "g.yaml"
        g.write_text(yaml.safe_dump(moved))
        code = main(["urdf", str(g), "-o", str(tmp_path / "o.urdf")])
        lines = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and len(lines) == 1, (label, point, lines)
        assert any(n in lines[0] for n in names), (label, point, lines)
        assert not (tmp_path / "o.urdf").exists()
