"""Output sign conventions and units (issue 27, §3–§4; docs/results.md, "Output
conventions and units"): the table applied to a real sweep's CSV against a
transformation done here with numpy from the axes' definitions, the derivative columns'
signs against finite differences of the converted columns, the inch output read back
and converted to mm, the header and the Parquet metadata naming the convention, every
column-writing command taking the options, an unknown convention a one-line error."""

import io
import json

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import yaml
from conftest import EXAMPLES

from pin_susp.cli import _parser, main
from pin_susp.io.conventions import CONVENTIONS, Output
from pin_susp.io.tables import CsvStream, csv_text, write_parquet
from pin_susp.model.geometry import load_geometry
from pin_susp.model.sweep import load_sweep
from pin_susp.subjects.corner import Corner

# each convention's axes, from its definition (docs/results.md): ISO x forward, y left,
# z up; SAE J670 x forward, y right, z down; Lotus x rearward, y right, z up
AXES = {
    "iso": (1, 1, 1),
    "sae": (1, -1, -1),
    "lotus": (-1, -1, 1),
    "optimumk": (1, 1, 1),
}
TOE = {"iso": 1, "sae": 1, "lotus": 1, "optimumk": -1}  # + toe-in, OptimumK + toe-out


def frame(text: str) -> pd.DataFrame:
    return pd.read_csv(io.StringIO(text), comment="#")


def units_of(text: str) -> dict:
    line = next(s for s in text.splitlines() if s.startswith("# units: "))
    return json.loads(line.removeprefix("# units: "))


@pytest.fixture(scope="module")
def bump():
    corner = Corner(load_geometry(EXAMPLES / "double_wishbone.yaml"))
    return corner.run_sweep(load_sweep(EXAMPLES / "bump.yaml"))


@pytest.fixture(scope="module")
def steer(tmp_path_factory):
    path = tmp_path_factory.mktemp("steer") / "steer.yaml"
    sweep = {
        "version": 1,
        "steps": 41,
        "targets": [
            {
                "point": "wheel_center",
                "direction": {"axis": "z"},
                "mode": "relative",
                "start": 0,
                "stop": 0,
            },
            {
                "point": "trackrod_inboard",
                "direction": {"axis": "y"},
                "mode": "relative",
                "start": -20,
                "stop": 20,
            },
        ],
    }
    path.write_text(yaml.safe_dump(sweep))
    corner = Corner(load_geometry(EXAMPLES / "double_wishbone.yaml"))
    return corner.run_sweep(load_sweep(path))


@pytest.mark.parametrize("name", list(CONVENTIONS))
def test_points_and_angles_against_the_axes(bump, name):
    iso = frame(csv_text(bump))
    out = frame(csv_text(bump, Output(name)))
    sx, sy, sz = AXES[name]
    axes = dict(zip("xyz", (sx, sy, sz), strict=True))
    coordinates = [c for c in iso.columns if c[-2:] in ("_x", "_y", "_z") and "_wrt_" not in c]
    assert {"wheel_center_z", "contact_patch_center_y", "svic_x", "fvic_z"} <= set(coordinates)
    for c in coordinates:  # every point and instant centre
        np.testing.assert_array_equal(out[c], axes[c[-1]] * iso[c], err_msg=c)
    np.testing.assert_array_equal(out["roadwheel_angle"], TOE[name] * iso["roadwheel_angle"])
    for same in ("camber", "caster", "kpi", "scrub_radius", "mechanical_trail", "half_track"):
        np.testing.assert_array_equal(out[same], iso[same])
    # Lotus' castor trail (hub) reads + the other way (two Lotus reports, docs/results.md)
    hub = -1 if name == "lotus" else 1
    np.testing.assert_array_equal(out["caster_trail_at_hub"], hub * iso["caster_trail_at_hub"])
    d = "deriv_caster_trail_at_hub_wrt_hub_z"  # d/d hub_z: hub_z flips with z
    np.testing.assert_array_equal(out[d], hub * sz * iso[d])
    np.testing.assert_array_equal(out["wheel_travel"], sz * iso["wheel_travel"])
    np.testing.assert_array_equal(out["rack_displacement"], sy * iso["rack_displacement"])
    np.testing.assert_array_equal(out["step_index"], iso["step_index"])
    assert list(out.columns) == list(iso.columns)


def fd_check(results, name: str, driver_column: str, derivative: str, column: str):
    """The converted derivative column against central differences of the converted
    columns it is the rate of (their steps are 1 mm apart or less)."""
    out = frame(csv_text(results, Output(name)))
    y, x = out[column].to_numpy(), out[driver_column].to_numpy()
    fd = np.gradient(y, x)[2:-2]
    d = out[derivative].to_numpy()[2:-2]
    scale = np.max(np.abs(d))
    assert scale > 1e-4, derivative  # a rate that can change sign
    np.testing.assert_allclose(fd, d, atol=2e-3 * scale)


