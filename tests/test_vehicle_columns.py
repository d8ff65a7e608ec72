"""The whole car's own columns (docs/vehicle.md, "The columns"), each against a
computation of its own from the chassis-frame points the results write and the
vehicle file's numbers read here with yaml:

- anti-dive, anti-lift and anti-squat from side-view instant centres built by hand:
  the double wishbone's two wishbone planes, the MacPherson's lower-arm plane and the
  plane through the top mount normal to the strut, the multilink's side-view pole of
  the upright's velocities (five-point central differences over 0.3 mm of heave);
- the pitch centre where the two axles' lines CP → SVIC meet (numpy's solve);
- the roll axis through the axles' roll centres, and the roll centres themselves from
  the front-view instant centres built the same ways;
- each axle's columns against that axle swept alone to the same chassis-frame
  wheel-centre heights and rack;
- the turning radius from the front wheels' spin axes and the contact patches (with
  the body tilted too: the on-road wheelbase the docs name);
- the mirror symmetry of the roll centres in roll; the FS car's numbers the docs quote.

Each check was run against a mutated pin_susp (a reaction point, a sign, a share, a
line's origin, the CG's x, the design steer, the blank at rack centre, the Ackermann
wheelbase, the corners' order, a MacPherson plane, a multilink pole) and failed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

import pin_susp

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CARS = {"fs": EXAMPLES / "vehicle_fs.yaml", "saloon": EXAMPLES / "vehicle_saloon.yaml"}
ENDS = {"front": ("fl", "fr"), "rear": ("rl", "rr")}
SIGN = {"fl": 1.0, "fr": -1.0, "rl": 1.0, "rr": -1.0}  # s: + left, − right
EPS = 0.3  # mm of heave: a multilink's poles by five-point central differences
# (heave mm, pitch deg, roll deg) where the side- and front-view constructions are checked
POSES = [(0.0, 0.0, 0.0), (12.0, 0.0, 0.0), (-9.0, 0.0, 0.0), (0.0, 0.8, 0.0), (5.0, -0.6, 1.2)]


AXLE_POINTS = ("axle_inboard", "axle_outboard")


def read(path: Path) -> dict:
    return yaml.safe_load(path.read_text())


def config(name) -> dict:
    """The vehicle file's own numbers, read here (not through pin_susp): the
    wheelbase, the CG (x from the front wheel centres' x in the axle file), the brake
    and drive shares and their reaction points (docs/vehicle.md's defaults), and each
    axle's mechanism."""
    path = CARS.get(name, name)  # an example's name, or a vehicle file's path
    car = read(path)
    v = car["vehicle_config"]
    axles = {end: read(path.parent / car[end]) for end in ENDS}
    front = axles["front"]["hardpoints"]["left"]
    inboard, outboard = (np.array([front[k][a] for a in "xyz"]) for k in AXLE_POINTS)
    spin = (outboard - inboard) / np.linalg.norm(outboard - inboard)
    # docs/geometry.md: wheel_center = axle_outboard − offset·â
    wc_x = (outboard - axles["front"]["axle_config"]["wheel"]["offset"] * spin)[0]
    L = float(v["wheelbase"])
    brakes, drive = v.get("brakes", {}), v.get("drive", {})
    bias = brakes.get("front_bias")
    return {
        "L": L,
        "cg_x": wc_x - v["cg"]["x"] * L,
        "cg_z": float(v["cg"]["z"]),
        "type": {end: a["type"] for end, a in axles.items()},
        "brake": {
            "front": (bias, brakes.get("front", "outboard")),
            "rear": (None if bias is None else 1.0 - bias, brakes.get("rear", "outboard")),
        },
        "drive": {end: (drive.get(end), drive.get(f"{end}_type", "inboard")) for end in ENDS},
        "axles": axles,
    }


def body(heave, pitch=0.0, roll=0.0, steer=0.0) -> dict:
    """A vehicle sweep as a dict, one value per step."""
    values = {"heave": heave, "pitch": pitch, "roll": roll, "steering_wheel": steer}
    n = max(len(np.atleast_1d(v)) for v in values.values())
    targets = [
        {"quantity": q, "values": np.broadcast_to(np.asarray(v, float), (n,)).tolist()}
        for q, v in values.items()
    ]
    return {"version": 1, "steps": n, "targets": targets}


def pt(df, label: str, name: str) -> np.ndarray:
    """A written point, chassis frame, mm: (n, 3)."""
    return np.stack([df[f"{label}_{name}_{a}"].to_numpy() for a in "xyz"], axis=1)


def normal(a, b, c) -> np.ndarray:
    return np.cross(b - a, c - a)


def axis_planes(df, label: str, kind: str) -> tuple:
    """Two planes (normal, a point) whose line is the upright's instant axis (docs/
    results.md, Instant centres): the two wishbones' planes (double wishbone), or the
    lower arm's and the plane through the top mount normal to the strut line
    LBJ → strut_top (MacPherson: the upright's point at the mount slides along it)."""
    lbj = pt(df, label, "lower_wishbone_outboard")
    lower = (
        normal(
            pt(df, label, "lower_wishbone_inboard_front"),
            pt(df, label, "lower_wishbone_inboard_rear"),
            lbj,
        ),
        lbj,
    )
    if kind == "double_wishbone":
        ubj = pt(df, label, "upper_wishbone_outboard")
        upper = normal(
            pt(df, label, "upper_wishbone_inboard_front"),
            pt(df, label, "upper_wishbone_inboard_rear"),
            ubj,
        )
        return lower, (upper, ubj)
    assert kind == "macpherson", kind
    top = pt(df, label, "strut_top")
    return lower, (top - lbj, top)


def meet(planes: tuple, axis: int, at: np.ndarray) -> np.ndarray:
    """Where the line of two planes crosses the plane {coordinate ``axis`` = at}: the
    3×3 system [n1; n2; e] X = [n1·p1, n2·p2, at] per step (numpy's solve)."""
    (n1, p1), (n2, p2) = planes
    e = np.zeros_like(n1)
    e[:, axis] = 1.0
    A = np.stack([n1, n2, e], axis=1)
    b = np.stack([np.einsum("ij,ij->i", n1, p1), np.einsum("ij,ij->i", n2, p2), at], axis=1)
    return np.linalg.solve(A, b[..., None])[..., 0]


UPRIGHT = (  # a multilink's points on its upright
    "wheel_center",
    "upper_front_link_outboard",
    "upper_rear_link_outboard",
    "lower_front_link_outboard",
    "lower_rear_link_outboard",
    "toe_link_outboard",
    "axle_outboard",
)


def twist(steps: dict, label: str) -> tuple:
    """The upright's velocity at the wheel centre and its turn rate (per mm of heave),
    from the chassis-frame points at heave + k·EPS, k = −2…2: every point's five-point
    central difference v_i = v + ω × (p_i − WC), least squares for ω."""
    wc = pt(steps[0], label, "wheel_center")
    rate = {
        n: (
            8 * (pt(steps[1], label, n) - pt(steps[-1], label, n))
            - (pt(steps[2], label, n) - pt(steps[-2], label, n))
        )
        / (12 * EPS)
        for n in UPRIGHT
    }
    v = rate["wheel_center"]
    omega = []
    for i in range(len(wc)):
        rows, rhs = [], []
        for n in UPRIGHT[1:]:
            r = pt(steps[0], label, n)[i] - wc[i]
            rows.append(-np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]]))
            rhs.append(rate[n][i] - v[i])
        omega.append(np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0])
    return v, np.array(omega), wc


