"""The car's attitude under steady acceleration (pin_susp/analyses/attitude.py,
`pin-susp attitude`), checked against computations of its own:

- the whole car's Newton–Euler balance at each equilibrium, from the written
  chassis-frame points, the wheel loads and the tyres' forces recomputed from
  vehicle_config (not the virtual work the model solves);
- on a car of equal corners front and rear and no bars (built here from
  fs_front.yaml), the roll gradient, each axle's lateral load transfer and its parts,
  and the TLLTD against the textbook's formulas — and against the same first-order
  theory assembled exactly from the vehicle sweep's own columns;
- left/right mirror symmetry, the design state's statics, the gradients against
  differences of ``solve`` and their signs, the ride frequencies against a difference
  of the springs' lengths along the road's height;
- the command: both example cars, a lifted wheel flagged, bad inputs one line each,
  the g-g plot.
"""

from __future__ import annotations

import copy
import csv
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from pin_susp.analyses.attitude import Accelerations, Attitude, G
from pin_susp.cli import main
from pin_susp.model.sweep import Sweep, Target
from pin_susp.subjects.vehicle import Vehicle

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
CARS = {"fs": EXAMPLES / "vehicle_fs.yaml", "saloon": EXAMPLES / "vehicle_saloon.yaml"}
LABELS = ("fl", "fr", "rl", "rr")
ENDS = {"front": ("fl", "fr"), "rear": ("rl", "rr")}
# (ax, ay) g: standing, cornering, braking, accelerating, trail-braking into a left turn
# (the saloon's rl wheel lifts at -0.7, 0.8: it trail-brakes a little less)
POINTS = {
    "fs": [(0.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.6, 0.0), (-0.7, 0.8)],
    "saloon": [(0.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.6, 0.0), (-0.5, 0.6)],
}


def accelerations(points) -> Accelerations:
    ax, ay = np.array(points, dtype=float).reshape(-1, 2).T
    return Accelerations(ax, ay)


@pytest.fixture(scope="module", params=list(CARS))
def case(request):
    """An example car, its Attitude and its results at POINTS."""
    car = Vehicle(CARS[request.param])
    attitude = Attitude(car)
    points = POINTS[request.param]
    results = attitude.run(accelerations(points))
    assert results["solver_converged"].all(), results.meta["why"]
    return SimpleNamespace(
        name=request.param, car=car, attitude=attitude, points=points, results=results
    )


# ------------------------------------------------------------ the world's geometry


def rotation(pitch: float, roll: float) -> np.ndarray:
    """R_y(θ)·R_x(φ): + pitch nose down, + roll right side down (ISO 8855)."""
    c, s = np.cos(roll), np.sin(roll)
    rx = np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])
    c, s = np.cos(pitch), np.sin(pitch)
    ry = np.array([[c, 0, s], [0, 1.0, 0], [-s, 0, c]])
    return ry @ rx


def pose(results, i: int):
    """The body's (heave m, R) at row i."""
    heave = results["heave"][i] * 1e-3
    return heave, rotation(np.radians(results["pitch"][i]), np.radians(results["roll"][i]))


def in_world(car, results, i: int, name: str) -> np.ndarray:
    """A chassis-frame point of row i on the road: w = c + h·ẑ + R_y(θ)·R_x(φ)·(p − c)."""
    c = car.vehicle.cg
    heave, R = pose(results, i)
    p = np.array([results[f"{name}_{axis}"][i] for axis in "xyz"]) * 1e-3
    return c + np.array([0.0, 0.0, heave]) + R @ (p - c)


def contact_point(car, results, i: int, label: str) -> np.ndarray:
    """The wheel's lowest point on the road: WC + r·unit(a_z·â − ẑ), â the spin axis."""
    wc = in_world(car, results, i, f"{label}_wheel_center")
    spin = in_world(car, results, i, f"{label}_axle_outboard") - in_world(
        car, results, i, f"{label}_axle_inboard"
    )
    spin /= np.linalg.norm(spin)
    down = spin * spin[2] - np.array([0.0, 0.0, 1.0])
    return wc + car.points[f"{label}_contact_patch_center"].radius * down / np.linalg.norm(down)


# ------------------------------------------------------------ the forces, from the file


def masses(car) -> dict:
    """vehicle_config.masses as given: sprung, unsprung per corner, total (kg)."""
    m = car.vehicle.masses
    unsprung = {c: float(m[f"unsprung_{'front' if c[0] == 'f' else 'rear'}"]) for c in LABELS}
    return {"sprung": float(m["sprung"]), "unsprung": unsprung,
            "total": float(m["sprung"]) + sum(unsprung.values())}  # fmt: skip


def lateral_shares(car) -> dict:
    """Each axle's share of the lateral force: the moment about the whole car's CG x
    (the sprung mass at the CG, each unsprung mass at its wheel centre at design)."""
    m, d = masses(car), car.design_positions
    x = {c: d[f"{c}_wheel_center"][0] for c in LABELS}
    xt = (m["sprung"] * car.vehicle.cg[0] + sum(m["unsprung"][c] * x[c] for c in LABELS)) / m[
        "total"
    ]
    xf, xr = (x["fl"] + x["fr"]) / 2, (x["rl"] + x["rr"]) / 2
    front = (xt - xr) / (xf - xr)
    return {"front": front, "rear": 1.0 - front}


