"""How fast the attitude solves (pin_susp/analyses/attitude.py), against a baseline run
in the same process.

    python benchmarks/bench_attitude.py [--rounds N] [--quick] [--json OUT.json]

On the example car (examples/vehicle_fs.yaml) it prints, per acceleration point, the
median over rounds measured in alternation (so that the machine's drift falls on all
alike, after a warm-up):

- a list of 10 points (standing, cornering, braking, accelerating and combined) and an
  11 × 17 grid (ax −1…0.5 g, ay −1.2…1.2 g: 187 points), each as ``Attitude.run``
  (every column: the equilibria, the vehicle sweep's columns at them, the gradients and
  the frequencies) and as ``equilibria`` alone — target <= 20 ms per point;
- the baseline: a 21-step vehicle sweep of the same car (rolled −2…2°, heave, pitch and
  the steering wheel held, every column), per step, and each attitude figure as a ratio
  to it;
- the gradients and the frequencies, which every run computes once (7 equilibria and a
  linearisation: a fixed cost that a short list's points share);
- building the Attitude (the design's preloads and static loads), once.

Timing lives here, never in the tests (tests/test_bench.py runs ``--quick`` and checks
only that every point converges and every figure is reported).
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

from pin_susp.analyses.attitude import Accelerations, Attitude
from pin_susp.model.sweep import Sweep, Target
from pin_susp.subjects.vehicle import Vehicle

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CAR = EXAMPLES / "vehicle_fs.yaml"
TARGET_MS = 20.0  # per acceleration point
# (ax, ay) g: within the FS car's grip, no wheel lifted
POINTS = [
    (0.0, 0.0),
    (0.0, 0.5),
    (0.0, 1.0),
    (-0.5, 0.0),
    (-1.0, 0.0),
    (0.5, 0.0),
    (-0.5, 0.5),
    (0.3, 0.6),
    (0.0, -0.8),
    (-0.8, -0.4),
]


def grid(n_ax: int, n_ay: int) -> Accelerations:
    """Every (ax, ay) of ax −1…0.5 g by ay −1.2…1.2 g, ay the faster (as a grid file)."""
    ax, ay = np.meshgrid(np.linspace(-1.0, 0.5, n_ax), np.linspace(-1.2, 1.2, n_ay), indexing="ij")
    return Accelerations(ax.ravel(), ay.ravel(), f"grid {n_ax} x {n_ay}")


def roll_sweep(steps: int) -> Sweep:
    """The baseline: the body rolled −2…2°, heave, pitch and the steering wheel held."""
    zero = np.zeros(steps)
    return Sweep(
        [
            Target(None, None, zero, quantity="heave"),
            Target(None, None, zero, quantity="pitch"),
            Target(None, None, np.linspace(-2.0, 2.0, steps), quantity="roll"),
            Target(None, None, zero, quantity="steering_wheel"),
        ],
        "roll",
    )


def alternating(jobs: dict, rounds: int) -> dict[str, float]:
    """Median ms per unit (point or step) of each job — (function, units) — the jobs run in
    turn round after round after a warm-up each."""
    times = {name: [] for name in jobs}
    for job, _ in jobs.values():
        job()  # warm-up
    for _ in range(rounds):
        for name, (job, units) in jobs.items():
            started = time.perf_counter()
            job()
            times[name].append((time.perf_counter() - started) / units * 1e3)
    return {name: float(np.median(t)) for name, t in times.items()}


def run(rounds: int, quick: bool) -> dict:
    car = Vehicle(CAR)
    started = time.perf_counter()
    attitude = Attitude(car)
    build_ms = (time.perf_counter() - started) * 1e3
    listed = Accelerations(*np.array(POINTS).T, "list of 10")
    gridded = grid(*((3, 5) if quick else (11, 17)))
    sweep = roll_sweep(21)
    last = {}

    def whole(name, a):
        def job():
            last[name] = attitude.run(a)

        return job

    jobs = {"sweep 21 steps, every column": (lambda: car.run_sweep(sweep), sweep.steps)}
    jobs["gradients + frequencies"] = (lambda: attitude.gradients() | attitude.frequencies(), 1)
    for a in (listed, gridded):
        jobs[f"{a.source}: run"] = (whole(a.source, a), len(a))
        jobs[f"{a.source}: equilibria"] = (lambda a=a: attitude.equilibria(a.ax, a.ay), len(a))
    ms = alternating(jobs, rounds)
    baseline = ms["sweep 21 steps, every column"]
    report = {
        "machine": {
            "python": platform.python_version(),
            "pin": pin.__version__,
            "processor": platform.machine(),
            "quick": quick,
        },
        "car": CAR.name,
        "build_ms": build_ms,
        "baseline_ms_per_step": baseline,
        "constants_ms": ms["gradients + frequencies"],  # once per run, in its every point
        "target_ms_per_point": TARGET_MS,
        "sets": {},
    }
    for a in (listed, gridded):
        results = last[a.source]
        report["sets"][a.source] = {
            "points": len(a),
            "converged": int(results["solver_converged"].sum()),
            "max_equilibrium_residual_N": float(np.max(results["equilibrium_residual"])),
            "columns": len(results.columns),
            "ms_per_point": {kind: ms[f"{a.source}: {kind}"] for kind in ("run", "equilibria")},
            "ratio_to_sweep_step": {
                kind: ms[f"{a.source}: {kind}"] / baseline for kind in ("run", "equilibria")
            },
        }
    return report


def show(report: dict) -> None:
    m = report["machine"]
    print(
        f"pin_susp attitude benchmark — Python {m['python']}, pin {m['pin']}"
        f"{' (quick)' if m['quick'] else ''}: {report['car']}"
    )
    print(f"  Attitude(car) built in {report['build_ms']:.1f} ms (the design's preloads)")
    print(
        f"  baseline: a 21-step vehicle sweep (roll -2...2 deg, every column) "
        f"{report['baseline_ms_per_step']:.2f} ms per step"
    )
    print(
        f"  the gradients and frequencies, once per run (its every point shares them): "
        f"{report['constants_ms']:.1f} ms"
    )
    target = report["target_ms_per_point"]
    for name, s in report["sets"].items():
        print(
            f"\n{name}: {s['points']} points, {s['converged']} converged, max residual "
            f"{s['max_equilibrium_residual_N']:.1e} N, {s['columns']} columns"
        )
        for kind in ("run", "equilibria"):
            t, ratio = s["ms_per_point"][kind], s["ratio_to_sweep_step"][kind]
            what = "run (every column)" if kind == "run" else "equilibria alone"
            print(
                f"  {what:20s} {t:7.2f} ms per point = {ratio:5.1f}x a sweep step "
                f"(target <= {target:g} ms: {'met' if t <= target else 'NOT met'})"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7, help="rounds of the alternation")
    parser.add_argument("--quick", action="store_true", help="2 rounds, a 3 x 5 grid")
    parser.add_argument("--json", metavar="OUT.json", help="also write the figures as JSON")
    args = parser.parse_args()
    report = run(2 if args.quick else args.rounds, args.quick)
    show(report)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2, default=float))
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
