"""What people look at: the meshcat replay in a real browser, the plots, the drawing."""

import os
import re
import shutil
import signal
import subprocess
import sys

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example, mirrored, sweep_csv

import pin_susp
from pin_susp.cli import main
from pin_susp.plots import ResultsFile, panels, report_figure
from pin_susp.viz.drawing import drawing_figure

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="module")
def replay(tmp_path_factory):
    out = tmp_path_factory.mktemp("replay") / "replay.html"
    assert (
        main(
            [
                "view",
                str(EXAMPLES / "pushrod_rocker.yaml"),
                str(EXAMPLES / "bump_steer.yaml"),
                "--html",
                str(out),
            ]
        )
        == 0
    )
    return out


def test_replay_makes_no_network_requests(replay):
    html = replay.read_text()
    assert len(html) > 500_000  # the viewer's code is inside the page
    urls = set(re.findall(r"""(?:src|href)\s*=\s*["']?(https?:)?//""", html))
    assert not urls
    external = {
        u
        for u in re.findall(r"https?://[^\s\"'<>)]+", html)
        if not u.startswith("http://www.w3.org/")
    }
    assert not external, sorted(external)[:5]


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (Debian package chromium)")
def test_replay_renders_the_suspension_in_headless_chromium(replay, tmp_path):
    from PIL import Image

    shot = _screenshot(replay, tmp_path)
    assert shot.exists(), "chromium wrote no screenshot"
    rgb = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    assert rgb.std() > 20  # not blank
    orange = (r > 170) & (g > 70) & (g < 170) & (b < 90)  # the upright
    green = (g > r + 50) & (g > b + 30)  # the trackrod and rack
    red = (r > 150) & (g < 90) & (b < 90)  # the coilover
    assert orange.sum() > 100 and green.sum() > 50 and red.sum() > 50


def test_scene_animates_one_frame_per_converged_step():
    from pin_susp.viz.scene import CornerScene

    corner = pin_susp.Corner(EXAMPLES / "camber_shim.yaml")
    results = corner.run_sweep(EXAMPLES / "bump_steer.yaml")
    scene = CornerScene(corner)
    try:
        assert len(scene.robots) == 2  # the drawn geometry as a ghost, and the as-set one
        qs = list(results.meta["q"])
        qs[3] = None  # a step that did not converge is left out
        assert scene.animate(qs) == len(results) - 1
        html = scene.html()
        assert "animation" in html
    finally:
        scene.close()
    assert scene.server.poll() is not None


def test_view_command_serves_and_stops_on_ctrl_c():
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pin_susp.cli",
            "view",
            str(EXAMPLES / "double_wishbone.yaml"),
            str(EXAMPLES / "bump_steer.yaml"),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        first = proc.stdout.readline()
        second = proc.stdout.readline()
        assert first.startswith("meshcat: http://127.0.0.1:") and "41 frames" in first
        assert "Ctrl+C" in second
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert "stopped" in out and "Traceback" not in err


def test_report_has_one_labelled_panel_per_metric_and_a_line_per_file(tmp_path):
    # pure bump (the rack held): a combined sweep is drawn against the step (test_plots.py)
    a = ResultsFile(sweep_csv(tmp_path, "double_wishbone.yaml", "bump_rack_held.yaml", "a.csv"))
    b = ResultsFile(sweep_csv(tmp_path, "pushrod_rocker.yaml", "bump_rack_held.yaml", "b.csv"))
    fig = report_figure([a, b])
    axes = [ax for ax in fig.axes if ax.get_visible()]
    titles = [ax.get_title() for ax in axes]
    expected = panels([a, b], "wheel_travel")
    assert len(axes) == len(expected)
    assert titles[:7] == [
        "Camber",
        "Roadwheel angle (toe, + in)",
        "Caster",
        "Kingpin inclination",
        "Scrub radius",
        "Mechanical trail",
        "Half track",
    ]
    assert "Rocker angle" in titles and "d Camber / d hub z" in titles
    by_title = dict(zip(titles, axes, strict=True))
    assert by_title["Camber"].get_ylabel() == "camber [deg]"
    assert by_title["Scrub radius"].get_ylabel() == "scrub_radius [mm]"
    assert by_title["Camber"].get_xlabel() == "Wheel travel (+ bump) [mm]"
    assert len(by_title["Camber"].get_lines()) == 2  # two designs compared
    assert len(by_title["Rocker angle"].get_lines()) == 1  # only b has a rocker
    line = by_title["Camber"].get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), a["camber"])
    np.testing.assert_allclose(line.get_xdata(), a["wheel_travel"])


