"""The generated URDF: loads in yourdfpy, agrees with Pinocchio, carries the closures."""

import io
import re
from pathlib import Path

import numpy as np
import pytest
import yourdfpy
from conftest import EXAMPLES, ROOT

import pin_susp
from pin_susp.model.urdf import read_closures

# corner files: a top-level hardpoints block (an axle file, scope: axle, has no corner
# URDF of its own yet; a study file's all_hardpoints is no geometry)
GEOMETRIES = sorted(
    p
    for p in EXAMPLES.glob("*.yaml")
    if re.search(r"^hardpoints:", p.read_text(), re.M) and "scope: axle" not in p.read_text()
)


def test_examples_exist():
    assert {p.name for p in GEOMETRIES} >= {"double_wishbone.yaml", "fixed_toe_link.yaml"}


@pytest.mark.parametrize("path", GEOMETRIES, ids=lambda p: p.stem)
def test_committed_urdf_is_up_to_date(path):
    committed = ROOT / "urdf" / f"{path.stem}.urdf"
    assert committed.exists(), f"missing {committed}: run `make urdf`"
    ours, theirs = committed.read_text(), pin_susp.Corner(path).urdf
    # Same text but for the last bits of solved numbers (a shimmed corner's points
    # come out of a solve, whose final digits may differ from one CPU to another).
    number = re.compile(r"-?\d+\.\d+(?:e-?\d+)?")
    assert number.sub("#", ours) == number.sub("#", theirs), f"stale {committed}: run `make urdf`"
    np.testing.assert_allclose(
        [float(x) for x in number.findall(ours)],
        [float(x) for x in number.findall(theirs)],
        rtol=0,
        atol=1e-12,
        err_msg=f"stale {committed}: run `make urdf`",
    )


def load_yourdfpy(text: str) -> yourdfpy.URDF:
    return yourdfpy.URDF.load(io.StringIO(text), build_scene_graph=True, load_meshes=False)


@pytest.mark.parametrize("path", GEOMETRIES, ids=lambda p: p.stem)
def test_yourdfpy_forward_kinematics_reproduces_pinocchio_at_a_solved_pose(path):
    corner = pin_susp.Corner(path)
    robot = load_yourdfpy(corner.urdf)
    assert robot.validate()
    targets = [pin_susp.Target("wheel_center", "z", 37.0)]
    if corner.geometry.steering == "rack":
        targets.append(pin_susp.Target("trackrod_inboard", "y", -6.0))
    pose = corner.solve_pose(targets)
    assert pose.converged
    # yourdfpy orders joints its own way: map by name.
    by_name = {
        corner.model.names[j]: pose.q[corner.model.joints[j].idx_q]
        for j in range(1, corner.model.njoints)
    }
    robot.update_cfg({name: by_name[name] for name in robot.actuated_joint_names})
    for name in corner.point_names[:-1]:  # every frame; the contact patch is not one
        p = robot.get_transform(name, "chassis")[:3, 3] * 1e3
        np.testing.assert_allclose(p, pose.points[name], atol=1e-9, err_msg=name)

    def world(link, xyz):
        return (robot.get_transform(link, "chassis") @ np.append(xyz, 1.0))[:3]

    for c in read_closures(corner.urdf):
        a, b = (world(link, xyz) for link, xyz in c.anchors)
        if c.kind == "ball":
            np.testing.assert_allclose(a * 1e3, b * 1e3, atol=1e-9)
        else:
            design = [corner.design_positions[link] for link, _ in c.anchors]
            assert np.linalg.norm(b - a) * 1e3 == pytest.approx(
                np.linalg.norm(design[1] - design[0]) * 1e3, abs=1e-9
            )


def test_every_hardpoint_is_a_link_and_closures_are_namespaced(corner):
    robot = load_yourdfpy(corner.urdf)
    for name in corner.geometry.hardpoints:
        assert name in robot.link_map
    kinds = {c.name: c.kind for c in read_closures(corner.urdf)}
    assert kinds == {"upper_ball_joint": "ball", "trackrod": "distance"}
    assert 'xmlns:pin_susp="' in corner.urdf


def test_tree_has_the_documented_joints(corner):
    joints = {
        corner.model.names[j]: corner.model.joints[j].shortname()
        for j in range(1, corner.model.njoints)
    }
    assert joints == {
        "lower_wishbone_pivot": "JointModelRevoluteUnaligned",
        "lower_ball_joint_z": "JointModelRZ",
        "lower_ball_joint_y": "JointModelRY",
        "lower_ball_joint_x": "JointModelRX",
        "upper_wishbone_pivot": "JointModelRevoluteUnaligned",
        "rack_slide": "JointModelPY",
    }
    assert corner.mobility == 2
    fixed = pin_susp.Corner(EXAMPLES / "fixed_toe_link.yaml")
    assert fixed.mobility == 1 and "rack_slide" not in list(fixed.model.names)


def test_urdf_is_in_metres_and_the_visuals_show_the_tyre(corner):
    robot = load_yourdfpy(corner.urdf)
    p = robot.get_transform("upper_wishbone_outboard", "chassis")[:3, 3]
    np.testing.assert_allclose(p, [-0.025, 0.75, 0.5], atol=1e-15)
    radii = [
        v.geometry.cylinder.radius
        for v in robot.link_map["upright"].visuals
        if v.geometry.cylinder is not None
    ]
    assert max(radii) == pytest.approx(0.3136)  # R = (13·25.4 + 2·0.55·270)/2 mm


def test_urdf_cli_writes_the_same_text(tmp_path: Path, corner):
    from pin_susp.cli import main

    out = tmp_path / "corner.urdf"
    assert main(["urdf", str(EXAMPLES / "double_wishbone.yaml"), "-o", str(out)]) == 0
    assert out.read_text() == corner.urdf