def tyre_forces(car, results, i: int, ax: float, ay: float) -> dict:
    """Each contact patch's (F_x, F_y, F_z), N, as docs/vehicle.md defines them: the lateral
    m·ay·g by axle (lateral_shares), left to right in proportion to the wheel loads; the
    longitudinal m·ax·g by the brake bias (ax < 0) or the drive split (ax > 0), half a
    side; F_z the written wheel load."""
    v, total = car.vehicle, masses(car)["total"] * G
    shares = lateral_shares(car)
    out = {}
    for end, (left, right) in ENDS.items():
        fz = {c: results[f"wheel_load_{c}"][i] for c in (left, right)}
        if ax < 0:
            share = v.front_bias if end == "front" else 1.0 - v.front_bias
        else:
            share = v.drive_split[end]
        for c in (left, right):
            fy = total * ay * shares[end] * fz[c] / (fz[left] + fz[right])
            out[c] = np.array([0.5 * total * ax * share, fy, fz[c]])
    return out


def test_whole_car_newton_euler_balance(case):
    """At each equilibrium the car as a whole is in balance (d'Alembert): the tyres'
    forces at the contact points, the sprung mass's weight and inertia m·(−a − g·ẑ) at
    its CG (c + h·ẑ) and each unsprung mass's at its wheel centre — ΣF = 0 (ΣF_z =
    m_total·g), and no moment about the CG's y axis (pitch) nor about the body's x axis
    R·x̂ (roll: the body's roll joint; the yaw is held — the body has no yaw freedom —
    so the moment about z, and with pitch about the road's x, carries the held yaw's
    reaction and is not zero)."""
    car, results = case.car, case.results
    m = masses(car)
    for i, (ax, ay) in enumerate(case.points):
        a = np.array([ax, ay, 0.0]) * G
        heave, R = pose(results, i)
        cg = car.vehicle.cg + np.array([0.0, 0.0, heave])
        loads = [(cg, m["sprung"] * (-a - np.array([0.0, 0.0, G])))]
        for label, force in tyre_forces(car, results, i, ax, ay).items():
            loads.append((contact_point(car, results, i, label), force))
            wc = in_world(car, results, i, f"{label}_wheel_center")
            loads.append((wc, m["unsprung"][label] * (-a - np.array([0.0, 0.0, G]))))
        force = sum(f for _, f in loads)
        moment = sum(np.cross(p - cg, f) for p, f in loads)
        where = f"{case.name} at ax {ax}, ay {ay}"
        np.testing.assert_allclose(force, 0.0, atol=1e-6, err_msg=where)
        assert abs(moment[1]) <= 1e-6, (where, moment)  # pitch, about y
        assert abs(moment @ (R @ [1.0, 0, 0])) <= 1e-6, (where, moment)  # roll


def test_mirror_symmetry(case):
    """ay → −ay mirrors the car: the wheel loads swap left for right, the roll changes
    sign, the heave, the pitch and the TLLTD stay (to 1e-9)."""
    points = [(0.0, 1.0), (0.6, 0.4), (-0.5, 0.6)]
    pairs = [p for ax, ay in points for p in ((ax, ay), (ax, -ay))]
    r = case.attitude.run(accelerations(pairs))
    assert r["solver_converged"].all(), r.meta["why"]
    one, other = slice(0, None, 2), slice(1, None, 2)
    weight = masses(case.car)["total"] * G
    for a, b in (("fl", "fr"), ("rl", "rr")):
        for x, y in ((a, b), (b, a)):
            np.testing.assert_allclose(
                r[f"wheel_load_{x}"][one],
                r[f"wheel_load_{y}"][other],
                rtol=1e-9,
                atol=1e-9 * weight,
            )
    np.testing.assert_allclose(r["roll"][one], -r["roll"][other], rtol=0, atol=1e-9)
    for column in ("heave", "pitch", "tlltd"):
        np.testing.assert_allclose(r[column][one], r[column][other], rtol=0, atol=1e-9)
    for end in ENDS:
        column = f"lateral_load_transfer_{end}"
        np.testing.assert_allclose(r[column][one], -r[column][other], rtol=1e-9, atol=1e-9 * weight)


