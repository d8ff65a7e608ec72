"""The steering wheel on a corner, an axle and a vehicle (docs/sweep.md, "The steering
wheel"; docs/results.md, "Steering"; docs/loads.md): each number against a computation
of its own — the rack target it stands for, finite differences of the CSV's columns,
the closed-form Ackermann on the corner's own columns at the opposite rack travel, the
axle of the corner mirrored, the trackrods' tensions on the rack's axis, and virtual
work through re-solved poses."""

import copy
import warnings
from dataclasses import replace

import numpy as np
import pytest
from conftest import EXAMPLES, example

import pin_susp
from pin_susp.analyses.load_case import AxleLoadCase
from pin_susp.analyses.loads import LoadCase
from pin_susp.constraints import DistanceClosure, JointTarget
from pin_susp.errors import InputError, PlausibilityWarning
from pin_susp.solve.solver import NewtonSolver

C = 90.0  # mm of rack per steering-wheel revolution
TRACK = 1920.9  # mm: the example corner's contact patches mirrored in y = 0 (1 920.895)


def corner_file(name="double_wishbone.yaml", c=C, track=TRACK) -> dict:
    """An example corner with the c-factor c (None: without one) and config.track."""
    g = example(name)
    g["config"]["steering"]["c_factor"] = c
    g["config"]["track"] = track
    if track is None:
        del g["config"]["track"]
    if c is None:
        del g["config"]["steering"]["c_factor"]
    return g


def axle_file(c=C) -> dict:
    a = example("axle_front.yaml")
    a["axle_config"]["steering"]["c_factor"] = c
    return a


def sweep(steering: dict, z=(0.0, 0.0), steps=13, **axle) -> dict:
    targets = [steering]
    if axle:
        targets += [{"quantity": "heave", "start": 0, "stop": 0}, axle["roll"]]
    else:
        targets.insert(0, {"point": "wheel_center", "direction": {"axis": "z"},
                           "start": z[0], "stop": z[1]})  # fmt: skip
    return {"version": 1, "steps": steps, "targets": targets}


def wheel(start, stop):
    return {"quantity": "steering_wheel", "start": start, "stop": stop}


def rack(start, stop, side=None):
    t = {"point": "trackrod_inboard", "direction": {"axis": "y"}, "start": start, "stop": stop}
    return t if side is None else t | {"side": side}


@pytest.fixture(scope="module")
def corner():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        return pin_susp.Corner(corner_file())


@pytest.fixture(scope="module")
def axle():
    return pin_susp.AxleModel(axle_file())


def same_columns(a, b, skip=()):
    """Every column the two results share, to 1e-9 (1e-10 relative: an instant centre
    500 m away; NaN where the other is NaN)."""
    shared = [k for k in a.keys() if k in b and k not in skip]
    assert len(shared) > 50
    for k in shared:
        x, y = np.asarray(a[k], dtype=float), np.asarray(b[k], dtype=float)
        np.testing.assert_allclose(x, y, rtol=1e-10, atol=1e-9, equal_nan=True, err_msg=k)


def test_a_steering_wheel_target_is_the_rack_target_angle_over_360_times_c(corner, axle):
    """The same sweep, step for step, as the rack target angle / 360 · c (+ left: these
    trackrods are ahead of the wheel centre, so the rack goes to +y), and the angle back
    as the steering_wheel_angle column."""
    angles = (-270.0, 180.0)
    travel = tuple(a / 360.0 * C for a in angles)
    by_wheel = corner.run_sweep(sweep(wheel(*angles), z=(-20, 30)))
    by_rack = corner.run_sweep(sweep(rack(*travel), z=(-20, 30)))
    same_columns(by_wheel, by_rack)
    np.testing.assert_allclose(by_wheel["steering_wheel_angle"], np.linspace(*angles, 13),
                               atol=1e-9)  # fmt: skip
    np.testing.assert_allclose(by_wheel["rack_displacement"], np.linspace(*travel, 13),
                               atol=1e-9)  # fmt: skip
    roll = {"quantity": "roll", "start": -1, "stop": 2}
    by_wheel = axle.run_sweep(sweep(wheel(*angles), roll=roll))
    by_rack = axle.run_sweep(sweep(rack(*travel, side="right"), roll=roll))
    same_columns(by_wheel, by_rack)
    np.testing.assert_allclose(by_wheel["steering_wheel_angle"], np.linspace(*angles, 13),
                               atol=1e-9)  # fmt: skip


