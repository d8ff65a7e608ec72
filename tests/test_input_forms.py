"""The engineer's forms of a geometry file (issue 27, docs/geometry.md): the wheel by its
centre, static camber and toe; a rocker by its pivot and axis; ``units:`` and
``force_units:`` on geometry, sweep, load-case and study inputs. Each is checked against
the same corner written in the spindle-point, rocker_axis_a/b and mm/N form (converted
here by hand, from the file's own numbers), and the design camber and toe against the
angles the file gives."""

import copy

import numpy as np
import pytest
import yaml
from conftest import EXAMPLES, example, mirrored

import pin_susp
from pin_susp.analyses.loads import member_forces
from pin_susp.errors import InputError
from pin_susp.model.geometry import load_geometry

CORNERS = [
    "double_wishbone.yaml",
    "macpherson.yaml",
    "multilink_front.yaml",
    "multilink_rear.yaml",
    "semi_trailing_arm.yaml",
    "pushrod_rocker.yaml",
    "camber_shim.yaml",
    "fixed_toe_link.yaml",
]
BUMP = [-20.0, 0.0, 15.0, 30.0]
LBF = 0.45359237 * 9.80665  # N
SPINDLE_COLUMNS = ("axle_inboard", "axle_midpoint")  # where the two forms' points differ


