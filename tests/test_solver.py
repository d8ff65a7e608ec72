"""The Newton closure solve against an independent point-based formulation,
a closed-form mechanism, and finite differences of its own rows."""

import numpy as np
import pinocchio as pin
import pytest
from conftest import EXAMPLES, example
from pointwise import PointwiseCorner, spec_metrics

import pin_susp
from pin_susp.constraints import PointTarget


def test_bump_steer_sweep_matches_pointwise_formulation(corner):
    results = corner.run_sweep(EXAMPLES / "bump_steer.yaml")
    assert results["solver_converged"].all()
    assert np.max(results["solver_max_residual"]) <= 1e-9  # mm

    data = example("double_wishbone.yaml")
    ref = PointwiseCorner(data)
    wc_design = corner.design_positions["wheel_center"][2] * 1e3
    sweep = example("bump_steer.yaml")
    bump = np.linspace(sweep["targets"][0]["start"], sweep["targets"][0]["stop"], sweep["steps"])
    rack = np.linspace(sweep["targets"][1]["start"], sweep["targets"][1]["stop"], sweep["steps"])
    x = None
    for i in range(sweep["steps"]):
        x, residual = ref.solve(wc_design + bump[i], rack[i], x)
        assert residual < 1e-10
        p = ref.points(x)
        for name in corner.point_names:
            for j, axis in enumerate("xyz"):
                assert results[f"{name}_{axis}"][i] == pytest.approx(p[name][j], abs=1e-8)
        for name, value in spec_metrics(p, 1.0).items():
            assert results[name][i] == pytest.approx(value, abs=1e-8), name
        assert results["wheel_travel"][i] == pytest.approx(bump[i], abs=1e-8)


def test_fixed_toe_link_matches_pointwise_formulation():
    corner = pin_susp.Corner(EXAMPLES / "fixed_toe_link.yaml")
    results = corner.run_sweep(EXAMPLES / "bump.yaml")
    ref = PointwiseCorner(example("fixed_toe_link.yaml"))
    x = None
    for i in range(len(results)):
        x, _ = ref.solve(results["wheel_center_z"][i], 0.0, x)
        for name, value in spec_metrics(ref.points(x), 1.0).items():
            assert results[name][i] == pytest.approx(value, abs=1e-8), name


def parallelogram() -> dict:
    """Equal, parallel wishbones and trackrod, pivots along X: the upright translates."""
    g = example("double_wishbone.yaml")
    g["hardpoints"] = {
        "lower_wishbone_inboard_front": {"x": 200, "y": 300, "z": 200},
        "lower_wishbone_inboard_rear": {"x": -200, "y": 300, "z": 200},
        "lower_wishbone_outboard": {"x": 0, "y": 700, "z": 200},
        "upper_wishbone_inboard_front": {"x": 200, "y": 300, "z": 500},
        "upper_wishbone_inboard_rear": {"x": -200, "y": 300, "z": 500},
        "upper_wishbone_outboard": {"x": 0, "y": 700, "z": 500},
        "trackrod_inboard": {"x": 120, "y": 300, "z": 350},
        "trackrod_outboard": {"x": 120, "y": 700, "z": 350},
        "axle_inboard": {"x": 0, "y": 700, "z": 350},
        "axle_outboard": {"x": 0, "y": 800, "z": 348},
    }
    return g


@pytest.mark.parametrize("dz", [-60.0, -10.0, 25.0, 80.0])
def test_parallelogram_corner_follows_its_circle(dz):
    """LBJ swings on a 400 mm arm: Δy = 400·(cos(asin(dz/400)) − 1); camber and toe fixed."""
    corner = pin_susp.Corner(parallelogram())
    design = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 0.0), pin_susp.Target("trackrod_inboard", "y", 0.0)]
    )
    pose = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", dz), pin_susp.Target("trackrod_inboard", "y", 0.0)]
    )
    assert pose.converged and pose.max_residual <= 1e-9
    dy = 400.0 * (np.cos(np.arcsin(dz / 400.0)) - 1.0)
    for name in ("lower_wishbone_outboard", "upper_wishbone_outboard", "wheel_center"):
        moved = pose.points[name] - design.points[name]
        np.testing.assert_allclose(moved, [0.0, dy, dz], atol=1e-9)
    # The axle drops 2 mm over 100 mm outboard: the wheel top leans out, +1.1458°.
    assert pose.metrics["camber"] == pytest.approx(np.degrees(np.arctan2(2.0, 100.0)), abs=1e-10)
    assert pose.metrics["roadwheel_angle"] == pytest.approx(0.0, abs=1e-10)
    assert pose.metrics["wheel_travel"] == pytest.approx(dz, abs=1e-10)


def test_pure_rack_travel_turns_the_parallelogram_upright_about_its_kingpin():
    """With the wheel centre held, rack travel steers the wheel; toe-out for +Y on the left
    when the trackrod is ahead of the axle."""
    corner = pin_susp.Corner(parallelogram())
    pose = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 0.0), pin_susp.Target("trackrod_inboard", "y", 10.0)]
    )
    assert pose.converged
    # Vertical kingpin through x = 0; trackrod 120 mm ahead: the arm turns by ≈ asin(10/120).
    assert pose.metrics["roadwheel_angle"] < -4.0
    # The upright only rotates about the (vertical) steering axis: both ball joints stay put.
    np.testing.assert_allclose(pose.points["upper_wishbone_outboard"], [0, 700, 500], atol=1e-9)
    np.testing.assert_allclose(pose.points["lower_wishbone_outboard"], [0, 700, 200], atol=1e-9)
    tro = pose.points["trackrod_outboard"]
    tri = pose.points["trackrod_inboard"]
    assert np.linalg.norm(tro - tri) == pytest.approx(400.0, abs=1e-9)
    # TRO stays on its 120 mm circle about the kingpin at height 350.
    assert np.hypot(tro[0], tro[1] - 700.0) == pytest.approx(120.0, abs=1e-9)
    turn = np.degrees(np.arctan2(-(tro[1] - 700.0), tro[0]))
    assert pose.metrics["roadwheel_angle"] == pytest.approx(turn, abs=1e-9)


