"""The whole car in the viewer and on paper (docs/vehicle.md, "View" and "Draw").

The replay is read back from the self-contained HTML of `pin-susp view` and checked
against the CSV of `pin-susp sweep` on the same files. The CSV's points are in the
chassis frame; the scene draws the car on the road, so each wheel centre the scene
places must be the CSV's put on the road by the body's pose, computed here on its own
from the files (the CG from vehicle_config, the pose from the heave, pitch and roll
columns): w = c + h·ẑ + R_y(pitch)·R_x(roll)·(p − c). The drawing's pitch centre is
read back from the figure's artists and compared with the sweep's columns at design.
"""

import contextlib
import io
import re
import signal
import subprocess
import sys
import urllib.request

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES
from test_axle_view import csv_point, read_csv, rotation, static, tracks
from test_viz import CHROMIUM, _commands, _screenshot

from pin_susp.cli import main

CARS = {"fs": EXAMPLES / "vehicle_fs.yaml", "saloon": EXAMPLES / "vehicle_saloon.yaml"}
LABELS = ("fl", "fr", "rl", "rr")
COMBINED = EXAMPLES / "vehicle_combined.yaml"  # heave, pitch, roll and steering at once


def visual(body: str) -> str:
    return f"/meshcat/pin_susp/corner/visuals/{body}_0"


def cg_of(path) -> np.ndarray:
    """The CG (m) from the vehicle file itself: x a fraction of the wheelbase behind
    the front wheel centre (the front axle file's axle_outboard less the wheel's
    offset along the spin axis), z above the road."""
    car = yaml.safe_load(path.read_text())
    config = car["vehicle_config"]
    front = yaml.safe_load((path.parent / car["front"]).read_text())
    points = front["hardpoints"]["left"]
    inboard, outboard = (
        np.array([points[n][k] for k in "xyz"], float) for n in ("axle_inboard", "axle_outboard")
    )
    spin = (outboard - inboard) / np.linalg.norm(outboard - inboard)
    centre = outboard - front["axle_config"]["wheel"].get("offset", 0) * spin
    x = centre[0] - config["cg"]["x"] * config["wheelbase"]
    return 1e-3 * np.array([x, 0.0, config["cg"]["z"]])


def on_road(p: np.ndarray, c: np.ndarray, heave, pitch, roll) -> np.ndarray:
    """Chassis-frame points (n, 3) m on the road at each row's body pose (heave m,
    pitch and roll rad): c + h·ẑ + R_y(pitch)·R_x(roll)·(p − c)."""
    out = []
    for point, h, theta, phi in zip(p, heave, pitch, roll, strict=True):
        rx = np.array([[1, 0, 0], [0, np.cos(phi), -np.sin(phi)], [0, np.sin(phi), np.cos(phi)]])
        ry = np.array(
            [[np.cos(theta), 0, np.sin(theta)], [0, 1, 0], [-np.sin(theta), 0, np.cos(theta)]]
        )
        out.append(c + h * np.array([0.0, 0.0, 1.0]) + ry @ rx @ (point - c))
    return np.array(out)


def pose(columns: dict) -> tuple:
    return (
        columns["heave"] * 1e-3,
        np.radians(columns["pitch"]),
        np.radians(columns["roll"]),
    )


@pytest.fixture(scope="module", params=list(CARS))
def replay(request, tmp_path_factory):
    """(the car's file, the CSV's columns, the replay's text, what view printed)."""
    path = CARS[request.param]
    tmp = tmp_path_factory.mktemp(request.param)
    out, html = tmp / "combined.csv", tmp / "combined.html"
    assert main(["sweep", str(path), str(COMBINED), "-o", str(out), "-q"]) == 0
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert main(["view", str(path), str(COMBINED), "--html", str(html)]) == 0
    return path, read_csv(out), html.read_text(), printed.getvalue()


