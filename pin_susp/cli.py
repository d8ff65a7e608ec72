"""The ``pin-susp`` command line.

Exit codes: 0 success; 1 the run finished but some steps did not converge
(their rows are written, flagged ``solver_converged = False`` with empty
metric cells); 2 a problem with the input (one line on stderr, nothing
written).

Start-up time: each command imports what it uses inside its own function
(numpy, Pinocchio and the package's modules included), so that ``--help``
costs no numpy and a sweep no plotting, loads or studies
(tests/test_startup.py).
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import math
import os
import re
import signal
import stat
import sys
import threading
import warnings
from pathlib import Path

from . import __version__
from .errors import PinSuspError, PlausibilityWarning

SHEET_METRICS = (  # column, unit, short heading
    ("camber", "deg", "camber"),
    ("roadwheel_angle", "deg", "toe"),
    ("caster", "deg", "caster"),
    ("kpi", "deg", "KPI"),
    ("scrub_radius", "mm", "scrub"),
    ("mechanical_trail", "mm", "trail"),
    ("half_track", "mm", "half track"),
    ("ride_height_change", "mm", "ride height"),
)
SETUP_COLUMNS = ("shim_thickness", "trackrod_length_delta", "pushrod_length_delta")

EXIT_NOT_CONVERGED = 1
EXIT_INPUT = 2


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error (one line, exit 2)
        return exc.code if isinstance(exc.code, int) else EXIT_INPUT
    import numpy as np

    from .yamlio import read_once

    with (
        _terminate_as_exit(),
        read_once(),  # each input read once: a pipe or a FIFO cannot be read twice
        warnings.catch_warnings(record=True) as caught,
        np.errstate(all="ignore"),
    ):
        # Undefined values (parallel arms, a toggle) are NaN by design and flagged
        # where they matter; numpy's warnings about them would only be noise.
        warnings.simplefilter("ignore")
        warnings.simplefilter("always", PlausibilityWarning)
        args.warnings = caught
        try:
            code = args.run(args)
            _print_warnings(args)  # only for a run that went through: exit 2 is one line
            return code
        except PinSuspError as exc:  # one line, whatever the file's keys hold
            message = str(exc).replace("\r", "\\r").replace("\n", "\\n")
            print(f"pin-susp: error: {message}", file=sys.stderr)
            return EXIT_INPUT
        except (KeyboardInterrupt, _Terminated) as exc:
            signal_number = exc.signal if isinstance(exc, _Terminated) else signal.SIGINT
            print(f"pin-susp: interrupted, {_unwritten(args)}", file=sys.stderr)
            return 128 + signal_number
        except BrokenPipeError:  # output piped into `head` and the like
            sys.stderr.close()
            return 0
        except OSError as exc:  # a safety net: each output path is checked before any work
            if exc.errno != errno.ENAMETOOLONG:
                raise
            name = exc.filename if exc.filename is not None else "a path"
            print(f"pin-susp: error: {name}: a name too long for the file system", file=sys.stderr)
            return EXIT_INPUT


def _unwritten(args) -> str:
    """What an interrupt leaves: no file; but what went into a stream (-o /dev/stdout, a
    pipe) is out, and a streamed sweep may have sent some of its rows."""
    output = getattr(args, "output", None)
    if isinstance(output, str) and output:
        from .export import is_stream

        if is_stream(Path(output)):
            return f"{output} is a stream: what was already sent to it is incomplete"
    return "nothing written"


def _print_warnings(args) -> None:
    """The implausible values seen so far, one line each (not with --quiet)."""
    seen = list(dict.fromkeys(str(w.message) for w in args.warnings))
    args.warnings.clear()
    if not getattr(args, "quiet", False):
        for message in seen:
            print(f"pin-susp: warning: {message}", file=sys.stderr)


class _Terminated(BaseException):
    """SIGTERM or SIGHUP: unwinds like Ctrl+C, so temporary files and servers are removed."""

    def __init__(self, signal_number: int):
        super().__init__(signal_number)
        self.signal = signal_number


@contextlib.contextmanager
def _terminate_as_exit():
    """While a command runs, SIGTERM and SIGHUP raise _Terminated (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signal_number, _frame):
        raise _Terminated(signal_number)

    previous = {s: signal.signal(s, handler) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


class _Parser(argparse.ArgumentParser):
    """argparse with usage errors on one line (the usage is in --help), and values
    that start with a minus and a digit (``--trackrod -1,0,1``) read as values."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-\.?[0-9]")

    def error(self, message: str):
        self.exit(EXIT_INPUT, f"pin-susp: error: {message} (see {self.prog} --help)\n")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="pin-susp",
        description="Suspension kinematics on Pinocchio: a corner from a YAML file of "
        "hardpoints (mm, ISO 8855), solved exactly through bump and steer sweeps.",
        epilog="Start with `pin-susp demo`. Formats: docs/geometry.md, docs/sweep.md, "
        "docs/results.md, docs/urdf.md.",
    )
    p.add_argument("--version", action="version", version=f"pin_susp {__version__}")
    sub = p.add_subparsers(title="commands", metavar="COMMAND", required=True)
    _sweep_command(sub)
    _urdf_command(sub)
    _mjcf_command(sub)
    _validate_command(sub)
    _demo_command(sub)
    _setup_command(sub)
    _sensitivity_command(sub)
    _plot_command(sub)
    _draw_command(sub)
    _view_command(sub)
    _loads_command(sub)
    _study_command(sub)
    return p


def _geometry_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("geometry", metavar="GEOMETRY", help="geometry YAML (hardpoints in mm)")


def _numbers(text: str) -> list[float]:
    """Lengths in mm separated by commas: finite, within the 100 m limit of any car."""
    from .yamlio import MAX_LENGTH_MM

    try:
        values = [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected numbers separated by commas, got {text!r}"
        ) from None
    for x in values:
        if not math.isfinite(x) or abs(x) > MAX_LENGTH_MM:
            raise argparse.ArgumentTypeError(
                f"{x:g} mm is not a finite length within {MAX_LENGTH_MM / 1000:g} m"
            )
    return values


def _finite(text: str, positive: bool = False) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(x) or (positive and x <= 0.0):
        bound = " > 0" if positive else ""
        raise argparse.ArgumentTypeError(f"expected a finite number{bound}, got {text!r}")
    return x


def _positive(text: str) -> float:
    return _finite(text, positive=True)


COUNT_LIMIT = 999_999  # --top: more entries than any table has hardpoint coordinates


def _count(text: str) -> int:
    if not re.fullmatch(r"[0-9]{1,6}", text.strip()):
        raise argparse.ArgumentTypeError(
            f"expected a whole number from 0 to {COUNT_LIMIT}, got {text!r}"
        )
    return int(text)


def _sweep_command(sub) -> None:
    s = sub.add_parser(
        "sweep",
        help="solve a sweep and write one CSV row per step",
        description="Solve every step of SWEEP on GEOMETRY (a corner, or an axle: scope: axle) "
        "and write the metrics (camber, toe, caster, KPI, scrub, trail, ...; an axle's per "
        "side, and its roll, roll centre, bar twist, ...) and every point to CSV. "
        "Exit code 1 if any step did not converge (its row is flagged).",
    )
    _run_arguments(
        s,
        "results CSV",
        "also draw the standard kinematics report (an axle's: camber, toe, steer, roll "
        "centre, bar twist, ... against roll, heave or rack)",
    )
    s.set_defaults(run=_sweep)


def _run_arguments(parser, output: str, plot: str, cases: bool = False) -> None:
    """GEOMETRY SWEEP [--cases] -o OUT.csv [-q] [--plot OUT.png]: a sweep's, a loads run's."""
    _geometry_argument(parser)
    parser.add_argument("sweep", metavar="SWEEP", help="sweep YAML (targets per step)")
    if cases:
        parser.add_argument(
            "--cases", required=True, metavar="LOADS.yaml", help="load cases (N, N·m, world axes)"
        )
    parser.add_argument(
        "-o", "--output", required=True, metavar="OUT.csv", help=f"{output} (Parquet: OUT.parquet)"
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    parser.add_argument("--plot", metavar="OUT.png", help=plot)


def _sweep(args) -> int:
    _check_outputs(args, args.output, args.plot)  # before the numerics are imported
    if args.plot is not None:
        _check_image(args.plot)
    from .corner import Corner
    from .geometry import load_geometry
    from .sweep import load_sweep

    if _is_axle(args.geometry):
        return _sweep_axle(args)
    corner = Corner(load_geometry(args.geometry))
    sweep = load_sweep(args.sweep)
    corner.solver_for(sweep.targets, sweep.source)  # target errors before any work
    if sweep.steps > STREAM_STEPS and args.plot is None:
        return _sweep_streamed(args, corner, sweep)
    results = corner.run_sweep(sweep, progress=_progress_bar(sweep.steps, args.quiet))
    digest = Digest.of(results)
    _warn_transmission(digest)
    plot = _write_results(args, results)
    if not args.quiet:
        _summary(digest, args.output)
        if plot:
            print(f"wrote {args.plot}")
    return _report_failures(digest)


def _sweep_streamed(args, corner, sweep) -> int:
    """A long sweep written as it is solved, a chunk of steps at a time: its memory does
    not grow with its length (the same rows as run_sweep's, to the solver's tolerance).
    A chunk is written by a second thread while the next one is solved (pyarrow's
    formatting and numpy leave the GIL): two chunks alive at most."""
    from concurrent.futures import ThreadPoolExecutor

    from .export import CsvStream, ParquetStream, is_parquet

    parts = corner.run_sweep_chunks(sweep, progress=_progress_bar(sweep.steps, args.quiet))
    first = next(parts)
    digest = Digest.of(first)
    kind = ParquetStream if is_parquet(args.output) else CsvStream
    with (
        kind(args.output, first.units, first.meta, list(first.columns), sweep.steps) as out,
        ThreadPoolExecutor(1) as writer,
    ):
        pending = writer.submit(out.write, first)
        del first
        for part in parts:
            pending.result()
            pending = writer.submit(out.write, part)
            digest.add(part)
            del part
        pending.result()
    _warn_transmission(digest)
    if not args.quiet:
        _summary(digest, args.output)
    return _report_failures(digest)


def _write_results(args, results) -> bool:
    """The CSV (Parquet for an OUT ending .parquet) and, with --plot, the report: both or
    neither; whether it was drawn."""
    from .export import all_or_none, csv_text, is_parquet, write_csv, write_text

    plot = args.plot is not None and results["solver_converged"].any()
    text = csv_text(results) if plot else None  # the report reads the CSV's text
    with all_or_none():
        if is_parquet(args.output):
            from .export import write_parquet

            write_parquet(results, args.output)
        elif text is None:
            write_csv(results, args.output)
        else:
            write_text(text, args.output)
        if plot:  # drawn from the CSV's text: the output may be a stream
            from .plots import ResultsFile, report_figure, save_figure

            written = ResultsFile(args.output, raw=text.encode())
            save_figure(report_figure([written]), args.plot)
    if args.plot is not None and not plot:
        print(f"pin-susp: no step converged: {args.plot} not drawn", file=sys.stderr)
    return plot


def _loads_command(sub) -> None:
    lo = sub.add_parser(
        "loads",
        help="member and joint forces at every step under load cases",
        description="Solve SWEEP on GEOMETRY (a corner or an axle) and, at every step, the "
        "quasi-static "
        "forces under each load case of CASES (README, Loads and rates): the tension in every "
        "two-force member (wishbone legs, trackrod or toe link, pushrod, links), the "
        "spring's force, the rack's, and the load at every ball joint and pivot bushing "
        "(a wishbone's also along each leg: a wishbone carrying the pushrod is no "
        "two-force member, its legs blank and said so). "
        "One CSV row per step and case, then the sweep's own columns. Exit code 1 if a "
        "step did not converge.",
    )
    _run_arguments(
        lo,
        "forces CSV",
        "also draw the force report: each member's force and each joint's load "
        "against wheel travel (or rack), a line per load case",
        cases=True,
    )
    lo.set_defaults(run=_loads)


def _loads(args) -> int:
    import numpy as np

    _check_outputs(args, args.output, args.plot)
    if args.plot is not None:
        _check_image(args.plot)
    corner, sweep, cases = _load_inputs(args.geometry, args.sweep, args.cases)
    results, forces = _solve_forces(corner, sweep, cases, args.quiet)
    plot = _write_results(args, forces)
    if not args.quiet:
        unbounded = int(np.nansum(forces["loads_unbounded"]))
        print(
            f"wrote {args.output}: {len(results)} steps x {len(cases)} load cases"
            + (f"; {unbounded} row(s) at a toggle (forces unbounded: blank)" if unbounded else "")
        )
        for note in results.meta.get("notes", ()):
            print(f"  {note}")
        _force_summary(forces)
        if plot:
            print(f"wrote {args.plot}")
    return _report_failures(results)


def _load_inputs(geometry, sweep, cases):
    """A corner or an axle, its sweep and load cases, every input error said before any
    work."""
    from .corner import Corner
    from .geometry import load_geometry
    from .loads import Statics, load_cases
    from .sweep import load_sweep

    if _is_axle(geometry):
        from .axle import axle_rows

        model = _axle_model(geometry)
        sweep = load_sweep(sweep)
        cases = load_cases(cases, axle=True)
        axle_rows(model, sweep.targets, sweep.source)  # target errors before any work
        Statics(model)  # no load path, or a bar without its stiffness
        return model, sweep, cases
    corner = Corner(load_geometry(geometry))
    sweep = load_sweep(sweep)
    cases = load_cases(cases)
    corner.solver_for(sweep.targets, sweep.source)  # target errors before any work
    Statics(corner)  # a corner without a load path
    return corner, sweep, cases


def _solve_forces(corner, sweep, cases, quiet: bool):
    """The sweep's results and, at every step and load case, the forces."""
    from .corner import Corner, Results
    from .loads import member_forces

    if not isinstance(corner, Corner):  # an axle
        from .axle import axle_results, solve_axle_sweep

        solutions = solve_axle_sweep(corner, sweep, progress=_progress_bar(sweep.steps, quiet))
        results = axle_results(corner, sweep, solutions)
        return results, member_forces(corner, sweep, cases, solutions, results)
    tangents = []
    solutions = corner.solve_steps(
        sweep, progress=_progress_bar(sweep.steps, quiet), tangents=tangents
    )
    results = Results.from_solutions(corner, solutions, sweep, tangents or None)
    return results, member_forces(corner, sweep, cases, solutions, results)


def _chosen_case(path, cases, name: str | None) -> str:
    """The load case to show: the one named (it must be in the file), else the first."""
    from .errors import InputError

    names = [c.name for c in cases]
    if name is not None and name not in names:
        listed = ", ".join(repr(n) for n in names)
        raise InputError(str(path), "cases", f"no load case named {name!r} (it has {listed})")
    return names[0] if name is None else name


def _force_summary(forces) -> None:
    """The largest tension and compression of each member over the sweep, per case; a
    wishbone that is not a two-force member (it carries a pushrod, say) by its bushing
    loads resolved along each leg, and said so."""
    import numpy as np

    bent = forces.meta.get("not_two_force", {})
    stand_in = {}  # a bent arm's blank leg → its bushing's load along the leg
    for _, legs, alongs in bent.values():
        stand_in.update(zip(legs, alongs, strict=True))
    names = [n for n in forces.columns if n.startswith(("force_", "torque_"))]
    names = [stand_in.get(n, n) for n in names]
    width = max([36, *(len(n) for n in names)])
    print(f"  {'member':{width}s} {'case':18s} {'min':>12s} {'max':>12s}")
    for case in dict.fromkeys(forces["load_case"]):
        rows = forces["load_case"] == case
        for name in names:
            values = forces[name][rows].astype(float)
            if np.isnan(values).all():
                continue
            unit = forces.units.get(name, "N")
            print(
                f"  {name:{width}s} {str(case)[:18]:18s} {np.nanmin(values):12.1f} "
                f"{np.nanmax(values):12.1f} {unit}"
            )
    for arm, (points, legs, alongs) in bent.items():
        print(
            f"  {arm}: not a two-force member (it also carries {', '.join(points)}): its "
            f"legs bend, {' and '.join(legs)} are blank; {' and '.join(alongs)} are its "
            "bushings' loads resolved along each leg (+ as a leg's tension)"
        )


def _is_axle(path) -> bool:
    """Whether a geometry file is an axle's (scope: axle)."""
    from .yamlio import load_yaml

    data, _, _ = load_yaml(path)
    return data.get("scope") == "axle"


def _axle_model(path):
    from .axle import AxleModel, load_axle

    return AxleModel(load_axle(path))


def _sweep_axle(args) -> int:
    """An axle's sweep: both corners' columns (suffixed by side) and the axle's."""
    import numpy as np

    from .axle import axle_results, solve_axle_sweep
    from .sweep import load_sweep

    model = _axle_model(args.geometry)
    sweep = load_sweep(args.sweep)
    solutions = solve_axle_sweep(model, sweep, progress=_progress_bar(sweep.steps, args.quiet))
    results = axle_results(model, sweep, solutions)
    digest = Digest.of(results)
    _warn_transmission(digest)
    plot = _write_results(args, results)
    if not args.quiet:
        ok = results["solver_converged"]
        print(
            f"wrote {args.output}: {len(results)} steps, {int(ok.sum())} converged, "
            f"max residual {np.nanmax(results['solver_max_residual']):.1e} mm"
        )
        for note in digest.notes:
            print(f"  {note}")
        shown = [
            (name, np.asarray(results[name], dtype=float))
            for name in AXLE_SUMMARY
            if name in results.columns and not np.all(np.isnan(results[name]))
        ]
        some = any(np.isnan(v).any() for _, v in shown)  # a blank cell: say at how many steps
        head = f"{'first':>13}{'last':>13}{'min':>13}{'max':>13}" + (f"{'blank':>8}" * some)
        print(f"  {'column':<28}{'unit':>7}{head}")
        for name, v in shown:
            empty = int(np.isnan(v).sum())
            print(
                f"  {name:<28}{results.units[name]:>7}{_cell(v[0])}{_cell(v[-1])}"
                f"{_cell(np.nanmin(v))}{_cell(np.nanmax(v))}" + (f"{empty or '':>8}" * some)
            )
        failed = len(results) - int(ok.sum())
        if failed:
            print(
                f"  (blank: an empty cell in the CSV; {failed} of {len(results)} steps did not "
                "converge, and their columns are blank)"
            )
        print("  (every column of both corners, suffixed _left/_right, is in the CSV)")
        if plot:
            print(f"wrote {args.plot}")
    return _report_failures(digest)


AXLE_SUMMARY = (
    "heave",
    "roll",
    "body_roll",
    "camber_left",
    "camber_right",
    "camber_to_ground_left",
    "camber_to_ground_right",
    "roadwheel_angle_left",
    "roadwheel_angle_right",
    "roll_center_y",
    "roll_center_z",
    "track",
    "ride_height_change",
    "arb_twist",
    "heave_link_length",
    "ackermann",
    "roll_stiffness",
    "arb_wheel_rate",
)


def _urdf_command(sub) -> None:
    u = sub.add_parser(
        "urdf",
        help="write the corner as URDF (tree + loop closures)",
        description="Write the URDF of GEOMETRY: the kinematic tree in metres, every "
        "hardpoint as a link, loop closures as <pin_susp:loop_closure> elements.",
    )
    _geometry_argument(u)
    u.add_argument(
        "-o", "--output", metavar="OUT.urdf", help="file to write (default: standard output)"
    )
    u.add_argument(
        "--at",
        metavar="SWEEP:STEP",
        help="also write the joint values of that solved step to a YAML sidecar "
        "(OUT.pose.yaml), so another tool can load the pose",
    )
    u.set_defaults(run=_urdf)


def _urdf(args) -> int:
    from .corner import Corner
    from .export import all_or_none, is_stream, write_text
    from .geometry import load_geometry

    if args.at is not None and args.output is None:
        raise PinSuspError("--at writes a sidecar beside the URDF: give -o OUT.urdf too")
    _check_outputs(args, args.output)
    sidecar = None
    if args.output is not None and args.at is not None:
        if is_stream(Path(args.output)):
            raise PinSuspError(f"--at writes a sidecar beside the URDF: {args.output} is a stream")
        sidecar = Path(args.output).with_suffix(".pose.yaml")
        _check_outputs(args, args.output, sidecar)
    if _is_axle(args.geometry):
        if args.at is not None:
            raise PinSuspError("--at: not for an axle yet (a corner's URDF at a step only)")
        corner = _axle_model(args.geometry)  # the URDF of both corners on one chassis
    else:
        corner = Corner(load_geometry(args.geometry))
    pose = _pose_at(corner, args.at) if args.at is not None else None
    if args.output is None:
        sys.stdout.write(corner.urdf)
        return 0
    with all_or_none():
        write_text(corner.urdf, args.output)
        if pose is not None:
            import yaml

            write_text(yaml.safe_dump(pose, sort_keys=False), sidecar)
    print(f"wrote {args.output}")
    if sidecar is not None:
        print(f"wrote {sidecar}")
    return 0


def _pose_at(corner, at: str) -> dict:
    """Joint values of one solved sweep step, by joint name (rad, m)."""
    from .sweep import load_sweep

    path, _, step = at.rpartition(":")
    if not path or not re.fullmatch(r"[0-9]{1,9}", step):
        raise PinSuspError(f"--at {at}: expected SWEEP.yaml:STEP, e.g. bump_steer.yaml:20")
    sweep = load_sweep(path)
    corner.solver_for(sweep.targets, sweep.source)
    i = int(step)
    if i >= sweep.steps:
        raise PinSuspError(f"--at {at}: the sweep has steps 0 to {sweep.steps - 1}")
    results = corner.run_sweep(sweep)
    if not results["solver_converged"][i]:
        why = results.meta["why"][i]
        raise PinSuspError(f"--at {at}: that step did not converge ({why})")
    q = results.meta["q"][i]
    model = corner.model
    joints = {model.names[j]: float(q[model.joints[j].idx_q]) for j in range(1, model.njoints)}
    return {
        "comment": "joint values of a solved pose; revolute in rad, prismatic in m; "
        "all zero is the design state",
        "urdf_robot": corner.tree.name,
        "sweep": sweep.source,
        "step": i,
        "targets": {t.point: float(t.values[i]) for t in corner.held_targets(sweep.targets)},
        "joints": joints,
    }


def _mjcf_command(sub) -> None:
    mj = sub.add_parser(
        "mjcf",
        help="write the corner as MJCF (MuJoCo; loop closures as equality connects)",
        description="Write GEOMETRY as MJCF: the URDF's bodies and joints, every point a "
        "site, ball closures as <connect>, distance closures as a rod on a universal joint "
        "closed by a <connect>. Loads in MuJoCo and in Pinocchio's MJCF parser.",
    )
    _geometry_argument(mj)
    mj.add_argument("-o", "--output", required=True, metavar="OUT.xml", help="file to write")
    mj.set_defaults(run=_mjcf)


def _mjcf(args) -> int:
    from .corner import Corner
    from .export import write_text
    from .geometry import load_geometry
    from .mjcf import tree_to_mjcf

    _check_outputs(args, args.output)
    if _is_axle(args.geometry):
        corner = _axle_model(args.geometry)
        source = corner.axle.source
    else:
        corner = Corner(load_geometry(args.geometry))
        source = corner.geometry.source
    comment = (
        f"generated by pin_susp {__version__} from {Path(source).name};"
        " regenerate with: pin-susp mjcf GEOMETRY -o FILE"
    )
    write_text(tree_to_mjcf(corner.tree, comment), args.output)
    print(f"wrote {args.output}")
    return 0


def _validate_command(sub) -> None:
    va = sub.add_parser(
        "validate",
        help="re-solve a sweep with MuJoCo or Drake and a point-based solver; compare every column",
        description="Solve SWEEP with pin_susp, then re-solve every step independently from "
        "the design state with a point-based formulation (hardpoints as unknowns, rigid "
        "distances, scipy) and with MuJoCo (from the exported MJCF) and/or Drake (the exported "
        "URDF in Drake's own parser, its InverseKinematics solved by IPOPT); print the largest "
        "difference per column and engine; exit 1 where one exceeds the tolerance. GEOMETRY "
        "is a corner or an axle (scope: axle: each side's columns, the axle's, the bar). "
        "MuJoCo and Drake are optional: pip install 'pin_susp[validate]'.",
    )
    _geometry_argument(va)
    va.add_argument("sweep", metavar="SWEEP", help="sweep YAML")
    va.add_argument(
        "--engine",
        choices=("mujoco", "drake", "all", "pointwise"),
        default="mujoco",
        help="the engine besides the point-based solver, which always runs: mujoco "
        "(default), drake, all (both), or pointwise (that one only)",
    )
    va.add_argument(
        "--mjcf",
        metavar="FILE.xml",
        help="an exported MJCF for MuJoCo to check against (default: export it now)",
    )
    va.add_argument(
        "--urdf",
        metavar="FILE.urdf",
        help="an exported URDF for Drake to check against (default: export it now)",
    )
    va.add_argument(
        "--tolerance",
        type=_positive,
        default=1e-6,
        metavar="TOL",
        help="largest difference accepted, mm and deg (default 1e-6)",
    )
    va.set_defaults(run=_validate)


def _validate(args) -> int:
    from .corner import Corner
    from .geometry import load_geometry
    from .sweep import load_sweep
    from .validate import validate
    from .yamlio import read_input

    axle = _is_axle(args.geometry)
    corner = _axle_model(args.geometry) if axle else Corner(load_geometry(args.geometry))
    sweep = load_sweep(args.sweep)
    if not axle:  # an axle's target errors come from its solve, before any work
        corner.solver_for(sweep.targets, sweep.source)
    name = corner.axle.name if axle else corner.geometry.name
    engines = {
        "mujoco": ("pointwise", "mujoco"),
        "drake": ("pointwise", "drake"),
        "all": ("pointwise", "mujoco", "drake"),
        "pointwise": ("pointwise",),
    }[args.engine]
    texts = {}
    for option, engine, what in (("mjcf", "mujoco", "MJCF"), ("urdf", "drake", "URDF")):
        path = getattr(args, option)
        if path is None:
            continue
        if engine not in engines:
            raise PinSuspError(
                f"--{option}: only {engine} reads it; add --engine {engine} (or --engine all)"
            )
        try:
            texts[option] = read_input(path).decode("utf-8")
        except OSError as exc:
            raise PinSuspError(f"{path}: cannot be read ({exc.strerror})") from None
        except UnicodeDecodeError:
            raise PinSuspError(f"{path}: not a text file ({what} is XML)") from None
    results, reports = validate(
        corner,
        sweep,
        texts.get("mjcf"),
        args.tolerance,
        mjcf_source=args.mjcf or "--mjcf",
        engines=engines,
        urdf_text=texts.get("urdf"),
        urdf_source=args.urdf or "--urdf",
    )
    names = list(dict.fromkeys(n for r in reports for n in r.differences))
    print(
        f"{name}: {len(results)} steps of {sweep.source}, each re-solved from "
        "the design state; largest |difference| to pin_susp"
    )
    width = max(map(len, names), default=6) + 2
    print(f"  {'column':<{width}}{'unit':>7}" + "".join(f"{r.engine:>14}" for r in reports))
    for name in names:
        unit = next(r.units[name] for r in reports if name in r.units)
        cells = "".join(
            f"{(f'{r.differences[name]:.1e}' + ('!' if name in r.disagree else ' ')):>14}"
            if name in r.differences
            else f"{'-':>14}"
            for r in reports
        )
        print(f"  {name:<{width}}{unit:>7}{cells}")
    ok = _report_failures(results, "are not compared") == 0
    for r in reports:
        if r.note:
            print(f"  {r.engine}: skipped — {r.note}")
            continue
        if r.failed_steps:
            print(f"  {r.engine}: did not converge at steps {_list(r.failed_steps)}")
        if r.branch_steps or r.other_branch:
            print(f"  {r.engine}: {_other_branch(r, corner)}")
        if r.not_compared:
            print(
                f"  {r.engine}: {', '.join(sorted(r.not_compared))} not compared (they need the "
                "toe link's length changed, which this engine's model cannot do)"
            )
        if getattr(r, "warnings", 0):
            print(f"  {r.engine}: {r.warnings} warnings (first: {r.first_warning})")
        if r.agrees:
            centres = "instant centres also within 1e-9 of their size" + (
                "; the roll centre of its size times max(1, |RC|/track)" if axle else ""
            )
            print(f"  {r.engine}: agrees within {args.tolerance:g} mm/deg ({centres})")
        elif r.disagree:
            ok = False
            print(f"  {r.engine}: DISAGREES on {', '.join(sorted(r.disagree))} (marked !)")
        elif r.failed_steps or r.branch_steps:
            ok = False
            unsolved = [
                f"{len(steps)} step(s) {what}"
                for steps, what in (
                    (r.failed_steps, "it did not solve"),
                    (r.branch_steps, "on another assembly branch"),
                )
                if steps
            ]
            print(
                f"  {r.engine}: agrees where it solved on pin_susp's branch, but leaves "
                f"{' and '.join(unsolved)} unconfirmed (nothing marked)"
            )
    return 0 if ok else 1


def _other_branch(r, subject) -> str:
    """An engine's steps on another assembly branch than pin_susp's, said as such: where
    pin_susp solved them (a difference of assembly, not of kinematics) and where it
    found no pose either; a dead centre at design is the likely cause."""
    said = []
    if r.branch_steps:
        said.append(
            f"lands on another assembly branch at steps {_list(r.branch_steps)} "
            f"({', '.join(sorted(r.flipped))}), where pin_susp keeps the design's: "
            "those steps are not compared"
        )
    if r.other_branch:
        said.append(
            f"{'and ' if said else 'lands on another assembly branch '}at steps "
            f"{_list(r.other_branch)}, which pin_susp reaches on no branch of the design's"
            + ("" if r.branch_steps else f" ({', '.join(sorted(r.flipped))})")
        )
    dead = [t for t in getattr(subject, "dead_centres", ()) if t.driven]
    if dead:
        near = ", ".join(f"{t.flow} {t.margin:.1f}° from dead centre" for t in dead)
        said.append(f"near the dead centre at design ({near}: see the dead-centre warning)")
    return "; ".join(said)


def _demo_command(sub) -> None:
    d = sub.add_parser(
        "demo",
        help="run the embedded example and write its results",
        description="Solve the embedded example corner (the test corner of open-kinematics "
        "0.4) through a combined bump+steer sweep and write into DIR: demo_geometry.yaml and "
        "demo_sweep.yaml (the inputs, to edit and rerun), demo_results.csv (every column), "
        "demo_report.png (the standard kinematics plots), demo_drawing.png (front and side "
        "view), demo_replay.html (the 3D replay, opens in a browser with no server) and "
        "demo_corner.urdf (the URDF with its loop closures).",
    )
    d.add_argument(
        "-o",
        "--output",
        default="pin_susp_demo",
        metavar="DIR",
        help="output folder (default: ./pin_susp_demo)",
    )
    d.set_defaults(run=_demo)


def _demo(args) -> int:
    import hashlib
    from dataclasses import replace
    from importlib import resources

    import yaml

    from .corner import Corner
    from .export import all_or_none, check_folder, csv_text, write_text
    from .geometry import load_geometry
    from .sweep import load_sweep

    if str(args.output).strip() == "":
        raise PinSuspError(f"{args.output!r}: the demo writes several files: give a folder")
    out = check_folder(args.output)
    if out.exists() and not out.is_dir():
        raise PinSuspError(f"{args.output!r}: the demo writes several files: give a folder")
    data = resources.files("pin_susp") / "data"
    inputs = {name: (data / name).read_text() for name in ("demo_geometry.yaml", "demo_sweep.yaml")}
    geometry_path, sweep_path = out / "demo_geometry.yaml", out / "demo_sweep.yaml"
    files = {
        "results": out / "demo_results.csv",
        "plots": out / "demo_report.png",
        "drawing": out / "demo_drawing.png",
        "3D replay": out / "demo_replay.html",
        "URDF": out / "demo_corner.urdf",
    }
    _check_outputs(args, geometry_path, sweep_path, *files.values())
    # read from the text, named as the copies written beside the results
    geometry, sweep = (
        replace(
            load(yaml.safe_load(inputs[path.name])),
            source=str(path),
            sha256=hashlib.sha256(inputs[path.name].encode()).hexdigest(),
        )
        for load, path in ((load_geometry, geometry_path), (load_sweep, sweep_path))
    )
    corner = Corner(geometry)
    results = corner.run_sweep(sweep, progress=_progress_bar(sweep.steps, False))
    digest = Digest.of(results)
    _warn_transmission(digest)
    with all_or_none():
        for name, text in inputs.items():
            write_text(text, out / name)
        write_text(corner.urdf, files["URDF"])
        text = csv_text(results)
        write_text(text, files["results"])
        _demo_pictures(corner, results, files, text)
    print(f"pin_susp demo: {corner.geometry.name}, {sweep.steps}-step bump + steer sweep")
    _summary(digest, files["results"])
    for what, path in [("geometry", geometry_path), ("sweep", sweep_path), *files.items()]:
        print(f"  {what:<10} {path}")
    print(
        f"open {files['3D replay']} in a browser to see the corner move; "
        f"{files['plots']} has the standard plots"
    )
    return _report_failures(digest)


def _demo_pictures(corner, results, files, csv: str) -> None:
    import contextlib
    import io

    from .export import write_text
    from .plots import ResultsFile, drawing_figure, report_figure, save_figure
    from .viz import CornerScene

    written = ResultsFile(files["results"], raw=csv.encode())
    save_figure(report_figure([written]), files["plots"])
    save_figure(drawing_figure(corner), files["drawing"])
    with contextlib.redirect_stdout(io.StringIO()):  # meshcat announces its server
        scene = CornerScene(corner)
    try:
        scene.animate(list(results.meta["q"]))
        write_text(scene.html(), files["3D replay"])
    finally:
        scene.close()


# Instant-centre columns: past this (mm) the arms are all but parallel and the
# centre is better described as "at infinity" than by a number.
FAR = 1e5
CENTRES = ("svic_x", "svic_z", "fvic_y", "fvic_z", "svsa_length", "fvsa_length")
# Rocker transmission angle outside this band (deg): the rocker nears over-centre.
TRANSMISSION_BAND = (30.0, 150.0)


# A corner's sweep longer than this (steps) is streamed to its file, a chunk at a time.
STREAM_STEPS = 10_000
# Beyond the metrics, the columns the summary shows where a sweep has them.
SUMMARY_EXTRA = (
    "deriv_camber_wrt_hub_z",
    "deriv_roadwheel_angle_wrt_hub_z",
    "motion_ratio",
    "spring_force",
    "spring_torque",
    "wheel_rate",
    "ride_rate",
)
SIDES = (("", ""), ("_left", "left "), ("_right", "right "))


class Steps:
    """Step numbers as a report names them: the first few, and how many in all (a sweep
    of millions of steps keeps no more)."""

    SHOWN = 10

    def __init__(self):
        self.first: list[int] = []
        self.count = 0

    def add(self, steps) -> None:
        room = self.SHOWN + 1 - len(self.first)  # one more than shown: "..." follows
        if room > 0:
            self.first += [int(i) for i in steps[:room]]
        self.count += len(steps)

    def __str__(self) -> str:
        return _list(self.first)

    def __eq__(self, other) -> bool:
        return isinstance(other, Steps) and (self.first, self.count) == (other.first, other.count)


class Digest:
    """What the summary, the warnings and the failure report need from a sweep's
    results, gathered a chunk at a time (``add``): a streamed sweep keeps no rows.
    Steps are the results' ``step_index``."""

    def __init__(self):
        self.steps = self.converged = 0
        self.max_residual = math.nan
        self.iterations = []  # how many steps took each count of iterations
        self.units: dict[str, str] = {}
        # name → [first, last, min, max, far step, |far|, blank steps]
        self.stats: dict[str, list] = {}
        # Steps are kept as Steps: the first few, and how many (a report names no more).
        self.short = Steps()  # out of reach or past a lock-up
        self.worst_short = 0.0  # their largest residual, mm
        self.flipped = Steps()  # on another assembly branch
        self.loops: set[str] = set()  # the loops that flipped
        # side → [Steps outside, worst step, its angle, |motion ratio| there (None: no
        # ratio)]; side → [the angle nearest 90°, |motion ratio| there]: which way the
        # ratio goes as the rocker nears over-centre
        self.band: dict[str, list] = {}
        self.nearest: dict[str, list] = {}
        self.dead: list = []  # the links near dead centre at design (deadcentre.Transmission)
        # side → [Steps below zero, least force, those in droop (or at design), in bump,
        # extending in bump (past over-centre)]
        self.unseat: dict[str, list] = {}
        self.notes: list[str] = []  # how the sweep's targets were read (the rack held)

    @classmethod
    def of(cls, results) -> Digest:
        if isinstance(results, Digest):
            return results
        digest = cls()
        digest.add(results)
        return digest

    def add(self, results) -> None:
        import numpy as np

        from .metrics import METRICS

        steps = np.asarray(results["step_index"])
        ok = np.asarray(results["solver_converged"], dtype=bool)
        residual = np.asarray(results["solver_max_residual"], dtype=float)
        self.steps += len(steps)
        self.converged += int(ok.sum())
        if len(steps):
            self.max_residual = np.nanmax(np.r_[self.max_residual, residual])
        counts = np.bincount(np.asarray(results["solver_iterations"], dtype=int)).tolist()
        self.iterations += [0] * (len(counts) - len(self.iterations))
        for i, count in enumerate(counts):
            self.iterations[i] += count
        for note in results.meta.get("notes", ()):
            if note not in self.notes:
                self.notes.append(note)
        why = results.meta["why"]
        if not self.dead:
            self.dead = list(results.meta.get("dead_centres", ()))
        for i in np.flatnonzero(~ok):
            if "branch" in why[i]:
                self.flipped.add([int(steps[i])])
                self.loops.add(why[i].rpartition(" of ")[2])
            else:
                self.short.add([int(steps[i])])
                self.worst_short = max(self.worst_short, float(residual[i]))
        names = [m.name for m in METRICS if m.written] + list(SUMMARY_EXTRA)
        for name in names:
            if name in results.columns and len(steps):
                self._column(name, np.asarray(results[name], dtype=float), steps)
                self.units[name] = results.units[name]
        low, high = TRANSMISSION_BAND
        for suffix, side in SIDES:
            angle = results.columns.get(f"rocker_transmission_angle{suffix}")
            if angle is not None:
                ratio = results.columns.get(f"motion_ratio{suffix}")

                def at(i, ratio=ratio):
                    return None if ratio is None or np.isnan(ratio[i]) else abs(float(ratio[i]))

                off = np.abs(angle - 90.0)
                solved = np.flatnonzero(~np.isnan(off))
                if len(solved):
                    best = solved[np.argmin(off[solved])]
                    near = self.nearest.get(side)
                    if near is None or off[best] < abs(near[0] - 90.0):
                        self.nearest[side] = [float(angle[best]), at(best)]
                outside = np.flatnonzero((angle < low) | (angle > high))
                if len(outside):
                    worst = outside[np.argmax(off[outside])]
                    band = self.band.setdefault(side, [Steps(), None, 90.0, None])
                    band[0].add(steps[outside])
                    if off[worst] > abs(band[2] - 90.0):
                        band[1:4] = int(steps[worst]), float(angle[worst]), at(worst)
            force = results.columns.get(f"spring_force{suffix}")
            if force is not None and np.nanmin(force, initial=np.inf) < 0.0:
                unseat = self.unseat.setdefault(side, [Steps(), np.inf, Steps(), Steps(), False])
                below = force < 0.0
                unseat[0].add(steps[np.flatnonzero(below)])
                unseat[1] = min(unseat[1], float(np.nanmin(force)))
                travel = results.columns.get(f"wheel_travel{suffix}")
                bump = below & (travel > 0.0) if travel is not None else np.zeros_like(below)
                unseat[2].add(steps[np.flatnonzero(below & ~bump)])  # droop, or at design
                unseat[3].add(steps[np.flatnonzero(bump)])
                ratio = results.columns.get(f"motion_ratio{suffix}")
                if ratio is not None:  # extending in bump: past over-centre
                    unseat[4] |= bool(np.any(bump & (ratio <= 0.0)))

    def _column(self, name: str, v, steps) -> None:
        import numpy as np

        stat = self.stats.get(name)
        if stat is None:
            stat = self.stats[name] = [v[0], v[-1], np.nan, np.nan, None, 0.0, 0]
        stat[1] = v[-1]
        stat[6] += int(np.isnan(v).sum())  # the CSV's empty cells
        if not np.isnan(v).all():
            stat[2] = np.nanmin(np.r_[stat[2], v])
            stat[3] = np.nanmax(np.r_[stat[3], v])
        far = np.flatnonzero(np.abs(v) > FAR)
        if len(far):
            i = far[np.argmax(np.abs(v[far]))]
            if abs(v[i]) > stat[5]:
                stat[4], stat[5] = int(steps[i]), abs(v[i])

    @property
    def failed(self) -> int:
        return self.short.count + self.flipped.count

    @property
    def iterations_median(self) -> float:
        import numpy as np

        total = np.cumsum(self.iterations)
        n = int(total[-1]) if len(total) else 0
        if not n:
            return float("nan")
        middle = np.searchsorted(total, [(n - 1) // 2 + 1, n // 2 + 1])
        return float(np.mean(middle))


def _summary(results, path) -> None:
    from .metrics import METRIC_BY_NAME

    d = Digest.of(results)
    print(
        f"wrote {path}: {d.steps} steps, {d.converged} converged, "
        f"max residual {d.max_residual:.1e} mm, "
        f"{d.iterations_median:g} iterations per step (median)"
    )
    for note in d.notes:
        print(f"  {note}")
    # a cell the CSV leaves empty (a step that did not converge, a value undefined
    # there) is blank here too, and a column with blanks says at how many steps
    some = any(0 < stat[6] < d.steps for stat in d.stats.values())
    head = f"{'first':>13}{'last':>13}{'min':>13}{'max':>13}" + (f"{'blank':>8}" * some)
    print(f"  {'metric':<32}{'unit':>7}{head}")
    blank = []
    for name, (first, last, low, high, far, _, empty) in d.stats.items():
        if empty == d.steps:  # NaN at every step
            blank.append(name)
            continue
        line = f"  {name:<32}{d.units[name]:>7}{_cell(first)}{_cell(last)}"
        if name in CENTRES and far is not None:
            line += f"   at infinity (instant axis parallel to the view) near step {far}"
        else:
            line += f"{_cell(low)}{_cell(high)}" + (f"{empty or '':>8}" if some else "")
        print(line)
    for name in blank:
        m = METRIC_BY_NAME.get(name)
        why = f"needs {m.needs}" if m is not None and m.needs else "undefined at every step"
        print(f"  {name:<32}{d.units[name]:>7}   (blank: {why})")
    if d.failed:
        print(
            f"  (blank: an empty cell in the CSV; {d.failed} of {d.steps} steps did not "
            "converge, and their metrics are blank)"
        )
    print("  (every column, derivatives included, is in the CSV)")


def _cell(value: float, width: int = 13) -> str:
    """A summary figure; an undefined one (NaN) blank, as the CSV's cell."""
    return f"{'':>{width}}" if value != value else f"{value:>{width}.6g}"


def _warn_transmission(results) -> None:
    """Name the steps where a rocker transmission angle leaves its band (an axle's
    per side), and where a rated spring's force goes below zero (it would unseat)."""
    d = Digest.of(results)
    low, high = TRANSMISSION_BAND
    for _, side in SIDES:
        if side in d.band:
            steps, worst, angle, ratio = d.band[side]
            best, best_ratio = d.nearest[side]
            warnings.warn(
                f"{side}rocker transmission angle outside {low:g}…{high:g} deg at steps "
                f"{steps} (worst {angle:.1f} deg at step {worst}): the rocker nears "
                f"over-centre, {_ratio_trend(ratio, best, best_ratio)}",
                PlausibilityWarning,
                stacklevel=2,
            )
        if side in d.unseat:
            steps, least, droop, bump, over_centre = d.unseat[side]
            advice = []
            if droop.count:  # it extends as the wheel drops: the preload runs out
                where = f" in droop (steps {droop})" if bump.count else ""
                advice.append(f"{where}: more preload, or limit the droop travel (a droop limiter)")
            if bump.count:
                where = f"; in bump (steps {bump})" if droop.count else " (in bump)"
                if over_centre:  # it should compress in bump: its motion ratio has turned
                    why = (
                        "the spring extends as the wheel rises there (motion_ratio <= 0: a "
                        "rocker past over-centre, or one that works the spring the wrong "
                        "way; check the pushrod and rocker) — droop is not the cause"
                    )
                else:  # compressing, yet below zero: it starts below zero (the preload)
                    why = "more preload: the spring compresses in bump here, it starts too low"
                advice.append(f"{where}: {why}")
            warnings.warn(
                f"{side}spring force below zero at steps {steps} "
                f"(least {least:.0f} N): the spring would unseat there" + "".join(advice),
                PlausibilityWarning,
                stacklevel=2,
            )


def _ratio_trend(ratio: float | None, best: float, best_ratio: float | None) -> str:
    """Which way the motion ratio goes as the pushrod nears the rocker's dead centre, by
    the numbers: |ratio| at the worst step against it where the angle is nearest 90°
    (as the geometry says, it rises: the rocker turns ever faster per mm of pushrod
    travel — unless the spring's side of the rocker nears its own dead centre too).
    Without a motion ratio (no spring), the geometry's word alone."""
    if ratio is None or best_ratio is None:
        return "the rocker turns ever faster per mm of wheel travel and can flip over"
    way = "rises toward infinity" if ratio > best_ratio else "falls toward zero"
    return (
        f"its motion ratio {way} (|{ratio:.3g}| there, |{best_ratio:.3g}| at "
        f"{best:.0f} deg) and can flip"
    )


def _dead_centre_cause(d: Digest) -> str:
    """The failure report's cause for steps out of reach or on another branch: a link
    that drives its body near dead centre at design (its warning is printed too)."""
    driven = [t for t in d.dead if t.driven]
    if not driven:
        return ""
    said = ", ".join(f"{t.flow} {t.margin:.1f}° from dead centre" for t in driven)
    return f" — the mechanism is at a dead centre at design ({said}: see the dead-centre warning)"


def _report_failures(
    results, consequence: str = "are flagged solver_converged=False with empty cells"
) -> int:
    """Name the steps that did not converge, and why, on stderr; the exit code."""
    d = Digest.of(results)
    if not d.failed:
        return 0
    reasons = []
    if d.short.count:
        reasons.append(
            f"steps {d.short} out of the mechanism's reach or past a lock-up "
            f"(residual up to {d.worst_short:.3g} mm)"
        )
    if d.flipped.count:
        reasons.append(
            f"steps {d.flipped} reach the targets only on another assembly branch "
            f"({', '.join(sorted(d.loops))} flipped over: not the design's mechanism)"
        )
    print(
        f"pin-susp: warning: {d.failed} of {d.steps} steps did not converge: "
        f"{'; '.join(reasons)}{_dead_centre_cause(d)}. Their rows {consequence}.",
        file=sys.stderr,
    )
    return EXIT_NOT_CONVERGED


def _list(steps: list[int]) -> str:
    return ", ".join(map(str, steps[:10])) + (" ..." if len(steps) > 10 else "")


def _check_image(path) -> None:
    """An image output: a writable path with an extension matplotlib can write."""
    from .export import check_output
    from .plots import check_image_path

    check_output(path, "image")
    check_image_path(path)


def _check_outputs(args, *paths) -> None:
    """Before any work: every output writable, each its own file, none of them an input."""
    from .export import check_output

    inputs = [getattr(args, name, None) for name in ("geometry", "sweep", "mjcf", "cases")]
    inputs += list(getattr(args, "results", None) or ())
    at = getattr(args, "at", None)
    if at:
        inputs.append(at.rpartition(":")[0])
    inputs = [Path(p) for p in inputs if p]
    seen = {}
    for path in (p for p in paths if p is not None):
        target = _identity(check_output(path))
        for source in inputs:
            if target == _identity(source):
                raise PinSuspError(f"{path}: is an input of this command: writing it would lose it")
        if target in seen and target[0] != "stream":
            raise PinSuspError(f"{seen[target]} and {path} are one file: give each output its own")
        seen[target] = path


def _identity(path: Path) -> tuple:
    """What makes two paths one file: device and inode when it exists, else its real path."""
    try:
        st = Path(path).stat()
    except OSError:
        return ("path", os.path.realpath(path))
    if not stat.S_ISREG(st.st_mode):
        return ("stream", st.st_dev, st.st_ino)
    return ("file", st.st_dev, st.st_ino)


def _progress_bar(total: int, quiet: bool, minimum: int = 50, label: str = "solving"):
    """A one-line progress bar on a terminal; nothing in logs or pipes."""
    if quiet or total < minimum or not sys.stderr.isatty():
        return None
    width = 30

    def show(done: int, total: int) -> None:
        filled = width * done // total
        end = "\n" if done == total else ""
        sys.stderr.write(
            f"\r  {label} [{'#' * filled}{'.' * (width - filled)}] {done}/{total}{end}"
        )
        sys.stderr.flush()

    return show


def _setup_command(sub) -> None:
    t = sub.add_parser(
        "setup",
        help="setup sheet: static metrics, shim/trackrod/pushrod rows, sensitivities, inverse",
        description="Print the static metrics of GEOMETRY as set (camber shim and length "
        "adjusters applied). List values to see one row each; ask for exact sensitivities; "
        "or give target values to find the shim, trackrod and pushrod settings that hit them.",
        epilog="Example: pin-susp setup examples/camber_shim.yaml --shim 15,20,25,30 "
        "--sensitivities; pin-susp setup examples/camber_shim.yaml --camber -2.5 --toe 0.1 "
        "-o set.yaml",
    )
    _geometry_argument(t)
    t.add_argument(
        "--shim",
        type=_numbers,
        default=[],
        metavar="MM,MM,...",
        help="fitted shim stack thicknesses, one row each",
    )
    t.add_argument(
        "--trackrod",
        type=_numbers,
        default=[],
        metavar="MM,MM,...",
        help="trackrod (or fixed toe link) length changes (+ longer), one row each; "
        "negative values as written: --trackrod -1,0,1",
    )
    t.add_argument(
        "--pushrod",
        type=_numbers,
        default=[],
        metavar="MM,MM,...",
        help="pushrod length changes (+ longer), one row each",
    )
    t.add_argument(
        "--sensitivities",
        action="store_true",
        help="exact d(camber, toe, ride height)/d(shim, trackrod, pushrod)",
    )
    t.add_argument(
        "--thread-pitch",
        type=_positive,
        metavar="MM",
        help="also give sensitivities per turn of an adjuster with this pitch "
        "(length change per turn; a left/right-hand turnbuckle: twice the pitch)",
    )
    t.add_argument("--camber", type=_finite, metavar="DEG", help="target static camber (shim)")
    t.add_argument(
        "--toe",
        type=_finite,
        metavar="DEG",
        help="target static roadwheel angle, + toe-in (trackrod)",
    )
    t.add_argument(
        "--ride-height-change",
        type=_finite,
        metavar="MM",
        help="target ride-height change, + car higher (pushrod)",
    )
    t.add_argument(
        "-o",
        "--output",
        metavar="SET.yaml",
        help="with targets: write the geometry with the setup found",
    )
    t.add_argument("--csv", metavar="OUT.csv", help="also write the sheet's rows as CSV")
    t.add_argument(
        "--side",
        choices=("left", "right"),
        help="an axle with its own right points: listed values and targets set this side "
        "alone (default: both sides; a mirrored axle has one setup for both)",
    )
    t.set_defaults(run=_setup)


def _setup(args) -> int:
    from . import setup
    from .export import all_or_none
    from .geometry import load_geometry

    _check_outputs(args, args.output, args.csv)
    targets = {
        name: value
        for name, value in (
            ("camber", args.camber),
            ("roadwheel_angle", args.toe),
            ("ride_height_change", args.ride_height_change),
        )
        if value is not None
    }
    if args.output is not None and not targets:
        raise PinSuspError("-o writes a solved setup: give --camber, --toe or --ride-height-change")
    if _is_axle(args.geometry):
        return _setup_axle(args, targets)
    if args.side is not None:
        raise PinSuspError(f"--side: {args.geometry} is a corner (--side sets one side of an axle)")
    geometry = load_geometry(args.geometry)
    title = f"{geometry.name}: setup sheet ({geometry.source})"
    link = _link(geometry)
    if targets:
        found = setup.solve_setup(geometry, targets)
        print(title)
        _sheet([found.before, found.after], ["before", "after"], _link(geometry))
        _hit(targets, found.iterations)
        with all_or_none():
            if args.output is not None:
                _write_setup(setup.geometry_data(found.geometry), geometry.name, args.output)
            if args.csv is not None:
                _sheet_csv([found.before, found.after], ["before", "after"], args.csv, link)
        _wrote(args.output, args.csv)
        return 0
    rows = setup.setup_sheet(geometry, args.shim, args.trackrod, args.pushrod)
    labels = _sheet_labels(args, link)
    print(title)
    _sheet(rows, labels, link)
    if args.sensitivities:
        _sensitivities(rows[0], geometry, args.thread_pitch)
    if args.csv is not None:
        _sheet_csv(rows, labels, args.csv, link)
    _wrote(args.csv)
    return 0


def _setup_axle(args, targets: dict) -> int:
    """An axle: each side's sheet as its corner's (its own shim and adjusters), the axle's
    static columns of both sides together, or the inverse solve per side."""
    import numpy as np

    from . import setup
    from .axle import SIDES, load_axle
    from .export import all_or_none

    axle = load_axle(args.geometry)
    chosen = setup.set_sides(axle, args.side)
    link = _link(axle.left)
    if targets:
        found = setup.solve_axle_setup(axle, targets, args.side)
        rows = {s: [found[s].before, found[s].after] for s in SIDES}
        labels = ["before", "after"]
    else:
        rows = setup.axle_setup_sheet(axle, args.shim, args.trackrod, args.pushrod, args.side)
        labels = _sheet_labels(args, link)
    # the axle's columns per row: both sides as set in that row (a side not set: as set)
    statics = [
        setup.axle_static(axle, {s: rows[s][min(i, len(rows[s]) - 1)] for s in SIDES})
        for i in range(len(labels))
    ]
    print(f"{axle.name}: setup sheet per side ({axle.source})")
    for s in SIDES:
        if s == "right" and axle.mirrored:
            print(
                "  right corner (the left mirrored: it takes the left's setup, the same shim "
                "stack and length deltas):"
            )
        else:
            setting = "" if s in chosen else f"; not set: --side {args.side}"
            print(f"  {s} corner (axle_config.{s}_setup{setting}):")
        _sheet(rows[s], labels[: len(rows[s])], link)
        if targets and found[s].iterations:
            _hit(targets, found[s].iterations)
        if args.sensitivities and not targets:
            _sensitivities(rows[s][0], axle.corner(s), args.thread_pitch)
    print("  axle (both sides as set in each row):")
    print(f"  {'':9}" + "".join(f"{head:>12}" for _, head in setup.AXLE_STATIC))
    print(f"  {'':9}" + "".join(f"{'mm':>12}" for _ in setup.AXLE_STATIC))
    for label, row in zip(labels, statics, strict=True):
        cells = (round(row[name], 3) + 0.0 for name, _ in setup.AXLE_STATIC)
        print(
            f"  {label:9}"
            + "".join(f"{v:>12.3f}" if np.isfinite(v) else f"{'-':>12}" for v in cells)
        )
    with all_or_none():
        if args.output is not None:
            data = setup.axle_data(axle, {s: found[s].geometry for s in chosen})
            _write_setup(data, axle.name, args.output)
        if args.csv is not None:
            sides = [(s, i) for s in SIDES for i in range(len(rows[s]))]
            _sheet_csv(
                [rows[s][i] for s, i in sides],
                [f"{s} {labels[i]}" for s, i in sides],
                args.csv,
                link,
                [statics[i] for _, i in sides],
            )
    _wrote(args.output, args.csv)
    return 0


def _sheet_labels(args, link: str) -> list[str]:
    """The sheet's row labels: the as-set row, then one per listed value."""
    return (
        ["as set"]
        + ["shim"] * len(args.shim)
        + [link] * len(args.trackrod)
        + ["pushrod"] * len(args.pushrod)
    )


def _hit(targets: dict, iterations: int) -> None:
    print(
        f"  hit {', '.join(f'{k} {v:g}' for k, v in targets.items())} "
        f"in {iterations} Newton iterations"
    )


def _write_setup(data: dict, name: str, path) -> None:
    """A geometry (corner or axle) file with the setup found."""
    import yaml

    from .export import write_text

    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
    write_text(f"# {name}: setup solved by pin-susp setup\n" + text, path)


def _wrote(*paths) -> None:
    for path in paths:
        if path is not None:
            print(f"wrote {path}")


def _link(geometry) -> str:
    """The length adjuster that sets toe: the trackrod, a fixed toe link, or none."""
    if not geometry.steering_points:
        return "no link"
    return "trackrod" if geometry.steering == "rack" else "toe link"


def _sheet(rows, labels, link: str = "trackrod") -> None:
    import numpy as np

    print(
        f"  {'':9}{'shim':>8}{link:>9}{'pushrod':>8}"
        + "".join(f"{head:>12}" for _, _, head in SHEET_METRICS)
    )
    print(
        f"  {'':9}{'mm':>8}{'Δ mm':>9}{'Δ mm':>8}"
        + "".join(f"{unit:>12}" for _, unit, _ in SHEET_METRICS)
    )
    for label, row in zip(labels, rows, strict=True):
        line = f"  {label:9}" + "".join(
            f"{v + 0.0:>{w}.3f}" for v, w in zip(row.setup, (8, 9, 8), strict=True)
        )
        line += "".join(
            f"{row.metrics[name] + 0.0:>12.4f}" if np.isfinite(row.metrics[name]) else f"{'-':>12}"
            for name, _, _ in SHEET_METRICS
        )
        print(line)


def _sensitivities(state, geometry, pitch) -> None:
    drawn = geometry.drawn or geometry
    have = (drawn.camber_shim is not None, bool(drawn.steering_points), drawn.has_pushrod)
    link = _link(drawn)
    columns = [("per mm shim", 0, 1.0), (f"per mm {link}", 1, 1.0), ("per mm pushrod", 2, 1.0)]
    if pitch:
        columns += [(f"per turn {link}", 1, pitch), ("per turn pushrod", 2, pitch)]
    columns = [c for c in columns if have[c[1]]]
    if not columns:
        print("  exact sensitivities: this corner has no setup adjuster (shim, link or pushrod)")
        return
    print("  exact sensitivities at the static state:")
    print(f"  {'':26}" + "".join(f"{c[0]:>19}" for c in columns))
    for name, unit in (("camber", "deg"), ("roadwheel_angle", "deg"), ("ride_height_change", "mm")):
        d = state.derivatives[name]
        print(
            f"  {name + ' (' + unit + ')':26}"
            + "".join(f"{d[i] * k:>19.6g}" for _, i, k in columns)
        )


def _sheet_csv(rows, labels, path, link: str = "trackrod", extra=None) -> None:
    """The sheet's rows; ``extra``: per row, more columns (name → value), e.g. an
    axle's track and roll centre."""
    from .export import atomic_write, format_cell

    setup_columns = [c.replace("trackrod", link.replace(" ", "_")) for c in SETUP_COLUMNS]
    names = ["row", *setup_columns] + [name for name, _, _ in SHEET_METRICS]
    extra = extra or [{}] * len(rows)
    with atomic_write(path) as f:
        f.write(f"# pin_susp {__version__} setup sheet; lengths mm, angles deg\n")
        f.write(",".join(names + list(extra[0])) + "\n")
        for label, row, more in zip(labels, rows, extra, strict=True):
            cells = [label, *map(format_cell, row.setup)]
            cells += [format_cell(row.metrics[name]) for name, _, _ in SHEET_METRICS]
            cells += [format_cell(v) for v in more.values()]
            f.write(",".join(cells) + "\n")


def _sensitivity_command(sub) -> None:
    h = sub.add_parser(
        "sensitivity",
        help="exact d(metric)/d(hardpoint coordinate), at design or along a sweep",
        description="How much each hardpoint coordinate moves each metric and each derivative "
        "column (camber gain, bump steer, ...): exact, by implicit differentiation of the "
        "closure equations. Writes a long-format CSV (step_index, metric, hardpoint, axis, "
        "value, unit) and prints the largest entries per metric.",
    )
    _geometry_argument(h)
    h.add_argument(
        "--sweep", metavar="SWEEP", help="at every step of this sweep (default: the design state)"
    )
    h.add_argument("-o", "--output", metavar="SENS.csv", help="long-format CSV")
    h.add_argument(
        "--top",
        type=_count,
        default=3,
        metavar="N",
        help="entries per metric in the printed table (default 3)",
    )
    h.add_argument(
        "--points",
        default="designer",
        metavar="GROUP|NAMES",
        help="which hardpoints the printed table ranks: designer (default: chassis pickups "
        "and link ends, not the spindle points), chassis, upright, all, or names separated "
        "by commas (the CSV always has every hardpoint)",
    )
    h.add_argument(
        "--one-sided",
        action="store_true",
        help="an axle: move each side's point alone (hardpoints left_P, right_P); default "
        "a symmetric move, the left P by (dx, dy, dz) and the right P by (dx, -dy, dz)",
    )
    h.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    h.set_defaults(run=_sensitivity)


def _sensitivity(args) -> int:
    from .corner import Corner
    from .geometry import load_geometry
    from .sensitivity import hardpoint_sensitivities, select_points
    from .sweep import load_sweep

    _check_outputs(args, args.output)
    if _is_axle(args.geometry):
        return _sensitivity_axle(args)
    if args.one_sided:
        raise PinSuspError("--one-sided: a corner has one side (it moves one side of an axle)")
    corner = Corner(load_geometry(args.geometry))
    points = select_points(corner, args.points)
    sweep = None
    if args.sweep is not None:
        sweep = load_sweep(args.sweep)
        corner.solver_for(sweep.targets, sweep.source)
    progress = _progress_bar(sweep.steps if sweep else 1, args.quiet)
    states, results = hardpoint_sensitivities(corner, sweep, progress, with_results=True)
    notes = []
    if corner.geometry.drawn is not None:
        notes.append("(with respect to the as-set hardpoints: shim and adjusters applied)")
    groups = [("", list(states[0].values) if states else [])]
    return _sensitivity_report(args, corner.geometry, sweep, states, results, points, groups, notes)


def _sensitivity_axle(args) -> int:
    """An axle's: each side's corner columns (_left, _right) and the axle's (track, roll
    centre, roll rates), for a symmetric move of both sides' points or a one-sided one."""
    from .axle import CENTER, SIDE_EXTRAS, SIDES

    side_points = {n for names in SIDE_EXTRAS.values() for n in names}
    center_points = {n for names in CENTER.values() for n in names}
    from .sensitivity import (
        AXLE_COLUMNS,
        ONE_SIDED_MOVE,
        SYMMETRIC_MOVE,
        AxleSensitivity,
        axle_held,
        axle_sensitivities,
        select_points,
    )
    from .sweep import load_sweep

    model = _axle_model(args.geometry)
    if model.axle is not None and model.axle.anti_roll_rigid:
        raise PinSuspError(
            f"{args.geometry}: sensitivity: not for an axle with a rigid anti-roll bar yet "
            "(each wheel's height is held, which a rigid bar does not allow)"
        )
    bar = [
        n
        for n in (args.points or "").split(",")
        if n.strip() in {*side_points, *center_points} or n.strip().startswith(SIDES)
    ]
    if bar:
        raise PinSuspError(
            f"--points: {bar[0].strip()} — the sensitivities of the anti-roll bar's and heave "
            "link's points (and of side-prefixed names) are not computed yet: give the "
            "corners' hardpoints (both sides move together; --one-sided for one side)"
        )
    sens = AxleSensitivity(model, args.one_sided)
    points = select_points(sens.sides["left"].corner, args.points)
    if args.one_sided:
        points = [f"{side}_{p}" for side in SIDES for p in points]
    sweep = None if args.sweep is None else load_sweep(args.sweep)
    progress = _progress_bar(sweep.steps if sweep else 1, args.quiet)
    states, results = axle_sensitivities(sens, sweep, progress)
    move = ONE_SIDED_MOVE if args.one_sided else SYMMETRIC_MOVE
    notes = [f"exact; {axle_held(model)}; {move}"]
    if any(g.drawn is not None for g in model.geometries.values()):
        notes.append("(with respect to the as-set hardpoints: shims and adjusters applied)")
    columns = list(states[0].values) if states else []
    groups = [("the axle:", AXLE_COLUMNS)]
    for side in ("left",) if model.axle.mirrored else SIDES:
        names = [n for n in columns if n.endswith(f"_{side}") and n not in AXLE_COLUMNS]
        groups.append((f"the {side} corner (columns suffixed _{side}):", names))
    if model.axle.mirrored:
        groups.append(("the right corner's columns mirror the left's (a mirrored axle)", ()))
    head = (f"hardpoint: {move}", axle_held(model))
    return _sensitivity_report(
        args, model.axle, sweep, states, results, points, groups, notes, head
    )


def _sensitivity_report(
    args, geometry, sweep, states, results, points, groups, notes=(), csv_notes=()
) -> int:
    """The CSV (``csv_notes`` in its head), the steps without sensitivities, and the
    printed table: a title, ``notes``, then per group (heading, columns) the largest
    entries among ``points``. The exit code."""
    from .sensitivity import POINT_GROUPS

    if args.output is not None:
        _sensitivity_csv(states, geometry.source, args.output, csv_notes)
    status = 0 if results is None else _report_failures(results, "have no sensitivities")
    if args.quiet or not states:
        return status
    s = states[0]
    where = "the design state" if sweep is None else f"step {s.step} of {sweep.source}"
    print(f"{geometry.name}: hardpoint sensitivities at {where}")
    for note in notes:
        print(f"  {note}")
    chosen = POINT_GROUPS.get(args.points, ", ".join(points))
    print(f"  moving {chosen}; other points: --points chassis|upright|all|NAME,NAME")
    for heading, names in groups:
        if heading:
            print(f"  {heading}")
        _sensitivity_table(s, names, args.top, set(points))
    if args.output is not None:
        print(
            f"wrote {args.output}: {len(states)} state(s) x {len(s.values)} metrics x "
            f"{3 * len(s.hardpoints)} hardpoint coordinates (every hardpoint)"
        )
    return status


def _sensitivity_table(s, names, top: int, points: set) -> None:
    """The ``top`` largest entries of each column in ``names`` among ``points``; then the
    columns these points do not move, and those undefined here."""
    import numpy as np

    from .sensitivity import STEP, largest

    unmoved, undefined = [], []
    for name in names:
        entries = largest(s, name, top, points)
        unit = s.units[name].removesuffix("/mm")
        if not np.isfinite(s.metrics[name]):
            undefined.append(name)
            continue
        if not entries:
            unmoved.append(name)
            continue
        step = STEP.get(unit, 1.0)
        print(f"  {name} = {s.metrics[name]:.6g} {unit}")
        for hardpoint, axis, value in entries:
            move = step / value
            print(
                f"    {hardpoint + ' ' + axis:34} {value:+.4g} {unit}/mm"
                f"   (to change it by +{step:g} {unit}, move {move:+.3g} mm)"
            )
    if unmoved:
        print(f"  not moved by these points here: {', '.join(unmoved)}")
    if undefined:
        print(f"  undefined here (blank in the results): {', '.join(undefined)}")


def _sensitivity_csv(states, source: str, path, notes=()) -> None:
    from .export import atomic_write, format_cell

    with atomic_write(path) as f:
        f.write(f"# pin_susp {__version__} hardpoint sensitivities of {source}\n")
        f.write("# value = d(metric)/d(hardpoint coordinate), per mm of the coordinate\n")
        f.writelines(f"# {note}\n" for note in notes)
        f.write("step_index,metric,hardpoint,axis,value,unit\n")
        for s in states:
            for name, values in s.values.items():
                for i, hardpoint in enumerate(s.hardpoints):
                    for a, axis in enumerate("xyz"):
                        f.write(
                            f"{s.step},{name},{hardpoint},{axis},"
                            f"{format_cell(values[i, a])},{s.units[name]}\n"
                        )


def _plot_command(sub) -> None:
    pl = sub.add_parser(
        "plot",
        help="standard kinematics report from results CSVs (one panel per metric)",
        description="Camber, toe, caster, KPI, scrub, trail, half track (and instant-centre "
        "heights, anti geometry, rocker, motion ratio, spring force, wheel and ride rate, "
        "camber gain and bump steer where present) against wheel travel, or rack travel from "
        "centre for a steer sweep; a sweep that moved both (bump + steer) against the step, "
        "its inputs drawn as the first panels. Several CSVs compare designs, a colour per "
        "file (of the same kind of sweep: a bump and a steer sweep cannot share one figure). "
        "An axle's CSV gives the axle report: camber (to the chassis and to the ground), toe, "
        "steer angle, roll centre, bar twist, IC heights, rates, per side, against roll, "
        "heave or rack (the step when several moved), and Ackermann against the mean steer "
        "angle. A forces CSV (pin-susp loads) gives the force report: each member's force and "
        "each joint's load, a line per load case, a toggle's steps left as gaps. A column "
        "that varies less than its unit's smallest span (0.5 mm, 0.05 deg, ...) is drawn "
        "flat, and labelled when constant.",
    )
    pl.add_argument(
        "results", nargs="+", metavar="RESULTS.csv", help="pin-susp sweep (or loads) output"
    )
    pl.add_argument(
        "-o", "--output", required=True, metavar="OUT.png", help="image (png, pdf, svg)"
    )
    pl.set_defaults(run=_plot)


def _plot(args) -> int:
    from .plots import ResultsFile, report_figure, save_figure

    _check_outputs(args, args.output)
    _check_image(args.output)
    files = [ResultsFile(path) for path in args.results]
    save_figure(report_figure(files), args.output)
    print(f"wrote {args.output}")
    return 0


def _draw_command(sub) -> None:
    dr = sub.add_parser(
        "draw",
        help="front and side view drawing of a corner (front view of an axle)",
        description="Draw GEOMETRY at its design (as-set) state in front and side view, with "
        "the instant-centre construction (ball joints to the front- and side-view instant "
        "centres, the contact patch through them, and the roll centre of a symmetric axle on "
        "the centreline); a shimmed corner shows its drawn geometry dashed. An axle "
        "(scope: axle) is drawn in front view, both corners, each contact patch through its "
        "FVIC and the roll centre where the two lines cross; --at draws it at a step of its "
        "sweep results.",
    )
    _geometry_argument(dr)
    dr.add_argument(
        "-o", "--output", required=True, metavar="OUT.png", help="image (png, pdf, svg)"
    )
    dr.add_argument(
        "--labels", action="store_true", help="name every hardpoint and add a colour legend"
    )
    dr.add_argument(
        "--at",
        metavar="RESULTS.csv:STEP",
        help="an axle: draw the pose of that step of its `pin-susp sweep` results "
        "(default: the design state)",
    )
    dr.set_defaults(run=_draw)


def _draw(args) -> int:
    from .corner import Corner
    from .geometry import load_geometry
    from .plots import ResultsFile, axle_drawing_figure, axle_pose, drawing_figure, save_figure

    _check_outputs(args, args.output)
    _check_image(args.output)
    if args.at is not None:
        path, _, step = args.at.rpartition(":")
        if not path or not re.fullmatch(r"[0-9]{1,9}", step):
            raise PinSuspError(f"--at {args.at}: expected RESULTS.csv:STEP, e.g. axle.csv:15")
    if _is_axle(args.geometry):
        model = _axle_model(args.geometry)
        q, caption = None, "design state"
        if args.at is not None:
            q, caption = axle_pose(model, ResultsFile(path), int(step))
        figure = axle_drawing_figure(model, q, labels=args.labels, caption=caption)
    elif args.at is not None:
        raise PinSuspError(f"--at: {args.geometry} is a corner, drawn at its design state only")
    else:
        figure = drawing_figure(Corner(load_geometry(args.geometry)), labels=args.labels)
    save_figure(figure, args.output)
    print(f"wrote {args.output}")
    return 0


def _view_command(sub) -> None:
    v = sub.add_parser(
        "view",
        help="3D view in meshcat (live, or a self-contained HTML replay)",
        description="Open GEOMETRY in a meshcat scene served locally (works offline) and print "
        "its URL; with SWEEP, play the solved motion as an animation. --html writes the scene "
        "and animation as one HTML file that opens in a browser with no server. An axle file "
        "shows both corners, the anti-roll bar and the roll centre (hidden where it is blank). "
        "With --cases (and SWEEP), the members are coloured by their force under one load "
        "case at every frame: red tension, blue compression, grey zero, full colour at the "
        "largest |force| over the sweep; one replay per case (--case).",
    )
    _geometry_argument(v)
    v.add_argument("sweep", metavar="SWEEP", nargs="?", help="sweep YAML to animate")
    v.add_argument("--html", metavar="OUT.html", help="write a self-contained replay and exit")
    v.add_argument("--fps", type=_positive, default=10.0, help="animation frames per second")
    v.add_argument(
        "--cases", metavar="LOADS.yaml", help="load cases: colour the members by their force"
    )
    v.add_argument("--case", metavar="NAME", help="the load case to colour by (default: the first)")
    v.set_defaults(run=_view)


def _view(args) -> int:
    import contextlib
    import io
    import time

    from .corner import Corner
    from .export import write_text
    from .geometry import load_geometry
    from .sweep import load_sweep
    from .viz import Scene, force_caption, force_key, roll_centres, signals_held

    _check_outputs(args, args.html)
    if args.case is not None and args.cases is None:
        raise PinSuspError(f"--case {args.case}: needs --cases LOADS.yaml, the cases it names")
    if args.cases is not None and args.sweep is None:
        raise PinSuspError(f"--cases {args.cases}: needs a SWEEP, whose steps the forces are of")
    qs, results, markers, forces = None, None, None, None
    if args.cases is not None:  # a corner, its sweep and its forces under every case
        model, sweep, cases = _load_inputs(args.geometry, args.sweep, args.cases)
        case = _chosen_case(args.cases, cases, args.case)
        results, forces = _solve_forces(model, sweep, cases, quiet=False)
        _warn_transmission(results)
        axle = not isinstance(model, Corner)
    else:
        axle = _is_axle(args.geometry)
        model = _axle_model(args.geometry) if axle else Corner(load_geometry(args.geometry))
    if args.sweep is not None and forces is None:
        sweep = load_sweep(args.sweep)
        progress = _progress_bar(sweep.steps, False)
        if axle:  # both corners and the bar
            from .axle import axle_results, solve_axle_sweep

            results = axle_results(model, sweep, solve_axle_sweep(model, sweep, progress=progress))
        else:
            model.solver_for(sweep.targets, sweep.source)
            results = model.run_sweep(sweep, progress=progress)
            _warn_transmission(results)
    if results is not None:
        qs = [
            q if ok else None
            for q, ok in zip(results.meta["q"], results["solver_converged"], strict=True)
        ]
        if axle:  # the roll centre, from the results' columns
            markers = {"roll_centre": roll_centres(results)}
    quiet = io.StringIO()
    with contextlib.redirect_stdout(quiet):  # meshcat announces its server on stdout
        scene = Scene(model)
    try:  # an interrupt before the scene is served is one as in every command: 130, 143
        colours, caption = None, ""
        if forces is not None:
            colours, scale = scene.force_colours(forces, case)
            others = f"the first of {len(cases)}: --case NAME for another" * (
                args.case is None and len(cases) > 1
            )
            bent = bool(scene.not_two_force)
            print(force_key(case, scale, others, bent))
            caption = force_caption(case, scale, Path(args.cases).name, bent)
        frames = (
            scene.animate(qs, fps=args.fps, markers=markers, colours=colours)
            if qs is not None
            else 0
        )
        page = scene.html(caption) if args.html is not None else None
    except BaseException:
        with contextlib.suppress(KeyboardInterrupt):  # a second Ctrl+C while it stops
            scene.close()
        raise
    if args.html is not None:
        with signals_held():  # a signal while the server stops: raised once it has
            scene.close()
        write_text(page, args.html)  # whole or not at all
        print(f"wrote {args.html}" + (f" ({frames} frames)" if frames else ""))
        return 0 if results is None else _report_failures(results, "are not in the replay")
    try:
        print(
            f"meshcat: {scene.viewer.url()}"
            + (f"  ({frames} frames: press play in Open Controls > Animations)" if frames else "")
        )
        if results is not None:
            _report_failures(results, "are not in the animation")
        _print_warnings(args)
        # A process started in the background of a script inherits SIGINT ignored:
        # we say "press Ctrl+C", so Ctrl+C must stop us.
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.default_int_handler)
        print("serving; press Ctrl+C to stop", flush=True)
        while True:
            time.sleep(0.5)
    except KeyboardInterrupt:  # the way to stop a live scene: it was served, exit 0
        print("stopped")
        return 0
    finally:
        with contextlib.suppress(KeyboardInterrupt):  # a second Ctrl+C while it stops
            scene.close()


# ---------------------------------------------------------------- study


def _study_command(sub) -> None:
    st = sub.add_parser(
        "study",
        help="many variants of a geometry on Dask: DOE, tolerance Monte Carlo, optimisation",
        description="Run the variants of STUDY (a design of experiments, manufacturing "
        "tolerances by Monte Carlo, or an optimisation to target values and curves; "
        "docs/studies.md) through its sweep on Dask, and write OUTDIR/variants.parquet "
        "(one row per variant), study.png, with --steps steps.parquet (every step), and "
        "for an optimisation best.yaml. Exit code 1 if a variant did not converge at "
        "every step (its row is flagged).",
    )
    st.add_argument("study", metavar="STUDY", help="study YAML (geometry, sweep, variables)")
    st.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUTDIR",
        help="a new or empty directory (or this study's unfinished one, with --resume)",
    )
    st.add_argument(
        "--scheduler",
        default="local",
        metavar="ADDRESS",
        help="tcp://HOST:PORT of a running Dask scheduler; 'local' (default): a cluster on "
        "this machine (127.0.0.1); 'none': serially, in this process",
    )
    st.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="the local cluster's worker processes (default: one per core)",
    )
    st.add_argument(
        "--steps",
        action="store_true",
        help="also write every step of every variant (steps.parquet, a Parquet dataset)",
    )
    st.add_argument(
        "--resume",
        action="store_true",
        help="finish an interrupted run in OUTDIR: only the batches not yet written are solved",
    )
    st.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    st.set_defaults(run=_study)


