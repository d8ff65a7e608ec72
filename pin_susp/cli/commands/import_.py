"""`pin-susp import`: another tool's hardpoint file as a pin_susp geometry — a Lotus
SHARK .shk, an OptimumK table (CSV or Excel), an Adams/Car property file
(docs/interop.md). The command is `import`; the module's name has an underscore
because `import` is a Python keyword."""

from __future__ import annotations

import re
from pathlib import Path

from ...errors import PinSuspError

DESCRIPTION = (
    "Read FILE — a Lotus SHARK .shk, an OptimumK hardpoint table (.csv, .xlsx) or an "
    "Adams/Car property file (hpl_/hpr_ hardpoints) — and write its corner as a pin_susp "
    "geometry YAML: axes to ISO 8855, lengths to mm, the side chosen. It prints each of "
    "the file's points as used (as which pin_susp point) or ignored (why), and every "
    "default it took; what the file does not carry (tyre, wheel offset, choices) comes "
    "from the options or from --template."
)
SUFFIXES = {".shk": "shk", ".csv": "optimumk", ".xlsx": "optimumk", ".xlsm": "optimumk"}
ADAMS = (".sub", ".tpl", ".asy", ".dat", ".txt", ".hpt")


def arguments(parser) -> None:
    from ..options import finite

    parser.add_argument("source", metavar="FILE", help="the other tool's file")
    parser.add_argument(
        "-o", "--output", required=True, metavar="OUT.yaml", help="geometry to write"
    )
    parser.add_argument(
        "--format",
        choices=("shk", "optimumk", "adams"),
        help="FILE's format (default from its suffix: .shk; .csv/.xlsx OptimumK; "
        ".sub/.tpl/.asy/.dat/.txt/.hpt Adams/Car)",
    )
    parser.add_argument(
        "--template",
        metavar="GEOMETRY",
        help="a pin_susp geometry whose config (tyre, offset, steering, rates ...), "
        "actuation, spring and side are kept; only the hardpoints come from FILE",
    )
    parser.add_argument(
        "--side", choices=("left", "right"), help="the corner to write (default: FILE's side)"
    )
    parser.add_argument(
        "--tyre", metavar="205/55R16", help="tyre size: section mm / aspect %% R rim in"
    )
    parser.add_argument(
        "--offset", type=finite, metavar="MM", help="wheel offset ET, mm (default 0, said)"
    )
    parser.add_argument(
        "--steering", choices=("rack", "none"), help="trackrod on a rack, or a fixed toe link"
    )
    parser.add_argument(
        "--type",
        dest="kind",
        choices=("double_wishbone", "macpherson"),
        help="mechanism (OptimumK, Adams)",
    )
    parser.add_argument(
        "--camber",
        type=finite,
        metavar="DEG",
        help="static camber (ISO: + top outboard) where FILE has no spindle point",
    )
    parser.add_argument(
        "--toe",
        type=finite,
        metavar="DEG",
        help="static toe (+ toe-in) where FILE has no spindle point",
    )
    parser.add_argument(
        "--axes",
        metavar="X,Y,Z",
        help="OptimumK: where the table's X, Y, Z point (default forward,left,up: ISO "
        "8855; e.g. rearward,right,up)",
    )
    parser.add_argument(
        "--units",
        choices=("mm", "m", "in"),
        help="OptimumK: the table's length unit, where its headers name none",
    )
    parser.add_argument(
        "--map",
        action="append",
        default=[],
        metavar="NAME=POINT",
        help="OptimumK: read the row NAME as the pin_susp point POINT (repeatable)",
    )
    parser.add_argument("--name", help="the geometry's name (default: FILE's)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print only what was written")


