"""How long `pin-susp sweep` takes through the command line, by length, and where it goes.

    python benchmarks/bench_cli.py [--rounds N] [--steps 11,201,...] [--against CHECKOUT]
                                   [--as-is] [--no-baseline] [--json OUT.json]

The example corner's combined bump + steer sweep (examples/double_wishbone.yaml; wheel
centre z −40…120 mm with the rack −40…40 mm, the sweep of issue 17) is run through the
CLI to CSV (``python -m pin_susp sweep GEOMETRY SWEEP -o out.csv -q``) at 11, 201, 501,
1 001, 2 001, 5 001 and 20 001 steps, in alternation, ``--rounds`` times (default 3); the
best wall time of each length is kept (the machine is shared: the best is the quiet
one). Each child caches its bytecode in a temporary folder (PYTHONPYCACHEPREFIX), as an
installed copy has it (``make`` compiles it), even where PYTHONDONTWRITEBYTECODE is set
(``--as-is``: as the environment has it; pin_susp is then compiled from source by every
run, ~0.1 s more import). Each run is split by time.perf_counter marks around its parts
(this file run as a child with ``--child``; the marks cost nothing measurable):

- start: the interpreter's start (the wall time less the child's own);
- import: ``pin_susp.cli`` and the numerics (numpy, pinocchio, the model's modules);
- build: the corner (load_subject: YAML, URDF, Pinocchio model, design state);
- batched set-up: the model's tree and rows as arrays (bulk.Tree, bulk.Rows), once;
- solve: every step (march.py; a sweep of bulk.MIN_STEPS or more solved at once);
- columns: every metric, derivative and point column (Assembly.sweep_results);
- writer import: pyarrow and its compute kernels (tables._compute), for a table of
  tables.FAST_CELLS cells or more (the compiled text style), once;
- write: the CSV's text and file (less the writer import);
- other: the rest (argument parsing, the sweep file, the summary).

It prints each length's wall time and split, the marginal cost per step between
lengths (the target of issue 30: <= 40 us per step between 201 and 2 001 steps and
beyond; also less each run's start and import, which do not depend on the length and
hold most of the machine's noise), the fixed costs by name (the 11-step run's split),
and the ratio of a baseline run in this process — the point-based formulation with
scipy least_squares and its analytic Jacobian, warm-started step to step
(bench_sweep.baseline) on 101 steps of the same sweep — to the CLI's marginal cost
per step. A sweep of more than
sweep.STREAM_STEPS steps streams: its solve, columns and write overlap (the writer is
a second thread), so its split sums to more than its wall time. ``--against CHECKOUT``
runs another checkout (a git worktree of an earlier commit) in alternation with this
one and prints its figures and each length's ratio of wall times.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
STEPS = (11, 201, 501, 1001, 2001, 5001, 20001)
PAIRS = ((11, 201), (201, 2001), (2001, 5001), (2001, 20001))
PHASES = (
    "start",
    "import",
    "build",
    "batched set-up",
    "solve",
    "columns",
    "writer import",
    "write",
    "other",
)
OPEN_KINEMATICS_MS = (8.0, 14.0)  # per step, measured outside this repository (issue 30)


def sweep_file(folder: Path, steps: int) -> Path:
    path = folder / f"sweep_{steps}.yaml"
    path.write_text(
        f"version: 1\nsteps: {steps}\ntargets:\n"
        "  - {point: wheel_center, direction: {axis: z}, start: -40, stop: 120}\n"
        "  - {point: trackrod_inboard, direction: {axis: y}, start: -40, stop: 40}\n"
    )
    return path


# -- the child: one CLI run, split -------------------------------------------------------


def child(sweep: str, out: str) -> None:
    """Run `pin-susp sweep` once in this process and print its split as JSON."""
    started = time.perf_counter()
    import pin_susp.cli.commands.sweep as command  # noqa: F401 (its imports, as the CLI's)
    import pin_susp.io.tables as tables
    import pin_susp.model.sweep as sweeps
    import pin_susp.solve.bulk as bulk
    import pin_susp.subjects.assembly as assembly
    import pin_susp.subjects.subject as subject
    from pin_susp.cli import main

    imported = time.perf_counter()
    spent: dict[str, float] = {}

    def timed(owner, name: str, phase: str, before=None) -> None:
        original = getattr(owner, name)

        def wrapper(*args, **kwargs):
            t = time.perf_counter()
            if before is not None:
                before(*args)
            try:
                return original(*args, **kwargs)
            finally:
                spent[phase] = spent.get(phase, 0.0) + time.perf_counter() - t

        setattr(owner, name, wrapper)

    def writer_import(stream, *_) -> None:
        if stream.fast and "pyarrow" not in sys.modules:
            t = time.perf_counter()
            load = getattr(tables, "_compute", None)  # pyarrow and its kernels
            if load is not None:
                load()
            else:  # before tables._compute: what _arrow_rows imported
                import pyarrow.compute  # noqa: F401

            spent["writer import"] = time.perf_counter() - t

    timed(subject, "load_subject", "build")
    timed(sweeps, "load_sweep", "sweep file")
    timed(bulk.Tree, "__init__", "batched set-up")
    timed(bulk.Rows, "__init__", "batched set-up")
    timed(assembly.Assembly, "solve_steps", "solve")
    timed(assembly.Assembly, "sweep_results", "columns")
    timed(tables.CsvStream, "write", "write", writer_import)
    code = main(["sweep", "examples/double_wishbone.yaml", sweep, "-o", out, "-q"])
    total = time.perf_counter() - started
    if code:
        raise SystemExit(code)
    spent["solve"] = spent.get("solve", 0.0) - spent.get("batched set-up", 0.0)
    spent["write"] = spent.get("write", 0.0) - spent.get("writer import", 0.0)
    spent["import"] = imported - started
    spent["other"] = total - sum(v for k, v in spent.items() if k != "sweep file")
    spent["total"] = total
    print(json.dumps(spent))


# -- the parent --------------------------------------------------------------------------


ROOT = Path(__file__).resolve().parent.parent


def run_once(sweep: Path, out: Path, env: dict, root: Path = ROOT) -> dict:
    started = time.perf_counter()
    done = subprocess.run(
        [sys.executable, __file__, "--child", str(sweep), str(out)],
        check=True,
        capture_output=True,
        text=True,
        cwd=root,
        env=env,
    )
    wall = time.perf_counter() - started
    split = json.loads(done.stdout.strip().splitlines()[-1])
    split["start"] = wall - split.pop("total")
    split["wall"] = wall
    return split


def child_env(folder: Path, bytecode: bool, root: Path = ROOT) -> dict:
    """The children's environment: the checkout ``root`` first on the path; with
    ``bytecode``, every module's bytecode cached under ``folder`` (PYTHONPYCACHEPREFIX:
    as installed, where `make` compiles it) even where the environment says not to
    write it (PYTHONDONTWRITEBYTECODE: each run then compiles pin_susp from source)."""
    path = os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")])
    env = dict(os.environ, PYTHONPATH=path)
    if bytecode:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = str(folder / f"pycache_{abs(hash(str(root)))}")
    return env


def measure(steps: tuple[int, ...], rounds: int, bytecode: bool = True, roots=(ROOT,)) -> list:
    """Each length's best run (by wall time) over ``rounds`` rounds in alternation, after
    a warm-up run (which writes the bytecode), for each checkout in ``roots`` (this one,
    then any other: ``--against``), the checkouts in alternation too."""
    import shutil

    folder = Path(tempfile.mkdtemp(prefix="bench_cli_"))
    try:
        files = {n: sweep_file(folder, n) for n in steps}
        envs = [child_env(folder, bytecode, root) for root in roots]
        for root, env in zip(roots, envs, strict=True):
            run_once(files[steps[0]], folder / "out.csv", env, root)
        best: list[dict[int, dict]] = [{} for _ in roots]
        for _ in range(rounds):
            for n in steps:
                for k, (root, env) in enumerate(zip(roots, envs, strict=True)):
                    split = run_once(files[n], folder / "out.csv", env, root)
                    if n not in best[k] or split["wall"] < best[k][n]["wall"]:
                        best[k][n] = split
        return best
    finally:
        shutil.rmtree(folder)


def baseline_us(steps: int = 101) -> float:
    """The point-based formulation per step (bench_sweep.baseline, analytic Jacobian)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from bench_sweep import baseline, issue_sweep

    import pin_susp

    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml")
    return baseline(corner, issue_sweep(steps), "analytic", 2)["time_us_per_step"]