def test_steer_sweep_is_plotted_against_the_rack(tmp_path):
    steer = tmp_path / "steer.yaml"
    steer.write_text(
        "steps: 11\ntargets:\n"
        "  - {point: wheel_center, direction: {axis: z}, start: 0, stop: 0}\n"
        "  - {point: trackrod_inboard, direction: {axis: y}, start: -20, stop: 20}\n"
    )
    out = tmp_path / "s.csv"
    assert (
        main(["sweep", str(EXAMPLES / "double_wishbone.yaml"), str(steer), "-o", str(out), "-q"])
        == 0
    )
    fig = report_figure([ResultsFile(out)])
    assert fig.axes[0].get_xlabel().startswith("Rack position")
    titles = [ax.get_title() for ax in fig.axes if ax.get_visible()]
    assert "d Roadwheel angle (toe, + in) / d rack" in titles


def test_plot_and_draw_commands_write_images(tmp_path, capsys):
    csv = sweep_csv(tmp_path, "fixed_toe_link.yaml", "bump.yaml", "r.csv")
    png = tmp_path / "report.png"
    assert main(["plot", str(csv), "-o", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    drawing = tmp_path / "draw.png"
    assert main(["draw", str(EXAMPLES / "camber_shim.yaml"), "-o", str(drawing)]) == 0
    assert drawing.stat().st_size > 10_000
    assert main(["plot", str(EXAMPLES / "bump.yaml"), "-o", str(tmp_path / "x.png")]) == 2
    assert "not a pin_susp results CSV" in capsys.readouterr().err


def test_drawing_has_front_and_side_view_and_the_drawn_ghost():
    fig = drawing_figure(pin_susp.Corner(EXAMPLES / "camber_shim.yaml"))
    titles = [ax.get_title() for ax in fig.axes]
    assert titles == ["Front view", "Side view"]
    assert "as drawn" in fig._suptitle.get_text()
    dashed = [ln for ln in fig.axes[0].get_lines() if ln.get_linestyle() == "--"]
    assert len(dashed) > 5


def test_sweep_plot_option(tmp_path):
    png = tmp_path / "p.png"
    assert (
        main(
            [
                "sweep",
                str(EXAMPLES / "double_wishbone.yaml"),
                str(EXAMPLES / "bump_steer.yaml"),
                "-o",
                str(tmp_path / "r.csv"),
                "--plot",
                str(png),
                "-q",
            ]
        )
        == 0
    )
    assert png.exists()


def test_no_progress_bar_when_not_a_terminal(tmp_path, capfd):
    assert (
        main(
            [
                "sweep",
                str(EXAMPLES / "fixed_toe_link.yaml"),
                str(EXAMPLES / "bump.yaml"),
                "-o",
                str(tmp_path / "r.csv"),
            ]
        )
        == 0
    )
    assert "solving [" not in capfd.readouterr().err


def _screenshot(page, tmp_path, size=(1000, 700)):
    """Headless chromium's screenshot (a PNG's path) of the page after 5 s of virtual time."""
    shot = tmp_path / f"{page.stem}.png"
    command = [
        CHROMIUM,
        "--headless",
        "--no-sandbox",
        "--enable-unsafe-swiftshader",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-extensions",
        "--no-first-run",
        "--run-all-compositor-stages-before-draw",
        "--virtual-time-budget=5000",
        f"--window-size={size[0]},{size[1]}",
        f"--screenshot={shot}",
    ]
    # headless chromium now and then hangs on start-up here: give it three tries
    for attempt in range(3):
        profile = tmp_path / f"profile-{page.stem}-{attempt}"
        proc = subprocess.Popen(
            [*command, f"--user-data-dir={profile}", page.as_uri()],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        try:
            proc.wait(timeout=60)
            break
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return shot


# Only the corner on the page's own (white) background: meshcat's gradient,
# grid and controls, and our ground plane, hidden. The scene's commands are
# applied later (each is a fetch() of a data: URL), so none must show them again.
CORNER_ONLY = """<script>
viewer.set_property(["Background"], "visible", false);
viewer.set_property(["Grid"], "visible", false);
viewer.set_property(["meshcat", "pin_susp", "ground"], "visible", false);
viewer.gui.domElement.style.display = "none";
</script>
</body>"""


@pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed (Debian package chromium)")
@pytest.mark.parametrize("side", ["left", "right"])
def test_replay_frames_the_corner_in_the_middle_of_the_view(side, tmp_path):
    from PIL import Image

    geometry = example("double_wishbone.yaml")
    if side == "right":
        geometry = mirrored(geometry)
    source = tmp_path / f"{side}.yaml"
    source.write_text(yaml.safe_dump(geometry))
    html = tmp_path / f"{side}.html"
    assert main(["view", str(source), "--html", str(html)]) == 0
    page = tmp_path / f"{side}-corner-only.html"
    page.write_text(html.read_text().replace("</body>", CORNER_ONLY, 1))
    shot = _screenshot(page, tmp_path)
    assert shot.exists(), "chromium wrote no screenshot"

    rgb = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    h, w, _ = rgb.shape
    border = np.concatenate([rgb[0], rgb[-1], rgb[:, 0], rgb[:, -1]])
    background = np.median(border, axis=0)
    ys, xs = np.nonzero(np.abs(rgb - background).max(axis=2) > 40)
    assert len(xs) > 5000, "no corner to be seen"
    x0, x1, y0, y1 = xs.min(), xs.max(), ys.min(), ys.max()
    width, height = (x1 - x0 + 1) / w, (y1 - y0 + 1) / h
    middle = ((x0 + x1 + 1) / 2 / w - 0.5, (y0 + y1 + 1) / 2 / h - 0.5)
    seen = f"corner over {width:.0%} × {height:.0%} of the view, its middle off by {middle}"
    assert max(width, height) >= 0.6, seen
    assert abs(middle[0]) <= 0.15 and abs(middle[1]) <= 0.15, seen
    assert x0 > 0 and y0 > 0 and x1 < w - 1 and y1 < h - 1, f"cut by the edge: {seen}"


def _commands(html: str) -> list[dict]:
    """The scene's meshcat commands in a static page (base64 msgpack in data: URLs)."""
    import base64

    import umsgpack

    blobs = re.findall(r'fetch\("data:application/octet-binary;base64,([A-Za-z0-9+/=]*)"\)', html)
    return [umsgpack.unpackb(base64.b64decode(b)) for b in blobs]


def _transform(commands: list[dict], path: str) -> np.ndarray:
    (matrix,) = [
        c["matrix"] for c in commands if c["type"] == "set_transform" and c["path"] == path
    ]
    return np.array(matrix, dtype=float).reshape(4, 4).T  # meshcat sends it column-major


@pytest.mark.parametrize("name", ["double_wishbone", "camber_shim", "right"])
def test_scene_has_the_ground_at_the_contact_patch_and_the_camera_on_the_corner(name):
    from pin_susp.viz.scene import CornerScene, bounds

    if name == "right":
        corner = pin_susp.Corner(mirrored(example("double_wishbone.yaml")))
    else:
        corner = pin_susp.Corner(EXAMPLES / f"{name}.yaml")
    assert (corner.geometry.drawn is not None) == (name == "camber_shim")
    scene = CornerScene(corner)
    try:
        commands = _commands(scene.html())
    finally:
        scene.close()

    (ground,) = [
        c["object"]
        for c in commands
        if c["type"] == "set_object" and c["path"] == "/meshcat/pin_susp/ground"
    ]
    (box,) = ground["geometries"]
    assert box["type"] == "BoxGeometry" and box["width"] >= 1.0 and box["depth"] < 0.01
    (material,) = ground["materials"]
    assert material["transparent"] and material["opacity"] < 1.0
    root = _transform(commands, "/meshcat/pin_susp")  # the corner's frame in the scene
    plane = _transform(commands, "/meshcat/pin_susp/ground")
    patch = corner.design_positions["contact_patch_center"]
    top = plane[2, 3] + box["depth"] / 2
    assert top == pytest.approx(patch[2], abs=1e-6)  # in the corner's frame: the ground
    assert np.all(np.abs(plane[:2, 3] - patch[:2]) < box["width"] / 2 - 0.1)  # under the tyre
    grid = _transform(commands, "/Grid")  # meshcat's grid on the same ground, in the scene
    assert grid[2, 3] == pytest.approx(root[2, 3] + plane[2, 3], abs=1e-6)

    # The camera orbits the scene's origin: a point of the corner near its middle,
    # seen from in front, outboard and above.
    lo, hi = bounds(*(c for c, _ in scene.robots))  # with the ghost, if any
    target = -root[:3, 3]
    assert np.all(target > lo) and np.all(target < hi)
    assert np.linalg.norm(target - (lo + hi) / 2) < 0.2 * np.linalg.norm(hi - lo)
    (position,) = [
        c["value"]
        for c in commands
        if c["type"] == "set_property" and c["path"] == "/Cameras/default/rotated/<object>"
    ]
    eye = np.array([position[0], -position[2], position[1]])  # three.js (y up) to the world's
    assert eye[0] > 0 and corner.geometry.sign * eye[1] > 0 and eye[2] > 0
    assert 0.3 < np.linalg.norm(eye) < 3.0
