"""Loads, setup and hardpoint sensitivities on a vehicle (docs/vehicle.md): per corner,
each written back into, or named by, its axle's file.

Checked against computations of their own:

- loads: each corner's member forces at a vehicle step against its axle's own loads
  (that axle file's AxleModel, a different model, solved at the same chassis-frame
  wheel-centre heights and rack under the same case) and, on a car without bars,
  against each corner's own (a Corner); a steady acceleration's case against the
  attitude: on a car without bars each spring's force at the attitude's equilibrium
  is the force its length gives there (preload + rate · compression), and on every
  car the body's heave force is the sprung mass's weight and inertia along the
  chassis's z (scipy's rotations), its pitch and roll torques nought under pure
  braking.
"""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation
from vehicles import axle_alone, body_sweep

import pin_susp
from pin_susp.analyses.attitude import Attitude
from pin_susp.analyses.load_case import (
    AccelerationCase,
    AxleLoadCase,
    CornersLoadCase,
    LoadCase,
    load_cases,
)
from pin_susp.analyses.loads import member_forces
from pin_susp.cli import main
from pin_susp.errors import InputError
from pin_susp.io.yamlio import load_yaml
from pin_susp.model.sweep import Sweep, Target
from pin_susp.subjects.axle import AxleModel
from pin_susp.subjects.vehicle import AXLES, LABELS, Vehicle

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FS = EXAMPLES / "vehicle_fs.yaml"
G = 9.80665
SIDE = {"fl": "left", "fr": "right", "rl": "left", "rr": "right"}
BAR_POINTS = ("droplink_rocker", "droplink_u_bar")


def axle_data(end: str) -> dict:
    return copy.deepcopy(load_yaml(EXAMPLES / "vehicle" / f"fs_{end}.yaml")[0])


def without_bars(tmp_path: Path) -> Path:
    """The example car with no anti-roll bars, its files written under tmp_path."""
    data = copy.deepcopy(load_yaml(FS)[0])
    for end in AXLES:
        axle = axle_data(end)
        axle["axle_config"]["anti_roll"] = {"type": "none"}
        for name in BAR_POINTS:
            del axle["hardpoints"]["left"][name]
        del axle["hardpoints"]["center"]
        (tmp_path / f"{end}.yaml").write_text(yaml.safe_dump(axle))
        data[end] = f"{end}.yaml"
    path = tmp_path / "car.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture(scope="module")
def fs():
    return Vehicle(FS)


@pytest.fixture(scope="module")
def bare(tmp_path_factory):
    return Vehicle(without_bars(tmp_path_factory.mktemp("bare")))


def random_case(seed: int) -> CornersLoadCase:
    """Loads on every wheel at once: a force at the contact patch and at the wheel
    centre and a moment, each its own."""
    rng = np.random.default_rng(seed)
    wheels = {
        label: LoadCase(
            "mixed",
            rng.normal(0.0, 700.0, 3) + [0.0, 0.0, 1500.0],
            rng.normal(0.0, 150.0, 3),
            rng.normal(0.0, 40.0, 3),
        )
        for label in LABELS
    }
    return CornersLoadCase("mixed", wheels)


SWEEP = body_sweep(np.linspace(-8, 8, 5), 0.6, np.linspace(-1.5, 1.5, 5), 20.0, {"rr": 3.0})
FORCES = ("force_", "load_", "torque_")


def forces_of(columns) -> list[str]:
    return [n for n in columns if n.startswith(FORCES) and n != "load_case"]


# ---------------------------------------------------------------- loads


