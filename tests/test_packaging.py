"""Driveshafts and travel limits (issue 28, 1–2; docs/geometry.md "Driveshaft", "Travel
limits"; docs/results.md; docs/loads.md "Bump stops"), each against a computation of
its own:

- the driveshaft's length, plunge and CV angles re-derived with numpy from the CSV's
  own point columns (wheel centre, axle points, CV joints), on a corner of each side
  and on both sides of an axle (mirror symmetry in roll);
- the derivative columns against central differences of the columns themselves;
- the damper's margins, the bump stop's force and ``limit_exceeded`` from the CSV's
  damper_length, and the sweep's summary line and exit status on a sweep that crosses
  the limits;
- the loads' spring force with the bump stop against the same sweep without it;
- one clear error per bad key.
"""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import EXAMPLES, example, mirrored

import pin_susp
from pin_susp.cli import main
from pin_susp.errors import InputError
from pin_susp.model.geometry import load_geometry
from pin_susp.model.sweep import Sweep, Target

OFFSET = 60.0  # mm, the outboard joint inboard of the wheel centre
SHAFT = ("driveshaft_length", "driveshaft_plunge", "cv_angle_inboard", "cv_angle_outboard")
STROKE, GAP, RATE, REBOUND = [225.0, 265.0], 10.0, 300.0, 10.0


def driven(outboard: dict | None = None, axis=None, limits: bool = True) -> dict:
    """The pushrod-rocker corner with a driveshaft (its outer joint placed by the offset,
    or ``outboard``) and travel limits on its coilover."""
    data = example("pushrod_rocker.yaml")
    data["hardpoints"]["cv_inboard"] = {"x": -20.0, "y": 250.0, "z": 300.0}
    shaft = {"max_plunge": 8.0, "max_cv_angle": 20.0}
    if outboard is None:
        shaft["outboard_offset"] = OFFSET
    else:
        data["hardpoints"]["cv_outboard"] = outboard
    if axis is not None:
        shaft["inboard_axis"] = axis
    data["config"]["driveshaft"] = shaft
    if not limits:
        return data
    data["config"]["limits"] = {
        "damper_stroke": list(STROKE),
        "bump_stop": {"gap": GAP, "rate": RATE},
        "rebound": REBOUND,
    }
    return data


def steer_and_bump(n: int = 9) -> list:
    """Bump with steer, the design state (0, 0) among the steps."""
    return [
        {
            "point": "wheel_center",
            "direction": {"axis": "z"},
            "values": np.linspace(-40, 40, n).tolist(),
        },
        {
            "point": "trackrod_inboard",
            "direction": {"axis": "y"},
            "values": np.linspace(-20, 20, n).tolist(),
        },
    ]


def run(tmp_path, data: dict, targets: list, name: str = "corner", expect: int = 0):
    """`pin-susp sweep` of ``data`` over ``targets``; its CSV read back."""
    geometry, sweep = tmp_path / f"{name}.yaml", tmp_path / f"{name}_sweep.yaml"
    geometry.write_text(yaml.safe_dump(data))
    data_sweep = targets if isinstance(targets, dict) else {"version": 1, "targets": targets}
    sweep.write_text(yaml.safe_dump(data_sweep))
    out = tmp_path / f"{name}.csv"
    assert main(["sweep", str(geometry), str(sweep), "-o", str(out), "-q"]) == expect
    return pd.read_csv(out, comment="#", keep_default_na=False, na_values=[""])


def xyz(df, name: str) -> np.ndarray:
    return df[[f"{name}_{a}" for a in "xyz"]].to_numpy(dtype=float)


def angle(a, b) -> np.ndarray:
    """The angle (deg) between lines a and b, either sense, row by row."""
    c = np.abs(np.sum(a * b, axis=1)) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)
    return np.degrees(np.arccos(np.clip(c, 0.0, 1.0)))


