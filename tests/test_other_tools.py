"""The columns other tools report (issue 27, §5; docs/results.md, "Metrics other tools
report"), each against a computation of its own:

- Lotus SHARK's own printout of two corners (its static values: kingpin offset at the
  wheel centre and at the ground, castor trail at the hub, castor offset, mechanical
  trail) from their hardpoints, and the spatial camber of a cambered, toed wheel;
- every new corner column re-derived with numpy from the CSV's own point columns;
- the derivative columns against central differences of the columns themselves over
  two small-step sweeps (one along the hub's z, one along the rack);
- the kinematic instant centre from the upright points' differences (a rigid body's
  velocities by least squares), and the kinematic roll centre from the contact
  patches' differences, each side moved alone;
- mirror symmetry on the axle (y = 0 in heave, odd in roll) and the vehicle's axles
  against the axle's own columns.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example, mirrored

import pin_susp
from pin_susp.cli import main
from pin_susp.columns.metrics import PointSet
from pin_susp.columns.other_tools import (
    camber_spatial,
    caster_trail_at_hub,
    kingpin_offset_at_hub,
    normal_trail,
)
from pin_susp.maths.vectors import roll_centre
from pin_susp.model.sweep import Sweep, Target

NEW = ("kingpin_offset_at_hub", "caster_trail_at_hub", "normal_trail", "camber_spatial")
RACKED = ("lower_wishbone_outboard", "upper_wishbone_outboard")


def points_of(df, names) -> dict[str, np.ndarray]:
    """Each named point from a results table's columns, (n, 3) mm."""
    return {n: df[[f"{n}_{a}" for a in "xyz"]].to_numpy() for n in names}


# -- closed forms ------------------------------------------------------------------------

# Two corners as Lotus SHARK printed them (Lotus axes: x rearward, y to the right, z up;
# mm): LBJ, UBJ, wheel spindle point, wheel centre, tyre rolling radius, and its static
# values: kingpin offset at the wheel centre and at the ground, castor trail (hub),
# castor offset (ground), mechanical trail, caster, kingpin angle.
LOTUS = {
    "v4.03 (a right corner)": (
        [(-12.46, 562.18, -60.00), (28.28, 538.13, 80.00), (0.0, 551.87, 0.0), (0.0, 650.0, 0.0)],
        279.40,
        {"at_wc": 98.13, "at_ground": 50.13, "hub_trail": 5.00, "offset": 76.31, "trail": 73.27,
         "caster": 16.22, "kpi": 9.75},
    ),
    "v5.01 (a left corner)": (
        [(4066.34, -688.22, 215.95), (4128.01, -618.94, 435.27), (4092.50, -655.70, 313.10),
         (4092.50, -750.00, 313.10)],
        225.0,
        {"at_wc": 92.47, "at_ground": 21.39, "hub_trail": 1.16, "offset": 62.11, "trail": 59.79,
         "caster": 15.71, "kpi": 17.53},
    ),
}  # fmt: skip


@pytest.mark.parametrize("case", list(LOTUS))
def test_lotus_printout_from_its_hardpoints(case):
    """ISO = (−x, −y, z) of Lotus'. Lotus' kingpin offset (w/c) is kingpin_offset_at_hub,
    its castor offset (grnd) mechanical_trail, its mechanical trail normal_trail, its
    castor trail (hub) −caster_trail_at_hub (the axis behind the hub reads + there), to
    its printed 0.01 mm."""
    lotus, radius, printed = LOTUS[case]
    lbj, ubj, spindle, wc = (np.array([-x, -y, z]) * 1e-3 for x, y, z in lotus)
    data = example("double_wishbone.yaml")
    corner = pin_susp.Corner(data if wc[1] > 0 else mirrored(data))
    p = {
        "lower_wishbone_outboard": lbj,
        "upper_wishbone_outboard": ubj,
        "wheel_center": wc,
        "axle_inboard": spindle,
        "axle_outboard": 2.0 * wc - spindle,
        "contact_patch_center": wc - np.array([0.0, 0.0, radius * 1e-3]),
    }
    ps = PointSet({k: v[None] for k, v in p.items()}, {}, corner.geometry)
    from pin_susp.columns.metrics import caster, kpi, mechanical_trail, scrub_radius

    got = {
        "at_wc": kingpin_offset_at_hub(ps),
        "at_ground": scrub_radius(ps),
        "hub_trail": -caster_trail_at_hub(ps),
        "offset": mechanical_trail(ps),
        "trail": normal_trail(ps),
    }
    for key, value in got.items():
        assert value[0] * 1e3 == pytest.approx(printed[key], abs=0.006), key
    assert np.degrees(caster(ps)[0]) == pytest.approx(printed["caster"], abs=0.006)
    assert np.degrees(kpi(ps)[0]) == pytest.approx(printed["kpi"], abs=0.006)


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_camber_spatial_is_the_wheel_planes_inclination(side):
    """A wheel cambered γ = −3° (top inboard) and toed δ = 10°: the spatial camber is γ,
    ISO's projected camber atan(tan γ / cos δ); at zero toe the two are equal."""
    data = example("double_wishbone.yaml")
    corner = pin_susp.Corner(data if side > 0 else mirrored(data))
    gamma = np.radians(-3.0)
    for delta, projected in ((np.radians(10.0), None), (0.0, gamma)):
        # outboard spin axis: toe-in turns it rearward-out; top inboard tips it upward
        a = np.array(
            [np.sin(delta) * np.cos(gamma), side * np.cos(delta) * np.cos(gamma), np.sin(-gamma)]
        )
        p = {"axle_inboard": np.zeros((1, 3)), "axle_outboard": 0.05 * a[None]}
        ps = PointSet(p, {}, corner.geometry)
        from pin_susp.columns.metrics import camber, roadwheel_angle

        assert np.degrees(roadwheel_angle(ps)[0]) == pytest.approx(np.degrees(delta), abs=1e-12)
        assert camber_spatial(ps)[0] == pytest.approx(gamma, abs=1e-14)
        want = np.arctan(np.tan(gamma) / np.cos(delta)) if projected is None else projected
        assert camber(ps)[0] == pytest.approx(want, abs=1e-14)
        assert (abs(camber(ps)[0] - gamma) > 5e-4) == (delta > 0)  # toed, they differ


