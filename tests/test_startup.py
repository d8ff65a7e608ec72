"""Start-up: each command imports what it uses, and nothing heavier.

`pin-susp sweep` of the 41-step example spends most of its wall time importing
(benchmarks/bench_startup.py has the figures). These tests run a command in a
new Python process and read which modules it imported: a plain sweep to CSV
needs numpy, Pinocchio, PyYAML and the solver's modules, never scipy, pandas,
pyarrow, Dask, matplotlib, meshcat, yourdfpy, nor pin_susp's loads,
sensitivities, studies, validation, plots or 3D view. No timing is asserted.
"""

import csv
import importlib
import json
import shutil
import subprocess
import sys

import pytest
import yaml
from conftest import EXAMPLES, run_cli

import pin_susp

# Libraries and pin_susp modules that no light command needs.
HEAVY = (
    "scipy",
    "pandas",
    "pyarrow",
    "dask",
    "distributed",
    "matplotlib",
    "meshcat",
    "yourdfpy",
    "mujoco",
    "pydrake",
    "pin_susp.analyses.loads",
    "pin_susp.analyses.load_case",
    "pin_susp.analyses.statics",
    "pin_susp.analyses.sensitivity",
    "pin_susp.study",
    "pin_susp.study.plots",
    "pin_susp.validate",
    "pin_susp.analyses.pointwise",
    "pin_susp.plots",
    "pin_susp.viz.drawing",
    "pin_susp.viz.drawing_centres",
    "pin_susp.viz.drawing_labels",
    "pin_susp.viz.scene",
    "pin_susp.viz.view_parts",
    "pin_susp.viz.force_colours",
    "pin_susp.viz.server",
    "pin_susp.subjects.axle",
    # a double wishbone's corner loads no other mechanism
    "pin_susp.model.mechanisms.macpherson",
    "pin_susp.model.mechanisms.multilink",
    "pin_susp.model.mechanisms.trailing_arm",
)


def imported(modules: set[str], names) -> list[str]:
    """Which of ``names`` were imported (a package counts with any of its submodules)."""
    return sorted(n for n in names if any(m == n or m.startswith(n + ".") for m in modules))


@pytest.fixture
def inputs(tmp_path):
    for name in ("double_wishbone.yaml", "bump_steer.yaml"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    return tmp_path


def test_a_plain_sweep_to_csv_imports_nothing_heavy(inputs):
    code, modules, proc = run_cli(
        inputs, "sweep", "double_wishbone.yaml", "bump_steer.yaml", "-o", "out.csv", "-q"
    )
    assert code == 0, proc.stderr
    assert imported(modules, HEAVY) == []
    # what it does need, it has
    assert {"numpy", "pinocchio", "yaml", "pin_susp.solve.solver", "pin_susp.io.tables"} <= modules
    # the CSV is the sweep's: 41 rows, each camber the very float the API computes
    lines = (inputs / "out.csv").read_text().splitlines()
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    results = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml").run_sweep(
        EXAMPLES / "bump_steer.yaml"
    )
    assert len(rows) == 41
    assert [float(r["camber"]) for r in rows] == list(results["camber"])
    assert [float(r["roadwheel_angle"]) for r in rows] == list(results["roadwheel_angle"])


def test_a_sweep_long_enough_for_the_compiled_style_imports_pyarrow_alone(inputs):
    # 1 001 rows of the corner's columns: past tables.FAST_CELLS, written by pyarrow from
    # numpy's buffers (pyarrow's conversion of a Python object would import pandas)
    from pin_susp.io.tables import fast_style

    sweep = yaml.safe_load((EXAMPLES / "bump_steer.yaml").read_text()) | {"steps": 1001}
    (inputs / "long.yaml").write_text(yaml.safe_dump(sweep))
    code, modules, proc = run_cli(
        inputs, "sweep", "double_wishbone.yaml", "long.yaml", "-o", "out.csv", "-q"
    )
    assert code == 0, proc.stderr
    # pyarrow's kernels by name from pyarrow._compute: not pyarrow.compute's wrappers
    assert "pyarrow._compute" in modules and "pyarrow.compute" not in modules
    assert imported(modules, ("pandas", "scipy", "matplotlib")) == []
    lines = (inputs / "out.csv").read_text().splitlines()
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    assert fast_style(len(rows), len(rows[0]))
    results = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml").run_sweep(inputs / "long.yaml")
    for name in ("camber", "roadwheel_angle", "solver_max_residual"):
        assert [float(r[name]) for r in rows] == list(results[name])
    assert [r["solver_converged"] for r in rows] == ["True"] * 1001
    assert [int(r["step_index"]) for r in rows] == list(range(1001))


def test_a_sweep_to_parquet_imports_pyarrow_but_not_pandas(inputs):
    # its numbers and flags go to Arrow on numpy's buffers (tables.arrow_column)
    import pyarrow.parquet as pq

    code, modules, proc = run_cli(
        inputs, "sweep", "double_wishbone.yaml", "bump_steer.yaml", "-o", "out.parquet", "-q"
    )
    assert code == 0, proc.stderr
    assert "pyarrow.parquet" in modules
    assert imported(modules, ("pandas", "scipy", "matplotlib")) == []
    table = pq.read_table(inputs / "out.parquet")
    results = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml").run_sweep(
        EXAMPLES / "bump_steer.yaml"
    )
    assert table.column_names == list(results.keys())
    for name in ("camber", "roadwheel_angle", "solver_converged", "step_index"):
        assert table.column(name).to_pylist() == list(results[name])