def instant_centres(cfg: dict, steps: dict) -> dict:
    """label → (SVIC (n, 2) x, z; FVIC (n, 2) y, z), mm, built by hand at each pose."""
    mid = steps[0]
    out = {}
    for end, labels in ENDS.items():
        kind = cfg["type"][end]
        for label in labels:
            wc = pt(mid, label, "wheel_center")
            if kind == "multilink":  # the poles of its bump twist (docs/results.md)
                v, w, wc = twist(steps, label)
                sv = np.stack([wc[:, 0] + v[:, 2] / w[:, 1], wc[:, 2] - v[:, 0] / w[:, 1]], 1)
                fv = np.stack([wc[:, 1] - v[:, 2] / w[:, 0], wc[:, 2] + v[:, 1] / w[:, 0]], 1)
            else:
                planes = axis_planes(mid, label, kind)
                sv = meet(planes, 1, wc[:, 1])[:, [0, 2]]
                fv = meet(planes, 0, wc[:, 0])[:, [1, 2]]
            out[label] = (sv, fv)
    return out


def hand_anti(cfg: dict, df, svic: dict, end: str, share, reaction: str) -> np.ndarray:
    """100 · share · tanθ · L / h per corner, the mean of the axle's two; θ the line
    reaction point → SVIC, rising towards the car's middle; h = CG_z − CP_z."""
    if not share:
        return np.full(len(df), np.nan)
    middle = -1.0 if end == "front" else 1.0  # the SVIC behind the front axle
    per = []
    for label in ENDS[end]:
        cp = pt(df, label, "contact_patch_center")
        at = cp if reaction == "outboard" else pt(df, label, "wheel_center")
        sx, sz = svic[label][0].T
        tan = (sz - at[:, 2]) / (middle * (sx - at[:, 0]))
        per.append(100.0 * share * tan * cfg["L"] / (cfg["cg_z"] - cp[:, 2]))
    return np.mean(per, axis=0)


