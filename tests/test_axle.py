"""The axle model (docs/axle.md): two corners composed on one chassis and one rack.

Checked against the corner model, solved on its own: a mirrored axle in pure
heave puts each side where the corner goes; in roll the left side is the
corner at +z and the right the mirrored corner at −z; the shared rack moves
both trackrods' inboard ends together.
"""

from pathlib import Path

import numpy as np
import pytest
import yaml
import yourdfpy
from conftest import ROOT, example, mirrored

import pin_susp
from pin_susp.model.geometry import load_geometry
from pin_susp.model.sweep import load_sweep
from pin_susp.subjects.axle import AxleModel, axle_results, load_axle, solve_axle_sweep

EXAMPLES = ["double_wishbone.yaml", "macpherson.yaml", "multilink_front.yaml"]


def corner_points(data, z, rack):
    corner = pin_susp.Corner(data)
    targets = [pin_susp.Target("wheel_center", "z", z)]
    if corner.geometry.steering == "rack":
        targets.append(pin_susp.Target("trackrod_inboard", "y", rack))
    return corner.solve_pose(targets).points


def axle(name):
    data = example(name)
    return data, AxleModel(load_geometry(data), load_geometry(mirrored(data)))


@pytest.mark.parametrize("name", EXAMPLES)
@pytest.mark.parametrize(("left_z", "right_z"), [(25.0, 25.0), (20.0, -20.0), (-15.0, 35.0)])
def test_each_side_of_a_mirrored_axle_is_the_corner_at_its_wheel_height(name, left_z, right_z):
    """Heave and roll alike: each side's points equal its corner's (the right side the
    mirrored corner's), the rack at the same travel on both."""
    data, model = axle(name)
    wc = {s: model.design_positions[f"{s}_wheel_center"][2] for s in ("left", "right")}
    rack = 4.0  # mm along +y: the left trackrod's end and the right one's move together
    solution = model.solve(
        {"left": wc["left"] + left_z * 1e-3, "right": wc["right"] + right_z * 1e-3}, rack * 1e-3
    )
    assert solution.converged and solution.max_residual <= 1e-12
    for side, z, corner in (("left", left_z, data), ("right", right_z, mirrored(data))):
        # the right corner's rack target is its trackrod end's y: the same +4 mm
        expected = corner_points(corner, z, rack)
        got = model.side_positions(solution.q, side)
        for point, p in expected.items():
            np.testing.assert_allclose(got[point] * 1e3, p, atol=1e-9, err_msg=f"{side} {point}")


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_axle_has_one_rack_and_each_corners_freedoms(name):
    data, model = axle(name)
    corner = pin_susp.Corner(data)
    rack = 1 if corner.geometry.steering == "rack" else 0
    assert model.mobility == 2 * (corner.mobility - rack) + rack  # bump per side + one rack
    names = [model.model.names[j] for j in range(1, model.model.njoints)]
    assert names.count("rack_slide") == rack
    assert all(n.startswith(("left_", "right_")) for n in names if n != "rack_slide")


@pytest.mark.parametrize("name", EXAMPLES)
def test_yourdfpy_reads_the_axle_urdf_and_agrees_with_pinocchio(tmp_path, name):
    data, model = axle(name)
    wc = {s: model.design_positions[f"{s}_wheel_center"][2] for s in ("left", "right")}
    q = model.solve({"left": wc["left"] + 0.02, "right": wc["right"] - 0.01}, 0.003).q
    path = tmp_path / "axle.urdf"
    path.write_text(model.urdf)
    robot = yourdfpy.URDF.load(str(path), load_meshes=False)
    m = model.model
    values = {m.names[j]: q[m.joints[j].idx_q] for j in range(1, m.njoints)}
    robot.update_cfg({j: values[j] for j in robot.actuated_joint_names})
    at = model.positions(q)
    for name in ("left_wheel_center", "right_wheel_center", "right_axle_inboard"):
        np.testing.assert_allclose(
            robot.get_transform(name, "chassis")[:3, 3], at[name], atol=1e-12
        )


def axle_file(tmp_path, change=None) -> Path:
    data = yaml.safe_load((ROOT / "examples" / "axle_front.yaml").read_text())
    if change:
        change(data)
    path = tmp_path / "axle.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_axle_file_mirrors_the_left_corner_and_adds_the_bar(tmp_path):
    a = load_axle(axle_file(tmp_path))
    assert (
        a.mirrored and a.anti_roll == "u_bar" and a.left.side == "left" and a.right.side == "right"
    )
    for name, p in a.left.hardpoints.items():
        np.testing.assert_array_equal(a.right.hardpoints[name], p * [1, -1, 1], err_msg=name)
    np.testing.assert_array_equal(
        a.side_points["right"]["droplink_u_bar"],
        a.side_points["left"]["droplink_u_bar"] * [1, -1, 1],
    )
    model = AxleModel(a)
    names = [c.name for c in model.closures]
    assert "left_droplink" in names and "right_droplink" in names
    # one rack, a bump per side: the bar's arms turn freely (the bar twists)
    assert model.mobility == 3