def test_design_is_the_static_balance(case):
    """(0, 0): no heave, pitch or roll; the wheel loads sum to m_total·g, left equal to
    right, and the front axle's share is the statics' own: moments about the rear axle's
    contact points of the sprung weight at the CG and each unsprung weight at its wheel
    centre, both where the (0, 0) row has them (the saloon's hardpoints put its wheels
    15 and 6 mm into the road: on it, they stand in bump, 0.16 and 0.09 mm further back
    than design_positions says)."""
    car, r = case.car, case.results
    assert case.points[0] == (0.0, 0.0)
    for column in ("heave", "pitch", "roll"):
        assert abs(r[column][0]) <= 1e-9, column
    m = masses(car)
    loads = {c: r[f"wheel_load_{c}"][0] for c in LABELS}
    assert sum(loads.values()) == pytest.approx(m["total"] * G, rel=1e-12)
    assert loads["fl"] == pytest.approx(loads["fr"], rel=1e-12)
    assert loads["rl"] == pytest.approx(loads["rr"], rel=1e-12)
    x = {c: contact_point(car, r, 0, c)[0] for c in LABELS}
    xf, xr = (x["fl"] + x["fr"]) / 2, (x["rl"] + x["rr"]) / 2
    wc = {c: in_world(car, r, 0, f"{c}_wheel_center")[0] for c in LABELS}  # as written
    moment = m["sprung"] * G * (car.vehicle.cg[0] - xr)
    moment += sum(m["unsprung"][c] * G * (wc[c] - xr) for c in LABELS)
    front = moment / (xf - xr)
    assert loads["fl"] + loads["fr"] == pytest.approx(front, rel=1e-9)
    assert r["longitudinal_load_transfer"][0] == pytest.approx(0.0, abs=1e-9)
    assert np.isnan(r["tlltd"][0])  # no lateral transfer: no share of it


# ------------------------------------------------------------ gradients and frequencies


def test_gradients_are_the_equilibria_differences_with_their_signs(case):
    """gradients() (differences at 0.01 g: central for the roll, second-order one-sided
    for the pitch) against the same differences of solve at 0.002 and 0.05 g — their
    truncation errors O(h²): measured 1e-5 and 3e-4 (the saloon's roll), 3e-6 and 8e-5
    (the pitch) — and their signs: ay > 0 (a left turn) rolls the body right side down
    (+) and loads the right wheels; braking pitches the nose down (+ pitch) and moves load
    forward, accelerating the other way; both pitch gradients +."""
    att = case.attitude
    g = att.gradients()
    for h, rel in ((0.002, (3e-5, 1e-5)), (0.05, (1e-3, 3e-4))):
        ax = np.array([0.0, 0.0, 0.0, -h, -2 * h, h, 2 * h])
        s = att.solve(ax, np.array([h, -h, 0.0, 0.0, 0.0, 0.0, 0.0]))
        assert s["converged"].all()
        roll, pitch = np.degrees(s["u"][:, 2]), np.degrees(s["u"][:, 1])
        assert (roll[0] - roll[1]) / (2 * h) == pytest.approx(g["roll_gradient"], rel=rel[0])
        braking = (4 * pitch[3] - pitch[4] - 3 * pitch[2]) / (2 * h)
        traction = -(4 * pitch[5] - pitch[6] - 3 * pitch[2]) / (2 * h)
        assert braking == pytest.approx(g["pitch_gradient_braking"], rel=rel[1])
        assert traction == pytest.approx(g["pitch_gradient_traction"], rel=rel[1])
    assert g["roll_gradient"] > 0 and g["pitch_gradient_braking"] > 0
    assert g["pitch_gradient_traction"] > 0
    r, points = case.results, case.points
    braking, accelerating, cornering = points.index((-1.0, 0.0)), points.index((0.6, 0.0)), 1
    assert r["pitch"][braking] > 0 > r["pitch"][accelerating]
    assert r["roll"][cornering] > 0 and r["lateral_load_transfer_front"][cornering] > 0
    assert r["wheel_load_fr"][cornering] > r["wheel_load_fl"][cornering]
    assert (
        r["longitudinal_load_transfer"][braking] > 0 > r["longitudinal_load_transfer"][accelerating]
    )


def road_sweep(labels, heights_mm) -> Sweep:
    """The body held at design, the road raised under ``labels`` by heights_mm."""
    zero = np.zeros(len(heights_mm))
    targets = [Target(None, None, zero, quantity=q) for q in ("heave", "pitch", "roll")]
    targets += [Target(None, None, heights_mm, side=c, quantity="road_z") for c in labels]
    return Sweep(targets, "<road>")