ANTI = (
    ("anti_dive_front", "front", "brake"),
    ("anti_lift_rear", "rear", "brake"),
    ("anti_squat_rear", "rear", "drive"),
    ("anti_lift_front", "front", "drive"),
)


def posed(path, poses=POSES) -> dict:
    """The car at each pose (frame 0) and k·EPS of heave from it (frames k = ±1, ±2)."""
    heave, pitch, roll = np.array(poses, dtype=float).T
    n, ks = len(poses), (0, 1, -1, 2, -2)
    car = pin_susp.Vehicle(path)
    m = len(ks)
    sweep = body(np.concatenate([heave + k * EPS for k in ks]), np.tile(pitch, m), np.tile(roll, m))
    df = car.run_sweep(sweep).to_pandas()
    assert df["solver_converged"].all()
    return {k: df.iloc[i * n : (i + 1) * n].reset_index(drop=True) for i, k in enumerate(ks)}


@pytest.fixture(scope="module", params=list(CARS))
def car(request):
    name = request.param
    cfg = config(name)
    steps = posed(CARS[name])
    return name, cfg, steps, instant_centres(cfg, steps)


# A plane construction is exact (1e-14 % measured); a multilink's pole from its
# points' five-point differences over EPS is good to ~1e-8 mm (the solver's 1e-12 mm
# residuals over 12·EPS against the stencil's EPS⁴ error: 0.3 mm is about the best).
ANTI_TOL = 1e-6  # %
CENTRE_TOL = 1e-6  # mm


def test_anti_percentages_from_hand_svics(car):
    """(acceptance 5(d)) Each anti % from SVICs built by hand, the reaction point (CP
    outboard, WC inboard), the file's wheelbase, CG height and shares."""
    name, cfg, steps, ic = car
    df = steps[0]
    for column, end, by in ANTI:
        share, reaction = cfg[by][end]
        want = hand_anti(cfg, df, ic, end, share, reaction)
        got = df[column].to_numpy()
        if not share:
            assert np.isnan(got).all(), column  # an axle without a share: blank
            continue
        assert np.isfinite(want).all() and np.abs(want).max() > 1.0, column
        np.testing.assert_allclose(got, want, rtol=0, atol=ANTI_TOL, err_msg=column)


