"""The K&C replay (``pin-susp kc ... --view kc.html``, docs/compliance.md): one sphere
per bushing at its pickup, its colour at every frame the K&C CSV's deflection of that
bushing under the chosen case (√(radial² + axial²) on YlOrRd over the largest), read
back from the page's meshcat commands."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
import pytest
from test_loads_plots import colour_tracks
from test_viz import _commands

from pin_susp.cli import main

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CORNER, SWEEP, CASES = (
    str(EXAMPLES / n) for n in ("kc_fs_corner.yaml", "bump_steer.yaml", "kc.yaml")
)
LABELS = ("fl", "fr", "rl", "rr")
PICKUPS = [f"{a}_wishbone_inboard_{e}" for a in ("lower", "upper") for e in ("front", "rear")]


def position_tracks(commands) -> dict[str, dict[int, list[float]]]:
    """Node → {frame: position} of every position track of the animation."""
    (animation,) = [c for c in commands if c["type"] == "set_animation"]
    out = {}
    for a in animation["animations"]:
        for track in a["clip"]["tracks"]:
            if track["name"] == ".position":
                out[a["path"]] = {k["time"]: k["value"] for k in track["keys"]}
    return out


@pytest.fixture(scope="module")
def replay(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("kc_view")
    out, html = tmp / "kc.csv", tmp / "kc.html"
    argv = ["kc", CORNER, SWEEP, "--cases", CASES, "-o", str(out), "-q"]
    assert main([*argv, "--view", str(html), "--case", "1 kN lateral"]) == 0
    return html.read_text(), _commands(html.read_text()), pd.read_csv(out, comment="#")


def test_each_bushing_is_coloured_by_its_csv_deflection(replay):
    _, commands, table = replay
    tracks = colour_tracks(commands)
    nodes = {p: f"/meshcat/pin_susp/bushings/bushing_{p}" for p in PICKUPS}
    assert set(tracks) == set(nodes.values())  # one colour track per bushing, no other
    rows = table[table["load_case"] == "1 kN lateral"]
    d = {p: np.hypot(rows[f"bushing_{p}_radial"], rows[f"bushing_{p}_axial"]).to_numpy()
         for p in PICKUPS}  # fmt: skip
    scale = max(v.max() for v in d.values())
    ramp = matplotlib.colormaps["YlOrRd"]
    for p, node in nodes.items():
        rgb = np.array([tracks[node][k] for k in range(len(d[p]))])  # a frame per step
        assert np.ptp(d[p]) > 0.01 * scale  # the deflection changes over the sweep,
        assert np.ptp(rgb, axis=0).max() > 0.01  # and with it the colour
        np.testing.assert_allclose(rgb, ramp(d[p] / scale)[:, :3], atol=1e-12)
        darker = np.argsort(d[p])  # deeper red (less green and blue) as it deflects more
        assert np.all(np.diff(rgb[darker].sum(axis=1)) <= 1e-12)


def test_each_sphere_sits_at_its_pickup(replay):
    _, commands, table = replay
    places = position_tracks(commands)
    first = table[table["load_case"] == "1 kN lateral"]
    for p in PICKUPS:
        track = places[f"/meshcat/pin_susp/bushings/bushing_{p}"]
        want = first[[f"{p}_{a}" for a in "xyz"]].to_numpy() * 1e-3  # the CSV's pickup, m
        np.testing.assert_allclose([track[k] for k in range(len(want))], want, atol=1e-12)


def test_the_replay_keys_its_case_and_scale(replay):
    html, _, _ = replay
    assert 'id="kc_key"' in html and "1 kN lateral" in html and " mm</span>" in html


def test_a_case_not_in_the_file_is_refused_before_any_work(tmp_path, capsys):
    html = tmp_path / "kc.html"
    argv = ["kc", CORNER, SWEEP, "--cases", CASES, "-o", str(tmp_path / "kc.csv")]
    assert main([*argv, "--view", str(html), "--case", "no such"]) == 2
    assert "no load case named 'no such'" in capsys.readouterr().err
    assert not html.exists() and not (tmp_path / "kc.csv").exists()


def test_a_cars_replay_has_each_corners_bushings_moving_with_the_body(tmp_path):
    html = tmp_path / "car.html"
    argv = ["kc", str(EXAMPLES / "vehicle_fs.yaml"), str(EXAMPLES / "vehicle_roll.yaml")]
    argv += ["--cases", str(EXAMPLES / "vehicle_kc.yaml"), "-o", str(tmp_path / "kc.csv")]
    assert main([*argv, "-q", "--view", str(html)]) == 0
    commands = _commands(html.read_text())
    nodes = {f"/meshcat/pin_susp/bushings/bushing_{p}_{c}" for p in PICKUPS for c in LABELS}
    assert set(colour_tracks(commands)) == nodes
    places = position_tracks(commands)
    for c in LABELS:  # the body rolls ±2 deg: the chassis pickups move with it
        track = places[f"/meshcat/pin_susp/bushings/bushing_lower_wishbone_inboard_front_{c}"]
        z = np.array([p[2] for p in track.values()])
        assert np.ptp(z) > 1e-3  # m
