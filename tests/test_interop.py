"""Robotics interop: MJCF in MuJoCo and Pinocchio, URDF used without pin_susp, validate."""

import importlib.util
import sys

import mujoco
import numpy as np
import pinocchio as pin
import pytest
import yaml
from conftest import EXAMPLES, ROOT, example

import pin_susp
from pin_susp.cli import main
from pin_susp.model.mjcf import tree_to_mjcf

CASES = [
    ("double_wishbone.yaml", "bump_steer.yaml"),
    ("camber_shim.yaml", "bump_steer.yaml"),
    ("pushrod_rocker.yaml", "bump_steer.yaml"),
    ("fixed_toe_link.yaml", "bump.yaml"),
]


@pytest.mark.parametrize(("geometry", "sweep"), CASES, ids=[c[0][:-5] for c in CASES])
def test_validate_agrees_with_mujoco_and_the_pointwise_solver(geometry, sweep, capsys):
    assert main(["validate", str(EXAMPLES / geometry), str(EXAMPLES / sweep)]) == 0
    out = capsys.readouterr().out
    assert "mujoco: agrees within 1e-06" in out and "pointwise: agrees within 1e-06" in out


@pytest.mark.parametrize("geometry", [c[0] for c in CASES])
def test_mjcf_loads_in_mujoco_and_in_pinocchio(geometry, tmp_path):
    out = tmp_path / "corner.xml"
    assert main(["mjcf", str(EXAMPLES / geometry), "-o", str(out)]) == 0
    corner = pin_susp.Corner(EXAMPLES / geometry)
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    assert m.neq == len(corner.closures)
    assert d.nefc == 3 * len(corner.closures)
    assert np.max(np.abs(d.efc_pos[: d.nefc])) < 1e-15  # closed at the design state
    # a rod adds two hinges and turns one distance row into three: the mobility stays
    assert m.nv - 3 * m.neq == corner.mobility
    model, constraints, *_ = pin.buildModelAndConstraintsFromMJCF(str(out))
    assert model.nv == m.nv
    assert [type(c).__name__ for c in constraints] == ["PointAnchorConstraintModel"] * m.neq
    # every site of MuJoCo is where pin_susp has its point
    for name, p in corner.design_positions.items():
        if name != "contact_patch_center":
            site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)
            np.testing.assert_allclose(d.site_xpos[site], p, atol=1e-15)


def plain_script():
    spec = importlib.util.spec_from_file_location("plain", EXAMPLES / "urdf_without_pin_susp.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_urdf_round_trips_through_the_plain_script(tmp_path):
    urdf = tmp_path / "corner.urdf"
    assert (
        main(
            [
                "urdf",
                str(EXAMPLES / "pushrod_rocker.yaml"),
                "-o",
                str(urdf),
                "--at",
                f"{EXAMPLES / 'bump_steer.yaml'}:30",
            ]
        )
        == 0
    )
    source = (EXAMPLES / "urdf_without_pin_susp.py").read_text()
    assert "import pin_susp" not in source and "from pin_susp" not in source
    plain = plain_script()
    model, closures, lengths = plain.load(urdf)
    assert [(n, k) for n, k, _ in closures] == [
        ("upper_ball_joint", "ball"),
        ("trackrod", "distance"),
        ("pushrod", "distance"),
    ]
    # the sidecar's joint values put yourdfpy and Pinocchio on pin_susp's solved frames
    pose = yaml.safe_load(urdf.with_suffix(".pose.yaml").read_text())
    assert pose["step"] == 30
    corner = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    results = corner.run_sweep(EXAMPLES / "bump_steer.yaml")
    names = [n for n in corner.point_names if n != "contact_patch_center"]
    frames = plain.yourdfpy_frames(urdf, pose["joints"], names)
    q = np.array([pose["joints"][model.names[j]] for j in range(1, model.njoints)])
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    for name in names:
        ours = [results[f"{name}_{a}"][30] for a in "xyz"]
        np.testing.assert_allclose(frames[name] * 1e3, ours, atol=1e-9, err_msg=name)
        np.testing.assert_allclose(
            data.oMf[model.getFrameId(name)].translation * 1e3, ours, atol=1e-9
        )
    # and the plain script's own Newton solve lands on pin_susp's pose
    q = plain.solve_pose(model, closures, lengths, wheel_center_dz=0.02, rack=0.0)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    pose = corner.solve_pose(
        [pin_susp.Target("wheel_center", "z", 20.0), pin_susp.Target("trackrod_inboard", "y", 0.0)]
    )
    for name in names:
        np.testing.assert_allclose(
            data.oMf[model.getFrameId(name)].translation * 1e3, pose.points[name], atol=1e-9
        )


def test_plain_script_runs_on_the_committed_urdf(capsys):
    plain_script().main(ROOT / "urdf" / "double_wishbone.urdf")
    assert "2 loop closures" in capsys.readouterr().out


def test_validate_fails_when_a_hardpoint_moved_after_export(tmp_path, capsys):
    exported = tmp_path / "corner.xml"
    assert main(["mjcf", str(EXAMPLES / "double_wishbone.yaml"), "-o", str(exported)]) == 0
    moved = example("double_wishbone.yaml")
    moved["hardpoints"]["upper_wishbone_outboard"]["z"] += 2.0
    path = tmp_path / "moved.yaml"
    path.write_text(yaml.safe_dump(moved))
    code = main(["validate", str(path), str(EXAMPLES / "bump_steer.yaml"), "--mjcf", str(exported)])
    out = capsys.readouterr().out
    assert code == 1
    assert "mujoco: DISAGREES" in out and "camber" in out.split("mujoco: DISAGREES")[1]
    assert "pointwise: agrees" in out


def test_validate_without_mujoco_says_how_to_install_and_still_checks(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "mujoco", None)
    assert (
        main(["validate", str(EXAMPLES / "fixed_toe_link.yaml"), str(EXAMPLES / "bump.yaml")]) == 0
    )
    out = capsys.readouterr().out
    assert "pip install 'pin_susp[validate]'" in out and "pointwise: agrees" in out


def test_mjcf_of_a_pushrod_corner_has_rod_bodies():
    corner = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml")
    text = tree_to_mjcf(corner.tree)
    for name in ("trackrod_rod", "pushrod_rod", "rocker"):
        assert f'<body name="{name}"' in text


@pytest.mark.parametrize("name", sorted(p.stem for p in (ROOT / "urdf").glob("*.urdf")))
def test_plain_script_solves_every_mechanisms_urdf_as_pin_susp_does(name):
    """The URDF alone (no pin_susp) solves the pose that pin_susp solves: wheel centre
    20 mm up, rack at design where there is one."""
    plain = plain_script()
    model, closures, lengths = plain.load(ROOT / "urdf" / f"{name}.urdf")
    q = plain.solve_pose(model, closures, lengths, wheel_center_dz=0.02)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    corner = pin_susp.Corner(EXAMPLES / f"{name}.yaml")
    targets = [pin_susp.Target("wheel_center", "z", 20.0)]
    if corner.geometry.steering == "rack":
        targets.append(pin_susp.Target("trackrod_inboard", "y", 0.0))
    pose = corner.solve_pose(targets)
    for point in ("wheel_center", "axle_inboard", "axle_outboard"):
        theirs = data.oMf[model.getFrameId(point)].translation * 1e3
        np.testing.assert_allclose(theirs, pose.points[point], atol=1e-9, err_msg=point)
