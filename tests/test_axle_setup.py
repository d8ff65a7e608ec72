"""`pin-susp setup` and `pin-susp sensitivity` on an axle (docs/axle.md, issue 13).

Checked against independent computations: each side's setup sheet against its
corner written out as a corner file (the right one mirrored); the inverse solve
by re-loading the axle with the adjusters found and solving it; the exact
hardpoint sensitivities of the axle's columns (roll centre, roll camber) against
central differences of full re-loads with the point moved.
"""

import copy

import numpy as np
import pytest
import yaml
from conftest import ROOT, example, mirrored

from pin_susp.analyses.sensitivity import AXLE_COLUMNS, AxleSensitivity, HardpointSensitivity
from pin_susp.analyses.setup import axle_setup_sheet, setup_sheet, solve_axle_setup
from pin_susp.cli import main
from pin_susp.model.geometry import load_geometry
from pin_susp.model.sweep import load_sweep
from pin_susp.solve.linkage import Linkage
from pin_susp.subjects.axle import AxleModel, axle_results, load_axle, solve_axle_sweep

AXLE = yaml.safe_load((ROOT / "examples/axle_front.yaml").read_text())
SHIM = example("camber_shim.yaml")["config"]["camber_shim"]  # the same upright's shim
BAR = ("droplink_rocker", "droplink_u_bar")  # the axle's own per-side points
SIDES = ("left", "right")


def flip(point: dict) -> dict:
    return {**point, "y": -point["y"]}


def axle_data(setup=None, right=False, right_setup=None, inclined=False) -> dict:
    """The example axle; ``setup``: its left_setup; ``right``: explicit right points (the
    left mirrored) with ``right_setup``; ``inclined``: upper wishbone pivots raised so
    that the roll centre exists (the example's arms are parallel in front view)."""
    data = copy.deepcopy(AXLE)
    left = data["hardpoints"]["left"]
    if inclined:
        for name in ("upper_wishbone_inboard_front", "upper_wishbone_inboard_rear"):
            left[name]["z"] = 540.0
    if setup is not None:
        data["axle_config"]["left_setup"] = setup
    if right:
        data["hardpoints"]["right"] = {k: flip(p) for k, p in left.items()}
    if right_setup is not None:
        data["axle_config"]["right_setup"] = right_setup
    return data


def mirrored_shim(shim: dict) -> dict:
    keys = ("shim_face_point_a", "shim_face_point_b", "shim_face_normal")
    return {k: flip(v) if k in keys else v for k, v in shim.items()}


def corner_file(data: dict, side: str = "left") -> dict:
    """One side of an axle written out as a corner file (its own points and setup)."""
    config = data["axle_config"]
    setup = config.get(f"{side}_setup", {})
    points = data["hardpoints"].get(side, data["hardpoints"]["left"])
    corner = {
        "type": data["type"],
        "side": "left",
        "name": "the corner",
        "hardpoints": {k: v for k, v in points.items() if k not in BAR},
        "config": {k: config[k] for k in ("steering", "wheel", "axle_position")}
        | data["vehicle_config"]
        | ({"camber_shim": setup["camber_shim"]} if "camber_shim" in setup else {})
        | {"setup": {k: v for k, v in setup.items() if k != "camber_shim"}},
        "actuation": config["actuation"],
        "spring": config["spring"],
    }
    return corner


def write(tmp_path, data, name="axle.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def static_columns(data) -> dict:
    """The axle's columns at its (as-set) design state: loaded and solved from scratch,
    each wheel centre and the rack held at design."""
    model = AxleModel(load_axle(copy.deepcopy(data)))
    targets = [
        {"point": "wheel_center", "side": s, "direction": {"axis": "z"}, "values": [0.0]}
        for s in SIDES
    ] + [{"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"}, "values": [0.0]}]
    sweep = load_sweep({"targets": targets})
    solutions = solve_axle_sweep(model, sweep)
    assert solutions[0].converged
    return axle_results(model, sweep, solutions), model


# ---------------------------------------------------------------- setup


