"""`pin-susp export`: a corner's hardpoints in another tool's layout — a Lotus SHARK
.shk or an OptimumK table (CSV, or Excel for an .xlsx name) (docs/interop.md)."""

from __future__ import annotations

from pathlib import Path

from ..options import check_outputs, geometry_argument

# the suffixes each layout is written to (.xlsx: an Excel workbook, else CSV text)
SUFFIXES = {"shk": (".shk",), "optimumk": (".csv", ".xlsx")}

DESCRIPTION = (
    "Write the hardpoints of GEOMETRY (a double wishbone or MacPherson corner) as a Lotus "
    "SHARK .shk point file or an OptimumK hardpoint table, with its wheel centre and "
    "spindle point; `pin-susp import` reads either back to the same corner (with "
    "--template GEOMETRY for what those files do not carry)."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument("--format", required=True, choices=("shk", "optimumk"), help="the layout")
    parser.add_argument(
        "-o", "--output", required=True, metavar="FILE", help="file to write (.shk; .csv or .xlsx)"
    )
    parser.add_argument(
        "--axes",
        default="forward,left,up",
        metavar="X,Y,Z",
        help="optimumk: where the table's X, Y, Z point (default forward,left,up: ISO 8855)",
    )


def run(args) -> int:
    from ...errors import PinSuspError
    from ...interop import reader
    from ...interop.corner import corner_points
    from ...interop.optimumk import parse_axes
    from ...io.atomic import atomic_write
    from ...model.geometry import load_geometry

    suffix = Path(args.output).suffix.lower()
    if suffix not in SUFFIXES[args.format]:
        raise PinSuspError(
            f"{args.output}: --format {args.format} writes {' or '.join(SUFFIXES[args.format])}"
            f" files, not {suffix or 'a name without a suffix'}: name the output "
            f"FILE{SUFFIXES[args.format][0]}"
        )
    check_outputs(args, args.output)
    try:
        axes = parse_axes(args.axes)
    except ValueError as exc:
        raise PinSuspError(f"--axes: {exc}") from None
    g = load_geometry(args.geometry)
    points = corner_points(g)
    module = reader(args.format)
    out = (
        module.write(g, points)
        if args.format == "shk"
        else module.write(g, points, args.output, axes)
    )
    with atomic_write(args.output, binary=isinstance(out, bytes)) as f:
        f.write(out)
    print(f"wrote {args.output}")
    return 0
