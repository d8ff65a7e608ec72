"""Anti-roll bars and heave links in a vehicle (docs/vehicle.md): each axle's elements
named by its corners' labels and its end, in the vehicle's one model.

Checked against computations of their own: each bar's twist, arm angles, points and
twist rates at a vehicle step against that axle file's AxleModel — a different model,
solved on its own — at the same chassis-frame wheel-centre heights and rack; the
twist rate against finite differences of the vehicle's sweep (the road raised under
one corner, the body held); the twist zero in pure heave, the arm angles mirrored in
roll; a heave link's length against its axle's alone; a dead-centre droplink named in
its axle's file.
"""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from vehicles import axle_alone, body_sweep

from pin_susp.errors import InputError
from pin_susp.io.yamlio import load_yaml
from pin_susp.model.sweep import load_sweep
from pin_susp.subjects.axle import AxleModel
from pin_susp.subjects.vehicle import AXLES, Vehicle

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FS = EXAMPLES / "vehicle_fs.yaml"
AXLE_FILES = {end: EXAMPLES / "vehicle" / f"fs_{end}.yaml" for end in AXLES}


def axle_data(end: str) -> dict:
    return copy.deepcopy(load_yaml(AXLE_FILES[end])[0])


def vehicle_data(front: dict | str, rear: dict | str) -> dict:
    data = copy.deepcopy(load_yaml(FS)[0])
    data["front"], data["rear"] = front, rear
    return data


def t_bar_and_heave_link() -> dict:
    """The example car with a heave link on the front rockers and a T-bar at the rear
    (its crossbar 600 mm across, 70 mm behind its pivot, droplinks straight down)."""
    front = axle_data("front")
    front["axle_config"]["heave_link"] = {"type": "rocker_to_rocker"}
    front["hardpoints"]["left"]["heave_link_rocker"] = {"x": 20, "y": 320, "z": 420}
    rear = axle_data("rear")
    rear["axle_config"]["anti_roll"] = {"type": "t_bar", "stiffness": 2.0}
    left = rear["hardpoints"]["left"]
    del left["droplink_u_bar"]
    left["droplink_t_bar"] = {"x": -1530, "y": 300, "z": 340}
    rear["hardpoints"]["center"] = {"arb_t_bar_pivot": {"x": -1600, "y": 0, "z": 340}}
    return vehicle_data(front, rear)


@pytest.fixture(scope="module", params=["u_bars", "t_bar"])
def car(request):
    if request.param == "u_bars":
        return Vehicle(FS)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # <dict> inline axles: nothing to warn of here
        return Vehicle(t_bar_and_heave_link())


@pytest.fixture(scope="module")
def rolled(car):
    """Rolled ±2 deg with some heave, pitch and steering, and the road warped."""
    roll = np.linspace(-2.0, 2.0, 9)
    return car.run_sweep(body_sweep(3.0, 0.4, roll, steer=30.0, roads={"rr": 4.0}))


def alone(car, end: str, results) -> tuple:
    """That axle's AxleModel swept on its own at the vehicle's chassis-frame wheel-centre
    heights (and its rack's travel)."""
    model, sweep = axle_alone(car, end, results)
    own = model.run_sweep(sweep)
    assert own["solver_converged"].all()
    return model, own


def test_the_bars_are_their_axles_own(car, rolled):
    """Each bar's twist, arm angles and points and each corner's twist rate along its
    own hub z at a vehicle step equal its axle's, swept alone at the same chassis-frame
    wheel heights and rack (to 1e-9)."""
    assert rolled["solver_converged"].all()
    for end, (first, second) in AXLES.items():
        model, own = alone(car, end, rolled)
        assert np.ptp(own["arb_twist"]) > 1.0  # the bar works: a check that can fail
        np.testing.assert_allclose(
            rolled[f"arb_twist_{end}"], own["arb_twist"], rtol=0, atol=1e-9, err_msg=end
        )
        bar = car.axle_elements[end].bar
        for label, side in ((first, "left"), (second, "right")):
            rate = f"deriv_arb_twist_wrt_hub_z_{label}"
            np.testing.assert_allclose(
                rolled[rate], own[f"deriv_arb_twist_wrt_hub_z_{side}"], rtol=0, atol=1e-9
            )
            assert np.all(np.abs(rolled[rate]) > 1e-3), rate
            points = [n for n in model.output_points if n.startswith(f"{side}_")]
            ends = [n.removeprefix(f"{side}_") for n in points if "droplink" in n]
            assert len(ends) == 2
            if bar.kind == "u_bar":
                np.testing.assert_allclose(
                    rolled[f"arb_arm_angle_{label}"], own[f"arb_arm_angle_{side}"], atol=1e-9
                )
            for name in ends:  # the bar's points in the chassis frame, as the axle's
                for a in "xyz":
                    np.testing.assert_allclose(
                        rolled[f"{label}_{name}_{a}"], own[f"{side}_{name}_{a}"], atol=1e-9
                    )
        centre = [n for n in model.output_points if n.startswith("arb_")]
        assert centre
        for name in centre:
            for a in "xyz":
                np.testing.assert_allclose(
                    rolled[f"{end}_{name}_{a}"], own[f"{name}_{a}"], rtol=0, atol=1e-9
                )