def by_hand(df, prefix: str = "", axis=(0.0, 1.0, 0.0), design: int = 4) -> dict:
    """The driveshaft's columns from the CSV's points (mm, deg); ``design``: the step at
    the design state."""
    spin = xyz(df, f"{prefix}axle_outboard") - xyz(df, f"{prefix}axle_inboard")
    spin /= np.linalg.norm(spin, axis=1)[:, None]
    outboard = xyz(df, f"{prefix}cv_outboard")
    shaft = outboard - xyz(df, f"{prefix}cv_inboard")
    length = np.linalg.norm(shaft, axis=1)
    return {
        "placed": xyz(df, f"{prefix}wheel_center") - OFFSET * spin,
        "outboard": outboard,
        "driveshaft_length": length,
        "driveshaft_plunge": length - length[design],
        "cv_angle_inboard": angle(shaft, np.broadcast_to(np.asarray(axis, float), shaft.shape)),
        "cv_angle_outboard": angle(shaft, spin),
    }


@pytest.mark.parametrize("side", ["left", "right"])
def test_driveshaft_columns_from_the_csvs_own_points(tmp_path, side):
    data, targets = driven(axis=[0.2, 1.0, -0.1], limits=False), steer_and_bump()
    axis = np.array([0.2, 1.0, -0.1])
    if side == "right":
        data = mirrored(data)
        data["config"]["driveshaft"]["inboard_axis"] = [0.2, -1.0, -0.1]
        targets[1]["values"] = [-v for v in targets[1]["values"]]
        axis = np.array([0.2, -1.0, -0.1])
    df = run(tmp_path, data, targets)
    assert df["solver_converged"].all()
    hand = by_hand(df, axis=axis)
    # the outer joint's frame on the upright is where the offset puts it, at every step
    np.testing.assert_allclose(hand["outboard"], hand["placed"], rtol=0, atol=1e-9)
    for column in SHAFT:
        np.testing.assert_allclose(df[column], hand[column], rtol=0, atol=1e-9, err_msg=column)
    assert df["driveshaft_plunge"][4] == pytest.approx(0.0, abs=1e-9)
    assert np.ptp(df["driveshaft_plunge"]) > 0.5 and np.ptp(df["cv_angle_inboard"]) > 1.0
    # the cv_inboard columns are the file's point, fixed to the chassis
    s = 1.0 if side == "left" else -1.0
    np.testing.assert_allclose(xyz(df, "cv_inboard"), [[-20.0, s * 250.0, 300.0]] * 9, atol=1e-9)


def test_a_right_corner_mirrors_the_left():
    left = pin_susp.Corner(driven()).run_sweep({"version": 1, "targets": steer_and_bump()})
    data, targets = mirrored(driven()), steer_and_bump()
    targets[1]["values"] = [-v for v in targets[1]["values"]]
    right = pin_susp.Corner(data).run_sweep({"version": 1, "targets": targets})
    for column in (*SHAFT, "damper_margin_compression", "bump_stop_force"):
        np.testing.assert_allclose(right[column], left[column], rtol=0, atol=1e-8)


def test_a_given_outboard_joint_rides_on_the_upright(tmp_path):
    """cv_outboard given as a hardpoint: a frame on the upright (it keeps its distances
    to the upright's points), no offset."""
    data = driven(outboard={"x": -20.0, "y": 870.0, "z": 305.0}, limits=False)
    df = run(tmp_path, data, steer_and_bump())
    hand = by_hand(df)
    for column in SHAFT:
        np.testing.assert_allclose(df[column], hand[column], rtol=0, atol=1e-9, err_msg=column)
    for other in ("axle_inboard", "axle_outboard", "trackrod_outboard", "lower_wishbone_outboard"):
        d = np.linalg.norm(hand["outboard"] - xyz(df, other), axis=1)
        assert np.ptp(d) < 1e-9, other


H = 1e-3  # mm


@pytest.mark.parametrize("outboard", [None, {"x": -20.0, "y": 870.0, "z": 305.0}])
def test_derivative_columns_match_central_differences(outboard):
    corner = pin_susp.Corner(driven(outboard))
    step = np.array([-H, 0.0, H])
    for along, driver in (("z", "hub_z"), ("rack", "rack_displacement")):
        z = 12.0 + (step if along == "z" else 0.0 * step)
        rack = 5.0 + (step if along == "rack" else 0.0 * step)
        r = corner.run_sweep(
            Sweep([Target("wheel_center", "z", z), Target("trackrod_inboard", "y", rack)])
        )
        assert r["solver_converged"].all()
        for column in SHAFT:
            fd = (r[column][2] - r[column][0]) / (2 * H)
            exact = r[f"deriv_{column}_wrt_{driver}"][1]
            assert exact == pytest.approx(fd, rel=1e-5, abs=1e-8), (column, driver)
            assert abs(exact) > 1e-4, (column, driver)


