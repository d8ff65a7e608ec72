"""The whole car (docs/vehicle.md): four corners under one body on the road.

Checked against computations of their own: each corner's columns against that
corner's own sweep at the same chassis-frame wheel-centre height and rack; the
contact patches on the road and the CG's heave from the written chassis-frame
points and the body's pose (scipy's rotations, the wheel's lowest point); the
rates along heave, pitch and roll against finite differences; left/right mirror
symmetry.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation
from vehicles import body_sweep

import pin_susp
from pin_susp.errors import InputError
from pin_susp.io.yamlio import load_yaml
from pin_susp.model.sweep import Sweep, Target, load_sweep
from pin_susp.subjects.vehicle import LABELS, Vehicle, load_vehicle

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FS = EXAMPLES / "vehicle_fs.yaml"
SALOON = EXAMPLES / "vehicle_saloon.yaml"  # MacPherson front, multilink rear


@pytest.fixture(scope="module", params=[FS, SALOON], ids=["fs", "saloon"])
def car(request):
    return Vehicle(request.param)


@pytest.fixture(scope="module")
def combined(car):
    return car.run_sweep(EXAMPLES / "vehicle_combined.yaml")


def test_every_step_closes(car):
    for name in ("heave", "pitch", "roll", "warp", "steer", "combined"):
        r = car.run_sweep(EXAMPLES / f"vehicle_{name}.yaml")
        assert r["solver_converged"].all(), name
        assert np.max(r["solver_max_residual"]) <= 1e-9, name


def test_corner_columns_are_the_corners_own(car, combined):
    """Each corner at a vehicle step is its own corner solved at the chassis-frame
    wheel-centre height and rack the vehicle gives it (to 1e-9)."""
    for label in LABELS:
        g = car.vehicle.corner(label)
        corner = pin_susp.Corner(g, warn=False)
        wc = combined[f"{label}_wheel_center_z"]
        targets = [Target("wheel_center", "z", wc, "absolute")]
        if g.steering == "rack":
            rack = combined[f"{label}_trackrod_inboard_y"]
            targets.append(Target("trackrod_inboard", "y", rack, "absolute"))
        own = corner.run_sweep(Sweep(targets, "<own>"))
        assert own["solver_converged"].all()
        for column in (
            "camber",
            "caster",
            "kpi",
            "roadwheel_angle",
            "scrub_radius",
            "mechanical_trail",
            "deriv_camber_wrt_hub_z",
            "deriv_roadwheel_angle_wrt_hub_z",
            "motion_ratio",
            "wheel_rate",
        ):
            if column in own.columns:
                np.testing.assert_allclose(
                    combined[f"{column}_{label}"], own[column], rtol=0, atol=1e-9, err_msg=column
                )


def world(results, label: str, point: str, cg: np.ndarray) -> np.ndarray:
    """A written (chassis-frame, mm) point in the road's frame, by scipy's rotations."""
    p = np.stack([results[f"{label}_{point}_{a}"] for a in "xyz"], axis=1)
    turn = Rotation.from_euler("YX", np.radians(np.stack([results["pitch"], results["roll"]], 1)))
    return cg + turn.apply(p - cg) + np.outer(results["heave"], [0.0, 0.0, 1.0])


def test_contact_patches_on_the_road(car):
    """The wheel's lowest point below its centre, from the written points and the
    body's pose, lies on the road (0, or its road_z) at every step."""
    sweep = load_sweep(EXAMPLES / "vehicle_warp.yaml")
    for r, roads in (
        (car.run_sweep(sweep), {"fr": np.linspace(0, 20, 21), "rl": np.linspace(0, 20, 21)}),
        (car.run_sweep(EXAMPLES / "vehicle_combined.yaml"), {}),
    ):
        cg = car.vehicle.cg * 1e3
        for label in LABELS:
            centre = world(r, label, "wheel_center", cg)
            spin = world(r, label, "axle_outboard", cg) - world(r, label, "axle_inboard", cg)
            spin /= np.linalg.norm(spin, axis=1)[:, None]
            up = np.array([0.0, 0.0, 1.0])
            down = -(up - (spin @ up)[:, None] * spin)  # the wheel plane's downward radius
            down /= np.linalg.norm(down, axis=1)[:, None]
            lowest = centre + car.corners[label].wheel.radius * 1e3 * down
            road = roads.get(label, np.zeros(len(r)))
            np.testing.assert_allclose(lowest[:, 2], road, rtol=0, atol=1e-9)


