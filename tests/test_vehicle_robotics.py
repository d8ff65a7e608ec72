"""The whole car's URDF and MJCF (docs/urdf.md, "A vehicle"), and `pin-susp validate` of a
vehicle (docs/vehicle.md): the body the root link, floating (Pinocchio's free-flyer,
Drake's floating base, MuJoCo's freejoint above the road's plane); the same points as
pin_susp's model at design and at a solved, posed step; MuJoCo and Drake placing the
body at each step's heave, pitch and roll and agreeing with pin_susp on every column.

Quick: each validation is a few steps of the example sweeps (`make drake` runs every
example sweep of both cars, every step, in tests/test_validate_drake.py).
"""

from __future__ import annotations

import io
import shutil
import subprocess
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pinocchio as pin
import pytest
import yaml
import yourdfpy
from conftest import EXAMPLES

from pin_susp.cli import main
from pin_susp.model.sweep import load_sweep
from pin_susp.model.tree import BodyPose
from pin_susp.subjects.vehicle import LABELS, Vehicle
from pin_susp.validate import validate
from pin_susp.validate.floating import OnRoad

NS = {"pin_susp": "https://github.com/pin-susp/pin_susp/urdf"}
CARS = {"fs": EXAMPLES / "vehicle_fs.yaml", "saloon": EXAMPLES / "vehicle_saloon.yaml"}
CHECK_URDF = shutil.which("check_urdf")
SOLVER = {"step_index", "solver_converged", "solver_max_residual", "solver_iterations"}


@pytest.fixture(scope="module", params=list(CARS))
def car(request):
    return request.param, Vehicle(CARS[request.param])


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> dict:
    """Each example car's URDF and MJCF as `pin-susp urdf` / `pin-susp mjcf` write them."""
    out = tmp_path_factory.mktemp("cars")
    texts = {}
    for name, path in CARS.items():
        for kind, suffix in (("urdf", "urdf"), ("mjcf", "xml")):
            target = out / f"{name}.{suffix}"
            assert main([kind, str(path), "-o", str(target)]) == 0
            texts[name, kind] = target.read_text()
    return texts


def short(name: str, steps: int = 3):
    """An example vehicle sweep, ``steps`` steps of it (its ends kept)."""
    data = yaml.safe_load((EXAMPLES / f"vehicle_{name}.yaml").read_text())
    data["steps"] = steps
    return load_sweep(data)


# --- the URDF --------------------------------------------------------------------------


def test_the_urdf_is_the_body_as_its_root_link(car, written):
    name, vehicle = car
    text = written[name, "urdf"]
    assert text == vehicle.export_urdf
    root = ET.fromstring(text)
    links = {el.get("name") for el in root.findall("link")}
    children = {el.find("child").get("link") for el in root.findall("joint")}
    assert links - children == {"chassis"}  # one root: the body
    assert not {"road", "body_heave", "body_pitch"} & links
    assert not {"body_heave", "body_pitch", "body_roll"} & {
        el.get("name") for el in root.findall("joint")
    }
    (base,) = root.findall("pin_susp:floating_base", NS)
    assert base.attrib == {"link": "chassis", "mass_link": "cg", "road_z": "0.0"}
    chassis = next(el for el in root.findall("link") if el.get("name") == "chassis")
    assert chassis.find("inertial") is None  # KDL: no inertia on the root
    cg = next(el for el in root.findall("link") if el.get("name") == "cg")
    assert float(cg.find("inertial/mass").get("value")) == vehicle.vehicle.masses["sprung"]
    corners = root.findall("pin_susp:corner", NS)
    assert [c.get("wheel_link").split("_")[0] for c in corners] == list(LABELS)
    assert len(root.findall("pin_susp:loop_closure", NS)) == len(vehicle.closures)