@pytest.mark.parametrize("name", list(CONVENTIONS))
@pytest.mark.parametrize("metric", ["roadwheel_angle", "camber", "wheel_center_x"])
def test_hub_z_derivatives_are_finite_differences_of_the_converted_columns(bump, name, metric):
    fd_check(bump, name, "wheel_center_z", f"deriv_{metric}_wrt_hub_z", metric)


@pytest.mark.parametrize("name", list(CONVENTIONS))
@pytest.mark.parametrize("metric", ["roadwheel_angle", "camber", "mechanical_trail"])
def test_rack_derivatives_are_finite_differences_of_the_converted_columns(steer, name, metric):
    fd_check(steer, name, "rack_displacement", f"deriv_{metric}_wrt_rack_displacement", metric)


def test_inches_read_back_give_the_mm_output(bump):
    mm, inch = csv_text(bump), csv_text(bump, Output("iso", "in"))
    units_mm, units_in = units_of(mm), units_of(inch)
    assert units_in["wheel_center_z"] == "in" and units_in["camber"] == "deg"
    assert units_in["deriv_camber_wrt_hub_z"] == "deg/in"
    assert units_in["deriv_half_track_wrt_hub_z"] == "in/in"
    a, b = frame(mm), frame(inch)
    factor = {"mm": 25.4, "deg/mm": 1 / 25.4, "mm/mm": 1.0, "mm/rad": 25.4}
    for column, unit in units_mm.items():
        back = b[column].to_numpy() * factor.get(unit, 1.0)  # in → mm, independent of the code
        np.testing.assert_allclose(back, a[column].to_numpy(), rtol=1e-15, atol=0, err_msg=column)


def test_forces_and_rates_in_lbf():
    form = Output("iso", "in")
    assert form.unit("N") == "lbf" and form.unit("N/mm") == "lbf/in"
    assert form.unit("N·m") == "lbf·in" and form.unit("N·m/deg") == "lbf·in/deg"
    lbf = 4.4482216152605  # N
    np.testing.assert_allclose(form.values("force_trackrod", np.array([lbf]), "N"), [1.0])
    np.testing.assert_allclose(form.values("wheel_rate", np.array([lbf / 25.4]), "N/mm"), [1.0])
    np.testing.assert_allclose(form.values("torque_arb", np.array([lbf * 0.0254]), "N·m"), [1.0])
    # a force component flips with its axis, a tension does not
    sae = Output("sae")
    assert sae.values("load_lower_ball_joint_z_left", np.array([2.0]), "N")[0] == -2.0
    assert sae.values("force_rack", np.array([2.0]), "N")[0] == -2.0  # along +y
    assert sae.values("force_trackrod", np.array([2.0]), "N")[0] == 2.0


def test_column_families_by_rule_including_the_new_columns():
    from pin_susp.io.conventions import sign

    sae, lotus, ok = CONVENTIONS["sae"], CONVENTIONS["lotus"], CONVENTIONS["optimumk"]
    assert sign("left_wheel_center_y", lotus) == -1 and sign("wheel_center_x_rl", lotus) == -1
    assert sign("kinematic_roll_center_y_front", sae) == -1
    assert (
        sign("kinematic_roll_center_z", sae) == -1 and sign("kinematic_roll_center_z", lotus) == 1
    )
    for same in ("kingpin_offset_at_hub", "normal_trail", "camber_spatial"):
        assert all(sign(same, c) == 1 for c in CONVENTIONS.values())
    hub = {n: sign("caster_trail_at_hub_fl", c) for n, c in CONVENTIONS.items()}
    assert hub == {"iso": 1, "sae": 1, "lotus": -1, "optimumk": 1}  # Lotus' the other way
    assert sign("trail_in_wheel_axes", ok) == 1 and sign("scrub_in_wheel_axes_left", sae) == 1
    assert sign("steering_wheel_angle", sae) == -1 and sign("steering_wheel_torque", sae) == -1
    assert sign("steering_ratio", sae) == 1
    assert sign("rack_force", lotus) == 1 and sign("rack_force", sae) == -1
    assert sign("steer_angle_fl", ok) == 1 and sign("steer_angle_fr", ok) == -1  # + outward
    assert sign("steer_angle_fl", sae) == -1 and sign("steer_angle_rr", lotus) == 1
    # a derivative: sign(column) · sign(driver)
    assert sign("deriv_roadwheel_angle_wrt_hub_z_left", sae) == -1
    assert sign("deriv_roadwheel_angle_wrt_hub_z", ok) == -1
    assert sign("deriv_roadwheel_angle_wrt_rack_displacement", ok) == -1
    assert sign("deriv_roll_center_z_wrt_axle_roll_front", lotus) == -1