# -- from the CSV's own points -------------------------------------------------------------


def meet(lo, k, z):
    """The axis lo + t·k at height z (numpy's solve of (lo + t·k)_z = z)."""
    return lo + np.linalg.solve([[k[2]]], [z - lo[2]])[0] * k


def by_hand(df, s: float, lower: str, upper: str) -> dict[str, np.ndarray]:
    """The four columns from the points alone: the kingpin line through ``lower`` and
    ``upper`` met with the horizontal planes through WC and CP (numpy's solve), the
    wheel's lateral and heading directions on the ground, and the normal trail as the
    CP's distance from the axis in the plane spanned by the heading and z."""
    p = points_of(df, (lower, upper, "wheel_center", "contact_patch_center", "axle_inboard",
                       "axle_outboard"))  # fmt: skip
    out = {k: [] for k in NEW}
    for i in range(len(df)):
        lo, up, wc, cp = (p[n][i] for n in (lower, upper, "wheel_center", "contact_patch_center"))
        a = p["axle_outboard"][i] - p["axle_inboard"][i]
        lateral = np.array([a[0], a[1], 0.0]) / np.hypot(a[0], a[1])
        heading = s * np.cross(lateral, [0.0, 0.0, 1.0])  # forward on either side
        k = up - lo

        h, g = (meet(lo, k, z) for z in (wc[2], cp[2]))
        out["kingpin_offset_at_hub"].append(-(h - wc) @ lateral)
        out["caster_trail_at_hub"].append((h - wc) @ heading)
        # side view in the wheel's axes: 2-D coordinates (along heading, z)
        u = np.array([k @ heading, k[2]])
        d = np.array([(cp - lo) @ heading, cp[2] - lo[2]])
        distance = abs(u[0] * d[1] - u[1] * d[0]) / np.linalg.norm(u)
        out["normal_trail"].append(np.sign((g - cp) @ heading) * distance)
        out["camber_spatial"].append(np.degrees(np.arcsin(-a[2] / np.linalg.norm(a))))
    return {k: np.array(v) for k, v in out.items()}


def sweep_file(tmp_path, data: dict, targets: list, name: str) -> pin_susp.Results:
    """A sweep of ``data`` with ``targets`` through the CLI, its CSV read back."""
    import pandas as pd

    geometry, sweep = tmp_path / f"{name}.yaml", tmp_path / f"{name}_sweep.yaml"
    geometry.write_text(yaml.safe_dump(data))
    sweep.write_text(yaml.safe_dump({"version": 1, "targets": targets}))
    out = tmp_path / f"{name}.csv"
    assert main(["sweep", str(geometry), str(sweep), "-o", str(out), "-q"]) == 0
    return pd.read_csv(out, comment="#")


def steer_and_bump(n: int = 9) -> list:
    rack = np.linspace(-30.0, 30.0, n).tolist()
    bump = np.linspace(-25.0, 35.0, n).tolist()
    return [
        {"point": "wheel_center", "direction": {"axis": "z"}, "values": bump},
        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": rack},
    ]


