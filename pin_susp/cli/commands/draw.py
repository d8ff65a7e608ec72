"""`pin-susp draw`: front and side view of a corner at design, or an axle in front view
(at design, or at a step of its sweep results with --from-results)."""

from __future__ import annotations

import re

from ...errors import PinSuspError
from ..options import axle_model, check_image, check_outputs, geometry_argument, is_axle

DESCRIPTION = (
    "Draw GEOMETRY at its design (as-set) state in front and side view, with "
    "the instant-centre construction (ball joints to the front- and side-view instant "
    "centres, the contact patch through them, and the roll centre of a symmetric axle on "
    "the centreline); a shimmed corner shows its drawn geometry dashed. An axle "
    "(scope: axle) is drawn in front view, both corners, each contact patch through its "
    "FVIC and the roll centre where the two lines cross; --at draws it at a step of its "
    "sweep results."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument(
        "-o", "--output", required=True, metavar="OUT.png", help="image (png, pdf, svg)"
    )
    parser.add_argument(
        "--labels", action="store_true", help="name every hardpoint and add a colour legend"
    )
    parser.add_argument(
        "--at",
        metavar="RESULTS.csv:STEP",
        help="an axle: draw the pose of that step of its `pin-susp sweep` results "
        "(default: the design state)",
    )


def run(args) -> int:
    from ...corner import Corner
    from ...geometry import load_geometry
    from ...plots import ResultsFile, axle_drawing_figure, axle_pose, drawing_figure, save_figure

    check_outputs(args, args.output)
    check_image(args.output)
    if args.at is not None:
        path, _, step = args.at.rpartition(":")
        if not path or not re.fullmatch(r"[0-9]{1,9}", step):
            raise PinSuspError(f"--at {args.at}: expected RESULTS.csv:STEP, e.g. axle.csv:15")
    if is_axle(args.geometry):
        model = axle_model(args.geometry)
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
