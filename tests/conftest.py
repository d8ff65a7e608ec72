import copy
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


@pytest.fixture(scope="session")
def corner():
    import pin_susp

    return pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