@pytest.mark.parametrize(
    "argv, output",
    [
        (("urdf", "double_wishbone.yaml", "-o", "out.urdf"), "out.urdf"),
        (("mjcf", "double_wishbone.yaml", "-o", "out.xml"), "out.xml"),
        (("setup", "double_wishbone.yaml", "--trackrod", "1", "--sensitivities"), None),
    ],
    ids=["urdf", "mjcf", "setup"],
)
def test_the_other_light_commands_import_nothing_heavy(inputs, argv, output):
    code, modules, proc = run_cli(inputs, *argv)
    assert code == 0, proc.stderr
    assert imported(modules, HEAVY) == []
    if output is not None:
        assert (inputs / output).stat().st_size > 0
    if argv[0] == "urdf":
        corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
        assert (inputs / output).read_text() == corner.urdf


# pin_susp.cli is a package: its entry, registry, shared options and run; a command's
# --help adds its own module and the report it prints through, and no other command.
CLI = {"pin_susp.cli", "pin_susp.cli.commands", "pin_susp.cli.options", "pin_susp.cli.run"}
OWN = {"sweep": {"pin_susp.cli.commands.sweep", "pin_susp.cli.report"}}


def test_help_and_version_import_no_numerics(tmp_path):
    for argv in (("--help",), ("--version",), ("sweep", "--help")):
        code, modules, proc = run_cli(tmp_path, *argv)
        assert code == 0, proc.stderr
        assert "pin-susp" in proc.stdout or "pin_susp" in proc.stdout
        assert imported(modules, ("numpy", "pinocchio", "yaml", *HEAVY)) == []
        ours = {m for m in modules if m.startswith("pin_susp.")}
        assert ours == CLI | {"pin_susp.errors"} | OWN.get(argv[0], set())


def test_import_pin_susp_loads_no_submodule_until_a_name_is_used(tmp_path):
    code = (
        "import json, sys; import pin_susp; "
        "before = sorted(m for m in sys.modules if m.startswith('pin_susp.')); "
        "pin_susp.load_geometry; "
        "after = sorted(m for m in sys.modules if m.startswith('pin_susp.')); "
        "print(json.dumps([before, after]))"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    before, after = json.loads(proc.stdout)
    assert before == []
    assert "pin_susp.model.geometry" in after
    assert imported(set(after), HEAVY) == []


# Every public name and the module that defines it (as pin_susp/__init__.py imported
# them all before they were loaded lazily).
PUBLIC = {
    "Axle": "subjects.axle",
    "AxleModel": "subjects.axle",
    "AxleResults": "subjects.axle",
    "load_axle": "subjects.axle",
    "Corner": "subjects.corner",
    "Results": "subjects.corner",
    "InputError": "errors",
    "PinSuspError": "errors",
    "Geometry": "model.geometry",
    "load_geometry": "model.geometry",
    "LoadCase": "analyses.loads",
    "load_cases": "analyses.loads",
    "member_forces": "analyses.loads",
    "METRICS": "columns.metrics",
    "Pose": "columns.metrics",
    "hardpoint_sensitivities": "analyses.sensitivity",
    "SetupModel": "analyses.setup",
    "apply_setup": "solve.as_set",
    "setup_sheet": "analyses.setup",
    "solve_setup": "analyses.setup",
    "Sweep": "model.sweep",
    "Target": "model.sweep",
    "load_sweep": "model.sweep",
    "Vehicle": "subjects.vehicle",
    "VehicleResults": "subjects.vehicle",
    "load_vehicle": "subjects.vehicle",
}


def test_every_public_name_still_resolves():
    assert sorted(pin_susp.__all__) == sorted(PUBLIC)
    for name, module in PUBLIC.items():
        value = getattr(pin_susp, name)
        assert value is getattr(importlib.import_module(f"pin_susp.{module}"), name), name
        assert name in dir(pin_susp)
    namespace = {}
    exec("from pin_susp import *", namespace)
    assert set(PUBLIC) <= set(namespace)
    assert pin_susp.__version__ == "0.1.0"
    # a submodule by attribute, as when `import pin_susp` imported them all
    assert pin_susp.analyses.loads.load_cases is pin_susp.load_cases
    with pytest.raises(AttributeError, match="no_such_name"):
        pin_susp.no_such_name  # noqa: B018
    assert not hasattr(pin_susp, "__wrapped__")


def test_a_yaml_file_read_twice_gives_each_caller_its_own_copy(tmp_path):
    """load_yaml parses a content once (the CLI reads a geometry's scope, then the
    geometry): each caller still gets its own mapping, and a changed file is re-read."""
    from pin_susp.io.yamlio import load_yaml

    path = shutil.copy(EXAMPLES / "double_wishbone.yaml", tmp_path / "g.yaml")
    expected = yaml.safe_load((EXAMPLES / "double_wishbone.yaml").read_text())
    first, name, sha = load_yaml(path)
    first["hardpoints"]["lower_wishbone_outboard"]["x"] = 1e3  # the caller's own change
    first["name"] = "changed"
    second, _, sha2 = load_yaml(path)
    assert second == expected and sha2 == sha and name == str(path)
    assert second["hardpoints"] is not first["hardpoints"]
    text = (tmp_path / "g.yaml").read_text().replace("z: ", "z:  ", 1)  # the same mapping
    (tmp_path / "g.yaml").write_text(text + "\nextra_note: 1\n")
    third, _, sha3 = load_yaml(path)
    assert sha3 != sha and third == {**expected, "extra_note": 1}
