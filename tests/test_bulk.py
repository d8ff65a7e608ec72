"""A long sweep solved for every step at once (pin_susp.solve.bulk) against Pinocchio itself,
the step-by-step march, and the independent point-based formulation."""

import numpy as np
import pinocchio as pin
import pytest
from conftest import EXAMPLES, example, torsion_bar
from pointwise import PointwiseCorner

import pin_susp
import pin_susp.subjects.assembly
import pin_susp.subjects.corner
from pin_susp.model.sweep import Sweep, Target
from pin_susp.solve import bulk
from pin_susp.solve import march as marching
from pin_susp.solve.bulk import Frames, Tree
from pin_susp.subjects.corner import Results

CORNERS = [
    "double_wishbone.yaml",
    "camber_shim.yaml",
    "pushrod_rocker.yaml",
    "macpherson.yaml",
    "multilink_front.yaml",
    "multilink_rear.yaml",
    "fixed_toe_link.yaml",
    "semi_trailing_arm.yaml",
]


def build(name: str) -> pin_susp.Corner:
    return pin_susp.Corner(EXAMPLES / name, warn=False)


def long_sweep(corner, steps: int = 401, bump=(-40.0, 60.0), rack=(-10.0, 10.0), curve=False):
    targets = [Target("wheel_center", "z", np.linspace(*bump, steps))]
    if corner.geometry.steering == "rack":
        values = np.linspace(*rack, steps)
        if curve:  # a path that is no straight line in target space
            values = rack[1] * np.sin(np.linspace(0.0, 3.0 * np.pi, steps))
        targets.append(Target("trackrod_inboard", "y", values))
    return Sweep(targets, "long")


def step_by_step(monkeypatch):
    """Make a subject's solve_steps (assembly.py) march every step (the reference)."""
    march = marching.march
    monkeypatch.setattr(
        pin_susp.subjects.assembly, "march", lambda *a, **k: march(*a, **{**k, "bulk": False})
    )


@pytest.mark.parametrize("name", CORNERS)
def test_tree_matches_pinocchio_frames_and_jacobians(name):
    """Every frame's position and LOCAL_WORLD_ALIGNED Jacobian, and every joint's
    placement and Jacobian, at random configurations: numpy's evaluation of the
    model's tree against Pinocchio's own."""
    corner = build(name)
    model = corner.model
    data = model.createData()
    tree = Tree(model)
    assert tree.supported
    q = corner.q_design + np.random.default_rng(7).normal(0.0, 0.4, (9, model.nq))
    frames = Frames(tree, list(range(model.nframes)))
    P, J = frames.evaluate(q)
    R, o = tree.placements(q)
    a = tree.axes(R)
    for n in range(len(q)):
        pin.computeJointJacobians(model, data, q[n])
        pin.updateFramePlacements(model, data)
        for k, f in enumerate(frames.ids):
            np.testing.assert_allclose(P[k][n], data.oMf[f].translation, rtol=0, atol=1e-15)
            expected = pin.getFrameJacobian(model, data, f, pin.LOCAL_WORLD_ALIGNED)
            expected = expected.reshape(6, model.nv)[:3]
            np.testing.assert_allclose(J[k][n], expected, rtol=0, atol=1e-15)
        for j in range(1, model.njoints):
            np.testing.assert_allclose(R[j, n], data.oMi[j].rotation, rtol=0, atol=1e-15)
            np.testing.assert_allclose(o[j, n], data.oMi[j].translation, rtol=0, atol=1e-15)
            expected = pin.getJointJacobian(model, data, j, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(
                tree.twist_jacobian(j, o, a)[n], expected.reshape(6, model.nv), atol=1e-15
            )


@pytest.mark.parametrize("name", CORNERS)
def test_long_sweep_equals_the_step_by_step_march(name, monkeypatch):
    """Every column of a 401-step sweep, solved at once, equals the same sweep marched
    step by step (to the solver's tolerance), and every step converged here."""
    corner = build(name)
    sweep = long_sweep(corner)
    tangents = []
    solutions = corner.solve_steps(sweep, tangents=tangents)
    assert all(s.converged for s in solutions)
    ours = Results.from_solutions(corner, solutions, sweep, tangents or None)
    step_by_step(monkeypatch)
    reference = corner.run_sweep(sweep)
    assert ours.columns.keys() == reference.columns.keys()
    for key, expected in reference.columns.items():
        got = np.asarray(ours.columns[key])
        if key in ("solver_iterations", "solver_max_residual"):
            continue
        expected = np.asarray(expected)
        if expected.dtype.kind != "f":
            np.testing.assert_array_equal(got, expected, err_msg=key)
            continue
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=key)
        # (an instant centre 20 km away carries the roundoff of a near-parallel pair)
        scale = 1.0 + np.nanmax(np.abs(expected), initial=0.0)
        np.testing.assert_allclose(got, expected, rtol=1e-7, atol=1e-9 * scale, err_msg=key)
    assert np.max(ours["solver_max_residual"]) <= 1e-9  # mm