def test_each_corners_forces_are_its_axles_own(fs):
    """Every member, joint and bar of each corner under a case on all four wheels at
    once, rolled, pitched, steered and warped, equals its axle's own loads (that axle
    file's model) at the same chassis-frame wheel heights and rack, to 1e-6 N."""
    case = random_case(1)
    forces = member_forces(fs, SWEEP, [case])
    assert forces["solver_converged"].all()
    compared = 0
    for end, (first, second) in AXLES.items():
        model, sweep = axle_alone(fs, end, forces)
        own = member_forces(
            model, sweep, [AxleLoadCase("mixed", case.wheel(first),
                                                            case.wheel(second))]
        )  # fmt: skip
        assert own["solver_converged"].all()
        for name in forces_of(own.columns):
            if name == "torque_arb":
                mine = f"torque_arb_{end}"
            elif name == "force_rack":
                mine = name
            else:
                stem, side = name.rsplit("_", 1)
                label = first if side == "left" else second
                mine = f"{stem.replace('load_arb_', f'load_{end}_arb_')}_{label}"
            np.testing.assert_allclose(
                forces[mine], own[name], rtol=0, atol=1e-6, err_msg=f"{mine} / {name}"
            )
            compared += 1
        assert np.abs(own["torque_arb"]).max() > 1.0  # the bar takes its share
    assert compared > 150


def test_without_bars_each_corner_is_a_corner_of_its_own(bare):
    """On a car without anti-roll bars each corner's forces are its own corner's (a
    Corner of its Geometry, solved at the same chassis-frame wheel-centre height and
    rack); the rear, on toe links, its toe link's."""
    case = random_case(2)
    forces = member_forces(bare, SWEEP, [case])
    for label in LABELS:
        g = bare.vehicle.corner(label)
        corner = pin_susp.Corner(g, warn=False)
        targets = [Target("wheel_center", "z", forces[f"{label}_wheel_center_z"], "absolute")]
        if g.steering == "rack":
            rack = forces[f"{label}_trackrod_inboard_y"]
            targets.append(Target("trackrod_inboard", "y", rack, "absolute"))
        own = member_forces(corner, Sweep(targets, "<own>"), [case.wheel(label)])
        names = [n for n in forces_of(own.columns) if n != "force_rack"]
        assert "force_spring" in names and len(names) > 30
        for name in names:
            np.testing.assert_allclose(
                forces[f"{name}_{label}"], own[name], rtol=0, atol=1e-6, err_msg=name
            )


def attitude_sweep(car, s: dict, i: int) -> Sweep:
    """The attitude's equilibrium ``i`` as a one-step sweep: its heave, pitch, roll and
    each contact patch's road height (the rack held at design, as the attitude's)."""
    u = s["u"][i]
    targets = [
        Target(None, None, [u[0] * 1e3], quantity="heave"),
        Target(None, None, [np.degrees(u[1])], quantity="pitch"),
        Target(None, None, [np.degrees(u[2])], quantity="roll"),
    ]
    targets += [
        Target(None, None, [u[3 + k] * 1e3], side=c, quantity="road_z")
        for k, c in enumerate(car.labels)
    ]
    return Sweep(targets, "<attitude>")


STEADY = [(0.0, 1.2), (-1.2, 0.0), (0.6, 0.9), (-0.8, -1.0)]  # g: ax, ay


def chassis_z(pitch_deg, roll_deg) -> np.ndarray:
    """The chassis's z axis in the road's frame (scipy: pitch about y, then roll)."""
    return Rotation.from_euler("YX", np.radians([pitch_deg, roll_deg])).apply([0.0, 0.0, 1.0])


def test_the_springs_hold_the_attitudes_accelerations_on_a_car_without_bars(bare):
    """A case {ax, ay} at the attitude's own equilibrium: with no bar each corner's
    spring alone holds its wheel, so its force must be the one its length gives there,
    the attitude's preload + rate · (design length − length), to 1e-6 N. The body's
    heave force is the sprung mass's weight and inertia, m·g·(ax, ay, 1), along the
    chassis's z."""
    att = Attitude(bare)
    ax, ay = np.array(STEADY).T
    s = att.equilibria(ax, ay)
    assert s["converged"].all()
    sprung = bare.vehicle.masses["sprung"]
    for i, (x, y) in enumerate(STEADY):
        f = member_forces(bare, attitude_sweep(bare, s, i), [AccelerationCase("a", x, y)])
        for k, c in enumerate(bare.labels):
            ends = [
                np.array([f[f"{c}_strut_{e}_{a}"][0] for a in "xyz"]) for e in ("top", "bottom")
            ]
            length = np.linalg.norm(ends[0] - ends[1]) * 1e-3
            spring = att.preload[k] + att.k[k] * (att.length0[k] - length)
            assert f[f"force_spring_{c}"][0] == pytest.approx(spring, abs=1e-6), (x, y, c)
            assert abs(spring - att.preload[k]) > 20.0 or (x, y) == (0.0, 0.0)
        weight = sprung * G * np.array([x, y, 1.0]) @ chassis_z(f["pitch"][0], f["roll"][0])
        assert f["force_body_heave"][0] == pytest.approx(weight, abs=1e-6)