def test_each_side_of_a_mirrored_axle_gets_the_corner_sheet(tmp_path, capsys):
    """With a left_setup (a 20 mm shim stack, a longer pushrod), each side's rows —
    as set, then each listed value — equal the corner file's, and the mirrored right
    side's too; in the printed sheet as well."""
    data = axle_data({"camber_shim": SHIM, "pushrod_length_delta": 1.5})
    sheets = axle_setup_sheet(load_axle(copy.deepcopy(data)), [15.0, 25.0], [-1.0], [2.0])
    corner = corner_file(data)
    expected = setup_sheet(load_geometry(corner), [15.0, 25.0], [-1.0], [2.0])
    right = mirrored(corner)
    right["config"]["camber_shim"] = mirrored_shim(SHIM)
    mirror = setup_sheet(load_geometry(right), [15.0, 25.0], [-1.0], [2.0])
    assert abs(expected[1].metrics["camber"] - expected[2].metrics["camber"]) > 1.0
    for side, rows in sheets.items():
        for got, want, other in zip(rows, expected, mirror, strict=True):
            np.testing.assert_allclose(got.setup, want.setup, rtol=0, atol=1e-12)
            for name, value in want.metrics.items():
                assert got.metrics[name] == pytest.approx(value, abs=1e-9), (side, name)
                assert other.metrics[name] == pytest.approx(value, abs=1e-9), name
                np.testing.assert_allclose(got.derivatives[name], want.derivatives[name], atol=1e-9)
    args = ["--shim", "15,25", "--trackrod", "-1", "--pushrod", "2", "--sensitivities"]
    assert main(["setup", str(write(tmp_path, corner, "corner.yaml")), *args]) == 0
    corner_lines = capsys.readouterr().out.splitlines()[1:]
    assert main(["setup", str(write(tmp_path, data)), *args]) == 0
    lines = capsys.readouterr().out.splitlines()
    left = lines.index("  left corner (axle_config.left_setup):")
    right = next(i for i, line in enumerate(lines) if line.startswith("  right corner (the left"))
    assert "takes the left's setup" in lines[right]
    n = len(corner_lines)
    assert lines[left + 1 : left + 1 + n] == corner_lines
    assert lines[right + 1 : right + 1 + n] == corner_lines
    assert lines[right + 1 + n] == "  axle (both sides as set in each row):"


def test_inverse_hits_its_targets_on_both_sides_of_a_mirrored_axle(tmp_path, capsys):
    """--camber --toe --ride-height-change on a mirrored axle: the left solved, the right
    takes its setup; the written file, re-loaded and solved as an axle, has both
    sides at the targets (ride height: −ΔCP_z from the drawn axle's: shim at its design
    thickness)."""
    data = axle_data({"camber_shim": SHIM})
    targets = ["--camber", "-2.5", "--toe", "0.1", "--ride-height-change", "3"]
    out, sheet = tmp_path / "set.yaml", tmp_path / "set.csv"
    assert (
        main(["setup", str(write(tmp_path, data)), *targets, "-o", str(out), "--csv", str(sheet)])
        == 0
    )
    printed = capsys.readouterr().out
    assert "hit camber -2.5, roadwheel_angle 0.1, ride_height_change 3" in printed
    written = yaml.safe_load(out.read_text())
    assert "right_setup" not in written["axle_config"]  # a mirrored axle: one setup
    # the drawn axle: the shim stack at its design thickness, no adjusters
    drawn, drawn_model = static_columns(axle_data({"camber_shim": SHIM | {"setup_thickness": 30}}))
    found, model = static_columns(written)
    for side in SIDES:
        assert found[f"camber_{side}"][0] == pytest.approx(-2.5, abs=1e-9)
        assert found[f"roadwheel_angle_{side}"][0] == pytest.approx(0.1, abs=1e-9)
        cp = f"{side}_contact_patch_center"
        rise = -(model.design_positions[cp][2] - drawn_model.design_positions[cp][2]) * 1e3
        assert rise == pytest.approx(3.0, abs=1e-9)
        assert abs(found[f"camber_{side}"][0] - drawn[f"camber_{side}"][0]) > 0.5
    rows = [line.split(",") for line in sheet.read_text().splitlines()[2:]]
    assert [r[0] for r in rows] == ["left before", "left after", "right before", "right after"]
    assert float(rows[3][-1]) == pytest.approx(found["roll_center_z"][0], abs=1e-9)


