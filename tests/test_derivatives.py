"""Instant centres, anti geometry, derivative columns and hardpoint sensitivities."""

import copy

import numpy as np
import pytest
from conftest import EXAMPLES, example, mirrored, sweep_csv

import pin_susp
from pin_susp.analyses.sensitivity import HardpointSensitivity
from pin_susp.cli import main


def front_view_corner() -> dict:
    """Pivots along X, wishbones tilted in front view: the instant axis runs along X."""
    g = example("double_wishbone.yaml")
    g["hardpoints"].update(
        {
            "lower_wishbone_inboard_front": {"x": 200, "y": 300, "z": 200},
            "lower_wishbone_inboard_rear": {"x": -200, "y": 300, "z": 200},
            "lower_wishbone_outboard": {"x": 0, "y": 700, "z": 150},
            "upper_wishbone_inboard_front": {"x": 200, "y": 350, "z": 500},
            "upper_wishbone_inboard_rear": {"x": -200, "y": 350, "z": 500},
            "upper_wishbone_outboard": {"x": 0, "y": 650, "z": 530},
            "trackrod_outboard": {"x": 150, "y": 680, "z": 275},
            "axle_inboard": {"x": 0, "y": 680, "z": 330},
            "axle_outboard": {"x": 0, "y": 800, "z": 332},
        }
    )
    return g


def design_pose(corner):
    targets = [pin_susp.Target("wheel_center", "z", 0.0)]
    if corner.geometry.steering == "rack":
        targets.append(pin_susp.Target("trackrod_inboard", "y", 0.0))
    return corner.solve_pose(targets)


def test_front_view_instant_centre_by_hand():
    """Lines (300, 200) + a(400, −50) and (350, 500) + b(300, 30) meet at a = −59/18."""
    pose = design_pose(pin_susp.Corner(front_view_corner()))
    a = -59 / 18
    assert pose.metrics["fvic_y"] == pytest.approx(300 + 400 * a, abs=1e-9)
    assert pose.metrics["fvic_z"] == pytest.approx(200 - 50 * a, abs=1e-9)
    # the instant axis is parallel to X: it never crosses the side-view plane
    assert np.isnan(pose.metrics["svic_x"]) and np.isnan(pose.metrics["svsa_angle"])
    cp = pose.points["contact_patch_center"]
    dy, dz = 300 + 400 * a - cp[1], 200 - 50 * a - cp[2]
    assert pose.metrics["fvsa_length"] == pytest.approx(np.hypot(dy, dz), abs=1e-9)


def instant_axis(p, plane_axis):
    """Independent construction: the two wishbone planes' line, cut by a plane through WC."""
    normals, offsets = [], []
    for arm in ("upper_wishbone", "lower_wishbone"):
        f, r, o = (p[f"{arm}_{e}"] for e in ("inboard_front", "inboard_rear", "outboard"))
        n = np.cross(r - f, o - f)
        normals.append(n)
        offsets.append(n @ f)
    direction = np.cross(*normals)
    cut = np.zeros(3)
    cut[plane_axis] = 1.0
    point = np.linalg.solve(np.array([*normals, cut]), [*offsets, p["wheel_center"][plane_axis]])
    return point, direction


