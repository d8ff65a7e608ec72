"""`pin-susp attitude`: a vehicle's quasi-static attitude under steady accelerations
(docs/vehicle.md, "Attitude"): the body's heave, pitch and roll, the wheel loads, the
lateral load transfer per axle and the TLLTD at each (ax, ay), one row each, with the
vehicle sweep's columns at that pose; the gradients and the ride frequencies; with
--plot, the g-g plot."""

from __future__ import annotations

import sys

from ..options import check_image, check_outputs, geometry_argument, output_arguments, output_form
from ..report import progress_bar

DESCRIPTION = (
    "Find the body's heave, pitch and roll at which the springs, the anti-roll bars and "
    "the tyres hold VEHICLE (scope: vehicle) under each steady acceleration of ACCEL "
    "(ax, ay in g), and write one row per acceleration: the wheel loads, the lateral load "
    "transfer per axle (elastic, geometric, unsprung), the TLLTD, the roll and pitch "
    "gradients, the ride frequencies and every column of a vehicle sweep at that pose "
    "(camber to ground, roll centres, ...). Exit code 1 if an acceleration has no "
    "equilibrium on four wheels (its row is flagged)."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument(
        "accelerations",
        metavar="ACCEL",
        help="accelerations YAML: a list of {ax, ay} in g, or a grid (docs/vehicle.md)",
    )
    parser.add_argument(
        "-o", "--output", required=True, metavar="OUT.csv", help="attitude CSV (Parquet: .parquet)"
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    parser.add_argument(
        "--plot",
        metavar="OUT.png",
        help="also draw the g-g plot: TLLTD, roll, pitch and each corner's camber to ground",
    )
    output_arguments(parser)


def run(args) -> int:
    from ...errors import InputError

    args.sweep = args.accelerations  # an input: never an output
    check_outputs(args, args.output, args.plot)
    if args.plot is not None:
        check_image(args.plot)
    from ...analyses.attitude import Attitude, load_accelerations
    from ...subjects.subject import load_subject, subject_class

    kind = subject_class(args.geometry)
    if not kind.on_road:
        raise InputError(
            str(args.geometry),
            "scope",
            f"attitude takes a vehicle (scope: vehicle): {article(kind.noun)} has no body on "
            "the road",
        )
    car = load_subject(args.geometry)
    accelerations = load_accelerations(args.accelerations)
    attitude = Attitude(car)  # its inputs' errors (masses, spring rates) before any work
    bar = progress_bar(len(accelerations), args.quiet, label="attitude")
    results = attitude.run(accelerations, progress=bar)
    _write(args, results, car.name)
    if not args.quiet:
        _summary(args, results)
    return _failures(results)


def article(noun: str) -> str:
    """The noun with its indefinite article: "an axle", "a corner"."""
    return f"{'an' if noun[0] in 'aeiou' else 'a'} {noun}"


def _write(args, results, name: str) -> None:
    """The CSV (Parquet for .parquet) and the g-g plot: both or neither."""
    from ...io.atomic import all_or_none
    from ...io.tables import is_parquet, write_csv

    with all_or_none():
        if is_parquet(args.output):
            from ...io.tables import write_parquet

            write_parquet(results, args.output, output_form(args))
        else:
            write_csv(results, args.output, output_form(args))
        if args.plot is not None and results["solver_converged"].any():
            from ...plots import save_figure
            from ...plots.attitude import gg_figure

            save_figure(gg_figure(results, f"{name}: attitude under acceleration"), args.plot)
    if args.plot is not None and not results["solver_converged"].any():
        print(
            f"pin-susp: no acceleration has an equilibrium: {args.plot} not drawn", file=sys.stderr
        )


ROWS = 12  # the summary's table: its first rows


def _summary(args, results) -> None:
    import numpy as np

    n = len(results)
    ok = results["solver_converged"]
    print(f"wrote {args.output}: {n} accelerations, {int(ok.sum())} in equilibrium")
    first = int(np.flatnonzero(ok)[0]) if ok.any() else None
    if first is not None:
        c = results.columns

        def pitch(name: str, given: str) -> str:  # blank without its split
            v = c[name][first]
            return f"{v:.3f} deg/g" if np.isfinite(v) else f"(blank: no {given})"

        print(
            f"  roll gradient {c['roll_gradient'][first]:.3f} deg/g, pitch gradient "
            f"{pitch('pitch_gradient_braking', 'brakes.front_bias')} braking, "
            f"{pitch('pitch_gradient_traction', 'drive')} accelerating"
        )
        line = (
            f"  ride frequency {c['ride_frequency_front'][first]:.2f} Hz front, "
            f"{c['ride_frequency_rear'][first]:.2f} Hz rear"
        )
        if "roll_frequency" in c:
            line += f", roll {c['roll_frequency'][first]:.2f} Hz"
        print(line)
    names = ("ax", "ay", "heave", "pitch", "roll", "tlltd")
    names += tuple(f"camber_to_ground_{label}" for label in ("fl", "fr", "rl", "rr"))
    heads = ("ax g", "ay g", "heave mm", "pitch", "roll", "TLLTD %", "CtG fl", "fr", "rl", "rr")
    print("  " + " ".join(f"{h:>8}" for h in heads))
    for i in range(min(n, ROWS)):
        cells = []
        for name in names:
            v = results[name][i]
            cells.append(f"{round(v, 3) + 0.0:8.3f}" if np.isfinite(v) else f"{'':>8}")
        print("  " + " ".join(cells))
    if n > ROWS:
        print(f"  ... {n - ROWS} more rows in {args.output}")
    for note in results.meta.get("notes", ()):
        print(f"  {note}")
    if args.plot is not None and ok.any():
        print(f"wrote {args.plot}")


def _failures(results) -> int:
    """Name the accelerations with no equilibrium, and why, on stderr; the exit code."""
    from ...errors import EXIT_NOT_CONVERGED

    why = results.meta["why"]
    bad = [i for i, ok in enumerate(results["solver_converged"]) if not ok]
    if not bad:
        return 0
    shown = "; ".join(
        f"ax {results['ax'][i]:g} g, ay {results['ay'][i]:g} g: {why[i]}" for i in bad[:5]
    )
    more = f"; and {len(bad) - 5} more" if len(bad) > 5 else ""
    print(
        f"pin-susp: warning: {len(bad)} of {len(results)} accelerations have no "
        f"equilibrium on four wheels ({shown}{more}). Their rows are flagged "
        "solver_converged=False with empty cells.",
        file=sys.stderr,
    )
    return EXIT_NOT_CONVERGED