def write(path, data):
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def sweep(geometry: dict) -> dict:
    """Bump, and the rack moved too on a corner with a rack."""
    targets = [{"point": "wheel_center", "direction": {"axis": "z"}, "values": BUMP}]
    steering = geometry.get("config", {}).get("steering", {}).get("type", "rack")
    if steering == "rack" and geometry.get("type") != "trailing_arm":
        targets.append(
            {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": [4, 0, -6, 2]}
        )
    return {"version": 1, "targets": targets}


def point(p) -> np.ndarray:
    return np.array([p["x"], p["y"], p["z"]] if isinstance(p, dict) else p, dtype=float)


def by_centre(geometry: dict) -> dict:
    """The corner with its wheel given by its centre, static camber and toe: computed
    here from its spindle points (â = unit(out − in), centre = out − offset·â;
    camber = −atan2(â_z, s·â_y), toe = atan2(â_x, s·â_y), docs/results.md)."""
    g = copy.deepcopy(geometry)
    s = 1.0 if g.get("side", "left") == "left" else -1.0
    inboard, outboard = (point(g["hardpoints"].pop(k)) for k in ("axle_inboard", "axle_outboard"))
    a = (outboard - inboard) / np.linalg.norm(outboard - inboard)
    wheel = g["config"]["wheel"]
    centre = outboard - wheel.get("offset", 0.0) * a
    wheel["center"] = centre.tolist()
    wheel["static_camber"] = float(-np.degrees(np.arctan2(a[2], s * a[1])))
    wheel["static_toe"] = float(np.degrees(np.arctan2(a[0], s * a[1])))
    return g


def run(tmp_path, geometry: dict, name: str, sweep_data: dict | None = None):
    path = write(tmp_path / f"{name}.yaml", geometry)
    return pin_susp.Corner(path).run_sweep(sweep_data or sweep(geometry))


def assert_same(one, other, skip=(), rel=1e-9, atol=1e-9):
    """Every column of two results equal (blank where the other is), but ``skip``."""
    assert list(one.keys()) == list(other.keys())
    compared = 0
    for name in one.keys():
        if any(name.startswith(s) or f"_{s}" in name for s in skip):
            continue
        a, b = (np.asarray(r[name]) for r in (one, other))
        if a.dtype.kind in "OUS":  # a load case's name
            assert a.tolist() == b.tolist(), name
            continue
        np.testing.assert_allclose(
            a.astype(float), b.astype(float), rtol=rel, atol=atol, err_msg=name
        )
        compared += 1
    assert compared > 20


@pytest.mark.parametrize("name", CORNERS)
@pytest.mark.parametrize("side", ["left", "right"])
def test_the_wheel_by_its_centre_sweeps_as_its_spindle_points(tmp_path, name, side):
    g = example(name)
    if side == "right":
        g = mirrored(g)
        for k in ("shim_face_point_a", "shim_face_point_b", "shim_face_normal"):
            shim = g["config"].get("camber_shim")
            if shim:
                shim[k]["y"] = -shim[k]["y"]
    spindle = run(tmp_path, g, "spindle")
    centre = run(tmp_path, by_centre(g), "centre")
    assert_same(spindle, centre, skip=SPINDLE_COLUMNS)
    # the derived spindle: 50 mm apart on the same spin axis, axle_outboard as the file's
    p = load_geometry(tmp_path / "centre.yaml").hardpoints_mm
    q = load_geometry(tmp_path / "spindle.yaml").hardpoints_mm
    assert np.linalg.norm(p["axle_outboard"] - p["axle_inboard"]) == pytest.approx(50.0)
    np.testing.assert_allclose(p["axle_outboard"], q["axle_outboard"], atol=1e-9)
    a, b = (u / np.linalg.norm(u) for u in (p["axle_outboard"] - p["axle_inboard"],
                                            q["axle_outboard"] - q["axle_inboard"]))  # fmt: skip
    np.testing.assert_allclose(a, b, atol=1e-12)


@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("camber, toe", [(-1.5, 0.1), (2.25, -0.7), (0.0, 0.0)])
def test_the_design_camber_and_toe_are_the_static_ones(tmp_path, side, camber, toe):
    """The sweep's design row says the file's angles; and independently, from its
    points: negative camber puts the contact patch outboard of the wheel centre, and
    toe-in turns the spin axis (wheel_outboard − wheel_inboard) forward on either side."""
    g = example("double_wishbone.yaml")
    if side == "right":
        g = mirrored(g)
    g = by_centre(g)
    g["config"]["wheel"] |= {"static_camber": camber, "static_toe": toe}
    r = run(tmp_path, g, "corner", {"version": 1, "targets": sweep(g)["targets"][:1]})
    design = list(BUMP).index(0.0)
    assert r["camber"][design] == pytest.approx(camber, abs=1e-9)
    assert r["roadwheel_angle"][design] == pytest.approx(toe, abs=1e-9)
    s = 1.0 if side == "left" else -1.0
    spin = np.array([r[f"wheel_outboard_{a}"][design] - r[f"wheel_inboard_{a}"][design]
                     for a in "xyz"])  # fmt: skip
    assert np.degrees(np.arctan2(spin[0], abs(spin[1]))) == pytest.approx(toe, abs=1e-9)
    out = s * (r["contact_patch_center_y"][design] - r["wheel_center_y"][design])
    assert np.sign(out) == np.sign(-camber) or camber == 0.0
    assert r["wheel_center_y"][design] == pytest.approx(g["config"]["wheel"]["center"][1])


def test_the_loaded_radius_raises_the_road(tmp_path, capsys):
    """The tyre by its diameter and width: the contact patch is loaded_radius from the
    wheel centre in the wheel plane, diameter/2 − loaded_radius nearer than unloaded;
    the design ride height (wheel centre above the road) is R_l·cos(inclination)."""
    g = by_centre(example("double_wishbone.yaml"))
    g["config"]["wheel"]["tire"] = {"diameter": 464.82, "width": 190}
    unloaded = load_geometry(write(tmp_path / "a.yaml", g))
    g["config"]["wheel"]["tire"]["loaded_radius"] = 225.0
    loaded = load_geometry(write(tmp_path / "b.yaml", g))
    p, q = unloaded.design_points_mm(), loaded.design_points_mm()
    shift = np.linalg.norm(q["contact_patch_center"] - p["contact_patch_center"])
    assert shift == pytest.approx(464.82 / 2 - 225.0, abs=1e-9)
    assert np.linalg.norm(q["contact_patch_center"] - q["wheel_center"]) == pytest.approx(225.0)
    a = q["axle_outboard"] - q["axle_inboard"]
    a_z = a[2] / np.linalg.norm(a)
    assert loaded.design_ride_height * 1e3 == pytest.approx(225.0 * np.sqrt(1 - a_z**2))
    assert loaded.wheel.section_width == pytest.approx(0.190)
    assert loaded.wheel.unloaded_radius == pytest.approx(0.23241)
    from pin_susp.cli import main

    assert main(["setup", str(tmp_path / "b.yaml")]) == 0  # the sheet reports it
    said = f"design ride height {225.0 * np.sqrt(1 - a_z**2):.3f} mm"
    assert said in capsys.readouterr().out
    assert main(["setup", str(tmp_path / "a.yaml")]) == 0
    assert "design ride height" not in capsys.readouterr().out  # no loaded radius given


def errors(tmp_path, geometry) -> str:
    with pytest.raises(InputError) as info:
        load_geometry(write(tmp_path / "corner.yaml", geometry))
    return str(info.value)


def test_the_two_wheel_forms_mixed_or_missing_name_each_other(tmp_path):
    g = example("double_wishbone.yaml")
    both = copy.deepcopy(g)
    both["config"]["wheel"] |= by_centre(g)["config"]["wheel"]
    text = errors(tmp_path, both)
    assert "config.wheel.center: given with hardpoints.axle_inboard" in text
    assert "not both" in text and "\n" not in text
    neither = by_centre(g)
    for k in ("center", "static_camber", "static_toe"):
        del neither["config"]["wheel"][k]
    text = errors(tmp_path, neither)
    assert "hardpoints.axle_inboard: missing point" in text and "config.wheel.center" in text
    partial = by_centre(g)
    del partial["config"]["wheel"]["static_toe"]
    assert "config.wheel.static_toe: missing key" in errors(tmp_path, partial)
    tyre = by_centre(g)
    tyre["config"]["wheel"]["tire"] |= {"diameter": 500, "width": 200}
    assert "not both" in errors(tmp_path, tyre)
    squashed = by_centre(g)
    squashed["config"]["wheel"]["tire"] = {"diameter": 400, "width": 200, "loaded_radius": 210}
    assert "loaded_radius: 210 mm is more than the unloaded radius" in errors(tmp_path, squashed)


# ---------------------------------------------------------------- rockers


def by_pivot(geometry: dict, axis, spacing: float | None = 200.0) -> dict:
    """The rocker by its pivot (midway between rocker_axis_a and b) and ``axis``."""
    g = copy.deepcopy(geometry)
    a, b = (point(g["hardpoints"].pop(k)) for k in ("rocker_axis_a", "rocker_axis_b"))
    g["hardpoints"]["rocker_pivot"] = (0.5 * (a + b)).tolist()
    g["hardpoints"]["rocker_axis"] = axis if isinstance(axis, str) else list(axis)
    if spacing is not None:
        g["actuation"]["bearing_spacing"] = spacing
    return g


LOADS = EXAMPLES / "loads.yaml"


@pytest.mark.parametrize("axis", ["normal_of_plane", [-1, 0, 0], [-3.5, 0, 0]])
@pytest.mark.parametrize("side", ["left", "right"])
def test_a_rocker_by_pivot_and_axis_sweeps_and_loads_as_its_two_points(tmp_path, axis, side):
    """The example's rocker axis a→b runs along −x, 200 mm apart: by its pivot, that
    direction (or the plane through pivot, pushrod and damper ends) and a 200 mm
    bearing spacing, every column — the loads' bearing forces too — is the same."""
    g = example("pushrod_rocker.yaml")
    if side == "right":
        g = mirrored(g)
    ab = write(tmp_path / "ab.yaml", g)
    pivot = write(tmp_path / "pivot.yaml", by_pivot(g, axis))
    bump = sweep(g)
    assert_same(*(pin_susp.Corner(p).run_sweep(bump) for p in (ab, pivot)))
    assert_same(*(member_forces(pin_susp.Corner(p), bump, LOADS) for p in (ab, pivot)))


def test_the_bearing_spacing_sets_the_bearings_and_their_loads(tmp_path):
    """A pivot 40 mm behind the rocker's arms (x = −40): the default 40 mm spacing puts
    a/b at pivot ∓ 20 mm along the axis (written out by hand here), and its bearing
    loads differ from a 200 mm spacing's (docs/loads.md)."""
    g = example("pushrod_rocker.yaml")
    near = copy.deepcopy(g)
    near["hardpoints"]["rocker_axis_a"] = {"x": -20.0, "y": 340, "z": 450}
    near["hardpoints"]["rocker_axis_b"] = {"x": -60.0, "y": 340, "z": 450}
    bump = sweep(g)
    ab = member_forces(pin_susp.Corner(write(tmp_path / "ab.yaml", near)), bump, LOADS)
    default = by_pivot(near, [-1, 0, 0], spacing=None)
    pivot = write(tmp_path / "pivot.yaml", default)
    assert_same(ab, member_forces(pin_susp.Corner(pivot), bump, LOADS))
    wide = write(tmp_path / "wide.yaml", by_pivot(near, [-1, 0, 0], spacing=200.0))
    wide = member_forces(pin_susp.Corner(wide), bump, LOADS)
    bearing = [c for c in ab.keys() if c.startswith("load_rocker_a_bushing")]
    assert len(bearing) == 3
    assert not np.allclose([ab[c] for c in bearing], [wide[c] for c in bearing], atol=1.0)


def test_a_degenerate_rocker_axis_is_an_error(tmp_path):
    g = example("pushrod_rocker.yaml")
    flat = by_pivot(g, "normal_of_plane")
    flat["hardpoints"]["strut_bottom"] = {"x": 0, "y": 340, "z": 480}  # on pivot→pushrod
    text = errors(tmp_path, flat)
    assert "hardpoints.rocker_axis: normal_of_plane" in text and "one line" in text
    assert "hardpoints.rocker_axis: is the zero vector" in errors(tmp_path, by_pivot(g, [0, 0, 0]))
    mixed = by_pivot(g, [-1, 0, 0])
    mixed["hardpoints"]["rocker_axis_a"] = {"x": 100, "y": 340, "z": 450}
    assert "rocker_pivot: given with hardpoints.rocker_axis_a" in errors(tmp_path, mixed)
    spaced = copy.deepcopy(g)
    spaced["actuation"]["bearing_spacing"] = 50
    assert "actuation.bearing_spacing" in errors(tmp_path, spaced)
    zero = by_pivot(g, [-1, 0, 0], spacing=0)
    assert "actuation.bearing_spacing: must be > 0" in errors(tmp_path, zero)


# ---------------------------------------------------------------- axles and vehicles

RACK = {"point": "trackrod_inboard", "side": "left", "direction": {"axis": "y"},
        "values": [0.0, 3.0, -2.0]}  # fmt: skip


def axle_sweep(roll) -> dict:
    """The rack, heave and ``roll`` (deg), three steps."""
    heave = {"quantity": "heave", "values": [-10.0, 0.0, 12.0]}
    return {"version": 1, "targets": [RACK, heave, {"quantity": "roll", "values": roll}]}


def test_an_axle_by_wheel_centre_and_rocker_pivot_sweeps_as_its_points(tmp_path):
    """A mirrored axle (one left side): the wheel by its centre in axle_config.wheel,
    the rocker by its pivot and the plane; and an axle with both sides written out."""
    axle = example("axle_front.yaml")
    side = {"side": "left", "hardpoints": axle["hardpoints"]["left"],
            "config": {"wheel": axle["axle_config"]["wheel"]}}  # fmt: skip
    centre = by_centre(side)
    forms = copy.deepcopy(axle)
    forms["hardpoints"]["left"] = by_pivot(
        {"hardpoints": centre["hardpoints"], "actuation": {}}, "normal_of_plane"
    )["hardpoints"]
    forms["axle_config"]["wheel"] = centre["config"]["wheel"]
    forms["axle_config"]["actuation"]["bearing_spacing"] = 200.0
    heave = axle_sweep([0.0, 0.0, 1.0])
    one, other = (
        pin_susp.Axle(write(tmp_path / f"{n}.yaml", d)).run_sweep(heave)
        for n, d in (("points", axle), ("forms", forms))
    )
    assert_same(one, other, skip=SPINDLE_COLUMNS)
    # both sides written out: the right's centre is the left's mirrored
    explicit = copy.deepcopy(forms)
    right = copy.deepcopy(forms["hardpoints"]["left"])
    for k, p in right.items():
        if isinstance(p, list):
            right[k] = [p[0], -p[1], p[2]]
        elif isinstance(p, dict):
            right[k] = {**p, "y": -p["y"]}
    explicit["hardpoints"]["right"] = right
    other = pin_susp.Axle(write(tmp_path / "explicit.yaml", explicit)).run_sweep(heave)
    assert_same(one, other, skip=SPINDLE_COLUMNS)


# ---------------------------------------------------------------- units

LENGTH = {"millimeters": 1.0, "meters": 1000.0, "inches": 25.4, "in": 25.4}  # mm per unit


def in_units(g: dict, units: str, force: str) -> dict:
    """The pushrod-rocker corner written in ``units`` and ``force`` by hand: every
    length / (mm per unit), the rates / (N/mm per lbf/in), forces / (N per lbf)."""
    g = copy.deepcopy(g)
    k, f = LENGTH[units], (LBF if force == "lbf" else 1.0)
    rate = f / (25.4 if force == "lbf" else 1.0)
    g["units"], g["force_units"] = units, force
    g["hardpoints"] = {n: {a: v / k for a, v in p.items()} for n, p in g["hardpoints"].items()}
    c = g["config"]
    c["cg_position"] = {a: v / k for a, v in c["cg_position"].items()}
    c["wheelbase"] /= k
    c["wheel"]["offset"] = 12.0 / k
    c["wheel"]["tyre"]["rate"] /= rate
    c["setup"] = {n: v / k for n, v in c["setup"].items()}
    g["spring"]["rate"] /= rate
    g["spring"]["preload"] /= f
    return g


@pytest.mark.parametrize(
    "units, force", [("inches", "lbf"), ("meters", "N"), ("inches", "N"), ("in", "lbf")]
)
def test_a_corner_sweep_and_loads_in_other_units_are_the_same(tmp_path, units, force):
    g = example("pushrod_rocker.yaml")
    g["config"]["wheel"]["offset"] = 12.0
    g["config"]["setup"]["pushrod_length_delta"] = 1.5
    k = LENGTH[units]
    bump = sweep(g)
    converted = copy.deepcopy(bump)
    converted["units"] = units
    for t in converted["targets"]:
        t["values"] = [v / k for v in t["values"]]
    loads = yaml.safe_load(LOADS.read_text())
    loads["cases"][0]["moment"] = {"mx": 50.0, "my": -20.0, "mz": 10.0}  # N·m
    in_n = write(tmp_path / "loads_n.yaml", loads)
    loads = copy.deepcopy(loads)
    f = LBF if force == "lbf" else 1.0
    loads["force_units"] = force
    for case in loads["cases"]:
        for part in ("contact_patch", "wheel_center", "moment"):
            per = f * (0.0254 if part == "moment" and force == "lbf" else 1.0)  # lbf·in
            if part in case:
                case[part] = {n: v / per for n, v in case[part].items()}
    mm = pin_susp.Corner(write(tmp_path / "mm.yaml", g))
    other = pin_susp.Corner(write(tmp_path / "other.yaml", in_units(g, units, force)))
    assert_same(mm.run_sweep(bump), other.run_sweep(converted), atol=1e-9)
    one = member_forces(mm, bump, in_n)
    assert_same(one, member_forces(other, converted, write(tmp_path / "l.yaml", loads)))


def test_an_axle_and_a_vehicle_in_meters_and_lbf_are_the_same(tmp_path):
    axle = example("axle_front.yaml")
    metres = copy.deepcopy(axle)
    metres["units"], metres["force_units"] = "meters", "lbf"
    metres["hardpoints"] = {
        s: {n: {a: v / 1000 for a, v in p.items()} for n, p in pts.items()}
        for s, pts in axle["hardpoints"].items()
    }
    metres["vehicle_config"]["cg_position"] = {
        a: v / 1000 for a, v in axle["vehicle_config"]["cg_position"].items()
    }
    metres["vehicle_config"]["wheelbase"] /= 1000
    heave = axle_sweep([0.0, 0.5, 1.0])
    one, other = (
        pin_susp.Axle(write(tmp_path / f"{n}.yaml", d)).run_sweep(heave)
        for n, d in (("mm", axle), ("m", metres))
    )
    assert_same(one, other)
    # a vehicle file in metres and lbf over the example's mm axle files
    v = example("vehicle_fs.yaml")
    c = v["vehicle_config"]
    v["units"], v["force_units"] = "meters", "lbf"
    c["wheelbase"] /= 1000
    c["cg"]["z"] /= 1000
    c["steering"]["c_factor"] /= 1000
    c["tyres"]["vertical"] /= LBF / 25.4
    for end in ("front", "rear"):
        v[end] = str(EXAMPLES / v[end])
    body = {"version": 1, "targets": [{"quantity": q, "values": v} for q, v in (
        ("heave", [-5.0, 8.0]), ("pitch", [0.0, 0.3]), ("roll", [0.0, 1.0]),
        ("steering_wheel", [0.0, 20.0]))]}  # fmt: skip
    one = pin_susp.Vehicle(EXAMPLES / "vehicle_fs.yaml").run_sweep(body)
    car = write(tmp_path / "car.yaml", v)
    assert_same(one, pin_susp.Vehicle(car).run_sweep(body))
    tyres = pin_susp.load_vehicle(car).tyres
    assert tyres == pytest.approx(pin_susp.load_vehicle(EXAMPLES / "vehicle_fs.yaml").tyres)
    assert tyres["f"] == pytest.approx(120.0, rel=1e-12)  # N/mm


def test_an_unknown_unit_is_named(tmp_path):
    g = example("double_wishbone.yaml")
    g["units"] = "furlongs"
    assert "units: expected one of millimeters, meters, inches, mm, m, in" in errors(tmp_path, g)
    g["units"], g["force_units"] = "meters", "kgf"
    assert "force_units: expected one of N, lbf" in errors(tmp_path, g)


def test_a_study_in_inches_is_the_same(tmp_path):
    """A study in inches over a geometry in inches by its wheel centre and a sweep in
    inches: the same variables (mm), targets on a length column (mm, a curve over
    wheel_travel), and a variant that sweeps as the mm study's."""
    from pin_susp.study.spec import load_study
    from pin_susp.study.variants import build, variant_data

    k = 25.4
    geometry = by_centre(example("macpherson.yaml"))
    inches = copy.deepcopy(geometry)
    inches["units"] = "inches"
    inches["hardpoints"] = {
        n: {a: v / k for a, v in p.items()} for n, p in geometry["hardpoints"].items()
    }
    w = inches["config"]["wheel"]
    w["center"] = [v / k for v in w["center"]]
    w["offset"] /= k
    c = inches["config"]
    c["cg_position"] = {a: v / k for a, v in c["cg_position"].items()}
    c["wheelbase"] /= k
    bump = yaml.safe_load((EXAMPLES / "bump_rack_held.yaml").read_text())
    bump_in = copy.deepcopy(bump) | {"units": "inches"}
    for t in bump_in["targets"]:
        t["start"], t["stop"] = t["start"] / k, t["stop"] / k

    def study(name, units, geometry, sweep, f):
        data = {
            "version": 1,
            "geometry": str(write(tmp_path / f"{name}_g.yaml", geometry)),
            "sweep": str(write(tmp_path / f"{name}_s.yaml", sweep)),
            "variables": [{"point": "trackrod_inboard", "axis": "z", "range": [-20 / f, 20 / f]}],
            "kind": "optimise",
            "optimise": {
                "objective": [
                    {"metric": "half_track", "target": 700.0 / f},
                    {
                        "metric": "camber",
                        "curve": {
                            "x": "wheel_travel",
                            "points": [[-25.4 / f, 0.5], [25.4 / f, -1]],
                        },
                    },
                ]  # fmt: skip
            },
        }
        if units:
            data["units"] = units
        return load_study(write(tmp_path / f"{name}.yaml", data))

    mm = study("mm", None, geometry, bump, 1.0)
    other = study("in", "inches", inches, bump_in, k)
    np.testing.assert_allclose([mm.low, mm.high], [other.low, other.high], rtol=1e-12)
    assert mm.low[0] == pytest.approx(-20.0)
    assert other.terms[0].target == pytest.approx(700.0, rel=1e-12)
    np.testing.assert_allclose(other.terms[1].curve, mm.terms[1].curve, rtol=1e-12)
    np.testing.assert_allclose(other.terms[1].curve, [[-25.4, 0.5], [25.4, -1.0]], rtol=1e-12)
    one, two = (
        build(variant_data(s.geometry_data, s.variables, [5.0]), "variant", True).run_sweep(
            s.sweep_data
        )
        for s in (mm, other)
    )
    assert_same(one, two)


def test_the_wheel_centre_example_sweeps_and_loads_as_the_pushrod_rocker(tmp_path):
    """examples/wheel_centre.yaml is examples/pushrod_rocker.yaml by its wheel centre,
    its tyre by diameter (2·(6.5 in + 0.55·270 mm) = 627.2 mm) and its rocker by pivot
    and plane: the same columns and loads, but for its own spindle points."""
    corners = [pin_susp.Corner(EXAMPLES / n) for n in ("pushrod_rocker.yaml", "wheel_centre.yaml")]
    bump = sweep(example("pushrod_rocker.yaml"))
    assert_same(*(c.run_sweep(bump) for c in corners), skip=SPINDLE_COLUMNS)
    assert_same(*(member_forces(c, bump, LOADS) for c in corners), skip=SPINDLE_COLUMNS)