@pytest.mark.parametrize("geometry", ["fixed_toe_link.yaml", "pushrod_rocker.yaml"])
def test_instant_centres_match_an_independent_plane_intersection(geometry):
    data = example(geometry)
    if geometry == "pushrod_rocker.yaml":  # tilt the upper wishbone: planes no longer parallel
        data["hardpoints"]["upper_wishbone_inboard_front"]["z"] = 530
        data["hardpoints"]["upper_wishbone_inboard_rear"]["z"] = 490
    sweep = "bump.yaml" if "toe" in geometry else "bump_steer.yaml"
    corner = pin_susp.Corner(data)
    results = corner.run_sweep(example(sweep))
    for i in range(0, len(results), 10):
        p = {n: np.array([results[f"{n}_{a}"][i] for a in "xyz"]) for n in corner.point_names}
        sv, _ = instant_axis(p, 1)
        fv, _ = instant_axis(p, 0)
        assert results["svic_x"][i] == pytest.approx(sv[0], rel=1e-9)
        assert results["svic_z"][i] == pytest.approx(sv[2], rel=1e-9)
        assert results["fvic_y"][i] == pytest.approx(fv[1], rel=1e-9)
        assert results["fvic_z"][i] == pytest.approx(fv[2], rel=1e-9)
        cp = p["contact_patch_center"]
        assert results["svsa_length"][i] == pytest.approx(sv[0] - cp[0], rel=1e-9)
        assert results["svsa_angle"][i] == pytest.approx(
            np.degrees(np.arctan((sv[2] - cp[2]) / (sv[0] - cp[0]))), abs=1e-9
        )


def test_parallel_wishbone_planes_leave_instant_centres_empty(tmp_path):
    out = sweep_csv(tmp_path, "double_wishbone.yaml", "bump_steer.yaml")
    lines = [ln for ln in out.read_text().splitlines() if not ln.startswith("#")]
    header = lines[0].split(",")
    first = dict(zip(header, lines[1].split(","), strict=True))
    # horizontal wishbones: parallel planes at design → no instant axis; no brake bias
    for name in ("anti_dive", "anti_lift", "anti_squat"):
        assert first[name] == ""
    assert "svic_x" in header and "motion_ratio" not in header


def test_nearly_parallel_planes_give_a_large_accurate_centre():
    data = example("double_wishbone.yaml")
    data["hardpoints"]["upper_wishbone_inboard_front"]["z"] = 500.001  # 1 µm over 500 mm
    pose = design_pose(pin_susp.Corner(data))
    p = {k: v for k, v in pose.points.items()}
    sv, _ = instant_axis(p, 1)
    assert abs(pose.metrics["svic_x"]) > 1e5
    assert pose.metrics["svic_x"] == pytest.approx(sv[0], rel=1e-6)
    assert pose.metrics["svic_z"] == pytest.approx(sv[2], rel=1e-6)


def anti_corner(axle: str) -> dict:
    data = example("double_wishbone.yaml")
    data["hardpoints"]["upper_wishbone_inboard_front"]["z"] = 520
    data["hardpoints"]["upper_wishbone_inboard_rear"]["z"] = 470
    data["config"].update(axle_position=axle, front_brake_bias=0.62, driven_axle=axle)
    return data


@pytest.mark.parametrize("axle", ["front", "rear"])
def test_anti_geometry_follows_the_formulas(axle):
    data = anti_corner(axle)
    results = pin_susp.Corner(data).run_sweep(example("bump_steer.yaml"))
    L, cg_z, fbb = 2500.0, 450.0, 0.62
    for i in (0, 20, 40):
        x, z = results["svic_x"][i], results["svic_z"][i]
        cpx, cpz = results["contact_patch_center_x"][i], results["contact_patch_center_z"][i]
        wcx, wcz = results["wheel_center_x"][i], results["wheel_center_z"][i]
        h = cg_z - cpz
        if axle == "front":
            assert results["anti_dive"][i] == pytest.approx(
                100 * fbb * L / h * (z - cpz) / (cpx - x), rel=1e-10
            )
            assert np.isnan(results["anti_lift"][i])
            squat = (z - wcz) / (wcx - x)
        else:
            assert results["anti_lift"][i] == pytest.approx(
                100 * (1 - fbb) * L / h * (z - cpz) / (x - cpx), rel=1e-10
            )
            assert np.isnan(results["anti_dive"][i])
            squat = (z - wcz) / (x - wcx)
        assert results["anti_squat"][i] == pytest.approx(100 * L / h * squat, rel=1e-10)
    assert np.all(np.isfinite(results["svic_x"]))