def test_explicit_right_points_equal_the_mirror(tmp_path):
    def explicit(data):
        data["hardpoints"]["right"] = {
            k: {"x": v["x"], "y": -v["y"], "z": v["z"]}
            for k, v in data["hardpoints"]["left"].items()
        }

    mirrored_model = AxleModel(load_axle(axle_file(tmp_path)))
    explicit_model = AxleModel(load_axle(axle_file(tmp_path, explicit)))
    wc = {s: mirrored_model.design_positions[f"{s}_wheel_center"][2] for s in ("left", "right")}
    heights = {"left": wc["left"] + 0.015, "right": wc["right"] - 0.02}
    a = mirrored_model.positions(mirrored_model.solve(heights, 0.002).q)
    b = explicit_model.positions(explicit_model.solve(heights, 0.002).q)
    for name in a:
        np.testing.assert_allclose(a[name], b[name], atol=1e-15, err_msg=name)


def direct_bar(mount):
    """Direct-acting corners (no rocker): the droplink hangs from the named body."""

    def change(data):
        config = data["axle_config"]
        config.update(actuation={"type": "direct"}, spring={"type": "none"})
        config["anti_roll"] = {"type": "u_bar", "mount": mount}
        left = data["hardpoints"]["left"]
        for k in ("pushrod_outboard", "pushrod_inboard", "rocker_axis_a", "rocker_axis_b"):
            left.pop(k)
        for k in ("strut_top", "strut_bottom", "droplink_rocker"):
            left.pop(k)
        left["droplink_lower"] = {"x": 0, "y": 700, "z": 250}

    return change


def t_bar_off_centre(data):
    """A T-bar whose pivot is not on the car's centreline."""
    data["axle_config"]["anti_roll"] = {"type": "t_bar"}
    left = data["hardpoints"]["left"]
    left["droplink_t_bar"] = left.pop("droplink_u_bar")
    data["hardpoints"]["center"] = {"arb_t_bar_pivot": {"x": 0, "y": 10, "z": 300}}


@pytest.mark.parametrize(
    ("change", "key"),
    [
        (lambda d: d["axle_config"].update(right_setup={}), "axle_config.right_setup"),
        (lambda d: d["hardpoints"]["left"].pop("droplink_u_bar"), "hardpoints.left.droplink_u_bar"),
        (lambda d: d["hardpoints"]["left"].pop("axle_inboard"), "hardpoints.left.axle_inboard"),
        (lambda d: d["axle_config"]["wheel"].pop("tire"), "axle_config.wheel.tire"),
        (lambda d: d["vehicle_config"].update(wheelbase=-1), "vehicle_config.wheelbase"),
        (
            lambda d: d["hardpoints"]["center"].pop("arb_u_bar_axis_b"),
            "hardpoints.center.arb_u_bar_axis_b",
        ),
        (t_bar_off_centre, "hardpoints.center.arb_t_bar_pivot"),
        (direct_bar("foo"), "axle_config.anti_roll.mount"),
        (
            lambda d: d["hardpoints"]["left"].update(droplink_u_bar={"x": 0, "y": 200, "z": 300}),
            "hardpoints.left.droplink_u_bar",
        ),
        (lambda d: d.update(version=[1]), "version"),
        (
            lambda d: d["axle_config"]["anti_roll"].update(mount="upright"),
            "axle_config.anti_roll.mount",
        ),
        (
            lambda d: d["axle_config"].update(
                left_setup={"camber_shim": {"shim_face_point_a": [0, 0, 0]}}
            ),
            "axle_config.left_setup.camber_shim",
        ),
    ],
)
def test_bad_axle_file_names_the_key_as_it_stands_in_the_file(tmp_path, change, key):
    path = axle_file(tmp_path, change)
    with pytest.raises(pin_susp.InputError) as info:
        load_axle(path)
    assert info.value.source == str(path)
    assert info.value.key.startswith(key), (info.value.key, str(info.value))


def roll_sweep(steps=5):
    return load_sweep(
        {
            "steps": steps,
            "targets": [
                {"quantity": "roll", "start": -3, "stop": 3},
                {"quantity": "heave", "values": [10.0] * steps},
                {
                    "point": "trackrod_inboard",
                    "side": "left",
                    "direction": {"axis": "y"},
                    "values": [0.0] * steps,
                },
            ],
        }
    )


def test_roll_and_heave_targets_hold_their_definitions(tmp_path):
    """roll = atan2(ΔWC_z,L − ΔWC_z,R, CP_y,L − CP_y,R), heave = ½(ΔWC_z,L + ΔWC_z,R),
    computed here from the solved points; a mirrored axle rolls symmetrically."""
    model = AxleModel(load_axle(axle_file(tmp_path)))
    solutions = solve_axle_sweep(model, roll_sweep())
    d = model.design_positions
    for roll, s in zip(np.linspace(-3, 3, 5), solutions, strict=True):
        assert s.converged and s.max_residual <= 1e-12
        p = model.positions(s.q)
        dl = p["left_wheel_center"][2] - d["left_wheel_center"][2]
        dr = p["right_wheel_center"][2] - d["right_wheel_center"][2]
        track = p["left_contact_patch_center"][1] - p["right_contact_patch_center"][1]
        assert np.degrees(np.arctan2(dl - dr, track)) == pytest.approx(roll, abs=1e-12)
        assert 0.5 * (dl + dr) * 1e3 == pytest.approx(10.0, abs=1e-9)
        assert dl * 1e3 == pytest.approx(20.0 - dr * 1e3, abs=1e-9)