def test_yourdfpy_and_pinocchio_put_every_point_where_pin_susp_does_at_design(car, written):
    name, vehicle = car
    text = written[name, "urdf"]
    robot = yourdfpy.URDF.load(io.StringIO(text), build_scene_graph=True, load_meshes=False)
    assert robot.validate() and robot.base_link == "chassis"
    model = pin.buildModelFromXML(text, pin.JointModelFreeFlyer())
    assert model.names[1] == "root_joint" and model.nq == 7 + len(robot.actuated_joint_names)
    assert model.nq == vehicle.model.nq - 3 + 7  # the body's three joints → a free-flyer
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    for point, at in vehicle.design_positions.items():
        if point.endswith("contact_patch_center"):
            continue  # not a frame: the lowest point of the tyre disc
        pinocchio = data.oMf[model.getFrameId(point)].translation
        urdfpy = robot.get_transform(point, "chassis")[:3, 3]
        np.testing.assert_allclose(pinocchio, at, rtol=0, atol=1e-12, err_msg=point)
        np.testing.assert_allclose(urdfpy, at, rtol=0, atol=1e-12, err_msg=point)
    mass = sum(link.inertial.mass for link in robot.link_map.values() if link.inertial)
    assert pin.computeTotalMass(model) == pytest.approx(mass, rel=1e-12)


def test_pinocchios_free_flyer_at_the_bodys_pose_is_pin_susps_solved_step(car, written):
    """A solved step of a combined sweep (heave, pitch, roll, steer): the free-flyer
    placed at the body's pose and every joint at pin_susp's value put every point of the
    exported URDF where pin_susp's own model (road, three body joints) has it."""
    name, vehicle = car
    sweep = short("combined", 5)
    results = vehicle.run_sweep(sweep)
    i = 3
    q = results.meta["q"][i]
    own = vehicle.positions(q)
    model = pin.buildModelFromXML(written[name, "urdf"], pin.JointModelFreeFlyer())
    data = model.createData()
    pose = [q[vehicle.model.joints[vehicle.model.getJointId(j)].idx_q] for j in vehicle_joints()]
    assert min(map(abs, pose)) > 1e-3  # heave, pitch and roll all away from design
    rotation, translation = vehicle.body.placement(*pose)
    x = pin.neutral(model)
    x[:3] = translation
    x[3:7] = pin.Quaternion(rotation).coeffs()  # x y z w
    for j in range(2, model.njoints):
        theirs = vehicle.model.joints[vehicle.model.getJointId(model.names[j])]
        x[model.joints[j].idx_q] = q[theirs.idx_q]
    pin.framesForwardKinematics(model, data, x)
    for point, at in own.items():
        if not point.endswith("contact_patch_center"):
            where = data.oMf[model.getFrameId(point)].translation
            np.testing.assert_allclose(where, at, rtol=0, atol=1e-12, err_msg=point)


def vehicle_joints():
    from pin_susp.subjects.elements.body import JOINTS

    return JOINTS


def test_drake_parses_it_strictly_and_floats_the_body(car, written):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from pin_susp.validate import quiet_drake

    name, vehicle = car
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    parser.SetStrictParsing()
    with quiet_drake() as counter:
        parser.AddModels(file_contents=written[name, "urdf"], file_type="urdf")
    plant.Finalize()
    assert counter.count == 0
    (base,) = plant.GetFloatingBaseBodies()
    assert plant.get_body(base).name() == "chassis"
    assert plant.num_positions() == vehicle.model.nq - 3 + 7  # a quaternion floating joint
    model = pin.buildModelFromXML(written[name, "urdf"], pin.JointModelFreeFlyer())
    total = plant.CalcTotalMass(plant.CreateDefaultContext())
    assert total == pytest.approx(pin.computeTotalMass(model), rel=1e-12)


@pytest.mark.skipif(CHECK_URDF is None, reason="check_urdf (liburdfdom-tools) not installed")
def test_check_urdf_accepts_the_car(written, tmp_path):
    path = tmp_path / "car.urdf"
    path.write_text(written["fs", "urdf"])
    done = subprocess.run([CHECK_URDF, str(path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "root Link: chassis" in done.stdout


# --- the MJCF --------------------------------------------------------------------------


def test_the_mjcf_floats_the_body_above_the_road(car, written, tmp_path):
    name, vehicle = car
    text = written[name, "mjcf"]
    m = mujoco.MjModel.from_xml_string(text)
    road = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "road")
    assert road >= 0 and m.geom_type[road] == mujoco.mjtGeom.mjGEOM_PLANE
    assert m.geom_bodyid[road] == 0 and not np.any(m.geom_pos[road])  # the world's, z = 0
    free = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "body_free")
    assert m.jnt_type[free] == mujoco.mjtJoint.mjJNT_FREE
    chassis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "chassis")
    assert m.jnt_bodyid[free] == chassis and m.body_parentid[chassis] == 0
    assert m.body_mass[chassis] == vehicle.vehicle.masses["sprung"]
    np.testing.assert_allclose(m.body_ipos[chassis], vehicle.body.cg, atol=1e-15)
    assert m.neq == sum(1 for _ in vehicle.closures)  # each closure one connect
    tyres = [g for g in range(m.ngeom) if m.geom_contype[g] and g != road]
    assert len(tyres) == 4 and all(m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER for g in tyres)
    path = tmp_path / "car.xml"
    path.write_text(text)
    model = pin.buildModelFromMJCF(str(path))  # Pinocchio reads the freejoint as its root
    assert model.names[1] == "body_free" and model.nq == m.nq


