"""`pin-susp clearance`: along a sweep, the distance from each corner's rim and tyre to
its links and the geometry file's ``clearance:`` bodies, with coal (docs/clearance.md);
a table written atomically, its summary printed, and a replay with --view."""

from __future__ import annotations

import sys

from ..options import check_outputs, count, geometry_argument, positive
from ..report import progress_bar, report_failures, report_limits

DESCRIPTION = (
    "Solve SWEEP on GEOMETRY (a corner, an axle or a vehicle) and measure, at every step, "
    "the signed distance (mm, negative: overlap) from each wheel's rim and tyre to the drawn "
    "links (capsules) and to the bodies of the file's clearance: key (meshes, boxes, tubes on "
    "the chassis), with coal; write one row per step and pair with both closest points, and "
    "print the closest pair and its step. An overlap is a warning (exit 0); exit 1 if a step "
    "did not converge."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument("sweep", metavar="SWEEP", help="sweep YAML (e.g. a bump × steer grid)")
    parser.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUT.csv",
        help="clearance table (Parquet: OUT.parquet)",
    )
    parser.add_argument(
        "--view", metavar="OUT.html", help="also a replay: each step's closest pair drawn red"
    )
    parser.add_argument("--fps", type=positive, default=10.0, help="replay frames per second")
    parser.add_argument("--top", type=count, default=5, help="closest pairs listed (default 5)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")


def run(args) -> int:
    check_outputs(args, args.output, args.view)
    from ...analyses.clearance import sweep_clearance
    from ...io.atomic import all_or_none, write_text
    from ...model.clearance_bodies import load_clearance
    from ...model.sweep import load_sweep
    from ...subjects.subject import load_subject

    subject = load_subject(args.geometry)
    bodies = load_clearance(args.geometry)
    sweep = load_sweep(args.sweep)
    subject.check_sweep(sweep)  # target errors before any work
    results = subject.run_sweep(sweep, progress=progress_bar(sweep.steps, args.quiet))
    measured = sweep_clearance(subject, sweep, results, bodies)
    page = None
    if args.view is not None:
        from ...viz.clearance_view import clearance_replay

        page = clearance_replay(subject, results, measured, bodies, args.fps)
    with all_or_none():
        write_table(measured, args.output, args.geometry, args.sweep)
        if page is not None:
            write_text(page, args.view)
    if not args.quiet:
        print("\n".join(measured.summary(args.top)))
        print(f"wrote {args.output} ({measured.distance.size} rows)")
        if page is not None:
            print(f"wrote {args.view}")
    pairs, steps, both = measured.overlaps()
    if both:
        print(
            f"pin-susp: warning: {pairs} pairs overlap at {steps} steps (distance < 0 in "
            f"{args.output})",
            file=sys.stderr,
        )
    return max(report_failures(results, "have no clearance (blank cells)"), report_limits(results))


def write_table(measured, path, geometry, sweep) -> None:
    """The table as CSV (``#`` comment lines, then a header) or Parquet, atomically."""
    from ... import __version__
    from ...io.atomic import atomic_write
    from ...io.tables import is_parquet

    frame = measured.table()
    if is_parquet(path):
        with atomic_write(path, binary=True) as f:
            frame.to_parquet(f, index=False)
        return
    head = (
        f"# pin_susp {__version__} clearance of {geometry} over {sweep}\n"
        "# distance: mm, negative where the shapes overlap; wheel_x..body_z: the closest "
        "points on the wheel's part and on the body, mm, world axes (ISO 8855)\n"
    )
    with atomic_write(path) as f:
        f.write(head)
        frame.to_csv(f, index=False, na_rep="", float_format="%.6f", lineterminator="\n")