def test_solved_at_once_rather_than_step_by_step(monkeypatch):
    """The example's long sweep takes the at-once path (a test that the path above is
    not the march's in disguise): the march sees only the coarse steps."""
    corner = build("double_wishbone.yaml")
    sweep = long_sweep(corner, steps=1001)
    seen = []
    march = marching.march

    def counting(solver_, values, *args, **kwargs):
        seen.append(len(values))
        return march(solver_, values, *args, **kwargs)

    monkeypatch.setattr(marching, "march", counting)
    monkeypatch.setattr(pin_susp.subjects.assembly, "march", counting)
    solutions = corner.solve_steps(sweep)
    assert all(s.converged for s in solutions)
    assert seen[0] == 1001 and max(seen[1:]) <= 2 * bulk.COARSE_STEPS


def test_each_step_closes_in_pinocchio_and_matches_the_point_based_solve():
    """The at-once solution's residual recomputed by Pinocchio (closures and targets),
    and its points against the point-based formulation solved with scipy."""
    corner = build("double_wishbone.yaml")
    sweep = long_sweep(corner, steps=601, curve=True)
    results = corner.run_sweep(sweep)
    assert results["solver_converged"].all()
    solutions = corner.solve_steps(sweep)
    s = corner.solver_for(sweep.targets, sweep.source)
    values = corner.target_values(sweep.targets)
    for i in range(0, 601, 25):
        s.set_targets(values[i])
        s.evaluate(solutions[i].q)
        assert np.abs(s.residual).max() <= 1e-12  # m
    reference = PointwiseCorner(example("double_wishbone.yaml"))
    design_z = corner.design_positions["wheel_center"][2] * 1e3
    x = None
    for i in range(0, 601, 50):
        bump = results["wheel_center_z"][i]
        rack = sweep.targets[1].values[i]
        x, residual = reference.solve(bump, rack, x)
        assert residual < 1e-10
        points = reference.points(x)
        for name in ("upper_wishbone_outboard", "trackrod_outboard", "axle_outboard"):
            for j, axis in enumerate("xyz"):
                assert results[f"{name}_{axis}"][i] == pytest.approx(points[name][j], abs=1e-8)
    assert results["wheel_center_z"][0] == pytest.approx(design_z - 40.0, abs=1e-9)


def test_a_sweep_past_the_linkage_reach_is_flagged_as_step_by_step(monkeypatch):
    """Steps the linkage cannot reach: the at-once path gives up, and the march's flags
    and explanations are the result (same as marching from the start)."""
    corner = build("pushrod_rocker.yaml")
    sweep = long_sweep(corner, steps=241, bump=(-40.0, 160.0))
    ours = corner.run_sweep(sweep)
    assert not ours["solver_converged"].all()
    step_by_step(monkeypatch)
    reference = corner.run_sweep(sweep)
    np.testing.assert_array_equal(ours["solver_converged"], reference["solver_converged"])
    np.testing.assert_array_equal(ours["wheel_center_z"], reference["wheel_center_z"])


def test_a_branch_flip_inside_a_coarse_segment_is_refused():
    """A step off a loop's design assembly found at once is refused (then marched)."""
    corner = build("double_wishbone.yaml")
    s = corner.solver_for(long_sweep(corner).targets, "long")
    qs = np.array([corner.q_design, corner.q_design])
    assert bulk.on_branches(s, qs)
    loop = s.branches.loops[0]
    loop.sign = -loop.sign
    try:
        assert not bulk.on_branches(s, qs)
    finally:
        loop.sign = -loop.sign


def test_vectorised_branch_measures_match_the_scalar_ones():
    from pin_susp.constraints import alignment, alignment_many, chirality, chirality_many

    rng = np.random.default_rng(3)
    points = rng.normal(size=(4, 50, 3))
    for mine, theirs in ((chirality_many, chirality), (alignment_many, alignment)):
        values = mine(*points)
        for n in range(50):
            assert values[n] == pytest.approx(theirs(*(p[n].tolist() for p in points)), abs=1e-15)