def test_the_car_dropped_in_mujoco_comes_to_rest_on_its_four_tyres(written):
    """Gravity on, from its design pose: the FS car (springs without preload) sinks onto
    its springs and stands still on four contacts, level to a degree."""
    m = mujoco.MjModel.from_xml_string(written["fs", "mjcf"])
    d = mujoco.MjData(m)
    for _ in range(int(2.5 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    assert d.ncon == 4 and np.abs(d.qvel).max() < 1e-4
    assert -0.05 < d.qpos[2] < -0.005  # m: down on its springs
    w, x, y, z = d.qpos[3:7]
    assert abs(w) > np.cos(np.radians(1.0) / 2)  # within a degree of level


# --- validate --------------------------------------------------------------------------


@pytest.mark.parametrize("sweep", ["roll", "pitch"])
def test_every_engine_agrees_with_pin_susp_on_every_column(car, sweep):
    """The point-based engine (in the body's frame), MuJoCo (its freejoint set to the
    body's pose) and Drake (its floating base bounded there) on every column pin_susp
    writes but a rated spring's: every corner's, the body's and what the road sees, the
    rates along the hubs, the rack and the body; every point within 1e-9 mm."""
    name, vehicle = car
    results, reports = validate(vehicle, short(sweep), engines=("pointwise", "mujoco", "drake"))
    numbers = [c for c in results.columns if results[c].dtype.kind != "O"]  # not limit_exceeded
    written_ = {c for c in numbers if c not in SOLVER and not np.isnan(results[c]).all()}
    points = {f"{p}_{a}" for p in vehicle.output_points for a in "xyz"}
    springs = {c for c in written_ if c.startswith(("spring_force_", "wheel_rate_", "ride_rate_"))}
    for report in reports:
        assert report.agrees, (report.engine, report.disagree, report.failed_steps, report.note)
        assert report.warnings == 0
        compared = set(report.differences) | report.not_compared
        assert compared == written_ - points - springs | {"points"}, report.engine
        assert report.differences["points"] <= 1e-9
        for column in ("camber_to_ground_rr", "deriv_camber_wrt_roll_fl", "roll", "heave"):
            assert report.differences[column] <= 1e-9, (report.engine, column)
    mujoco_ = reports[1]
    assert mujoco_.not_compared == {
        f"isa_{m}_{c}" for m in ("caster", "kpi", "pitch") for c in ("rl", "rr")
    }


def test_the_contact_target_from_the_bodys_frame_has_its_gradient():
    """OnRoad (the point-based engine's contact row with the body placed): its gradient
    against central differences of its error."""
    vehicle = Vehicle(CARS["fs"])
    rotation, translation = vehicle.body.placement(0.01, np.radians(1.5), np.radians(-2.0))
    target = OnRoad("fl_", 0.3, BodyPose(rotation, translation), 0.004)
    p = {k: v.copy() for k, v in vehicle.design_positions.items()}
    p["fl_axle_outboard"] += [0.003, -0.002, 0.01]
    for name, gradient in target.gradient(p).items():
        h = 1e-6
        numeric = np.zeros(3)
        for a in range(3):
            up, down = {**p, name: p[name].copy()}, {**p, name: p[name].copy()}
            up[name][a] += h
            down[name][a] -= h
            numeric[a] = (target.error(up) - target.error(down)) / (2 * h)
        np.testing.assert_allclose(gradient, numeric, rtol=0, atol=1e-8, err_msg=name)


# --- the CLI ---------------------------------------------------------------------------


def one_error_line(capsys, argv) -> str:
    capsys.readouterr()
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1, err
    return err


def test_cli_validate_of_a_car_prints_its_columns_and_each_engines_verdict(tmp_path, capsys):
    sweep = tmp_path / "roll.yaml"
    data = yaml.safe_load((EXAMPLES / "vehicle_roll.yaml").read_text())
    sweep.write_text(yaml.safe_dump(data | {"steps": 3}))
    capsys.readouterr()
    code = main(["validate", str(CARS["fs"]), str(sweep), "--engine", "all"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert out.splitlines()[1].split()[-3:] == ["pointwise", "mujoco", "drake"]
    rows = {line.split()[0] for line in out.splitlines()[2:] if line.startswith("  ")}
    assert {"camber_fl", "camber_to_ground_rr", "wheelbase_left", "roll", "points"} <= rows
    assert {"deriv_camber_wrt_roll_fl", "contact_patch_road_z_rr"} <= rows
    assert "not compared (no engine computes them): spring_force_*, wheel_rate_*" in out
    for engine in ("pointwise", "mujoco", "drake"):
        assert f"{engine}: agrees within 1e-06" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["roll.yaml"]  # nothing written


def test_cli_validates_the_cars_written_files(written, tmp_path, capsys):
    """The URDF and MJCF given back with --urdf and --mjcf are checked and used."""
    urdf, mjcf = tmp_path / "car.urdf", tmp_path / "car.xml"
    urdf.write_text(written["fs", "urdf"])
    mjcf.write_text(written["fs", "mjcf"])
    sweep = tmp_path / "pitch.yaml"
    data = yaml.safe_load((EXAMPLES / "vehicle_pitch.yaml").read_text())
    sweep.write_text(yaml.safe_dump(data | {"steps": 2}))
    argv = ["validate", str(CARS["fs"]), str(sweep), "--engine", "all"]
    capsys.readouterr()
    assert main([*argv, "--urdf", str(urdf), "--mjcf", str(mjcf)]) == 0
    assert "drake: agrees" in capsys.readouterr().out
    corner = tmp_path / "corner.xml"
    assert main(["mjcf", str(EXAMPLES / "pushrod_rocker.yaml"), "-o", str(corner)]) == 0
    err = one_error_line(capsys, [*argv, "--mjcf", str(corner)])
    assert f"{corner}: is not the MJCF of this geometry (FS_car)" in err
    fixed = tmp_path / "fixed.xml"
    fixed.write_text(written["fs", "mjcf"].replace('<freejoint name="body_free" />', ""))
    err = one_error_line(capsys, [*argv, "--mjcf", str(fixed)])
    assert "missing joint body_free" in err


def test_cli_writes_the_cars_files_whole_and_refuses_bad_input_in_one_line(tmp_path, capsys):
    out = tmp_path / "car.urdf"
    out.write_text("an older file\n")
    assert main(["urdf", str(CARS["saloon"]), "-o", str(out)]) == 0
    assert out.read_text() == Vehicle(CARS["saloon"]).export_urdf
    assert sorted(p.name for p in tmp_path.iterdir()) == ["car.urdf"]  # no temporary left
    # a sprung mass that is no mass: one line naming the key, the old file untouched
    data = yaml.safe_load(CARS["fs"].read_text())
    data["vehicle_config"]["masses"]["sprung"] = -5
    for axle in ("front", "rear"):
        data[axle] = str(EXAMPLES / data[axle])
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    for kind, name in (("urdf", "car.urdf"), ("mjcf", "car.xml")):
        before = (tmp_path / name).read_text() if (tmp_path / name).exists() else None
        err = one_error_line(capsys, [kind, str(bad), "-o", str(tmp_path / name)])
        assert "vehicle_config.masses.sprung" in err and "-5" in err
        assert ((tmp_path / name).read_text() if (tmp_path / name).exists() else None) == before
    err = one_error_line(
        capsys, ["urdf", str(CARS["fs"]), "-o", str(out), "--at", "examples/vehicle_roll.yaml:2"]
    )
    assert "--at: not for a vehicle yet" in err
    sweep = tmp_path / "twice.yaml"
    twice = yaml.safe_load((EXAMPLES / "vehicle_roll.yaml").read_text())
    twice["targets"].append({"quantity": "roll", "start": 0, "stop": 0})
    sweep.write_text(yaml.safe_dump(twice))
    err = one_error_line(capsys, ["validate", str(CARS["fs"]), str(sweep)])
    assert "roll exactly once" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.yaml", "car.urdf", "twice.yaml"]