def test_one_side_of_an_axle_with_its_own_right_points(tmp_path, capsys):
    """--side right sets the right corner's own adjusters (right_setup) alone: the
    re-loaded axle has the right side at the target, the left one as it was."""
    data = axle_data(
        {"camber_shim": SHIM}, right=True, right_setup={"camber_shim": mirrored_shim(SHIM)}
    )
    path, out = write(tmp_path, data), tmp_path / "set.yaml"
    argv = ["setup", str(path), "--side", "right", "--camber", "-1.2", "--toe", "-0.2"]
    assert main([*argv, "-o", str(out)]) == 0
    assert "left corner (axle_config.left_setup; not set: --side right)" in capsys.readouterr().out
    written = yaml.safe_load(out.read_text())
    assert written["axle_config"]["left_setup"] == data["axle_config"]["left_setup"]
    before, _ = static_columns(data)
    after, _ = static_columns(written)
    assert after["camber_right"][0] == pytest.approx(-1.2, abs=1e-9)
    assert after["roadwheel_angle_right"][0] == pytest.approx(-0.2, abs=1e-9)
    for name in ("camber_left", "roadwheel_angle_left"):
        assert after[name][0] == pytest.approx(before[name][0], abs=1e-12)
    # the API: both sides by default, each solved with its own adjusters
    found = solve_axle_setup(load_axle(copy.deepcopy(data)), {"camber": -1.7})
    for side in SIDES:
        assert found[side].after.metrics["camber"] == pytest.approx(-1.7, abs=1e-9)
        assert found[side].iterations > 0


# ---------------------------------------------------------------- sensitivity


def corner_values(data: dict) -> dict:
    corner = Linkage(load_geometry(data))
    return HardpointSensitivity(corner).at(corner.q_design).values