@pytest.mark.parametrize(
    ("targets", "key"),
    [
        ([{"point": "wheel_center", "direction": {"axis": "z"}, "values": [1]}], "targets[0].side"),
        ([{"quantity": "roll", "values": [1]}], "targets"),
    ],
)
def test_axle_targets_must_name_a_side_and_fix_the_pose(tmp_path, targets, key):
    model = AxleModel(load_axle(axle_file(tmp_path)))
    with pytest.raises(pin_susp.InputError) as info:
        solve_axle_sweep(model, load_sweep({"targets": targets}))
    assert info.value.key == key


def test_a_corner_refuses_a_side_or_an_axle_quantity():
    corner = pin_susp.Corner(example("double_wishbone.yaml"))
    for target, key in (
        ({"point": "wheel_center", "side": "left", "direction": {"axis": "z"}}, "targets[0].side"),
        ({"quantity": "heave"}, "targets[0].quantity"),
    ):
        sweep = load_sweep({"targets": [target | {"values": [1.0]}, RACK]})
        with pytest.raises(pin_susp.InputError) as info:
            corner.run_sweep(sweep)
        assert info.value.key == key


RACK = {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": [0.0]}


def read_csv(path):
    lines = [x for x in path.read_text().splitlines() if not x.startswith("#")]
    header = lines[0].split(",")
    rows = [
        [float(c) if c not in ("", "True", "False") else c for c in r.split(",")] for r in lines[1:]
    ]
    return {h: np.array([r[i] for r in rows], dtype=object) for i, h in enumerate(header)}


def test_axle_sweep_through_the_cli_and_its_roll_centre(tmp_path):
    """The CSV's roll centre is where the lines CP→FVIC of both sides cross, computed
    here from the CSV's own points and instant centres; a mirrored axle's columns at
    +roll are the other side's at −roll."""
    from pin_susp.cli import main

    out = tmp_path / "axle.csv"
    code = main(
        ["sweep", str(ROOT / "examples/axle_front.yaml"), str(ROOT / "examples/heave_roll.yaml"),
         "-o", str(out), "-q"]
    )  # fmt: skip
    assert code == 0
    c = read_csv(out)
    n = len(c["step_index"])
    assert all(v == "True" for v in c["solver_converged"])
    for i in range(n):
        cl = np.array([c["left_contact_patch_center_y"][i], c["left_contact_patch_center_z"][i]])
        cr = np.array([c["right_contact_patch_center_y"][i], c["right_contact_patch_center_z"][i]])
        fl = np.array([c["fvic_y_left"][i], c["fvic_z_left"][i]], dtype=float)
        fr = np.array([c["fvic_y_right"][i], c["fvic_z_right"][i]], dtype=float)
        # cl + t (fl − cl) = cr + u (fr − cr)
        t, _ = np.linalg.solve(np.column_stack([fl - cl, cr - fr]), cr - cl)
        rc = cl + t * (fl - cl)
        assert c["roll_center_y"][i] == pytest.approx(rc[0], abs=1e-6 * max(1.0, abs(rc[0])))
        assert c["roll_center_z"][i] == pytest.approx(rc[1], abs=1e-6 * max(1.0, abs(rc[1])))
        j = n - 1 - i
        for name in ("camber", "roadwheel_angle", "caster", "kpi", "half_track", "motion_ratio"):
            assert c[f"{name}_left"][i] == pytest.approx(c[f"{name}_right"][j], abs=1e-9), name
        assert c["roll"][i] == pytest.approx(-c["roll"][j], abs=1e-12)


def test_each_side_in_heave_is_the_corner_with_its_derivatives(tmp_path):
    """Pure heave with the rack held: every column of each side equals the corner's
    sweep at the same wheel-centre heights (derivatives along that side's hub z with
    the other wheel and the rack held: the sides meet only at the rack)."""
    model = AxleModel(load_axle(axle_file(tmp_path)))
    heights = [-20.0, 0.0, 15.0]

    def target(point, axis, values, side=None):
        t = {"point": point, "direction": {"axis": axis}, "values": values}
        return t if side is None else t | {"side": side}

    rack = [0.0] * len(heights)
    sweep = load_sweep(
        {
            "targets": [
                target("wheel_center", "z", heights, "left"),
                target("wheel_center", "z", heights, "right"),
                target("trackrod_inboard", "y", rack, "left"),
            ]
        }
    )
    axle = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    corner_sweep = {
        "targets": [target("wheel_center", "z", heights), target("trackrod_inboard", "y", rack)]
    }
    drawn = example("pushrod_rocker.yaml")
    compared = 0
    for side, data in (("left", drawn), ("right", mirrored(drawn))):
        corner = pin_susp.Corner(data).run_sweep(corner_sweep)
        for name in corner.columns:
            # anti-geometry needs the axle's position and brake bias: the axle file has
            # them (vehicle_config, axle_config), the corner file does not
            if name.startswith("anti_"):
                continue
            ours = f"{name}_{side}" if f"{name}_{side}" in axle.columns else f"{side}_{name}"
            if ours not in axle.columns:
                continue
            np.testing.assert_allclose(axle[ours], corner[name], atol=1e-9, err_msg=ours)
            compared += 1
    assert compared > 150  # metrics, derivatives, motion ratio, points; both sides


def test_axle_urdf_and_mjcf_through_the_cli(tmp_path):
    """The composed URDF parses back to the same model; MuJoCo reads the MJCF with one
    connect per ball closure and droplink/link (each corner's and the bar's)."""
    import mujoco
    import pinocchio as pin

    from pin_susp.cli import main

    geometry = str(ROOT / "examples/axle_front.yaml")
    assert main(["urdf", geometry, "-o", str(tmp_path / "a.urdf")]) == 0
    assert main(["mjcf", geometry, "-o", str(tmp_path / "a.xml")]) == 0
    model = AxleModel(load_axle(geometry))
    assert (tmp_path / "a.urdf").read_text() == model.urdf
    parsed = pin.buildModelFromUrdf(str(tmp_path / "a.urdf"))
    assert parsed.nv == model.model.nv == 15
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "a.xml"))
    assert m.neq == len(model.closures) == 8


