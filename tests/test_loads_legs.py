"""A wishbone that is not a two-force member (issue 24, point 9): with the pushrod on
the lower wishbone its legs bend, their tension columns are blank, and the loads say
so; each bushing's load resolved along its leg is written for every wishbone."""

import csv

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example
from test_loads_plots import colour_tracks
from test_viz import _commands

from pin_susp.cli import main

SWEEP = str(EXAMPLES / "bump_steer.yaml")
CASES = str(EXAMPLES / "loads.yaml")
ENDS = ("front", "rear")


def pushrod_on_the_lower_wishbone() -> dict:
    """The pushrod-rocker example with the pushrod's outboard end on the lower wishbone,
    30 mm inboard of the lower ball joint and 5 mm above it."""
    g = example("pushrod_rocker.yaml")
    g["actuation"]["mount"] = "lower_wishbone"
    g["hardpoints"]["pushrod_outboard"] = {"x": 0, "y": 870, "z": 205}
    return g


def loads(tmp_path, geometry: dict, capsys):
    path = tmp_path / "corner.yaml"
    path.write_text(yaml.safe_dump(geometry))
    out = tmp_path / "forces.csv"
    assert main(["loads", str(path), SWEEP, "--cases", CASES, "-o", str(out)]) == 0
    with open(out, newline="") as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    columns = {
        name: np.array([float(r[j]) if r[j] else np.nan for r in rows[1:]])
        for j, name in enumerate(rows[0])
        if name not in ("load_case", "solver_converged")
    }
    return columns, capsys.readouterr().out


def vector(columns, name: str) -> np.ndarray:
    return np.stack([columns[f"{name}_{a}"] for a in "xyz"], axis=1)


def along_by_hand(columns, geometry: dict, arm: str, end: str) -> np.ndarray:
    """The bushing's load on the chassis (its CSV vector) on the leg's unit vector, from
    the chassis pickup (the file's point) to the ball joint (the CSV's, at each row)."""
    p = geometry["hardpoints"][f"{arm}_inboard_{end}"]
    pickup = np.array([p[a] for a in "xyz"], dtype=float)
    leg = vector(columns, f"{arm}_outboard") - pickup
    leg /= np.linalg.norm(leg, axis=1)[:, None]
    return np.sum(vector(columns, f"load_{arm}_{end}_bushing") * leg, axis=1)


def test_a_two_force_wishbones_bushings_resolved_along_its_legs_are_its_legs(tmp_path, capsys):
    """Each wishbone of the example, loaded at its ball joint alone: the bushing loads
    along each leg, from the CSV's vectors and points, are the legs' tensions."""
    geometry = example("pushrod_rocker.yaml")
    columns, out = loads(tmp_path, geometry, capsys)
    for arm in ("lower_wishbone", "upper_wishbone"):
        for end in ENDS:
            leg = columns[f"force_{arm}_{end}"]
            along = columns[f"load_{arm}_{end}_bushing_along_leg"]
            assert np.isfinite(leg).all() and np.abs(leg).max() > 100.0
            np.testing.assert_allclose(along, leg, rtol=1e-9, atol=1e-9)
            by_hand = along_by_hand(columns, geometry, arm, end)
            np.testing.assert_allclose(by_hand, leg, rtol=1e-9, atol=1e-6)
    assert "not a two-force member" not in out


def test_a_wishbone_carrying_the_pushrod_says_it_is_not_a_two_force_member(tmp_path, capsys):
    geometry = pushrod_on_the_lower_wishbone()
    columns, out = loads(tmp_path, geometry, capsys)
    bounded = columns["loads_unbounded"] == 0
    assert bounded.all()
    for end in ENDS:
        assert np.isnan(columns[f"force_lower_wishbone_{end}"]).all()
        along = columns[f"load_lower_wishbone_{end}_bushing_along_leg"]
        assert np.isfinite(along).all() and np.abs(along).max() > 100.0
        np.testing.assert_allclose(
            along, along_by_hand(columns, geometry, "lower_wishbone", end), rtol=1e-9, atol=1e-6
        )
        assert np.isfinite(columns[f"force_upper_wishbone_{end}"]).all()  # still two-force
    assert (
        "lower_wishbone: not a two-force member (it also carries pushrod_outboard): its legs "
        "bend, force_lower_wishbone_front and force_lower_wishbone_rear are blank" in out
    )
    table = [line.split() for line in out.splitlines()]
    assert any(r[:1] == ["load_lower_wishbone_front_bushing_along_leg"] for r in table)
    assert not any(r[:1] == ["force_lower_wishbone_front"] for r in table)


