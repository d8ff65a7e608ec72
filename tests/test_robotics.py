"""The URDF and MJCF as robotics tools take them: urdfdom's check_urdf, Pinocchio,
yourdfpy and Drake load every committed URDF; masses, joint limits and metadata follow
the documented rules (docs/urdf.md); the MJCF simulates, and a corner load settles in
MuJoCo where pin_susp's statics put it (examples/drop_test.py)."""

import copy
import importlib.util
import io
import itertools
import shutil
import subprocess
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from conftest import EXAMPLES, ROOT, example, mirrored, torsion_bar

import pin_susp
from pin_susp.cli import main
from pin_susp.model.mjcf import tree_to_mjcf

URDFS = sorted((ROOT / "urdf").glob("*.urdf"))
NS = {"pin_susp": "https://github.com/pin-susp/pin_susp/urdf"}
CHECK_URDF = shutil.which("check_urdf")
# the documented defaults (docs/urdf.md)
STEEL, TYRE = 7850.0, 150.0  # kg/m³
PLACEHOLDER = 1e-3  # kg
WHEEL_TRAVEL, RACK_TRAVEL, MARGIN = 0.1, 0.05, 1.5  # m, m, ×
FLOOR = {"revolute": np.radians(10.0), "prismatic": 0.01}


def corner_of(urdf_path) -> pin_susp.Corner:
    return pin_susp.Corner(EXAMPLES / f"{urdf_path.stem}.yaml")


def load_yourdfpy(text: str) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(io.StringIO(text), build_scene_graph=True, load_meshes=False)


def joint_values(corner, q) -> dict[str, float]:
    model = corner.model
    return {model.names[j]: q[model.joints[j].idx_q] for j in range(1, model.njoints)}


# --- the tools load it ------------------------------------------------------------------


def test_urdfs_are_committed():
    assert len(URDFS) >= 8