def axle(limits: dict | None = None) -> dict:
    data = example("axle_front.yaml")
    data["hardpoints"]["left"]["cv_inboard"] = {"x": -20.0, "y": 250.0, "z": 300.0}
    data["axle_config"]["driveshaft"] = {
        "outboard_offset": OFFSET,
        "inboard_axis": [0.1, 1.0, 0.05],
    }
    if limits is not None:
        data["axle_config"]["limits"] = limits
    return data


def test_an_axles_driveshafts_mirror_in_roll(tmp_path):
    """Both sides from the CSV's own points (the right's inboard axis the left's
    mirrored), and the right at roll φ the left at −φ."""
    targets = example("heave_roll.yaml")
    limits = {"damper_stroke": list(STROKE), "bump_stop": {"gap": GAP, "rate": RATE}}
    df = run(tmp_path, axle(limits), targets, "axle", expect=1)
    assert df["solver_converged"].all()
    for side, axis in (("left", [0.1, 1.0, 0.05]), ("right", [0.1, -1.0, 0.05])):
        hand = by_hand(df, f"{side}_", axis, design=15)
        np.testing.assert_allclose(hand["outboard"], hand["placed"], rtol=0, atol=1e-9)
        for column in SHAFT[:1] + SHAFT[2:]:  # (the plunge: roll's zero is not design)
            np.testing.assert_allclose(
                df[f"{column}_{side}"], hand[column], rtol=0, atol=1e-9, err_msg=column
            )
    names = (*SHAFT, "damper_margin_compression", "damper_margin_extension", "bump_stop_force")
    for column in names:
        left, right = df[f"{column}_left"].to_numpy(), df[f"{column}_right"].to_numpy()
        np.testing.assert_allclose(right, left[::-1], rtol=1e-10, atol=1e-8, err_msg=column)
        assert np.ptp(left) > 1e-3, column
    left, right = (df[f"limit_exceeded_{side}"].fillna("").tolist() for side in ("left", "right"))
    assert right == left[::-1] and any(left) and not all(left)


# -- travel limits -----------------------------------------------------------------------


def test_margins_bump_stop_and_limits_from_the_damper_length(tmp_path, capsys):
    """A bump sweep from 45 mm droop to 60 mm bump crosses the rebound stop and the
    stroke's min: margins, the bump stop's force and limit_exceeded from the CSV's own
    damper_length; the summary names the steps and the limit, exit 1."""
    bump = np.linspace(-45, 60, 22).tolist()
    targets = [{"point": "wheel_center", "direction": {"axis": "z"}, "values": bump}]
    geometry = tmp_path / "corner.yaml"
    geometry.write_text(yaml.safe_dump(driven()))
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(yaml.safe_dump({"version": 1, "targets": targets}))
    out = tmp_path / "out.csv"
    assert main(["sweep", str(geometry), str(sweep), "-o", str(out)]) == 1
    printed = capsys.readouterr()
    df = pd.read_csv(out, comment="#", keep_default_na=False, na_values=[""])
    length = df["damper_length"].to_numpy()
    drawn = example("pushrod_rocker.yaml")["hardpoints"]  # the damper at design
    design = np.linalg.norm([drawn["strut_top"][a] - drawn["strut_bottom"][a] for a in "xyz"])
    np.testing.assert_allclose(df["damper_margin_compression"], length - STROKE[0], atol=1e-9)
    extension = np.minimum(STROKE[1] - length, design + REBOUND - length)
    np.testing.assert_allclose(df["damper_margin_extension"], extension, atol=1e-9)
    bump = RATE * np.maximum(0.0, design - length - GAP)
    np.testing.assert_allclose(df["bump_stop_force"], bump, rtol=1e-12, atol=1e-9)
    assert (bump > 0).any() and (bump == 0).any()
    expected = [
        "+".join(
            n
            for n, hit in (
                ("damper_stroke_min", v < STROKE[0]),
                ("damper_stroke_max", v > STROKE[1]),
                ("rebound", v - design > REBOUND),
            )
            if hit
        )
        for v in length
    ]
    cells = ["" if isinstance(c, float) else c for c in df["limit_exceeded"]]
    assert cells == expected
    past = [i for i, c in enumerate(expected) if c]
    low = [i for i, c in enumerate(expected) if "damper_stroke_min" in c]
    rebound = [i for i, c in enumerate(expected) if "rebound" in c]
    assert low and rebound and len(past) < len(expected)
    line = next(s for s in printed.out.splitlines() if "past a hard travel limit" in s)
    assert line.startswith(f"  {len(past)} of 22 steps past a hard travel limit: ")
    assert (
        f"damper_stroke_min at {len(low)} step" in line
        and f"rebound at {len(rebound)} step" in line
    )
    assert f"({', '.join(map(str, low))})" in line
    assert "past a hard travel limit" in printed.err and "limit_exceeded" in printed.err