@pytest.mark.parametrize("name", list(CARS))
def test_inboard_front_brakes_react_at_the_wheel_centre(tmp_path, name):
    """vehicle_config.brakes.front: inboard (a copy of the file, its axles' paths made
    absolute): anti-dive from the wheel centre, by the ratio of the two tangents; the
    rear's anti-lift unchanged."""
    cfg = config(name)

    def inboard_brakes(data, front):
        data["vehicle_config"]["brakes"]["front"] = "inboard"

    path = copied(tmp_path, name, inboard_brakes)
    assert config(path)["brake"]["front"][1] == "inboard"
    poses = POSES[:3]
    base, inboard = posed(CARS[name], poses), posed(path, poses)
    ic = instant_centres(cfg, inboard)
    df = inboard[0]
    want = hand_anti(cfg, df, ic, "front", cfg["brake"]["front"][0], "inboard")
    np.testing.assert_allclose(df["anti_dive_front"], want, rtol=0, atol=ANTI_TOL)
    # the same geometry: outboard over inboard is tan θ(CP) / tan θ(WC), corner by corner
    ratio = []
    for label in ENDS["front"]:
        sx, sz = ic[label][0].T
        cp, wc = pt(df, label, "contact_patch_center"), pt(df, label, "wheel_center")
        ratio.append(((sz - cp[:, 2]) / (cp[:, 0] - sx)) / ((sz - wc[:, 2]) / (wc[:, 0] - sx)))
    assert np.ptp(ratio, axis=0).max() < 1e-9  # a symmetric car: both corners alike
    np.testing.assert_allclose(
        base[0]["anti_dive_front"] / df["anti_dive_front"], ratio[0], rtol=1e-9
    )
    assert np.abs(np.array(ratio) - 1.0).min() > 0.05  # the flip matters
    np.testing.assert_allclose(df["anti_lift_rear"], base[0]["anti_lift_rear"], atol=1e-12)


def test_pitch_centre_where_the_side_view_lines_meet(car):
    """pitch_center_x, _z: the crossing of each axle's line from its mean contact patch
    to its mean SVIC (hand SVICs), numpy's 2×2 solve."""
    name, cfg, steps, ic = car
    df = steps[0]
    line = {}
    for end, labels in ENDS.items():
        p = np.mean([pt(df, c, "contact_patch_center")[:, [0, 2]] for c in labels], axis=0)
        s = np.mean([ic[c][0] for c in labels], axis=0)
        line[end] = (p, s - p)
    (pf, df_), (pr, dr) = line["front"], line["rear"]
    A = np.stack([df_, -dr], axis=2)  # pf + a·df = pr + b·dr
    ab = np.linalg.solve(A, (pr - pf)[..., None])[..., 0]
    centre = pf + ab[:, :1] * df_
    np.testing.assert_allclose(df["pitch_center_x"], centre[:, 0], rtol=0, atol=CENTRE_TOL)
    np.testing.assert_allclose(df["pitch_center_z"], centre[:, 1], rtol=0, atol=CENTRE_TOL)


def test_roll_axis_and_roll_centres(car):
    """roll_axis_inclination and roll_axis_height_at_cg through (mean CP x,
    roll_center_z) of each axle and the file's CG x; each roll centre from hand FVICs:
    the lines CP → FVIC of its two sides crossed in front view."""
    name, cfg, steps, ic = car
    df = steps[0]
    x = {
        end: np.mean([pt(df, c, "contact_patch_center")[:, 0] for c in labels], axis=0)
        for end, labels in ENDS.items()
    }
    zf, zr = df["roll_center_z_front"].to_numpy(), df["roll_center_z_rear"].to_numpy()
    slope = (zf - zr) / (x["front"] - x["rear"])
    np.testing.assert_allclose(
        df["roll_axis_inclination"], np.degrees(np.arctan(slope)), rtol=0, atol=1e-12
    )
    np.testing.assert_allclose(
        df["roll_axis_height_at_cg"], zr + slope * (cfg["cg_x"] - x["rear"]), rtol=0, atol=1e-9
    )
    for end, (left, right) in ENDS.items():
        pl = pt(df, left, "contact_patch_center")[:, 1:]
        pr = pt(df, right, "contact_patch_center")[:, 1:]
        dl, dr = ic[left][1] - pl, ic[right][1] - pr
        ab = np.linalg.solve(np.stack([dl, -dr], axis=2), (pr - pl)[..., None])[..., 0]
        rc = pl + ab[:, :1] * dl
        np.testing.assert_allclose(df[f"roll_center_y_{end}"], rc[:, 0], rtol=0, atol=CENTRE_TOL)
        np.testing.assert_allclose(df[f"roll_center_z_{end}"], rc[:, 1], rtol=0, atol=CENTRE_TOL)