def fd_pose(corner, bump, rack):
    targets = [pin_susp.Target("wheel_center", "z", bump)]
    if corner.geometry.steering == "rack":
        targets.append(pin_susp.Target("trackrod_inboard", "y", rack))
    pose = corner.solve_pose(targets)
    return {**pose.metrics, "wheel_center_x": pose.points["wheel_center"][0]}


@pytest.mark.parametrize("geometry", ["pushrod_rocker.yaml", "fixed_toe_link.yaml", "anti_front"])
def test_derivative_columns_match_central_differences_of_the_full_solve(geometry):
    data = anti_corner("front") if geometry == "anti_front" else example(geometry)
    if geometry == "pushrod_rocker.yaml":
        data["spring"] = {"type": "torsion_bar"}
        for key in ("strut_top", "strut_bottom"):
            data["hardpoints"].pop(key)
    corner = pin_susp.Corner(data)
    h = 1e-3  # mm
    for bump, rack in ((-25.0, 4.0), (35.0, -7.0)):
        pose = corner.solve_pose(
            [pin_susp.Target("wheel_center", "z", bump)]
            + (
                [pin_susp.Target("trackrod_inboard", "y", rack)]
                if corner.geometry.steering == "rack"
                else []
            )
        )
        assert len(pose.derivatives) >= 8
        for name, value in pose.derivatives.items():
            metric, driver = name.removeprefix("deriv_").split("_wrt_")
            db, dr = (h, 0.0) if driver == "hub_z" else (0.0, h)
            plus, minus = (
                fd_pose(corner, bump + db, rack + dr),
                fd_pose(corner, bump - db, rack - dr),
            )
            fd = (plus[metric] - minus[metric]) / (2 * h)
            assert value == pytest.approx(fd, rel=1e-6, abs=1e-8), name
        if "torsion_bar_twist" in pose.metrics:
            assert pose.derivatives["deriv_torsion_bar_twist_wrt_hub_z"] != 0.0


def test_motion_ratio_is_minus_the_damper_rate():
    results = pin_susp.Corner(example("fixed_toe_link.yaml")).run_sweep(example("bump.yaml"))
    np.testing.assert_array_equal(
        results["motion_ratio"], -results["deriv_damper_length_wrt_hub_z"]
    )
    assert results.units["motion_ratio"] == "mm/mm"
    assert 0.5 < results["motion_ratio"][30] < 1.0


def test_new_columns_mirror_with_the_conventions():
    from test_metrics import mirrored_sweep

    left_geo, sweep = anti_corner("front"), example("bump_steer.yaml")
    left = pin_susp.Corner(left_geo).run_sweep(sweep)
    right = pin_susp.Corner(mirrored(left_geo)).run_sweep(mirrored_sweep(sweep))
    same = (
        "svic_x",
        "svic_z",
        "fvic_z",
        "svsa_length",
        "fvsa_length",
        "svsa_angle",
        "anti_dive",
        "anti_squat",
    )
    for name in same:
        np.testing.assert_allclose(right[name], left[name], rtol=1e-9, err_msg=name)
    np.testing.assert_allclose(right["fvic_y"], -left["fvic_y"], rtol=1e-9)
    for name in left.columns:
        if name.endswith("_wrt_hub_z"):
            np.testing.assert_allclose(right[name], left[name], atol=1e-12, err_msg=name)
        elif name.endswith("_wrt_rack_displacement"):  # +y rack is the other way on the right
            np.testing.assert_allclose(right[name], -left[name], atol=1e-12, err_msg=name)


def rebuild_and_solve(data, targets):
    corner = pin_susp.Corner(data)
    pose = corner.solve_pose(targets)
    return {**pose.metrics, **pose.derivatives, "wheel_center_x": pose.points["wheel_center"][0]}


