"""The Python API explains itself (issue 24, point 7): one-line reprs, a DataFrame as
the CSV has it, hardpoints read back in the file's mm, the standard report drawn from
results in memory, the axle at the top level, and docstrings that cite docs/."""

import re

import numpy as np
import pandas as pd
import pytest
from conftest import EXAMPLES, ROOT, example

import pin_susp
from pin_susp.cli import main
from pin_susp.errors import PinSuspError

GEOMETRY = str(EXAMPLES / "double_wishbone.yaml")
SWEEP = str(EXAMPLES / "bump_steer.yaml")
CORNER_FILES = (
    "double_wishbone.yaml",
    "pushrod_rocker.yaml",
    "camber_shim.yaml",
    "fixed_toe_link.yaml",
    "macpherson.yaml",
    "multilink_rear.yaml",
    "multilink_front.yaml",
    "semi_trailing_arm.yaml",
)


@pytest.fixture(scope="module")
def corner():
    return pin_susp.Corner(GEOMETRY)


@pytest.fixture(scope="module")
def results(corner):
    return corner.run_sweep(SWEEP)


def test_corner_results_and_geometry_reprs_say_what_they_are(corner, results):
    assert repr(corner) == (
        "<Corner 'double_wishbone.yaml' 'example corner': double_wishbone, left, rack, 2 inputs>"
    )
    assert repr(results) == (
        "<Results 'bump_steer.yaml' on 'double_wishbone.yaml': "
        f"41 steps, 41 converged, {len(results.columns)} columns>"
    )
    assert len(results.columns) > 80
    assert repr(corner.geometry) == (
        "<Geometry 'double_wishbone.yaml' 'example corner': double_wishbone, left, rack, "
        f"{len(corner.geometry.hardpoints)} hardpoints>"
    )
    rocker = pin_susp.Corner(EXAMPLES / "pushrod_rocker.yaml", warn=False)
    assert "pushrod_rocker, coilover, 2 inputs>" in repr(rocker)
    shimmed = pin_susp.Corner(EXAMPLES / "camber_shim.yaml", warn=False)
    assert ", as set, 2 inputs>" in repr(shimmed)  # the drawn geometry is not as set
    assert "as set" not in repr(pin_susp.load_geometry(EXAMPLES / "camber_shim.yaml"))
    trailing = pin_susp.Corner(EXAMPLES / "semi_trailing_arm.yaml", warn=False)
    assert repr(trailing).endswith(": trailing_arm, left, none, coilover, 1 inputs>")
    # a dict has no file: its name alone
    assert repr(pin_susp.Corner(example("double_wishbone.yaml"))).startswith(
        "<Corner 'example corner': double_wishbone"
    )


def test_reprs_of_failed_empty_and_half_built_objects_do_not_raise():
    failed = pin_susp.Results(
        {
            "step_index": np.arange(8) + 100,  # a chunk's steps count from the sweep's
            "solver_converged": np.array([True, False] * 4),
            "camber": np.full(8, np.nan),
        },
        {},
        {"geometry": ("<dict>", None), "sweep": ("/x/s.yaml", None)},
    )
    assert repr(failed) == (
        "<Results 's.yaml': 8 steps, 4 converged (failed: 101, 103, 105, 107), 3 columns>"
    )
    many = pin_susp.Results(
        {"step_index": np.arange(9), "solver_converged": np.zeros(9, bool)}, {}, {}
    )
    assert "0 converged (failed: 0, 1, 2, 3, 4, ...)" in repr(many)
    assert repr(pin_susp.Results({}, {}, {})) == "<Results: 0 steps, 0 converged, 0 columns>"
    assert repr(pin_susp.Results(None, None, None)) == "<Results>"
    assert repr(pin_susp.Corner.__new__(pin_susp.Corner)) == "<Corner>"
    assert repr(pin_susp.AxleModel.__new__(pin_susp.AxleModel)) == "<AxleModel>"


def test_to_pandas_is_the_csv(results, tmp_path):
    out = tmp_path / "r.csv"
    results.to_csv(out)
    csv = pd.read_csv(out, comment="#")
    frame = results.to_pandas()
    assert list(frame.columns) == list(csv.columns) == list(results.keys())
    assert len(frame) == len(csv) == 41
    for name in csv.columns:  # the very floats (blank cells NaN in both)
        np.testing.assert_array_equal(
            frame[name].to_numpy(dtype=float), csv[name].to_numpy(dtype=float), err_msg=name
        )
    assert frame.attrs["units"]["camber"] == "deg"
    assert frame.attrs["units"]["wheel_center_z"] == "mm"
    # a mapping of its columns: dict(results), `in`; pd.DataFrame(results) says what to use
    assert dict(results).keys() == results.columns.keys() and "camber" in results
    with pytest.raises(TypeError, match=r"results\.to_pandas\(\)"):
        pd.DataFrame(results)
    with pytest.raises(KeyError, match="no column 'nope'"):
        results["nope"]


@pytest.mark.parametrize("name", CORNER_FILES)
def test_hardpoints_read_back_in_the_files_mm(name):
    data = example(name)
    g = pin_susp.load_geometry(EXAMPLES / name)
    mm = g.hardpoints_mm
    assert sorted(mm) == sorted(data["hardpoints"])
    for point, p in data["hardpoints"].items():  # exactly the file's numbers
        assert mm[point].tolist() == [float(p[a]) for a in "xyz"], point
        np.testing.assert_allclose(g.hardpoints[point], mm[point] * 1e-3, rtol=1e-15, atol=0)
    mm["axle_inboard"][0] = 1e9  # a copy: the model's metres are untouched
    assert g.hardpoints["axle_inboard"][0] == float(data["hardpoints"]["axle_inboard"]["x"]) * 1e-3