def test_the_elements_are_named_by_the_corners_and_the_axle(car):
    bodies = {b.name for b in car.tree.bodies}
    closures = {c.name for c in car.tree.closures}
    assert {"fl_droplink", "fr_droplink", "rl_droplink", "rr_droplink"} <= closures
    if car.vehicle.rear.anti_roll == "t_bar":
        assert "rear_t_bar" in bodies and "rear_arb_t_bar_pivot" in car.points
        assert {"fl_heave_link_rocker", "fr_heave_link_rocker"} <= set(car.points)
    else:
        assert {"fl_arb_arm", "fr_arb_arm", "rl_arb_arm", "rr_arb_arm"} <= bodies
        assert {"front_arb_u_bar_axis_a", "rear_arb_u_bar_axis_b"} <= set(car.points)
    assert not any(n.startswith(("left_", "right_", "arb_")) for n in car.points)
    assert not {"t_bar", "arb_bar"} & bodies


def test_no_twist_in_heave_and_mirrored_arms_in_roll(car):
    """The body heaved alone twists no bar (to 1e-9 deg) though the arms turn; rolled
    one way, each left arm turns as the right one rolled the other way."""
    r = car.run_sweep(EXAMPLES / "vehicle_heave.yaml")
    for end in AXLES:
        assert np.max(np.abs(r[f"arb_twist_{end}"])) <= 1e-9, end
        first = AXLES[end][0]
        assert np.ptp(r[f"{first}_droplink_rocker_z"]) > 5.0  # the droplinks do move
    for label in ("fl", "fr", "rl", "rr"):
        if f"arb_arm_angle_{label}" in r.columns:
            assert np.ptp(r[f"arb_arm_angle_{label}"]) > 2.0
    roll = np.linspace(-2.0, 2.0, 9)
    r = car.run_sweep(body_sweep(-4.0, 0.3, roll))
    for end, (a, b) in AXLES.items():
        twist = r[f"arb_twist_{end}"]
        assert np.ptp(twist) > 2.0
        np.testing.assert_allclose(twist, -twist[::-1], rtol=0, atol=1e-9)
        if f"arb_arm_angle_{a}" in r.columns:
            np.testing.assert_allclose(
                r[f"arb_arm_angle_{a}"], r[f"arb_arm_angle_{b}"][::-1], rtol=0, atol=1e-9
            )
        np.testing.assert_allclose(
            r[f"deriv_arb_twist_wrt_hub_z_{a}"],
            -r[f"deriv_arb_twist_wrt_hub_z_{b}"][::-1],
            rtol=0,
            atol=1e-9,
        )


def test_heave_link_length_is_its_axles_own():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        car = Vehicle(t_bar_and_heave_link())
    r = car.run_sweep(body_sweep(np.linspace(-20, 20, 9), 0.5, np.linspace(-1.5, 1.5, 9)))
    _, own = alone(car, "front", r)
    length = r["heave_link_length_front"]
    assert np.ptp(length) > 1.0  # the rockers do move it
    np.testing.assert_allclose(length, own["heave_link_length"], rtol=0, atol=1e-9)
    ends = [
        np.stack([r[f"{label}_heave_link_rocker_{a}"] for a in "xyz"], 1)
        for label in "fl fr".split()
    ]
    np.testing.assert_allclose(length, np.linalg.norm(ends[0] - ends[1], axis=1), atol=1e-9)
    assert "heave_link_length_rear" not in r.columns


