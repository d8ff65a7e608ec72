"""`pin-susp validate` on an axle (docs/axle.md): every step of an axle sweep re-solved
by the point-based formulation — both corners' points as unknowns, one rack unknown
for both trackrods, the U-bar's arm ends on circles about the bar's axis, the T-bar's
crossbar a rigid triangle with its pivot and its midpoint in y = 0, rigid droplinks,
numpy/scipy only — and by MuJoCo from the exported MJCF, column by column.
"""

from dataclasses import replace

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example, mirrored
from pointwise import PointwiseAxle

from pin_susp.analyses import pointwise
from pin_susp.cli import main
from pin_susp.model.geometry import load_geometry
from pin_susp.model.sweep import load_sweep
from pin_susp.subjects.axle import AxleModel, axle_results, load_axle, solve_axle_sweep
from pin_susp.validate import validate

AXLE = EXAMPLES / "axle_front.yaml"
T_BAR = EXAMPLES.parent / "tests" / "data" / "axle_t_bar.yaml"
SOLVER = {"step_index", "solver_converged", "solver_max_residual", "solver_iterations"}


def every(sweep, n: int):
    """Every n-th step of a sweep (its first and last kept): a few steps, quickly."""
    keep = np.unique(np.r_[np.arange(0, sweep.steps, n), sweep.steps - 1])
    return replace(sweep, targets=[replace(t, values=t.values[keep]) for t in sweep.targets])


def bump_steer():
    """Each wheel centre at its own height and the rack moving: bump, rebound, roll
    and steer at once."""

    def target(point, axis, values, side="left"):
        return {"point": point, "side": side, "direction": {"axis": axis}, "values": values}

    return load_sweep(
        {
            "targets": [
                target("wheel_center", "z", [-30.0, 0.0, 25.0, 40.0]),
                target("wheel_center", "z", [20.0, -10.0, 0.0, -35.0], "right"),
                target("trackrod_inboard", "y", [-10.0, 5.0, 0.0, 12.0]),
            ]
        }
    )


SWEEPS = {
    "roll": lambda: every(load_sweep(EXAMPLES / "roll.yaml"), 10),
    "heave_roll": lambda: every(load_sweep(EXAMPLES / "heave_roll.yaml"), 10),
    "bump_steer": bump_steer,
}


def assert_points_equal_the_point_based_formulation(geometry, sweep):
    """Each step re-solved from the design state by the point-based formulation: every
    point of pin_susp's CSV columns (both corners', the bar's) within 1e-9 mm."""
    axle = load_axle(geometry)
    model = AxleModel(axle)
    results = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    assert results["solver_converged"].all()
    reference = PointwiseAxle(axle)
    for step in range(sweep.steps):
        points, residual = reference.solve(sweep.targets, step)
        assert residual < 1e-12
        for name in model.output_points:
            ours = [results[f"{name}_{axis}"][step] for axis in "xyz"]
            np.testing.assert_allclose(ours, points[name], rtol=0, atol=1e-9, err_msg=name)
    return results


@pytest.mark.parametrize("name", SWEEPS)
def test_axle_sweep_equals_the_point_based_formulation(name):
    results = assert_points_equal_the_point_based_formulation(AXLE, SWEEPS[name]())
    assert np.ptp(results["arb_twist"]) > 1.0  # the bar is wound: its droplinks did work


@pytest.mark.parametrize("geometry", [AXLE, T_BAR], ids=["u_bar", "t_bar"])
@pytest.mark.parametrize("name", SWEEPS)
def test_validate_compares_every_axle_column_with_both_engines(name, geometry):
    """Both engines agree on every column pin_susp writes (per side, the axle's, the
    derivatives along hub z, the rack and roll) that either has a value in."""
    axle = AxleModel(load_axle(geometry))
    results, reports = validate(axle, SWEEPS[name]())
    written = {c for c in results.columns if c not in SOLVER and not np.isnan(results[c]).all()}
    point_columns = {f"{p}_{a}" for p in axle.output_points for a in "xyz"}
    for report in reports:
        assert report.agrees, (report.engine, report.disagree, report.failed_steps, report.note)
        assert set(report.differences) == written - point_columns | {"points"}
        assert report.differences["points"] <= 1e-9
        assert not report.not_compared


