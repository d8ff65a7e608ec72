"""Time the Newton sweep in-process: per-step solve and whole sweep with metrics.

    python benchmarks/bench_sweep.py [--repeat N]

Prints the median, p10 and p90 over repetitions after a warm-up, the
iterations per step and the worst residual. (Timing lives here, never in
the tests.)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import pin_susp

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def percentiles(samples):
    return np.percentile(samples, [50, 10, 90])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=30)
    args = parser.parse_args()

    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    sweep = pin_susp.load_sweep(EXAMPLES / "bump_steer.yaml")
    solver = corner.solver_for(sweep.targets)
    values = corner.target_values(sweep.targets)
    start = corner.target_values([t.at_design() for t in sweep.targets])[0]
    corner.run_sweep(sweep)  # warm-up

    per_step, whole = [], []
    for _ in range(args.repeat):
        q, previous = corner.q_design, start
        for v in values:
            t0 = time.perf_counter()
            solution = solver.solve(q, previous, v)
            per_step.append(time.perf_counter() - t0)
            q, previous = solution.q, v
        t0 = time.perf_counter()
        results = corner.run_sweep(sweep)
        whole.append(time.perf_counter() - t0)

    med, p10, p90 = percentiles(per_step) * 1e6
    print(f"example corner, {sweep.steps}-step combined bump+steer sweep, {args.repeat} repeats")
    print(f"  per-step solve      median {med:7.1f} us   p10 {p10:7.1f}   p90 {p90:7.1f}")
    med, p10, p90 = percentiles(whole) * 1e3
    print(f"  sweep with metrics  median {med:7.2f} ms   p10 {p10:7.2f}   p90 {p90:7.2f}")
    its = results["solver_iterations"]
    print(
        f"  iterations per step median {np.median(its):g}, max {its.max()} "
        f"(first step from design: {its[0]})"
    )
    print(f"  max residual        {results['solver_max_residual'].max():.2e} mm")


if __name__ == "__main__":
    main()