def test_a_steady_acceleration_balances_the_body(fs):
    """On the example car (bars front and rear): at every step of a roll sweep the
    body's heave force under {ax, ay} is the sprung mass's m·g·(ax, ay, 1) along the
    chassis's z (the tyres' forces add up to the car's m·a, the unsprung masses take
    their own); under pure braking at its equilibrium (outboard brakes) the wheels put
    no pitch or roll torque on the body about its CG."""
    cases = [AccelerationCase(f"{x} {y}", x, y) for x, y in STEADY]
    roll = body_sweep(5.0, 0.4, np.linspace(-2.0, 2.0, 5))
    f = member_forces(fs, roll, cases)
    sprung = fs.vehicle.masses["sprung"]
    for x, y in STEADY:
        rows = f["load_case"] == f"{x} {y}"
        z = np.array([chassis_z(p, r) for p, r in zip(f["pitch"][rows], f["roll"][rows],
                                                        strict=True)])  # fmt: skip
        expected = sprung * G * z @ np.array([x, y, 1.0])
        np.testing.assert_allclose(f["force_body_heave"][rows], expected, rtol=0, atol=1e-6)
    att = Attitude(fs)
    s = att.equilibria(np.array([-1.2]), np.array([0.0]))
    braked = member_forces(fs, attitude_sweep(fs, s, 0), [AccelerationCase("brake", -1.2, 0)])
    assert abs(braked["pitch"][0]) > 0.5  # it dives
    for name in ("torque_body_pitch", "torque_body_roll"):
        assert abs(braked[name][0]) < 1e-6, name
    assert braked["force_spring_fl"][0] > 1.3 * braked["force_spring_rl"][0]  # weight forward


def test_a_vehicles_load_cases_name_its_corners(tmp_path):
    path = tmp_path / "cases.yaml"
    labels = LABELS
    path.write_text(
        "cases:\n  - {name: bump, fl: {contact_patch: {fx: 0, fy: 0, fz: 2000}}}\n"
        "  - {name: turn, ay: 1.2}\n"
    )
    bump, turn = load_cases(path, labels=labels, accelerations=True)
    assert list(bump.wheel("fl").contact_patch) == [0.0, 0.0, 2000.0]
    assert not bump.wheel("rr").contact_patch.any()
    assert (turn.ax, turn.ay) == (0.0, 1.2)
    for text, key, words in [
        ("cases: [{name: a, ax: 1}]", "cases[0].ax", "unknown key"),  # not on the road
        ("cases: [{name: a, left: {}}]", "cases[0].left", "known keys here: ax, ay,"),
        ("cases: [{name: a, contact_patch: {fx: 0, fy: 0, fz: 1}}]", "cases[0].contact_patch",
         "fl:, fr:, rl: and rr: blocks"),
        ("cases: [{name: a}]", "cases[0]", "fl:, fr:, rl: or rr: block"),
        ("cases: [{name: a, ax: 1, fl: {}}]", "cases[0].fl", "not both"),
        ("cases: [{name: a, ay: 40}]", "cases[0].ay", "beyond 10 g"),
    ]:  # fmt: skip
        path.write_text(text)
        with pytest.raises(InputError) as info:
            load_cases(path, labels=labels, accelerations=key != "cases[0].ax")
        assert info.value.key == key and words in info.value.problem, text
    with pytest.raises(InputError) as info:  # an axle's cases take no acceleration
        path.write_text("cases: [{name: a, ax: 1}]")
        load_cases(path, axle=True)
    assert info.value.key == "cases[0].ax"


