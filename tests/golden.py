"""Golden outputs: every command on every example, the files they write, kept as they were.

The outputs under ``tests/data/golden/`` were written by the commit named in its
``COMMIT`` file, before the code was reorganised; ``tests/test_golden.py`` runs the
same jobs on today's code and compares every file. Regenerate them (only when an
output is meant to change, and say so in the commit) with::

    .venv/bin/python tests/golden.py tests/data/golden

Each job runs ``pin_susp.cli.main`` in process, in a folder holding a copy of
``examples/`` (so the paths the files record are relative and the same everywhere).
"""

from __future__ import annotations

import contextlib
import io
import os
import shutil
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"

# corner geometries and the sweep each takes (a rack corner steers; a toe link does not)
RACK = ("double_wishbone", "pushrod_rocker", "camber_shim", "macpherson", "multilink_front")
TOE_LINK = ("fixed_toe_link", "multilink_rear", "semi_trailing_arm")
# a small tolerance study: the example's, 8 builds (a fixed seed)
SMALL_STUDY = """\
version: 1
geometry: double_wishbone.yaml
sweep: bump_rack_held.yaml
variables:
  all_hardpoints: {tolerance: 0.5}
kind: monte_carlo
monte_carlo: {samples: 8, seed: 1, distribution: normal}
summary: [camber, roadwheel_angle, deriv_roadwheel_angle_wrt_hub_z]
"""
THREE_STEPS = """\
version: 1
steps: 3
targets:
  - {point: wheel_center, direction: {axis: z}, mode: relative, start: -20, stop: 20}
  - {point: trackrod_inboard, direction: {axis: y}, mode: relative, start: -5, stop: 5}
"""
AXLE_CASES = """\
version: 1
cases:
  - name: turn
    left: {contact_patch: {fx: 0, fy: -2700, fz: 1800}}
    right: {contact_patch: {fx: 0, fy: -1300, fz: 900}}
  - name: braking
    left: {contact_patch: {fx: -1900, fy: 0, fz: 1300}}
    right: {contact_patch: {fx: -1900, fy: 0, fz: 1300}}
"""


def jobs() -> list[tuple[str, list[str]]]:
    """(output name, argv) for every job; argv paths are relative to the job's folder."""
    out: list[tuple[str, list[str]]] = []
    for name in RACK + TOE_LINK:
        g = f"examples/{name}.yaml"
        sweep = "examples/bump_steer.yaml" if name in RACK else "examples/bump.yaml"
        out.append((f"sweep_{name}.csv", ["sweep", g, sweep, "-q"]))
        out.append((f"urdf_{name}.urdf", ["urdf", g]))
        out.append((f"mjcf_{name}.xml", ["mjcf", g]))
    out.append(
        (
            "sweep_double_wishbone.parquet",
            ["sweep", "examples/double_wishbone.yaml", "examples/bump_steer.yaml", "-q"],
        )
    )
    out.append(
        (
            "sweep_rack_held_double_wishbone.csv",
            ["sweep", "examples/double_wishbone.yaml", "examples/bump_rack_held.yaml", "-q"],
        )
    )
    axle = "examples/axle_front.yaml"
    for sweep in ("roll", "heave_roll"):
        out.append(
            (f"sweep_axle_front_{sweep}.csv", ["sweep", axle, f"examples/{sweep}.yaml", "-q"])
        )
    out.append(("sweep_axle_front_roll.parquet", ["sweep", axle, "examples/roll.yaml", "-q"]))
    out.append(("urdf_axle_front.urdf", ["urdf", axle]))
    out.append(("mjcf_axle_front.xml", ["mjcf", axle]))
    cases = ["--cases", "examples/loads.yaml"]
    out.append(
        (
            "loads_pushrod_rocker.csv",
            ["loads", "examples/pushrod_rocker.yaml", "examples/bump_rack_held.yaml", *cases, "-q"],
        )
    )
    out.append(
        (
            "loads_macpherson.csv",
            ["loads", "examples/macpherson.yaml", "examples/bump_steer.yaml", *cases, "-q"],
        )
    )
    out.append(
        (
            "loads_axle_front.csv",
            [
                "loads",
                "examples/axle_sprung.yaml",
                "examples/roll.yaml",
                "--cases",
                "examples/axle_loads.yaml",
                "-q",
            ],
        )
    )
    shim = "examples/camber_shim.yaml"
    out.append(("setup_shims.csv", ["setup", shim, "--shim", "15,20,25,30", "--sensitivities"]))
    out.append(("setup_targets.yaml", ["setup", shim, "--camber", "-2.5", "--toe", "0"]))
    out.append(
        (
            "setup_pushrod.csv",
            ["setup", "examples/pushrod_rocker.yaml", "--pushrod=-1,0,1", "--sensitivities"],
        )
    )
    out.append(("setup_axle.csv", ["setup", axle, "--trackrod=-1,0,1", "--sensitivities"]))
    for name in ("double_wishbone", "macpherson", "multilink_rear", "semi_trailing_arm"):
        out.append((f"sensitivity_{name}.csv", ["sensitivity", f"examples/{name}.yaml", "-q"]))
    out.append(
        (
            "sensitivity_sweep_double_wishbone.csv",
            [
                "sensitivity",
                "examples/double_wishbone.yaml",
                "--sweep",
                "examples/three_steps.yaml",
                "-q",
            ],
        )
    )
    out.append(("sensitivity_axle_front.csv", ["sensitivity", axle, "-q"]))
    out.append(
        (
            "study_tolerances",
            ["study", "examples/small_study.yaml", "--scheduler", "none", "--steps", "-q"],
        )
    )
    out.append(
        (
            "study_bump_steer",
            ["study", "examples/study_bump_steer.yaml", "--scheduler", "none", "-q"],
        )
    )
    return out