def _steer(results, labels):
    """The mean steer angle (+ left) of the wheels, deg, from their toe columns."""
    sign = {"": 1.0, "left": 1.0, "right": -1.0, "fl": 1.0, "fr": -1.0}
    out = []
    for label in labels:
        suffix = f"_{label}" if label else ""
        out.append(-sign[label] * results[f"roadwheel_angle{suffix}"])
    return np.mean(out, axis=0)


def _against_differences(results, labels, h, on_road=False):
    """steering_ratio at the inner steps against central differences of the steering
    wheel's angle over the mean steer angle, the steps h apart (O(h²)). The ratio holds
    each wheel's height; a car on the road lets the wheel centre rise as it steers, so
    there each wheel's share of that rise (its toe's rate along its own height, times
    its centre's rise, from the columns) comes off its steer's difference."""
    angle, steer = results["steering_wheel_angle"], _steer(results, labels)
    change = steer[2:] - steer[:-2]
    if on_road:
        sign = {"fl": 1.0, "fr": -1.0}
        for label in labels:
            z = results[f"{label}_wheel_center_z"]
            rate = results[f"deriv_roadwheel_angle_wrt_hub_z_{label}"][1:-1]
            change = change + sign[label] * rate * (z[2:] - z[:-2]) / len(labels)
    fd = (angle[2:] - angle[:-2]) / change
    np.testing.assert_allclose(results["steering_ratio"][1:-1], fd, rtol=2e-5)
    assert np.all(np.isfinite(results["steering_ratio"]))
    assert 5.0 < np.nanmin(results["steering_ratio"])  # a car's: turns of the wheel


def test_the_steering_ratio_is_the_derivative_of_the_columns(corner, axle):
    """d steering-wheel angle / d mean roadwheel steer, exact, against finite differences
    of the two columns: the corner's own wheel, the axle's two, the vehicle's front."""
    angles = np.arange(-180.0, 180.5, 1.0)
    s = {"version": 1, "targets": [
        {"point": "wheel_center", "direction": {"axis": "z"}, "values": [15.0] * len(angles)},
        {"quantity": "steering_wheel", "values": angles.tolist()}]}  # fmt: skip
    _against_differences(corner.run_sweep(s), [""], 1.0)
    roll = {"quantity": "roll", "start": 0, "stop": 0}
    _against_differences(axle.run_sweep(sweep(wheel(-180, 180), steps=361, roll=roll)),
                         ["left", "right"], 1.0)  # fmt: skip
    car = pin_susp.Vehicle(EXAMPLES / "vehicle_fs.yaml")  # c_factor 90
    body = [{"quantity": q, "start": 0, "stop": 0} for q in ("heave", "pitch", "roll")]
    s = {"version": 1, "steps": 241, "targets": [*body, wheel(-120, 120)]}
    _against_differences(car.run_sweep(s), ["fl", "fr"], 1.0, on_road=True)


def test_the_ratio_of_a_corner_at_centre_is_its_mirrored_axles(corner, axle):
    """Straight ahead the two wheels of a symmetric axle steer alike: its mean's ratio is
    the corner's own."""
    one = corner.run_sweep(sweep(wheel(0, 0), steps=1))
    roll = {"quantity": "roll", "start": 0, "stop": 0}
    both = axle.run_sweep(sweep(wheel(0, 0), steps=1, roll=roll))
    assert one["steering_ratio"][0] == pytest.approx(both["steering_ratio"][0], rel=1e-9)