def test_ride_frequency_from_the_springs_lengths(case):
    """ride_frequency_<end> = √(k_ride / m)/2π, from a vehicle sweep of its own: both
    wheels of the axle raised by the road (−2…2 mm, the body held), the spring's length
    ℓ(z) and the wheel centre's height z_wc(z) at each. The wheel's load is F·(−dℓ/dz) +
    m_u·g·dz_wc/dz (the spring's force F = F₀ + k·(ℓ₀ − ℓ) through its length's rate,
    and the unsprung weight's), so its rate at the contact patch is k·ℓ'² − F₀·ℓ'' +
    m_u·g·z_wc'' (five-point differences); in series with the tyre; on the sprung mass
    the axle's corners carry (the static load / g less the unsprung mass). The U-bar does
    not twist: both wheels rise together."""
    car, att = case.car, case.attitude
    m = masses(car)
    kt = car.vehicle.tyres
    heights = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])  # mm
    h = 1e-3
    for end, (left, right) in ENDS.items():
        r = car.run_sweep(road_sweep((left, right), heights))
        assert r["solver_converged"].all()
        length = r[f"damper_length_{left}"] * 1e-3
        zwc = r[f"{left}_wheel_center_z"] * 1e-3
        first = (length[0] - 8 * length[1] + 8 * length[3] - length[4]) / (12 * h)
        second = lambda f: (-f[0] + 16 * f[1] - 30 * f[2] + 16 * f[3] - f[4]) / (12 * h * h)  # noqa: E731
        i = LABELS.index(left)
        k = car.corners[left].spring_rate * 1e3
        rate = (
            k * first**2 - att.preload[i] * second(length) + m["unsprung"][left] * G * second(zwc)
        )
        tyre = kt[end[0]] * 1e3
        ride = rate * tyre / (rate + tyre)
        mass = case.results[f"wheel_load_{left}"][0] / G - m["unsprung"][left]
        expected = np.sqrt(ride / mass) / (2 * np.pi)
        assert case.results[f"ride_frequency_{end}"][0] == pytest.approx(expected, rel=1e-6), end
        assert 1.0 < expected < 5.0  # a car's, Hz


# ------------------------------------------------------------ equal corners, no bars

SHIFT = -1530.0  # mm: the rear corners are the front's, a wheelbase behind


def equal_axles(folder: Path, preload: dict | None = None) -> Path:
    """A car with equal corners front and rear and no bars: fs_front.yaml (anti_roll
    none) and the same corners shifted by SHIFT in x as the rear (on toe links at the
    trackrods' points), no unsprung masses, rigid tyres (no tyres key). ``preload``:
    each axle's spring preload (N), for the corners' own wheel_rate with it."""
    folder.mkdir(parents=True, exist_ok=True)
    front = yaml.safe_load((EXAMPLES / "vehicle" / "fs_front.yaml").read_text())
    front["axle_config"]["anti_roll"] = {"type": "none"}
    del front["hardpoints"]["center"]
    for bar in ("droplink_rocker", "droplink_u_bar"):
        del front["hardpoints"]["left"][bar]
    rear = copy.deepcopy(front)
    rear["name"] = "rear axle"
    rear["axle_config"]["axle_position"] = "rear"
    rear["axle_config"]["steering"] = {"type": "none"}
    renamed = {"trackrod_inboard": "toe_link_inboard", "trackrod_outboard": "toe_link_outboard"}
    rear["hardpoints"]["left"] = {
        renamed.get(name, name): dict(p, x=p["x"] + SHIFT)
        for name, p in front["hardpoints"]["left"].items()
    }
    car = yaml.safe_load((EXAMPLES / "vehicle_fs.yaml").read_text())
    car["vehicle_config"]["masses"] = {"sprung": 230, "unsprung_front": 0, "unsprung_rear": 0}
    del car["vehicle_config"]["tyres"]
    for end, axle in (("front", front), ("rear", rear)):
        if preload is not None:
            axle["axle_config"]["spring"]["preload"] = float(preload[end])
        (folder / f"{end}.yaml").write_text(yaml.safe_dump(axle))
        car[end] = f"{end}.yaml"
    (folder / "car.yaml").write_text(yaml.safe_dump(car))
    return folder / "car.yaml"


def body_roll(rolls_deg) -> Sweep:
    zero = np.zeros(len(rolls_deg))
    targets = [Target(None, None, zero, quantity=q) for q in ("heave", "pitch")]
    return Sweep(targets + [Target(None, None, np.asarray(rolls_deg), quantity="roll")], "<roll>")


@pytest.fixture(scope="module")
def equal(tmp_path_factory):
    """The equal-corners car, its Attitude, and what the textbook needs of it from the
    vehicle's own sweeps (none of it from the attitude but the springs' preloads):
    - at design, with each spring's preload set to the attitude's F₀: each corner's
      wheel_rate k_w = k·MR² + F₀·dMR/dz (N/m), motion ratio, track t, roll centre
      heights (roll_center_z_<end>, roll_axis_height_at_cg), the wheel centre's travel
      per roll s_φ (deriv_wheel_center_z_wrt_roll);
    - rolled ±0.05° (heave, pitch and the rack held): s_φφ, a difference of the wheel
      centres' heights, and each contact point's lateral motion on the road per roll;
    - the road raised under each corner (body held): the contact patch's lateral scrub
      dy/dz and the wheel centre's rise per road height s_z."""
    folder = tmp_path_factory.mktemp("equal")
    car = Vehicle(equal_axles(folder / "plain"))
    att = Attitude(car)
    preload = {"front": att.preload[0], "rear": att.preload[2]}
    rated = Vehicle(equal_axles(folder / "preloaded", preload))
    design = rated.run_sweep(body_roll([0.0]))
    out = SimpleNamespace(car=car, attitude=att, design=design, side={})
    delta = 0.05  # deg
    rolled = car.run_sweep(body_roll([-delta, 0.0, delta]))
    dphi = np.radians(delta)
    for i, c in enumerate(LABELS):
        s = rolled[f"{c}_wheel_center_z"] * 1e-3
        lateral = [contact_point(car, rolled, j, c)[1] for j in (0, 2)]
        road = car.run_sweep(road_sweep((c,), np.array([-0.01, 0.01])))
        rise = np.diff(road[f"{c}_contact_patch_center_z"])[0]
        side = SimpleNamespace(
            k_w=design[f"wheel_rate_{c}"][0] * 1e3,
            force=att.preload[i] * design[f"motion_ratio_{c}"][0],  # F₀·MR at the wheel
            s_phi=design[f"deriv_wheel_center_z_wrt_roll_{c}"][0] * 1e-3 * 180 / np.pi,
            s_phiphi=(s[0] - 2 * s[1] + s[2]) / dphi**2,
            lever=(lateral[1] - lateral[0]) / (2 * dphi),  # the road's y per roll
            scrub=abs(np.diff(road[f"{c}_contact_patch_center_y"])[0]) / rise,
            s_z=np.diff(road[f"{c}_wheel_center_z"])[0] / rise,
        )
        out.side[c] = side
    out.track = {end: design[f"track_{end}"][0] * 1e-3 for end in ENDS}
    out.h_rc = {end: design[f"roll_center_z_{end}"][0] * 1e-3 for end in ENDS}
    out.h_axis = design["roll_axis_height_at_cg"][0] * 1e-3
    out.mg = masses(car)["total"] * G
    out.h_cg = car.vehicle.cg[2]
    out.shares = lateral_shares(car)
    return out