def rows_of(corner, targets):
    solver = corner.solver_for(targets)
    return solver, solver.rows


@pytest.mark.parametrize("point", ["wheel_center", "contact_patch_center", "trackrod_outboard"])
def test_every_jacobian_row_matches_central_differences(corner, point):
    targets = [
        pin_susp.Target(point, [0.3, -0.2, 0.9], 0.0),
        pin_susp.Target("trackrod_inboard", "y", 0.0),
    ]
    solver = corner.solver_for(targets)
    q = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 35.0), pin_susp.Target("trackrod_inboard", "y", -8.0)]
    ).q
    solver.evaluate(q)
    J = solver.jacobian.copy()
    assert J.shape == (6, corner.model.nv)
    h = 1e-6
    for i in range(corner.model.nv):
        e = np.zeros(corner.model.nv)
        e[i] = h
        solver.evaluate(pin.integrate(corner.model, q, e))
        plus = solver.residual.copy()
        solver.evaluate(pin.integrate(corner.model, q, -e))
        minus = solver.residual.copy()
        np.testing.assert_allclose(J[:, i], (plus - minus) / (2 * h), atol=1e-8)
    assert isinstance(solver.rows[-1], PointTarget)


def test_warm_started_steps_take_few_iterations(corner):
    results = corner.run_sweep(EXAMPLES / "bump_steer.yaml")
    assert np.max(results["solver_iterations"][1:]) <= 4
    assert np.median(results["solver_iterations"]) <= 4


def test_absolute_and_vector_targets_agree_with_relative_axis_targets(corner):
    wc = corner.design_positions["wheel_center"] * 1e3
    relative = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 20.0), pin_susp.Target("trackrod_inboard", "y", 5.0)]
    )
    absolute = corner.solve_pose(
        [
            pin_susp.Target("wheel_center", [0, 0, 2.0], wc[2] + 20.0, mode="absolute"),
            pin_susp.Target("trackrod_inboard", "y", 200.0 + 5.0, mode="absolute"),
        ]
    )
    for name in relative.points:
        np.testing.assert_allclose(absolute.points[name], relative.points[name], atol=1e-9)


def test_contact_patch_target_holds_its_point(corner):
    pose = corner.solve_pose(
        [
            pin_susp.Target("contact_patch_center", "z", 30.0),
            pin_susp.Target("trackrod_inboard", "y", 3.0),
        ]
    )
    design = corner.design_positions["contact_patch_center"][2] * 1e3
    assert pose.points["contact_patch_center"][2] == pytest.approx(design + 30.0, abs=1e-9)


def test_unreachable_step_is_flagged_and_the_sweep_goes_on(corner):
    sweep = {
        "steps": 3,
        "targets": [
            {"point": "wheel_center", "direction": {"axis": "z"}, "values": [10.0, 900.0, 20.0]},
            {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": [0.0, 0.0, 0.0]},
        ],
    }
    results = corner.run_sweep(sweep)
    assert list(results["solver_converged"]) == [True, False, True]
    assert results["solver_max_residual"][1] > 1e-3
    assert np.isnan(results["camber"][1]) and np.isnan(results["wheel_center_z"][1])
    assert results["wheel_travel"][2] == pytest.approx(20.0, abs=1e-9)
    assert results["solver_iterations"][1] > 12  # it subdivided before giving up


def test_relative_target_along_a_reversed_vector_moves_the_other_way(corner):
    up = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 20.0), pin_susp.Target("trackrod_inboard", "y", 0)]
    )
    down_vector = corner.solve_pose(
        [
            pin_susp.Target("wheel_center", [0, 0, -3.0], -20.0),
            pin_susp.Target("trackrod_inboard", [0, -1.0, 0], 0.0),
        ]
    )
    np.testing.assert_allclose(
        down_vector.points["wheel_center"], up.points["wheel_center"], atol=1e-9
    )
    assert up.metrics["wheel_travel"] == pytest.approx(20.0, abs=1e-10)


def test_singular_jacobian_takes_a_bounded_damped_step(corner):
    """At a lock-up J has no inverse: the step is damped least squares, finite and bounded."""
    from pin_susp.solve.solver import MAX_STEP

    solver = corner.solver_for(
        [pin_susp.Target("wheel_center", "z", 0.0), pin_susp.Target("trackrod_inboard", "y", 0)]
    )
    solver.evaluate(corner.q_design)
    solver.jacobian[5] = solver.jacobian[4]  # two equal rows: rank 5
    solver.residual[:] = [0, 0, 0, 0, 1e-3, 2e-3]
    dv = solver._step()
    assert np.all(np.isfinite(dv)) and np.max(np.abs(dv)) <= MAX_STEP
    # it moves the residual of the duplicated row towards the mean of its two targets
    change = solver.jacobian @ dv
    assert change[4] == pytest.approx(-1.5e-3, rel=1e-3)
    np.testing.assert_allclose(change[:4], 0.0, atol=1e-6)  # λ = |r|² bends it slightly
