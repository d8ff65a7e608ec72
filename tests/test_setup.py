"""Setup options: the camber-shim assembly, pushrod-rocker, adjusters, sensitivities, inverse."""

import copy

import numpy as np
import pytest
from conftest import EXAMPLES, example, mirrored
from pointwise import PointwiseCorner, shim_assembly, spec_metrics

import pin_susp
from pin_susp.analyses.setup import SetupModel, apply_setup, setup_values, solve_setup, with_setup
from pin_susp.cli import main
from pin_susp.columns.metrics import STANDARD
from pin_susp.model.geometry import load_geometry
from pin_susp.solve.shim import ShimAssembly

MM = 1e-3


def shimmed(setup_thickness: float) -> dict:
    g = example("camber_shim.yaml")
    g["config"]["camber_shim"]["setup_thickness"] = setup_thickness
    return g


def static(g) -> pin_susp.Pose:
    """The static pose of a corner: its (as-set) design state."""
    corner = pin_susp.Corner(g)
    targets = [pin_susp.Target("wheel_center", "z", 0.0)]
    if corner.geometry.steering == "rack":
        targets.append(pin_susp.Target("trackrod_inboard", "y", 0.0))
    return corner.solve_pose(targets)


@pytest.mark.parametrize("thickness", [0.0, 12.5, 20.0, 41.0])
def test_shim_solve_matches_the_rotation_vector_formulation(thickness):
    data = shimmed(thickness)
    ours = apply_setup(load_geometry(data)).hardpoints
    theirs = shim_assembly(data)
    for name, p in theirs.items():
        np.testing.assert_allclose(ours[name] / MM, p, atol=1e-9, err_msg=name)


def test_as_shimmed_state_is_physical():
    g = load_geometry(shimmed(20.0))
    assembly = ShimAssembly(g)
    solution = assembly.solve()
    assert solution.max_residual <= 1e-12
    kin, pts = assembly.kin, assembly.points
    n = g.camber_shim.normal
    n_block = kin.data.oMf[pts["datum_a_block"].frame_id].rotation @ n
    n_body = kin.data.oMf[pts["datum_a_body"].frame_id].rotation @ n
    np.testing.assert_allclose(n_body, n_block, atol=1e-14)  # faces parallel, same sense
    for d in "ab":  # separated by the fitted stack at both datums
        gap = pts[f"datum_{d}_body"].position(kin) - pts[f"datum_{d}_block"].position(kin)
        np.testing.assert_allclose(gap, 0.020 * n_block, atol=1e-15)
    d = g.design_points()
    s = apply_setup(g).hardpoints
    # UBJ stays on its wishbone arc: same distances to both pivots
    for end in ("front", "rear"):
        pivot = d[f"upper_wishbone_inboard_{end}"]
        assert np.linalg.norm(s["upper_wishbone_outboard"] - pivot) == pytest.approx(
            np.linalg.norm(d["upper_wishbone_outboard"] - pivot), abs=1e-15
        )
    np.testing.assert_array_equal(s["lower_wishbone_outboard"], d["lower_wishbone_outboard"])
    np.testing.assert_array_equal(s["trackrod_inboard"], d["trackrod_inboard"])
    assert np.linalg.norm(s["trackrod_outboard"] - s["trackrod_inboard"]) == pytest.approx(
        np.linalg.norm(d["trackrod_outboard"] - d["trackrod_inboard"]), abs=1e-15
    )
    # the upright body moved rigidly about the LBJ
    lbj = d["lower_wishbone_outboard"]
    for a, b in (("axle_inboard", "axle_outboard"), ("axle_outboard", "trackrod_outboard")):
        assert np.linalg.norm(s[a] - s[b]) == pytest.approx(np.linalg.norm(d[a] - d[b]), abs=1e-15)
        assert np.linalg.norm(s[a] - lbj) == pytest.approx(np.linalg.norm(d[a] - lbj), abs=1e-15)