def test_a_corner_without_its_track_has_no_partner(corner):
    """Without config.track no second solve: the steering wheel's columns alone."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        r = pin_susp.Corner(corner_file(track=None)).run_sweep(sweep(wheel(-90, 90)))
    assert "steering_ratio" in r and "ackermann" not in r and "turning_radius" not in r
    assert "ackermann" in corner.run_sweep(sweep(wheel(-90, 90)))


def test_a_corners_ackermann_is_the_closed_form_on_its_own_columns(corner):
    """The mirrored partner at rack travel x is this corner at −x mirrored: with a sweep
    symmetric in the rack, row j = n−1−i is the partner of row i. Its steer angles, track,
    Ackermann and turning radius from those columns alone (wheelbase 2 500 mm)."""
    r = corner.run_sweep(sweep(wheel(-300, 300), z=(10, 10), steps=21))
    own = -r["roadwheel_angle"]  # a left corner's steer, + left
    mate = -own[::-1]  # the partner's: the mirror image at the opposite travel
    toe0 = corner.run_sweep(sweep(wheel(0, 0), z=(0, 0), steps=1))["roadwheel_angle"][0]
    d_own, d_mate = -toe0, toe0
    cp_y = r["contact_patch_center_y"]
    track = cp_y + cp_y[::-1]
    np.testing.assert_allclose(r["track"], track, atol=1e-9)
    L = 2500.0
    left_inner = own + mate > 0
    di, do = np.abs(own - d_own), np.abs(mate - d_mate)
    inner = np.where(left_inner, di, do)
    outer = np.where(left_inner, do, di)
    ideal = np.degrees(np.arctan(L / (L / np.tan(np.radians(outer)) - track)))
    ackermann = 100 * (inner - outer) / (ideal - outer)
    with np.errstate(divide="ignore"):  # straight ahead: no radius
        radius = L * 1e-3 / np.tan(np.radians(0.5 * (own - d_own + mate - d_mate)))
    steered = np.abs(r["rack_displacement"]) > 1e-3
    assert steered.sum() == 20 and np.isnan(r["ackermann"][~steered]).all()
    for name, expected in (("steer_angle_inner", inner), ("steer_angle_outer", outer),
                           ("ackermann", ackermann), ("turning_radius", radius)):  # fmt: skip
        np.testing.assert_allclose(r[name][steered], expected[steered], rtol=1e-9, err_msg=name)
    assert r["turning_radius"][-1] > 0 > r["turning_radius"][0]  # + turning left


def test_a_corners_ackermann_is_its_mirrored_axles(axle):
    """The axle's left corner alone (its right the left mirrored) gives the axle's track,
    inner and outer angles, Ackermann and steering ratio at every step."""
    left = axle.axle.left  # its file's config, with the track its partner stands in
    data = copy.deepcopy(left.data) | {"config": left.data["config"] | {"track": TRACK}}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        alone = pin_susp.Corner(replace(left, data=data))
    roll = {"quantity": "roll", "start": 0, "stop": 0}
    both = axle.run_sweep(sweep(wheel(-250, 250), steps=11, roll=roll))
    assert np.ptp(both["heave"]) < 1e-9  # both wheel centres at design height
    one = alone.run_sweep(sweep(wheel(-250, 250), z=(0, 0), steps=11))
    names = ("track", "steer_angle_inner", "steer_angle_outer", "ackermann")
    for name in names:
        np.testing.assert_allclose(one[name], both[name], atol=1e-9, rtol=1e-9, err_msg=name)
    assert np.isfinite(one["ackermann"]).sum() == 10
    # the corner's ratio is its own wheel's: the axle's mean rate is the corner's at x
    # and at −x (its partner's), 1/ratio the mean of the corner's two
    mean = 0.5 * (1.0 / one["steering_ratio"] + 1.0 / one["steering_ratio"][::-1])
    np.testing.assert_allclose(1.0 / mean, both["steering_ratio"], rtol=1e-9)


def test_steering_inputs_refused_with_their_key(tmp_path):
    g = corner_file(c=-5)
    with pytest.raises(InputError, match=r"config\.steering\.c_factor.*> 0"):
        pin_susp.Corner(g)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        plain = pin_susp.Corner(corner_file(c=None))
    with pytest.raises(InputError, match=r"targets\[1\].*needs config\.steering\.c_factor"):
        plain.run_sweep(sweep(wheel(0, 10)))
    with pytest.raises(InputError, match=r"axle_config\.steering\.c_factor.*> 0"):
        pin_susp.AxleModel(axle_file(c=0))
    with pytest.raises(InputError, match=r"config\.track.*1920\.9 mm.*more than 1 mm"):
        pin_susp.Corner(corner_file(track=1925))
    toe = example("fixed_toe_link.yaml")
    toe["config"]["steering"] = dict(toe["config"].get("steering", {}), c_factor=90)
    with pytest.raises(InputError, match="c_factor.*needs a rack"):
        pin_susp.Corner(toe)


# ---------------------------------------------------------------- loads


def _cases():
    return [
        LoadCase("braking", np.array([-3000.0, 200.0, 2500.0]), np.zeros(3), np.zeros(3)),
        LoadCase("cornering", np.array([0.0, -4500.0, 2300.0]), np.array([150.0, 0, -80]),
                 np.zeros(3)),
    ]  # fmt: skip


@pytest.fixture(scope="module", params=["pushrod_rocker.yaml", "macpherson.yaml"])
def rocker(request):
    """A corner with its trackrods ahead of the wheel (+1: the rack to +y steers left)
    and one with them behind (−1)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        corner = pin_susp.Corner(corner_file(request.param, track=None))
    s = sweep(wheel(-120, 90), z=(-20, 25), steps=4)
    return corner, s, pin_susp.member_forces(corner, s, _cases())