def test_a_sweep_within_the_limits_exits_0(tmp_path):
    targets = [{"point": "wheel_center", "direction": {"axis": "z"}, "values": [-10.0, 0.0, 10.0]}]
    df = run(tmp_path, driven(), targets)
    assert df["limit_exceeded"].isna().all()  # blank cells
    assert (df["bump_stop_force"] == 0.0).all()


def test_the_driveshafts_warnings_name_the_first_step(tmp_path, capsys):
    data = driven()
    data["config"]["driveshaft"] |= {"max_plunge": 0.3, "max_cv_angle": 4.0}
    targets = [
        {
            "point": "wheel_center",
            "direction": {"axis": "z"},
            "values": np.linspace(-40, 40, 9).tolist(),
        }
    ]
    geometry, sweep = tmp_path / "corner.yaml", tmp_path / "sweep.yaml"
    geometry.write_text(yaml.safe_dump(data))
    sweep.write_text(yaml.safe_dump({"version": 1, "targets": targets}))
    out = tmp_path / "out.csv"
    assert main(["sweep", str(geometry), str(sweep), "-o", str(out)]) == 1  # (rebound)
    err = capsys.readouterr().err
    df = pd.read_csv(out, comment="#")
    for column, key, limit in (
        ("driveshaft_plunge", "max_plunge", 0.3),
        ("cv_angle_inboard", "max_cv_angle", 4.0),
        ("cv_angle_outboard", "max_cv_angle", 4.0),
    ):
        over = np.flatnonzero(np.abs(df[column]) > limit)
        n = len(over)
        said = f"{column} past config.driveshaft.{key} at {n} step{'s' * (n != 1)}, first at"
        said += f" step {over[0]}"
        assert 0 < len(over) < 9 and said in err, (column, err)
        assert all(column in df["limit_exceeded"][i] for i in over)


def test_loads_give_the_bump_stop_its_share(tmp_path):
    """The force along the damper is the spring's and the bump stop's: with the stop the
    spring's force is the one without it less the stop's; every other column is equal."""
    sweep = {
        "version": 1,
        "targets": [
            {"point": "wheel_center", "direction": {"axis": "z"}, "values": [0.0, 30.0, 55.0]}
        ],
    }
    cases = EXAMPLES / "loads.yaml"
    plain = copy.deepcopy(driven())
    del plain["config"]["limits"]
    with_stop = pin_susp.member_forces(pin_susp.Corner(driven()), sweep, str(cases))
    without = pin_susp.member_forces(pin_susp.Corner(plain), sweep, str(cases))
    stop = with_stop["bump_stop_force"]
    assert (stop > 100.0).any()
    np.testing.assert_allclose(
        with_stop["force_spring"] + stop, without["force_spring"], rtol=1e-12
    )
    for name, values in without.columns.items():
        if name != "force_spring" and values.dtype.kind == "f":
            np.testing.assert_array_equal(with_stop[name], values, err_msg=name)


# -- one clear error per bad key ------------------------------------------------------------


def _set(data: dict, path: str, value) -> dict:
    *parents, last = path.split(".")
    block = data
    for name in parents:
        block = block.setdefault(name, {})
    if value is None:
        del block[last]
    else:
        block[last] = value
    return data


