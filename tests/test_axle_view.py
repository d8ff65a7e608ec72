"""The viewer on an axle: both corners, the anti-roll bar and the roll centre.

Read back from the self-contained HTML replay of `pin-susp view` and checked
against the CSV of `pin-susp sweep` on the same files: each body's recorded
pose moves its points (taken from the geometry file itself, not the model)
onto the CSV's points; the droplinks and the heave link run between their
ends' columns; the roll-centre marker sits on the roll_center_y/_z columns
and is hidden where they are blank.
"""

import csv

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, ROOT
from test_viz import CHROMIUM, _commands, _screenshot

from pin_susp.cli import main

# Each body's points in the geometry file (the axle's centre points unprefixed).
BODIES = {
    "upright": (
        "upper_wishbone_outboard",
        "lower_wishbone_outboard",
        "trackrod_outboard",
        "axle_inboard",
        "axle_outboard",
        "pushrod_outboard",
    ),
    "lower_wishbone": (
        "lower_wishbone_inboard_front",
        "lower_wishbone_inboard_rear",
        "lower_wishbone_outboard",
    ),
    "upper_wishbone": (
        "upper_wishbone_inboard_front",
        "upper_wishbone_inboard_rear",
        "upper_wishbone_outboard",
    ),
    "rocker": ("rocker_axis_a", "rocker_axis_b", "pushrod_inboard", "strut_bottom"),
}
U_BAR_ARM = ("arb_u_bar_axis_a", "arb_u_bar_axis_b", "droplink_u_bar")  # per side
T_BAR = ("arb_t_bar_pivot", "left_droplink_t_bar", "right_droplink_t_bar")  # one body


def low_roll_centre(data: dict) -> dict:
    """axle_front with the upper wishbones' inboard ends 60 mm lower (the roll centre
    near the ground, 87 mm up at design) and a heave link between the rockers."""
    left = data["hardpoints"]["left"]
    for end in ("front", "rear"):
        left[f"upper_wishbone_inboard_{end}"]["z"] = 440
    left["heave_link_rocker"] = {"x": 0, "y": 320, "z": 480}
    data["axle_config"]["heave_link"] = {"type": "rocker_to_rocker"}
    return data


CASES = {  # name: (geometry file, change)
    "u_bar": (EXAMPLES / "axle_front.yaml", None),
    "low_rc": (EXAMPLES / "axle_front.yaml", low_roll_centre),
    "t_bar": (ROOT / "tests" / "data" / "axle_t_bar.yaml", None),
}


@pytest.fixture(scope="module", params=list(CASES))
def replay(request, tmp_path_factory):
    """(geometry dict, CSV columns, the replay's meshcat commands) of a ±3° roll."""
    path, change = CASES[request.param]
    data = yaml.safe_load(path.read_text())
    if change is not None:
        data = change(data)
    tmp = tmp_path_factory.mktemp(request.param)
    geometry = tmp / "axle.yaml"
    geometry.write_text(yaml.safe_dump(data))
    sweep = str(EXAMPLES / "roll.yaml")
    out, html = tmp / "roll.csv", tmp / "roll.html"
    assert main(["sweep", str(geometry), sweep, "-o", str(out), "-q"]) == 0
    assert main(["view", str(geometry), sweep, "--html", str(html)]) == 0
    return data, read_csv(out), _commands(html.read_text())


def read_csv(path) -> dict[str, np.ndarray]:
    """A results CSV's columns as floats (blank: NaN; True/False: 1/0)."""
    lines = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    rows = list(csv.reader(lines))
    value = {"": "nan", "True": "1", "False": "0"}
    return {
        name: np.array([float(value.get(r[i], r[i])) for r in rows[1:]])
        for i, name in enumerate(rows[0])
    }


