"""`pin-susp validate`: a sweep re-solved by a point-based solver and by MuJoCo and/or
Drake, every column compared to pin_susp's; the table of largest differences and each
engine's verdict."""

from __future__ import annotations

import numpy as np

from ...errors import PinSuspError
from ..options import geometry_argument, positive
from ..report import report_failures, step_list

DESCRIPTION = (
    "Solve SWEEP with pin_susp, then re-solve every step independently from "
    "the design state with a point-based formulation (hardpoints as unknowns, rigid "
    "distances, scipy) and with MuJoCo (from the exported MJCF) and/or Drake (the exported "
    "URDF in Drake's own parser, its InverseKinematics solved by IPOPT); print the largest "
    "difference per column and engine; exit 1 where one exceeds the tolerance. GEOMETRY "
    "is a corner, an axle (scope: axle: each side's columns, the axle's, the bar) or a "
    "vehicle (scope: vehicle: the engines' floating body placed at each step's heave, "
    "pitch and roll, every corner's columns, what the road sees). "
    "MuJoCo and Drake are optional: pip install 'pin_susp[validate]'."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument("sweep", metavar="SWEEP", help="sweep YAML")
    parser.add_argument(
        "--engine",
        choices=("mujoco", "drake", "all", "pointwise"),
        default="mujoco",
        help="the engine besides the point-based solver, which always runs: mujoco "
        "(default), drake, all (both), or pointwise (that one only)",
    )
    parser.add_argument(
        "--mjcf",
        metavar="FILE.xml",
        help="an exported MJCF for MuJoCo to check against (default: export it now)",
    )
    parser.add_argument(
        "--urdf",
        metavar="FILE.urdf",
        help="an exported URDF for Drake to check against (default: export it now)",
    )
    parser.add_argument(
        "--tolerance",
        type=positive,
        default=1e-6,
        metavar="TOL",
        help="largest difference accepted, mm and deg (default 1e-6)",
    )


def run(args) -> int:
    from ...io.yamlio import read_input
    from ...model.sweep import load_sweep
    from ...subjects.subject import load_subject
    from ...validate import validate

    corner = load_subject(args.geometry)
    sweep = load_sweep(args.sweep)
    corner.check_sweep(sweep)  # target errors before any work
    name = corner.name
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
    unchecked = _not_compared(results, reports, corner)
    if unchecked:
        print(f"  not compared (no engine computes them): {', '.join(unchecked)}")
    ok = report_failures(results, "are not compared") == 0
    for r in reports:
        if r.note:
            print(f"  {r.engine}: skipped — {r.note}")
            continue
        if r.failed_steps:
            print(f"  {r.engine}: did not converge at steps {step_list(r.failed_steps)}")
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
                "; the roll centre of its size times max(1, |RC|/track)"
                if "roll_center_z" in results  # a roll centre compared (an axle's columns)
                else ""
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


def _not_compared(results, reports, subject) -> list[str]:
    """The columns with values that no engine that ran compared (a rated spring's, a
    vehicle's body pose and its rates along it), each corner's once (``_*``): none
    where no engine ran."""
    compared = set().union(*(set(r.differences) | r.not_compared for r in reports))
    if not compared:
        return []
    points = {f"{p}_{axis}" for p in subject.output_points for axis in "xyz"}
    suffixes = [subject.suffix(label) for label in subject.labels if label]
    out = {}
    for name in results.columns:
        if name in compared or name in points or name == "step_index":
            continue
        if np.asarray(results[name]).dtype.kind == "O":  # text (limit_exceeded), of the
            continue  # numbers compared
        if name.startswith("solver_") or np.isnan(results[name]).all():
            continue
        stem = next((name.removesuffix(s) for s in suffixes if name.endswith(s)), None)
        out.setdefault(name if stem is None else f"{stem}_*", None)
    return list(out)


def _other_branch(r, subject) -> str:
    """An engine's steps on another assembly branch than pin_susp's, said as such: where
    pin_susp solved them (a difference of assembly, not of kinematics) and where it
    found no pose either; a dead centre at design is the likely cause."""
    said = []
    if r.branch_steps:
        said.append(
            f"lands on another assembly branch at steps {step_list(r.branch_steps)} "
            f"({', '.join(sorted(r.flipped))}), where pin_susp keeps the design's: "
            "those steps are not compared"
        )
    if r.other_branch:
        said.append(
            f"{'and ' if said else 'lands on another assembly branch '}at steps "
            f"{step_list(r.other_branch)}, which pin_susp reaches on no branch of the design's"
            + ("" if r.branch_steps else f" ({', '.join(sorted(r.flipped))})")
        )
    dead = [t for t in getattr(subject, "dead_centres", ()) if t.driven]
    if dead:
        near = ", ".join(f"{t.flow} {t.margin:.1f}° from dead centre" for t in dead)
        said.append(f"near the dead centre at design ({near}: see the dead-centre warning)")
    return "; ".join(said)
