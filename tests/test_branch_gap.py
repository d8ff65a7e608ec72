"""A step after a gap of failed steps is checked against the design branch like any
other (issue 24, 11): an upper-wishbone pivot placed on the lower ball joint.

With the pivot on the LBJ, the upper ball joint's declared branch plane (upper pivot
axis, LBJ) is undefined at design, so the loop must be told apart from its other
crank: the LBJ's circle about the lower pivot meets the upright's sphere about the
UBJ on either side of the plane (lower pivot axis, UBJ). The tests recompute that
signed volume — and the trackrod's — from the CSV's own point columns.
"""

import csv

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example

import pin_susp
from pin_susp.cli import main
from pin_susp.model.sweep import load_sweep
from pin_susp.solve.bulk import on_branches
from pin_susp.solve.march import march
from pin_susp.solve.solver import NewtonSolver

LBJ = {"x": 0, "y": 900, "z": 200}  # the example's lower ball joint
PIVOTS = ("upper_wishbone_inboard_front", "upper_wishbone_inboard_rear")


def pivot_on_lbj(tmp_path, pivot: str):
    g = example("double_wishbone.yaml")
    g["hardpoints"][pivot] = dict(LBJ)
    path = tmp_path / "pivot_on_lbj.yaml"
    path.write_text(yaml.safe_dump(g, sort_keys=False))
    return path, g["hardpoints"]


def bump_steer(tmp_path, steps: int):
    s = yaml.safe_load((EXAMPLES / "bump_steer.yaml").read_text())
    s["steps"] = steps
    path = tmp_path / f"bump_steer_{steps}.yaml"
    path.write_text(yaml.safe_dump(s))
    return path


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    cell = {"": "nan", "True": "1", "False": "0"}
    return {k: np.array([float(cell.get(r[k], r[k])) for r in rows]) for k in rows[0]}


def volume(a, b, c, d):
    """Signed volume (×6) of the tetrahedron a, b, c, d, rows of points (n, 3)."""
    return np.einsum("ni,ni->n", np.cross(b - a, c - a), d - a)


def loops(columns, hardpoints):
    """The two loops' signed volumes at every step, from the CSV's points (chassis
    points from the geometry file) and at design."""

    def at(name):
        if f"{name}_x" in columns:
            return np.column_stack([columns[f"{name}_{a}"] for a in "xyz"])
        return np.tile([hardpoints[name][a] for a in "xyz"], (len(columns["step_index"]), 1))

    def design(name):
        return np.array([[hardpoints[name][a] for a in "xyz"]], dtype=float)

    sets = {
        "upright": (  # the side of the plane (lower pivot axis, UBJ) the LBJ is on
            "lower_wishbone_inboard_front",
            "lower_wishbone_inboard_rear",
            "upper_wishbone_outboard",
            "lower_wishbone_outboard",
        ),
        "trackrod": (  # the side of the plane (kingpin, rack end) the steering arm is on
            "lower_wishbone_outboard",
            "upper_wishbone_outboard",
            "trackrod_inboard",
            "trackrod_outboard",
        ),
    }
    return {
        name: (volume(*(at(n) for n in points)), volume(*(design(n) for n in points))[0])
        for name, points in sets.items()
    }


def sweep(tmp_path, geometry, steps: int, capsys):
    out = tmp_path / f"out_{steps}.csv"
    code = main(["sweep", str(geometry), str(bump_steer(tmp_path, steps)), "-o", str(out)])
    _, err = capsys.readouterr()
    assert code == 1, err  # some steps are out of reach on the design branch
    return read_csv(out), err


def assert_on_design_branch(columns, hardpoints):
    ok = columns["solver_converged"] == 1.0
    assert ok.sum() >= 10
    for name, (values, design) in loops(columns, hardpoints).items():
        assert abs(design) > 1e4, name  # mm³: the design is well clear of a toggle
        assert np.all(values[ok] * design > 0.0), (
            name,
            np.flatnonzero(ok & (values * design <= 0)),
        )
        assert np.all(np.abs(values[ok]) > 1e3), name


@pytest.mark.parametrize("pivot", PIVOTS)
def test_no_step_after_a_gap_is_accepted_with_the_upright_flipped(tmp_path, capsys, pivot):
    """Step by step (41 steps): steps 21–34 (front) are out of reach on the design
    branch; 35–40 were accepted with the UBJ below the LBJ (KPI 142°) — flagged now."""
    geometry, hardpoints = pivot_on_lbj(tmp_path, pivot)
    columns, err = sweep(tmp_path, geometry, 41, capsys)
    assert_on_design_branch(columns, hardpoints)
    ok = columns["solver_converged"] == 1.0
    assert not ok[35:].any()
    assert ok[:17].all()  # the design branch's own travel is still solved
    assert np.all(
        columns["upper_wishbone_outboard_z"][ok] > columns["lower_wishbone_outboard_z"][ok]
    )
    assert "did not converge" in err


@pytest.mark.parametrize("pivot", PIVOTS)
def test_a_long_sweep_after_a_gap_stays_on_the_design_branch(tmp_path, capsys, pivot):
    """The same through the long-sweep path (401 steps: bulk.solve_sweep first)."""
    geometry, hardpoints = pivot_on_lbj(tmp_path, pivot)
    columns, _ = sweep(tmp_path, geometry, 401, capsys)
    assert_on_design_branch(columns, hardpoints)
    ok = columns["solver_converged"] == 1.0
    assert not ok[350:].any()  # the 41-step sweep's steps 35–40


