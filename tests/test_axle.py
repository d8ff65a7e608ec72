"""The axle model (spec/axle.md): two corners composed on one chassis and one rack.

Checked against the corner model, solved on its own: a mirrored axle in pure
heave puts each side where the corner goes; in roll the left side is the
corner at +z and the right the mirrored corner at −z; the shared rack moves
both trackrods' inboard ends together.
"""

import numpy as np
import pytest
import yourdfpy
from conftest import example, mirrored

import pin_susp
from pin_susp.axle import AxleModel
from pin_susp.geometry import load_geometry

EXAMPLES = ["double_wishbone.yaml", "macpherson.yaml", "multilink_front.yaml"]


def corner_points(data, z, rack):
    corner = pin_susp.Corner(data)
    targets = [pin_susp.Target("wheel_center", "z", z)]
    if corner.geometry.steering == "rack":
        targets.append(pin_susp.Target("trackrod_inboard", "y", rack))
    return corner.solve_pose(targets).points


def axle(name):
    data = example(name)
    return data, AxleModel(load_geometry(data), load_geometry(mirrored(data)))


@pytest.mark.parametrize("name", EXAMPLES)
@pytest.mark.parametrize(("left_z", "right_z"), [(25.0, 25.0), (20.0, -20.0), (-15.0, 35.0)])
def test_each_side_of_a_mirrored_axle_is_the_corner_at_its_wheel_height(name, left_z, right_z):
    """Heave and roll alike: each side's points equal its corner's (the right side the
    mirrored corner's), the rack at the same travel on both."""
    data, model = axle(name)
    wc = {s: model.design_positions[f"{s}_wheel_center"][2] for s in ("left", "right")}
    rack = 4.0  # mm along +y: the left trackrod's end and the right one's move together
    solution = model.solve(
        {"left": wc["left"] + left_z * 1e-3, "right": wc["right"] + right_z * 1e-3}, rack * 1e-3
    )
    assert solution.converged and solution.max_residual <= 1e-12
    for side, z, corner in (("left", left_z, data), ("right", right_z, mirrored(data))):
        # the right corner's rack target is its trackrod end's y: the same +4 mm
        expected = corner_points(corner, z, rack)
        got = model.side_positions(solution.q, side)
        for point, p in expected.items():
            np.testing.assert_allclose(got[point] * 1e3, p, atol=1e-9, err_msg=f"{side} {point}")


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_axle_has_one_rack_and_each_corners_freedoms(name):
    data, model = axle(name)
    corner = pin_susp.Corner(data)
    rack = 1 if corner.geometry.steering == "rack" else 0
    assert model.mobility == 2 * (corner.mobility - rack) + rack  # bump per side + one rack
    names = [model.model.names[j] for j in range(1, model.model.njoints)]
    assert names.count("rack_slide") == rack
    assert all(n.startswith(("left_", "right_")) for n in names if n != "rack_slide")


@pytest.mark.parametrize("name", EXAMPLES)
def test_yourdfpy_reads_the_axle_urdf_and_agrees_with_pinocchio(tmp_path, name):
    data, model = axle(name)
    wc = {s: model.design_positions[f"{s}_wheel_center"][2] for s in ("left", "right")}
    q = model.solve({"left": wc["left"] + 0.02, "right": wc["right"] - 0.01}, 0.003).q
    path = tmp_path / "axle.urdf"
    path.write_text(model.urdf)
    robot = yourdfpy.URDF.load(str(path), load_meshes=False)
    m = model.model
    values = {m.names[j]: q[m.joints[j].idx_q] for j in range(1, m.njoints)}
    robot.update_cfg({j: values[j] for j in robot.actuated_joint_names})
    at = model.positions(q)
    for name in ("left_wheel_center", "right_wheel_center", "right_axle_inboard"):
        np.testing.assert_allclose(
            robot.get_transform(name, "chassis")[:3, 3], at[name], atol=1e-12
        )