def _on_rack(forces, prefixes):
    """Σ over the trackrods of tension · unit(outboard − inboard)·ŷ: the trackrods' pull
    on the rack along +y, from the loads output's own columns."""
    total = 0.0
    for p, suffix in prefixes:
        end = {e: np.stack([forces[f"{p}trackrod_{e}_{a}"] for a in "xyz"], axis=1)
               for e in ("inboard", "outboard")}  # fmt: skip
        u = end["outboard"] - end["inboard"]
        total = total + forces[f"force_trackrod{suffix}"] * u[:, 1] / np.linalg.norm(u, axis=1)
    return total


def test_rack_force_is_the_trackrods_tension_on_the_racks_axis(rocker):
    corner, _, forces = rocker
    ahead = corner.geometry.hardpoints["trackrod_outboard"][0] > 0.0  # the wheel at x = 0
    assert corner.steering.sense == (1.0 if ahead else -1.0)
    expected = corner.steering.sense * _on_rack(forces, [("", "")])
    np.testing.assert_allclose(forces["rack_force"], expected, rtol=1e-9, atol=1e-6)
    assert np.abs(forces["rack_force"]).max() > 100.0  # N: a load that steers
    torque = forces["rack_force"] * C * 1e-3 / (2 * np.pi)
    np.testing.assert_allclose(forces["steering_wheel_torque"], torque, rtol=1e-12)
    cases = [AxleLoadCase("turn", _cases()[1], _cases()[0])]
    roll = {"quantity": "roll", "start": -1, "stop": 1}
    data = axle_file()
    data["axle_config"]["spring"] = {"type": "coilover", "rate": 175.0, "preload": 2600.0}
    data["axle_config"]["anti_roll"]["stiffness"] = 40.0  # N·m/deg: the loads' share
    rated = pin_susp.AxleModel(data)
    both = pin_susp.member_forces(rated, sweep(wheel(-90, 90), steps=3, roll=roll), cases)
    expected = _on_rack(both, [("left_", "_left"), ("right_", "_right")])
    np.testing.assert_allclose(both["rack_force"], expected, rtol=1e-9, atol=1e-6)
    np.testing.assert_allclose(
        both["steering_wheel_torque"], both["rack_force"] * C * 1e-3 / (2 * np.pi), rtol=1e-12
    )