def test_equal_axles_are_equal(equal):
    """The car is what it says: the same corner at each wheel (the same motion ratio,
    track, roll centre front and rear: a level roll axis at the axles' height)."""
    for c in LABELS:
        assert equal.design[f"motion_ratio_{c}"][0] == pytest.approx(
            equal.design["motion_ratio_fl"][0], rel=1e-12
        )
        assert equal.side[c].scrub == pytest.approx(equal.side["fl"].scrub, rel=1e-6)
    assert equal.track["front"] == pytest.approx(equal.track["rear"], rel=1e-12)
    assert equal.h_rc["front"] == pytest.approx(equal.h_rc["rear"], rel=1e-9)
    assert equal.h_axis == pytest.approx(equal.h_rc["front"], rel=1e-9)
    assert equal.design["roll_axis_inclination"][0] == pytest.approx(0.0, abs=1e-9)


def roll_stiffness(equal, end: str) -> float:
    """The textbook's K_φ of an axle, N·m/rad: Σ k_w·(t/2)², the springs' alone."""
    t = equal.track[end]
    return sum(equal.side[c].k_w * (t / 2) ** 2 for c in ENDS[end])


def test_roll_gradient_against_the_textbook(equal):
    """The roll gradient (gradients(), rad per g here) of the equal-corners car, three
    ways, each closer to the model:

    1. The textbook's m·g·h'/ΣK_φ, h' = h_cg − roll_axis_height_at_cg and K_φ =
       Σ k_w·(t/2)² per axle (k_w the corner's own wheel_rate with the spring's static
       force as its preload: k·MR² + F₀·dMR/dz). It is the first-order form of 2: the
       body's weight, moved sideways h'·φ by the roll, adds m·g·h'·φ to the roll moment,
       which 2 keeps; here 0.56 % of ΣK_φ.
    2. That correction: m·g·h'/(ΣK_φ − m·g·h'). It differs from the model by 1.4 %
       (measured), and not at the small-angle order: its inputs are first-order
       approximations of this linkage's own rates —
       (a) the roll centre: roll_center_z is where the lines from each contact patch
           through the wishbone planes' front-view instant centre cross (45.6 mm);
           the contact patches' own lateral scrub, which the tyres' lateral forces work
           through, puts it at t/2·dy/dz = 49.8 mm (the upright's bump motion is a
           screw — its bump steer and caster change — not a turn about that centre):
           the lever h' is 1.8 % shorter;
       (b) the wheel's travel per roll: the wheel centre moves s_φ = 0.26 % less than
           t/2 (the contact patch rises faster than the wheel centre as the camber
           gain tilts the wheel: r·sin γ·dγ/dz), so the springs' roll stiffness is
           0.5 % less;
       (c) the weight's term: in the model's coordinates (roll about the CG, heave and
           the contact patches on the road) it is the springs' static forces times the
           wheel centres' second-order travel Σ F₀·MR·s_φφ, which m·g·h' approximates
           (0.08 % of the stiffness here).
       Replacing (a) and (b) by the car's own rates leaves (c) alone: 0.07 %.
    3. Exactly, from the vehicle sweep's own columns (no attitude but F₀): the roll
       moment per g is Σ F_y,c·∂y_c/∂φ (each contact patch's lateral motion on the road
       per roll, from the rolled car's written points) and the roll stiffness Σ (k_w·s_φ²
       + F₀·MR·s_φφ) — the second derivative along the roll of the springs' energy with
       the wheels on the road (the weight's is zero: the CG rises with the heave alone).
       The model agrees to 1e-6 (its ±0.01 g differences and s_φφ's)."""
    att, sides = equal.attitude, equal.side
    model = np.radians(att.gradients()["roll_gradient"])  # rad/g
    mg = equal.mg
    h = equal.h_cg - equal.h_axis
    K = roll_stiffness(equal, "front") + roll_stiffness(equal, "rear")
    textbook = mg * h / K
    corrected = mg * h / (K - mg * h)
    # 3: exact
    moment = sum(
        mg * equal.shares["front" if c[0] == "f" else "rear"] / 2 * sides[c].lever for c in LABELS
    )
    stiffness = sum(
        sides[c].k_w * sides[c].s_phi ** 2 + sides[c].force * sides[c].s_phiphi for c in LABELS
    )
    assert model == pytest.approx(moment / stiffness, rel=1e-5)
    # 2 with the car's own lever (a) and wheel travel (b): (c) is left
    lever = moment / mg
    own = sum(sides[c].k_w * sides[c].s_phi ** 2 for c in LABELS)
    assert model == pytest.approx(mg * lever / (own - mg * lever), rel=1.5e-3)
    assert lever == pytest.approx(
        equal.h_cg - equal.track["front"] / 2 * sides["fl"].scrub, rel=1e-6
    )
    # 2 and 1 as the textbook has them
    assert model == pytest.approx(corrected, rel=0.02)
    assert textbook < corrected
    assert model == pytest.approx(textbook, rel=0.02 + mg * h / K)