BAD = [
    (
        "config.limits.damper_stroke",
        [265, 225],
        "config.limits.damper_stroke: min 265 mm must be below max 225 mm",
    ),
    ("config.limits.damper_stroke", [225, 225], "min 225 mm must be below max 225 mm"),
    ("config.limits.damper_stroke", [100], "expected [min, max]"),
    ("config.limits.damper_stroke", [260, 300], "design length 250.2"),
    (
        "config.limits.bump_stop",
        {"gap": -2, "rate": 300},
        "config.limits.bump_stop.gap: must be >= 0, got -2",
    ),
    ("config.limits.bump_stop", {"gap": 5}, "config.limits.bump_stop.rate: missing key"),
    ("config.limits.rebound", 0, "config.limits.rebound: must be > 0 mm, got 0"),
    (
        "config.limits.droop",
        5,
        "config.limits.droop: unknown key (known keys here: bump_stop, damper_stroke, rebound)",
    ),
    ("config.driveshaft.outboard_offset", None, "config.driveshaft.outboard_offset: missing (mm)"),
    ("config.driveshaft.max_cv_angle", 95, "config.driveshaft.max_cv_angle: must be below 90 deg"),
    (
        "config.driveshaft.inboard_axis",
        [0, 0, 0],
        "config.driveshaft.inboard_axis: is the zero vector",
    ),
    ("config.driveshaft.max_plunge", -1, "config.driveshaft.max_plunge: must be > 0 mm"),
    ("hardpoints.cv_inboard", None, "config.driveshaft: needs hardpoints.cv_inboard"),
    (
        "hardpoints.cv_outboard",
        {"x": 0, "y": 900, "z": 300},
        "config.driveshaft.outboard_offset: hardpoints.cv_outboard is given",
    ),
    (
        "config.driven_axle",
        "rear",
        "hardpoints.cv_inboard: a driveshaft on a front corner, but config.driven_axle is rear",
    ),
]


@pytest.mark.parametrize("path, value, message", BAD, ids=[f"{p}={v}" for p, v, _ in BAD])
def test_a_bad_key_is_one_clear_error(path, value, message):
    data = _set(driven(), path, value)
    if path == "config.driven_axle":
        data["config"]["axle_position"] = "front"
    with pytest.raises(InputError) as error:
        load_geometry(data)
    assert message in str(error.value)
    assert "\n" not in str(error.value)


def test_limits_need_a_damper_and_cv_outboard_needs_cv_inboard():
    data = example("pushrod_rocker.yaml")
    data["spring"] = {"type": "torsion_bar", "rate": 40}
    for p in ("strut_top", "strut_bottom"):
        del data["hardpoints"][p]
    data["config"]["limits"] = {"rebound": 10}
    with pytest.raises(InputError, match=r"config.limits: travel limits need a damper"):
        load_geometry(data)
    data = example("pushrod_rocker.yaml")
    data["hardpoints"]["cv_outboard"] = {"x": 0, "y": 900, "z": 300}
    with pytest.raises(
        InputError, match=r"hardpoints.cv_outboard: a driveshaft needs hardpoints.cv_inboard"
    ):
        load_geometry(data)


def test_an_axle_files_keys_are_named_as_the_file_has_them(tmp_path, capsys):
    path, out = tmp_path / "axle.yaml", tmp_path / "out.csv"
    for data, key in (
        (axle({"damper_stroke": [300, 200]}), "axle_config.limits.damper_stroke: min 300 mm"),
        (_set(axle(), "axle_config.driveshaft.max_cv_angle", 90), "axle_config.driveshaft.max_cv"),
    ):
        path.write_text(yaml.safe_dump(data))
        assert main(["sweep", str(path), str(EXAMPLES / "heave_roll.yaml"), "-o", str(out)]) == 2
        assert key in capsys.readouterr().err
        assert not out.exists()


def test_the_cli_says_a_bad_key_in_one_line(tmp_path, capsys):
    path = tmp_path / "corner.yaml"
    path.write_text(
        yaml.safe_dump(_set(driven(), "config.limits.bump_stop", {"gap": -1, "rate": 1}))
    )
    assert (
        main(["sweep", str(path), str(EXAMPLES / "bump.yaml"), "-o", str(tmp_path / "o.csv")]) == 2
    )
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "config.limits.bump_stop.gap" in err and "Traceback" not in err