def test_heave_is_the_cgs_rise(car, combined):
    """A point at the CG, moved as the body's pose says, rises by the heave."""
    cg = car.vehicle.cg
    turn = Rotation.from_euler(
        "YX", np.radians(np.stack([combined["pitch"], combined["roll"]], 1))
    ).as_matrix()
    assert np.allclose(turn @ np.zeros(3), 0.0)  # the CG does not move under a turn about it
    np.testing.assert_allclose(combined["heave"], np.linspace(0, -10, 21), atol=1e-12)
    np.testing.assert_allclose(combined["pitch"], np.linspace(0, 1, 21), atol=1e-12)
    assert cg[1] == 0.0


@pytest.mark.parametrize(("quantity", "at", "h"), [("heave", 5.0, 1e-3), ("roll", 0.7, 1e-4)])
def test_rates_along_the_body(car, quantity, at, h):
    """deriv_*_wrt_heave / _roll against central finite differences of the sweep."""
    values = np.array([at - h, at, at + h])
    pose = {"heave": 0.0, "pitch": 0.3, "roll": 0.0} | {quantity: values}
    r = car.run_sweep(body_sweep(pose["heave"], pose["pitch"], pose["roll"], steer=20.0))
    for label in LABELS:
        for column in ("camber", "roadwheel_angle", "wheel_center_z"):
            source = (
                f"{label}_wheel_center_z" if column == "wheel_center_z" else f"{column}_{label}"
            )
            fd = (r[source][2] - r[source][0]) / (2 * h)
            exact = r[f"deriv_{column}_wrt_{quantity}_{label}"][1]
            assert exact == pytest.approx(fd, rel=1e-5, abs=1e-8), (label, column)


def test_mirror_symmetry_in_roll(car):
    """Rolled one way, the left corners are the right ones rolled the other way."""
    roll = np.linspace(-2, 2, 9)
    r = car.run_sweep(body_sweep(np.full(9, 3.0), np.full(9, 0.4), roll))
    for a, b in (("fl", "fr"), ("rl", "rr")):
        # (roadwheel_angle is each corner's own toe sign, mirrored with its corner)
        for column in ("camber", "camber_to_ground", "wheel_travel", "kpi", "roadwheel_angle"):
            np.testing.assert_allclose(
                r[f"{column}_{a}"], r[f"{column}_{b}"][::-1], rtol=0, atol=1e-9
            )


def test_rack_held_without_a_steering_target_is_held_in_the_body(car):
    """No steering target: the rack stays at design in the body (rack_displacement 0) as
    the body rolls and pitches, the same steps as a centred steering wheel's. (It used to
    hold the rack's inboard end in the road's frame: the rack slid about 1 mm at 2° of
    roll, its left and right rolls not mirrored, and the rack's force went to the road.)"""
    roll = np.linspace(-2, 2, 5)
    held = body_sweep(np.full(5, 3.0), np.full(5, 0.4), roll)
    held = Sweep([t for t in held.targets if t.quantity != "steering_wheel"], "<test>")
    r = car.run_sweep(held)
    assert r.meta["notes"] == ["rack held at design (the sweep gives no rack target)"]
    np.testing.assert_allclose(r["rack_displacement"], 0.0, atol=1e-9)
    centred = car.run_sweep(body_sweep(np.full(5, 3.0), np.full(5, 0.4), roll))
    for label in LABELS:
        for column in ("roadwheel_angle", "camber_to_ground"):
            name = f"{column}_{label}"
            np.testing.assert_allclose(r[name], centred[name], rtol=0, atol=1e-9)