def test_steering_wheel_torque_by_virtual_work(rocker):
    """Turn the steering wheel by ±ε with every member and the spring held (the loads'
    model): the loads' work on the upright's material points equals torque · 2ε."""
    corner, s, forces = rocker
    cases = _cases()
    results = corner.run_sweep(s)
    p = corner.points
    eps = np.radians(0.01)  # rad of the steering wheel
    for step, q0 in enumerate(results.meta["q"]):
        corner.kin.update_positions(q0)
        spring = np.linalg.norm(p["strut_top"].position(corner.kin)
                                - p["strut_bottom"].position(corner.kin))  # fmt: skip
        wc = corner.kin.data.oMf[p["wheel_center"].frame_id].copy()
        cp = wc.actInv(p["contact_patch_center"].position(corner.kin).copy())
        moved = []
        for sign in (1.0, -1.0):
            held = DistanceClosure("spring", p["strut_top"], p["strut_bottom"], spring)
            target = JointTarget(corner.model, "rack_slide")
            solver = NewtonSolver(corner.kin, [*corner.closures, held], [target])
            start = np.array([q0[target.index_q]])
            turn = corner.steering.sense * sign * eps  # the rack's way for + left
            goal = start + turn / (2 * np.pi) * C * 1e-3
            solution = solver.solve(q0, start, goal)
            assert solution.converged
            corner.kin.update_positions(solution.q)
            frame = corner.kin.data.oMf[p["wheel_center"].frame_id]
            moved.append((frame.act(cp), frame.translation.copy()))
        d_cp, d_wc = moved[0][0] - moved[1][0], moved[0][1] - moved[1][1]
        for k, case in enumerate(cases):
            work = case.contact_patch @ d_cp + case.wheel_center @ d_wc
            torque = forces["steering_wheel_torque"][step * len(cases) + k]
            assert torque * 2 * eps == pytest.approx(work, rel=1e-6, abs=1e-9), (step, k)


def test_a_vehicles_rack_force_is_its_front_trackrods_on_the_racks_axis():
    """The car's rack, in its chassis frame (the points' columns are there): its two
    trackrods' tensions along chassis y; the torque through the car's c-factor (90)."""
    car = pin_susp.Vehicle(EXAMPLES / "vehicle_fs.yaml")
    body = [{"quantity": q, "start": 0, "stop": v} for q, v in (("heave", 5), ("pitch", 0.5),
                                                                ("roll", 1.0))]  # fmt: skip
    s = {"version": 1, "steps": 3, "targets": [*body, wheel(-60, 90)]}
    forces = pin_susp.member_forces(car, s, EXAMPLES / "vehicle_loads.yaml")
    expected = _on_rack(forces, [("fl_", "_fl"), ("fr_", "_fr")])
    assert car.steering.sense == 1.0 and car.steering.c_factor == 90.0
    np.testing.assert_allclose(forces["rack_force"], expected, rtol=1e-9, atol=1e-6)
    assert np.abs(forces["rack_force"]).max() > 100.0
    np.testing.assert_allclose(
        forces["steering_wheel_torque"], forces["rack_force"] * 0.090 / (2 * np.pi), rtol=1e-12
    )


def test_a_vehicle_takes_its_front_axles_c_factor_where_it_gives_none(tmp_path):
    import yaml

    data = example("vehicle_fs.yaml")
    del data["vehicle_config"]["steering"]
    front = example("vehicle/fs_front.yaml")
    front["axle_config"]["steering"]["c_factor"] = 60.0
    data["front"] = front
    data["rear"] = str(EXAMPLES / data["rear"])
    path = tmp_path / "car.yaml"
    path.write_text(yaml.safe_dump(data))
    car = pin_susp.Vehicle(path)
    assert car.steering.c_factor == 60.0
    body = [{"quantity": q, "start": 0, "stop": 0} for q in ("heave", "pitch", "roll")]
    r = car.run_sweep({"version": 1, "steps": 3, "targets": [*body, wheel(-30, 30)]})
    np.testing.assert_allclose(r["rack_displacement"], [-5.0, 0.0, 5.0], atol=1e-9)
    front["axle_config"]["steering"]["c_factor"] = -1
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(InputError, match=r"front\.axle_config\.steering\.c_factor"):
        pin_susp.Vehicle(path)