@pytest.mark.parametrize(
    "name, lower, upper",
    [
        ("double_wishbone.yaml", *RACKED),
        ("macpherson.yaml", "lower_wishbone_outboard", "strut_top"),
    ],
)
@pytest.mark.parametrize("side", ["left", "right"])
def test_new_columns_from_the_csvs_own_points(tmp_path, name, lower, upper, side):
    data = example(name)
    targets = steer_and_bump()
    if side == "right":
        data = mirrored(data)
        targets[1]["values"] = [-v for v in targets[1]["values"]]
    df = sweep_file(tmp_path, data, targets, "corner")
    assert df["solver_converged"].all()
    hand = by_hand(df, 1.0 if side == "left" else -1.0, lower, upper)
    for column in NEW:
        np.testing.assert_allclose(df[column], hand[column], rtol=0, atol=1e-9, err_msg=column)
    # steered and bumped, each differs from its ground-plane or projected neighbour
    assert np.abs(df["camber_spatial"] - df["camber"]).max() > 1e-3
    assert np.abs(df["normal_trail"] - df["trail_in_wheel_axes"]).max() > 0.1
    assert np.ptp(df["kingpin_offset_at_hub"]) > 0.1 and np.ptp(df["normal_trail"]) > 1.0


def test_a_trailing_arm_has_no_kingpin_columns():
    df = pin_susp.Corner(example("semi_trailing_arm.yaml")).run_sweep(example("bump.yaml"))
    for column in NEW[:3]:
        assert np.isnan(df[column]).all() and np.isnan(df[f"deriv_{column}_wrt_hub_z"]).all()
    assert np.isfinite(df["camber_spatial"]).all()
    assert np.isfinite(df["kinematic_instant_center_y"]).all()


# -- derivative columns against differences of the columns -----------------------------------

H = 1e-3  # mm


def three_steps(corner, z0: float, rack0: float, along: str) -> pin_susp.Results:
    """Steps at z0 − H, z0, z0 + H (``along`` "z") or rack0 ∓ H ("rack"), the other held."""
    step = np.array([-H, 0.0, H])
    z = z0 + (step if along == "z" else 0.0 * step)
    rack = rack0 + (step if along == "rack" else 0.0 * step)
    return corner.run_sweep(
        Sweep([Target("wheel_center", "z", z), Target("trackrod_inboard", "y", rack)])
    )


@pytest.mark.parametrize(
    "name", ["double_wishbone.yaml", "macpherson.yaml", "multilink_front.yaml"]
)
def test_derivative_columns_match_central_differences(name):
    corner = pin_susp.Corner(example(name))
    for along, driver in (("z", "hub_z"), ("rack", "rack_displacement")):
        r = three_steps(corner, 12.0, 5.0, along)
        assert r["solver_converged"].all()
        for column in NEW:
            fd = (r[column][2] - r[column][0]) / (2 * H)
            exact = r[f"deriv_{column}_wrt_{driver}"][1]
            assert exact == pytest.approx(fd, rel=1e-5, abs=1e-8), (column, driver)
            assert abs(exact) > 1e-5 or column == "caster_trail_at_hub", (column, driver)


# -- the kinematic instant centre and roll centre ------------------------------------------


def test_kinematic_instant_centre_from_the_uprights_differences():
    """The upright's bump twist from central differences of its points' columns (rack
    held), ω by least squares over v_i − v_WC = ω × (p_i − WC); the front-view pole is
    the point of the plane x = WC_x whose velocity has no y, z part (numpy's solve)."""
    name = "macpherson.yaml"
    corner = pin_susp.Corner(example(name))
    h = 1e-2
    r = corner.run_sweep(Sweep([Target("wheel_center", "z", [7.0 - h, 7.0, 7.0 + h]),
                                Target("trackrod_inboard", "y", [4.0] * 3)]))  # fmt: skip
    upright = ("lower_wishbone_outboard", "strut_bottom", "trackrod_outboard", "axle_inboard",
               "axle_outboard")  # fmt: skip
    p = points_of(r.to_pandas(), (*upright, "wheel_center"))
    v = {n: (p[n][2] - p[n][0]) / (2 * h) for n in p}
    wc = p["wheel_center"][1]
    rows, rhs = [], []
    for n in upright:
        rr = p[n][1] - wc
        rows.append(np.array([[0, rr[2], -rr[1]], [-rr[2], 0, rr[0]], [rr[1], -rr[0], 0]]))
        rhs.append(v[n] - v["wheel_center"])  # ω × r = −r × ω
    w = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
    # (ω × (P − WC))_y,z = −v_WC,y,z with P_x = WC_x: [[0, −ω_x], [ω_x, 0]] (dy, dz)
    d = np.linalg.solve([[0.0, -w[0]], [w[0], 0.0]], -v["wheel_center"][1:])
    assert r["kinematic_instant_center_y"][1] == pytest.approx(wc[1] + d[0], rel=1e-6)
    assert r["kinematic_instant_center_z"][1] == pytest.approx(wc[2] + d[1], rel=1e-6)
    # the plane construction (no turn about the kingpin) is another point
    assert abs(r["fvic_y"][1] - r["kinematic_instant_center_y"][1]) > 10.0