def design_point(data: dict, name: str) -> np.ndarray:
    """A point (m) from the axle file itself: ``left_…``/``right_…`` (the right side
    the left mirrored, as the file has no hardpoints.right) or a centre point."""
    hp = data["hardpoints"]
    side, _, rest = name.partition("_")
    if side in ("left", "right"):
        p = hp["left"][rest]
        return 1e-3 * np.array([p["x"], p["y"] * (1 if side == "left" else -1), p["z"]])
    return 1e-3 * np.array([hp["center"][name][k] for k in "xyz"])


def csv_point(columns: dict, name: str) -> np.ndarray:
    """A point's columns (m, N×3)."""
    return 1e-3 * np.column_stack([columns[f"{name}_{k}"] for k in "xyz"])


def static(commands, path: str, kind: str = "set_transform") -> dict:
    (command,) = [c for c in commands if c["type"] == kind and c["path"] == path]
    return command


def tracks(commands, path: str) -> dict[str, dict[int, object]]:
    """An animated node's tracks: {'.position': {frame: value}, ...}."""
    (animation,) = [c for c in commands if c["type"] == "set_animation"]
    (clip,) = [a["clip"] for a in animation["animations"] if a["path"] == path]
    return {t["name"]: {k["time"]: k["value"] for k in t["keys"]} for t in clip["tracks"]}


def rotation(quaternion) -> np.ndarray:
    """three.js's (x, y, z, w) as a rotation matrix."""
    x, y, z, w = quaternion
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def visual(body: str) -> str:
    return f"/meshcat/pin_susp/corner/visuals/{body}_0"


def bodies(data: dict) -> dict[str, tuple[str, ...]]:
    """Every moving body of the axle file, by its name in the URDF: its points."""
    out = {
        f"{side}_{body}": tuple(f"{side}_{p}" for p in points)
        for side in ("left", "right")
        for body, points in BODIES.items()
    }
    if data["axle_config"]["anti_roll"]["type"] == "u_bar":
        for side in ("left", "right"):
            out[f"{side}_arb_arm"] = (*U_BAR_ARM[:2], f"{side}_{U_BAR_ARM[2]}")
    else:
        out["t_bar"] = T_BAR
    for side in ("left", "right"):
        out[f"{side}_rocker"] += (f"{side}_droplink_rocker",)
        if "heave_link_rocker" in data["hardpoints"]["left"]:
            out[f"{side}_rocker"] += (f"{side}_heave_link_rocker",)
    return out


def test_each_body_moves_its_file_points_onto_the_csv_points(replay):
    """Both corners, the rockers and the bar: pose(frame) · pose(design)⁻¹ applied to
    the body's points as written in the file gives the CSV's points at that step."""
    data, columns, commands = replay
    ok = columns["solver_converged"] == 1
    assert ok.all()
    steps = np.flatnonzero(ok)
    for body, points in bodies(data).items():
        design = static(commands, visual(body))
        T0 = np.array(design["matrix"], dtype=float).reshape(4, 4).T  # column-major
        frames = tracks(commands, visual(body))
        assert sorted(frames[".position"]) == list(range(len(steps))), body
        p0 = np.array([design_point(data, p) for p in points])
        moved = 0.0
        for frame, step in enumerate(steps):
            R = rotation(frames[".quaternion"][frame])
            t = np.array(frames[".position"][frame])
            R_rel = R @ T0[:3, :3].T
            at = (p0 - T0[:3, 3]) @ R_rel.T + t
            want = np.array([csv_point(columns, p)[step] for p in points])
            np.testing.assert_allclose(at, want, atol=1e-9, err_msg=f"{body} step {step}")
            moved = max(moved, np.abs(want - p0).max())
        assert moved > 1e-3, f"{body} does not move: the check would not see a wrong pose"