def test_the_bent_wishbones_bushing_loads_hold_it_in_equilibrium(tmp_path, capsys):
    """Independent of how the pivot's load is split: the arm's forces and moments from the
    CSV alone — the chassis through its two bushings, the upright through the lower
    ball joint, the pushrod's tension along it — sum to zero at every row."""
    geometry = pushrod_on_the_lower_wishbone()
    columns, _ = loads(tmp_path, geometry, capsys)
    hp = geometry["hardpoints"]
    at = {e: np.array([hp[f"lower_wishbone_inboard_{e}"][a] for a in "xyz"]) * 1e-3 for e in ENDS}
    ball = vector(columns, "lower_wishbone_outboard") * 1e-3
    top, bottom = (vector(columns, f"pushrod_{e}") * 1e-3 for e in ("inboard", "outboard"))
    rod = (top - bottom) / np.linalg.norm(top - bottom, axis=1)[:, None]
    parts = [(at[e], -vector(columns, f"load_lower_wishbone_{e}_bushing")) for e in ENDS]
    parts += [
        (ball, vector(columns, "load_lower_ball_joint")),  # the upright on the arm
        (bottom, columns["force_pushrod"][:, None] * rod),  # a pull toward the rocker
    ]
    force = sum(f for _, f in parts)
    moment = sum(np.cross(np.broadcast_to(r, f.shape), f) for r, f in parts)
    scale = np.abs(columns["force_pushrod"]).max()
    assert np.abs(force).max() < 1e-9 * scale
    assert np.abs(moment).max() < 1e-9 * scale


def test_the_replay_colours_a_bent_wishbone_as_no_two_force_member(tmp_path, capsys):
    """Its legs have no tension: they are NOT_TWO_FORCE at every frame, not a colour of
    the ramp (blue, compression), and the key and the page say what that colour is."""
    import matplotlib

    from pin_susp.viz.scene import NOT_TWO_FORCE

    path = tmp_path / "corner.yaml"
    path.write_text(yaml.safe_dump(pushrod_on_the_lower_wishbone()))
    html = tmp_path / "forces.html"
    argv = ["view", str(path), SWEEP, "--cases", CASES, "--case", "2g cornering"]
    assert main([*argv, "--html", str(html)]) == 0
    assert "yellow-green: a wishbone leg that is not a two-force member" in capsys.readouterr().out
    text = html.read_text()
    assert "not a two-force member" in text
    tracks = colour_tracks(_commands(text))
    bent = [n for n, t in tracks.items() if all(v == list(NOT_TWO_FORCE) for v in t.values())]
    assert len(bent) == 2 and len(tracks) == 7  # the lower legs; the rest by their force
    ramp = matplotlib.colormaps["coolwarm"](np.linspace(0, 1, 1001))[:, :3]
    assert np.abs(ramp - np.array(NOT_TWO_FORCE)).sum(axis=1).min() > 0.3  # off the ramp
    for node, track in tracks.items():
        if node not in bent:
            assert all(v != list(NOT_TWO_FORCE) for v in track.values())


@pytest.mark.parametrize("geometry", ["pushrod_rocker.yaml", "bent"])
def test_the_statics_name_the_bent_arms(geometry):
    import pin_susp
    from pin_susp.analyses.loads import Statics

    data = pushrod_on_the_lower_wishbone() if geometry == "bent" else example(geometry)
    bent = Statics(pin_susp.Corner(data)).not_two_force()
    if geometry == "bent":
        assert bent == {
            "lower_wishbone": (
                ["pushrod_outboard"],
                ["force_lower_wishbone_front", "force_lower_wishbone_rear"],
                [
                    "load_lower_wishbone_front_bushing_along_leg",
                    "load_lower_wishbone_rear_bushing_along_leg",
                ],
            )
        }
    else:
        assert bent == {}
