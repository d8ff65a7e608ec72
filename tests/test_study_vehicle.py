"""A study of a whole car (docs/studies.md, docs/vehicle.md): each variant's row its own
sweep's, the left and right corners mirror images, one corner's variables nothing to
another's columns; what a vehicle study refuses."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

from pin_susp import Vehicle, load_sweep
from pin_susp.cli import main
from pin_susp.study import load_study, run_study, variant_data

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
COLUMNS = ["roadwheel_angle_fl", "roadwheel_angle_fr", "camber_fl", "camber_fr"]
COLUMNS += ["roadwheel_angle_rl", "camber_rl"]
COLUMNS += ["wheel_rate_fl", "spring_force_rl"]  # (a rated spring's: worked out when asked)


def vehicle_study(folder: Path, body: dict, sweep: str = "vehicle_roll.yaml") -> Path:
    data = {
        "version": 1,
        "geometry": str(EXAMPLES / "vehicle_fs.yaml"),
        "sweep": str(EXAMPLES / sweep),
    } | body
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def doe(tmp_path_factory):
    """The example vehicle DOE (examples/study_vehicle.yaml) at two levels: the front
    trackrods' inner ends and the left rear toe link's, each ±6 mm; its variants."""
    folder = tmp_path_factory.mktemp("vehicle_doe")
    data = yaml.safe_load((EXAMPLES / "study_vehicle.yaml").read_text())
    data |= {"doe": {"method": "full_factorial", "levels": 2}, "summary": COLUMNS}
    body = {k: v for k, v in data.items() if k not in ("geometry", "sweep")}
    study = load_study(vehicle_study(folder, body))
    return study, run_study(study, folder / "out", scheduler=None).variants


def test_each_vehicle_variant_is_its_own_sweep_of_its_own_file(doe, tmp_path):
    """A variant's row against the car its data describes, written out as a vehicle
    file (both axles inline) and swept as `pin-susp sweep` sweeps it."""
    study, variants = doe
    assert len(variants) == 8 and variants["converged"].all()
    sweep = load_sweep(EXAMPLES / "vehicle_roll.yaml")
    for vid in (0, 5):
        row = variants.iloc[vid]
        data = variant_data(study.geometry_data, study.variables, row[study.names].to_numpy())
        path = tmp_path / f"variant_{vid}.yaml"
        path.write_text(yaml.safe_dump(data, sort_keys=False))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            car = Vehicle(path)
            steps = car.run_sweep(sweep)
            static = car.run_sweep(load_sweep(EXAMPLES / "vehicle_heave.yaml"))
        middle = int(np.argmin(np.abs(static["heave"])))  # heave 0, pitch 0, roll 0
        assert static["heave"][middle] == 0.0
        for m in COLUMNS:
            assert row[f"{m}_min"] == pytest.approx(steps[m].min(), rel=0, abs=1e-12), m
            assert row[f"{m}_max"] == pytest.approx(steps[m].max(), rel=0, abs=1e-12), m
            assert row[f"{m}_static"] == pytest.approx(static[m][middle], rel=0, abs=1e-9), m
        moved = row["d_fl_trackrod_inboard_z"]
        assert data["front"]["hardpoints"]["left"]["trackrod_inboard"]["z"] == 250.0 + moved


def test_left_and_right_variants_are_mirror_images(doe):
    """The car rolled both ways (±2°) is its own mirror image: a variant with the left
    trackrod end at a and the right at b has the left wheel's toe and camber range of
    the variant with them swapped's right wheel."""
    _, variants = doe
    fl, fr = variants["d_fl_trackrod_inboard_z"], variants["d_fr_trackrod_inboard_z"]
    rl = variants["d_rl_toe_link_inboard_z"]
    pairs = 0
    for i in range(len(variants)):
        j = np.flatnonzero((fl == fr[i]) & (fr == fl[i]) & (rl == rl[i]))
        assert len(j) == 1
        a, b = variants.iloc[i], variants.iloc[j[0]]
        for m in ("roadwheel_angle", "camber"):
            for figure in ("min", "max", "static"):
                left, right = a[f"{m}_fl_{figure}"], b[f"{m}_fr_{figure}"]
                assert left == pytest.approx(right, rel=0, abs=1e-9), (m, figure)
        pairs += fl[i] != fr[i]
    assert pairs == 4  # (the others their own mirror)
    spread = variants["roadwheel_angle_fl_max"].max() - variants["roadwheel_angle_fl_max"].min()
    assert spread > 0.1  # deg: ±6 mm of trackrod height steers the wheel in roll