def test_more_shim_gives_more_positive_camber_and_a_mirror_agrees():
    cambers = [static(shimmed(t)).metrics["camber"] for t in (10.0, 20.0, 30.0, 40.0)]
    assert np.all(np.diff(cambers) > 0.5)
    assert cambers[2] == pytest.approx(-np.degrees(np.arctan2(5, 150)), abs=1e-12)  # drawn
    left = static(shimmed(15.0)).metrics
    right_data = mirrored(shimmed(15.0))
    shim = right_data["config"]["camber_shim"]
    for key in ("shim_face_point_a", "shim_face_point_b", "shim_face_normal"):
        shim[key]["y"] = -shim[key]["y"]
    right = static(right_data).metrics
    for name in ("camber", "roadwheel_angle", "caster", "kpi", "half_track"):
        assert right[name] == pytest.approx(left[name], abs=1e-10), name


def test_setup_equal_to_design_leaves_the_geometry_bit_for_bit():
    g = load_geometry(shimmed(30.0))
    assert apply_setup(g) is g
    drawn = load_geometry(example("double_wishbone.yaml"))
    corner = pin_susp.Corner(g)
    for name, p in drawn.hardpoints.items():
        np.testing.assert_array_equal(corner.geometry.hardpoints[name], p)
    # the same URDF but for the comment and the robot's name (lines 1-3)
    assert corner.urdf.split("\n", 3)[3] == pin_susp.Corner(drawn).urdf.split("\n", 3)[3]


def test_shimmed_corner_sweep_matches_the_pointwise_formulation():
    data = example("camber_shim.yaml")
    corner = pin_susp.Corner(data)
    results = corner.run_sweep(EXAMPLES / "bump_steer.yaml")
    hardpoints = {k: v for k, v in PointwiseCorner(data).hp.items()}
    hardpoints.update(shim_assembly(data))
    ref = PointwiseCorner(data, hardpoints)
    x = None
    for i in range(0, len(results), 5):
        x, residual = ref.solve(
            results["wheel_center_z"][i], results["trackrod_inboard_y"][i] - 200.0, x
        )
        assert residual < 1e-10
        for name, value in spec_metrics(ref.points(x), 1.0).items():
            assert results[name][i] == pytest.approx(value, abs=1e-8), name
    assert results["wheel_travel"][0] == pytest.approx(-40.0)
    assert corner.geometry.drawn is not None


def test_pushrod_rocker_sweep_matches_the_pointwise_formulation_with_the_rocker():
    data = example("pushrod_rocker.yaml")
    corner = pin_susp.Corner(data)
    results = corner.run_sweep(EXAMPLES / "bump_steer.yaml")
    assert results["solver_converged"].all() and results["solver_max_residual"].max() <= 1e-9
    ref = PointwiseCorner(data)
    x = None
    for i in range(len(results)):
        x, residual = ref.solve(
            results["wheel_center_z"][i], results["trackrod_inboard_y"][i] - 200.0, x
        )
        assert residual < 1e-10
        p = ref.points(x)
        for name in ("pushrod_inboard", "strut_bottom", "upper_wishbone_outboard"):
            for j, axis in enumerate("xyz"):
                assert results[f"{name}_{axis}"][i] == pytest.approx(p[name][j], abs=1e-8)
        top, bottom = p["strut_top"], p["strut_bottom"]
        assert results["damper_length"][i] == pytest.approx(np.linalg.norm(top - bottom), abs=1e-8)
        # the rocker turns about +x (axis a → b is −x): right-hand rule about a → b
        arm0 = data["hardpoints"]["pushrod_inboard"]
        v0 = np.array([arm0["y"] - 340.0, arm0["z"] - 450.0])
        v = p["pushrod_inboard"][1:] - np.array([340.0, 450.0])
        about_minus_x = -np.degrees(np.arctan2(v0[0] * v[1] - v0[1] * v[0], v0 @ v))
        assert results["rocker_angle"][i] == pytest.approx(about_minus_x, abs=1e-8)
    # bump compresses the damper and turns the rocker
    assert results["damper_length"][-1] < results["damper_length"][0]


def test_rocker_angle_is_the_rocker_joint_angle():
    corner = pin_susp.Corner(example("pushrod_rocker.yaml"))
    pose = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 30.0), pin_susp.Target("trackrod_inboard", "y", 0.0)]
    )
    joint = corner.model.joints[corner.model.getJointId("rocker_pivot")]
    assert pose.metrics["rocker_angle"] == pytest.approx(np.degrees(pose.q[joint.idx_q]), abs=1e-10)