def marginals(best: dict[int, dict], net: bool = False) -> dict[str, float]:
    """us per step between lengths: of the best wall times, or (``net``) of the wall
    times less the interpreter's start and the imports, which do not depend on the
    length (the shared machine's noise is mostly there)."""

    def work(split):
        return split["wall"] - (split["start"] + split["import"] if net else 0.0)

    out = {}
    for short, long in PAIRS:
        if short in best and long in best:
            extra = work(best[long]) - work(best[short])
            out[f"{short}-{long}"] = extra / (long - short) * 1e6
    return out


def show(best: dict, margin: dict, net: dict, base: float | None, bytecode: bool) -> None:
    print(
        "pin-susp sweep examples/double_wishbone.yaml (bump + steer: wheel centre z -40...120 "
        "mm, rack -40...40 mm) to CSV, best of the rounds, s"
        + ("" if bytecode else " (bytecode as the environment has it)")
        + ":"
    )
    print(f"  {'steps':>6s} {'wall':>6s}  " + " ".join(f"{p[:10]:>10s}" for p in PHASES))
    for n, split in sorted(best.items()):
        cells = " ".join(f"{split.get(p, 0.0):10.3f}" for p in PHASES)
        print(f"  {n:6d} {split['wall']:6.3f}  {cells}")
    print(
        "marginal cost per step (difference of best wall times over the extra steps; "
        "in brackets, less start and import):"
    )
    for pair, us in margin.items():
        flag = "" if us <= 40 else "  (target <= 40 us)"
        print(f"  {pair:>12s} steps: {us:6.1f} us per step ({net[pair]:5.1f}){flag}")
    if 11 in best:
        fixed = best[11]
        named = ", ".join(f"{p} {fixed.get(p, 0.0) * 1e3:.0f} ms" for p in PHASES)
        print(f"fixed cost (the 11-step run, {fixed['wall'] * 1e3:.0f} ms): {named}")
    paid = {n: s for n, s in best.items() if s.get("writer import")}
    if paid:
        n = min(paid)
        print(
            f"  paid by longer tables: writer import {paid[n]['writer import'] * 1e3:.0f} ms "
            f"(from {n} steps here: tables.FAST_CELLS cells), batched set-up "
            f"{best[max(best)].get('batched set-up', 0.0) * 1e3:.0f} ms (from bulk.MIN_STEPS)"
        )
    if base is not None and margin:
        worst = max(margin.get("201-2001", 0.0), margin.get("2001-20001", 0.0))
        low, high = OPEN_KINEMATICS_MS
        print(
            f"baseline in this process: point-based least_squares (analytic Jacobian) "
            f"{base:.0f} us per step = {base / worst:.0f}x the CLI's worst marginal "
            f"({worst:.1f} us); open-kinematics' {low:.0f}-{high:.0f} ms per step "
            f"(measured outside) = {low * 1e3 / worst:.0f}-{high * 1e3 / worst:.0f}x"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="runs of each length")
    parser.add_argument(
        "--steps", default=",".join(map(str, STEPS)), help="comma-separated sweep lengths"
    )
    parser.add_argument("--no-baseline", action="store_true", help="skip the point-based run")
    parser.add_argument(
        "--as-is",
        action="store_true",
        help="the environment's bytecode setting (default: bytecode cached, as installed)",
    )
    parser.add_argument("--json", metavar="OUT.json", help="also write the figures as JSON")
    parser.add_argument(
        "--against",
        metavar="CHECKOUT",
        type=Path,
        help="another checkout of pin_susp (e.g. a git worktree of main) run in alternation: "
        "its figures and each length's wall-time ratio this / it",
    )
    parser.add_argument("--child", nargs=2, metavar=("SWEEP", "OUT"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(*args.child)
        return
    steps = tuple(int(s) for s in args.steps.split(","))
    roots = (ROOT,) if args.against is None else (ROOT, args.against.resolve())
    bests = measure(steps, args.rounds, bytecode=not args.as_is, roots=roots)
    base = None if args.no_baseline else baseline_us()
    figures = {"baseline_us_per_step": base, "bytecode_cached": not args.as_is}
    for root, best in zip(roots, bests, strict=True):
        margin, net = marginals(best), marginals(best, net=True)
        print(f"\n{root}:")
        show(best, margin, net, base, not args.as_is)
        figures[str(root)] = {
            "best": best,
            "marginal_us_per_step": margin,
            "marginal_less_start_and_import": net,
        }
    if len(bests) == 2:
        ours, theirs = bests
        ratios = {n: ours[n]["wall"] / theirs[n]["wall"] for n in ours}
        figures["wall_ratio_this_over_against"] = ratios
        cells = ", ".join(f"{n} steps {r:.2f}" for n, r in ratios.items())
        print(f"\nwall time, this checkout / {roots[1]}: {cells}")
    if args.json:
        Path(args.json).write_text(json.dumps(figures, indent=2))
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