def test_a_corner_in_inches_and_lbf_is_the_same():
    """The keys' lengths in inches and the bump stop's rate in lbf/in, converted by hand:
    the same columns (docs/geometry.md, "Units")."""
    lbf = 4.4482216152605
    mm = driven()
    g = copy.deepcopy(mm)
    g["units"], g["force_units"] = "inches", "lbf"
    g["hardpoints"] = {n: {a: v / 25.4 for a, v in p.items()} for n, p in g["hardpoints"].items()}
    c = g["config"]
    c["cg_position"] = {a: v / 25.4 for a, v in c["cg_position"].items()}
    c["wheelbase"] /= 25.4
    c["wheel"]["tyre"]["rate"] /= lbf / 25.4
    g["spring"] = {"type": "coilover", "rate": 175 / (lbf / 25.4), "preload": 2600 / lbf}
    for key in ("outboard_offset", "max_plunge"):
        c["driveshaft"][key] /= 25.4
    c["limits"] = {
        "damper_stroke": [v / 25.4 for v in STROKE],
        "bump_stop": {"gap": GAP / 25.4, "rate": RATE / (lbf / 25.4)},
        "rebound": REBOUND / 25.4,
    }
    sweep = {"version": 1, "targets": steer_and_bump()}
    one, other = (pin_susp.Corner(d).run_sweep(sweep) for d in (mm, g))
    names = (*SHAFT, "damper_margin_compression", "damper_margin_extension", "bump_stop_force")
    for name in names:
        np.testing.assert_allclose(other[name], one[name], rtol=1e-9, atol=1e-9, err_msg=name)
    assert list(other["limit_exceeded"]) == list(one["limit_exceeded"])
    assert any(one["limit_exceeded"])


def test_a_vehicles_driven_axle_has_them_per_corner(tmp_path):
    """The FS car's rear axle driven through shafts: each rear corner's columns from the
    CSV's own points, the right in roll φ the left in −φ, and limit_exceeded_rl/_rr."""
    (tmp_path / "vehicle").mkdir()
    for name in ("fs_front.yaml", "fs_rear.yaml"):
        data = yaml.safe_load((EXAMPLES / "vehicle" / name).read_text())
        if name == "fs_rear.yaml":
            data["hardpoints"]["left"]["cv_inboard"] = {"x": -1530.0, "y": 200.0, "z": 280.0}
            data["axle_config"]["driveshaft"] = {"outboard_offset": OFFSET}
            data["axle_config"]["limits"] = {"rebound": 10.0, "bump_stop": {"gap": 5, "rate": 300}}
        (tmp_path / "vehicle" / name).write_text(yaml.safe_dump(data))
    car = yaml.safe_load((EXAMPLES / "vehicle_fs.yaml").read_text())
    (tmp_path / "car.yaml").write_text(yaml.safe_dump(car))
    sweep = example("vehicle_roll.yaml")
    (tmp_path / "roll.yaml").write_text(yaml.safe_dump(sweep))
    out = tmp_path / "car.csv"
    code = main(
        ["sweep", str(tmp_path / "car.yaml"), str(tmp_path / "roll.yaml"), "-o", str(out), "-q"]
    )
    df = pd.read_csv(out, comment="#", keep_default_na=False, na_values=[""])
    assert df["solver_converged"].all()
    rear = yaml.safe_load((tmp_path / "vehicle" / "fs_rear.yaml").read_text())["hardpoints"]
    p = {
        n: np.array([rear["left"][n][a] for a in "xyz"]) for n in ("axle_inboard", "axle_outboard")
    }
    spin = (p["axle_outboard"] - p["axle_inboard"]) / np.linalg.norm(
        p["axle_outboard"] - p["axle_inboard"]
    )
    # the shaft at design from the file's points (offset 0: the wheel centre on axle_outboard)
    design = np.linalg.norm(p["axle_outboard"] - OFFSET * spin - [-1530.0, 200.0, 280.0])
    for label in ("rl", "rr"):
        hand = by_hand(df, f"{label}_")
        hand["driveshaft_plunge"] = hand["driveshaft_length"] - design
        np.testing.assert_allclose(hand["outboard"], hand["placed"], rtol=0, atol=1e-9)
        for column in SHAFT:
            np.testing.assert_allclose(
                df[f"{column}_{label}"], hand[column], rtol=0, atol=1e-9, err_msg=column
            )
    for column in (*SHAFT, "bump_stop_force", "damper_margin_extension"):
        rl, rr = df[f"{column}_rl"].to_numpy(), df[f"{column}_rr"].to_numpy()
        np.testing.assert_allclose(rr, rl[::-1], rtol=1e-9, atol=1e-8, err_msg=column)
    assert "driveshaft_length_fl" not in df  # the front is not driven
    past = df["limit_exceeded_rl"].fillna("").tolist()
    assert code == 1 and any(past) and not all(past)
    assert past == df["limit_exceeded_rr"].fillna("").tolist()[::-1]