@pytest.mark.parametrize("geometry", ["double_wishbone.yaml", "pushrod_rocker.yaml"])
def test_hardpoint_sensitivities_match_rebuild_and_solve_for_every_entry(geometry):
    data = example(geometry)
    data["hardpoints"]["upper_wishbone_inboard_front"]["z"] = 520  # IC defined
    corner = pin_susp.Corner(data)
    targets = [
        pin_susp.Target("wheel_center", "z", 30.0),
        pin_susp.Target("trackrod_inboard", "y", -6.0),
    ]
    pose = corner.solve_pose(targets)
    s = HardpointSensitivity(corner).at(pose.q, targets)
    assert s.metrics["camber"] == pytest.approx(pose.metrics["camber"], abs=1e-12)
    h = 1e-3  # mm
    checked = 0
    for i, name in enumerate(s.hardpoints):
        for a, axis in enumerate("xyz"):
            moved = []
            for sign in (1.0, -1.0):
                d = copy.deepcopy(data)
                d["hardpoints"][name][axis] += sign * h
                moved.append(rebuild_and_solve(d, targets))
            for metric, values in s.values.items():
                fd = (moved[0][metric] - moved[1][metric]) / (2 * h)
                scale = max(1.0, abs(moved[0][metric]))
                assert values[i, a] == pytest.approx(fd, rel=1e-5, abs=2e-9 * scale), (
                    metric,
                    name,
                    axis,
                )
                checked += 1
    assert checked > 800