@pytest.mark.parametrize("name", ["macpherson.yaml", "pushrod_rocker.yaml", "multilink_front.yaml"])
def test_tree_velocities_and_accelerations_match_pinocchio(name):
    """Every frame's velocity and classical acceleration, and every body's angular
    velocity and acceleration, at random (q, v, a): against Pinocchio's
    forwardKinematics(q, v, a)."""
    corner = build(name)
    model = corner.model
    data = model.createData()
    tree = Tree(model)
    rng = np.random.default_rng(11)
    q = corner.q_design + rng.normal(0.0, 0.3, (5, model.nq))
    qd, qdd = rng.normal(size=(5, model.nv)), rng.normal(size=(5, model.nv))
    R, o = tree.placements(q)
    a = tree.axes(R)
    state = tree.motion(o, a, qd, qdd)
    frames = Frames(tree, list(range(model.nframes)))
    P, _ = frames.evaluate(q, jacobians=False)
    world = pin.LOCAL_WORLD_ALIGNED
    for n in range(len(q)):
        pin.forwardKinematics(model, data, q[n], qd[n], qdd[n])
        pin.updateFramePlacements(model, data)
        for k, f in enumerate(frames.ids):
            j = frames.joint[k]
            vel, acc = bulk.point_motion(
                j, P[k][n : n + 1], o[:, n : n + 1], [x[:, n : n + 1] for x in state]
            )
            np.testing.assert_allclose(
                vel[0], pin.getFrameVelocity(model, data, f, world).linear, atol=1e-13
            )
            np.testing.assert_allclose(
                acc[0], pin.getFrameClassicalAcceleration(model, data, f, world).linear, atol=1e-12
            )
            np.testing.assert_allclose(
                state[0][j, n], pin.getFrameVelocity(model, data, f, world).angular, atol=1e-13
            )
            np.testing.assert_allclose(
                state[1][j, n], pin.getFrameAcceleration(model, data, f, world).angular, atol=1e-12
            )


@pytest.mark.parametrize(
    "geometry",
    [example("macpherson.yaml"), example("pushrod_rocker.yaml"), torsion_bar()],
    ids=["macpherson strut", "pushrod coilover", "torsion bar"],
)
def test_spring_length_and_its_rates_at_once_equal_each_pose_alone(geometry):
    """The spring's length (a torsion bar's wind-up), motion ratio and its rate — the
    second-order closure solve — for every step at once, against Pinocchio's
    forwardKinematics(q, v, a) one pose at a time (rates.SpringRates.derivatives)."""
    from pin_susp.solve.rates import SpringRates

    corner = pin_susp.Corner(geometry, warn=False)
    solutions = corner.solve_steps(long_sweep(corner, steps=61))
    qs = [s.q for s in solutions]
    qs[7] = None  # a step that did not converge: NaN
    rates = SpringRates(corner)
    at_once = np.array(rates.derivatives_at_once(qs))
    assert np.isnan(at_once[:, 7]).all()
    for i, q in enumerate(qs):
        if q is not None:
            expected = rates.derivatives(q)
            np.testing.assert_allclose(at_once[:, i], expected, rtol=1e-12, atol=1e-15)


def test_a_sweep_that_turns_back_and_holds_equals_the_march(monkeypatch):
    """Bump up and back down (the apex inside a coarse segment), then held for 50 steps:
    predictions off the segment's line, and segments of zero length."""
    corner = build("double_wishbone.yaml")
    up = np.linspace(-30.0, 50.0, 151)
    bump = np.r_[up, up[::-1][1:], np.full(50, -30.0)]
    rack = np.r_[np.linspace(0.0, 8.0, 151), np.linspace(8.0, -8.0, 150), np.full(50, -8.0)]
    sweep = Sweep([Target("wheel_center", "z", bump), Target("trackrod_inboard", "y", rack)], "s")
    ours = corner.run_sweep(sweep)
    assert ours["solver_converged"].all()
    step_by_step(monkeypatch)
    reference = corner.run_sweep(sweep)
    for key in ("camber", "roadwheel_angle", "deriv_camber_wrt_hub_z", "upper_wishbone_outboard_x"):
        np.testing.assert_allclose(ours[key], reference[key], rtol=0, atol=1e-10, err_msg=key)