@pytest.fixture(scope="module")
def gentle(equal):
    """The equal-corners car at ay = 0.02 g (and −0.02)."""
    r = equal.attitude.run(accelerations([(0.0, 0.02), (0.0, -0.02)]))
    assert r["solver_converged"].all()
    return r


def test_load_transfer_at_small_ay_against_the_textbook(equal, gentle):
    """At 0.02 g each axle's lateral load transfer is the textbook's F_y,axle·h_rc/t
    (geometric) + K_φ,axle·φ/t (elastic), φ the body's roll, and the model's columns are
    those two parts (no unsprung masses: no third):

    - _geometric_ is F_y·h/t with h = t/2·dy/dz, the height the contact patches'
      lateral scrub gives (1e-4: at 0.02 g, not at 0); it exceeds F_y·roll_center_z/t
      by their ratio, 49.8/45.6 mm (the wishbone planes' roll centre: see
      test_roll_gradient_against_the_textbook, 2a);
    - _elastic_ is K_φ·φ/t to the wheel's travel per roll (−0.45 % here: 2b); with
      each wheel's own rates — k_w·s_z·|s_φ|·φ, s_z the wheel centre's rise per road
      height — to the preload's mixed term (0.1 %);
    - the total to the textbook's to 2 %: its roll centre is 4 mm low (the geometric
      part 9 % short, the elastic one long by the larger roll it implies)."""
    r = gentle
    phi = np.radians(r["roll"][0])
    ay = r["ay"][0]
    for end, (left, _) in ENDS.items():
        t = equal.track[end]
        fy = equal.mg * ay * equal.shares[end]
        geometric = r[f"lateral_load_transfer_geometric_{end}"][0]
        elastic = r[f"lateral_load_transfer_elastic_{end}"][0]
        total = r[f"lateral_load_transfer_{end}"][0]
        assert r[f"lateral_load_transfer_unsprung_{end}"][0] == pytest.approx(0.0, abs=1e-12)
        assert geometric + elastic == pytest.approx(total, rel=1e-12)
        scrubbed = t / 2 * equal.side[left].scrub
        assert geometric == pytest.approx(fy * scrubbed / t, rel=1e-4), end
        assert geometric / (fy * equal.h_rc[end] / t) == pytest.approx(
            scrubbed / equal.h_rc[end], rel=1e-4
        )
        K = roll_stiffness(equal, end)
        assert elastic == pytest.approx(K * phi / t, rel=0.01), end
        side = equal.side[left]
        assert elastic == pytest.approx(side.k_w * side.s_z * abs(side.s_phi) * phi, rel=2e-3)
        textbook = fy * equal.h_rc[end] / t + K * phi / t
        assert total == pytest.approx(textbook, rel=0.02), end
        # mirrored at −ay
        assert r[f"lateral_load_transfer_{end}"][1] == pytest.approx(-total, rel=1e-9)