def test_torsion_bar_twist_is_the_rocker_angle():
    data = example("pushrod_rocker.yaml")
    data["spring"] = {"type": "torsion_bar"}
    for key in ("strut_top", "strut_bottom"):
        data["hardpoints"].pop(key)
    results = pin_susp.Corner(data).run_sweep(example("bump_steer.yaml"))
    np.testing.assert_array_equal(results["torsion_bar_twist"], results["rocker_angle"])
    assert "damper_length" not in results.columns


def test_pushrod_adjuster_holds_the_rocker_and_raises_the_car():
    base = example("pushrod_rocker.yaml")
    longer = copy.deepcopy(base)
    longer["config"]["setup"]["pushrod_length_delta"] = 3.0
    g = pin_susp.Corner(longer).geometry
    d = g.drawn.hardpoints
    s = g.hardpoints
    np.testing.assert_array_equal(s["pushrod_inboard"], d["pushrod_inboard"])  # rocker held
    np.testing.assert_array_equal(s["trackrod_inboard"], d["trackrod_inboard"])  # rack held
    length = np.linalg.norm(s["pushrod_outboard"] - s["pushrod_inboard"])
    drawn = np.linalg.norm(d["pushrod_outboard"] - d["pushrod_inboard"])
    assert (length - drawn) / MM == pytest.approx(3.0, abs=1e-9)
    assert g.ride_height_change / MM > 5.0  # the wheel drops: the car rises


def test_trackrod_adjuster_holds_wheel_centre_height_and_toes_out():
    data = example("double_wishbone.yaml")
    data["config"]["setup"] = {"trackrod_length_delta": 1.5}
    g = pin_susp.Corner(data).geometry
    wc = g.design_points()["wheel_center"]
    wc0 = g.drawn.design_points()["wheel_center"]
    assert wc[2] == pytest.approx(wc0[2], abs=1e-15)
    trackrod = np.linalg.norm(g.hardpoints["trackrod_outboard"] - g.hardpoints["trackrod_inboard"])
    assert trackrod / MM == pytest.approx(
        np.linalg.norm(
            g.drawn.hardpoints["trackrod_outboard"] - g.drawn.hardpoints["trackrod_inboard"]
        )
        / MM
        + 1.5,
        abs=1e-9,
    )
    # a longer trackrod ahead of the axle pushes the front of the wheel out: toe-out
    assert static(data).metrics["roadwheel_angle"] < -0.4


def shimmed_pushrod() -> dict:
    """The pushrod-rocker corner with the shim of the shim example, 25 of 30 mm fitted."""
    data = example("pushrod_rocker.yaml")
    data["config"]["camber_shim"] = shimmed(25.0)["config"]["camber_shim"]
    return data


@pytest.mark.parametrize(
    "example_name",
    ["camber_shim.yaml", "pushrod_rocker.yaml", "fixed_toe_link.yaml", "shimmed pushrod"],
)
def test_exact_setup_sensitivities_match_central_differences(example_name):
    if example_name == "shimmed pushrod":
        g = load_geometry(shimmed_pushrod())
    else:
        g = load_geometry(EXAMPLES / example_name)
    model = SetupModel(g)
    p0 = setup_values(g) + np.array([0.0, 0.4, 0.6 if g.has_pushrod else 0.0]) * MM
    state = model.state(p0)
    h = 1e-3 * MM
    for i, present in enumerate((g.camber_shim is not None, True, g.has_pushrod)):
        if not present:
            continue
        e = np.zeros(3)
        e[i] = h
        plus = pin_susp.Corner(with_setup(g, p0 + e))
        minus = pin_susp.Corner(with_setup(g, p0 - e))
        for name in ("camber", "roadwheel_angle"):
            fd = (static(plus.geometry).metrics[name] - static(minus.geometry).metrics[name]) / (
                2 * h / MM
            )
            assert state.derivatives[name][i] == pytest.approx(fd, abs=1e-7), (name, i)
        fd = (plus.geometry.ride_height_change - minus.geometry.ride_height_change) / (2 * h)
        assert state.derivatives["ride_height_change"][i] == pytest.approx(fd, abs=1e-7)