def test_the_fs_cars_design_numbers_in_docs_vehicle_md():
    """docs/vehicle.md's FS car at design, from the hand constructions: roll centres
    45.6 and 59.3 mm, 18.0 % anti-dive, 18.6 % anti-lift, 21.1 % anti-squat; and the
    pitch centre's and the roll axis' columns (checked against hand ones above): at
    x = −1 025 mm, 51.0 mm high; 52.0 mm high at the CG, inclined −0.51°."""
    cfg = config("fs")
    steps = posed(CARS["fs"], [(0.0, 0.0, 0.0)])
    one, df = instant_centres(cfg, steps), steps[0]
    for column, end, by, quoted in (
        ("anti_dive_front", "front", "brake", 18.0),
        ("anti_lift_rear", "rear", "brake", 18.6),
        ("anti_squat_rear", "rear", "drive", 21.1),
    ):
        share, reaction = cfg[by][end]
        assert round(hand_anti(cfg, df, one, end, share, reaction)[0], 1) == quoted, column
    for end, quoted in (("front", 45.6), ("rear", 59.3)):
        left, right = ENDS[end]
        pl, pr = (pt(df, c, "contact_patch_center")[0, 1:] for c in (left, right))
        dl, dr = one[left][1][0] - pl, one[right][1][0] - pr
        a = np.linalg.solve(np.stack([dl, -dr], axis=1), pr - pl)[0]
        assert round((pl + a * dl)[1], 1) == quoted, end
    assert round(df["pitch_center_x"].iloc[0]) == -1025
    assert round(df["pitch_center_z"].iloc[0], 1) == 51.0
    assert round(df["roll_axis_height_at_cg"].iloc[0], 1) == 52.0
    assert round(df["roll_axis_inclination"].iloc[0], 2) == -0.51


AXLE_COLUMNS = (
    "heave",
    "roll",
    "body_roll",
    "ride_height_change",
    "track",
    "roll_center_y",
    "roll_center_z",
    "kinematic_roll_center_y",
    "kinematic_roll_center_z",
    "deriv_roll_center_y_wrt_roll",
    "deriv_roll_center_z_wrt_roll",
    "ackermann",
    "roll_stiffness",
)


def in_car(column: str) -> str:
    """An axle's column as the car names it: a rate along the axle's own roll is
    ``_wrt_axle_roll`` there (``_wrt_roll`` is the body's, docs/vehicle.md)."""
    return column.replace("_wrt_roll", "_wrt_axle_roll")


@pytest.mark.parametrize("name", list(CARS))
def test_axle_columns_are_the_axles_own(name):
    """At vehicle roll, heave, pitch and steering steps, each axle swept alone to the
    same chassis-frame wheel-centre heights per side (absolute point targets) and the
    same rack gives the vehicle's _front/_rear columns (to 1e-9)."""
    cfg = config(name)
    df = (
        pin_susp.Vehicle(CARS[name])
        .run_sweep(
            body(
                [0, 0, 0, 10, -8], [0, 0, 0.5, 0, -0.7], [0, 1.5, -1.5, 0, 1.0], [0, 0, 30, -30, 45]
            )
        )
        .to_pandas()
    )
    assert df["solver_converged"].all()
    for end, (left, right) in ENDS.items():
        data = dict(cfg["axles"][end])
        data["vehicle_config"] = {"wheelbase": cfg["L"]}  # Ackermann with the car's
        axle = pin_susp.Axle(data)
        targets = [
            {
                "point": "wheel_center",
                "side": side,
                "direction": {"axis": "z"},
                "mode": "absolute",
                "values": df[f"{label}_wheel_center_z"].tolist(),
            }
            for side, label in (("left", left), ("right", right))
        ]
        if data["axle_config"]["steering"]["type"] == "rack":
            targets.append(
                {
                    "point": "trackrod_inboard",
                    "side": "left",
                    "direction": {"axis": "y"},
                    "mode": "absolute",
                    "values": df[f"{left}_trackrod_inboard_y"].tolist(),
                }
            )
        own = axle.run_sweep({"version": 1, "steps": len(df), "targets": targets}).to_pandas()
        assert own["solver_converged"].all()
        for column in AXLE_COLUMNS:
            if f"{in_car(column)}_{end}" not in df.columns:  # the rear's Ackermann: no rack
                assert column not in own or own[column].isna().all(), column
                continue
            mine = df[f"{in_car(column)}_{end}"].to_numpy()
            np.testing.assert_allclose(mine, own[column], rtol=0, atol=1e-9, err_msg=column)
        for side, label in (("left", left), ("right", right)):
            np.testing.assert_allclose(
                df[f"steer_angle_{label}"], own[f"steer_angle_{side}"], rtol=0, atol=1e-9
            )
        for column in (
            "heave",
            "roll",
            "track",
            "roll_center_y",
            "roll_center_z",
            "kinematic_roll_center_z",
        ):
            assert np.isfinite(df[f"{column}_{end}"]).all(), column  # compared, not blanks
        if "roll_stiffness" in own:
            assert np.isfinite(df[f"roll_stiffness_{end}"]).all()