def test_roll_derivatives_match_central_differences_of_full_solves(tmp_path):
    """deriv_*_wrt_roll (roll camber, roll steer, roll-centre migration) and the bar's
    twist rate per hub z against differences of re-solved poses, ±1e-4 deg of roll."""
    model = AxleModel(load_axle(axle_file(tmp_path)))

    def at(rolls):
        n = len(rolls)
        sweep = load_sweep(
            {
                "targets": [
                    {"quantity": "roll", "values": rolls},
                    {"quantity": "heave", "values": [10.0] * n},
                    {
                        "point": "trackrod_inboard",
                        "side": "left",
                        "direction": {"axis": "y"},
                        "values": [3.0] * n,
                    },
                ]
            }
        )
        return axle_results(model, sweep, solve_axle_sweep(model, sweep))

    h = 1e-4
    for roll in (-2.0, 1.5):
        r, plus, minus = at([roll]), at([roll + h]), at([roll - h])
        pairs = [(f"{m}_{s}", f"deriv_{m}_wrt_roll_{s}") for m in ("camber", "roadwheel_angle")
                 for s in ("left", "right")]  # fmt: skip
        pairs += [(f"roll_center_{a}", f"deriv_roll_center_{a}_wrt_roll") for a in "yz"]
        for column, derivative in pairs:
            fd = (plus[column][0] - minus[column][0]) / (2 * h)
            assert r[derivative][0] == pytest.approx(fd, rel=1e-6, abs=1e-7), derivative
        # the twist's rate along roll from its per-side hub-z rates (zL = +, zR = −)
        fd = (plus["arb_twist"][0] - minus["arb_twist"][0]) / (2 * h)
        gain = {
            s: r[f"deriv_camber_wrt_roll_{s}"][0] / r[f"deriv_camber_wrt_hub_z_{s}"][0]
            for s in ("left", "right")
        }  # fmt: skip  mm of own hub z per deg of roll
        exact = sum(r[f"deriv_arb_twist_wrt_hub_z_{s}"][0] * gain[s] for s in ("left", "right"))
        assert exact == pytest.approx(fd, rel=1e-6)


def test_ackermann_from_the_two_solved_wheel_planes(tmp_path):
    """Steer angles from each solved spin axis (ISO yaw: −s·atan2(a_x, s·a_y)), their
    change from design, the inner wheel the one inside the turn, and the ideal inner
    angle atan2(L, L/tan δ_o − track): the formula written here from the CSV's points."""
    model = AxleModel(load_axle(axle_file(tmp_path)))
    racks = [-30.0, -12.0, 0.0, 12.0, 30.0]
    n = len(racks)
    sweep = load_sweep(
        {
            "targets": [
                {"quantity": "roll", "values": [0.0] * n},
                {"quantity": "heave", "values": [0.0] * n},
                {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
                 "values": racks},
            ]
        }
    )  # fmt: skip
    r = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    wheelbase = 2500.0

    def steer(side, step=None):
        s = 1.0 if side == "left" else -1.0
        a = np.array(
            [r[f"{side}_axle_outboard_{x}"] - r[f"{side}_axle_inboard_{x}"] for x in "xyz"]
        )
        if step is not None:
            a = a[:, step]
        return -s * np.degrees(np.arctan2(a[0], s * a[1]))

    design = {side: steer(side, step=2) for side in ("left", "right")}  # rack 0, no roll
    for i in range(n):
        angles = {side: steer(side)[i] for side in ("left", "right")}
        for side in ("left", "right"):
            assert r[f"steer_angle_{side}"][i] == pytest.approx(angles[side], abs=1e-9)
        delta = {side: abs(angles[side] - design[side]) for side in angles}
        inner, outer = (
            ("left", "right") if angles["left"] + angles["right"] > 0 else ("right", "left")
        )
        d_o = np.radians(delta[outer])
        if delta[outer] < 0.5:
            assert np.isnan(r["ackermann"][i])
            continue
        ideal = np.degrees(np.arctan2(wheelbase, wheelbase / np.tan(d_o) - r["track"][i]))
        expected = 100.0 * (delta[inner] - delta[outer]) / (ideal - delta[outer])
        assert r["ackermann"][i] == pytest.approx(expected, rel=1e-9)
    assert np.isfinite(r["ackermann"][[0, 1, 3, 4]]).all()