def macpherson_axle(mount: str) -> dict:
    """The MacPherson example corner on both sides with a U-bar behind the axle; each
    droplink hangs from the body ``mount`` names (no rocker)."""
    corner = example("macpherson.yaml")
    config = corner["config"]
    left = dict(corner["hardpoints"])
    left |= {
        "upright": {
            "droplink_lower": {"x": -20, "y": 660, "z": 380},  # on the strut tube, inboard
            "droplink_u_bar": {"x": -20, "y": 640, "z": 200},  # arm: 100 mm ahead of the bar
        },
        "lower_wishbone": {
            "droplink_lower": {"x": 0, "y": 650, "z": 135},
            "droplink_u_bar": {"x": 0, "y": 600, "z": 200},  # 120 mm ahead of the bar
        },
    }[mount]
    vehicle = ("cg_position", "wheelbase", "front_brake_bias", "driven_axle")
    return {
        "type": "macpherson",
        "scope": "axle",
        "name": f"MacPherson axle, droplinks on the {mount}",
        "vehicle_config": {k: config[k] for k in vehicle},
        "axle_config": {
            "axle_position": "front",
            "steering": config["steering"],
            "wheel": config["wheel"],
            "anti_roll": {"type": "u_bar", "mount": mount},
        },
        "hardpoints": {
            "left": left,
            "center": {
                "arb_u_bar_axis_a": {"x": -120, "y": 550, "z": 200},
                "arb_u_bar_axis_b": {"x": -120, "y": -550, "z": 200},
            },
        },
    }


def mm(point: dict) -> np.ndarray:
    return np.array([point[x] for x in "xyz"], float)


def solved(results, name: str) -> np.ndarray:
    """A point's (n, 3) positions from the results' columns (mm)."""
    return np.column_stack([results[f"{name}_{x}"] for x in "xyz"])


ROLL_STEER = {
    "targets": [
        {"quantity": "roll", "values": [-3.0, 2.0]},
        {"quantity": "heave", "values": [10.0, -20.0]},
        {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
         "values": [5.0, -8.0]},
    ]
}  # fmt: skip


@pytest.mark.parametrize("mount", ["upright", "lower_wishbone"])
def test_macpherson_axle_with_a_u_bar_on_the_named_body(mount):
    """Droplinks from the strut's upright or the lower arm: the points equal the
    point-based formulation's; every droplink keeps its length and every arm end its
    distance to the bar's axis (read from pin_susp's own points); both engines agree."""
    data = macpherson_axle(mount)
    sweep = load_sweep(ROLL_STEER)
    results = assert_points_equal_the_point_based_formulation(data, sweep)
    center = data["hardpoints"]["center"]
    a, b = (mm(center[f"arb_u_bar_axis_{k}"]) for k in "ab")
    axis = (b - a) / np.linalg.norm(b - a)
    for side, mirror in (("left", 1.0), ("right", -1.0)):
        lower, end = (
            mm(data["hardpoints"]["left"][k]) * [1.0, mirror, 1.0]
            for k in ("droplink_lower", "droplink_u_bar")
        )
        moved = {k: solved(results, f"{side}_{k}") for k in ("droplink_lower", "droplink_u_bar")}
        length = np.linalg.norm(moved["droplink_u_bar"] - moved["droplink_lower"], axis=1)
        np.testing.assert_allclose(length, np.linalg.norm(end - lower), atol=1e-9)
        arm = np.linalg.norm(np.cross(moved["droplink_u_bar"] - a, axis), axis=1)
        np.testing.assert_allclose(arm, np.linalg.norm(np.cross(end - a, axis)), atol=1e-9)
    assert abs(results["arb_twist"]).min() > 5.0
    _, reports = validate(AxleModel(load_axle(data)), sweep)
    for report in reports:
        assert report.agrees, (report.engine, report.disagree, report.failed_steps, report.note)


def sweep_file(tmp_path, sweep: dict) -> str:
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(sweep))
    return str(path)


