"""How fast pin_susp measures a corner's clearance over a bump × steer grid, in process.

    python benchmarks/bench_clearance.py [--rounds N] [--bumps N] [--racks N] [--json OUT.json]

On examples/packaging.yaml (the FS front corner and its frame tube) over a grid of
wheel-centre z −30…30 mm (41 values) × rack −25…25 mm (21 values) — 861 steps, the
example's grid — it times, in alternation, several rounds (figures are p10 / median /
p90 seconds):

- ``sweep``: the grid solved (``Corner.run_sweep``), the baseline every ratio is to;
- ``pairs``: the pairs built and checked at design (``Clearance(...)``: what is
  skipped by construction);
- ``clearance``: every pair at every step with coal (``Clearance.measure``);
- ``total``: the three together (target: ≤ 2 s);
- ``coal_floor``: coal alone, one ``ComputeDistance`` call per pair and step on the
  same shapes at their first step (what the Python loop round coal cannot go below);

then the calls per pair-step (coal's re-centring) and the pair count.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from pin_susp.analyses.clearance import Clearance, ring_piece
from pin_susp.model.clearance_bodies import load_clearance
from pin_susp.model.sweep import Sweep, Target
from pin_susp.subjects.subject import load_subject

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
TARGET = 2.0  # s: the grid's clearance, in process


def grid(bumps: int, racks: int) -> Sweep:
    """The serpentine bump × steer grid (as examples/packaging_grid.yaml)."""
    b, r = [], []
    for j, rack in enumerate(np.linspace(-25.0, 25.0, racks)):
        values = np.linspace(-30.0, 30.0, bumps)
        b += list(values if j % 2 == 0 else values[::-1])
        r += [rack] * bumps
    return Sweep([Target("wheel_center", "z", b), Target("trackrod_inboard", "y", r)], "grid")


def coal_floor(clearance: Clearance, steps: int) -> float:
    """Seconds for one bare coal call per pair and step (the shapes at design)."""
    import coal

    request = coal.DistanceRequest()
    calls = []
    for pair in clearance.pairs:
        piece = ring_piece(pair.ring)
        shape = pair.shape
        if shape.kind == "capsule":
            geometry = coal.Capsule(shape.radius, float(np.linalg.norm(shape.b - shape.a)))
        else:
            geometry = shape.geometry
        compute = coal.ComputeDistance(piece, geometry)
        T1 = coal.Transform3s(np.eye(3), pair.ring.centre)
        T2 = coal.Transform3s(np.eye(3), 0.5 * (shape.a + shape.b))
        calls.append((compute, T1, T2, piece, geometry))  # coal keeps no reference of its own
    t = time.perf_counter()
    for _ in range(steps):
        for compute, T1, T2, _, _ in calls:
            compute(T1, T2, request, coal.DistanceResult())
    return time.perf_counter() - t


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--bumps", type=int, default=41)
    parser.add_argument("--racks", type=int, default=21)
    parser.add_argument("--json", metavar="OUT.json")
    args = parser.parse_args()

    geometry = EXAMPLES / "packaging.yaml"
    corner = load_subject(geometry)
    bodies = load_clearance(geometry)
    sweep = grid(args.bumps, args.racks)
    Clearance(corner, bodies).measure([corner.q_design])  # imports (coal, scipy) paid once
    times = {k: [] for k in ("sweep", "pairs", "clearance", "total", "coal_floor")}
    calls = None
    for _ in range(args.rounds):
        t0 = time.perf_counter()
        results = corner.run_sweep(sweep)
        t1 = time.perf_counter()
        clearance = Clearance(corner, bodies)
        t2 = time.perf_counter()
        qs = [
            q if ok else None
            for q, ok in zip(results.meta["q"], results["solver_converged"], strict=True)
        ]
        measured = clearance.measure(qs)
        t3 = time.perf_counter()
        times["sweep"].append(t1 - t0)
        times["pairs"].append(t2 - t1)
        times["clearance"].append(t3 - t2)
        times["total"].append(t3 - t0)
        times["coal_floor"].append(coal_floor(clearance, sweep.steps))
        calls = calls if calls is not None else _calls(clearance, qs)
    assert np.isfinite(measured["distance"]).all()

    def stats(v):
        q = np.quantile(v, [0.1, 0.5, 0.9])
        return {"p10": q[0], "median": q[1], "p90": q[2]}

    report = {k: stats(v) for k, v in times.items()}
    base = statistics.median(times["sweep"])
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}")
    pairs = len(clearance.pairs)
    print(
        f"{geometry.name}: {sweep.steps} steps ({args.bumps} bump x {args.racks} rack), "
        f"{pairs} pairs ({len(clearance.skipped)} skipped), {args.rounds} rounds\n"
    )
    print(f"{'part':<14}{'s p10':>9}{'median':>9}{'p90':>9}{'x sweep':>9}")
    for name, t in report.items():
        ratio = t["median"] / base
        print(f"{name:<14}{t['p10']:>9.3f}{t['median']:>9.3f}{t['p90']:>9.3f}{ratio:>9.2f}")
    total = report["total"]["median"]
    print(f"\ncoal calls per pair-step: {calls:.3f}")
    print(f"clearance of the grid in process: {total:.2f} s median (target <= {TARGET:g} s)")
    if args.json:
        Path(args.json).write_text(json.dumps({"times": report, "calls": calls}, indent=1))


def _calls(clearance: Clearance, qs) -> float:
    """Coal calls per pair-step (the re-centring's), counted on one run."""
    import coal

    count = [0]
    original = coal.ComputeDistance

    class Counting:
        def __init__(self, *a):
            self.inner = original(*a)

        def __call__(self, *a):
            count[0] += 1
            return self.inner(*a)

    coal.ComputeDistance = Counting
    try:
        clearance.measure(qs)
    finally:
        coal.ComputeDistance = original
    still = sum(p.shape.bodies == (p.ring.body, p.ring.body) for p in clearance.pairs)
    return count[0] / ((len(clearance.pairs) - still) * len(qs) + still)


if __name__ == "__main__":
    main()