def test_loads_of_a_vehicle_through_the_cli(tmp_path, capsys):
    """`pin-susp loads VEHICLE SWEEP --cases`: a row per step and case, every corner's
    forces and the body's; the summary leaves out what a case does not load."""
    out = tmp_path / "forces.csv"
    cases = EXAMPLES / "vehicle_loads.yaml"
    argv = ["loads", str(FS), str(EXAMPLES / "vehicle_roll.yaml"), "--cases", str(cases)]
    assert main([*argv, "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith(f"wrote {out}: 21 steps x 5 load cases\n")
    lines = [line for line in out.read_text().splitlines() if not line.startswith("#")]
    header = lines[0].split(",")
    for name in ("force_spring_fl", "force_toe_link_rr", "torque_arb_front", "force_body_heave",
                 "load_lower_ball_joint_z_rl", "camber_fl"):  # fmt: skip
        assert name in header, name
    assert len(lines) == 1 + 21 * 5
    bump = [line for line in printed.splitlines() if "3g bump fl" in line]
    assert any(line.split()[0] == "force_spring_fl" for line in bump)
    assert not any(line.split()[0].endswith(("_rl", "_rr")) for line in bump)
    # a steady acceleration needs the attitude's inputs
    data = copy.deepcopy(load_yaml(FS)[0])
    del data["vehicle_config"]["masses"]
    data["front"], data["rear"] = (str(EXAMPLES / "vehicle" / f"fs_{e}.yaml") for e in AXLES)
    car = tmp_path / "car.yaml"
    car.write_text(yaml.safe_dump(data))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["loads", str(car), *argv[2:], "-o", str(out)]) == 2
    assert "masses" in capsys.readouterr().err
    # --plot draws the force report, every corner's members
    assert main([*argv, "-o", str(out), "--plot", str(tmp_path / "f.png")]) == 0
    assert "wrote" in capsys.readouterr().out and (tmp_path / "f.png").stat().st_size > 0


# ---------------------------------------------------------------- setup


def with_own_right(tmp_path: Path, inline: bool = False) -> Path:
    """The example car with its front axle's right corner drawn on its own (the left
    mirrored) and each front corner given its own setup; the rear as it is (mirrored,
    a left_setup of its own). ``inline``: the front axle inside the vehicle file."""
    data = copy.deepcopy(load_yaml(FS)[0])
    front = axle_data("front")
    left = front["hardpoints"]["left"]
    front["hardpoints"]["right"] = {k: {**p, "y": -p["y"]} for k, p in left.items()}
    front["axle_config"]["left_setup"] = {"pushrod_length_delta": 1.5}
    front["axle_config"]["right_setup"] = {"trackrod_length_delta": 0.4}
    rear = axle_data("rear")
    rear["axle_config"]["left_setup"] = {"trackrod_length_delta": -0.3}
    (tmp_path / "rear.yaml").write_text(yaml.safe_dump(rear))
    data["rear"] = "rear.yaml"
    if inline:
        data["front"] = front
    else:
        (tmp_path / "front.yaml").write_text(yaml.safe_dump(front))
        data["front"] = "front.yaml"
    path = tmp_path / ("inline.yaml" if inline else "car.yaml")
    path.write_text(yaml.safe_dump(data))
    return path


def axle_static(path) -> dict:
    """An axle file re-loaded and solved at its design state (each wheel centre and the
    rack held where they are): its columns."""
    from pin_susp.subjects.axle import load_axle

    model = AxleModel(load_axle(path))
    targets = [
        Target("wheel_center", "z", [0.0], "relative", side=side) for side in ("left", "right")
    ]
    if model.model.existJointName("rack_slide"):
        targets.append(Target("trackrod_inboard", "y", [0.0], "relative", side="left"))
    results = model.run_sweep(Sweep(targets, "<design>"))
    assert results["solver_converged"].all()
    return results


def test_each_corners_setup_sheet_is_its_axles_own(tmp_path):
    """The vehicle's sheet per corner (as set, then each listed value, with the exact
    sensitivities) equals that corner's axle's own sheet for its side; each axle's
    static columns (track, roll centre) equal that axle's own in every row."""
    from pin_susp.analyses.setup import axle_setup_sheet, static_state, subject_setup_sheet
    from pin_susp.subjects.axle import load_axle
    from pin_susp.subjects.subject import load_drawn

    path = with_own_right(tmp_path)
    car = load_drawn(path)
    lists = ([], [-1.0, 0.5], [2.0])
    sheets = subject_setup_sheet(car, *lists)
    for end, (first, second) in AXLES.items():
        axle_path = tmp_path / f"{end}.yaml"
        own = axle_setup_sheet(load_axle(axle_path), *lists)
        for label, side in ((first, "left"), (second, "right")):
            assert len(sheets[label]) == len(own[side]) == 4
            for got, want in zip(sheets[label], own[side], strict=True):
                np.testing.assert_array_equal(got.setup, want.setup)
                for name, value in want.metrics.items():
                    assert got.metrics[name] == value, (label, name)
                    np.testing.assert_array_equal(got.derivatives[name], want.derivatives[name])
        axle = load_drawn(axle_path)
        for i in range(4):
            mine = static_state(car, {c: sheets[c][i] for c in LABELS})
            theirs = static_state(axle, {s: own[s][i] for s in ("left", "right")})
            for name in ("track", "roll_center_y", "roll_center_z"):
                assert mine[f"{name}_{end}"] == pytest.approx(theirs[name], abs=1e-9)
    # the setups the files give: the front's each its own, the rear's mirrored
    assert sheets["fl"][0].setup[2] == pytest.approx(1.5) and sheets["fr"][0].setup[1] == 0.4
    assert sheets["rl"][0].setup[1] == sheets["rr"][0].setup[1] == pytest.approx(-0.3)
    assert sheets["fl"][1].metrics["roadwheel_angle"] != sheets["fl"][2].metrics["roadwheel_angle"]


def test_a_solved_setup_is_written_into_its_axles_file(tmp_path, capsys):
    """--side fr --toe 0.2 --ride-height-change 2: the fr corner's own trackrod and
    pushrod, written into the front axle's right_setup in an axle file beside the
    vehicle file (which names it; the rear still the file it was); the front axle
    re-loaded from it and solved has the fr corner at its targets, the fl one as it
    was. --side rear sets both rear corners (a mirrored axle: its left_setup)."""
    path = with_own_right(tmp_path)
    out = tmp_path / "out" / "set.yaml"
    out.parent.mkdir()
    argv = ["setup", str(path), "--side", "fr", "--toe", "0.2", "--ride-height-change", "2"]
    assert main([*argv, "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"  fl corner ({tmp_path / 'front.yaml'}: axle_config.left_setup; not set: " in printed
    assert f"  fr corner ({tmp_path / 'front.yaml'}: axle_config.right_setup):" in printed
    assert f"wrote {out}\nwrote {out.parent / 'set_front.yaml'}\n" in printed
    written = yaml.safe_load(out.read_text())
    assert written["front"] == "set_front.yaml" and written["rear"] == "../rear.yaml"
    front = yaml.safe_load((out.parent / "set_front.yaml").read_text())
    given = yaml.safe_load((tmp_path / "front.yaml").read_text())["axle_config"]
    assert front["axle_config"]["left_setup"] == given["left_setup"]
    assert set(front["axle_config"]["right_setup"]) == {"trackrod_length_delta",
                                                        "pushrod_length_delta"}  # fmt: skip
    before, after = axle_static(tmp_path / "front.yaml"), axle_static(out.parent / "set_front.yaml")
    assert after["roadwheel_angle_right"][0] == pytest.approx(0.2, abs=1e-9)
    for name in ("camber_left", "roadwheel_angle_left", "left_contact_patch_center_z"):
        assert after[name][0] == pytest.approx(before[name][0], abs=1e-12), name
    # ride height: the right contact patch 2 mm lower than drawn (no setup at all)
    drawn = copy.deepcopy(front)
    del drawn["axle_config"]["left_setup"], drawn["axle_config"]["right_setup"]
    (tmp_path / "drawn.yaml").write_text(yaml.safe_dump(drawn))
    rise = axle_static(tmp_path / "drawn.yaml")["right_contact_patch_center_z"][0]
    assert rise - after["right_contact_patch_center_z"][0] == pytest.approx(2.0, abs=1e-9)
    Vehicle(out)  # the written car reads
    # one axle of a vehicle: both its corners, a mirrored axle's left_setup
    argv = ["setup", str(path), "--side", "rear", "--toe", "-0.1"]
    assert main([*argv, "-o", str(tmp_path / "rear_set.yaml")]) == 0
    rear = yaml.safe_load((tmp_path / "rear_set_rear.yaml").read_text())["axle_config"]
    assert "right_setup" not in rear
    after = axle_static(tmp_path / "rear_set_rear.yaml")
    for side in ("left", "right"):
        assert after[f"roadwheel_angle_{side}"][0] == pytest.approx(-0.1, abs=1e-9)
    assert yaml.safe_load((tmp_path / "rear_set.yaml").read_text())["front"] == "front.yaml"


def test_an_inline_axles_setup_is_the_vehicle_files(tmp_path, capsys):
    """An axle inside the vehicle file: its corners' setup named and written there,
    under front.axle_config; its errors too."""
    path = with_own_right(tmp_path, inline=True)
    out = tmp_path / "set.yaml"
    assert main(["setup", str(path), "--side", "fl", "--toe", "0.15", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"  fl corner ({path}: front.axle_config.left_setup):" in printed
    assert f"wrote {out}\n" in printed and not (tmp_path / "set_front.yaml").exists()
    written = yaml.safe_load(out.read_text())
    assert written["front"]["axle_config"]["right_setup"] == {"trackrod_length_delta": 0.4}
    assert "trackrod_length_delta" in written["front"]["axle_config"]["left_setup"]
    (tmp_path / "front_set.yaml").write_text(yaml.safe_dump(written["front"]))
    assert axle_static(tmp_path / "front_set.yaml")["roadwheel_angle_left"][0] == pytest.approx(
        0.15, abs=1e-9
    )
    assert main(["setup", str(path), "--camber", "-2"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pin-susp: error: {path}: front.axle_config.left_setup.camber_shim: "
                          "fl corner: a camber target needs a camber shim")  # fmt: skip


def test_bad_vehicle_setup_input_names_the_axle_file(capsys, tmp_path):
    """A mirrored axle's corner alone is refused, naming that axle's file; a side no
    vehicle has; a corner's setup error names its axle file and key."""
    front = EXAMPLES / "vehicle" / "fs_front.yaml"
    assert main(["setup", str(FS), "--side", "fr", "--toe", "0"]) == 2
    err = capsys.readouterr().err
    assert f"the front axle ({front}) is mirrored" in err and "give --side front" in err
    assert main(["setup", str(FS), "--side", "left"]) == 2
    assert "unknown side 'left' (a vehicle's corner, fl, fr, rl or rr" in capsys.readouterr().err
    assert main(["setup", str(FS), "--camber", "-2"]) == 2
    err = capsys.readouterr().err
    assert f"{front}: axle_config.left_setup.camber_shim: fl corner: " in err
    out = tmp_path / "x.yaml"
    assert main(["setup", str(FS), "--toe", "0.1", "-o", str(EXAMPLES / "vehicle" / "fs")]) == 2
    assert "would be written over an input" in capsys.readouterr().err
    assert not out.exists()


# ---------------------------------------------------------------- sensitivities

# Central differences of re-solved vehicles, h = 0.01 mm (the axle's, test_axle_setup.py:
# truncation below 1e-8, each re-solve's residual under 1e-9 mm); tolerance 1e-6
# (relative) + 1e-7 (absolute, per mm).
H = 0.01
STEP = dict(heave=6.0, pitch=0.5, roll=1.5, steer=20.0, roads={"rr": 3.0})  # one step


def car_files(tmp_path: Path, right: bool = False) -> dict:
    """The example car's vehicle and axle files as dicts (``right``: each axle's right
    corner drawn on its own, the left mirrored)."""
    data = {"car": copy.deepcopy(load_yaml(FS)[0])}
    for end in AXLES:
        axle = axle_data(end)
        if right:
            left = axle["hardpoints"]["left"]
            axle["hardpoints"]["right"] = {k: {**p, "y": -p["y"]} for k, p in left.items()}
        data[end] = axle
    return data


def build(tmp_path: Path, files: dict, name: str = "car") -> Vehicle:
    folder = tmp_path / name
    folder.mkdir(exist_ok=True)
    car = copy.deepcopy(files["car"])
    for end in AXLES:
        (folder / f"{end}.yaml").write_text(yaml.safe_dump(files[end]))
        car[end] = f"{end}.yaml"
    (folder / "car.yaml").write_text(yaml.safe_dump(car))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Vehicle(folder / "car.yaml")


def held(car: Vehicle, travel: dict, steer: float):
    """The car's columns with each corner's chassis-frame wheel travel and the rack as
    given — what the sensitivities hold: the body at zero (its chassis frame the
    road's), each road height found so that its wheel centre is where it is wanted."""
    road = dict(travel)
    design = {c: car.design_positions[f"{c}_wheel_center"][2] * 1e3 for c in LABELS}
    slope = dict.fromkeys(LABELS, 1.0)
    last = None
    for _ in range(12):
        sweep = body_sweep(0.0, 0.0, 0.0, steer, road)
        (solution,) = car.solve_steps(sweep)
        assert solution.converged
        at = car.positions(solution.q)
        got = {c: at[f"{c}_wheel_center"][2] * 1e3 - design[c] for c in LABELS}
        miss = {c: travel[c] - got[c] for c in LABELS}
        if max(abs(m) for m in miss.values()) < 1e-11:
            break
        if last is not None:  # the secant's slope per corner
            for c in LABELS:
                if abs(road[c] - last[0][c]) > 1e-14:
                    slope[c] = (got[c] - last[1][c]) / (road[c] - last[0][c])
        last = (dict(road), got)
        road = {c: road[c] + miss[c] / slope[c] for c in LABELS}
    else:
        raise AssertionError(f"the wheel travels were not reached: {miss}")
    return car.sweep_results(sweep, [solution])


def moved(files: dict, end: str, side: str, point: str, axis: str, h: float, mirror: bool):
    out = copy.deepcopy(files)
    points = out[end]["hardpoints"]
    points[side][point][axis] += h
    if mirror and "right" in points:
        points["right"][point][axis] += -h if axis == "y" else h
    return out


def central(tmp_path, files, end, side, point, axis, columns, travel, steer, mirror=True):
    got = []
    for h in (H, -H):
        car = build(tmp_path, moved(files, end, side, point, axis, h, mirror), f"m{h}")
        results = held(car, travel, steer)
        got.append({c: results[c][0] for c in columns})
    return {c: (got[0][c] - got[1][c]) / (2 * H) for c in columns}


SENSITIVE = ("camber_fl", "roadwheel_angle_rl", "deriv_camber_wrt_hub_z_fr", "caster_rr",
             "roll_center_z_front", "track_rear", "deriv_roll_center_z_wrt_axle_roll_front",
             "body_roll_rear", "pitch_center_x", "pitch_center_z", "anti_dive_front",
             "anti_lift_rear", "anti_squat_rear", "roll_axis_height_at_cg",
             "roll_axis_inclination")  # fmt: skip
MIRRORED = [
    ("front", "upper_wishbone_outboard", "z"),
    ("front", "lower_wishbone_inboard_rear", "z"),
    ("front", "trackrod_inboard", "z"),
    ("rear", "lower_wishbone_inboard_front", "z"),
    ("rear", "toe_link_outboard", "y"),
    ("rear", "axle_outboard", "z"),
]


def step_and_sensitivity(car: Vehicle, one_sided: bool = False):
    from pin_susp.analyses.sensitivity import SubjectSensitivity, subject_sensitivities

    sweep = body_sweep(STEP["heave"], STEP["pitch"], STEP["roll"], STEP["steer"], STEP["roads"])
    results = car.run_sweep(sweep)
    (s,), _ = subject_sensitivities(SubjectSensitivity(car, one_sided), sweep)
    travel = {c: results[f"wheel_travel_{c}"][0] for c in LABELS}
    return results, s, travel


def test_mirrored_sensitivities_match_central_differences_of_re_solved_cars(tmp_path):
    """At a rolled, pitched, steered and warped step, each hardpoint moved on both
    corners of its axle (the right mirrored): the corners', the axles' and the car's
    columns against re-solved cars with the point moved, each wheel centre's
    chassis-frame travel and the rack held. The held car's columns equal the step's
    (what is held is all they depend on)."""
    files = car_files(tmp_path)
    car = build(tmp_path, files)
    results, s, travel = step_and_sensitivity(car)
    again = held(car, travel, STEP["steer"])
    for column in SENSITIVE:
        assert s.metrics[column] == pytest.approx(results[column][0], abs=1e-9), column
        assert again[column][0] == pytest.approx(results[column][0], abs=1e-9), column
    assert list(s.values)[-len(car.sensitivity_columns) :] == list(car.sensitivity_columns)
    assert s.hardpoints[0].startswith("front_") and s.hardpoints[-1].startswith("rear_")
    for end, point, axis in MIRRORED:
        expected = central(tmp_path, files, end, "left", point, axis, SENSITIVE, travel,
                           STEP["steer"])  # fmt: skip
        row = s.hardpoints.index(f"{end}_{point}"), "xyz".index(axis)
        for column in SENSITIVE:
            exact = s.values[column][row]
            assert exact == pytest.approx(expected[column], rel=1e-6, abs=1e-7), (
                point, axis, column,
            )  # fmt: skip
    assert abs(s.values["pitch_center_z"][s.hardpoints.index("front_lower_wishbone_inboard_rear"),
                                          2]) > 1.0  # fmt: skip


def test_one_corners_sensitivities_match_central_differences(tmp_path):
    """--one-sided on a car whose axles draw their right corners: fl_P moves the fl
    corner's alone (the fr's columns do not move), against re-solved cars with the left
    point moved alone."""
    files = car_files(tmp_path, right=True)
    car = build(tmp_path, files)
    results, s, travel = step_and_sensitivity(car, one_sided=True)
    assert s.hardpoints[0].startswith("fl_") and s.hardpoints[-1].startswith("rr_")
    columns = ("camber_fl", "camber_fr", "roll_center_z_front", "pitch_center_z",
               "anti_dive_front", "body_roll_front")  # fmt: skip
    for end, side, point, axis in (("front", "left", "upper_wishbone_inboard_front", "z"),
                                   ("rear", "right", "lower_wishbone_outboard", "y")):  # fmt: skip
        expected = central(tmp_path, files, end, side, point, axis, columns, travel,
                           STEP["steer"], mirror=False)  # fmt: skip
        label = AXLES[end][0 if side == "left" else 1]
        row = s.hardpoints.index(f"{label}_{point}"), "xyz".index(axis)
        for column in columns:
            assert s.values[column][row] == pytest.approx(expected[column], rel=1e-6, abs=1e-7), (
                label, column,
            )  # fmt: skip
    row = s.hardpoints.index("fl_upper_wishbone_inboard_front"), 2
    assert s.values["camber_fr"][row] == 0.0 and s.values["camber_fl"][row] != 0.0


def test_vehicle_sensitivity_through_the_cli(tmp_path, capsys):
    out = tmp_path / "sens.csv"
    sweep = str(EXAMPLES / "vehicle_roll.yaml")
    assert main(["sensitivity", str(FS), "--sweep", sweep, "-o", str(out), "--top", "1"]) == 0
    printed = capsys.readouterr().out
    assert "a mirrored move per axle: hardpoint front_P" in printed
    for heading in ("  the front axle:", "  the rear axle:", "  the car:",
                    "  the fl corner (columns suffixed _fl):",
                    "  the fr corner's columns mirror the fl's (a mirrored axle)"):  # fmt: skip
        assert heading in printed, heading
    assert "  pitch_center_z = " in printed and "  anti_dive_front = " in printed
    lines = out.read_text().splitlines()
    assert any(line.startswith("# hardpoint: a mirrored move per axle") for line in lines)
    rows = [line for line in lines if line.startswith("20,anti_squat_rear,rear_")]
    assert len(rows) == 3 * len({r.split(",")[2] for r in rows}) > 30
    assert main(["sensitivity", str(FS), "--points", "fl_upper_wishbone_outboard"]) == 2
    assert "side-prefixed names" in capsys.readouterr().err
    assert main(["sensitivity", str(FS), "--points", "toe_link_inboard", "-q"]) == 0
