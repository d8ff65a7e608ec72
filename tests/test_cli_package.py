"""The CLI as a package (issue 25, 3): every command one module under
pin_susp/cli/commands, registered by name with its summary; `pin-susp --help` lists
them all and imports none of them, a command imports its own; every module of the
CLI small and in the README's module table; `--at` one meaning (a step of a sweep
YAML), draw's step of results named `--from-results`, its old `--at` still working.
"""

import importlib
import inspect
import keyword
from pathlib import Path

import pytest
from conftest import EXAMPLES, run_cli

import pin_susp
from pin_susp.cli import _parser, main
from pin_susp.cli.commands import COMMANDS

CLI = Path(pin_susp.__file__).parent / "cli"
README = Path(pin_susp.__file__).parent.parent / "README.md"


def test_every_registered_command_is_a_module_with_its_parts():
    files = {p.stem for p in (CLI / "commands").glob("*.py")} - {"__init__"}
    # a command named by a Python keyword (import) lives in the module with an underscore
    modules = {name: name + "_" if keyword.iskeyword(name) else name for name in COMMANDS}
    assert set(modules.values()) == files  # no command module unregistered, none missing
    for name, (path, summary) in COMMANDS.items():
        assert path == f"pin_susp.cli.commands.{modules[name]}"
        assert summary and "\n" not in summary and len(summary) <= 90, name
        module = importlib.import_module(path)
        assert isinstance(module.DESCRIPTION, str) and len(module.DESCRIPTION) > 40, name
        assert list(inspect.signature(module.arguments).parameters) == ["parser"], name
        assert list(inspect.signature(module.run).parameters) == ["args"], name
        # the parser built for the command line runs the module's run
        args = _parser().parse_args([name, *REQUIRED.get(name, ("g.yaml",))])
        assert args.run is module.run, name


# what each command needs to parse (nothing is read: parse_args alone)
REQUIRED = {
    "sweep": ("g.yaml", "s.yaml", "-o", "o.csv"),
    "loads": ("g.yaml", "s.yaml", "--cases", "c.yaml", "-o", "o.csv"),
    "kc": ("g.yaml", "s.yaml", "--cases", "c.yaml", "-o", "o.csv"),
    "validate": ("g.yaml", "s.yaml"),
    "mjcf": ("g.yaml", "-o", "o.xml"),
    "demo": (),
    "plot": ("r.csv", "-o", "o.png"),
    "draw": ("g.yaml", "-o", "o.png"),
    "study": ("s.yaml", "-o", "out"),
    "attitude": ("v.yaml", "a.yaml", "-o", "o.csv"),
    "import": ("car.shk", "-o", "o.yaml"),
    "export": ("g.yaml", "--format", "shk", "-o", "o.shk"),
    "clearance": ("g.yaml", "s.yaml", "-o", "o.csv"),
    "envelope": ("g.yaml", "s.yaml", "-o", "o.stl"),
}


def cli_modules(tmp_path, *argv: str) -> tuple[int, list[str], str]:
    """main(argv) in a new process: its exit code, the command modules it imported and
    its standard output."""
    code, modules, proc = run_cli(tmp_path, *argv)
    return code, sorted(m for m in modules if m.startswith("pin_susp.cli.commands.")), proc.stdout


def test_help_lists_every_command_and_imports_none_a_sweep_its_own(tmp_path):
    code, commands, out = cli_modules(tmp_path, "--help")
    assert code == 0 and commands == []
    said = " ".join(out.split())  # argparse wraps a long summary
    for name, (_, summary) in COMMANDS.items():
        assert f"{name} {' '.join(summary.split())}" in said, name
    for name in ("double_wishbone.yaml", "bump_steer.yaml"):
        (tmp_path / name).write_text((EXAMPLES / name).read_text())
    argv = ("sweep", "double_wishbone.yaml", "bump_steer.yaml", "-o", "out.csv", "-q")
    code, commands, _ = cli_modules(tmp_path, *argv)
    assert code == 0 and (tmp_path / "out.csv").stat().st_size > 10_000
    assert commands == ["pin_susp.cli.commands.sweep"]


