"""`pin-susp envelope`: the tyre's swept volume over a sweep as one closed STL mesh in
mm (docs/clearance.md), written atomically."""

from __future__ import annotations

from ..options import check_outputs, geometry_argument
from ..report import progress_bar, report_failures, report_limits

DESCRIPTION = (
    "Solve SWEEP on GEOMETRY (a corner, an axle or a vehicle; e.g. a bump × steer grid) and "
    "write the volume every tyre sweeps as one watertight binary STL in mm: the union of the "
    "convex hulls of consecutive steps' tyres (one hull of every step with --hull, or where no "
    "boolean engine is installed). Exit 1 if a step did not converge (it is left out)."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument("sweep", metavar="SWEEP", help="sweep YAML (e.g. a bump × steer grid)")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.stl", help="binary STL, mm")
    parser.add_argument(
        "--hull", action="store_true", help="one convex hull of every step's tyre (no union)"
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")


def run(args) -> int:
    check_outputs(args, args.output)
    from ...analyses.envelope import envelope
    from ...errors import PinSuspError
    from ...io.atomic import atomic_write
    from ...model.sweep import load_sweep
    from ...subjects.subject import load_subject

    subject = load_subject(args.geometry)
    sweep = load_sweep(args.sweep)
    subject.check_sweep(sweep)
    results = subject.run_sweep(sweep, progress=progress_bar(sweep.steps, args.quiet))
    qs = results.solved_configurations
    if not any(q is not None for q in qs):
        report_failures(results, "are left out")
        raise PinSuspError(f"{args.sweep}: no step converged: no envelope written")
    mesh, method, poses = envelope(subject, qs, hull_only=args.hull)
    data = mesh.export(file_type="stl")
    with atomic_write(args.output, binary=True) as f:
        f.write(data)
    if not args.quiet:
        low, high = mesh.bounds
        how = (
            "a union of convex hulls of consecutive steps" if method == "union" else "a convex hull"
        )
        print(
            f"envelope: {poses} tyre poses, {how}: {len(mesh.faces)} triangles, "
            f"watertight {mesh.is_watertight}, volume {mesh.volume / 1e9:.4f} m³"
        )
        print(
            "bounds (mm): "
            + ", ".join(
                f"{a} {lo:.1f}…{hi:.1f}" for a, lo, hi in zip("xyz", low, high, strict=True)
            )
        )
        print(f"wrote {args.output}")
    return max(report_failures(results, "are left out of the envelope"), report_limits(results))