def _argv(name: str, argv: list[str], outdir: Path) -> list[str]:
    """The job's argv with its output path: -o, or --csv for a setup sheet."""
    target = str(outdir / name)
    if argv[0] == "setup":
        return [*argv, "-o" if name.endswith(".yaml") else "--csv", target]
    return [*argv, "-o", target]


def run(outdir: Path, work: Path) -> list[str]:
    """Run every job with its inputs copied into ``work``; write into ``outdir``.
    The names of the files written, relative to ``outdir``."""
    from pin_susp.cli import main

    outdir.mkdir(parents=True, exist_ok=True)
    shutil.copytree(EXAMPLES, work / "examples", dirs_exist_ok=True)
    (work / "examples" / "small_study.yaml").write_text(SMALL_STUDY)
    (work / "examples" / "axle_loads.yaml").write_text(AXLE_CASES)
    (work / "examples" / "three_steps.yaml").write_text(THREE_STEPS)
    axle = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    axle["axle_config"]["spring"] = {"type": "coilover", "rate": 175.0}  # N/mm
    axle["axle_config"]["anti_roll"]["stiffness"] = 40.0  # N·m/deg
    (work / "examples" / "axle_sprung.yaml").write_text(yaml.safe_dump(axle))
    here = Path.cwd()
    os.chdir(work)
    try:
        for name, argv in jobs():
            with contextlib.redirect_stdout(io.StringIO()):
                status = main(_argv(name, argv, outdir))
            if status != 0:
                raise RuntimeError(f"golden job {name}: exit {status}: {argv}")
    finally:
        os.chdir(here)
    # a picture's bytes depend on matplotlib's build, its data is in the tables: not kept
    return sorted(
        str(p.relative_to(outdir)) for p in outdir.rglob("*") if p.is_file() and p.suffix != ".png"
    )


if __name__ == "__main__":
    import tempfile

    target = Path(sys.argv[1]).resolve()
    if target.exists():
        shutil.rmtree(target)
    with tempfile.TemporaryDirectory() as work:
        files = run(target, Path(work))
    for picture in target.rglob("*.png"):
        picture.unlink()
    commit = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    (target / "COMMIT").write_text(
        f"{commit}\nregenerate: .venv/bin/python tests/golden.py tests/data/golden\n"
    )
    print(f"wrote {len(files)} files into {target}")