def yaw(df, label: str) -> np.ndarray:
    """A wheel's heading, rad, + turning left: −s·atan2(a_x, s·a_y) of its spin axis a
    (docs/results.md's roadwheel angle, the axle's steer angle), from the written
    points: (n,)."""
    s = SIGN[label]
    a = pt(df, label, "axle_outboard") - pt(df, label, "axle_inboard")
    return -s * np.arctan2(a[:, 0], s * a[:, 1])


def design_yaw(cfg: dict, label: str) -> float:
    """The heading at design from the front axle file's points (the right's, or the
    left's mirrored where it gives none), rad."""
    hardpoints = cfg["axles"]["front"]["hardpoints"]
    s = SIGN[label]
    side = hardpoints["left"] if s > 0 else hardpoints.get("right")
    flip = 1.0 if s > 0 or side is not None else -1.0
    side = side or hardpoints["left"]
    a = {k: side["axle_outboard"][k] - side["axle_inboard"][k] for k in "xy"}
    return float(-s * np.arctan2(a["x"], s * flip * a["y"]))


def hand_radius(cfg: dict, df, base: np.ndarray) -> np.ndarray:
    """``base`` (mm) over tan of the front wheels' mean heading from design, m."""
    delta = np.mean([yaw(df, c) - design_yaw(cfg, c) for c in ENDS["front"]], axis=0)
    with np.errstate(divide="ignore"):
        return base / np.tan(delta) / 1e3


def road_base(df) -> np.ndarray:
    """The mean wheelbase on the road, mm (docs/vehicle.md: wheelbase_left, _right)."""
    return 0.5 * (df["wheelbase_left"] + df["wheelbase_right"]).to_numpy()


def copied(tmp_path: Path, name: str, change) -> Path:
    """A copy of an example car in tmp_path, its axles' paths absolute; ``change``
    (data, front axle's data) edits it; the front axle copied too."""
    data = read(CARS[name])
    front = read(CARS[name].parent / data["front"])
    for end in ENDS:
        data[end] = str((CARS[name].parent / data[end]).resolve())
    change(data, front)
    data["front"] = str(tmp_path / "front.yaml")
    Path(data["front"]).write_text(yaml.safe_dump(front))
    path = tmp_path / "car.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def toed(data: dict, front: dict) -> None:
    """Toe at design on the left front wheel alone (its own right side written out, the
    left's mirrored): the left spin axis turned by moving axle_inboard 3 mm along x (the
    wheel centre, axle_outboard with offset 0, stays)."""
    assert front["axle_config"]["wheel"]["offset"] == 0
    left = front["hardpoints"]["left"]
    front["hardpoints"]["right"] = {k: {**p, "y": -p["y"]} for k, p in left.items()}
    left["axle_inboard"]["x"] += 3.0