def test_steering_wheel_is_the_rack_through_the_c_factor(car):
    r = car.run_sweep(EXAMPLES / "vehicle_steer.yaml")
    np.testing.assert_allclose(r["steering_wheel_angle"], np.linspace(-90, 90, 21), atol=1e-9)
    turns = np.linspace(-90, 90, 21) / 360
    c = car.vehicle.c_factor
    np.testing.assert_allclose(np.abs(r["rack_displacement"]), np.abs(turns) * c, atol=1e-9)
    # + turning left: each front wheel's spin axis turns anticlockwise seen from above
    for label, outboard in (("fl", 1.0), ("fr", -1.0)):
        axis = r[f"{label}_axle_outboard_x"] - r[f"{label}_axle_inboard_x"]
        heading = np.degrees(np.arctan2(-axis * outboard, 150.0))  # the axle is 150 mm
        assert np.all(np.diff(heading) > 0), label


def test_bad_files(tmp_path):
    data = {
        "scope": "vehicle",
        "vehicle_config": {"wheelbase": 1500, "cg": {"x": 0.5, "z": 280}},
        "front": str(EXAMPLES / "vehicle" / "fs_front.yaml"),
        "rear": str(EXAMPLES / "vehicle" / "fs_rear.yaml"),
    }
    with pytest.raises(InputError, match="wheelbase.*1530 mm apart"):
        load_vehicle(data)
    data["vehicle_config"]["wheelbase"] = 1530
    data["vehicle_config"]["cg"] = {"z": 280}
    with pytest.raises(InputError, match="cg: give exactly one of x"):
        load_vehicle(data)
    data["vehicle_config"]["cg"] = {"x": 0.5, "z": 280}
    rigid = load_yaml(EXAMPLES / "vehicle" / "fs_front.yaml")[0]
    rigid["axle_config"]["anti_roll"]["stiffness"] = "rigid"  # it would lock the body's roll
    data["front"] = rigid
    with pytest.raises(
        InputError, match=r"^<dict>: front\.axle_config\.anti_roll\.stiffness: a rigid"
    ):
        load_vehicle(data)
    data["front"] = {"scope": "axle", "axle_config": {"axle_position": "front"}}
    with pytest.raises(InputError, match=r"^<dict>: front\.hardpoints: missing key"):
        load_vehicle(data)  # an inline axle's errors under its key in the vehicle file
    data["front"] = str(EXAMPLES / "vehicle" / "fs_rear.yaml")
    with pytest.raises(InputError, match="axle_position: rear, not front"):
        load_vehicle(data)
    data["front"] = str(EXAMPLES / "vehicle" / "fs_front.yaml")
    data["vehicle_config"]["cg"] = {"x": 47, "z": 280}  # mm typed for a fraction
    with pytest.raises(InputError, match="cg.x: 47 is not a fraction"):
        load_vehicle(data)
    data["vehicle_config"]["cg"] = {"x": 0.5, "z": 280}
    data["front"] = "nowhere.yaml"
    with pytest.raises(InputError, match="front: no axle file"):
        load_vehicle(data)


