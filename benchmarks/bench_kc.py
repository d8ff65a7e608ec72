"""How fast the K&C solves (pin_susp/analyses/compliance.py), against a baseline run in
the same process.

    python benchmarks/bench_kc.py [--rounds N] [--quick] [--json OUT.json]

On the FS corner on spherical bearings (examples/kc_fs_corner.yaml), the 41-step bump +
steer sweep (examples/bump_steer.yaml) and the 4 cases of examples/kc.yaml, it prints
the median over rounds, measured in alternation (after a warm-up) of:

- ``kc_linear``: the linear K&C at the sweep's 41 solved poses, 4 cases (every column:
  the motions, the rates' 4 unit loads, the bushings' deflections) — target <= 50 ms;
- ``kc_linear_with_sweep``: the same with the sweep's own solve and columns
  (``kc_results`` from the files' data) — target <= 50 ms too (the whole);
- ``kc_nonlinear``: the nonlinear loaded poses of the same (41 × 4 solves);
- the baseline: the sweep alone (``solve_steps`` + ``sweep_results``), and each figure's
  ratio to it.

Timing lives here, never in the tests.
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np

from pin_susp.analyses.compliance import KC, kc_results
from pin_susp.analyses.load_case import load_cases
from pin_susp.analyses.statics import Statics
from pin_susp.model.sweep import load_sweep
from pin_susp.subjects.subject import load_subject

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
TARGET_MS = 50.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--quick", action="store_true", help="two rounds, no nonlinear")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    rounds = 2 if args.quick else args.rounds
    subject = load_subject(EXAMPLES / "kc_fs_corner.yaml")
    sweep = load_sweep(EXAMPLES / "bump_steer.yaml")
    cases = load_cases(EXAMPLES / "kc.yaml")
    kc = KC(subject)
    W = Statics.loads_matrix(kc, cases)
    qs = [s.q for s in subject.solve_steps(sweep)]

    def baseline():
        solutions = subject.solve_steps(sweep)
        subject.sweep_results(sweep, solutions)

    runs = {
        "baseline_sweep": baseline,
        "kc_linear": lambda: kc.linear(qs, W),
        "kc_linear_with_sweep": lambda: kc_results(subject, sweep, cases, kc=kc),
    }
    if not args.quick:
        runs["kc_nonlinear"] = lambda: kc.nonlinear(qs, W)
    times = {name: [] for name in runs}
    for run in runs.values():  # warm-up
        run()
    for _ in range(rounds):
        for name, run in runs.items():
            t = time.perf_counter()
            run()
            times[name].append(time.perf_counter() - t)
    ms = {name: 1e3 * float(np.median(t)) for name, t in times.items()}
    base = ms["baseline_sweep"]
    print(f"K&C of {len(qs)} steps x {len(cases)} cases, {platform.python_version()}, "
          f"median of {rounds} rounds")  # fmt: skip
    for name, value in ms.items():
        flag = ""
        if name in ("kc_linear", "kc_linear_with_sweep"):
            verdict = "met" if value <= TARGET_MS else "MISSED"
            flag = f"  (target <= {TARGET_MS:.0f} ms: {verdict})"
        print(f"  {name:24s} {value:9.2f} ms   {value / base:6.2f} x the sweep{flag}")
    if args.json:
        args.json.write_text(json.dumps({"ms": ms, "steps": len(qs), "cases": len(cases)}))


if __name__ == "__main__":
    main()
