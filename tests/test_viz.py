"""What people look at: the meshcat replay in a real browser, the plots, the drawing."""

import os
import re
import shutil
import signal
import subprocess
import sys

import numpy as np
import pytest
from conftest import EXAMPLES, sweep_csv

import pin_susp
from pin_susp.cli import main
from pin_susp.plots import ResultsFile, drawing_figure, panels, report_figure

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

    shot = tmp_path / "shot.png"
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
        "--window-size=1000,700",
        f"--screenshot={shot}",
    ]
    # headless chromium now and then hangs on start-up here: give it three tries
    for attempt in range(3):
        proc = subprocess.Popen(
            [*command, f"--user-data-dir={tmp_path / f'profile{attempt}'}", replay.as_uri()],
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
    assert shot.exists(), "chromium wrote no screenshot"
    rgb = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    assert rgb.std() > 20  # not blank
    orange = (r > 170) & (g > 70) & (g < 170) & (b < 90)  # the upright
    green = (g > r + 50) & (g > b + 30)  # the trackrod and rack
    red = (r > 150) & (g < 90) & (b < 90)  # the coilover
    assert orange.sum() > 100 and green.sum() > 50 and red.sum() > 50


def test_scene_animates_one_frame_per_converged_step():
    from pin_susp.viz import CornerScene

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
    a = ResultsFile(sweep_csv(tmp_path, "double_wishbone.yaml", "bump_steer.yaml", "a.csv"))
    b = ResultsFile(sweep_csv(tmp_path, "pushrod_rocker.yaml", "bump_steer.yaml", "b.csv"))
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
