"""How fast pin_susp solves, against two baselines run in the same process.

    python benchmarks/bench_sweep.py [--repeat N] [--quick] [--json OUT.json]

For the example corner (combined bump + steer), the shimmed corner, the
pushrod-rocker corner and one example of every other mechanism (MacPherson,
multilink with a rack and with a toe link, semi-trailing arm; bump alone
where there is no rack, against the fixed-toe-link double wishbone) it prints:

- per-step solve time: median, p10, p90 over every step of every repetition
  (after a warm-up), Newton iterations per step, worst residual;
- a 101-step sweep with every metric and exact derivative column, whole;
- the same 101 steps solved by the independent point-based formulation with
  scipy least_squares, (a) finite-difference and (b) analytic Jacobians, and
  the ratios baseline / pin_susp per step (``--quick``: 21 steps of the same span);
- per-step time for sweeps of 11, 101, 1 001 and 10 001 steps;
- a 51 × 41 bump × steer grid solved by continuation along rows;
- each mechanism's per-step time as a ratio to the double wishbone's on the
  same kind of sweep (target: MacPherson and multilink <= 1.5x);
- the example axle (examples/axle_front.yaml: two pushrod-rocker corners, one
  rack, a U-bar) against its corner (examples/pushrod_rocker.yaml), per step,
  measured in alternation: bump + steer on both wheels and a roll sweep (roll
  and heave targets), solve alone and solve with every column (target <= 2.5x);
- the axle's roll sweep of 2 001 steps with every column against its corner's long
  sweep (bump + steer, 2 001 steps) with every column, per step, in alternation
  (target <= 1.3x; ``--axle-long`` runs this figure alone);
- the example car (examples/vehicle_fs.yaml) rolled ±2° in 2 001 steps with every
  column against its corner's bump + steer, per step, in alternation (target <= 3x;
  ``--vehicle`` runs this figure alone, and only it: not yet in the full run);
- the member forces under examples/loads.yaml's 3 load cases on the pushrod-rocker
  corner's 101-step sweep, as a share of the sweep's own time (target <= 30 %).

Timing lives here, never in the tests (a test runs ``--quick`` and checks
only iterations and residuals).
"""

from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import yaml

import pin_susp
from pin_susp.analyses.pointwise import PointwiseCorner
from pin_susp.model.sweep import Sweep, Target, load_sweep
from pin_susp.subjects.axle import AxleModel, axle_results, load_axle, solve_axle_sweep

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CORNERS = ("double_wishbone.yaml", "camber_shim.yaml", "pushrod_rocker.yaml")
# every other mechanism, and the double wishbone each is compared with (same sweep kind)
MECHANISMS = {
    "macpherson.yaml": "double_wishbone.yaml",
    "multilink_front.yaml": "double_wishbone.yaml",
    "fixed_toe_link.yaml": None,
    "multilink_rear.yaml": "fixed_toe_link.yaml",
    "semi_trailing_arm.yaml": "fixed_toe_link.yaml",
}


def bump_steer(steps: int) -> Sweep:
    """The example sweep (−40…60 mm bump with −10…10 mm rack) at any resolution."""
    return Sweep(
        [
            Target("wheel_center", "z", np.linspace(-40, 60, steps)),
            Target("trackrod_inboard", "y", np.linspace(-10, 10, steps)),
        ],
        "bump+steer",
    )


def bump(steps: int) -> Sweep:
    """−40…60 mm of bump alone (a corner without a rack)."""
    return Sweep([Target("wheel_center", "z", np.linspace(-40, 60, steps))], "bump")


def percentiles(samples) -> dict:
    p50, p10, p90 = np.percentile(samples, [50, 10, 90])
    return {"median": p50, "p10": p10, "p90": p90}


def per_step(corner, sweep, repeat: int) -> dict:
    corner.solve_steps(sweep)  # warm-up
    times, iterations, residual = [], [], 0.0
    for _ in range(repeat):
        solutions = corner.solve_steps(sweep, step_times=times)
    iterations = [s.iterations for s in solutions]
    residual = max(s.max_residual for s in solutions)
    return {
        "time_us": {k: v * 1e6 for k, v in percentiles(times).items()},
        "iterations_median": float(np.median(iterations)),
        "iterations_max": int(max(iterations)),
        "iterations_first_step": int(iterations[0]),
        "max_residual_mm": residual * 1e3,
        "converged": all(s.converged for s in solutions),
    }