@pytest.mark.parametrize("name", [*CARS, "toed"])
def test_turning_radius_from_the_spin_axes(name, tmp_path):
    """turning_radius: the mean on-road wheelbase over tan of the front wheels' mean
    steer angle from design (the axle file's spin axes: "toed", the FS car with 1.1°
    of toe on its left front wheel alone, tells a design angle from zero), each from
    its spin axis; + turning left
    for a + steering wheel; blank at rack centre. The body level: the chassis frame is
    the road's, and the on-road wheelbase the contact patches' x."""
    path = copied(tmp_path, "fs", toed) if name == "toed" else CARS[name]
    cfg = config(path)
    wheel = np.array([-90.0, -20.0, 0.0, 35.0, 90.0])
    df = pin_susp.Vehicle(path).run_sweep(body(0.0, steer=wheel)).to_pandas()
    cp = {c: pt(df, c, "contact_patch_center")[:, 0] for c in SIGN}
    base = 0.5 * (cp["fl"] - cp["rl"] + cp["fr"] - cp["rr"])
    np.testing.assert_allclose(road_base(df), base, rtol=0, atol=1e-9)
    want, got = hand_radius(cfg, df, base), df["turning_radius"].to_numpy()
    turning = wheel != 0
    assert np.isnan(got[~turning]).all()  # the rack at centre
    np.testing.assert_allclose(got[turning], want[turning], rtol=1e-12)
    assert np.isfinite(got[turning]).all()
    assert np.all(np.sign(got[turning]) == np.sign(wheel[turning]))  # + turning left
    design = [np.degrees(design_yaw(cfg, c)) for c in ENDS["front"]]
    if name == "toed":  # the mean heading at design is not straight ahead
        assert abs(design[0]) > 1.0 and design[1] == 0.0
    else:
        assert design == [0.0, 0.0]  # the examples: straight ahead at design


@pytest.mark.parametrize("name", list(CARS))
def test_turning_radius_on_the_road_with_the_body_tilted(name):
    """Pitched, heaved and rolled while steering: the wheelbase is the road's."""
    cfg = config(name)
    sweep = body([0.0, 15.0, -15.0, 0.0], [1.5, 1.5, -1.5, 0.0], [0.0, 0.0, 0.0, 2.0], 60.0)
    df = pin_susp.Vehicle(CARS[name]).run_sweep(sweep).to_pandas()
    cp = {c: pt(df, c, "contact_patch_center")[:, 0] for c in SIGN}
    chassis = 0.5 * (cp["fl"] - cp["rl"] + cp["fr"] - cp["rr"])
    assert np.abs(road_base(df) - chassis).min() > 0.1  # mm: the tilt matters
    got = df["turning_radius"].to_numpy()  # the road's base (docs/vehicle.md)
    np.testing.assert_allclose(got, hand_radius(cfg, df, road_base(df)), rtol=1e-12)
    assert np.abs(got / hand_radius(cfg, df, chassis) - 1.0).max() > 1e-4  # it matters


@pytest.mark.parametrize("name", list(CARS))
def test_roll_centres_mirror_in_roll(name):
    """Rolled ±2° (a symmetric car), each axle's roll centre height is even in roll
    and its lateral position odd."""
    roll = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
    df = pin_susp.Vehicle(CARS[name]).run_sweep(body(0.0, roll=roll)).to_pandas()
    for end in ENDS:
        for kind in ("", "kinematic_"):
            z = df[f"{kind}roll_center_z_{end}"].to_numpy()
            y = df[f"{kind}roll_center_y_{end}"].to_numpy()
            np.testing.assert_allclose(z, z[::-1], rtol=0, atol=1e-9)
            np.testing.assert_allclose(y, -y[::-1], rtol=0, atol=1e-9)
            assert np.abs(y[0]) > 10.0 and np.ptp(z) > 0.1  # it does migrate


def test_the_axles_roll_rates_and_the_bodys_are_both_written():
    """The axle's rate along its own roll (one wheel up, the other down, the body held)
    and the body's along its roll on the road are two columns, not one overwriting the
    other."""
    car = pin_susp.Vehicle(CARS["fs"])
    df = car.run_sweep(body(0.0, roll=np.array([0.0, 1.0]))).to_pandas()
    axle, on_road = df["deriv_camber_wrt_axle_roll_fl"], df["deriv_camber_wrt_roll_fl"]
    assert np.all(np.isfinite(axle)) and np.all(np.isfinite(on_road))
    assert np.abs(axle - on_road).max() > 1e-3  # two different motions
