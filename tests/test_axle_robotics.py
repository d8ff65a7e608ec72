"""An axle's URDF and MJCF carry what a corner's do: masses (axle_config.inertia), each
side's spring and <pin_susp:corner>; the tools load them, and MuJoCo settles an axle
under equal wheel loads where pin_susp's statics put each corner."""

import copy
import importlib.util
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
from conftest import EXAMPLES, example

import pin_susp
from pin_susp.cli import main
from pin_susp.model.mjcf import tree_to_mjcf
from pin_susp.subjects.axle import SIDES, AxleModel, load_axle

NS = {"pin_susp": "https://github.com/pin-susp/pin_susp/urdf"}
CHECK_URDF = shutil.which("check_urdf")
AXLE = EXAMPLES / "axle_front.yaml"
SETTLED = 1e-7  # m/s, rad/s
MAX_TIME = 10.0  # s


def drop_test():
    spec = importlib.util.spec_from_file_location("drop_test", EXAMPLES / "drop_test.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_yourdfpy(text: str) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(io.StringIO(text), build_scene_graph=True, load_meshes=False)


def axle_with(spring: dict) -> dict:
    """The example axle with another spring (a torsion bar drops the struts' points)."""
    data = example("axle_front.yaml")
    data["axle_config"]["spring"] = spring
    if spring["type"] != "coilover":
        for point in ("strut_top", "strut_bottom"):
            del data["hardpoints"]["left"][point]
    return data


# pushrod_rocker.yaml's spring, and test_robotics' torsion bar on the same rocker
COILOVER = {"type": "coilover", "rate": 175, "preload": 2600}  # N/mm, N
TORSION_BAR = {"type": "torsion_bar", "rate": 40, "preload": 150}  # N·m/deg, N·m


@pytest.fixture(scope="module")
def written(tmp_path_factory) -> dict[str, str]:
    """The example axle's URDF and MJCF as `pin-susp urdf` / `pin-susp mjcf` write them."""
    out = tmp_path_factory.mktemp("axle")
    texts = {}
    for kind in ("urdf", "mjcf"):
        path = out / f"axle.{kind}"
        assert main([kind, str(AXLE), "-o", str(path)]) == 0
        texts[kind] = path.read_text()
    return texts


# --- the URDF --------------------------------------------------------------------------


@pytest.mark.skipif(CHECK_URDF is None, reason="check_urdf (liburdfdom-tools) not installed")
def test_check_urdf_accepts_the_axle(written, tmp_path):
    path = tmp_path / "axle.urdf"
    path.write_text(written["urdf"])
    done = subprocess.run([CHECK_URDF, str(path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "root Link: chassis" in done.stdout
    assert "error" not in (done.stdout + done.stderr).lower()


def test_pinocchio_yourdfpy_and_drake_load_the_axle_with_the_same_masses(written):
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    text = written["urdf"]
    model = pin.buildModelFromXML(text)
    robot = load_yourdfpy(text)
    assert robot.validate()
    plant = MultibodyPlant(0.0)
    parser = Parser(plant)
    parser.SetStrictParsing()
    parser.AddModels(file_contents=text, file_type="urdf")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("chassis"))
    plant.Finalize()
    assert plant.num_positions() == model.nq == len(robot.actuated_joint_names)
    mass = sum(link.inertial.mass for link in robot.link_map.values() if link.inertial)
    assert pin.computeTotalMass(model) == pytest.approx(mass, rel=1e-12)
    assert plant.CalcTotalMass(plant.CreateDefaultContext()) == pytest.approx(mass, rel=1e-12)
    # both corners' moving links weigh what the corner's own URDF says they weigh
    corner = load_yourdfpy(pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml").urdf)
    for name, link in corner.link_map.items():
        if link.inertial is None or name == "rack":
            continue
        for side in SIDES:
            other = robot.link_map[f"{side}_{name}"].inertial.mass
            assert other == pytest.approx(link.inertial.mass, rel=1e-12), (side, name)


def test_two_corners_and_two_springs_in_the_urdf(written):
    root = ET.fromstring(written["urdf"])
    corners = [el.attrib for el in root.findall("pin_susp:corner", NS)]
    assert [c["side"] for c in corners] == ["left", "right"]
    for c in corners:
        assert c["mechanism"] == "double_wishbone"
        assert c["wheel_link"] == f"{c['side']}_upright"
        assert c["tyre_radius"] == "0.3136"  # (13·25.4 + 2·0.55·270)/2 mm
    springs = [el.attrib for el in root.findall("pin_susp:spring", NS)]
    # the example's spring: a coilover with no rate given and no preload
    assert springs == [
        {
            "side": side,
            "type": "coilover",
            "top": f"{side}_strut_top",
            "bottom": f"{side}_strut_bottom",
            "preload": "0.0",
            "damping": "3000.0",
        }
        for side in SIDES
    ]
    links = {el.get("name") for el in root.findall("link")}
    assert all(s[end] in links for s in springs for end in ("top", "bottom"))


def test_the_axles_spring_rate_and_preload_are_written_per_side():
    root = ET.fromstring(AxleModel(load_axle(axle_with(COILOVER))).urdf)
    for el in root.findall("pin_susp:spring", NS):
        assert (el.get("rate"), el.get("preload")) == ("175000.0", "2600.0")


def test_a_torsion_bar_axle_has_each_sides_bump_sense():
    """Each side's torsion bar is its rocker pivot, turned by bump as in that side's own
    corner (the right is the left mirrored: the opposite sense)."""
    axle = AxleModel(load_axle(axle_with(TORSION_BAR)))
    springs = ET.fromstring(axle.urdf).findall("pin_susp:spring", NS)
    assert [s.get("joint") for s in springs] == ["left_rocker_pivot", "right_rocker_pivot"]
    bumps = []
    for side, spring in zip(SIDES, springs, strict=True):
        corner = pin_susp.Corner(axle.geometries[side])
        own = ET.fromstring(corner.urdf).find("pin_susp:spring", NS).attrib
        assert {k: v for k, v in spring.attrib.items() if k not in ("side", "joint")} == {
            k: v for k, v in own.items() if k != "joint"
        }
        assert spring.get("rate") == repr(40 * 180 / np.pi)
        bumps.append(float(spring.get("bump")))
    assert bumps[0] == -bumps[1]
    # and in the MJCF: each side's pivot with its corner's stiffness and reference
    m = mujoco.MjModel.from_xml_string(tree_to_mjcf(axle.tree))
    for side in SIDES:
        corner = pin_susp.Corner(axle.geometries[side])
        c = mujoco.MjModel.from_xml_string(tree_to_mjcf(corner.tree))
        ours = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{side}_rocker_pivot")
        theirs = mujoco.mj_name2id(c, mujoco.mjtObj.mjOBJ_JOINT, "rocker_pivot")
        assert m.jnt_stiffness[ours] == c.jnt_stiffness[theirs] == pytest.approx(40 * 180 / np.pi)
        assert m.qpos_spring[m.jnt_qposadr[ours]] == c.qpos_spring[c.jnt_qposadr[theirs]] != 0.0
    assert m.ntendon == 0


def test_axle_config_inertia_sets_both_corners_masses():
    data = example("axle_front.yaml")
    data["axle_config"]["inertia"] = {"density": 2700.0, "wheel_mass": 12.5}
    axle = load_axle(data)
    for side in SIDES:
        assert (axle.corner(side).density, axle.corner(side).wheel_mass) == (2700.0, 12.5)
    robot = load_yourdfpy(AxleModel(axle).urdf)
    geometry = example("pushrod_rocker.yaml")
    geometry["config"]["inertia"] = {"density": 2700.0, "wheel_mass": 12.5}
    corner = load_yourdfpy(pin_susp.Corner(geometry).urdf)
    plain = load_yourdfpy(pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml").urdf)
    for name in ("upright", "lower_wishbone", "rocker"):
        mass = corner.link_map[name].inertial.mass
        assert mass != pytest.approx(plain.link_map[name].inertial.mass, rel=1e-3)
        for side in SIDES:
            assert robot.link_map[f"{side}_{name}"].inertial.mass == pytest.approx(mass, rel=1e-12)


def test_a_bad_axle_config_inertia_is_one_error_line(tmp_path, capsys):
    data = example("axle_front.yaml")
    data["axle_config"]["inertia"] = {"density": 0}
    path = tmp_path / "axle.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["urdf", str(path), "-o", str(tmp_path / "axle.urdf")]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err == f"pin-susp: error: {path}: axle_config.inertia.density: must be > 0, got 0\n"
    assert not (tmp_path / "axle.urdf").exists()


# --- the MJCF --------------------------------------------------------------------------


def test_the_axle_mjcf_has_a_spring_tendon_per_side(written):
    m = mujoco.MjModel.from_xml_string(written["mjcf"])
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    axle = AxleModel(load_axle(AXLE))
    corner = pin_susp.Corner(axle.geometries["left"])
    c = mujoco.MjModel.from_xml_string(tree_to_mjcf(corner.tree))
    assert m.ntendon == 2 and c.ntendon == 1
    for k, side in enumerate(SIDES):
        assert mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_TENDON, k) == f"{side}_spring"
        assert m.tendon_stiffness[k] == c.tendon_stiffness[0] == 50e3  # the default 50 N/mm
        assert m.tendon_damping[k] == c.tendon_damping[0] > 0.0
        top, bottom = (axle.design_positions[f"{side}_strut_{e}"] for e in ("top", "bottom"))
        assert d.ten_length[k] == pytest.approx(np.linalg.norm(bottom - top), abs=1e-12)
    np.testing.assert_array_equal(m.opt.gravity, [0.0, 0.0, -9.81])
    assert m.nu == 1  # the steering holds the rack


def settle_axle(axle: AxleModel, load: float) -> tuple[dict[str, float], float]:
    """MuJoCo's settled wheel travel per side (mm) with the same load up at both contact
    patches, gravity off, the chassis fixed, the rack held at design; and the time (s)."""
    drop = drop_test()
    m = mujoco.MjModel.from_xml_string(tree_to_mjcf(axle.tree))
    m.opt.gravity[:] = 0.0
    d = mujoco.MjData(m)
    sides = {}
    for side, g in axle.geometries.items():
        sites = {
            n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"{side}_{n}")
            for n in ("wheel_center", "axle_inboard", "axle_outboard")
        }
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{side}_{g.mechanism.WHEEL_BODY}")
        sides[side] = (sites, body, g.wheel.radius)
    mujoco.mj_forward(m, d)
    design = {s: d.site_xpos[sites["wheel_center"]][2] for s, (sites, _, _) in sides.items()}
    force = np.array([0.0, 0.0, load])
    for _ in range(round(MAX_TIME / m.opt.timestep)):
        mujoco.mj_step1(m, d)
        d.qfrc_applied[:] = 0.0
        for sites, body, radius in sides.values():
            point = drop.contact_patch(d, sites, radius)
            mujoco.mj_applyFT(m, d, force, np.zeros(3), point, body, d.qfrc_applied)
        mujoco.mj_step2(m, d)
        assert not d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number, "went unstable"
        if d.time > 0.1 and np.max(np.abs(d.qvel)) < SETTLED:
            break
    else:
        pytest.fail(f"not settled after {MAX_TIME:g} s")
    mujoco.mj_forward(m, d)
    travel = {
        s: (d.site_xpos[sites["wheel_center"]][2] - design[s]) * 1e3
        for s, (sites, _, _) in sides.items()
    }
    return travel, float(d.time)


def test_an_axle_under_equal_loads_settles_each_wheel_at_the_corners_static_travel():
    """The example axle with pushrod_rocker.yaml's spring (the example gives no rate):
    equal loads do not twist the anti-roll bar, so each wheel settles where pin_susp's
    statics put the axle's own left corner under that load, to 0.1 mm."""
    load = 1500.0  # N
    axle = AxleModel(load_axle(axle_with(copy.deepcopy(COILOVER))))
    left = axle.geometries["left"]
    assert (left.spring_rate, left.spring_preload) == (175.0, 2600.0)
    ours = drop_test().static_travel(pin_susp.Corner(left), load)
    assert ours == pytest.approx(14.57, abs=0.01)  # well away from design: a real test
    theirs, time = settle_axle(axle, load)
    for side in SIDES:
        assert abs(theirs[side] - ours) <= 0.1, (side, theirs[side], ours)
    assert time < 5.0