def test_every_cli_module_is_small_and_in_the_readme_table():
    table = README.read_text().split("## How it works", 1)[1].split("\n\n", 2)[1]
    for path in sorted(CLI.rglob("*.py")):
        lines = path.read_text().count("\n")
        assert lines <= 600, f"{path}: {lines} lines"
        if path.name == "__main__.py":
            continue
        name = path.relative_to(CLI.parent).as_posix()  # cli/report.py
        listed = f"`{name}`" in table or (
            path.parent.name == "commands" and f"`{path.name}`" in table
        )
        assert listed, name


@pytest.fixture(scope="module")
def roll(tmp_path_factory):
    """The example axle's roll sweep, as its results CSV."""
    out = tmp_path_factory.mktemp("roll") / "roll.csv"
    geometry, sweep = EXAMPLES / "axle_front.yaml", EXAMPLES / "roll.yaml"
    assert main(["sweep", str(geometry), str(sweep), "-o", str(out), "-q"]) == 0
    return str(out)


def test_draw_from_results_is_the_old_draw_at(roll, tmp_path, capsys, monkeypatch):
    """The same drawing by either name; the old one says the new on one line, after it."""
    import matplotlib

    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")  # the SVG's date and ids fixed
    monkeypatch.setitem(matplotlib.rcParams, "svg.hashsalt", "test_cli_package")
    axle = str(EXAMPLES / "axle_front.yaml")
    new, old, design = tmp_path / "new.svg", tmp_path / "old.svg", tmp_path / "design.svg"
    assert main(["draw", axle, "-o", str(new), "--from-results", f"{roll}:5"]) == 0
    assert capsys.readouterr() == (f"wrote {new}\n", "")
    assert main(["draw", axle, "-o", str(old), "--at", f"{roll}:5"]) == 0
    out, err = capsys.readouterr()
    assert out == f"wrote {old}\n"
    assert err.count("\n") == 1 and err.startswith("pin-susp: warning: draw --at RESULTS")
    assert "is now --from-results RESULTS.csv:STEP" in err
    assert new.read_bytes() == old.read_bytes()
    assert main(["draw", axle, "-o", str(design)]) == 0  # the step is drawn, not the design
    assert design.read_bytes() != new.read_bytes()


@pytest.mark.parametrize(
    "argv, message",
    [
        (("--from-results", "{roll}"), "--from-results {roll}: expected RESULTS.csv:STEP"),
        (("--from-results", "{roll}:99"), "{roll}: step 99: no such step"),
        (("--at", "{roll}:1", "--from-results", "{roll}:1"), "give one"),
        (("--at", "{sweep}:3"), "--at {sweep}:3: draw does not solve a sweep"),
        (("--from-results", "{roll}:1", "-o", "{roll}"), "is an input of this command"),
        (("--from-results", "{roll}:1", "--corner"), "--from-results: {corner} is a corner"),
    ],
    ids=["no step", "past the end", "both", "a sweep", "onto its input", "a corner"],
)
def test_draw_from_results_errors_name_the_option_given(roll, tmp_path, capsys, argv, message):
    corner = str(EXAMPLES / "double_wishbone.yaml")
    names = {"roll": roll, "sweep": str(EXAMPLES / "roll.yaml"), "corner": corner}
    argv = [a.format(**names) for a in argv]
    geometry = str(EXAMPLES / "axle_front.yaml")
    if "--corner" in argv:
        argv.remove("--corner")
        geometry = corner
    out = str(tmp_path / "d.png")
    command = ["draw", geometry, "-o", out, *argv]
    before = Path(roll).read_bytes()
    assert main(command) == 2
    err = capsys.readouterr().err
    assert err.startswith("pin-susp: error: ") and err.count("\n") == 1, err
    assert message.format(**names) in err, err
    assert not Path(out).exists() and Path(roll).read_bytes() == before