def test_tlltd_against_the_textbook_split(equal, gentle):
    """TLLTD = the front's share of the two axles' transfers. From the textbook's parts
    (roll_center_z, K_φ = Σ k_w·(t/2)², the gravity-corrected roll) to 0.2 points; from
    the car's own (the scrub's roll centre, each wheel's own rates, the model's roll) to
    0.01 points. Equal axles: it is the front's share of the lateral force (the
    geometric part) pulled toward 50 % (the elastic part, split by the stiffnesses)."""
    r = gentle
    ay = r["ay"][0]
    mg = equal.mg
    K = {end: roll_stiffness(equal, end) for end in ENDS}
    h = equal.h_cg - equal.h_axis
    phi = mg * h * ay / (sum(K.values()) - mg * h)
    transfer = {
        end: (mg * ay * equal.shares[end] * equal.h_rc[end] + K[end] * phi) / equal.track[end]
        for end in ENDS
    }
    textbook = 100 * transfer["front"] / (transfer["front"] + transfer["rear"])
    assert r["tlltd"][0] == pytest.approx(textbook, abs=0.2)
    phi = np.radians(r["roll"][0])
    own = {}
    for end, (left, _) in ENDS.items():
        side = equal.side[left]
        geometric = mg * ay * equal.shares[end] * side.scrub / 2
        own[end] = geometric + side.k_w * side.s_z * abs(side.s_phi) * phi
    assert r["tlltd"][0] == pytest.approx(100 * own["front"] / sum(own.values()), abs=0.01)
    assert r["tlltd"][1] == pytest.approx(r["tlltd"][0], abs=1e-9)
    assert 50.0 < r["tlltd"][0] < 100 * equal.shares["front"]


# ------------------------------------------------------------ the command


def write(path: Path, data) -> Path:
    path.write_text(yaml.safe_dump(data))
    return path


def read_csv(path: Path) -> list[dict]:
    lines = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    return list(csv.DictReader(lines))


COLUMNS = (
    "ax ay equilibrium_residual wheel_load_fl wheel_load_fr wheel_load_rl wheel_load_rr "
    "lateral_load_transfer_front lateral_load_transfer_rear "
    "lateral_load_transfer_elastic_front lateral_load_transfer_geometric_rear "
    "lateral_load_transfer_unsprung_front longitudinal_load_transfer tlltd roll_gradient "
    "pitch_gradient_braking pitch_gradient_traction ride_frequency_front ride_frequency_rear "
    "roll_frequency heave pitch roll camber_to_ground_fl roll_center_z_front "
    "roll_stiffness_front wheel_rate_fl fl_wheel_center_x solver_converged"
).split()


@pytest.mark.parametrize("name", list(CARS))
def test_cli_writes_every_column(tmp_path, capsys, name):
    accel = write(
        tmp_path / "accel.yaml", {"accelerations": [{"ax": -0.4, "ay": 0.5}, {"ay": 0.3}]}
    )
    out = tmp_path / "attitude.csv"
    assert main(["attitude", str(CARS[name]), str(accel), "-o", str(out)]) == 0
    captured = capsys.readouterr()
    assert "wrote" in captured.out and "roll gradient" in captured.out
    assert captured.err == ""
    rows = read_csv(out)
    assert len(rows) == 2
    for column in COLUMNS:
        assert column in rows[0], column
    assert all(row["solver_converged"] == "True" for row in rows)
    assert float(rows[1]["ax"]) == 0.0 and float(rows[1]["ay"]) == 0.3


def test_cli_flags_a_lifted_wheel(tmp_path, capsys):
    """The FS car trail-braking at −1.5 g into a 1.6 g left turn lifts its inside rear
    wheel: that row is flagged, its cells empty, one warning line, exit code 1; the
    others are written as usual; --plot draws the converged ones."""
    points = [{"ax": 0.0, "ay": 0.5}, {"ax": -1.5, "ay": 1.6}, {"ax": 0.3, "ay": -0.2}]
    accel = write(tmp_path / "accel.yaml", {"accelerations": points})
    out, png = tmp_path / "attitude.csv", tmp_path / "gg.png"
    code = main(["attitude", str(CARS["fs"]), str(accel), "-o", str(out), "--plot", str(png)])
    assert code == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "warning: 1 of 3" in err and "the rl wheel lifts" in err
    rows = read_csv(out)
    assert [row["solver_converged"] for row in rows] == ["True", "False", "True"]
    lifted = rows[1]
    assert float(lifted["ax"]) == -1.5 and float(lifted["ay"]) == 1.6
    for column in ("wheel_load_rl", "heave", "roll", "tlltd", "camber_to_ground_fl"):
        assert lifted[column] == "", column
        assert rows[0][column] != "", column
    import matplotlib.image

    image = matplotlib.image.imread(png)
    assert png.stat().st_size > 0 and image.shape[0] > 100 and image.shape[1] > 100


def bad_vehicle(folder: Path, change) -> Path:
    """The FS car with its axles by absolute path, changed by ``change(data)``."""
    data = yaml.safe_load(CARS["fs"].read_text())
    for end in ENDS:
        data[end] = str(EXAMPLES / "vehicle" / f"fs_{end}.yaml")
    change(data)
    return write(folder / "car.yaml", data)


def without_rate(folder: Path) -> Path:
    rear = yaml.safe_load((EXAMPLES / "vehicle" / "fs_rear.yaml").read_text())
    rear["axle_config"]["spring"] = {"type": "coilover"}
    write(folder / "rear.yaml", rear)
    return bad_vehicle(folder, lambda d: d.update(rear=str(folder / "rear.yaml")))


def grid(steps) -> dict:
    return {"grid": {"ax": {"start": -1, "stop": 1, "steps": steps},
                     "ay": {"start": 0, "stop": 1, "steps": 3}}}  # fmt: skip


