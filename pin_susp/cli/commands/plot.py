"""`pin-susp plot`: the standard kinematics report (a corner's, an axle's, a vehicle's or
a forces report) from one or more results files."""

from __future__ import annotations

from ..options import check_image, check_outputs

DESCRIPTION = (
    "Camber, toe, caster, KPI, scrub, trail, half track (and instant-centre "
    "heights, anti geometry, rocker, motion ratio, spring force, wheel and ride rate, "
    "camber gain and bump steer where present) against wheel travel, or rack travel from "
    "centre for a steer sweep; a sweep that moved both (bump + steer) against the step, "
    "its inputs drawn as the first panels. Several CSVs compare designs, a colour per "
    "file (of the same kind of sweep: a bump and a steer sweep cannot share one figure). "
    "An axle's CSV gives the axle report: camber (to the chassis and to the ground), toe, "
    "steer angle, roll centre, bar twist, IC heights, rates, per side, against roll, "
    "heave or rack (the step when several moved), and Ackermann against the mean steer "
    "angle. A vehicle's CSV gives the vehicle report: each corner's camber to ground, "
    "camber, toe and wheel travel (the front solid, the rear dashed, left and right a colour "
    "each), each axle's roll centre, track, bar twist and roll stiffness, the roll axis, "
    "the pitch centre, the anti % and the wheelbase, against heave, pitch, roll, steering "
    "or a road height (warp), the step when several moved. A forces CSV (pin-susp loads) "
    "gives the force report: each member's force and each joint's load, a line per load "
    "case, a toggle's steps left as gaps. A column "
    "that varies less than its unit's smallest span (0.5 mm, 0.05 deg, ...) is drawn "
    "flat, and labelled when constant."
)


def arguments(parser) -> None:
    parser.add_argument(
        "results", nargs="+", metavar="RESULTS.csv", help="pin-susp sweep (or loads) output"
    )
    parser.add_argument(
        "-o", "--output", required=True, metavar="OUT.png", help="image (png, pdf, svg)"
    )


def run(args) -> int:
    from ...plots import ResultsFile, report_figure, save_figure

    check_outputs(args, args.output)
    check_image(args.output)
    files = [ResultsFile(path) for path in args.results]
    save_figure(report_figure(files), args.output)
    print(f"wrote {args.output}")
    return 0