def test_the_replay_holds_the_whole_car_and_a_frame_per_step(replay):
    path, columns, html, printed = replay
    assert printed.strip().endswith("(21 frames)"), printed
    # self-contained: no page, script or image fetched from a server
    assert not re.findall(r"""(?:src|href)\s*=\s*["']?(https?:)?//""", html)
    assert len(html) > 500_000  # the viewer's code is inside the page
    commands = _commands(html)
    objects = {c["path"] for c in commands if c["type"] == "set_object"}
    bodies = [f"{label}_upright" for label in LABELS] + ["fl_lower_wishbone", "fr_lower_wishbone"]
    if "fs" in path.name:  # its U-bars' arms, its rockers, its rear wishbones
        bodies += [f"{label}_{b}" for label in LABELS for b in ("arb_arm", "rocker")]
        bodies += ["rl_lower_wishbone", "rr_lower_wishbone"]
    else:  # the five-link's
        bodies += ["rl_lower_front_link", "rr_lower_front_link", "fl_strut_rod"]
    for body in bodies:
        assert visual(body) in objects, body
        assert sorted(tracks(commands, visual(body))[".position"]) == list(range(21)), body
    assert any(p.startswith("/meshcat/pin_susp/corner/visuals/chassis") for p in objects)
    for marker in ("roll_centre_front", "roll_centre_rear", "pitch_centre", "cg"):
        assert f"/meshcat/pin_susp/{marker}" in objects, marker
    assert "/meshcat/pin_susp/ground" in objects


def test_each_wheel_centre_is_where_the_bodys_pose_puts_it_on_the_road(replay):
    """Each upright's recorded pose at every step moves its wheel centre (at rest: the
    CSV's first step, the design on the road) onto the CSV's chassis-frame wheel centre
    put on the road by the step's heave, pitch and roll, to 1e-9 m."""
    path, columns, html, _ = replay
    commands = _commands(html)
    assert np.all(columns["solver_converged"] == 1)
    assert all(abs(columns[k][0]) < 1e-12 for k in ("heave", "pitch", "roll"))  # at rest
    assert abs(columns["roll"][-1] - 1.5) < 1e-9 and abs(columns["pitch"][-1] - 1.0) < 1e-9
    c = cg_of(path)
    heave, pitch, roll = pose(columns)
    for label in LABELS:
        node = visual(f"{label}_upright")
        rest = np.array(static(commands, node)["matrix"], dtype=float).reshape(4, 4).T
        chassis = csv_point(columns, f"{label}_wheel_center")
        local = rest[:3, :3].T @ (chassis[0] - rest[:3, 3])  # in the upright's own frame
        frames = tracks(commands, node)
        got = np.array(
            [
                rotation(frames[".quaternion"][i]) @ local + np.array(frames[".position"][i])
                for i in range(len(chassis))
            ]
        )
        want = on_road(chassis, c, heave, pitch, roll)
        np.testing.assert_allclose(got, want, atol=1e-9, err_msg=label)
        # the body's pose moves it: a scene in the chassis frame would fail here
        assert np.abs(want[-1] - chassis[-1]).max() > 2e-3, label


def test_the_markers_are_the_columns_on_the_road(replay):
    """The CG, each axle's roll centre and the pitch centre at every step: the columns
    (chassis frame) on the road by the body's pose."""
    path, columns, html, _ = replay
    commands = _commands(html)
    c = cg_of(path)
    heave, pitch, roll = pose(columns)
    n = len(heave)
    mid = {
        end: 0.5 * (columns[f"{a}_contact_patch_center_x"] + columns[f"{b}_contact_patch_center_x"])
        for end, (a, b) in (("front", ("fl", "fr")), ("rear", ("rl", "rr")))
    }
    chassis = {
        "cg": np.tile(c, (n, 1)),
        "pitch_centre": 1e-3
        * np.column_stack([columns["pitch_center_x"], np.zeros(n), columns["pitch_center_z"]]),
        **{
            f"roll_centre_{end}": 1e-3
            * np.column_stack(
                [mid[end], columns[f"roll_center_y_{end}"], columns[f"roll_center_z_{end}"]]
            )
            for end in ("front", "rear")
        },
    }
    for name, points in chassis.items():
        assert np.all(np.isfinite(points)), name
        frames = tracks(commands, f"/meshcat/pin_susp/{name}")
        got = np.array([frames[".position"][i] for i in range(n)])
        np.testing.assert_allclose(got, on_road(points, c, heave, pitch, roll), atol=1e-9)
        assert all(frames[".visible"][i] for i in range(n)), name
    # the CG rises by the heave alone: the body turns about it
    np.testing.assert_allclose(
        np.array([tracks(commands, "/meshcat/pin_susp/cg")[".position"][i] for i in range(n)]),
        c + np.outer(heave, [0.0, 0.0, 1.0]),
        atol=1e-12,
    )