def test_cli_validates_an_axle_and_prints_its_columns(tmp_path, capsys):
    code = main(["validate", str(AXLE), sweep_file(tmp_path, ROLL_STEER)])
    out = capsys.readouterr().out
    assert code == 0, out
    rows = {line.split()[0] for line in out.splitlines()[2:] if line.startswith("  ")}
    assert {"camber_left", "camber_right", "roll", "arb_twist", "points"} <= rows
    assert {"deriv_roll_center_z_wrt_roll", "deriv_arb_twist_wrt_hub_z_right"} <= rows
    assert "pointwise: agrees within 1e-06" in out and "mujoco: agrees within 1e-06" in out
    assert list(tmp_path.iterdir()) == [tmp_path / "sweep.yaml"]  # nothing written


def test_cli_axle_validate_fails_when_the_bar_moved_after_export(tmp_path, capsys):
    """The MJCF exported before a droplink's arm end moved 5 mm: MuJoCo's axle is not
    the file's any more (exit 1, its columns marked), the point-based one still is."""
    exported = tmp_path / "axle.xml"
    assert main(["mjcf", str(AXLE), "-o", str(exported)]) == 0
    data = yaml.safe_load(AXLE.read_text())
    data["hardpoints"]["left"]["droplink_u_bar"]["x"] += 5.0
    moved = tmp_path / "moved.yaml"
    moved.write_text(yaml.safe_dump(data))
    capsys.readouterr()
    sweep = sweep_file(tmp_path, ROLL_STEER)
    code = main(["validate", str(moved), sweep, "--mjcf", str(exported)])
    out = capsys.readouterr().out
    assert code == 1
    assert "pointwise: agrees" in out and "mujoco: DISAGREES" in out
    assert "arb_arm_angle_left" in out.split("mujoco: DISAGREES on ", 1)[1]