def test_a_direct_acting_axle_hangs_the_droplink_from_the_named_body(tmp_path):
    model = AxleModel(load_axle(axle_file(tmp_path, direct_bar("lower_wishbone"))))
    for side in ("left", "right"):
        assert model.tree.points[f"{side}_droplink_lower"][0] == f"{side}_lower_wishbone"
    sweep = load_sweep(
        {
            "targets": [
                {"quantity": "roll", "values": [-1.0, 1.0]},
                {"quantity": "heave", "values": [0.0, 0.0]},
                {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
                 "values": [0.0, 0.0]},
            ]
        }
    )  # fmt: skip
    results = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    assert results["solver_converged"].all()
    # mirrored axle: the left arm at −1° of roll turns as the right one at +1°
    left, right = results["arb_arm_angle_left"], results["arb_arm_angle_right"]
    np.testing.assert_allclose(left, right[::-1], atol=1e-9)
    assert abs(results["arb_twist"][0]) > 0.1


def test_each_side_takes_its_setup_before_the_sweep(tmp_path):
    """left_setup (a camber shim 10 mm thinner, a longer pushrod) is applied as the
    corner applies it: the left side then equals the set-up corner, and the mirrored
    right side takes the same setup (spec: a mirrored right side takes the left's)."""
    shim = yaml.safe_load((ROOT / "examples/camber_shim.yaml").read_text())["config"]["camber_shim"]
    setup = {"camber_shim": shim, "pushrod_length_delta": 1.5}

    def with_setup(data):
        data["axle_config"]["left_setup"] = setup

    model = AxleModel(load_axle(axle_file(tmp_path, with_setup)))
    heights = [-10.0, 20.0]
    axle_sweep = load_sweep(
        {
            "targets": [
                {"point": "wheel_center", "side": s, "direction": {"axis": "z"}, "values": heights}
                for s in ("left", "right")
            ]
            + [{"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
                "values": [0.0, 0.0]}]
        }
    )  # fmt: skip
    axle = axle_results(model, axle_sweep, solve_axle_sweep(model, axle_sweep))
    corner_data = example("pushrod_rocker.yaml")
    corner_data["config"]["camber_shim"] = shim
    corner_data["config"]["setup"] = {"pushrod_length_delta": 1.5}
    corner = pin_susp.Corner(corner_data)
    result = corner.run_sweep(
        {
            "targets": [
                {"point": "wheel_center", "direction": {"axis": "z"}, "values": heights},
                {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": [0.0, 0.0]},
            ]
        }
    )
    for name in ("camber", "roadwheel_angle", "damper_length", "half_track"):
        np.testing.assert_allclose(axle[f"{name}_left"], result[name], atol=1e-9, err_msg=name)
        np.testing.assert_allclose(axle[f"{name}_right"], result[name], atol=1e-9, err_msg=name)
    assert (
        abs(
            result["camber"][0]
            - pin_susp.Corner(example("pushrod_rocker.yaml")).run_sweep(
                {
                    "targets": [
                        {"point": "wheel_center", "direction": {"axis": "z"}, "values": [-10.0]},
                        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": [0.0]},
                    ]
                }
            )["camber"][0]
        )
        > 1.0
    )  # fmt: skip  the shim changed the corner


DATA = ROOT / "tests" / "data"


def test_open_kinematics_axle_files_load_unchanged_and_roll_alike(tmp_path):
    """open-kinematics 0.4's two axle test geometries sweep through the CLI as they
    stand; the rocker, torsion bars and U-bar of the second constrain no wheel motion,
    so both give the same corner columns, and each is mirror-symmetric in roll."""
    from pin_susp.cli import main

    sweep = DATA / "open_kinematics_axle_rocker_sweep.yaml"
    csv = {}
    for name in ("open_kinematics_axle_geometry", "open_kinematics_axle_geometry_rocker"):
        out = tmp_path / f"{name}.csv"
        assert main(["sweep", str(DATA / f"{name}.yaml"), str(sweep), "-o", str(out), "-q"]) == 0
        csv[name] = c = read_csv(out)
        assert all(v == "True" for v in c["solver_converged"])
        assert max(c["solver_max_residual"]) <= 1e-9
        n = len(c["roll"])
        for i in range(n):
            assert c["camber_left"][i] == pytest.approx(c["camber_right"][n - 1 - i], abs=1e-9)
    plain, rocker = csv.values()
    for name in ("camber_left", "roadwheel_angle_right", "roll", "roll_center_z", "track"):
        np.testing.assert_allclose(
            plain[name].astype(float), rocker[name].astype(float), atol=1e-9, err_msg=name
        )
    assert np.ptp(rocker["arb_twist"].astype(float)) > 10.0  # the bar twists in roll


def t_bar_model(rigid=False) -> AxleModel:
    data = yaml.safe_load((DATA / "axle_t_bar.yaml").read_text())
    if rigid:
        data["axle_config"]["anti_roll"]["stiffness"] = "rigid"
    return AxleModel(load_axle(data))


def test_t_bar_is_a_rigid_crossbar_on_its_pivot_and_its_twist_is_the_turn_about_the_stem():
    """Read from the solved points alone: pivot → crossbar ends stay rigid, the
    crossbar's midpoint stays in y = 0, the droplinks keep their lengths; the
    crossbar's rotation (fitted by scipy) is a pitch about y and then a turn about the
    design stem, and that turn is the arb_twist column."""
    from scipy.spatial.transform import Rotation

    model = t_bar_model()
    solutions = solve_axle_sweep(model, roll_sweep(7))
    results = axle_results(model, roll_sweep(7), solutions)
    d = model.design_positions
    hub = model.axle.center["arb_t_bar_pivot"]
    ends0 = np.array([d["left_droplink_t_bar"], d["right_droplink_t_bar"]]) - hub
    stem0 = ends0.mean(axis=0)
    u0 = stem0 / np.linalg.norm(stem0)
    for i, s in enumerate(solutions):
        assert s.converged
        p = model.positions(s.q)
        ends = np.array([p["left_droplink_t_bar"], p["right_droplink_t_bar"]]) - hub
        np.testing.assert_allclose(np.linalg.norm(ends, axis=1), np.linalg.norm(ends0, axis=1))
        assert abs(ends.mean(axis=0)[1]) < 1e-12
        for side in ("left", "right"):
            a, b = f"{side}_droplink_rocker", f"{side}_droplink_t_bar"
            assert np.linalg.norm(p[a] - p[b]) == pytest.approx(np.linalg.norm(d[a] - d[b]))
        turn, _ = Rotation.align_vectors(ends, ends0)
        stem = turn.apply(stem0)
        pitch = Rotation.from_rotvec([0.0, np.arctan2(np.cross(stem0, stem)[1], stem0 @ stem), 0])
        twist = (pitch.inv() * turn).as_rotvec()
        assert np.linalg.norm(np.cross(twist, u0)) < 1e-9  # a turn about the stem only
        assert results.columns["arb_twist"][i] == pytest.approx(np.degrees(twist @ u0), abs=1e-9)
    assert abs(results.columns["arb_twist"][0]) > 3.0


def test_t_bar_twist_rate_matches_central_differences_of_wheel_heights():
    model = t_bar_model()
    d = model.design_positions
    z = {s: d[f"{s}_wheel_center"][2] for s in ("left", "right")}
    z["left"] += 0.01
    base = model.solve(z)
    results = axle_results(model, one_step(), [base])
    h = 1e-5
    for side in ("left", "right"):
        twist = []
        for dz in (h, -h):
            moved = dict(z, **{side: z[side] + dz})
            s = model.solve(moved, q0=base.q)
            twist.append(axle_results(model, one_step(), [s]).columns["arb_twist"][0])
        fd = (twist[0] - twist[1]) / (2 * h * 1e3)
        exact = results.columns[f"deriv_arb_twist_wrt_hub_z_{side}"][0]
        assert exact == pytest.approx(fd, rel=1e-6, abs=1e-9)
        assert abs(exact) > 1e-2


def one_step():
    return load_sweep({"targets": [{"quantity": "heave", "values": [0.0]}]})


@pytest.mark.parametrize("bar", ["u_bar", "t_bar"])
def test_a_rigid_bar_cannot_roll(tmp_path, bar):
    """A locked bar (stiffness: rigid) leaves heave and the rack: a roll target is
    refused as unreachable (exit 2, nothing written), and driving the left wheel
    alone carries the right one to the same height."""
    from pin_susp.cli import main

    data = yaml.safe_load(
        (
            ROOT / "examples/axle_front.yaml" if bar == "u_bar" else DATA / "axle_t_bar.yaml"
        ).read_text()
    )
    data["axle_config"]["anti_roll"]["stiffness"] = "rigid"
    path = tmp_path / "rigid.yaml"
    path.write_text(yaml.safe_dump(data))
    model = AxleModel(load_axle(path))
    assert model.mobility == 2
    out = tmp_path / "out.csv"
    assert main(["sweep", str(path), str(ROOT / "examples/roll.yaml"), "-o", str(out), "-q"]) == 2
    assert not out.exists()
    with pytest.raises(pin_susp.InputError, match="rigid.*unreachable"):
        solve_axle_sweep(model, load_sweep(ROOT / "examples/roll.yaml"))
    sweep = load_sweep(
        {
            "steps": 5,
            "targets": [
                {"point": "wheel_center", "side": "left", "direction": {"axis": "z"},
                 "start": -30, "stop": 30},
                {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
                 "start": 0, "stop": 0},
            ],
        }
    )  # fmt: skip
    solutions = solve_axle_sweep(model, sweep)
    for s in solutions:
        assert s.converged
        p = model.positions(s.q)
        assert p["right_wheel_center"][2] == pytest.approx(p["left_wheel_center"][2], abs=1e-12)
    assert model.positions(solutions[0].q)["left_wheel_center"][2] == pytest.approx(
        model.design_positions["left_wheel_center"][2] - 0.03
    )
    # one wheel cannot move with the other held: those rates are blank, the rest is written
    columns = axle_results(model, sweep, solutions).columns
    assert np.isfinite(columns["camber_left"]).all() and np.isfinite(columns["arb_twist"]).all()
    assert np.isnan(columns["deriv_camber_wrt_hub_z_left"]).all()


def test_an_older_open_kinematics_axle_layout_is_named(tmp_path):
    from pin_susp.cli import main

    path = tmp_path / "old.yaml"
    path.write_text("type: double_wishbone_axle\nhardpoints: {side: left, points: {}}\n")
    with pytest.raises(pin_susp.InputError, match="older open-kinematics axle layout"):
        load_geometry(path)
    out = tmp_path / "out.csv"
    assert main(["sweep", str(path), str(ROOT / "examples/roll.yaml"), "-o", str(out)]) == 2
    assert not out.exists()


def no_side(sweep):
    del sweep["targets"][2]["side"]


def right_setup_mirrored(axle):
    axle["axle_config"]["right_setup"] = {"trackrod_length_delta": 1.0}


def bar_pivot_off_centre(axle):
    t_bar_off_centre(axle)


@pytest.mark.parametrize(
    ("geometry_change", "sweep_change", "corner", "where", "words"),
    [
        (right_setup_mirrored, None, False, "axle_config.right_setup", "hardpoints.right"),
        (bar_pivot_off_centre, None, False, "hardpoints.center.arb_t_bar_pivot", "centreline"),
        (None, no_side, False, "targets[2].side", "missing"),
        (None, None, True, "targets[0].side", "axle"),
    ],
    ids=["right_setup", "bar_pivot", "no_side", "side_on_corner"],
)
def test_bad_axle_input_gets_one_line_and_exit_2(
    tmp_path, capsys, geometry_change, sweep_change, corner, where, words
):
    """Through the CLI: one line naming the file and key, exit 2, nothing written."""
    from pin_susp.cli import main

    if corner:
        geometry = tmp_path / "corner.yaml"
        geometry.write_text((ROOT / "examples/double_wishbone.yaml").read_text())
    else:
        geometry = axle_file(tmp_path, geometry_change)
    sweep_data = yaml.safe_load((ROOT / "examples/roll.yaml").read_text())
    if corner:
        sweep_data = {"targets": [
            {"point": "wheel_center", "side": "left", "direction": {"axis": "z"}, "values": [1]},
            RACK,
        ]}  # fmt: skip
    if sweep_change:
        sweep_change(sweep_data)
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(yaml.safe_dump(sweep_data))
    out = tmp_path / "out.csv"
    assert main(["sweep", str(geometry), str(sweep), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    blamed = sweep if sweep_change or corner else geometry
    assert lines[0].startswith(f"pin-susp: error: {blamed}: {where}"), lines[0]
    assert words in lines[0]
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [geometry.name, sweep.name]
    )


@pytest.mark.parametrize("name", ["fixed_toe_link.yaml", "multilink_rear.yaml"])
def test_a_toe_link_axle_has_each_corners_columns_with_the_toe_link_rates(name):
    """Without a rack each side's second driver is its fixed toe link's length, as the
    corner's: every column (the steer-axis ones included) equals the corner's sweep."""
    data, model = axle(name)
    heights = [-20.0, 0.0, 15.0]
    sweep = load_sweep(
        {
            "targets": [
                {"point": "wheel_center", "side": s, "direction": {"axis": "z"}, "values": heights}
                for s in ("left", "right")
            ]
        }
    )
    columns = axle_results(model, sweep, solve_axle_sweep(model, sweep)).columns
    compared = 0
    for side, drawn in (("left", data), ("right", mirrored(data))):
        corner = pin_susp.Corner(drawn).run_sweep(
            {"targets": [{"point": "wheel_center", "direction": {"axis": "z"}, "values": heights}]}
        )
        for column in corner.columns:
            ours = f"{column}_{side}"
            if ours in columns and not column.startswith("anti_"):
                np.testing.assert_allclose(columns[ours], corner[column], atol=1e-9, err_msg=ours)
                compared += 1
    assert compared > 50 and any(c.startswith("isa_") for c in corner.columns)


def droplink_at(point):
    def change(data):
        data["hardpoints"]["left"]["droplink_u_bar"] = point

    return change


def targets_of(*targets):
    return {"steps": 1, "targets": list(targets)}


HEAVE0 = {"quantity": "heave", "values": [0]}
RACK_L = {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"}, "values": [0]}
RACK_R = RACK_L | {"side": "right"}
HEAVE1 = HEAVE0 | {"values": [1]}
ROLL120 = {"quantity": "roll", "values": [120]}
ON_ROCKER = {"x": 0, "y": 300, "z": 450}  # droplink_rocker's place


@pytest.mark.parametrize(
    ("geometry_change", "sweep", "blamed", "words"),
    [
        (droplink_at(ON_ROCKER), None, "hardpoints.left.droplink_u_bar", "no length"),
        (droplink_at({"x": 0, "y": 300, "z": 380}), None, "hardpoints", "dead centre"),
        (lambda d: d.pop("scope"), None, "scope", "needs scope: axle"),
        (None, targets_of(HEAVE0, HEAVE1, RACK_L), "targets[1]", "repeats targets[0]"),
        (None, targets_of(HEAVE0, RACK_R, RACK_L), "targets[2]", "the rack is one freedom"),
        (None, targets_of(ROLL120, HEAVE0, RACK_L), "targets[0]", "±90 deg"),
    ],
    ids=["zero_droplink", "dead_centre", "no_scope", "heave_twice", "rack_twice", "roll_120"],
)  # fmt: skip
def test_axle_mistakes_found_by_review_get_one_line(
    tmp_path, capsys, geometry_change, sweep, blamed, words
):
    """Each blames the file and key at fault (the geometry, not the sweep), exit 2."""
    from pin_susp.cli import main

    geometry = axle_file(tmp_path, geometry_change)
    sweep_path = tmp_path / "sweep.yaml"
    data = sweep or yaml.safe_load((ROOT / "examples/roll.yaml").read_text())
    sweep_path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out.csv"
    assert main(["sweep", str(geometry), str(sweep_path), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    source = sweep_path if sweep else geometry
    assert err.startswith(f"pin-susp: error: {source}: {blamed}") and words in err, err
    assert len(err.splitlines()) == 1 and not out.exists()


def test_ackermann_is_blank_without_a_steering_input(tmp_path):
    """Roll steer alone (the rack at its centre) is not steering: no Ackermann figure."""
    model = AxleModel(load_axle(axle_file(tmp_path)))
    sweep = load_sweep(ROOT / "examples/roll.yaml")
    columns = axle_results(model, sweep, solve_axle_sweep(model, sweep)).columns
    assert np.isnan(columns["ackermann"]).all()
    assert np.nanmax(np.abs(columns["steer_angle_left"] - columns["steer_angle_left"][15])) > 0.5


def test_sensitivity_says_what_it_does_not_cover(tmp_path, capsys):
    from pin_susp.cli import main

    out = tmp_path / "s.csv"
    args = ["sensitivity", str(ROOT / "examples/axle_front.yaml"), "--points", "droplink_rocker"]
    assert main([*args, "-o", str(out)]) == 2
    assert "anti-roll bar" in capsys.readouterr().err
    rigid = axle_file(tmp_path, lambda d: d["axle_config"]["anti_roll"].update(stiffness="rigid"))
    assert main(["sensitivity", str(rigid), "-o", str(out)]) == 2
    assert "rigid anti-roll bar" in capsys.readouterr().err and not out.exists()


def test_the_roll_rows_jacobian_is_its_residuals_derivative(tmp_path):
    """The roll target's row (closed form, from the wheel centres' frames) against
    central differences of its residual along random configuration directions."""
    from pin_susp.constraints import RollTarget
    from pin_susp.subjects.axle import axle_rows

    model = AxleModel(load_axle(axle_file(tmp_path)))
    (roll,) = [r for r in axle_rows(model, roll_sweep().targets) if isinstance(r, RollTarget)]
    rng = np.random.default_rng(3)
    q = model.q_design + rng.normal(0.0, 0.02, model.model.nq)
    model.kin.update(q)
    row = roll.jacobian(model.kin)[0]
    h = 1e-6
    for _ in range(5):
        dq = rng.normal(size=model.model.nv)
        values = []
        for sign in (1.0, -1.0):
            model.kin.update(q + sign * h * dq)
            values.append(roll.residual(model.kin)[0])
        assert row @ dq == pytest.approx((values[0] - values[1]) / (2 * h), rel=1e-6, abs=1e-9)


def no_bar(data):
    data["axle_config"]["anti_roll"] = {"type": "none"}
    data["hardpoints"].pop("center")


@pytest.mark.parametrize(
    ("change", "key", "words"),
    [
        (lambda d: d["hardpoints"]["left"].update(arb_u_bar_axis_a={"x": 0, "y": 300, "z": 300}),
         "hardpoints.left.arb_u_bar_axis_a", "hardpoints.center"),
        (no_bar, "hardpoints.left.droplink_rocker", "does not have"),
    ],
)  # fmt: skip
def test_a_bar_point_in_the_wrong_place_says_where_it_goes(tmp_path, change, key, words):
    with pytest.raises(pin_susp.InputError) as info:
        load_axle(axle_file(tmp_path, change))
    assert info.value.key == key and words in str(info.value)
