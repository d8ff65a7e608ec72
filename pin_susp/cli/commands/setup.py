"""`pin-susp setup`: the setup sheet of a corner, an axle or a vehicle (static metrics
with the camber shim and length adjusters applied, a row per listed value; a vehicle's
per corner), exact sensitivities to the adjusters, and the inverse solve to target
camber, toe and ride height."""

from __future__ import annotations

from ... import __version__
from ...errors import PinSuspError
from ..options import (
    check_outputs,
    finite,
    geometry_argument,
    numbers,
    output_arguments,
    output_form,
    positive,
)
from ..report import wrote

DESCRIPTION = (
    "Print the static metrics of GEOMETRY as set (camber shim and length "
    "adjusters applied). List values to see one row each; ask for exact sensitivities; "
    "or give target values to find the shim, trackrod and pushrod settings that hit them."
)


EPILOG = (
    "Example: pin-susp setup examples/camber_shim.yaml --shim 15,20,25,30 "
    "--sensitivities; pin-susp setup examples/camber_shim.yaml --camber -2.5 --toe 0.1 "
    "-o set.yaml"
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument(
        "--shim",
        type=numbers,
        default=[],
        metavar="MM,MM,...",
        help="fitted shim stack thicknesses, one row each",
    )
    parser.add_argument(
        "--trackrod",
        type=numbers,
        default=[],
        metavar="MM,MM,...",
        help="trackrod (or fixed toe link) length changes (+ longer), one row each; "
        "negative values as written: --trackrod -1,0,1",
    )
    parser.add_argument(
        "--pushrod",
        type=numbers,
        default=[],
        metavar="MM,MM,...",
        help="pushrod length changes (+ longer), one row each",
    )
    parser.add_argument(
        "--sensitivities",
        action="store_true",
        help="exact d(camber, toe, ride height)/d(shim, trackrod, pushrod)",
    )
    parser.add_argument(
        "--thread-pitch",
        type=positive,
        metavar="MM",
        help="also give sensitivities per turn of an adjuster with this pitch "
        "(length change per turn; a left/right-hand turnbuckle: twice the pitch)",
    )
    parser.add_argument("--camber", type=finite, metavar="DEG", help="target static camber (shim)")
    parser.add_argument(
        "--toe",
        type=finite,
        metavar="DEG",
        help="target static roadwheel angle, + toe-in (trackrod)",
    )
    parser.add_argument(
        "--ride-height-change",
        type=finite,
        metavar="MM",
        help="target ride-height change, + car higher (pushrod)",
    )
    parser.add_argument(
        "-o",
        "--output",
        metavar="SET.yaml",
        help="with targets: write the geometry with the setup found (a vehicle's: the "
        "vehicle file, with each axle file set beside it, SET_front.yaml)",
    )
    parser.add_argument("--csv", metavar="OUT.csv", help="also write the sheet's rows as CSV")
    parser.add_argument(
        "--side",
        choices=("left", "right", "fl", "fr", "rl", "rr", "front", "rear"),
        help="an axle with its own right points: listed values and targets set this side "
        "alone (default: both sides; a mirrored axle has one setup for both); a vehicle: "
        "one corner (fl, fr, rl, rr: its axle with its own right points) or one axle "
        "(front, rear)",
    )
    output_arguments(parser)  # the --csv sheet's; targets and -o SET.yaml stay ISO, mm


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


def run(args) -> int:
    import numpy as np

    from ...analyses import setup
    from ...io.atomic import all_or_none
    from ...subjects.subject import load_drawn

    check_outputs(args, args.output, args.csv)
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
    # each corner's sheet as a corner's (its own shim and adjusters), the subject's own
    # static columns of its corners together (an axle's), or the inverse solve per corner;
    # the subject as drawn: its setup is the sheet's to apply and to report
    subject = load_drawn(args.geometry, args.side)
    chosen = subject.setup_labels(args.side)
    drawn = subject.drawn_corners
    links = {s: _link(drawn[s]) for s in subject.labels}  # a vehicle's: trackrod, toe link
    link = links[subject.labels[0]] if len(set(links.values())) == 1 else "trackrod or toe link"
    if targets:
        found = setup.solve_subject_setup(subject, targets, args.side)
        rows = {s: [found[s].before, found[s].after] for s in subject.labels}
        labels = {s: ["before", "after"] for s in subject.labels}
    else:
        rows = setup.subject_setup_sheet(subject, args.shim, args.trackrod, args.pushrod, args.side)
        labels = {s: _sheet_labels(args, links[s]) for s in subject.labels}
    longest = max(labels.values(), key=len)
    # the subject's columns per row: its corners as set in that row (one not set: as set)
    statics = [
        setup.static_state(subject, {s: rows[s][min(i, len(rows[s]) - 1)] for s in rows})
        for i in range(len(longest))
    ]
    per = f" per {subject.setup_unit}" if subject.blocks else ""
    print(f"{subject.name}: setup sheet{per} ({subject.source})")
    for s in subject.labels:
        owner = subject.setup_owner(s)
        if owner != s:
            print(
                f"  {s} corner (the {owner} mirrored: it takes the {owner}'s setup, the same "
                "shim stack and length deltas):"
            )
        elif s:
            setting = "" if s in chosen else f"; not set: --side {args.side}"
            print(f"  {s} corner ({subject.setup_place(s)}{setting}):")
        _sheet(rows[s], labels[s][: len(rows[s])], links[s])
        _ride_height(drawn[s])
        if targets and (found[s].iterations or not s):  # a corner not set: no hit
            _hit(targets, found[s].iterations)
        if args.sensitivities and not targets:
            _sensitivities(rows[s][0], drawn[s], args.thread_pitch)
    columns = subject.static_columns
    if columns:
        print(f"  {subject.static_heading}:")
        print(f"  {'':9}" + "".join(f"{head:>12}" for _, head in columns))
        print(f"  {'':9}" + "".join(f"{'mm':>12}" for _ in columns))
        for label, row in zip(longest, statics, strict=True):
            cells = (round(row[name], 3) + 0.0 for name, _ in columns)
            print(
                f"  {label:9}"
                + "".join(f"{v:>12.3f}" if np.isfinite(v) else f"{'-':>12}" for v in cells)
            )
    written = []
    if args.output is not None:  # the subject's file (a vehicle's axle files beside it)
        written = subject.setup_files({s: found[s].geometry for s in chosen}, args.output)
        check_outputs(args, *(path for path, _ in written[1:]), args.csv)
    with all_or_none():
        for path, data in written:
            _write_setup(data, subject.name, path)
        if args.csv is not None:
            rows_of = [(s, i) for s in subject.labels for i in range(len(rows[s]))]
            _sheet_csv(
                [rows[s][i] for s, i in rows_of],
                [" ".join(filter(None, (s, labels[s][i]))) for s, i in rows_of],
                args.csv,
                link,
                [statics[i] for _, i in rows_of],
                output_form(args),
            )
    wrote(*(path for path, _ in written), args.csv)
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

    from ...io.atomic import write_text

    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
    write_text(f"# {name}: setup solved by pin-susp setup\n" + text, path)


def _ride_height(geometry) -> None:
    """The design ride height where the tyre is given by its loaded radius (docs/geometry.md,
    "The wheel by its centre"): the wheel centre's height above the road at design."""
    if geometry.wheel.loaded_radius is not None:
        print(
            f"  design ride height {geometry.design_ride_height * 1e3:.3f} mm: the wheel "
            f"centre above the road on the tyre's loaded radius "
            f"({geometry.wheel.loaded_radius * 1e3:g} mm)"
        )


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


def _sheet_csv(rows, labels, path, link: str = "trackrod", extra=None, form=None) -> None:
    """The sheet's rows; ``extra``: per row, more columns (name → value, mm), e.g. an
    axle's track and roll centre; ``form``: the convention and units (io.conventions)."""
    from ...io.atomic import atomic_write
    from ...io.conventions import ISO_MM
    from ...io.tables import format_cell

    form = form or ISO_MM
    setup_columns = [c.replace("trackrod", link.replace(" ", "_")) for c in SETUP_COLUMNS]
    names = ["row", *setup_columns] + [name for name, _, _ in SHEET_METRICS]
    extra = extra or [{}] * len(rows)
    units = dict.fromkeys(setup_columns, "mm") | {n: u for n, u, _ in SHEET_METRICS}
    units |= dict.fromkeys(extra[0], "mm")

    def cell(name, value) -> str:
        return format_cell(form.values(name, value, units[name]))

    lengths = form.unit("mm")
    with atomic_write(path) as f:
        f.write(f"# pin_susp {__version__} setup sheet; lengths {lengths}, angles deg\n")
        if form.header():
            f.write(form.header() + "\n")
        f.write(",".join(names + list(extra[0])) + "\n")
        for label, row, more in zip(labels, rows, extra, strict=True):
            cells = [label, *(cell(n, v) for n, v in zip(setup_columns, row.setup, strict=True))]
            cells += [cell(name, row.metrics[name]) for name, _, _ in SHEET_METRICS]
            cells += [cell(n, v) for n, v in more.items()]
            f.write(",".join(cells) + "\n")
