"""`pin-susp urdf`: the corner (axle, vehicle) as URDF with its loop closures (docs/urdf.md);
--at SWEEP.yaml:STEP adds the joint values of that solved step as a YAML sidecar."""

from __future__ import annotations

import re
import sys
from pathlib import Path

from ...errors import PinSuspError
from ..options import check_outputs, geometry_argument

DESCRIPTION = (
    "Write the URDF of GEOMETRY: the kinematic tree in metres, every "
    "hardpoint as a link, loop closures as <pin_susp:loop_closure> elements."
)


def arguments(parser) -> None:
    geometry_argument(parser)
    parser.add_argument(
        "-o", "--output", metavar="OUT.urdf", help="file to write (default: standard output)"
    )
    parser.add_argument(
        "--at",
        metavar="SWEEP:STEP",
        help="also write the joint values of that solved step to a YAML sidecar "
        "(OUT.pose.yaml), so another tool can load the pose",
    )


def run(args) -> int:
    from ...io.atomic import all_or_none, is_stream, write_text
    from ...subjects.subject import load_subject, subject_class

    if args.at is not None and args.output is None:
        raise PinSuspError("--at writes a sidecar beside the URDF: give -o OUT.urdf too")
    check_outputs(args, args.output)
    sidecar = None
    if args.output is not None and args.at is not None:
        if is_stream(Path(args.output)):
            raise PinSuspError(f"--at writes a sidecar beside the URDF: {args.output} is a stream")
        sidecar = Path(args.output).with_suffix(".pose.yaml")
        check_outputs(args, args.output, sidecar)
    kind = subject_class(args.geometry) if args.at is not None else None
    if kind is not None and not kind.poses_at_steps:
        article = "an" if kind.noun[0] in "aeiou" else "a"
        raise PinSuspError(
            f"--at: not for {article} {kind.noun} yet (a corner's URDF at a step only)"
        )
    corner = load_subject(args.geometry)  # an axle's: both corners on one chassis; a car's
    pose = _pose_at(corner, args.at) if args.at is not None else None
    if args.output is None:
        sys.stdout.write(corner.export_urdf)
        return 0
    with all_or_none():
        write_text(corner.export_urdf, args.output)
        if pose is not None:
            import yaml

            write_text(yaml.safe_dump(pose, sort_keys=False), sidecar)
    print(f"wrote {args.output}")
    if sidecar is not None:
        print(f"wrote {sidecar}")
    return 0


def _pose_at(corner, at: str) -> dict:
    """Joint values of one solved sweep step, by joint name (rad, m)."""
    from ...model.sweep import load_sweep

    path, _, step = at.rpartition(":")
    if not path or not re.fullmatch(r"[0-9]{1,9}", step):
        raise PinSuspError(f"--at {at}: expected SWEEP.yaml:STEP, e.g. bump_steer.yaml:20")
    sweep = load_sweep(path)
    corner.solver_for(sweep.targets, sweep.source)
    i = int(step)
    if i >= sweep.steps:
        raise PinSuspError(f"--at {at}: the sweep has steps 0 to {sweep.steps - 1}")
    results = corner.run_sweep(sweep)
    if not results["solver_converged"][i]:
        why = results.meta["why"][i]
        raise PinSuspError(f"--at {at}: that step did not converge ({why})")
    q = results.meta["q"][i]
    model = corner.model
    joints = {model.names[j]: float(q[model.joints[j].idx_q]) for j in range(1, model.njoints)}
    return {
        "comment": "joint values of a solved pose; revolute in rad, prismatic in m; "
        "all zero is the design state",
        "urdf_robot": corner.tree.name,
        "sweep": sweep.source,
        "step": i,
        "targets": {t.point: float(t.values[i]) for t in corner.held_targets(sweep.targets)},
        "joints": joints,
    }
