"""The ``pin-susp`` command line.

Exit codes: 0 success; 1 the run finished but some steps did not converge
(their rows are written, flagged ``solver_converged = False`` with empty
metric cells); 2 a problem with the input (one line on stderr, nothing
written).
"""

from __future__ import annotations

import argparse
import shutil
import sys
from importlib import resources
from pathlib import Path

import numpy as np

from . import __version__
from .corner import Corner, Results
from .errors import PinSuspError
from .export import write_text
from .geometry import load_geometry
from .sweep import load_sweep

EXIT_NOT_CONVERGED = 1
EXIT_INPUT = 2


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    try:
        return args.run(args)
    except PinSuspError as exc:
        print(f"pin-susp: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("pin-susp: interrupted, nothing written", file=sys.stderr)
        return 130


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="pin-susp",
        description="Suspension kinematics on Pinocchio: a corner from a YAML file of "
        "hardpoints (mm, ISO 8855), solved exactly through bump and steer sweeps.",
        epilog="Start with `pin-susp demo`. Formats: docs/geometry.md, docs/sweep.md, "
        "docs/results.md.",
    )
    p.add_argument("--version", action="version", version=f"pin_susp {__version__}")
    sub = p.add_subparsers(title="commands", metavar="COMMAND", required=True)

    s = sub.add_parser(
        "sweep",
        help="solve a sweep and write one CSV row per step",
        description="Solve every step of SWEEP on the corner GEOMETRY and write the "
        "metrics (camber, toe, caster, KPI, scrub, trail, ...) and every point to CSV. "
        "Exit code 1 if any step did not converge (its row is flagged).",
    )
    s.add_argument("geometry", metavar="GEOMETRY", help="geometry YAML (hardpoints in mm)")
    s.add_argument("sweep", metavar="SWEEP", help="sweep YAML (targets per step)")
    s.add_argument("-o", "--output", required=True, metavar="OUT.csv", help="results CSV")
    s.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    s.set_defaults(run=_sweep)

    u = sub.add_parser(
        "urdf",
        help="write the corner as URDF (tree + loop closures)",
        description="Write the URDF of GEOMETRY: the kinematic tree in metres, every "
        "hardpoint as a link, loop closures as <pin_susp:loop_closure> elements.",
    )
    u.add_argument("geometry", metavar="GEOMETRY", help="geometry YAML (hardpoints in mm)")
    u.add_argument(
        "-o", "--output", metavar="OUT.urdf", help="file to write (default: standard output)"
    )
    u.set_defaults(run=_urdf)

    d = sub.add_parser(
        "demo",
        help="run the embedded example and write its results",
        description="Solve the embedded example corner through a combined bump+steer "
        "sweep; write its geometry, sweep, URDF and results CSV into DIR.",
    )
    d.add_argument(
        "-o",
        "--output",
        default="pin_susp_demo",
        metavar="DIR",
        help="output folder (default: ./pin_susp_demo)",
    )
    d.set_defaults(run=_demo)
    return p


def _sweep(args) -> int:
    corner = Corner(load_geometry(args.geometry))
    sweep = load_sweep(args.sweep)
    corner.solver_for(sweep.targets, sweep.source)  # target errors before any work
    results = corner.run_sweep(sweep, progress=_progress_bar(sweep.steps, args.quiet))
    results.to_csv(args.output)
    if not args.quiet:
        _summary(results, args.output)
    return _report_failures(results)


def _urdf(args) -> int:
    corner = Corner(load_geometry(args.geometry))
    if args.output:
        write_text(corner.urdf, args.output)
        print(f"wrote {args.output}")
    else:
        sys.stdout.write(corner.urdf)
    return 0


def _demo(args) -> int:
    out = Path(args.output)
    data = resources.files("pin_susp") / "data"
    out.mkdir(parents=True, exist_ok=True)
    for name in ("demo_geometry.yaml", "demo_sweep.yaml"):
        with resources.as_file(data / name) as src:
            shutil.copyfile(src, out / name)
    geometry_path, sweep_path = out / "demo_geometry.yaml", out / "demo_sweep.yaml"
    corner = Corner(load_geometry(geometry_path))
    sweep = load_sweep(sweep_path)
    results = corner.run_sweep(sweep, progress=_progress_bar(sweep.steps, False))
    write_text(corner.urdf, out / "demo_corner.urdf")
    results.to_csv(out / "demo_results.csv")
    print(f"pin_susp demo: {corner.geometry.name}, {sweep.steps}-step bump + steer sweep")
    _summary(results, out / "demo_results.csv")
    print(f"  geometry {geometry_path}\n  sweep    {sweep_path}")
    print(f"  URDF     {out / 'demo_corner.urdf'}")
    return _report_failures(results)


def _summary(results: Results, path) -> None:
    ok = results["solver_converged"]
    print(
        f"wrote {path}: {len(results)} steps, {int(ok.sum())} converged, "
        f"max residual {np.nanmax(results['solver_max_residual']):.1e} mm, "
        f"{np.median(results['solver_iterations']):g} iterations per step (median)"
    )
    rows = [
        (name, results.units[name])
        for name in (
            "wheel_travel",
            "camber",
            "roadwheel_angle",
            "caster",
            "kpi",
            "scrub_radius",
            "mechanical_trail",
            "half_track",
        )
    ]
    print(f"  {'metric':<18}{'unit':>5}{'first':>12}{'last':>12}{'min':>12}{'max':>12}")
    for name, unit in rows:
        v = results[name]
        if np.all(np.isnan(v)):
            continue
        print(
            f"  {name:<18}{unit:>5}{v[0]:>12.4f}{v[-1]:>12.4f}"
            f"{np.nanmin(v):>12.4f}{np.nanmax(v):>12.4f}"
        )


def _report_failures(results: Results) -> int:
    failed = results.failed_steps
    if len(failed) == 0:
        return 0
    worst = np.max(results["solver_max_residual"][failed])
    print(
        f"pin-susp: warning: {len(failed)} of {len(results)} steps did not converge "
        f"(steps {', '.join(map(str, failed[:10]))}{' ...' if len(failed) > 10 else ''}; "
        f"residual up to {worst:.3g} mm): the targets are out of the mechanism's reach "
        "or pass a lock-up. Their rows are flagged solver_converged=False with empty cells.",
        file=sys.stderr,
    )
    return EXIT_NOT_CONVERGED


def _progress_bar(total: int, quiet: bool):
    """A one-line progress bar on a terminal; nothing in logs or pipes."""
    if quiet or total < 50 or not sys.stderr.isatty():
        return None
    width = 30

    def show(done: int, total: int) -> None:
        filled = width * done // total
        end = "\n" if done == total else ""
        sys.stderr.write(
            f"\r  solving [{'#' * filled}{'.' * (width - filled)}] {done}/{total}{end}"
        )
        sys.stderr.flush()

    return show


if __name__ == "__main__":
    sys.exit(main())