def test_droplinks_and_heave_link_run_between_their_ends(replay):
    data, columns, commands = replay
    bar = f"droplink_{data['axle_config']['anti_roll']['type']}"  # the bar's end
    links = {f"{s}_droplink": (f"{s}_droplink_rocker", f"{s}_{bar}") for s in ("left", "right")}
    if data["axle_config"]["heave_link"]["type"] != "none":
        links["heave_link"] = ("left_heave_link_rocker", "right_heave_link_rocker")
    for name, (a, b) in links.items():
        path = f"/meshcat/pin_susp/links/{name}"
        assert static(commands, path, "set_object")["object"]["geometries"][0]["type"] == (
            "CylinderGeometry"
        )
        frames = tracks(commands, path)
        ends = csv_point(columns, a), csv_point(columns, b)
        for frame in frames[".position"]:
            np.testing.assert_allclose(
                frames[".position"][frame], 0.5 * (ends[0] + ends[1])[frame], atol=1e-9
            )
            axis = rotation(frames[".quaternion"][frame])[:, 1]  # the rod's y axis
            d = ends[1][frame] - ends[0][frame]
            np.testing.assert_allclose(np.abs(axis @ d), np.linalg.norm(d), rtol=1e-9)


def test_roll_centre_marker_follows_the_csv_and_hides_where_blank(replay):
    data, columns, commands = replay
    path = "/meshcat/pin_susp/roll_centre"
    frames = tracks(commands, path)
    rc_y, rc_z = columns["roll_center_y"], columns["roll_center_z"]
    x = 0.5 * (columns["left_contact_patch_center_x"] + columns["right_contact_patch_center_x"])
    blank = np.isnan(rc_y)
    assert np.array_equal(blank, np.isnan(rc_z))
    if data["hardpoints"]["left"]["upper_wishbone_inboard_front"]["z"] == 500:
        # parallel wishbones at design (both horizontal): no roll centre at step 15 only
        assert np.flatnonzero(blank).tolist() == [15]
    else:
        assert not blank.any()
    visible = frames[".visible"]
    assert [visible[i] for i in range(len(blank))] == (~blank).tolist()
    shown = np.flatnonzero(~blank)
    got = np.array([frames[".position"][i] for i in shown])
    want = 1e-3 * np.column_stack([x, rc_y, rc_z])[shown]
    np.testing.assert_allclose(got, want, atol=1e-9)
    assert np.ptp(want[:, 1]) > 0.1  # it moves across in roll

    # at design (step 15 of the sweep is the design state): the marker's static place
    assert np.abs(columns["roll"][15]) < 1e-9 and np.abs(columns["heave"][15]) < 1e-9
    shown_at_design = static(commands, path, "set_property")
    assert shown_at_design["property"] == "visible"
    assert shown_at_design["value"] == (not blank[15])
    if not blank[15]:
        T = np.array(static(commands, path)["matrix"], dtype=float).reshape(4, 4).T
        np.testing.assert_allclose(T[:3, 3], want[list(shown).index(15)], atol=1e-9)


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (Debian package chromium)")
def test_axle_replay_renders_both_corners_and_the_roll_centre(tmp_path):
    """In a real browser: both uprights, the bar, and the roll centre (cyan) at a
    frame where it is defined, gone at one where it is blank (a step blanked here)."""
    import contextlib
    import io

    from PIL import Image

    from pin_susp.model.sweep import load_sweep
    from pin_susp.subjects.axle import AxleModel, axle_results, load_axle, solve_axle_sweep
    from pin_susp.viz.scene import Scene, roll_centres

    model = AxleModel(load_axle(low_roll_centre(yaml.safe_load(CASES["low_rc"][0].read_text()))))
    sweep = load_sweep(EXAMPLES / "roll.yaml")
    results = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    centres = roll_centres(results)
    centres[10] = np.nan
    with contextlib.redirect_stdout(io.StringIO()):
        scene = Scene(model)
    try:
        scene.animate(list(results.meta["q"]), markers={"roll_centre": centres})
        html = scene.html()
    finally:
        scene.close()
    assert scene.server.poll() is not None

    pixels = {}
    for frame in (15, 10):  # paused there once loaded (time = frame / fps)
        seek = f"viewer.animator.pause(); viewer.animator.seek({frame / 10});"
        page = tmp_path / f"frame{frame}.html"
        page.write_text(
            html.replace("</body>", f"<script>setTimeout(() => {{{seek}}}, 2500);</script></body>")
        )
        shot = _screenshot(page, tmp_path)
        assert shot.exists(), "chromium wrote no screenshot"
        rgb = np.asarray(Image.open(shot).convert("RGB")).astype(int)
        r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
        h, w = r.shape
        orange = (r > 170) & (g > 70) & (g < 170) & (b < 90)  # the uprights
        gold = (r > 150) & (g > 130) & (b < 80) & (r - g < 60)  # the bar
        assert orange[:, : w // 2].sum() > 50 and orange[:, w // 2 :].sum() > 50
        assert gold.sum() > 100
        pixels[frame] = ((r < 90) & (g > 170) & (b > 190)).sum()  # the roll centre's cyan
    assert pixels[15] > 40 and pixels[10] == 0, pixels


def test_a_set_up_axle_shows_its_drawn_geometry_as_a_ghost():
    """A camber shim and a trackrod adjuster: the ghost is the axle file without them."""
    import contextlib
    import io

    from conftest import example

    from pin_susp.subjects.axle import AxleModel, load_axle
    from pin_susp.viz.scene import Scene

    data = yaml.safe_load((EXAMPLES / "axle_front.yaml").read_text())
    drawn = AxleModel(load_axle(data))
    data["axle_config"]["left_setup"] = {
        "camber_shim": example("camber_shim.yaml")["config"]["camber_shim"],  # 30 → 20 mm
        "trackrod_length_delta": 2.0,
    }
    with contextlib.redirect_stdout(io.StringIO()):
        scene = Scene(AxleModel(load_axle(data)))
    try:
        commands = _commands(scene.html())
    finally:
        scene.close()
    (ghost, _), (as_set, _) = scene.robots
    for name, p in drawn.design_positions.items():
        np.testing.assert_allclose(ghost.design_positions[name], p, atol=1e-12, err_msg=name)
    moved = {
        n: np.abs(as_set.design_positions[n] - p).max() for n, p in ghost.design_positions.items()
    }
    assert moved["left_upper_wishbone_inboard_front"] == 0.0 and moved["left_wheel_center"] > 1e-3
    # a mirrored right side takes the left's setup
    left, right = (as_set.design_positions[f"{s}_wheel_center"] for s in ("left", "right"))
    np.testing.assert_allclose(right, left * [1, -1, 1], atol=1e-12)
    paths = {c["path"] for c in commands if c["type"] == "set_object"}
    assert {"/meshcat/pin_susp/drawn/visuals/left_upright_0", visual("left_upright")} <= paths


def test_view_command_serves_an_axle_on_loopback_and_stops_on_ctrl_c(tmp_path):
    import signal
    import subprocess
    import sys

    command = ["view", str(EXAMPLES / "axle_front.yaml"), str(EXAMPLES / "roll.yaml")]
    proc = subprocess.Popen(
        [sys.executable, "-m", "pin_susp.cli", *command],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    try:
        first = proc.stdout.readline()
        assert first.startswith("meshcat: http://127.0.0.1:") and "31 frames" in first, first
        assert "Ctrl+C" in proc.stdout.readline()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    assert "stopped" in out and "Traceback" not in err


def test_a_bad_axle_sweep_is_one_line_and_writes_nothing(tmp_path, capsys):
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(
        "steps: 3\ntargets:\n  - {quantity: roll, start: -1, stop: 1}\n"
        "  - {quantity: heave, start: 0, stop: 0}\n"
        "  - {point: trackrod_inboard, direction: {axis: y}, start: 0, stop: 0}\n"
    )
    html = tmp_path / "out.html"
    geometry = str(EXAMPLES / "axle_front.yaml")
    assert main(["view", geometry, str(sweep), "--html", str(html)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "targets[2].side" in err, err
    assert not html.exists()