def test_cli_sweep_writes_the_car(tmp_path):
    import subprocess
    import sys

    out = tmp_path / "roll.csv"
    run = subprocess.run(
        [sys.executable, "-m", "pin_susp", "sweep", str(FS), str(EXAMPLES / "vehicle_roll.yaml")]
        + ["-o", str(out)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode == 0, run.stderr
    assert "suffixed _fl/_fr/_rl/_rr" in run.stdout
    assert "rack held" not in run.stdout
    header = next(line for line in out.read_text().splitlines() if not line.startswith("#"))
    for column in ("camber_fl", "camber_to_ground_rr", "deriv_camber_wrt_roll_fl", "roll"):
        assert column in header.split(",")
    at = f"{EXAMPLES / 'vehicle_roll.yaml'}:3"
    for refused in (["urdf", str(FS), "--at", at, "-o", str(tmp_path / "car.urdf")],):
        run = subprocess.run(
            [sys.executable, "-m", "pin_susp", *refused],
            capture_output=True,
            text=True,
            cwd=tmp_path,
        )
        assert run.returncode == 2 and "not for a vehicle yet" in run.stderr, refused
        assert run.stderr.count("\n") == 1 and "Traceback" not in run.stderr
    assert not (tmp_path / "car.urdf").exists()


def test_misspelt_scope_and_the_wrong_kinds_quantities_say_so(tmp_path):
    """A misspelt scope is named as such (not taken for an axle's); a vehicle's pitch
    on an axle and an axle's roll on a corner name whose quantities they are; the
    steering wheel given twice is named."""
    from pin_susp.errors import InputError
    from pin_susp.model.geometry import load_geometry
    from pin_susp.model.sweep import load_sweep
    from pin_susp.subjects.axle import AxleModel

    data = yaml.safe_load((EXAMPLES / "vehicle_fs.yaml").read_text())
    data["scope"] = "vehicel"
    with pytest.raises(InputError, match="scope: expected one of corner, axle, vehicle"):
        load_geometry(data)
    axle = AxleModel(EXAMPLES / "vehicle" / "fs_front.yaml")
    with pytest.raises(InputError, match="pitch is a vehicle's quantity: this geometry is an axle"):
        axle.run_sweep(EXAMPLES / "vehicle_pitch.yaml")
    twice = {
        "version": 1,
        "steps": 2,
        "targets": [{"quantity": q, "start": 0, "stop": 0} for q in ("heave", "pitch", "roll")]
        + [{"quantity": "steering_wheel", "start": 0, "stop": 10}] * 2,
    }
    with pytest.raises(InputError, match=r"targets\[4\]: repeats targets\[3\]'s steering"):
        Vehicle(EXAMPLES / "vehicle_fs.yaml").run_sweep(load_sweep(twice))


def test_a_wheel_off_the_road_at_design_is_an_error(tmp_path):
    """A wheel centre too low for its tyre (its contact patch below z = 0 at design)
    is named in its axle file, with how far: every sweep would start by moving it."""
    from pin_susp.errors import InputError

    for name in ("vehicle_fs.yaml", "vehicle/fs_front.yaml", "vehicle/fs_rear.yaml"):
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text((EXAMPLES / name).read_text())
    front = tmp_path / "vehicle" / "fs_front.yaml"
    data = yaml.safe_load(front.read_text())
    for key in ("axle_inboard", "axle_outboard"):
        data["hardpoints"]["left"][key]["z"] -= 3.0
    front.write_text(yaml.safe_dump(data))
    with pytest.raises(InputError) as got:
        Vehicle(tmp_path / "vehicle_fs.yaml")
    assert got.value.source == str(front) and got.value.key == "hardpoints"
    assert "the fl contact patch is 3 mm below the road" in got.value.problem


def test_the_rack_is_held_and_moved_in_the_chassis_frame():
    """Without a steering target the rack stays at design while the body rolls (it is
    held by its joint, not by its end's position on the road); a rack target as on an
    axle (trackrod_inboard along y) and the vehicle's rack quantity move it by exactly
    their travel, rolled or not."""
    from pin_susp.model.sweep import load_sweep

    car = Vehicle(EXAMPLES / "vehicle_fs.yaml")
    body = [
        {"quantity": "heave", "start": 0, "stop": 0},
        {"quantity": "pitch", "start": 0, "stop": 0},
        {"quantity": "roll", "start": -2, "stop": 2},
    ]
    held = car.run_sweep(load_sweep({"version": 1, "steps": 5, "targets": body}))
    assert held.meta["notes"] and np.abs(held["rack_displacement"]).max() < 1e-9
    # the rack's end on the road moves with the roll: a hold in the road frame would not
    assert np.ptp(held["fl_trackrod_inboard_z"]) == 0.0  # (chassis frame: it stays)
    on_axle = {"point": "trackrod_inboard", "side": "fl", "direction": {"axis": "y"}}
    for target, expected in (
        (on_axle | {"start": 5, "stop": 5}, [5.0] * 5),
        ({"quantity": "rack", "start": -5, "stop": 5}, np.linspace(-5, 5, 5)),
    ):
        r = car.run_sweep(load_sweep({"version": 1, "steps": 5, "targets": [*body, target]}))
        np.testing.assert_allclose(r["rack_displacement"], expected, rtol=0, atol=1e-9)


def test_a_vehicles_axle_files_are_its_inputs_and_must_be_axles(tmp_path, capsys):
    """-o never writes over an axle file the vehicle reads; a front or rear that is not
    an axle file, or is the other end's, says so; the CG's x_mm lies between the axles."""
    from pin_susp.cli import main

    for name in ("vehicle_fs.yaml", "vehicle/fs_front.yaml", "vehicle/fs_rear.yaml"):
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text((EXAMPLES / name).read_text())
    car, rear = tmp_path / "vehicle_fs.yaml", tmp_path / "vehicle" / "fs_rear.yaml"
    before = rear.read_text()
    sweep = str(EXAMPLES / "vehicle_roll.yaml")
    assert main(["sweep", str(car), sweep, "-o", str(rear)]) == 2
    assert "is an input of this command" in capsys.readouterr().err
    assert rear.read_text() == before
    data = yaml.safe_load(car.read_text())
    cases = (
        ({"front": str(EXAMPLES / "double_wishbone.yaml")}, "front", "not an axle file"),
        ({"rear": "vehicle/fs_front.yaml"}, "rear", "axle_position: front, not rear"),
        ({"vehicle_config": data["vehicle_config"] | {"cg": {"x_mm": 700, "z": 280}}},
         "vehicle_config.cg.x_mm", "not between the axles"),
    )  # fmt: skip
    for change, key, said in cases:
        with pytest.raises(InputError) as got:
            load_vehicle(data | change if "front" not in change else {**data, **change})
        assert got.value.key == key and said in got.value.problem, (key, got.value)


def test_a_long_sweep_keeps_its_tangents(car):
    """A sweep solved at once (bulk.py) keeps its tangents per target and each toe
    link's (Assembly.solve_steps, ``tangents_by_targets``): the drivers' tangents at the
    chassis frame from them (Vehicle.drive_tangents) are the drive solver's own, and
    every column is the one computed without them (label_motion and body_rates solving
    their own), to 1e-9 of its size."""
    steps = 201  # solved at once (bulk.MIN_STEPS)
    sweep = body_sweep(
        np.linspace(-10, 10, steps), np.linspace(-0.5, 0.5, steps), np.linspace(-2, 2, steps), 30
    )
    tangents = []
    solutions = car.solve_steps(sweep, tangents=tangents)
    assert len(tangents) == steps and all(t is not None for t in tangents)
    qs = [s.q for s in solutions]
    chassis = car.chassis_configurations(qs)
    drive = car.drive_tangents(qs, chassis, tangents)
    for i in (0, 100, 200):
        car._drive.evaluate(chassis[i])
        own = car._drive.tangent(car.drive_rhs)
        np.testing.assert_allclose(drive[i], own, rtol=0, atol=1e-9 * np.abs(own).max())
    kept = car.sweep_results(sweep, solutions, tangents)
    solved = car.sweep_results(sweep, solutions)  # no tangents: every one solved here
    assert set(kept.columns) == set(solved.columns)
    for name, values in solved.columns.items():
        if np.asarray(values).dtype.kind == "f":
            size = max(1.0, np.nanmax(np.abs(values), initial=0.0))
            np.testing.assert_allclose(
                kept[name], values, rtol=0, atol=1e-9 * size, equal_nan=True, err_msg=name
            )