def test_chunks_of_a_sweep_equal_the_whole_sweep():
    """run_sweep_chunks: the chunks, joined, are run_sweep's columns (step_index counted
    from the sweep's start), each chunk from the last converged pose before it."""
    corner = build("pushrod_rocker.yaml")
    sweep = long_sweep(corner, steps=700)
    whole = corner.run_sweep(sweep)
    seen = []
    parts = list(corner.run_sweep_chunks(sweep, rows=250, progress=lambda i, n: seen.append(i)))
    assert [len(p) for p in parts] == [250, 250, 200]
    assert seen[-1] == 700 and seen == sorted(seen)
    for key, expected in whole.columns.items():
        if key in ("solver_iterations", "solver_max_residual"):
            continue
        got = np.concatenate([p.columns[key] for p in parts])
        if expected.dtype.kind != "f":
            np.testing.assert_array_equal(got, expected, err_msg=key)
        else:
            np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9, err_msg=key)


def test_a_sweep_with_no_converged_step_gives_empty_cells():
    """No configuration to evaluate at once: every cell of the step is blank (NaN)."""
    corner = build("double_wishbone.yaml")
    sweep = Sweep(
        [Target("wheel_center", "z", [2000.0]), Target("trackrod_inboard", "y", [0.0])], "far"
    )
    results = corner.run_sweep(sweep)
    assert not results["solver_converged"][0]
    assert np.isnan(results["camber"][0]) and np.isnan(results["wheel_center_x"][0])
    assert np.isnan(results["deriv_camber_wrt_hub_z"][0])


# ---------------------------------------------------------------- an axle's long sweep


def axle_sweeps(steps: int = 401) -> dict:
    """The example axle's roll (−3…3° at 10 mm of heave, the rack held) and both wheels'
    bump with the rack moving (its Ackermann defined): point, roll and heave rows."""
    from pin_susp.model.sweep import load_sweep

    rack = {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"}}
    wheel = lambda side, a, b: {  # noqa: E731
        "point": "wheel_center", "side": side, "direction": {"axis": "z"}, "start": a, "stop": b
    }  # fmt: skip
    return {
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
        "bump+steer": load_sweep(
            {
                "steps": steps,
                "targets": [
                    wheel("left", -30, 40),
                    wheel("right", 20, -25),
                    rack | {"start": -10, "stop": 10},
                ],
            }
        ),
    }


def axle_step_by_step(monkeypatch):
    """Make the axle march every step and evaluate its columns one Pinocchio call after
    another (the reference)."""
    import pin_susp.subjects.axle

    march = marching.march
    monkeypatch.setattr(
        pin_susp.subjects.assembly, "march", lambda *a, **k: march(*a, **{**k, "bulk": False})
    )
    monkeypatch.setattr(pin_susp.subjects.axle, "MIN_STEPS", 10**9)


@pytest.mark.parametrize("kind", ["roll", "bump+steer"])
def test_an_axle_long_sweep_solved_at_once_equals_the_step_by_step_march(kind, monkeypatch):
    """Every column of a 401-step axle sweep — each side's metrics and exact derivatives,
    the roll derivatives, the bar's, the points — solved and evaluated at once equals the
    same sweep marched and evaluated step by step (to 1e-9), every step converged and on
    every loop's design assembly (the scalar branch check, step by step), and the sweep
    took the at-once path: the march saw only the coarse steps."""
    from pin_susp.subjects.axle import AxleModel, axle_results, solve_axle_sweep

    model = AxleModel(EXAMPLES / "axle_front.yaml")
    sweep = axle_sweeps()[kind]
    seen = []
    march = marching.march

    def counting(solver_, values, *args, **kwargs):
        seen.append(len(values))
        if kwargs.get("bulk"):
            counting.solver = solver_
        return march(solver_, values, *args, **kwargs)

    monkeypatch.setattr(marching, "march", counting)
    monkeypatch.setattr(pin_susp.subjects.assembly, "march", counting)
    solutions = solve_axle_sweep(model, sweep)
    assert seen[0] == 401 and len(seen) == 2 and seen[1] <= 2 * bulk.COARSE_STEPS
    assert all(s.converged for s in solutions)
    guard = counting.solver.branches
    for s in solutions:
        model.kin.update(s.q)
        assert guard.left(model.kin) is None
    ours = axle_results(model, sweep, solutions)
    monkeypatch.setattr(marching, "march", march)
    axle_step_by_step(monkeypatch)
    reference = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    assert ours.columns.keys() == reference.columns.keys()
    for key, expected in reference.columns.items():
        if key in ("solver_iterations", "solver_max_residual"):
            continue
        got, expected = np.asarray(ours.columns[key]), np.asarray(expected)
        if expected.dtype.kind != "f":
            np.testing.assert_array_equal(got, expected, err_msg=key)
            continue
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=key)
        scale = 1.0 + np.nanmax(np.abs(expected), initial=0.0)
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9 * scale, err_msg=key)
    assert np.max(ours["solver_max_residual"]) <= 1e-9  # mm