def test_a_pose_of_the_api_carries_the_shaft_and_the_limits():
    """Corner.solve_pose on the packaging example: the shaft's length from the pose's own
    points, limit_exceeded as text (blank within the limits, the rebound named past it)."""
    corner = pin_susp.Corner(EXAMPLES / "packaging.yaml")
    pose = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 20.0), pin_susp.Target("trackrod_inboard", "y", 5.0)]
    )
    p = pose.points
    length = np.linalg.norm(p["cv_inboard"] - p["cv_outboard"])
    assert pose.metrics["driveshaft_length"] == pytest.approx(length, abs=1e-9)
    assert pose.metrics["limit_exceeded"] == ""
    droop = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", -120.0), pin_susp.Target("trackrod_inboard", "y", 0)]
    )  # the damper 35.9 mm longer than at design: past the rebound stop's 35
    assert droop.metrics["damper_margin_extension"] < 0
    assert "rebound" in droop.metrics["limit_exceeded"]


@pytest.mark.parametrize("command", ["clearance", "envelope", "loads", "kc"])
def test_every_command_that_solves_the_sweep_flags_a_hard_limit(tmp_path, capsys, command):
    """A step past the damper's stroke: exit 1 and the warning line, whichever command
    solved the sweep (docs/results.md, "Travel limits") — never written as good."""
    name, stroke = (
        ("kc_saloon_corner.yaml", [385, 392]) if command == "kc" else ("packaging.yaml", [240, 260])
    )
    g = example(name)
    g["config"]["limits"] = {"damper_stroke": stroke}
    (tmp_path / "g.yaml").write_text(yaml.safe_dump(g))
    extra = {
        "clearance": ["-o", "out.csv"],
        "envelope": ["-o", "out.stl"],
        "loads": ["--cases", str(EXAMPLES / "loads.yaml"), "-o", "out.csv"],
        "kc": ["--cases", str(EXAMPLES / "kc.yaml"), "-o", "out.csv"],
    }[command]
    argv = [command, "g.yaml", str(EXAMPLES / "bump_steer.yaml"), *extra, "-q"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "past a hard travel limit: damper_stroke_m" in err
    g["config"]["limits"] = {"damper_stroke": [100, 900]}  # wide: within it everywhere
    (tmp_path / "g.yaml").write_text(yaml.safe_dump(g))
    assert main(argv) == 0


def test_the_inboard_joint_inboard_of_the_upright(tmp_path):
    """cv_inboard outboard of the spindle: an error naming it; across the centre line:
    a warning (an offset diff may, rarely that far)."""
    g = example("packaging.yaml")
    g["hardpoints"]["cv_inboard"]["y"] = 1300.0
    (tmp_path / "g.yaml").write_text(yaml.safe_dump(g))
    with pytest.raises(InputError, match="hardpoints.cv_inboard: y = 1300 mm is outboard"):
        pin_susp.Corner(tmp_path / "g.yaml")
    g["hardpoints"]["cv_inboard"]["y"] = -230.0
    (tmp_path / "g.yaml").write_text(yaml.safe_dump(g))
    from pin_susp.errors import PlausibilityWarning
    from pin_susp.model.geometry import load_geometry

    with pytest.warns(PlausibilityWarning, match="230 mm across the car's centre"):
        load_geometry(tmp_path / "g.yaml")
