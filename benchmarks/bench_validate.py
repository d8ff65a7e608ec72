"""validate's engines: seconds for the example's 41-step bump + steer sweep.

Each engine re-solves every step from the design state: the point-based solver
(scipy, the baseline, run in the same process), MuJoCo and Drake (IPOPT). The
figure for issue 16: `validate --engine drake` on a 41-step sweep in ≤ 10 s.

    python benchmarks/bench_validate.py [--repeat N]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    import pin_susp
    from pin_susp.validate import validate

    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    sweep = pin_susp.load_sweep(EXAMPLES / "bump_steer.yaml")
    times = {}
    for engine in ("pointwise", "mujoco", "drake"):
        runs = []
        for _ in range(args.repeat):
            started = time.perf_counter()
            validate(corner, sweep, engines=(engine,))
            runs.append(time.perf_counter() - started)
        times[engine] = float(np.median(runs))
    command = [
        sys.executable,
        "-m",
        "pin_susp.cli",
        "validate",
        str(EXAMPLES / "double_wishbone.yaml"),
    ]
    command += [str(EXAMPLES / "bump_steer.yaml"), "--engine", "drake"]
    started = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    wall = time.perf_counter() - started
    base = times["pointwise"]
    print("validate, double_wishbone.yaml, 41-step bump + steer (pin_susp's own solve included):")
    for engine, t in times.items():
        print(f"  {engine:10s} {t:6.2f} s  {1e3 * t / 41:6.1f} ms/step  {t / base:5.2f}x pointwise")
    print(f"  pin-susp validate --engine drake, wall, with start-up: {wall:.1f} s (target <= 10 s)")


if __name__ == "__main__":
    main()