def test_streamed_chunks_are_the_whole_file(bump, tmp_path):
    form = Output("lotus", "in")
    path = tmp_path / "s.csv"
    names = list(bump.columns)
    with CsvStream(path, bump.units, bump.meta, names, len(bump), form) as out:
        for rows in (slice(0, 20), slice(20, None)):
            out.write(type("Chunk", (), {"columns": {n: bump[n][rows] for n in names}})())
    assert path.read_text() == csv_text(bump, form)


def test_header_and_parquet_metadata_name_the_convention(bump, tmp_path):
    text = csv_text(bump, Output("sae", "in"))
    assert "# convention: sae (SAE J670: x forward, y right, z down)" in text
    assert "# convention" not in csv_text(bump)  # the default: the file as before
    write_parquet(bump, tmp_path / "o.parquet", Output("sae", "in"))
    table = pq.read_table(tmp_path / "o.parquet")
    meta = table.schema.metadata
    assert meta[b"convention"] == b"sae" and meta[b"output_units"] == b"in"
    assert json.loads(meta[b"units"])["wheel_center_z"] == "in"
    np.testing.assert_allclose(
        table.column("wheel_center_z").to_numpy(), -np.asarray(bump["wheel_center_z"]) / 25.4
    )
    write_parquet(bump, tmp_path / "d.parquet")
    assert b"convention" not in pq.read_table(tmp_path / "d.parquet").schema.metadata