def test_one_corners_variables_leave_the_others_columns(doe):
    """The body's heave, pitch and roll held: a rear toe link moved leaves the front
    wheels' toe and camber as they were, and the front trackrods the rear's."""
    _, variants = doe
    front = [f"{m}_{c}" for m in ("roadwheel_angle", "camber") for c in ("fl", "fr")]
    front = [f"{name}_{f}" for name in front for f in ("min", "max")]
    rear = [f"{m}_rl_{f}" for m in ("roadwheel_angle", "camber") for f in ("min", "max")]
    by_front = variants.groupby(["d_fl_trackrod_inboard_z", "d_fr_trackrod_inboard_z"])
    for _, group in by_front:
        assert len(group) == 2
        assert np.ptp(group[front].to_numpy(), axis=0).max() < 1e-10
    for _, group in variants.groupby("d_rl_toe_link_inboard_z"):
        assert np.ptp(group[rear].to_numpy(), axis=0).max() < 1e-10
    assert np.ptp(variants["roadwheel_angle_rl_max"]) > 0.01


@pytest.mark.parametrize(
    "body, key, problem",
    [
        (
            {"variables": [{"point": "trackrod_inboard", "axis": "z", "range": [-1, 1]}]},
            "variables[0].side",
            "on a vehicle each variable names its corner (fl, fr, rl, rr)",
        ),
        (
            {
                "variables": [
                    {"side": "left", "point": "trackrod_inboard", "axis": "z", "range": [-1, 1]}
                ]
            },
            "variables[0].side",
            "expected one of fl, fr, rl, rr",
        ),
        (
            {
                "variables": [
                    {"side": "rl", "point": "trackrod_inboard", "axis": "z", "range": [-1, 1]}
                ]
            },
            "variables[0].point",
            "unknown hardpoint 'trackrod_inboard'",
        ),
        (
            {
                "variables": [
                    {"side": "fl", "point": "trackrod_inboard", "axis": "z", "range": [-1, 1]}
                ],
                "kind": "optimise",
                "optimise": {"objective": [{"metric": "roadwheel_angle_fl", "target": 0}]},
            },
            "optimise",
            "a vehicle's sweep holds its body on the road",
        ),
    ],
)
def test_what_a_vehicle_study_refuses(tmp_path, capsys, body, key, problem):
    if "kind" not in body:
        body |= {"kind": "doe", "doe": {"method": "full_factorial", "levels": 2}}
    body["summary"] = ["camber_fl"]
    path = vehicle_study(tmp_path, body)
    code = main(["study", str(path), "-o", str(tmp_path / "out"), "--scheduler", "none"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert f"{path}: {key}: " in err and problem in err, err
    assert not (tmp_path / "out").exists()


def test_a_vehicle_monte_carlo_has_no_first_order_prediction(tmp_path):
    """Its sensitivities hold each wheel centre's height in the chassis, its design state
    the body on the road: no prediction beside its spread (it would be off by a first-
    order amount), the spread itself written."""
    body = {
        "variables": [{"side": "fr", "point": "axle_outboard", "axis": "z", "range": [-1, 1]}],
        "kind": "monte_carlo",
        "monte_carlo": {"samples": 3, "seed": 1},
        "summary": ["camber_fr"],
    }
    study = load_study(vehicle_study(tmp_path, body, "vehicle_heave.yaml"))
    outcome = run_study(study, tmp_path / "out", scheduler=None)
    assert outcome.linear is None
    assert outcome.variants["converged"].all()
    assert np.ptp(outcome.variants["camber_fr_static"]) > 0.01  # deg: the spin axis tilted
    from pin_susp.study.plots import study_figure

    notes = [t.get_text() for t in study_figure(study, outcome.variants).texts]
    assert any("a vehicle's design state holds its body on the road" in t for t in notes)


def test_the_summary_columns_units_are_the_sweeps(tmp_path):
    """A rate per degree of roll is deg/deg in variants.parquet's units and on study.png
    (not the deg/mm of a rate in bump), and a vehicle corner's column is labelled by
    its corner."""
    import json

    import pyarrow.parquet as pq

    from pin_susp.study.plots import describe, study_figure

    body = {
        "variables": [{"side": "fl", "point": "trackrod_inboard", "axis": "z", "range": [-2, 2]}],
        "kind": "doe",
        "doe": {"method": "full_factorial", "levels": 2},
        "summary": ["deriv_roadwheel_angle_wrt_roll_fl", "roadwheel_angle_fl"],
    }
    study = load_study(vehicle_study(tmp_path, body))
    outcome = run_study(study, tmp_path / "out", scheduler=None)
    meta = pq.read_schema(tmp_path / "out" / "variants.parquet").metadata
    units = json.loads(meta[b"units"])
    assert units["deriv_roadwheel_angle_wrt_roll_fl_max"] == "deg/deg"
    assert units["roadwheel_angle_fl_static"] == "deg"
    assert units["d_fl_trackrod_inboard_z"] == "mm"
    figure = study_figure(study, outcome.variants)
    titles = [ax.get_title() for ax in figure.axes]
    labels = [ax.get_xlabel() + ax.get_ylabel() for ax in figure.axes]
    assert "deriv_roadwheel_angle_wrt_roll_fl_max [deg/deg]" in titles
    assert not any("deg/mm" in t for t in titles + labels)
    label, unit = describe("camber_rr")
    assert label.endswith("(rear right)") and unit == "deg"


def test_a_run_made_before_an_axle_file_was_edited_is_not_resumed(tmp_path, capsys):
    """The vehicle file names its axle files: a run is another study's once one of them
    is edited (its variants would mix two cars), said in one line."""
    import shutil

    examples = tmp_path / "examples"
    shutil.copytree(EXAMPLES / "vehicle", examples / "vehicle")
    shutil.copy(EXAMPLES / "vehicle_fs.yaml", examples)
    shutil.copy(EXAMPLES / "vehicle_heave.yaml", examples)
    study = examples / "study.yaml"
    body = {
        "version": 1,
        "geometry": "vehicle_fs.yaml",
        "sweep": "vehicle_heave.yaml",
        "variables": [{"side": "rl", "point": "toe_link_inboard", "axis": "z", "range": [-1, 1]}],
        "kind": "doe",
        "doe": {"method": "full_factorial", "levels": 2},
        "summary": ["roadwheel_angle_rl"],
    }
    study.write_text(yaml.safe_dump(body, sort_keys=False))
    out = tmp_path / "out"
    assert main(["study", str(study), "-o", str(out), "--scheduler", "none", "-q"]) == 0
    rear = examples / "vehicle" / "fs_rear.yaml"
    rear.write_text(rear.read_text().replace("z: 275}", "z: 285}", 1))
    capsys.readouterr()
    code = main(["study", str(study), "-o", str(out), "--scheduler", "none", "--resume"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert "fs_rear.yaml was edited" in err


def test_a_study_without_summary_summarises_each_corners_camber_and_toe(tmp_path, capsys):
    """No ``summary``: a corner's camber and toe, on a vehicle each corner's (not an
    error naming a key the file does not have); a geometry whose clearance block
    `pin-susp sweep` refuses is refused by the study too, before any variant."""
    body = {
        "variables": [{"side": "fl", "point": "trackrod_inboard", "axis": "z", "range": [-1, 1]}],
        "kind": "doe",
        "doe": {"method": "full_factorial", "levels": 2},
    }
    study = load_study(vehicle_study(tmp_path, body, "vehicle_heave.yaml"))
    corners = ("fl", "fr", "rl", "rr")
    assert study.summary == [f"{m}_{c}" for m in ("camber", "roadwheel_angle") for c in corners]
    corner = yaml.safe_load((EXAMPLES / "double_wishbone.yaml").read_text())
    corner["clearance"] = {"bodies": 5}
    geometry = tmp_path / "corner.yaml"
    geometry.write_text(yaml.safe_dump(corner))
    path = tmp_path / "corner_study.yaml"
    data = {"version": 1, "geometry": str(geometry), "sweep": str(EXAMPLES / "bump.yaml")}
    data |= {k: v for k, v in body.items() if k != "variables"}
    data["variables"] = [{"point": "trackrod_inboard", "axis": "z", "range": [-1, 1]}]
    path.write_text(yaml.safe_dump(data))
    code = main(["study", str(path), "-o", str(tmp_path / "out"), "--scheduler", "none"])
    err = capsys.readouterr().err
    assert code == 2 and f"{geometry}: clearance.bodies: " in err and err.count("\n") == 1
