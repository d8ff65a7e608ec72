"""`pin-susp draw`: front and side view of a corner at design, or an axle in front view
(at design, or at a step of its sweep results with --from-results RESULTS.csv:STEP), or
a whole car at design (its side view with the pitch centre, each axle's front view).

`--at` names a step of a sweep YAML across the CLI (`urdf --at SWEEP.yaml:STEP`);
draw's old `--at RESULTS.csv:STEP` still works, hidden from --help, with a one-line
note of its new name after the drawing is written; given a sweep YAML it is refused
(draw reads a solved step, it does not solve a sweep)."""

from __future__ import annotations

import argparse
import re
import sys

from ...errors import PinSuspError
from ..options import check_image, check_outputs, geometry_argument

DESCRIPTION = (
    "Draw GEOMETRY at its design (as-set) state in front and side view, with "
    "the instant-centre construction (ball joints to the front- and side-view instant "
    "centres, the contact patch through them, and the roll centre of a symmetric axle on "
    "the centreline); a shimmed corner shows its drawn geometry dashed. An axle "
    "(scope: axle) is drawn in front view, both corners, each contact patch through its "
    "FVIC and the roll centre where the two lines cross; --from-results draws it at a "
    "step of its sweep results. A vehicle (scope: vehicle) is drawn at design in side "
    "view, each axle's contact patch through its SVIC to the pitch centre where the two "
    "lines meet, over each axle's front view."
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
        "--from-results",
        metavar="RESULTS.csv:STEP",
        help="an axle: draw the pose of that step of its `pin-susp sweep` results "
        "(default: the design state)",
    )
    # the old spelling, before --at meant a sweep's step everywhere (urdf --at SWEEP:STEP)
    parser.add_argument("--at", metavar="RESULTS.csv:STEP", help=argparse.SUPPRESS)


RENAMED = (
    "draw --at RESULTS.csv:STEP is now --from-results RESULTS.csv:STEP "
    "(--at names a step of a sweep YAML, as in urdf --at SWEEP.yaml:STEP)"
)


def _step(args) -> tuple[str, str | None]:
    """The option given (as typed: its errors name it) and its RESULTS.csv:STEP."""
    if args.at is None:
        return "--from-results", args.from_results
    if args.from_results is not None:
        raise PinSuspError("--at and --from-results: give one (--at is its old name)")
    if args.at.rpartition(":")[0].lower().endswith((".yaml", ".yml")):
        raise PinSuspError(
            f"--at {args.at}: draw does not solve a sweep: draw a step of its results, "
            "--from-results RESULTS.csv:STEP (pin-susp sweep writes them)"
        )
    return "--at", args.at


def run(args) -> int:
    from ...plots import ResultsFile, save_figure
    from ...subjects.subject import load_subject, subject_class
    from ...viz.drawing import subject_figure

    check_outputs(args, args.output)
    check_image(args.output)
    option, at = _step(args)
    if at is not None:
        path, _, step = at.rpartition(":")
        if not path or not re.fullmatch(r"[0-9]{1,9}", step):
            raise PinSuspError(f"{option} {at}: expected RESULTS.csv:STEP, e.g. axle.csv:15")
        kind = subject_class(args.geometry)
        if not kind.drawn_at_steps:  # before the file is read
            raise PinSuspError(
                f"{option}: {args.geometry} is a {kind.noun}, drawn at its design state only"
            )
    subject = load_subject(args.geometry)
    pose = None if at is None else (ResultsFile(path), int(step))
    figure = subject_figure(subject, labels=args.labels, at=pose)
    save_figure(figure, args.output)
    print(f"wrote {args.output}")
    if option == "--at":
        print(f"pin-susp: warning: {RENAMED}", file=sys.stderr)
    return 0