def test_design_points_in_mm_are_the_derived_points_by_hand():
    data = example("double_wishbone.yaml")
    hp = {k: np.array([float(v[a]) for a in "xyz"]) for k, v in data["hardpoints"].items()}
    wheel = data["config"]["wheel"]
    tire = wheel["tire"]
    a = hp["axle_outboard"] - hp["axle_inboard"]
    a /= np.linalg.norm(a)
    wc = hp["axle_outboard"] - float(wheel.get("offset", 0.0)) * a
    radius = 0.5 * tire["rim_diameter"] * 25.4 + tire["aspect_ratio"] * tire["section_width"]
    down = np.array([0.0, 0.0, -1.0]) - (-a[2]) * a
    cp = wc + radius * down / np.linalg.norm(down)
    points = pin_susp.load_geometry(data).design_points_mm()
    np.testing.assert_allclose(points["wheel_center"], wc, atol=1e-9)
    np.testing.assert_allclose(points["contact_patch_center"], cp, atol=1e-9)


def _figure_content(fig) -> list:
    """What a figure shows: its title, and each panel's title, axis labels and lines."""
    shown = [fig._suptitle.get_text()]
    for ax in fig.axes:
        shown.append((ax.get_title(), ax.get_xlabel(), ax.get_ylabel()))
        shown += [(line.get_label(), line.get_xydata().tolist()) for line in ax.get_lines()]
    return shown


def test_the_report_drawn_from_memory_is_the_clis(results, tmp_path, monkeypatch):
    results.plot(tmp_path / "api.png")
    png = (tmp_path / "api.png").read_bytes()
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and len(png) > 50_000
    drawn = []  # the figures, not rendered again
    monkeypatch.setattr("pin_susp.plots.save_figure", lambda fig, path: drawn.append(fig))
    argv = ["sweep", GEOMETRY, SWEEP, "-o", str(tmp_path / "bump_steer.csv")]
    assert main([*argv, "--plot", str(tmp_path / "cli.png"), "-q"]) == 0
    results.plot(tmp_path / "same.png")  # titled by the sweep's file, as the CLI's by -o's
    results.plot(tmp_path / "named.png", label="my.bump")
    cli, api, named = (_figure_content(fig) for fig in drawn)
    assert api == cli
    assert len(cli) > 20 and cli[0] == "pin_susp kinematics: bump_steer"
    assert named[0] == "pin_susp kinematics: my.bump"  # the legend's label too, no data
    assert named[1:] == [(("my.bump", c[1]) if c[0] == "bump_steer" else c) for c in cli[1:]]


def test_the_report_refuses_before_writing_anything(results, tmp_path):
    with pytest.raises(PinSuspError, match="unsupported image format 'xyz'"):
        results.plot(tmp_path / "r.xyz")
    none = pin_susp.Results(
        {"step_index": np.arange(2), "solver_converged": np.zeros(2, bool)}, {}, {}
    )
    with pytest.raises(PinSuspError, match="no step converged"):
        none.plot(tmp_path / "r.png")
    assert list(tmp_path.iterdir()) == []


def test_the_axle_is_at_the_top_level_like_the_corner(tmp_path):
    from pin_susp.subjects.axle import AxleModel, axle_results, load_axle, solve_axle_sweep

    assert pin_susp.Axle is pin_susp.AxleModel is AxleModel
    assert pin_susp.load_axle is load_axle
    axle = pin_susp.Axle(EXAMPLES / "axle_front.yaml")
    assert repr(axle) == (
        "<AxleModel 'axle_front.yaml' 'front axle with U-bar': double_wishbone, 2 corners, "
        f"rack, pushrod_rocker, coilover, anti-roll u_bar, {axle.mobility} inputs>"
    )
    assert axle.mobility == 3  # two wheels and the rack
    assert repr(axle.axle).startswith("<AxleGeometry 'axle_front.yaml'")
    sweep = pin_susp.load_sweep(EXAMPLES / "roll.yaml")
    results = axle.run_sweep(sweep)
    assert isinstance(results, pin_susp.AxleResults)
    assert repr(results).startswith("<AxleResults 'roll.yaml' on 'axle_front.yaml': 31 steps")
    # the same columns as the module's functions give (the route the CLI takes)
    model = AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))
    direct = axle_results(model, sweep, solve_axle_sweep(model, sweep))
    assert list(direct.keys()) == list(results.keys())
    for name in ("roll", "camber_left", "roll_center_z", "right_wheel_center_z"):
        np.testing.assert_array_equal(results[name], direct[name])
    frame = results.to_pandas()
    assert frame.shape == (31, len(results.columns))
    data = example("axle_front.yaml")
    for point, p in data["hardpoints"]["left"].items():  # each side's hardpoints in mm
        if point in axle.geometries["left"].hardpoints_mm:
            got = axle.axle.left.hardpoints_mm[point].tolist()
            assert got == [float(p[a]) for a in "xyz"], point


def _code_files():
    return sorted((ROOT / "pin_susp").rglob("*.py")) + sorted((ROOT / "tests").glob("*.py"))


def test_the_code_cites_docs_that_exist_never_the_design_spec():
    cited = set()
    for path in _code_files():
        text = path.read_text()
        where = path.relative_to(ROOT)
        assert not re.search(r"\bspec/\w+\.md", text), f"{where} cites spec/ (not in the repo)"
        assert "../" + "shared" not in text and "DESIGN" + ".md" not in text, where
        cited |= set(re.findall(r"\bdocs/[\w/.-]+?\.md\b", text))
    assert {"docs/results.md", "docs/axle.md", "docs/loads.md", "docs/geometry.md"} <= cited
    missing = sorted(c for c in cited if not (ROOT / c).is_file())
    assert missing == []
