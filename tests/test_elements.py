"""The shared elements, one module each (pin_susp/elements/), and the composition of
labelled corners' trees (compose.py): what each adds to the axle's tree and results."""

from pathlib import Path

import numpy as np

from pin_susp.model.compose import SHARED, compose_tree, prefixed
from pin_susp.model.geometry import load_geometry
from pin_susp.subjects.axle import AxleModel, axle_tree, load_axle
from pin_susp.subjects.elements import elements_of, rack
from pin_susp.subjects.elements.anti_roll_bar import AntiRollBar
from pin_susp.subjects.elements.heave_link import HeaveLink

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def test_a_corners_own_label_leaves_its_tree_as_it_is():
    g = load_geometry(EXAMPLES / "double_wishbone.yaml")
    tree = g.mechanism.tree(g)
    assert prefixed(tree, "") is tree
    left = prefixed(tree, "left")
    assert set(left.points) == {f"left_{n}" for n in tree.points}
    assert [b.name for b in left.bodies if b.name in SHARED] == ["chassis", "rack"]


def test_composed_corners_share_the_chassis_and_the_rack_once():
    g = load_geometry(EXAMPLES / "double_wishbone.yaml")
    tree = compose_tree({s: g.mechanism.tree(g) for s in ("left", "right")}, "two")
    names = [b.name for b in tree.bodies]
    assert names.count("chassis") == 1 and names.count("rack") == 1
    assert len(names) == 2 * (len(g.mechanism.tree(g).bodies) - 2) + 2


def test_the_elements_add_their_parts_in_order():
    axle = load_axle(EXAMPLES / "axle_front.yaml")
    bar, heave = elements_of(axle)
    assert isinstance(bar, AntiRollBar) and isinstance(heave, HeaveLink)
    assert bar.kind == axle.anti_roll == "u_bar"
    tree = axle_tree(axle.left, axle.right, "axle", axle)
    assert "left_droplink" in [c.name for c in tree.closures]
    assert "bar" in tree.materials
    assert AntiRollBar(None).kind == "none" and AntiRollBar(None).rate_columns(None, {}) == {}


def test_each_element_gives_its_columns():
    model = AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))
    d = {k: v[None] for k, v in model.design_positions.items()}
    assert rack.travel(d, d) == np.zeros(1)
    assert rack.columns(None) == {} and rack.travel({}, {}) is None
    twist = model.bar.columns(model, d, d)
    assert set(twist) == {"arb_arm_angle_left", "arb_arm_angle_right", "arb_twist"}
    assert np.allclose(twist["arb_twist"][0], 0.0)
    length = HeaveLink(model.axle).columns(model, d, d)
    assert set(length) <= {"heave_link_length"}