def test_each_side_of_a_mirrored_axle_has_the_corner_sensitivities():
    """Symmetric moves: the left's columns are the corner file's; the right's are the
    mirrored corner file's, its y column negated (the right point moves by −dy)."""
    data = axle_data(inclined=True)
    s = AxleSensitivity(AxleModel(load_axle(copy.deepcopy(data)))).at()
    corner = corner_file(data)
    left, right = corner_values(corner), corner_values(mirrored(corner))
    rows = [s.hardpoints.index(h) for h in load_geometry(corner).hardpoints]
    for name, values in left.items():
        np.testing.assert_allclose(s.values[f"{name}_left"][rows], values, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(
            s.values[f"{name}_right"][rows], right[name] * [1, -1, 1], atol=1e-12, err_msg=name
        )
    assert list(s.values)[-len(AXLE_COLUMNS) :] == list(AXLE_COLUMNS)


# Central differences of full re-loads, h = 0.01 mm: the truncation error h²/6·f''' is
# below 1e-8 here (the roll centre's slopes change on a scale of 100 mm), and the
# re-solved poses carry a residual under 1e-12 m (1e-9 mm), i.e. 5e-8 in a
# difference over 2h = 0.02 mm. Measured: within 7e-9 at design, 4e-8 (relative) at
# a roll step, shrinking as h² (truncation-dominated); tolerance 1e-6
# (relative) + 1e-7 (absolute, per mm).
H = 0.01


def fd(data, side, point, axis, column, solve, symmetric=True):
    """Central difference of ``column`` with ``point`` moved by ±H along ``axis`` on
    ``side`` (a mirrored file: the right side follows the left)."""
    out = []
    for h in (H, -H):
        moved = copy.deepcopy(data)
        moved["hardpoints"][side][point][axis] += h
        if symmetric and "right" in moved["hardpoints"]:
            moved["hardpoints"]["right"][point][axis] += -h if axis == "y" else h
        out.append(solve(moved)[column][0])
    return (out[0] - out[1]) / (2 * H)


MOVES = [
    ("upper_wishbone_inboard_front", "z"),
    ("upper_wishbone_inboard_rear", "y"),
    ("lower_wishbone_outboard", "z"),
    ("lower_wishbone_inboard_front", "z"),
    ("axle_outboard", "z"),
]


def test_roll_centre_height_per_hardpoint_matches_central_differences_of_reloads():
    """d roll_center_z / d hardpoint, both sides moved symmetrically (the mirrored file's
    left point: the right follows), against re-loaded and re-solved axles; and the
    same with explicit right points both moved."""
    data = axle_data(inclined=True)
    s = AxleSensitivity(AxleModel(load_axle(copy.deepcopy(data)))).at()
    base, _ = static_columns(data)
    assert s.metrics["roll_center_z"] == pytest.approx(base["roll_center_z"][0], abs=1e-9)
    assert np.isfinite(base["roll_center_z"][0]) and abs(base["roll_center_z"][0]) > 10.0
    solve = lambda d: static_columns(d)[0]  # noqa: E731
    for point, axis in MOVES:
        exact = s.values["roll_center_z"][s.hardpoints.index(point), "xyz".index(axis)]
        expected = fd(data, "left", point, axis, "roll_center_z", solve)
        assert exact == pytest.approx(expected, rel=1e-6, abs=1e-7), (point, axis)
        # a symmetric move keeps the roll centre on the centreline
        assert abs(s.values["roll_center_y"][s.hardpoints.index(point), "xyz".index(axis)]) < 1e-9
    assert np.abs(s.values["roll_center_z"]).max() > 0.5
    explicit = axle_data(inclined=True, right=True)
    point, axis = MOVES[2]
    assert fd(explicit, "left", point, axis, "roll_center_z", solve) == pytest.approx(
        s.values["roll_center_z"][s.hardpoints.index(point), 2], rel=1e-6
    )


def test_one_sided_moves_along_a_roll_step_match_central_differences():
    """--one-sided, at a roll sweep's step (2° of roll, 10 mm heave, rack 3 mm): the
    roll centre, body roll, roll camber and roll-centre migration per left_ or right_
    point, against re-solves with each wheel centre's height and the rack held as
    solved at that step; the other side's corner columns do not move."""
    data = axle_data(inclined=True, right=True)
    model = AxleModel(load_axle(copy.deepcopy(data)))
    rack = {
        "point": "trackrod_inboard",
        "side": "left",
        "direction": {"axis": "y"},
        "values": [3.0],
    }
    roll = load_sweep(
        {
            "targets": [
                {"quantity": "roll", "values": [2.0]},
                {"quantity": "heave", "values": [10.0]},
                rack,
            ]
        }
    )
    solution = solve_axle_sweep(model, roll)[0]
    at = axle_results(model, roll, [solution])
    s = AxleSensitivity(model, one_sided=True).at(solution.q)
    assert s.hardpoints[0].startswith("left_") and s.hardpoints[-1].startswith("right_")
    for column in ("roll_center_z", "deriv_roll_center_z_wrt_roll", "deriv_camber_wrt_roll_right"):
        assert s.metrics[column] == pytest.approx(at[column][0], rel=1e-9)
    assert abs(s.metrics["deriv_roll_center_z_wrt_roll"]) > 1.0  # not the symmetric zero
    held = load_sweep(
        {
            "targets": [
                {"point": "wheel_center", "side": side, "direction": {"axis": "z"},
                 "values": [at[f"wheel_travel_{side}"][0]]}
                for side in SIDES
            ] + [rack]
        }
    )  # fmt: skip

    def solve(d):
        m = AxleModel(load_axle(d))
        return axle_results(m, held, solve_axle_sweep(m, held))

    columns = ("roll_center_z", "body_roll", "deriv_camber_wrt_roll_left",
               "deriv_roll_center_z_wrt_roll")  # fmt: skip
    for side, (point, axis) in (("left", MOVES[2]), ("right", MOVES[0])):
        row = s.hardpoints.index(f"{side}_{point}"), "xyz".index(axis)
        for column in columns:
            expected = fd(data, side, point, axis, column, solve, symmetric=False)
            assert s.values[column][row] == pytest.approx(expected, rel=1e-6, abs=1e-7), column
        other = "right" if side == "left" else "left"
        assert s.values[f"camber_{other}"][row] == 0.0


def test_axle_sensitivity_through_the_cli(tmp_path, capsys):
    path, out = write(tmp_path, axle_data(inclined=True)), tmp_path / "sens.csv"
    assert main(["sensitivity", str(path), "-o", str(out), "--top", "1"]) == 0
    printed = capsys.readouterr().out
    assert "a symmetric move" in printed and "  the axle:" in printed
    assert "the right corner's columns mirror the left's" in printed
    lines = out.read_text().splitlines()
    assert any(line.startswith("# hardpoint: a symmetric move") for line in lines)
    s = AxleSensitivity(AxleModel(load_axle(path))).at()
    row = next(
        line for line in lines if line.startswith("0,roll_center_z,lower_wishbone_outboard,z,")
    )
    assert float(row.split(",")[4]) == pytest.approx(s.values["roll_center_z"][2, 2], rel=1e-12)


# ---------------------------------------------------------------- bad input


def test_bad_axle_setup_and_sensitivity_input_gets_one_line(tmp_path, capsys):
    axle = write(tmp_path, axle_data())
    explicit = write(tmp_path, axle_data(right=True), "explicit.yaml")
    corner = ROOT / "examples/camber_shim.yaml"
    out = tmp_path / "out.yaml"
    cases = [
        (["setup", str(corner), "--side", "left", "-o", str(out), "--camber", "-2"],
         "--side: " + str(corner) + " is a corner"),
        (["setup", str(axle), "--side", "middle"], "argument --side: invalid choice: 'middle'"),
        (["setup", str(axle), "--side", "front"], "--side: unknown side 'front' (left or right)"),
        (["setup", str(axle), "--side", "right", "--camber", "-2", "-o", str(out)],
         "is a mirrored axle (no hardpoints.right)"),
        (["setup", str(explicit), "--side", "right", "--camber", "-2", "-o", str(out)],
         "axle_config.right_setup.camber_shim: right corner: a camber target needs a camber shim"),
        (["setup", str(axle), "--camber", "-2", "-o", str(out)],
         "axle_config.left_setup.camber_shim: left corner: a camber target needs a camber shim"),
        (["sensitivity", str(corner), "--one-sided", "-o", str(out)],
         "--one-sided: a corner has one side"),
    ]  # fmt: skip
    for argv, message in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and message in err[0], (argv, err)
        assert not out.exists()


def test_a_setup_that_cannot_be_applied_is_reported_by_the_sheet(tmp_path, capsys, monkeypatch):
    """A file whose own setup cannot be applied (a 900 mm shim stack) gets the sheet's
    error — its own solve's residual, an axle's side and file key — not the one of a
    model built first; ``--side`` on a corner names the file as typed, before reading
    it; on a mirrored axle, the side is refused before the setup is tried."""
    monkeypatch.chdir(tmp_path)
    corner = example("camber_shim.yaml")
    corner["config"]["camber_shim"]["setup_thickness"] = 900.0
    write(tmp_path, corner, "corner.yaml")
    write(tmp_path, axle_data({"camber_shim": {**SHIM, "setup_thickness": 900.0}}))
    (tmp_path / "broken.yaml").write_text("type: double_wishbone\nhardpoints: {}\n")
    reach = "the shimmed upright does not assemble (residual 29.5 mm): beyond the linkage's reach"
    mirrored_side = (
        "--side: axle.yaml is a mirrored axle (no hardpoints.right): its right side takes "
        "the left's setup, so one setup sets both sides; give the right corner's own points "
        "(hardpoints.right, with axle_config.right_setup) to set one side alone"
    )
    cases = [
        (["corner.yaml"], f"corner.yaml: config.camber_shim.setup_thickness: {reach}"),
        (["corner.yaml", "--camber", "-2", "-o", "out.yaml"],
         f"corner.yaml: config.camber_shim.setup_thickness: {reach}"),
        (["axle.yaml"],
         f"axle.yaml: axle_config.left_setup.camber_shim.setup_thickness: left corner: {reach}"),
        (["axle.yaml", "--camber", "-2", "-o", "out.yaml"],
         f"axle.yaml: axle_config.left_setup.camber_shim.setup_thickness: left corner: {reach}"),
        (["axle.yaml", "--side", "right"], mirrored_side),
        (["./corner.yaml", "--side", "left"],
         "--side: ./corner.yaml is a corner (--side sets one side of an axle)"),
        (["./broken.yaml", "--side", "left"],
         "--side: ./broken.yaml is a corner (--side sets one side of an axle)"),
    ]  # fmt: skip
    for argv, message in cases:
        assert main(["setup", *argv]) == 2, argv
        captured = capsys.readouterr()
        assert captured.out == "" and captured.err == f"pin-susp: error: {message}\n", argv
        assert not (tmp_path / "out.yaml").exists()