def _study(args) -> int:
    import time

    from . import study as studies

    if args.workers is not None and args.workers < 1:
        raise PinSuspError(f"--workers must be 1 or more, got {args.workers}")
    scheduler = None if args.scheduler == "none" else args.scheduler
    if scheduler != "local" and args.workers is not None:
        raise PinSuspError(
            "--workers sizes the local cluster: a scheduler has its own workers, and "
            "--scheduler none runs in this process"
        )
    if args.output.strip() == "":
        raise PinSuspError("the output directory's path is empty: give -o OUTDIR")
    study = studies.load_study(args.study)
    out = Path(args.output)
    started = time.perf_counter()
    total = len(studies.batches(study))
    label = "starts" if study.kind == "optimise" else "batches"
    try:
        outcome = studies.run_study(
            study,
            out,
            scheduler=scheduler,
            workers=args.workers,
            steps=args.steps,
            resume=args.resume,
            progress=_progress_bar(total, args.quiet, minimum=1, label=label),
            announce=None if args.quiet else print,
            warn=lambda text: args.quiet or print(f"pin-susp: warning: {text}", file=sys.stderr),
        )
    except (KeyboardInterrupt, _Terminated) as exc:
        signal_number = exc.signal if isinstance(exc, _Terminated) else signal.SIGINT
        kept = studies.finished_batches(out)
        if kept is None:
            print("pin-susp: interrupted, nothing written", file=sys.stderr)
        else:
            bar = not args.quiet and sys.stderr.isatty()  # end the progress bar's line
            print(
                f"{chr(10) if bar else ''}pin-susp: interrupted: {kept} of {total} batches "
                f"are kept in {out}; "
                "the same command with --resume solves the rest",
                file=sys.stderr,
            )
        return 128 + signal_number
    seconds = time.perf_counter() - started
    variants = outcome.variants
    written = [out / "variants.parquet"]
    written += [out / "steps.parquet"] if (out / "steps.parquet").exists() else []
    written += [p for p in (outcome.best, outcome.figure) if p is not None]
    if outcome.figure is None:
        print(f"pin-susp: no variant converged: {out / 'study.png'} not drawn", file=sys.stderr)
    if not args.quiet:
        for line in outcome.lines:
            print(line)
        resumed = outcome.batches - outcome.computed
        rate = len(variants) / seconds if not resumed and study.kind != "optimise" else None
        timing = f" in {seconds:.1f} s" + (f" ({rate:.0f} variants/s)" if rate else "")
        if resumed:
            timing += f"; {resumed} of {outcome.batches} batches were already done"
        print(f"solved{timing}")
        for path in written:
            print(f"wrote {path}")
    return EXIT_NOT_CONVERGED if not variants["converged"].all() else 0


if __name__ == "__main__":
    sys.exit(main())