@pytest.mark.skipif(
    CHECK_URDF is None,
    reason="urdfdom's check_urdf is not installed (Debian package liburdfdom-tools)",
)
@pytest.mark.parametrize("path", URDFS, ids=lambda p: p.stem)
def test_check_urdf_accepts_every_committed_urdf(path):
    done = subprocess.run([CHECK_URDF, str(path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Successfully Parsed XML" in done.stdout
    assert "root Link: chassis" in done.stdout  # the root a robot_state_publisher sees
    assert "error" not in (done.stdout + done.stderr).lower()


@pytest.mark.parametrize("path", URDFS, ids=lambda p: p.stem)
def test_pinocchio_yourdfpy_and_drake_load_it_with_the_same_masses(path):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    text = path.read_text()
    model = pin.buildModelFromXML(text)
    robot = load_yourdfpy(text)
    assert robot.validate()
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    parser.SetStrictParsing()  # a warning is an error
    parser.AddModels(file_contents=text, file_type="urdf")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("chassis"))
    plant.Finalize()
    context = plant.CreateDefaultContext()
    assert plant.num_positions() == model.nq == len(robot.actuated_joint_names)
    mass = sum(link.inertial.mass for link in robot.link_map.values() if link.inertial)
    assert pin.computeTotalMass(model) == pytest.approx(mass, rel=1e-12)
    assert plant.CalcTotalMass(context) == pytest.approx(mass, rel=1e-12)
    assert mass > 5.0  # a wheel and its links, not grams
    for name in robot.actuated_joint_names:  # the limits as written, in each tool
        joint = plant.GetJointByName(name)
        j = model.joints[model.getJointId(name)]
        assert joint.position_upper_limits()[0] == model.upperPositionLimit[j.idx_q]
        assert joint.velocity_upper_limits()[0] == model.velocityLimit[j.idx_v] > 0.0
        assert model.effortLimit[j.idx_v] > 0.0


def test_the_root_is_the_chassis_without_inertia_and_joint_names_are_unique():
    """What robot_state_publisher (KDL) wants: one root, no inertia on it."""
    for path in URDFS:
        root = ET.fromstring(path.read_text())
        assert root.find("link[@name='chassis']/inertial") is None
        children = {j.find("child").get("link") for j in root.iter("joint")}
        links = [link.get("name") for link in root.iter("link")]
        assert [n for n in links if n not in children] == ["chassis"]
        names = [j.get("name") for j in root.iter("joint")]
        assert len(names) == len(set(names))


# --- masses --------------------------------------------------------------------------


def drawn_solids(link: yourdfpy.Link):
    """(mass, centre, inertia about it) of each drawn shape, link axes, from the visuals
    as yourdfpy parsed them: a cylinder of steel (the tyre of TYRE), a ball of steel."""
    for v in link.visuals:
        c, axis = v.origin[:3, 3], v.origin[:3, 2]  # a URDF cylinder lies along its z
        if v.geometry.sphere is not None:
            r = v.geometry.sphere.radius
            m = STEEL * 4 / 3 * np.pi * r**3
            yield m, c, 0.4 * m * r * r * np.eye(3)
        else:
            r, h = v.geometry.cylinder.radius, v.geometry.cylinder.length
            m = (TYRE if v.material.name == "tyre" else STEEL) * np.pi * r * r * h
            across, along = m * (3 * r * r + h * h) / 12, m * r * r / 2
            yield m, c, across * np.eye(3) + (along - across) * np.outer(axis, axis)


@pytest.mark.parametrize("path", URDFS, ids=lambda p: p.stem)
def test_each_inertial_is_the_drawn_shapes_as_solids(path):
    robot = load_yourdfpy(corner_of(path).urdf)  # as written now (the committed: test_urdf)
    moving = {j.child for j in robot.joint_map.values() if j.type != "fixed"}
    for name in moving:
        link = robot.link_map[name]
        inertial = link.inertial
        solids = list(drawn_solids(link))
        if not solids:  # a ball joint's inner links
            assert inertial.mass == PLACEHOLDER
            continue
        mass = sum(m for m, _, _ in solids)
        center = sum(m * c for m, c, _ in solids) / mass
        about = np.zeros((3, 3))
        for m, c, i in solids:
            about += i + m * (
                (c - center) @ (c - center) * np.eye(3) - np.outer(c - center, c - center)
            )
        assert inertial.mass == pytest.approx(mass, rel=1e-12), name
        np.testing.assert_allclose(inertial.origin[:3, 3], center, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(inertial.inertia, about, atol=1e-12 * np.abs(about).max())
        np.testing.assert_array_equal(inertial.origin[:3, :3], np.eye(3))
    for name in robot.link_map:
        if name not in moving and name != "chassis":  # points on fixed joints: frames
            assert robot.link_map[name].inertial is None, name


def test_config_inertia_sets_the_density_and_the_wheels_mass():
    def masses(geometry) -> dict[str, float]:
        robot = load_yourdfpy(pin_susp.Corner(geometry).urdf)
        return {n: link.inertial.mass for n, link in robot.link_map.items() if link.inertial}

    geometry = example("pushrod_rocker.yaml")
    base = masses(copy.deepcopy(geometry))
    tyre = TYRE * np.pi * 0.3136**2 * 0.27  # the 13-inch, 270 mm tyre's cylinder
    geometry["config"]["inertia"] = {"density": 2 * STEEL, "wheel_mass": 9.5}
    heavy = masses(geometry)
    for name in ("lower_wishbone", "upper_wishbone", "rocker", "rack"):
        assert heavy[name] == pytest.approx(2 * base[name], rel=1e-12)
    upright = base["upright"] - tyre  # the steel of the upright
    assert heavy["upright"] == pytest.approx(2 * upright + 9.5, rel=1e-12)
    assert heavy["lower_ball_joint_link_z"] == PLACEHOLDER


@pytest.mark.parametrize(
    ("key", "value", "problem"),
    [
        ("density", 0, "must be > 0, got 0"),
        ("density", 7.85e6, "7.85e+06 kg/m³ is beyond 30000 kg/m³: a unit slip?"),
        ("wheel_mass", "heavy", "expected a number, got text 'heavy'"),
        ("colour", 1, "unknown key (known keys here: density, wheel_mass)"),
    ],
)
def test_a_bad_config_inertia_is_one_error_line(tmp_path, capsys, key, value, problem):
    import yaml

    geometry = example("pushrod_rocker.yaml")
    geometry["config"]["inertia"] = {key: value}
    path = tmp_path / "corner.yaml"
    path.write_text(yaml.safe_dump(geometry))
    assert main(["urdf", str(path), "-o", str(tmp_path / "corner.urdf")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == f"pin-susp: error: {path}: config.inertia.{key}: {problem}\n"
    assert not (tmp_path / "corner.urdf").exists()


def test_a_study_variant_without_visuals_is_written_kinematic_with_the_same_joints():
    drawn = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    bare = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml", visuals=False)
    assert "<inertial>" in drawn.urdf and "<inertial>" not in bare.urdf
    for model in (drawn.model, bare.model):
        assert list(model.names) == list(drawn.model.names)
        np.testing.assert_array_equal(model.upperPositionLimit, drawn.model.upperPositionLimit)


# --- joint limits ----------------------------------------------------------------------


def rates_by_finite_differences(corner, h=1e-2) -> dict[str, np.ndarray]:
    """Each joint's d(value)/d(wheel-centre z) and d/d(rack) (per m) at design, from
    poses solved h mm either side."""
    rack = corner.geometry.steering == "rack"

    def q_at(z: float, r: float) -> np.ndarray:
        targets = [pin_susp.Target("wheel_center", "z", z)]
        if rack:
            targets.append(pin_susp.Target("trackrod_inboard", "y", r))
        pose = corner.solve_pose(targets)
        assert pose.converged
        return pose.q

    columns = [(q_at(h, 0.0) - q_at(-h, 0.0)) / (2 * h * 1e-3)]
    if rack:
        columns.append((q_at(0.0, h) - q_at(0.0, -h)) / (2 * h * 1e-3))
    return {
        name: np.array([c[i] for c in columns]) for i, name in enumerate(corner.model.names[1:])
    }


@pytest.mark.parametrize("path", URDFS, ids=lambda p: p.stem)
def test_joint_limits_follow_the_documented_rule(path):
    """± 1.5 × (|dq/dz|·100 mm + |dq/drack|·50 mm) + 10° (10 mm); the velocity limit
    likewise from 5 m/s and 0.5 m/s, + 1 rad/s (0.1 m/s)."""
    corner = corner_of(path)
    model = pin.buildModelFromXML(corner.urdf)
    for name, rate in rates_by_finite_differences(corner).items():
        j = model.joints[model.getJointId(name)]
        kind = "prismatic" if j.shortname().startswith("JointModelP") else "revolute"
        travel = np.array([WHEEL_TRAVEL, RACK_TRAVEL])[: len(rate)]
        speed = np.array([5.0, 0.5])[: len(rate)]
        reach = MARGIN * np.abs(rate) @ travel + FLOOR[kind]
        fast = MARGIN * np.abs(rate) @ speed + {"revolute": 1.0, "prismatic": 0.1}[kind]
        assert model.upperPositionLimit[j.idx_q] == pytest.approx(reach, rel=1e-6), name
        assert model.lowerPositionLimit[j.idx_q] == -model.upperPositionLimit[j.idx_q]
        assert model.velocityLimit[j.idx_v] == pytest.approx(fast, rel=1e-6), name
        assert model.effortLimit[j.idx_v] == 1e4


@pytest.mark.parametrize("path", URDFS, ids=lambda p: p.stem)
def test_every_pose_of_the_travel_envelope_is_within_the_limits(path):
    """Wheel centre ±100 mm, rack ±50 mm: every pose pin_susp can solve (the loops close)
    has every joint inside the URDF's limits — and the limits are far from ±π."""
    corner = corner_of(path)
    model = pin.buildModelFromXML(corner.urdf)
    upper = dict(zip(model.names[1:], model.upperPositionLimit, strict=True))
    rack = corner.geometry.steering == "rack"
    solved, grid = 0, 25 if rack else 5
    for z, r in itertools.product(
        np.linspace(-100, 100, 5), np.linspace(-50, 50, 5 if rack else 1)
    ):
        targets = [pin_susp.Target("wheel_center", "z", z)]
        if rack:
            targets.append(pin_susp.Target("trackrod_inboard", "y", r))
        pose = corner.solve_pose(targets)
        if not pose.converged:  # beyond the reach of this corner's loops
            continue
        solved += 1
        for name, value in joint_values(corner, pose.q).items():
            assert abs(value) < upper[name], (name, z, r, value, upper[name])
    assert solved >= 0.6 * grid
    assert max(upper.values()) < np.pi - 1.0


# --- metadata --------------------------------------------------------------------------


def test_side_tyre_spring_and_design_configuration_are_in_the_file():
    corner = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    root = ET.fromstring(corner.urdf)
    meta = root.find("pin_susp:corner", NS).attrib
    assert meta == {
        "mechanism": "double_wishbone",
        "side": "left",
        "wheel_link": "upright",
        "tyre_radius": "0.3136",  # (13·25.4 + 2·0.55·270)/2 mm
        "tyre_width": "0.27",
        "design": "as_drawn",
    }
    assert root.find("pin_susp:spring", NS).attrib == {
        "type": "coilover",
        "top": "strut_top",
        "bottom": "strut_bottom",
        "rate": "175000.0",  # 175 N/mm
        "preload": "2600.0",
        "damping": "3000.0",  # N·s/m, the default damper
    }
    design = {
        j.get("name"): float(j.get("value"))
        for j in root.findall("pin_susp:design_configuration/pin_susp:joint", NS)
    }
    assert design == dict.fromkeys(corner.model.names[1:], 0.0)
    right = pin_susp.Corner(mirrored(example("pushrod_rocker.yaml")))
    assert ET.fromstring(right.urdf).find("pin_susp:corner", NS).get("side") == "right"
    shimmed = ET.fromstring((ROOT / "urdf" / "camber_shim.urdf").read_text())
    assert shimmed.find("pin_susp:corner", NS).get("design") == "as_set"


# --- the MJCF --------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["pushrod_rocker", "macpherson", "multilink_rear"])
def test_mjcf_has_the_urdfs_masses_ranges_and_spring(name):
    corner = pin_susp.Corner(EXAMPLES / f"{name}.yaml")
    m = mujoco.MjModel.from_xml_string(tree_to_mjcf(corner.tree))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    robot = load_yourdfpy(corner.urdf)
    for link_name, link in robot.link_map.items():
        if link.inertial is None or link_name == "chassis":
            continue
        b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, link_name)
        assert m.body_mass[b] == pytest.approx(link.inertial.mass, rel=1e-12)
        np.testing.assert_allclose(m.body_ipos[b], link.inertial.origin[:3, 3], atol=1e-12)
        principal = np.linalg.eigvalsh(link.inertial.inertia)  # MuJoCo diagonalises it
        np.testing.assert_allclose(np.sort(m.body_inertia[b]), principal, rtol=1e-9, atol=1e-15)
    model = pin.buildModelFromXML(corner.urdf)
    for j in range(1, model.njoints):
        jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, model.names[j])
        upper = model.upperPositionLimit[model.joints[j].idx_q]
        np.testing.assert_array_equal(m.jnt_range[jid], [-upper, upper])
        assert m.jnt_limited[jid]
    np.testing.assert_array_equal(m.opt.gravity, [0.0, 0.0, -9.81])
    # the spring: the geometry's rate, and its preload at the design length
    rate, preload = corner.geometry.spring_rate, corner.geometry.spring_preload
    rate = 50.0 if rate is None else rate  # N/mm where the geometry gives none
    top, bottom = (corner.design_positions[f"strut_{e}"] for e in ("top", "bottom"))
    assert m.ntendon == 1 and m.tendon_stiffness[0] == rate * 1e3
    assert d.ten_length[0] == pytest.approx(np.linalg.norm(bottom - top), abs=1e-12)
    # its generalised force: the preload along d(length)/dq, from the two sites' Jacobians
    jac = {}
    for end in ("top", "bottom"):
        jac[end] = np.zeros((3, m.nv))
        site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"strut_{end}")
        mujoco.mj_jacSite(m, d, jac[end], None, site)
    along = (bottom - top) / np.linalg.norm(bottom - top)
    grows = along @ (jac["bottom"] - jac["top"])
    np.testing.assert_allclose(d.qfrc_spring, preload * grows, atol=1e-9 * (1 + preload))
    assert m.tendon_damping[0] > 0.0
    assert m.nu == (corner.geometry.steering == "rack")  # the steering holds the rack


def drop_test():
    spec = importlib.util.spec_from_file_location("drop_test", EXAMPLES / "drop_test.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize(
    ("geometry", "load", "travel"),
    [
        (EXAMPLES / "pushrod_rocker.yaml", 1500.0, 14.57),
        (EXAMPLES / "macpherson.yaml", 3000.0, 7.69),
        (torsion_bar(), 500.0, -4.41),
    ],
    ids=["pushrod coilover", "macpherson strut", "torsion bar"],
)
def test_a_corner_load_settles_in_mujoco_where_pin_susps_statics_put_it(geometry, load, travel):
    """The drop test: the chassis fixed, gravity off, the load up at the contact patch;
    MuJoCo's settled wheel travel is pin_susp's static solve's to 0.1 mm."""
    drop = drop_test()
    corner = pin_susp.Corner(geometry)
    ours = drop.static_travel(corner, load)
    assert ours == pytest.approx(travel, abs=0.01)  # well away from design: a real test
    theirs, time = drop.settle(corner, load)
    assert abs(theirs - ours) <= 0.1
    assert time < 5.0


def test_drop_test_prints_both_travels(capsys):
    drop_test().main([str(EXAMPLES / "pushrod_rocker.yaml"), "--load", "1500"])
    out = capsys.readouterr().out
    assert "pin_susp statics: wheel travel 14.57" in out and "MuJoCo (settled" in out