@pytest.mark.parametrize("end", list(AXLES))
def test_a_dead_centre_droplink_is_named_in_its_axle_file(tmp_path, end):
    """A droplink in line with its bar arm (no leverage on it: the arm turns freely) in
    the front or the rear axle: one InputError naming that axle's file and key."""
    files = {}
    for e in AXLES:
        data = axle_data(e)
        if e == end:  # the droplink's top moved ahead of the arm's end, level with it
            left = data["hardpoints"]["left"]
            arm = left["droplink_u_bar"]
            left["droplink_rocker"] = {"x": arm["x"] + 100, "y": arm["y"], "z": arm["z"]}
        files[e] = tmp_path / f"{e}.yaml"
        files[e].write_text(yaml.safe_dump(data))
    path = tmp_path / "car.yaml"
    path.write_text(yaml.safe_dump(vehicle_data(files["front"].name, files["rear"].name)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # its dead centre is warned of when read, too
        with pytest.raises(InputError) as error:
            Vehicle(path)
        with pytest.raises(InputError, match="do not fix the axle's pose"):
            AxleModel(files[end])  # the axle on its own: refused alike
    assert error.value.source == str(files[end])
    assert error.value.key == "hardpoints"
    assert f"{AXLES[end][0]}_arb_arm" in error.value.problem and "dead centre" in str(error.value)
    assert str(error.value).count("\n") == 0
    files[end].write_text(AXLE_FILES[end].read_text())  # as the example: it builds
    assert Vehicle(path).mobility == 8


def test_a_dead_centre_droplink_inline_is_named_in_the_vehicle_file():
    front = axle_data("front")
    left = front["hardpoints"]["left"]
    left["droplink_rocker"] = dict(left["droplink_u_bar"], x=left["droplink_u_bar"]["x"] + 80)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InputError, match=r"^<dict>: front\.hardpoints: the wheels"):
            Vehicle(vehicle_data(front, str(AXLE_FILES["rear"])))


@pytest.mark.parametrize("label", ["fl", "fr", "rl", "rr"])
def test_twist_rate_against_finite_differences(car, label):
    """deriv_arb_twist_wrt_hub_z along the corner's own chassis-frame wheel-centre
    height, the body, the rack and the other wheels held: the road raised under that
    corner alone, heave, pitch, roll and the steering held."""
    end = "front" if label[0] == "f" else "rear"
    h = 1e-2  # mm of road
    for at in (0.0, 12.0):
        roads = {label: np.array([at - h, at, at + h])}
        r = car.run_sweep(body_sweep(2.0, 0.3, 0.8, steer=20.0, roads=roads))
        assert r["solver_converged"].all()
        for other in (lb for lb in ("fl", "fr", "rl", "rr") if lb != label):
            assert np.ptp(r[f"{other}_wheel_center_z"]) < 1e-9  # only this corner moves
        twist, wc = r[f"arb_twist_{end}"], r[f"{label}_wheel_center_z"]
        fd = (twist[2] - twist[0]) / (wc[2] - wc[0])
        exact = r[f"deriv_arb_twist_wrt_hub_z_{label}"][1]
        assert abs(exact) > 1e-3
        assert exact == pytest.approx(fd, rel=1e-6), (label, at)


def test_the_example_car_writes_its_bars(tmp_path):
    """The FS car's warp (tests/test_vehicle.py solves every example sweep) writes each
    bar's columns, with their units, and the bar's points."""
    r = Vehicle(FS).run_sweep(load_sweep(EXAMPLES / "vehicle_warp.yaml"))
    assert r["solver_converged"].all()
    assert r.units["arb_twist_front"] == r.units["arb_arm_angle_rr"] == "deg"
    assert r.units["deriv_arb_twist_wrt_hub_z_fl"] == "deg/mm"
    assert np.ptp(r["arb_twist_rear"]) > 5.0  # warp twists the bars
    out = tmp_path / "warp.csv"
    r.to_csv(out)
    header = next(line for line in out.read_text().splitlines() if not line.startswith("#"))
    assert {"fl_droplink_u_bar_x", "rear_arb_u_bar_axis_b_z", "arb_twist_rear"} <= set(
        header.split(",")
    )


def test_the_vehicle_sees_its_axles_transmissions():
    """Each link's transmission angle at design on a pivoted body (docs/geometry.md,
    "Dead centres"), the pushrods', coilovers' and droplinks' on the rockers and the bar
    arms: the vehicle's (its chassis on the road) are its axles' own, relabelled."""
    from pin_susp.model.deadcentre import transmissions

    got = {(t.link, t.body): t.angle for t in transmissions(Vehicle(FS).tree)}
    count = 0
    for end, labels in AXLES.items():
        for t in transmissions(AxleModel(AXLE_FILES[end]).tree):
            side = t.link.partition("_")[0]
            label = dict(zip(("left", "right"), labels, strict=True))[side]
            key = (label + t.link.removeprefix(side), label + t.body.removeprefix(side))
            assert got[key] == pytest.approx(t.angle, abs=1e-9), key
            count += 1
    assert count == len(got) and any(body.endswith("_arb_arm") for _, body in got)