# name → (the vehicle (a path, or a function of the folder), the accelerations, the
# file the message names ("accel", "car", "rear" or a path), and what it says)
BAD = {
    "an axle file": (
        EXAMPLES / "vehicle" / "fs_front.yaml",
        {"accelerations": [{"ay": 1}]},
        EXAMPLES / "vehicle" / "fs_front.yaml",
        "scope: attitude takes a vehicle (scope: vehicle): an axle has no body",
    ),
    "a corner file": (
        EXAMPLES / "pushrod_rocker.yaml",
        {"accelerations": [{"ay": 1}]},
        EXAMPLES / "pushrod_rocker.yaml",
        "scope: attitude takes a vehicle (scope: vehicle): a corner has no body",
    ),
    "an unknown key": (
        CARS["fs"],
        {"accelerations": [{"ax": 0, "az": 1}]},
        "accel",
        "accelerations[0].az: unknown key",
    ),
    "a string ax": (
        CARS["fs"],
        {"accelerations": [{"ax": "hard", "ay": 0}]},
        "accel",
        "accelerations[0].ax: expected a number",
    ),
    "|ax| > 5 g": (
        CARS["fs"],
        {"accelerations": [{"ax": 0, "ay": 0}, {"ax": -5.5, "ay": 0}]},
        "accel",
        "accelerations[1].ax: -5.5 g is beyond any car's grip",
    ),
    "an empty list": (
        CARS["fs"],
        {"accelerations": []},
        "accel",
        "accelerations: the list is empty",
    ),
    "no accelerations": (CARS["fs"], {"name": "nothing"}, "accel", "accelerations: give a list"),
    "grid steps 0": (CARS["fs"], grid(0), "accel", "grid.ax.steps: expected a whole number"),
    "grid steps 2.5": (CARS["fs"], grid(2.5), "accel", "grid.ax.steps: expected a whole number"),
    "no masses.sprung": (
        lambda folder: bad_vehicle(folder, lambda d: d["vehicle_config"]["masses"].pop("sprung")),
        {"accelerations": [{"ay": 1}]},
        "car",
        "vehicle_config.masses.sprung: missing key",
    ),
    "a spring without a rate": (
        without_rate,
        {"accelerations": [{"ay": 1}]},
        "rear",
        "axle_config.spring.rate: the attitude needs every spring's rate: the rl corner",
    ),
}


@pytest.mark.parametrize("case_name", list(BAD))
def test_cli_bad_input_gets_one_clear_line(tmp_path, capsys, case_name):
    vehicle, accel, named, says = BAD[case_name]
    vehicle = vehicle(tmp_path) if callable(vehicle) else vehicle
    accel = write(tmp_path / "accel.yaml", accel)
    out, png = tmp_path / "attitude.csv", tmp_path / "gg.png"
    code = main(["attitude", str(vehicle), str(accel), "-o", str(out), "--plot", str(png)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    source = {"accel": accel, "car": tmp_path / "car.yaml", "rear": tmp_path / "rear.yaml"}
    assert f"pin-susp: error: {source.get(named, named)}: {says}" in err, err
    assert not out.exists() and not png.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporaries


def test_the_splits_a_longitudinal_acceleration_needs_and_a_grids_size(tmp_path):
    """Braking without the brakes' split, or driving without the drive's, is one error
    naming the key (not a car that neither brakes nor drives); a bar without its
    stiffness too; a grid of more than 20 000 accelerations is refused before any work."""
    import pin_susp
    from pin_susp.analyses.attitude import Attitude, load_accelerations
    from pin_susp.errors import InputError
    from pin_susp.io.yamlio import load_yaml

    examples = Path(__file__).resolve().parent.parent / "examples"
    data = load_yaml(examples / "vehicle_fs.yaml")[0]
    data["front"], data["rear"] = (
        str(examples / "vehicle" / f"fs_{e}.yaml") for e in ("front", "rear")
    )
    for key, ax in (("brakes", -0.5), ("drive", 0.5)):
        given = {**data, "vehicle_config": dict(data["vehicle_config"])}
        del given["vehicle_config"][key]
        attitude = Attitude(pin_susp.Vehicle(given))
        attitude.equilibria(np.array([0.0]), np.array([1.0]))  # lateral alone: no split needed
        gradients = attitude.gradients()  # the one without its split blank, not ~0
        gone = "pitch_gradient_braking" if key == "brakes" else "pitch_gradient_traction"
        kept = "pitch_gradient_traction" if key == "brakes" else "pitch_gradient_braking"
        assert np.isnan(gradients[gone]) and gradients[kept] > 0.5
        with pytest.raises(InputError, match=f"vehicle_config.{key}"):
            attitude.equilibria(np.array([ax]), np.array([0.0]))
    big = tmp_path / "big.yaml"
    big.write_text(
        "grid:\n  ax: {start: -1, stop: 1, steps: 200}\n  ay: {start: -1, stop: 1, steps: 101}\n"
    )
    with pytest.raises(InputError, match="20,200 accelerations: at most 20,000"):
        load_accelerations(big)