def axle_steps(axle, left, right, rack):
    targets = [
        Target("wheel_center", "z", left, side="left"),
        Target("wheel_center", "z", right, side="right"),
        Target("trackrod_inboard", "y", rack, side="left"),
    ]
    r = axle.run_sweep(Sweep(targets))
    assert r["solver_converged"].all()
    return r


def test_kinematic_roll_centre_from_the_contact_patches_differences():
    """Each side's wheel centre moved ±h alone (the other and the rack held): the contact
    patch's velocity from its columns; the lines through each CP normal to it (front
    view) meet, by numpy's solve, at the axle's kinematic roll centre."""
    axle = pin_susp.Axle(EXAMPLES / "axle_front.yaml")
    h, zl, zr, rack = 1e-2, 8.0, -5.0, 3.0
    step = np.array([-h, 0.0, h])
    moved = {
        "left": axle_steps(axle, zl + step, [zr] * 3, [rack] * 3),
        "right": axle_steps(axle, [zl] * 3, zr + step, [rack] * 3),
    }
    a, b = [], []
    for side, r in moved.items():
        cp = points_of(r.to_pandas(), (f"{side}_contact_patch_center",))[
            f"{side}_contact_patch_center"
        ]
        vel = (cp[2] - cp[0]) / (2 * h)
        a.append(vel[1:])
        b.append(vel[1:] @ cp[1][1:])
    y, z = np.linalg.solve(np.array(a), np.array(b))
    r = moved["left"]
    assert r["kinematic_roll_center_y"][1] == pytest.approx(y, rel=1e-6)
    assert r["kinematic_roll_center_z"][1] == pytest.approx(z, rel=1e-6)
    assert abs(r["kinematic_roll_center_z"][1] - r["roll_center_z"][1]) > 1.0  # not the same


def test_kinematic_roll_centre_mirrors_on_a_symmetric_axle():
    """In heave (the rack centred) y = 0 and the two sides' instant centres are mirror
    images; in roll y is odd and z even."""
    axle = pin_susp.Axle(EXAMPLES / "axle_front.yaml")
    heave = np.linspace(-30.0, 30.0, 7)
    r = axle_steps(axle, heave, heave, np.zeros(7))
    np.testing.assert_allclose(r["kinematic_roll_center_y"], 0.0, atol=1e-9)
    assert np.ptp(r["kinematic_roll_center_z"]) > 10.0  # it migrates in heave
    ky, kz = r["kinematic_instant_center_y_left"], r["kinematic_instant_center_y_right"]
    np.testing.assert_allclose(ky, -kz, rtol=1e-9)
    np.testing.assert_allclose(
        r["kinematic_instant_center_z_left"], r["kinematic_instant_center_z_right"], rtol=1e-9
    )
    # at design (zero toe) each contact patch lies in its plane x = WC_x and slides
    # round the rim along x: its line is the line CP → kinematic instant centre
    design = int(np.argmin(np.abs(heave)))
    assert abs(r["roadwheel_angle_left"][design]) < 1e-9
    lines = [
        [r[f"{side}_contact_patch_center_{a}"][design] for a in "yz"]
        + [r[f"kinematic_instant_center_{a}_{side}"][design] for a in "yz"]
        for side in ("left", "right")
    ]
    assert r["kinematic_roll_center_z"][design] == pytest.approx(roll_centre(lines)[1], rel=1e-9)
    rolled = axle.run_sweep(EXAMPLES / "roll.yaml")
    y, z = rolled["kinematic_roll_center_y"], rolled["kinematic_roll_center_z"]
    np.testing.assert_allclose(y, -y[::-1], rtol=0, atol=1e-6)
    np.testing.assert_allclose(z, z[::-1], rtol=0, atol=1e-6)
    assert np.abs(y[0]) > 100.0


def test_the_fs_cars_kinematic_roll_centre_is_the_one_its_contact_patches_scrub_as():
    """docs/vehicle.md: the FS car's linkage scrubs its front contact patches as a roll
    centre 49.8 mm high would, where the front-view construction gives 45.6 mm."""
    car = pin_susp.Vehicle(EXAMPLES / "vehicle_fs.yaml")
    from vehicles import body_sweep

    r = car.run_sweep(body_sweep(0.0, 0.0, 0.0))
    assert r["kinematic_roll_center_z_front"][0] == pytest.approx(49.8, abs=0.05)
    assert r["roll_center_z_front"][0] == pytest.approx(45.6, abs=0.05)
    assert r["kinematic_roll_center_y_front"][0] == pytest.approx(0.0, abs=1e-9)