COMMANDS = {  # every command that writes columns: its arguments, its table
    "sweep": ["examples/double_wishbone.yaml", "examples/bump.yaml", "-o", "{out}/o.csv"],
    "loads": [
        "examples/macpherson.yaml",
        "examples/bump.yaml",
        "--cases",
        "examples/loads.yaml",
        "-o",
        "{out}/o.csv",
    ],
    "setup": ["examples/camber_shim.yaml", "--shim", "15,20", "--csv", "{out}/o.csv"],
    "sensitivity": ["examples/double_wishbone.yaml", "-o", "{out}/o.csv"],
    "attitude": ["examples/vehicle_fs.yaml", "examples/vehicle_attitude.yaml", "-o", "o.csv"],
    "demo": ["-o", "{out}"],
}
RUN = ("sweep", "loads", "setup", "sensitivity")  # run here; the others parsed


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_command_takes_the_options(command, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(EXAMPLES.parent)
    argv = [command, *(a.format(out=tmp_path) for a in COMMANDS[command])]
    argv += ["--convention", "lotus", "--units", "in"]
    args = _parser().parse_args(argv)
    assert (args.convention, args.units) == ("lotus", "in")
    if command not in RUN:
        return
    assert main([*argv, "-q"] if command in ("sweep", "loads", "sensitivity") else argv) == 0
    text = (tmp_path / "o.csv").read_text()
    assert "# convention: lotus" in text, command
    assert "units: lengths in, forces lbf" in text, command


def test_sensitivity_values_follow_the_coordinates_axis(tmp_path, monkeypatch):
    monkeypatch.chdir(EXAMPLES.parent)
    base = ["sensitivity", "examples/double_wishbone.yaml", "-q", "-o"]
    assert main([*base, str(tmp_path / "iso.csv")]) == 0
    assert main([*base, str(tmp_path / "lotus.csv"), "--convention", "lotus"]) == 0
    iso = pd.read_csv(tmp_path / "iso.csv", comment="#")
    lotus = pd.read_csv(tmp_path / "lotus.csv", comment="#")
    sign = {"x": -1, "y": -1, "z": 1}  # Lotus' axes; camber's sign is +1 in every one
    rows = iso["metric"] == "camber"
    expect = iso.loc[rows, "value"] * iso.loc[rows, "axis"].map(sign)
    np.testing.assert_array_equal(lotus.loc[rows, "value"], expect)


def test_the_options_name_the_modules_conventions():
    from pin_susp.cli import options
    from pin_susp.io import conventions

    assert options.CONVENTIONS == tuple(conventions.CONVENTIONS)
    assert options.UNITS == conventions.UNITS


def test_an_unknown_convention_is_a_one_line_error(capsys):
    assert main(["sweep", "g.yaml", "s.yaml", "-o", "o.csv", "--convention", "jis"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "jis" in err and "lotus" in err


def test_a_study_file_names_its_convention(tmp_path):
    from pin_susp.errors import PinSuspError
    from pin_susp.study.spec import load_study

    data = yaml.safe_load((EXAMPLES / "study_bump_steer.yaml").read_text())
    for key in ("geometry", "sweep"):
        data[key] = str(EXAMPLES / data[key])
    data["conventions"] = "lotus"
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    assert load_study(tmp_path / "s.yaml").convention == "lotus"
    data["conventions"] = "jis"
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(data))
    with pytest.raises(PinSuspError, match="conventions"):
        load_study(tmp_path / "s.yaml")


def test_a_studys_variants_min_and_max_swap_where_the_sign_flips():
    from pin_susp.study.folder import in_convention

    table = pa.table(
        {
            "variant_id": [0, 1],
            "d_trackrod_inboard_y": [1.0, -2.0],
            "roadwheel_angle_min": [-0.5, 0.1],
            "roadwheel_angle_max": [0.7, 0.2],
            "camber_min": [-2.0, -1.0],
        }
    )
    out = in_convention(table, Output("optimumk"))  # toe: + out
    assert out.column("roadwheel_angle_min").to_pylist() == [-0.7, -0.2]
    assert out.column("roadwheel_angle_max").to_pylist() == [0.5, -0.1]
    assert out.column("camber_min").to_pylist() == [-2.0, -1.0]
    lotus = in_convention(table, Output("lotus"))
    assert lotus.column("d_trackrod_inboard_y").to_pylist() == [-1.0, 2.0]


def test_a_study_in_lotus_axes_is_the_iso_one_turned(tmp_path):
    from pin_susp.study import load_study, run_study

    body = {
        "version": 1,
        "geometry": str(EXAMPLES / "double_wishbone.yaml"),
        "sweep": str(EXAMPLES / "bump_rack_held.yaml"),
        "variables": [{"point": "trackrod_inboard", "axis": "y", "range": [-5, 5]}],
        "kind": "doe",
        "doe": {"method": "latin_hypercube", "samples": 3, "seed": 3},
        "summary": ["camber", "roadwheel_angle", "wheel_center_x"],
    }
    tables = {}
    for name in ("iso", "lotus"):
        path = tmp_path / f"{name}.yaml"
        path.write_text(yaml.safe_dump(body | {"conventions": name}))
        out = tmp_path / name
        run_study(load_study(path), out, scheduler=None, steps=True)
        tables[name] = (
            pq.read_table(out / "variants.parquet"),
            pd.read_parquet(out / "steps.parquet"),
        )
    (iso, iso_steps), (lotus, lotus_steps) = tables["iso"], tables["lotus"]
    assert lotus.schema.metadata[b"convention"] == b"lotus"
    assert b"convention" not in iso.schema.metadata
    col = lambda t, n: np.asarray(t.column(n).to_pylist(), dtype=float)  # noqa: E731
    np.testing.assert_array_equal(
        col(lotus, "d_trackrod_inboard_y"), -col(iso, "d_trackrod_inboard_y")
    )
    # x rearward: the wheel centre's x flips, its min and max swap; toe and camber stay
    np.testing.assert_array_equal(col(lotus, "wheel_center_x_min"), -col(iso, "wheel_center_x_max"))
    np.testing.assert_array_equal(col(lotus, "wheel_center_x_max"), -col(iso, "wheel_center_x_min"))
    np.testing.assert_array_equal(col(lotus, "camber_min"), col(iso, "camber_min"))
    for c, s in (("wheel_center_x", -1), ("wheel_center_y", -1), ("wheel_center_z", 1)):
        np.testing.assert_array_equal(lotus_steps[c], s * iso_steps[c])
    np.testing.assert_array_equal(lotus_steps["roadwheel_angle"], iso_steps["roadwheel_angle"])


@pytest.mark.parametrize("option", [["--units", "in"], ["--convention", "lotus"]])
def test_plot_refuses_a_file_written_in_another_convention_or_units(tmp_path, capsys, option):
    """The report's labels are ISO's in mm: a converted file is refused, not mislabelled."""
    geometry, sweep = str(EXAMPLES / "double_wishbone.yaml"), str(EXAMPLES / "bump.yaml")
    assert main(["sweep", geometry, sweep, "-o", "out.csv", "-q", *option]) == 0
    capsys.readouterr()
    assert main(["plot", "out.csv", "-o", "report.png"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "written in convention" in err and option[1] in err
    assert not (tmp_path / "report.png").exists()
    assert main(["sweep", geometry, sweep, "-o", "iso.csv", "-q"]) == 0
    assert main(["plot", "iso.csv", "-o", "report.png"]) == 0
