import copy
import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"


def example(name: str) -> dict:
    """An example file as a fresh dict (tests may change it)."""
    return yaml.safe_load((EXAMPLES / name).read_text())


def mirrored(geometry: dict) -> dict:
    """The corner mirrored through Y = 0: every y negated, the other side."""
    g = copy.deepcopy(geometry)
    g["side"] = "right" if g.get("side", "left") == "left" else "left"
    for p in g["hardpoints"].values():
        p["y"] = -p["y"]
    return g


def torsion_bar() -> dict:
    """The pushrod-rocker example with a torsion bar on its rocker for a spring."""
    geometry = example("pushrod_rocker.yaml")
    geometry["spring"] = {"type": "torsion_bar", "rate": 40, "preload": 150}  # N·m/deg, N·m
    for point in ("strut_top", "strut_bottom"):
        del geometry["hardpoints"][point]
    return geometry


def translated(geometry: dict, v) -> dict:
    """Every hardpoint moved by the vector v (mm)."""
    g = copy.deepcopy(geometry)
    for p in g["hardpoints"].values():
        for axis, d in zip("xyz", v, strict=True):
            p[axis] += d
    return g


def sweep_csv(tmp_path: Path, geometry: str, sweep: str, name: str = "results.csv") -> Path:
    """`pin-susp sweep` on two example files, quietly; the CSV's path."""
    from pin_susp.cli import main

    out = tmp_path / name
    assert (
        main(["sweep", str(EXAMPLES / geometry), str(EXAMPLES / sweep), "-o", str(out), "-q"]) == 0
    )
    return out


def main_saving(argv: list[str]) -> tuple[int, list]:
    """`pin-susp ARGV` in process: its exit code and the figures it saved, each as it was
    saved (a picture's own figure, to read its panels off without drawing it again)."""
    import pin_susp.plots
    from pin_susp.cli import main

    saved, save = [], pin_susp.plots.save_figure

    def keep(fig, path):
        saved.append(fig)
        save(fig, path)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(pin_susp.plots, "save_figure", keep)
        return main(argv), saved


# Runs pin_susp.cli.main(argv) as the console script would, then writes the names of
# every imported module (a command's own output stays on stdout).
RUN_CLI = """
import json, sys
from pin_susp.cli import main
code = main(sys.argv[2:])
with open(sys.argv[1], "w") as f:
    json.dump({"exit": code, "modules": sorted(sys.modules)}, f)
"""


def run_cli(tmp_path, *argv: str) -> tuple[int, set[str], subprocess.CompletedProcess]:
    """One command in a new process, in tmp_path: its exit code and imported modules."""
    report = tmp_path / "modules.json"
    proc = subprocess.run(
        [sys.executable, "-c", RUN_CLI, str(report), *argv],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert report.exists(), proc.stderr
    data = json.loads(report.read_text())
    return data["exit"], set(data["modules"]), proc


@pytest.fixture(scope="session")
def corner():
    import pin_susp

    return pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")


@pytest.fixture(autouse=True)
def _work_in_tmp_path(tmp_path, monkeypatch):
    """Every test runs in its own temporary folder: a stray relative write lands there."""
    monkeypatch.chdir(tmp_path)


def pytest_sessionfinish(session, exitstatus):
    """A test that replaced /dev/null (an output renamed over it) fails the run."""
    if os.path.exists("/dev/null") and not stat.S_ISCHR(os.stat("/dev/null").st_mode):
        print("\n/dev/null is no longer a character device: a test wrote over it")
        session.exitstatus = 1
