"""`pin-susp sensitivity`: exact d(metric)/d(hardpoint coordinate) of a corner, an axle
or a vehicle, at design or along a sweep; the long-format CSV and the table of the
largest entries per metric."""

from __future__ import annotations

from ... import __version__
from ...errors import PinSuspError
from ..options import check_outputs, count, geometry_argument, output_arguments, output_form
from ..report import progress_bar, report_failures

DESCRIPTION = (
    "How much each hardpoint coordinate moves each metric and each derivative "
    "column (camber gain, bump steer, ...): exact, by implicit differentiation of the "
    "closure equations. Writes a long-format CSV (step_index, metric, hardpoint, axis, "
    "value, unit) and prints the largest entries per metric."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument(
        "--sweep", metavar="SWEEP", help="at every step of this sweep (default: the design state)"
    )
    parser.add_argument("-o", "--output", metavar="SENS.csv", help="long-format CSV")
    parser.add_argument(
        "--top",
        type=count,
        default=3,
        metavar="N",
        help="entries per metric in the printed table (default 3)",
    )
    parser.add_argument(
        "--points",
        default="designer",
        metavar="GROUP|NAMES",
        help="which hardpoints the printed table ranks: designer (default: chassis pickups "
        "and link ends, not the spindle points), chassis, upright, all, or names separated "
        "by commas (the CSV always has every hardpoint)",
    )
    parser.add_argument(
        "--one-sided",
        action="store_true",
        help="an axle: move each side's point alone (hardpoints left_P, right_P); default "
        "a symmetric move, the left P by (dx, dy, dz) and the right P by (dx, -dy, dz); a "
        "vehicle: each corner's alone (fl_P, ...), default each axle's mirrored (front_P, "
        "rear_P)",
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
    output_arguments(parser)  # the CSV's; the printed table is ISO, mm


def run(args) -> int:
    """Each labelled corner's columns (an axle's suffixed _left, _right) and the subject's
    own of its corners together (an axle's track, roll centre, roll rates); an axle's
    points moved symmetrically on both sides, or one side alone (--one-sided)."""
    from ...analyses.sensitivity import (
        ONE_SIDED_MOVE,
        SYMMETRIC_MOVE,
        SubjectSensitivity,
        subject_sensitivities,
    )
    from ...model.sweep import load_sweep
    from ...subjects.subject import load_subject, subject_class

    check_outputs(args, args.output)
    # a labelled corner's points move alone; a corner's one, unlabelled, has no other
    if args.one_sided and not any(subject_class(args.geometry).labels):
        raise PinSuspError("--one-sided: a corner has one side (it moves one side of an axle)")
    model = load_subject(args.geometry)
    if model.anti_roll_rigid:
        raise PinSuspError(
            f"{args.geometry}: sensitivity: not for an axle with a rigid anti-roll bar yet "
            "(each wheel's height is held, which a rigid bar does not allow)"
        )
    named = tuple(  # a point named with its side, corner or axle (left_P, fl_P, front_P)
        p for s in model.labels for one in (False, True) if (p := model.sensitivity_move(s, one)[0])
    )
    own = [
        n
        for n in (args.points or "").split(",")
        if n.strip() in model.element_points or n.strip().startswith((*model.blocks, *named))
    ]
    if own:
        raise PinSuspError(
            f"--points: {own[0].strip()} — the sensitivities of the anti-roll bar's and heave "
            "link's points (and of side-prefixed names) are not computed yet: give the "
            "corners' hardpoints (both sides move together; --one-sided for one side)"
        )
    sens = SubjectSensitivity(model, args.one_sided)
    points = _points(sens, args.points)
    sweep = None
    if args.sweep is not None:
        sweep = load_sweep(args.sweep)
        model.check_sweep(sweep)
    progress = progress_bar(sweep.steps if sweep else 1, args.quiet)
    states, results = subject_sensitivities(sens, sweep, progress)
    held = model.sensitivity_held()
    move = model.sensitivity_move_text(args.one_sided)
    if move is None:
        move = ONE_SIDED_MOVE if args.one_sided else SYMMETRIC_MOVE
    notes = [f"exact; {held}; {move}"] if held else []
    if any(g.drawn is not None for g in model.corners.values()):
        adjusted = "shims and adjusters" if model.blocks else "shim and adjusters"
        notes.append(f"(with respect to the as-set hardpoints: {adjusted} applied)")
    groups = model.sensitivity_groups(list(states[0].values) if states else [])
    head = (f"hardpoint: {move}", held) if held else ()
    return _sensitivity_report(args, model, sweep, states, results, points, groups, notes, head)


def _points(sens, spec: str) -> list[str]:
    """The hardpoints the table ranks, as the subject's directions name them: each
    corner's chosen points (a group, or names that corner has: a vehicle's rear has
    toe links, its front trackrods); an unknown name said once, for the first corner."""
    from ...analyses.sensitivity import select_points
    from ...errors import InputError

    chosen, errors = [], []
    for label, side in sens.sides.items():
        try:
            chosen += [sens.name_of(label, p) for p in select_points(side.corner, spec)]
        except InputError as exc:
            errors.append(exc)
    if len(errors) == len(sens.sides):
        raise errors[0]
    return list(dict.fromkeys(chosen))


def _sensitivity_report(
    args, geometry, sweep, states, results, points, groups, notes=(), csv_notes=()
) -> int:
    """The CSV (``csv_notes`` in its head), the steps without sensitivities, and the
    printed table: a title, ``notes``, then per group (heading, columns) the largest
    entries among ``points``. The exit code."""
    from ...analyses.sensitivity import POINT_GROUPS

    if args.output is not None:
        _sensitivity_csv(states, geometry.source, args.output, csv_notes, output_form(args))
    status = 0 if results is None else report_failures(results, "have no sensitivities")
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

    from ...analyses.sensitivity import STEP, largest

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


def _sensitivity_csv(states, source: str, path, notes=(), form=None) -> None:
    """The long-format CSV; ``form``: its convention and units (io.conventions): a
    value's sign is the metric's times its coordinate's axis', d(metric)/d(coordinate)
    read as the derivative column ``deriv_<metric>_wrt_<axis>``."""
    from ...io.atomic import atomic_write
    from ...io.conventions import ISO_MM
    from ...io.tables import format_cell

    form = form or ISO_MM
    per = form.unit("mm")
    with atomic_write(path) as f:
        f.write(f"# pin_susp {__version__} hardpoint sensitivities of {source}\n")
        f.write(f"# value = d(metric)/d(hardpoint coordinate), per {per} of the coordinate\n")
        if form.header():
            f.write(form.header() + "\n")
        f.writelines(f"# {note}\n" for note in notes)
        f.write("step_index,metric,hardpoint,axis,value,unit\n")
        for s in states:
            for name, values in s.values.items():
                unit = form.unit(s.units[name])
                for i, hardpoint in enumerate(s.hardpoints):
                    for a, axis in enumerate("xyz"):
                        as_column = f"deriv_{name}_wrt_{axis}"  # its sign: metric's · axis'
                        value = form.values(as_column, values[i, a], s.units[name])
                        f.write(f"{s.step},{name},{hardpoint},{axis},{format_cell(value)},{unit}\n")