def test_setup_model_state_is_the_forward_as_set_state():
    """The reduced drawn-model solve and the shim model + adjusters agree exactly."""
    data = example("camber_shim.yaml")
    data["config"]["setup"]["trackrod_length_delta"] = -0.8
    g = load_geometry(data)
    state = SetupModel(g).state(setup_values(g))
    forward = static(data)
    for name in STANDARD:
        assert state.metrics[name] == pytest.approx(forward.metrics[name], abs=1e-10)
    assert state.metrics["ride_height_change"] == pytest.approx(
        pin_susp.Corner(data).geometry.ride_height_change / MM, abs=1e-10
    )


@pytest.mark.parametrize(
    "targets",
    [
        {"camber": -2.5, "roadwheel_angle": 0.1},
        {"camber": -3.1},
        {"roadwheel_angle": -0.25},
    ],
)
def test_inverse_setup_then_forward_solve_reproduces_the_targets(targets):
    found = solve_setup(load_geometry(EXAMPLES / "camber_shim.yaml"), targets)
    pose = static(found.geometry)
    for name, value in targets.items():
        assert pose.metrics[name] == pytest.approx(value, abs=1e-9)
    assert found.iterations <= 6


def test_inverse_setup_with_ride_height_on_the_pushrod_corner():
    targets = {"roadwheel_angle": 0.2, "ride_height_change": 5.0}
    found = solve_setup(load_geometry(EXAMPLES / "pushrod_rocker.yaml"), targets)
    corner = pin_susp.Corner(found.geometry)
    assert corner.geometry.ride_height_change / MM == pytest.approx(5.0, abs=1e-9)
    assert static(found.geometry).metrics["roadwheel_angle"] == pytest.approx(0.2, abs=1e-9)


def test_unreachable_camber_says_which_target_and_why():
    with pytest.raises(pin_susp.InputError, match=r"camber -12 not reachable: .*shim stack of -"):
        solve_setup(load_geometry(EXAMPLES / "camber_shim.yaml"), {"camber": -12.0})
    with pytest.raises(pin_susp.InputError, match="roadwheel_angle 80 not reachable: .*locks up"):
        solve_setup(load_geometry(EXAMPLES / "camber_shim.yaml"), {"roadwheel_angle": 80.0})
    with pytest.raises(pin_susp.InputError, match="a camber target needs a camber shim"):
        solve_setup(load_geometry(EXAMPLES / "double_wishbone.yaml"), {"camber": -2.0})