def test_sensitivity_cli_writes_long_format_and_a_table(tmp_path, capsys):
    out = tmp_path / "sens.csv"
    assert (
        main(
            [
                "sensitivity",
                str(EXAMPLES / "fixed_toe_link.yaml"),
                "--sweep",
                str(EXAMPLES / "bump.yaml"),
                "-o",
                str(out),
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "deriv_camber_wrt_hub_z" in printed and "to change it by" in printed
    lines = [ln for ln in out.read_text().splitlines() if not ln.startswith("#")]
    assert lines[0] == "step_index,metric,hardpoint,axis,value,unit"
    rows = [ln.split(",") for ln in lines[1:]]
    steps = {r[0] for r in rows}
    assert len(steps) == 61
    per_step = len(rows) // 61
    assert per_step % (12 * 3) == 0  # 12 hardpoints × xyz per metric
    units = {r[1]: r[5] for r in rows}
    assert units["camber"] == "deg/mm" and units["deriv_camber_wrt_hub_z"] == "deg/mm/mm"


def same_sensitivities(a, b, columns=None) -> None:
    """Two lists of Sensitivity equal bit for bit (in ``columns``, else every one)."""
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        names = list(x.values) if columns is None else columns
        assert names and x.step == y.step and x.hardpoints == y.hardpoints
        for name in names:
            assert np.array_equal(x.values[name], y.values[name], equal_nan=True), name
            assert np.array_equal(x.metrics[name], y.metrics[name], equal_nan=True), name


@pytest.mark.parametrize(
    "geometry",
    [
        "double_wishbone.yaml",
        "macpherson.yaml",
        "multilink_rear.yaml",
        "pushrod_rocker.yaml",
        "semi_trailing_arm.yaml",  # (no closure: its arm's pivot alone)
    ],
)
def test_many_states_at_once_and_a_shared_model_give_each_states_own(geometry):
    """HardpointSensitivity.at_many (the states' metric functions run once for all) gives
    what ``at`` gives at each state alone, bit for bit — also where no column asked for
    reads the drivers' rates (needs_rates: they are left out, the states' dq/dh solved
    together) — and so does a variant's model that shares another's frames and
    Pinocchio data (``like``, a study's) what its own gives."""
    from pin_susp.analyses.sensitivity_model import needs_rates
    from pin_susp.columns.metrics import METRICS

    def states(corner):
        rack = [pin_susp.Target("trackrod_inboard", "y", 4.0)]
        held = rack if corner.geometry.steering == "rack" else []
        out = [(corner.q_design, None)]
        for z in (-25.0, 10.0, 30.0):
            targets = [pin_susp.Target("wheel_center", "z", z)] + held
            out.append((corner.solve_pose(targets).q, targets))
        # other rows (the states of each set of rows solved together): the contact patch
        targets = [pin_susp.Target("contact_patch_center", "z", 15.0)] + held
        out.insert(2, (corner.solve_pose(targets).q, targets))
        return out

    data = example(geometry)
    corner = pin_susp.Corner(data)
    first = HardpointSensitivity(corner)
    at = states(corner)
    alone = [first.at(q, targets, step=i) for i, (q, targets) in enumerate(at)]
    same_sensitivities(first.at_many(at, list(range(len(at)))), alone)
    # the columns of positions alone (Metric.rates False), without the drivers' rates
    g = corner.geometry
    plain = [m.name for m in METRICS if not m.rates and m.applies(g)]
    assert not needs_rates(g, set(plain)) and needs_rates(g, {"deriv_camber_wrt_hub_z"})
    steps = list(range(len(at)))
    same_sensitivities(first.at_many(at, steps, set(plain)), alone, plain)
    # (a column unknown at a state — a trailing arm's kingpin — is worked out again with
    # the rates, in case they are what it lacks)
    known = [n for n in plain if all(np.isfinite(s.values[n]).all() for s in alone)]
    rest = [n for n in known if not n.startswith(("svic", "fvic", "svsa", "fvsa", "anti"))]
    same_sensitivities(first.at_many(at, steps, set(rest)), alone, rest)
    assert frozenset(rest) not in first.rated  # (computed without the rates)
    if geometry == "multilink_rear.yaml":  # its instant centres come from its motion
        assert np.isfinite(alone[1].values["svic_x"]).all()
        first.at_many(at, steps, {"svic_x"})
        assert frozenset({"svic_x"}) in first.rated  # found unknown without the rates
    # variants: a link end moved, its model sharing the first's frames and data; a
    # pivot's end moved (its axis turned: the data keeps a pivot's axis), not sharing
    link, pivot = "trackrod_outboard", "lower_wishbone_inboard_front"
    if geometry == "multilink_rear.yaml":  # (a universal joint at its lower front link)
        link, pivot = "toe_link_outboard", "lower_front_link_outboard"
    if geometry == "semi_trailing_arm.yaml":
        link, pivot = "strut_top", "arm_pivot_outboard"
    for point, shares in ((link, True), (pivot, False)):
        moved = copy.deepcopy(data)
        moved["hardpoints"][point]["z"] += 7.0
        variant = pin_susp.Corner(moved)
        shared = HardpointSensitivity(variant, like=first)
        assert (shared.kin.data is first.kin.data) == shares
        at = states(variant)
        own = HardpointSensitivity(variant).at_many(at, list(range(len(at))))
        same_sensitivities(shared.at_many(at, list(range(len(at)))), own)
        assert any(not np.array_equal(v, alone[1].values[k]) for k, v in own[1].values.items())


def test_an_axles_sensitivities_at_many_states_are_each_states_own():
    """SubjectSensitivity.at_many on an axle (its own columns, of both corners: roll
    centre, track, the roll rates) equals ``at`` state by state, bit for bit."""
    from pin_susp.analyses.sensitivity import SubjectSensitivity
    from pin_susp.model.sweep import load_sweep
    from pin_susp.subjects.axle import AxleModel, load_axle, solve_axle_sweep

    model = AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))
    rack = {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"}}
    roll = load_sweep(
        {
            "targets": [
                {"quantity": "roll", "values": [-2.0, 0.5, 3.0]},
                {"quantity": "heave", "values": [10.0, 0.0, -5.0]},
                rack | {"values": [3.0, 0.0, -2.0]},
            ]
        }
    )
    states = [(None, 0, None)] + [
        (solution.q, i + 1, None) for i, solution in enumerate(solve_axle_sweep(model, roll))
    ]
    for one_sided in (False, True):
        sens = SubjectSensitivity(model, one_sided)
        alone = [sens.at(q, step, targets) for q, step, targets in states]
        assert "roll_center_z" in alone[0].values
        same_sensitivities(sens.at_many(states), alone)