def whole_sweep(corner, sweep, repeat: int) -> dict:
    corner.run_sweep(sweep)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        results = corner.run_sweep(sweep)
        times.append(time.perf_counter() - t0)
    columns = len(results.columns)
    derivatives = sum(1 for c in results.columns if c.startswith("deriv_"))
    return {
        "time_ms": {k: v * 1e3 for k, v in percentiles(times).items()},
        "columns": columns,
        "derivative_columns": derivatives,
    }


def baseline(corner, sweep, jacobian: str, repeat: int) -> dict:
    """The point-based formulation, warm-started step to step like ours."""
    from pin_susp.validate import step_targets

    model = PointwiseCorner(corner.geometry)
    targets = step_targets(corner, sweep)
    times, worst = [], 0.0
    for _ in range(repeat):
        x = None
        t0 = time.perf_counter()
        for step in targets:
            x, residual = model.solve(step, x, jacobian=jacobian)
            worst = max(worst, residual)
        times.append((time.perf_counter() - t0) / len(targets))
    return {"time_us_per_step": float(np.median(times)) * 1e6, "max_residual_mm": worst * 1e3}


def scaling(corner, sizes, repeat: int, kind=bump_steer) -> dict:
    out = {}
    for n in sizes:
        sweep = kind(n)
        corner.solve_steps(kind(11))
        times = []
        for _ in range(max(1, repeat // max(1, n // 101))):
            t0 = time.perf_counter()
            corner.solve_steps(sweep)
            times.append((time.perf_counter() - t0) / n)
        out[str(n)] = float(np.median(times)) * 1e6
    return out


def grid(corner, bumps: int, racks: int) -> dict:
    """bump × steer grid: each row a bump sweep at one rack position, started from the
    previous row's first solution (continuation across rows)."""
    t0 = time.perf_counter()
    q_row = None
    worst, solved = 0.0, 0
    for rack in np.linspace(-10, 10, racks):
        row = Sweep(
            [
                Target("wheel_center", "z", np.linspace(-40, 60, bumps)),
                Target("trackrod_inboard", "y", np.full(bumps, rack)),
            ],
            "grid row",
        )
        solutions = corner.solve_steps(row, q_start=q_row)
        q_row = solutions[0].q
        worst = max(worst, max(s.max_residual for s in solutions))
        solved += sum(s.converged for s in solutions)
    total = time.perf_counter() - t0
    return {
        "points": bumps * racks,
        "converged": solved,
        "total_ms": total * 1e3,
        "us_per_point": total / (bumps * racks) * 1e6,
        "max_residual_mm": worst * 1e3,
    }


def run(repeat: int, quick: bool) -> dict:
    report = {
        "machine": {
            "python": platform.python_version(),
            "pin": pin.__version__,
            "processor": platform.machine(),
            "quick": quick,
        },
        "corners": {},
    }
    sizes = (11, 101) if quick else (11, 101, 1001, 10001)
    for name in (*CORNERS, *MECHANISMS):
        corner = pin_susp.Corner(EXAMPLES / name)
        kind = bump_steer if corner.geometry.steering == "rack" else bump
        sweep = kind(41)
        sweep101 = kind(101)
        entry = {
            "per_step": per_step(corner, sweep, repeat),
            "sweep_101": whole_sweep(corner, sweep101, max(3, repeat // 4)),
        }
        ours = np.median(_times(corner, sweep101, max(2, repeat // 8))) * 1e6
        slow = kind(21) if quick else sweep101  # --quick: the same span in 21 steps
        entry["baselines"] = {
            "ours_us_per_step_101": ours,
            "a_fd_jacobian": baseline(corner, slow, "2-point", 1),
            "b_analytic_jacobian": baseline(corner, slow, "analytic", 1 if quick else 2),
        }
        for key in ("a_fd_jacobian", "b_analytic_jacobian"):
            entry["baselines"][key]["ratio"] = entry["baselines"][key]["time_us_per_step"] / ours
        entry["scaling_us_per_step"] = scaling(corner, sizes, repeat, kind)
        if name == "double_wishbone.yaml":
            entry["grid"] = grid(corner, *((11, 9) if quick else (51, 41)))
        entry["sweep"] = sweep.source
        report["corners"][name] = entry
    pairs = {name: ref for name, ref in MECHANISMS.items() if ref is not None}
    for name, ratio in interleaved(pairs, max(3, repeat // 2)).items():
        report["corners"][name]["vs"] = {"corner": pairs[name], "ratio": ratio}
    report["long"] = long_sweep(max(3, repeat // 8), 201 if quick else 2001, 21 if quick else 201)
    pairs = [(201, 2001)] if quick else [(2001, 20001), (20001, 100001)]
    report["cli"] = [cli_marginal(pair, 2 if quick else 5) for pair in pairs]
    report["axle"] = axle_vs_corner(max(3, repeat // 2))
    report["axle_long"] = axle_long(max(3, repeat // 8), 201 if quick else 2001)
    report["loads"] = loads_overhead(max(3, repeat // 4))
    return report


def issue_sweep(steps: int) -> Sweep:
    """The long sweep of issue 17 (open-kinematics' test corner): wheel centre
    −40…120 mm with the rack −40…40 mm."""
    return Sweep(
        [
            Target("wheel_center", "z", np.linspace(-40, 120, steps)),
            Target("trackrod_inboard", "y", np.linspace(-40, 40, steps)),
        ],
        "bump+steer, long",
    )


def long_sweep(rounds: int, steps: int, baseline_steps: int) -> dict:
    """The example corner's long sweep in process, per step, measured in alternation:
    the solve alone, the solve with every column, and with the CSV's text and the Parquet
    file too; the same solve + columns marched one step after another (the path before
    issue 17); and the point-based baselines on the first ``baseline_steps`` steps."""
    import tempfile

    import pin_susp.subjects.corner
    from pin_susp.io.tables import csv_text, write_parquet
    from pin_susp.solve import march as marching

    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    sweep = issue_sweep(steps)
    march = marching.march

    def step_by_step():
        pin_susp.subjects.corner.march = lambda *a, **k: march(*a, **{**k, "bulk": False})
        try:
            return corner.run_sweep(sweep)
        finally:
            pin_susp.subjects.corner.march = march

    folder = tempfile.TemporaryDirectory()
    parquet = Path(folder.name) / "out.parquet"
    jobs = {
        "solve": lambda: corner.solve_steps(sweep, tangents=[]),
        "solve + every column": lambda: corner.run_sweep(sweep),
        "... + CSV text": lambda: csv_text(corner.run_sweep(sweep)),
        "... + Parquet file": lambda: write_parquet(corner.run_sweep(sweep), parquet),
        "step by step: solve + every column": step_by_step,
    }
    us = alternating(jobs, rounds, steps)
    results = corner.run_sweep(sweep)
    writes = {
        "CSV text": lambda: csv_text(results),
        "Parquet": lambda: write_parquet(results, parquet),
    }
    written = alternating(writes, rounds, steps)
    folder.cleanup()
    head = Sweep([replace_values(t, baseline_steps) for t in sweep.targets], "head")
    base = {
        "a_fd_jacobian": baseline(corner, head, "2-point", 1),
        "b_analytic_jacobian": baseline(corner, head, "analytic", 1),
    }
    ours = us["solve + every column"]
    return {
        "steps": steps,
        "columns": len(results.columns),
        "us_per_step": us,
        "writer_us_per_row": written,
        "baselines": {k: v | {"ratio": v["time_us_per_step"] / ours} for k, v in base.items()},
        "vs_step_by_step": us["step by step: solve + every column"] / ours,
        "converged": bool(results["solver_converged"].all()),
        "max_residual_mm": float(np.max(results["solver_max_residual"])),
    }


def replace_values(target: Target, n: int) -> Target:
    from dataclasses import replace

    return replace(target, values=target.values[:n])


def cli_marginal(steps: tuple[int, int], rounds: int) -> dict:
    """`pin-susp sweep` of the long sweep through the command line at two lengths, in
    alternation: the wall time, and the marginal cost per step (solve, every column,
    the CSV; a sweep of more than 10 000 steps streams) as the difference over the extra
    steps."""
    import shutil
    import subprocess
    import sys
    import tempfile

    exe = shutil.which("pin-susp") or str(Path(sys.executable).parent / "pin-susp")
    folder = Path(tempfile.mkdtemp())
    files = {}
    for n in steps:
        sweep = folder / f"sweep_{n}.yaml"
        sweep.write_text(
            f"version: 1\nsteps: {n}\ntargets:\n"
            "  - {point: wheel_center, direction: {axis: z}, start: -40, stop: 120}\n"
            "  - {point: trackrod_inboard, direction: {axis: y}, start: -40, stop: 40}\n"
        )
        files[n] = sweep
    geometry = str(EXAMPLES / "double_wishbone.yaml")
    times = {n: [] for n in steps}
    for _ in range(rounds):
        for n in steps:
            started = time.perf_counter()
            subprocess.run(
                [exe, "sweep", geometry, str(files[n]), "-o", str(folder / "out.csv"), "-q"],
                check=True,
            )
            times[n].append(time.perf_counter() - started)
    shutil.rmtree(folder)
    wall = {n: float(np.median(t)) for n, t in times.items()}
    short, long = steps
    return {
        "wall_s": {str(n): t for n, t in wall.items()},
        "marginal_us_per_step": (wall[long] - wall[short]) / (long - short) * 1e6,
    }


def loads_overhead(rounds: int, steps: int = 101) -> dict:
    """The sweep with every column, and the same with the forces of 3 load cases added
    (pin-susp loads), per step, in alternation."""
    from pin_susp.analyses.loads import load_cases, member_forces

    corner = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    cases = load_cases(EXAMPLES / "loads.yaml")
    sweep = bump_steer(steps)

    def with_forces():
        tangents = []
        solutions = corner.solve_steps(sweep, tangents=tangents)
        results = pin_susp.Results.from_solutions(corner, solutions, sweep, tangents)
        return member_forces(corner, sweep, cases, solutions, results)

    jobs = {"sweep": lambda: corner.run_sweep(sweep), "sweep + forces": with_forces}
    us = alternating(jobs, rounds, steps)
    return {"us_per_step": us, "added": us["sweep + forces"] / us["sweep"] - 1.0, "cases": 3}


def alternating(jobs: dict, rounds: int, steps: int) -> dict[str, float]:
    """Median µs per step of each job, the jobs run in turn round after round (after a
    warm-up), so that the machine's drift falls on all of them alike."""
    times = {name: [] for name in jobs}
    for job in jobs.values():
        job()  # warm-up
    for _ in range(rounds):
        for name, job in jobs.items():
            started = time.perf_counter()
            job()
            times[name].append((time.perf_counter() - started) / steps * 1e6)
    return {name: float(np.median(t)) for name, t in times.items()}


def axle_sweeps(steps: int) -> dict[str, Sweep]:
    """The axle's sweeps: both wheels' bump with the rack (the corner's bump + steer on
    each side), and roll −3…3° at 10 mm of heave with the rack held."""
    side = lambda s, point, axis, a, b: {  # noqa: E731
        "point": point, "side": s, "direction": {"axis": axis}, "start": a, "stop": b,
    }  # fmt: skip
    rack = side("left", "trackrod_inboard", "y", -10, 10)
    return {
        "bump+steer": load_sweep(
            {
                "steps": steps,
                "targets": [
                    side("left", "wheel_center", "z", -40, 60),
                    side("right", "wheel_center", "z", -40, 60),
                    rack,
                ],
            }
        ),
        "roll": load_sweep(
            {
                "steps": steps,
                "targets": [
                    {"quantity": "roll", "start": -3, "stop": 3},
                    {"quantity": "heave", "start": 10, "stop": 10},
                    rack | {"start": 0, "stop": 0},
                ],
            }
        ),
    }


def axle_vs_corner(rounds: int, steps: int = 101) -> dict:
    """Per-step time of the example axle over its corner's, in alternation (so that the
    machine's drift cancels): solve alone, and solve with every column."""
    corner = axle_corner()
    model = AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))
    reference = bump_steer(steps)
    jobs = {
        "corner solve": lambda: corner.solve_steps(reference),
        "corner whole": lambda: corner.run_sweep(reference),
    }
    for kind, sweep in axle_sweeps(steps).items():
        jobs[f"axle {kind} solve"] = lambda sweep=sweep: solve_axle_sweep(model, sweep)
        jobs[f"axle {kind} whole"] = lambda sweep=sweep: axle_results(
            model, sweep, solve_axle_sweep(model, sweep)
        )
    us = alternating(jobs, rounds, steps)
    out = {"us_per_step": us, "ratio": {}}
    for name, t in us.items():
        if name.startswith("axle"):
            out["ratio"][name] = t / us[f"corner {name.rsplit(' ', 1)[1]}"]
    return out


def axle_corner(drawn_from: str = "pushrod_rocker.yaml"):
    """The axle's corner as the axle has it: no spring rate (whose rate columns an axle
    does not write yet), so that both write the same kind of columns."""
    drawn = yaml.safe_load((EXAMPLES / drawn_from).read_text())
    drawn["spring"] = {"type": drawn["spring"]["type"]}
    drawn["config"]["wheel"].pop("tyre", None)
    return pin_susp.Corner(drawn)


def axle_long(rounds: int, steps: int = 2001) -> dict:
    """The example axle's roll sweep (examples/roll.yaml's −3…3° at design heave, the
    rack held) of ``steps`` steps with every column, against its corner's long sweep
    (bump + steer) of as many steps with every column: per step, in alternation in one
    process (target <= 1.3x, issue 25)."""
    corner = axle_corner()
    model = AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))
    roll = yaml.safe_load((EXAMPLES / "roll.yaml").read_text()) | {"steps": steps}
    sweep = load_sweep(roll)
    reference = bump_steer(steps)
    last = {}

    def axle_whole():
        last["axle"] = axle_results(model, sweep, solve_axle_sweep(model, sweep))

    def corner_whole():
        last["corner"] = corner.run_sweep(reference)

    jobs = {
        "corner solve": lambda: corner.solve_steps(reference),
        "corner solve + every column": corner_whole,
        "axle roll solve": lambda: solve_axle_sweep(model, sweep),
        "axle roll solve + every column": axle_whole,
    }
    us = alternating(jobs, rounds, steps)
    results = last["axle"]
    return {
        "steps": steps,
        "us_per_step": us,
        "ratio": us["axle roll solve + every column"] / us["corner solve + every column"],
        "ratio_solve": us["axle roll solve"] / us["corner solve"],
        "columns": {"axle": len(results.columns), "corner": len(last["corner"].columns)},
        "converged": bool(results["solver_converged"].all()),
        "max_residual_mm": float(np.max(results["solver_max_residual"])),
    }


def interleaved(pairs: dict[str, str], rounds: int) -> dict[str, float]:
    """Median per-step time of each corner over its reference's, measured in alternation
    (a 101-step sweep each, round after round) so that the machine's drift cancels."""
    names = list(dict.fromkeys([*pairs, *pairs.values()]))
    corners = {n: pin_susp.Corner(EXAMPLES / n) for n in names}
    sweeps = {
        n: (bump_steer if c.geometry.steering == "rack" else bump)(101) for n, c in corners.items()
    }
    times = {n: [] for n in names}
    for n in names:
        corners[n].solve_steps(sweeps[n])  # warm-up
    for _ in range(rounds):
        for n in names:
            corners[n].solve_steps(sweeps[n], step_times=times[n])
    median = {n: float(np.median(t)) for n, t in times.items()}
    return {n: median[n] / median[ref] for n, ref in pairs.items()}


def _times(corner, sweep, repeat):
    corner.solve_steps(sweep)
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        corner.solve_steps(sweep)
        out.append((time.perf_counter() - t0) / sweep.steps)
    return out


def show(report: dict) -> None:
    print(
        f"pin_susp benchmark — Python {report['machine']['python']}, pin "
        f"{report['machine']['pin']}{' (quick)' if report['machine']['quick'] else ''}"
    )
    for name, e in report["corners"].items():
        s, w, b = e["per_step"], e["sweep_101"], e["baselines"]
        t = s["time_us"]
        print(f"\n{name} ({e['sweep']})")
        print(
            f"  per-step solve            median {t['median']:7.1f} us   p10 {t['p10']:6.1f}"
            f"   p90 {t['p90']:6.1f}   (target <= 60 us)"
        )
        print(
            f"  Newton iterations         median {s['iterations_median']:g}, max "
            f"{s['iterations_max']} (first step, from design: {s['iterations_first_step']});"
            f" max residual {s['max_residual_mm']:.1e} mm"
        )
        wt = w["time_ms"]
        print(
            f"  101-step sweep, all {w['columns']} columns ({w['derivative_columns']} exact "
            f"derivatives): median {wt['median']:.2f} ms  p10 {wt['p10']:.2f}  p90 "
            f"{wt['p90']:.2f}   (target <= 20 ms)"
        )
        print(
            f"  baselines, 101 steps, per step: ours {b['ours_us_per_step_101']:.1f} us;"
            f" (a) scipy + FD Jacobian {b['a_fd_jacobian']['time_us_per_step']:.0f} us "
            f"= {b['a_fd_jacobian']['ratio']:.0f}x (target >= 50x);"
            f" (b) scipy + analytic Jacobian {b['b_analytic_jacobian']['time_us_per_step']:.0f}"
            f" us = {b['b_analytic_jacobian']['ratio']:.0f}x (target >= 15x)"
        )
        scale = ", ".join(f"{n}: {v:.1f}" for n, v in e["scaling_us_per_step"].items())
        print(f"  scaling, us per step by sweep length: {scale}")
        if "vs" in e:
            print(
                f"  per-step time / {e['vs']['corner']}'s on the same sweep kind, measured in "
                "alternation: "
                f"{e['vs']['ratio']:.2f}x (target <= 1.5x for MacPherson and multilink)"
            )
        if "grid" in e:
            g = e["grid"]
            print(
                f"  bump x steer grid {g['points']} points: {g['total_ms']:.1f} ms "
                f"({g['us_per_point']:.1f} us/point), {g['converged']} converged, "
                f"max residual {g['max_residual_mm']:.1e} mm"
            )


def show_long(long: dict, cli: dict) -> None:
    us, b = long["us_per_step"], long["baselines"]
    print(
        f"\nlong sweep (issue 17): double_wishbone.yaml, {long['steps']} steps, wheel centre "
        f"-40...120 mm, rack -40...40 mm, {long['columns']} columns; per step, in alternation:"
    )
    for name, t in us.items():
        print(f"  {name:38s} {t:8.1f} us")
    print(
        "  target: solve + every column <= 22 us; the same solved step by step is "
        f"{long['vs_step_by_step']:.1f}x slower"
    )
    for name, t in long["writer_us_per_row"].items():
        print(f"  writing the table alone, {name:14s} {t:8.1f} us per row")
    print(
        f"  baselines (point-based, scipy least_squares, warm-started) per step: "
        f"(a) FD Jacobian {b['a_fd_jacobian']['time_us_per_step']:.0f} us = "
        f"{b['a_fd_jacobian']['ratio']:.0f}x, (b) analytic Jacobian "
        f"{b['b_analytic_jacobian']['time_us_per_step']:.0f} us = "
        f"{b['b_analytic_jacobian']['ratio']:.0f}x solve + every column (target >= 50x)"
    )
    print("  through the CLI (pin-susp sweep to CSV; past 10 000 steps it streams):")
    for pair in cli:
        wall = ", ".join(f"{n} steps {t:.2f} s" for n, t in pair["wall_s"].items())
        m = pair["marginal_us_per_step"]
        print(
            f"    {wall}: marginal {m:.1f} us per step (target ~30 us; open-kinematics "
            f"0.4.1, measured outside this repository at 8-10 ms per step, is "
            f"{8000 / m:.0f}-{10000 / m:.0f}x that)"
        )


def show_axle(axle: dict) -> None:
    print("\naxle_front.yaml against its corner pushrod_rocker.yaml (bump + steer), per step,")
    print("measured in alternation (target <= 2.5x):")
    us = axle["us_per_step"]
    for name in ("corner solve", "corner whole"):
        print(f"  {name:26s} {us[name]:8.1f} us")
    for name, ratio in axle["ratio"].items():
        print(f"  {name:26s} {us[name]:8.1f} us = {ratio:.2f}x")


def show_axle_long(long: dict) -> None:
    us = long["us_per_step"]
    print(
        f"\naxle_front.yaml roll sweep of {long['steps']} steps ({long['columns']['axle']} "
        f"columns) against its corner's bump + steer of {long['steps']} steps "
        f"({long['columns']['corner']} columns), per step, measured in alternation:"
    )
    for name, t in us.items():
        print(f"  {name:32s} {t:8.1f} us")
    print(
        f"  axle / corner: solve + every column {long['ratio']:.2f}x (target <= 1.3x), "
        f"solve alone {long['ratio_solve']:.2f}x; max residual {long['max_residual_mm']:.1e} mm"
    )


def show_loads(loads: dict) -> None:
    us = loads["us_per_step"]
    print(
        f"\nloads: pushrod_rocker.yaml, 101 steps, {loads['cases']} load cases: sweep "
        f"{us['sweep']:.1f} us/step, with the forces {us['sweep + forces']:.1f} us/step = "
        f"+{100 * loads['added']:.0f} % (target <= 30 %)"
    )


def vehicle_roll(rounds: int, steps: int = 2001) -> dict:
    """The example car (examples/vehicle_fs.yaml) rolled ±2° in ``steps`` steps with
    every column, against its corner's bump + steer (examples/pushrod_rocker.yaml) of as
    many steps with every column: per step, in alternation (issue 26's target <= 3x)."""
    from pin_susp.subjects.vehicle import Vehicle

    car = Vehicle(EXAMPLES / "vehicle_fs.yaml")
    flat = np.zeros(steps)
    roll = Sweep(
        [
            Target(None, None, flat, quantity="heave"),
            Target(None, None, flat, quantity="pitch"),
            Target(None, None, np.linspace(-2, 2, steps), quantity="roll"),
            Target(None, None, flat, quantity="steering_wheel"),
        ],
        "roll",
    )
    corner = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    reference = bump_steer(steps)
    jobs = {
        "corner solve": lambda: corner.solve_steps(reference),
        "corner solve + every column": lambda: corner.run_sweep(reference),
        "vehicle roll solve": lambda: car.solve_steps(roll),
        "vehicle roll solve + every column": lambda: car.run_sweep(roll),
    }
    us = alternating(jobs, rounds, steps)
    return {
        "steps": steps,
        "us_per_step": us,
        "ratio": us["vehicle roll solve + every column"] / us["corner solve + every column"],
        "ratio_solve": us["vehicle roll solve"] / us["corner solve"],
    }


def show_vehicle(figures: dict) -> None:
    print(
        f"\nvehicle_fs.yaml rolled ±2° in {figures['steps']} steps against pushrod_rocker.yaml's "
        "bump + steer, per step, measured in alternation:"
    )
    for name, us in figures["us_per_step"].items():
        print(f"  {name:<36}{us:7.1f} us")
    print(
        f"  vehicle / corner: solve + every column {figures['ratio']:.2f}x (target <= 3x), "
        f"solve alone {figures['ratio_solve']:.2f}x"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=40, help="repetitions per measurement")
    parser.add_argument("--quick", action="store_true", help="few repetitions, small sizes")
    parser.add_argument("--json", metavar="OUT.json", help="also write the figures as JSON")
    parser.add_argument(
        "--axle-long",
        action="store_true",
        help="only the axle's long roll sweep against its corner's (2 001 steps each)",
    )
    parser.add_argument(
        "--vehicle", action="store_true", help="only the car's roll sweep against its corner's"
    )
    args = parser.parse_args()
    if args.vehicle:
        show_vehicle(vehicle_roll(max(3, args.repeat // 8), 201 if args.quick else 2001))
        return
    if args.axle_long:
        show_axle_long(axle_long(max(3, args.repeat // 8), 201 if args.quick else 2001))
        return
    report = run(3 if args.quick else args.repeat, args.quick)
    show(report)
    show_long(report["long"], report["cli"])
    show_axle(report["axle"])
    show_axle_long(report["axle_long"])
    show_loads(report["loads"])
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2, default=float))
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