def run(args) -> int:
    from ...interop import reader
    from ...interop.corner import Wanted, build, parse_tyre, yaml_text
    from ...interop.optimumk import parse_axes
    from ...io.atomic import check_output, write_text

    check_output(args.output)
    for given in (args.source, args.template):
        if given is not None and Path(given).exists() and Path(args.output).exists():
            if Path(given).samefile(args.output):
                raise PinSuspError(
                    f"{args.output}: is an input of this command: writing it would lose it"
                )
    fmt = args.format or _format(args.source)
    _refuse_options(args, fmt)
    try:
        args.axes_given = args.axes is not None
        args.axes_text = args.axes or "forward,left,up"
        args.axes = parse_axes(args.axes_text)
        tyre = None if args.tyre is None else parse_tyre(args.tyre)
    except ValueError as exc:
        raise PinSuspError(f"--{'tyre' if 'tyre' in str(exc) else 'axes'}: {exc}") from None
    args.map = dict(_pair(m) for m in args.map)
    try:
        raw = Path(args.source).read_bytes()
    except OSError as exc:
        raise PinSuspError(f"{args.source}: cannot read it ({exc.strerror})") from None
    module = reader(fmt)
    if fmt == "optimumk":
        src = module.read(args.source, raw, args)
    else:
        src = module.read(args.source, _text(args.source, raw, fmt), args)
    want = Wanted(
        template=args.template,
        side=args.side,
        tyre=tyre,
        offset=args.offset,
        steering=args.steering,
        kind=args.kind,
        camber=args.camber,
        toe=args.toe,
        name=args.name,
    )
    data, report = build(src, want)
    write_text(yaml_text(data, report), args.output)
    if not args.quiet:
        print("\n".join(report))
    print(f"wrote {args.output}")
    return 0


# why --units, --axes and --map are an OptimumK table's only: the other formats say
# their units, axes and point names themselves
NAMED = {
    "shk": "a Lotus .shk (mm, Lotus axes, Lotus names)",
    "adams": "an Adams/Car file (its [UNITS] block, Adams axes, Adams names)",
}


def _refuse_options(args, fmt: str) -> None:
    """An option FILE's format does not take is refused, naming it; a static camber
    or toe beyond ±45° too (as a wheel by its centre, docs/geometry.md)."""
    from ...interop.corner import angle_problem

    for what in ("camber", "toe"):
        value = getattr(args, what)
        problem = None if value is None else angle_problem(value)
        if problem:
            raise PinSuspError(f"--{what} {value:g}: {problem}")
    if fmt == "optimumk":
        return
    given = [
        flag
        for flag, value in (("--units", args.units), ("--axes", args.axes), ("--map", args.map))
        if value
    ]
    if given:
        raise PinSuspError(
            f"{given[0]}: {args.source} is {NAMED[fmt]}: {given[0]} is for an OptimumK table"
        )


def _text(path: str, raw: bytes, fmt: str) -> str:
    """FILE's text (UTF-8, else Latin-1); a file of binary data is refused."""
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    if not text.strip():
        raise PinSuspError(f"{path}: the file is empty")
    if re.search(r"[\x00-\x08\x0b\x0e-\x19\x1b-\x1f\x7f]", text):
        what = "a Lotus .shk" if fmt == "shk" else "an Adams/Car property file"
        raise PinSuspError(f"{path}: not a text file (binary data): {what} is text")
    return text


def _format(path: str) -> str:
    suffix = Path(path).suffix.lower()
    if suffix in SUFFIXES:
        return SUFFIXES[suffix]
    if suffix in ADAMS:
        return "adams"
    raise PinSuspError(f"{path}: which format? give --format shk|optimumk|adams")


def _pair(text: str) -> tuple[str, str]:
    name, eq, point = text.rpartition("=")
    if not eq or not name.strip() or not point.strip():
        raise PinSuspError(
            f"--map {text}: expected NAME=POINT, e.g. 'LCA Front=lower_wishbone_inboard_front'"
        )
    from ...interop.optimumk import NAMES

    known = (*NAMES, "axle_inboard", "axle_outboard")
    if point.strip() not in known:
        raise PinSuspError(
            f"--map {text}: {point.strip()!r} is not a pin_susp point (one of {', '.join(known)})"
        )
    return name.strip(), point.strip()