def test_setup_cli_inverse_round_trip(tmp_path, capsys):
    out = tmp_path / "set.yaml"
    assert (
        main(
            [
                "setup",
                str(EXAMPLES / "camber_shim.yaml"),
                "--camber",
                "-2.5",
                "--toe",
                "0.1",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "before" in printed and "after" in printed and f"wrote {out}" in printed
    metrics = static(load_geometry(out)).metrics
    assert metrics["camber"] == pytest.approx(-2.5, abs=1e-9)
    assert metrics["roadwheel_angle"] == pytest.approx(0.1, abs=1e-9)


def test_setup_cli_sheet_rows_and_sensitivities(tmp_path, capsys):
    sheet = tmp_path / "sheet.csv"
    assert (
        main(
            [
                "setup",
                str(EXAMPLES / "camber_shim.yaml"),
                "--shim",
                "10,30",
                "--sensitivities",
                "--thread-pitch",
                "1.5",
                "--csv",
                str(sheet),
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "per mm shim" in printed and "per turn trackrod" in printed
    rows = [line.split(",") for line in sheet.read_text().splitlines()[1:]]
    assert rows[0][:2] == ["row", "shim_thickness"]
    assert [r[0] for r in rows[1:]] == ["as set", "shim", "shim"]
    camber_at_30 = float(rows[3][4])
    assert camber_at_30 == pytest.approx(-np.degrees(np.arctan2(5, 150)), abs=1e-12)


SETUP_ERRORS = {
    "negative shim": (
        lambda g: g["config"]["camber_shim"].update(setup_thickness=-5),
        "config.camber_shim.setup_thickness: must be >= 0",
    ),
    "zero normal": (
        lambda g: g["config"]["camber_shim"].update(shim_face_normal=[0, 0, 0]),
        "config.camber_shim.shim_face_normal: is the zero vector",
    ),
    "A = B": (
        lambda g: g["config"]["camber_shim"].update(
            shim_face_point_b=dict(g["config"]["camber_shim"]["shim_face_point_a"])
        ),
        "config.camber_shim.shim_face_point_b: coincides with shim_face_point_a",
    ),
    "A-B along normal": (
        lambda g: g["config"]["camber_shim"].update(shim_face_normal={"x": 0, "y": 0, "z": 1}),
        "config.camber_shim.shim_face_point_b: A→B runs along the shim face normal",
    ),
    "pushrod adjuster without pushrod": (
        lambda g: g["config"]["setup"].update(pushrod_length_delta=2.0),
        "config.setup.pushrod_length_delta: this corner has no pushrod (actuation type direct)",
    ),
    "unknown adjuster": (
        lambda g: g["config"]["setup"].update(camber_delta=1.0),
        "config.setup.camber_delta: unknown key",
    ),
    "shim out of reach": (
        lambda g: g["config"]["camber_shim"].update(setup_thickness=900),
        "config.camber_shim.setup_thickness: the shimmed upright does not assemble",
    ),
}


@pytest.mark.parametrize("case", SETUP_ERRORS, ids=str)
def test_bad_setup_input_gets_one_clear_line(tmp_path, capsys, case):
    change, message = SETUP_ERRORS[case]
    data = example("camber_shim.yaml")
    change(data)
    path = tmp_path / "corner.yaml"
    import yaml

    path.write_text(yaml.safe_dump(data))
    assert main(["setup", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err


def test_setup_list_for_a_missing_part_is_an_error(capsys):
    assert main(["setup", str(EXAMPLES / "double_wishbone.yaml"), "--pushrod", "2"]) == 2
    assert "--pushrod needs a pushrod" in capsys.readouterr().err
    assert main(["setup", str(EXAMPLES / "double_wishbone.yaml"), "--shim", "10"]) == 2
    assert "--shim needs a camber shim" in capsys.readouterr().err


# -- what a new user tried first: the API takes what Corner takes, and the CLI's names --


@pytest.mark.parametrize("form", ["path", "str", "dict", "geometry"])
def test_setup_api_accepts_a_path_a_dict_or_a_geometry(form):
    path = EXAMPLES / "camber_shim.yaml"
    g = {
        "path": path,
        "str": str(path),
        "dict": example("camber_shim.yaml"),
        "geometry": load_geometry(path),
    }[form]
    sheet = pin_susp.setup_sheet(g, shim=[25.0])
    reference = pin_susp.setup_sheet(load_geometry(path), shim=[25.0])
    assert sheet[1].metrics["camber"] == reference[1].metrics["camber"]
    found = pin_susp.solve_setup(g, {"camber": -2.5})
    assert found.after.metrics["camber"] == pytest.approx(-2.5, abs=1e-9)


def test_solve_setup_speaks_the_cli_names():
    path = EXAMPLES / "camber_shim.yaml"
    by_cli = solve_setup(path, {"toe": 0.1, "camber": -2.5})
    by_column = solve_setup(path, {"roadwheel_angle": 0.1, "camber": -2.5})
    assert by_cli.after.metrics == by_column.after.metrics
    with pytest.raises(pin_susp.InputError, match="valid: camber.*toe or roadwheel_angle"):
        solve_setup(path, {"toes": 0.1})


def test_negative_lists_work_as_written(capsys):
    assert main(["setup", str(EXAMPLES / "double_wishbone.yaml"), "--trackrod", "-1,0,1"]) == 0
    rows = [ln for ln in capsys.readouterr().out.splitlines() if ln.strip().startswith("trackrod")]
    assert [float(r.split()[2]) for r in rows] == [-1.0, 0.0, 1.0]


def test_a_toe_link_corner_says_toe_link_not_trackrod(tmp_path, capsys):
    path = str(EXAMPLES / "fixed_toe_link.yaml")
    assert main(["setup", path, "--trackrod=-1", "--csv", str(tmp_path / "s.csv")]) == 0
    out = capsys.readouterr().out
    assert "toe link" in out and "trackrod" not in out
    assert "toe_link_length_delta" in (tmp_path / "s.csv").read_text()