def test_the_loop_of_a_pivot_on_the_lbj_is_guarded_by_its_other_crank(tmp_path):
    """The upper ball joint's branch falls back to the plane (lower pivot axis, UBJ)
    with the design's sign; the batched check refuses the flipped poses that a march
    guarded by the trackrod alone (the check before the fix) accepted."""
    geometry, hardpoints = pivot_on_lbj(tmp_path, PIVOTS[0])
    corner = pin_susp.Corner(geometry)
    loop = next(b for b in corner.branches if b.name == "upper_ball_joint")
    assert not loop.degenerate
    assert [p.name for p in loop.points] == [
        "lower_wishbone_inboard_front",
        "lower_wishbone_inboard_rear",
        "upper_wishbone_outboard",
        "lower_wishbone_outboard",
    ]
    p = {n: np.array([[hardpoints[n][a] for a in "xyz"]], dtype=float) for n in hardpoints}
    assert loop.sign == np.sign(volume(*(p[q.name] for q in loop.points))[0])

    s = load_sweep(str(EXAMPLES / "bump_steer.yaml"))
    solver = corner.solver_for(s.targets)
    values = corner.target_values(s.targets)
    start = corner.target_values([t.at_design() for t in s.targets])[0]
    q19, q20 = (x.q for x in march(solver, values[:21], corner.q_design, start)[19:])
    tangents = []
    for q, v in ((q19, values[19]), (q20, values[20])):
        solver.set_targets(v)
        solver.evaluate(q)
        tangents.append(solver.tangent())
    # the guess the march made for step 35 after the gap (extrapolating steps 19, 20 as
    # if step 35 followed step 20) and Newton guarded by the trackrod alone: the old check
    guess = (
        5.0 * q19 - 4.0 * q20 + (2.0 * tangents[0] + 4.0 * tangents[1]) @ (values[35] - values[20])
    )
    trackrod_only = [b for b in corner.branches if b.name == "trackrod"]
    old = NewtonSolver(corner.kin, corner.closures, solver.targets, trackrod_only)
    old.set_targets(values[35])
    flipped = old.newton(guess)
    assert flipped.converged and flipped.max_residual < 1e-12
    corner.kin.update_positions(flipped.q)
    assert loop.chirality(corner.kin) * loop.sign < -0.05  # the upright upside down
    p = corner.motion([flipped.q])
    assert p["upper_wishbone_outboard"].val[0][2] < p["lower_wishbone_outboard"].val[0][2]
    assert on_branches(solver, np.array([q19, q20]))
    assert not on_branches(solver, flipped.q[None])  # the batched check
    solver.set_targets(values[35])
    assert solver.newton(flipped.q).branch == "upper_ball_joint"  # the step-by-step one


def test_an_axle_with_the_pivot_on_the_lbj_guards_both_uprights(tmp_path, capsys):
    """The axle's corners (prefixed by side) keep the fallback: both upper ball joints
    are guarded by the lower pivot's plane, and a heave sweep's converged steps keep
    the design's sign on both sides (from the CSV's points)."""
    from pin_susp.subjects.axle import AxleModel, load_axle

    data = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    data["hardpoints"]["left"][PIVOTS[0]] = dict(LBJ)  # the right side mirrors the left
    path = tmp_path / "axle.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    model = AxleModel(load_axle(path))
    for side in ("left", "right"):
        loop = next(b for b in model.branches if b.name == f"{side}_upper_ball_joint")
        assert not loop.degenerate
        assert loop.points[-1].name == f"{side}_lower_wishbone_outboard"
    sweep = tmp_path / "heave.yaml"
    sweep.write_text(
        yaml.safe_dump(
            {
                "version": 1,
                "steps": 41,
                "targets": [
                    {"quantity": "heave", "start": -40, "stop": 60},
                    {"quantity": "roll", "start": 0, "stop": 0},
                    {
                        "point": "trackrod_inboard",
                        "side": "left",
                        "direction": {"axis": "y"},
                        "start": -10,
                        "stop": 10,
                    },
                ],
            }
        )
    )
    out = tmp_path / "axle.csv"
    assert main(["sweep", str(path), str(sweep), "-o", str(out), "-q"]) == 1
    columns = read_csv(out)
    ok = columns["solver_converged"] == 1.0
    assert ok.sum() >= 10 and not ok[35:].any()
    names = (  # the side of the plane (lower pivot axis, UBJ) the LBJ is on
        "lower_wishbone_inboard_front",
        "lower_wishbone_inboard_rear",
        "upper_wishbone_outboard",
        "lower_wishbone_outboard",
    )
    for side, mirror in (("left", 1.0), ("right", -1.0)):  # the right: y negated
        at = [np.column_stack([columns[f"{side}_{n}_{a}"] for a in "xyz"]) for n in names]
        drawn = data["hardpoints"]["left"]
        design = volume(
            *(np.array([[drawn[n]["x"], mirror * drawn[n]["y"], drawn[n]["z"]]]) for n in names)
        )
        assert abs(design[0]) > 1e4
        assert np.all(volume(*at)[ok] * design[0] > 0.0), side


def test_validate_says_an_engine_on_the_flipped_assembly_lands_on_another_branch(tmp_path, capsys):
    """MuJoCo closes step 21 of the pivot-on-LBJ corner with the upright flipped over:
    validate checks its points with the loop's own points, fallback included."""
    pytest.importorskip("mujoco")
    path, _ = pivot_on_lbj(tmp_path, PIVOTS[0])
    assert main(["validate", str(path), str(EXAMPLES / "bump_steer.yaml")]) == 1
    out = capsys.readouterr().out
    assert "mujoco: lands on another assembly branch at steps 21," in out, out
    assert "(the upper_ball_joint loop)" in out and "DISAGREES" not in out