def test_cli_axle_validate_names_a_bad_target(tmp_path, capsys):
    """An axle's point target without its side: one line naming the file and key, exit 2."""
    targets = [dict(t) for t in ROLL_STEER["targets"]]
    del targets[2]["side"]
    path = sweep_file(tmp_path, {"targets": targets})
    assert main(["validate", str(AXLE), path]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and path in err and "targets[2].side" in err


def test_a_rigid_u_bar_turns_both_arms_as_one():
    """stiffness: rigid — one bump target moves both wheels: pin_susp's poses equal the
    point-based formulation's (the bar one part), both arms turned alike."""
    data = yaml.safe_load(AXLE.read_text())
    data["axle_config"]["anti_roll"]["stiffness"] = "rigid"
    axle = load_axle(data)
    model = AxleModel(axle)
    sweep = load_sweep(
        {
            "targets": [
                {"point": "wheel_center", "side": "left", "direction": {"axis": "z"},
                 "values": [15.0, -20.0, 30.0]},
                {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
                 "values": [3.0, -4.0, 0.0]},
            ]
        }
    )  # fmt: skip
    reference = PointwiseAxle(axle)
    center = data["hardpoints"]["center"]
    a, b = (mm(center[f"arb_u_bar_axis_{k}"]) for k in "ab")
    axis = (b - a) / np.linalg.norm(b - a)
    for step, solution in enumerate(solve_axle_sweep(model, sweep)):
        assert solution.converged
        ours = {k: v * 1e3 for k, v in model.positions(solution.q).items()}
        points, residual = reference.solve(sweep.targets, step)
        assert residual < 1e-12
        for name in model.output_points:
            np.testing.assert_allclose(ours[name], points[name], rtol=0, atol=1e-9, err_msg=name)
        # each arm's turn about the axis from design (right-hand rule), written here
        turn = {}
        for side in ("left", "right"):
            design = reference.points_model.design[f"{side}_droplink_u_bar"] * 1e3
            w0, w = (
                np.cross(axis, np.cross(p - a, axis))
                for p in (design, ours[f"{side}_droplink_u_bar"])
            )
            turn[side] = np.arctan2(np.cross(w0, w) @ axis, w0 @ w)
        assert turn["left"] == pytest.approx(turn["right"], abs=1e-12)
        assert abs(turn["left"]) > 1e-2  # the bar turned, and the right wheel with it


def test_a_droplink_on_a_body_the_point_based_formulation_lacks_is_said():
    """The strut's sliding tube is no rigid part of points here: the point-based engine
    says so (its report's note, not a failure), MuJoCo still checks every column."""
    data = macpherson_axle("upright")
    data["axle_config"]["anti_roll"]["mount"] = "strut_rod"
    pointwise, mujoco = validate(AxleModel(load_axle(data)), load_sweep(ROLL_STEER))[1]
    assert "no rigid part 'strut_rod'" in pointwise.note and not pointwise.differences
    assert mujoco.agrees and mujoco.differences["points"] <= 1e-9


def test_a_roll_centre_far_out_is_compared_relative_to_its_lever():
    """open-kinematics' axle with parallel wishbones: near design the roll centre lies
    hundreds of metres out, where rounding grows by |RC|/track — the engines still
    agree over the file's own roll sweep (±3.6°, 16 steps)."""
    data = EXAMPLES.parent / "tests" / "data"
    model = AxleModel(load_axle(data / "open_kinematics_axle_geometry.yaml"))
    results, reports = validate(model, load_sweep(data / "open_kinematics_axle_rocker_sweep.yaml"))
    assert np.abs(results["roll_center_y"]).max() > 100e3  # mm
    for report in reports:
        assert report.agrees, (report.engine, report.disagree, report.failed_steps, report.note)


def test_a_toe_link_axle_is_validated_along_each_sides_toe_link():
    """Two multilink rear corners (no rack): each side's second driver is its fixed toe
    link's length. The point-based engine moves it (its steer-axis columns compared);
    MuJoCo's links are rigid, so it names those columns as not compared."""
    data = example("multilink_rear.yaml")
    model = AxleModel(load_geometry(data), load_geometry(mirrored(data)))
    sweep = load_sweep(
        {
            "targets": [
                {"point": "wheel_center", "side": side, "direction": {"axis": "z"},
                 "values": values}
                for side, values in (("left", [-20.0, 15.0]), ("right", [10.0, 15.0]))
            ]
        }
    )  # fmt: skip
    pointwise, mujoco = validate(model, sweep)[1]
    steer_axis = {f"isa_{m}_{side}" for m in ("caster", "kpi") for side in ("left", "right")}
    assert pointwise.agrees and not pointwise.not_compared
    assert steer_axis <= set(pointwise.differences)
    assert mujoco.agrees and steer_axis <= mujoco.not_compared


def t_bar(rigid: bool = False) -> dict:
    """tests/data/axle_t_bar.yaml; ``rigid``: its bar locked (stiffness: rigid)."""
    data = yaml.safe_load(T_BAR.read_text())
    if rigid:
        data["axle_config"]["anti_roll"]["stiffness"] = "rigid"
    return data


def crossbar_middle(results) -> np.ndarray:
    return 0.5 * (solved(results, "left_droplink_t_bar") + solved(results, "right_droplink_t_bar"))


@pytest.mark.parametrize("name", SWEEPS)
def test_t_bar_axle_sweep_equals_the_point_based_formulation(name):
    """The point-based T-bar: the pivot (fixed, a ball) and the crossbar's ends one
    rigid part, one plane row holding the crossbar's midpoint in y = 0, a rigid
    droplink per side. Both wheels at their own heights and the rack: pin_susp's
    points equal its within 1e-9 mm, the crossbar twisted about its stem."""
    results = assert_points_equal_the_point_based_formulation(t_bar(), SWEEPS[name]())
    assert np.ptp(results["arb_twist"]) > 4.0  # deg: the crossbar twisted
    assert np.abs(crossbar_middle(results)[:, 1]).max() < 1e-9


RIGID_T_BAR_SWEEPS = {
    "heave": {
        "targets": [
            {"quantity": "heave", "values": [-30.0, 25.0, 40.0]},
            {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
             "values": [3.0, -4.0, 8.0]},
        ]
    },
    "one_wheel": {
        "targets": [
            {"point": "wheel_center", "side": "right", "direction": {"axis": "z"},
             "values": [15.0, -20.0, 30.0]},
            {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
             "values": [0.0, -4.0, 5.0]},
        ]
    },
}  # fmt: skip


@pytest.mark.parametrize("name", RIGID_T_BAR_SWEEPS)
def test_a_rigid_t_bar_only_pitches(name):
    """stiffness: rigid — the point-based crossbar one part with a fixed axis along y
    through the pivot: pin_susp's points equal its within 1e-9 mm; the crossbar
    pitched (its ends keep their y) and did not twist, one wheel moved the other."""
    results = assert_points_equal_the_point_based_formulation(
        t_bar(rigid=True), load_sweep(RIGID_T_BAR_SWEEPS[name])
    )
    design = mm(t_bar()["hardpoints"]["left"]["droplink_t_bar"])
    np.testing.assert_allclose(solved(results, "left_droplink_t_bar")[:, 1], design[1], atol=1e-9)
    np.testing.assert_allclose(results["arb_twist"], 0.0, atol=1e-9)
    assert np.ptp(crossbar_middle(results)[:, 2]) > 10.0  # mm: it pitched
    assert np.ptp(results["left_wheel_center_z"]) > 30.0  # both wheels moved


def no_plane_row(bar):
    """The T-bar's formulation without its midpoint plane row."""

    def without(*args):
        bar(*args)
        return []

    return without


def free_to_twist(bar):
    """The T-bar's formulation as if its bar were not rigid."""
    from pin_susp.subjects.elements import AntiRollBar

    def twisting(element, *args):
        loose = replace(element.axle, anti_roll_stiffness=None)
        return bar(AntiRollBar(loose, element.labels, element.prefix), *args)

    return twisting


@pytest.mark.parametrize(
    "rigid, sweep, broken",
    [
        (False, SWEEPS["bump_steer"], no_plane_row),
        (False, SWEEPS["roll"], no_plane_row),
        (True, lambda: load_sweep(RIGID_T_BAR_SWEEPS["heave"]), free_to_twist),
    ],
)
def test_the_t_bar_checks_fail_on_a_wrong_point_based_bar(monkeypatch, rigid, sweep, broken):
    """The checks above can fail: without the plane row the point-based crossbar may
    also turn its midpoint off y = 0; a rigid bar let twist leaves the wheels free to
    roll in heave. Either lands points millimetres from pin_susp's (the solve itself
    still converges: the comparison fails, not the residual)."""
    monkeypatch.setitem(pointwise.ANTI_ROLL, "t_bar", broken(pointwise.ANTI_ROLL["t_bar"]))
    with pytest.raises(AssertionError, match="Not equal to tolerance rtol=0, atol=1e-09"):
        assert_points_equal_the_point_based_formulation(t_bar(rigid), sweep())


def test_cli_validates_a_t_bar_axle_with_the_point_based_engine_too(capsys):
    code = main(["validate", str(T_BAR), str(EXAMPLES / "roll.yaml")])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "pointwise: agrees within 1e-06" in out and "mujoco: agrees within 1e-06" in out
    row = next(line.split() for line in out.splitlines() if line.startswith("  arb_twist "))
    assert float(row[2]) < 1e-6 and float(row[3]) < 1e-6  # both engines compared it


@pytest.mark.parametrize("bar", ["u_bar", "t_bar"])
def test_a_rigid_bar_validates_with_its_per_side_rates_blank_everywhere(tmp_path, capsys, bar):
    """A rigid bar: one wheel cannot move with the other held, so neither the sweep
    nor the engines have per-side rates; everything else is compared and agrees."""
    source = AXLE if bar == "u_bar" else AXLE.parent.parent / "tests/data/axle_t_bar.yaml"
    data = yaml.safe_load(source.read_text())
    data["axle_config"]["anti_roll"]["stiffness"] = "rigid"
    geometry = tmp_path / "rigid.yaml"
    geometry.write_text(yaml.safe_dump(data))
    heave = {
        "steps": 5,
        "targets": [
            {"quantity": "heave", "start": -20, "stop": 20},
            {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
             "start": -5, "stop": 5},
        ],
    }  # fmt: skip
    sweep = tmp_path / "heave.yaml"
    sweep.write_text(yaml.safe_dump(heave))
    assert main(["validate", str(geometry), str(sweep)]) == 0
    out = capsys.readouterr().out
    assert "pointwise: agrees" in out and "mujoco: agrees" in out and "not compared" not in out