def test_the_replay_is_written_whole_or_not_at_all(tmp_path, monkeypatch):
    """An interrupt while the page is being written leaves the replay that was there."""
    from pin_susp.io import atomic

    html = tmp_path / "replay.html"
    html.write_text("the last replay")

    def half_then_interrupt(text, path):
        with atomic.atomic_write(path) as f:
            f.write(text[: len(text) // 2])
            raise KeyboardInterrupt

    monkeypatch.setattr(atomic, "write_text", half_then_interrupt)
    args = ["view", str(CARS["fs"]), str(EXAMPLES / "vehicle_roll.yaml"), "--html", str(html)]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(args) == 128 + signal.SIGINT
    assert html.read_text() == "the last replay"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["replay.html"]


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (Debian package chromium)")
def test_the_replay_shows_the_car_rolled_on_the_road_in_chromium(tmp_path):
    """In a real browser: the four uprights, both bars and the markers, at design and
    at the roll sweep's last step (2°: the picture moves), the car on the road's plane."""
    from PIL import Image

    html = tmp_path / "roll.html"
    args = ["view", str(CARS["fs"]), str(EXAMPLES / "vehicle_roll.yaml"), "--html", str(html)]
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(args) == 0
    shots = {}
    for frame in (10, 20):  # roll 0 and +2 deg, paused there once loaded (frame / fps)
        seek = f"viewer.animator.pause(); viewer.animator.seek({frame / 10});"
        page = tmp_path / f"frame{frame}.html"
        page.write_text(
            html.read_text().replace(
                "</body>", f"<script>setTimeout(() => {{{seek}}}, 2500);</script></body>"
            )
        )
        shot = _screenshot(page, tmp_path)
        assert shot.exists(), "chromium wrote no screenshot"
        rgb = np.asarray(Image.open(shot).convert("RGB")).astype(int)
        r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
        h, w = r.shape
        orange = (r > 170) & (g > 70) & (g < 170) & (b < 90)  # the uprights
        gold = (r > 150) & (g > 130) & (b < 80) & (r - g < 60)  # the bars
        cyan = (r < 90) & (g > 170) & (b > 190)  # a roll centre
        purple = (r > 120) & (r < 200) & (g < 100) & (b > 200)  # the pitch centre
        assert orange[:, : w // 2].sum() > 50 and orange[:, w // 2 :].sum() > 50, frame
        assert gold.sum() > 200, frame
        assert cyan.sum() > 20 and purple.sum() > 20, (frame, cyan.sum(), purple.sum())
        shots[frame] = rgb
    moved = np.abs(shots[10] - shots[20]).max(axis=2) > 40
    assert moved.sum() > 500  # rolled 2 degrees: the car is not where it was


def test_view_serves_the_car_on_loopback_and_stops_on_ctrl_c(tmp_path):
    command = ["view", str(CARS["fs"]), str(EXAMPLES / "vehicle_roll.yaml")]
    proc = subprocess.Popen(
        [sys.executable, "-m", "pin_susp.cli", *command],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    try:
        first = proc.stdout.readline()
        assert first.startswith("meshcat: http://127.0.0.1:") and "21 frames" in first, first
        assert "Ctrl+C" in proc.stdout.readline()
        url = first.split()[1]
        with urllib.request.urlopen(url, timeout=10) as page:  # served, on loopback
            assert page.status == 200
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    assert "stopped" in out and "Traceback" not in err


# --- the drawing -----------------------------------------------------------------------


@pytest.fixture(scope="module", params=list(CARS))
def drawing(request, tmp_path_factory):
    """(the car's file, its sweep's columns at design, the drawing's figure)."""
    import pin_susp
    from pin_susp.viz.drawing import subject_figure

    path = CARS[request.param]
    tmp = tmp_path_factory.mktemp(f"draw_{request.param}")
    out = tmp / "roll.csv"
    assert (
        main(["sweep", str(path), str(EXAMPLES / "vehicle_roll.yaml"), "-o", str(out), "-q"]) == 0
    )
    columns = read_csv(out)
    design = {name: values[10] for name, values in columns.items()}  # roll 0: the design
    assert all(abs(design[k]) < 1e-12 for k in ("heave", "pitch", "roll"))
    return path, design, subject_figure(pin_susp.Vehicle(path))


def lines(ax) -> dict:
    return {line.get_gid(): line for line in ax.get_lines() if line.get_gid()}


def test_the_side_view_draws_the_pitch_centre_where_its_lines_meet(drawing):
    """The pitch centre's marker at the sweep's pitch_center_x, _z at design; each
    axle's line from its contact patch through its SVIC (the mean of its corners'
    svic columns) and on to the pitch centre; the CG where the file puts it."""
    path, design, fig = drawing
    side, front, rear = fig.axes[:3]
    assert side.get_title() == "Side view: design state"
    drawn = lines(side)
    pc = np.array([design["pitch_center_x"], design["pitch_center_z"]])
    np.testing.assert_allclose(np.ravel(drawn["pitch_centre"].get_xydata()), pc, atol=1e-9)
    np.testing.assert_allclose(
        np.ravel(drawn["cg"].get_xydata()), cg_of(path)[[0, 2]] * 1e3, atol=1e-9
    )
    for end, corners in (("front", ("fl", "fr")), ("rear", ("rl", "rr"))):
        cp = np.mean([[design[f"{c}_contact_patch_center_{k}"] for k in "xz"] for c in corners], 0)
        sv = np.mean([[design[f"svic_{k}_{c}"] for k in "xz"] for c in corners], 0)
        a, b = drawn[f"pitch_line_{end}"].get_xydata()
        np.testing.assert_allclose(a, cp, atol=1e-9)  # from the contact patch
        for point in (sv, pc):  # through the SVIC and the pitch centre
            along = (point - a) @ (b - a) / ((b - a) @ (b - a))
            assert -1e-9 <= along <= 1 + 1e-9, (end, along)
            np.testing.assert_allclose(a + along * (b - a), point, atol=1e-6)
    note = next(t.get_text() for t in side.texts if t.get_gid() == "ic_note")
    assert note.startswith(f"pitch centre: x = {pc[0]:.0f} mm, z = {pc[1]:.0f} mm"), note
    assert f"anti-dive front: {design['anti_dive_front']:.1f} %" in note
    # only the left corners, and their wheels: two tyres
    assert sum(1 for line in side.get_lines() if line.get_gid() == "tyre") == 2


def test_each_axles_front_view_crosses_at_the_cars_roll_centre(drawing):
    """The front views are the axle drawing of each axle posed at the car's design:
    their roll centre is the car's roll_center_y_<end>, _z_<end> at design."""
    _, design, fig = drawing
    for ax, end in zip(fig.axes[1:3], ("front", "rear"), strict=True):
        assert ax.get_title() == f"Front view: the {end} axle at design"
        rc = np.ravel(lines(ax)["roll_centre"].get_xydata())
        want = [design[f"roll_center_y_{end}"], design[f"roll_center_z_{end}"]]
        np.testing.assert_allclose(rc, want, atol=1e-6)
        assert sum(1 for line in ax.get_lines() if line.get_gid() == "tyre") == 2


def test_draw_writes_the_car(tmp_path, capsys):
    out = tmp_path / "car.png"
    assert main(["draw", str(CARS["saloon"]), "-o", str(out), "--labels"]) == 0
    assert capsys.readouterr().out == f"wrote {out}\n"
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bad_inputs_are_one_line_and_write_nothing(tmp_path, capsys):
    fs = str(CARS["fs"])
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text("steps: 3\ntargets:\n  - {quantity: roll, start: -1, stop: 1}\n")
    html, png = tmp_path / "out.html", tmp_path / "car.png"
    loads = tmp_path / "loads.yaml"
    loads.write_text("cases: []\n")
    roll = str(EXAMPLES / "vehicle_roll.yaml")
    cases = (
        (["view", fs, str(sweep), "--html", str(html)], "heave exactly once"),
        (["view", fs, roll, "--cases", str(loads), "--html", str(html)], "a list of load cases"),
        (["draw", fs, "-o", str(png), "--from-results", "r.csv:3"], "is a vehicle, drawn at"),
        (["draw", fs, "-o", str(tmp_path / "car.txt")], "car.txt"),
    )
    for args, said in cases:
        assert main(args) == 2, args
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and said in err and "Traceback" not in err, (args, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["loads.yaml", "sweep.yaml"]
