"""Clearance and the wheel envelope (docs/clearance.md): coal's distances against closed
forms and a brute-force sampling of the shapes' surfaces, the table against its
summary, the envelope closed and round every tyre pose, the clearance: key's errors."""

import re

import numpy as np
import pandas as pd
import pytest
import yaml
from conftest import EXAMPLES

from pin_susp.analyses.clearance import Clearance, ClearanceRun, ring_distance
from pin_susp.analyses.clearance_shapes import Poses, wheel_rings
from pin_susp.cli import main
from pin_susp.model.clearance_bodies import ClearanceBody
from pin_susp.model.sweep import Sweep, Target
from pin_susp.subjects.subject import load_subject

PACKAGING = EXAMPLES / "packaging.yaml"
GRID = EXAMPLES / "packaging_grid.yaml"


@pytest.fixture(scope="module")
def corner():
    return load_subject(PACKAGING)


def _grid(bumps, racks) -> Sweep:
    b, r = np.meshgrid(bumps, racks)
    return Sweep(
        [Target("wheel_center", "z", b.ravel()), Target("trackrod_inboard", "y", r.ravel())],
        "grid",
    )


def _qs(results):
    return [
        q if ok else None
        for q, ok in zip(results.meta["q"], results["solver_converged"], strict=True)
    ]


def _only(clearance: Clearance, name: str) -> Clearance:
    clearance.pairs = [p for p in clearance.pairs if p.shape.name == name]
    return clearance


def _point(results, name, k):
    return np.array([results[f"{name}_{a}"][k] for a in "xyz"])


# ------------------------------------------------------------------ closed forms


def test_a_roof_over_the_tyre_is_as_far_as_the_tyres_highest_point_from_the_results(
    corner, tmp_path
):
    """A wide box above the wheel: its distance from the tyre is its underside's height
    less the tyre cylinder's highest point, c_z + R·√(1 − u_z²) + h·|u_z|, from the
    results' own wheel points at each step (bump and steer)."""
    sweep = _grid([-20.0, 0.0, 25.0], [-20.0, 10.0])
    results = corner.run_sweep(sweep)
    bottom = 0.700  # m
    roof = ClearanceBody(
        "roof",
        "box",
        center=np.array([-0.02, 0.9, bottom + 0.05]),
        size=np.array([1.5, 1.5, 0.1]),
        rotation=np.eye(3),
    )
    run = ClearanceRun(_only(Clearance(corner, [roof]), "roof"), _qs(results), sweep)
    tyre = next(r for r in wheel_rings(corner) if r.part == "tyre")
    for k in range(len(results)):
        a, b = _point(results, "wheel_inboard", k), _point(results, "wheel_outboard", k)
        u = (b - a) / np.linalg.norm(b - a)
        top = 0.5 * (a + b)[2] + 1e3 * tyre.outer * np.sqrt(1 - u[2] ** 2)
        top += 0.5 * np.linalg.norm(b - a) * abs(u[2])
        assert run.distance[0, k] == pytest.approx(1e3 * bottom - top, abs=1e-3)
        assert run.on_body[0, k, 2] == pytest.approx(1e3 * bottom, abs=1e-6)


def test_a_tube_tangent_to_the_tread_is_its_gap_less_its_radius_and_an_overlap_negative(corner):
    """A tube square to the spin axis, its axis ``gap`` from the tread at design: the
    distance is gap − radius (negative: the overlap's depth, coal's signed distance)."""
    tyre = next(r for r in wheel_rings(corner) if r.part == "tyre")
    e = np.cross(tyre.axis, [1.0, 0.0, 0.0])
    e /= np.linalg.norm(e)  # radial, in the mid plane
    t = np.cross(tyre.axis, e)
    for gap, radius in ((0.030, 0.010), (0.004, 0.010)):
        middle = tyre.centre + (tyre.outer + gap) * e
        tube = ClearanceBody(
            "tube", "tube", start=middle - 0.3 * t, end=middle + 0.3 * t, radius=radius
        )
        clearance = _only(Clearance(corner, [tube]), "tube")
        d = clearance.measure([corner.q_design])
        assert 1e3 * d["distance"][0, 0] == pytest.approx(1e3 * (gap - radius), abs=1e-3)
        on_wheel = d["on_wheel"][0, 0]
        assert np.linalg.norm(on_wheel - (tyre.centre + tyre.outer * e)) < 1e-5


# ------------------------------------------------------------------ brute force


def _segment_distance(points, a, b):
    """Each point's distance to the segment a → b (closed form)."""
    d = b - a
    t = np.clip(((points - a) @ d) / max(d @ d, 1e-300), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * d), axis=1)


def _ring_surface(ring, c, u, e, v, theta, s, which):
    """Points of one of the ring's four faces at (theta, s|rho) grids (world)."""
    if which in ("outer", "inner"):
        rho = ring.outer if which == "outer" else ring.inner
        radial = np.cos(theta)[:, None] * e + np.sin(theta)[:, None] * v
        return c + rho * radial + s[:, None] * u
    side = ring.half_width if which == "outboard" else -ring.half_width
    radial = np.cos(theta)[:, None] * e + np.sin(theta)[:, None] * v
    return c + s[:, None] * radial + side * u


def _brute(ring, c, u, a, b, radius):
    """The capsule's distance to the ring's surface by sampling that surface densely
    and zooming in on the nearest sample (the capsule by its axis' closed form)."""
    e = np.cross(u, [1.0, 0.0, 0.0])
    e /= np.linalg.norm(e)
    v = np.cross(u, e)
    best = np.inf
    for which in ("outer", "inner", "outboard", "inboard"):
        lo = np.array([-np.pi, -ring.half_width if which in ("outer", "inner") else ring.inner])
        hi = np.array([np.pi, ring.half_width if which in ("outer", "inner") else ring.outer])
        for _ in range(8):
            g0, g1 = np.meshgrid(np.linspace(lo[0], hi[0], 181), np.linspace(lo[1], hi[1], 61))
            pts = _ring_surface(ring, c, u, e, v, g0.ravel(), g1.ravel(), which)
            d = _segment_distance(pts, a, b)
            i = int(np.argmin(d))
            best = min(best, d[i] - radius)
            span = (hi - lo) / 8.0
            centre = np.array([g0.ravel()[i], g1.ravel()[i]])
            low = np.array(
                [-np.inf, -ring.half_width if which in ("outer", "inner") else ring.inner]
            )
            high = np.array(
                [np.inf, ring.half_width if which in ("outer", "inner") else ring.outer]
            )
            lo, hi = np.maximum(centre - span, low), np.minimum(centre + span, high)
    return best


def test_coal_matches_a_brute_force_sampling_of_the_surfaces_to_a_micrometre(corner):
    """Two pairs along the example's grid, at a few steps: the tyre against the frame
    tube (outside the wheel) and the rim against the trackrod's outer ball joint
    (inside its barrel)."""
    from pin_susp.model.clearance_bodies import load_clearance

    sweep = _grid([-30.0, 30.0], [-25.0, 25.0])
    results = corner.run_sweep(sweep)
    qs = _qs(results)
    clearance = Clearance(corner, load_clearance(PACKAGING))
    wanted = {"tyre/frame_tube", "rim/upright:trackrod_outboard"}
    clearance.pairs = [p for p in clearance.pairs if p.name in wanted]
    assert {p.name for p in clearance.pairs} == wanted
    measured = clearance.measure(qs)
    for i, pair in enumerate(clearance.pairs):
        bodies = sorted({pair.ring.body, *pair.shape.bodies})
        poses = Poses(corner, bodies, qs)
        c = poses.place(pair.ring.body, pair.ring.centre)
        u = poses.turn(pair.ring.body, pair.ring.axis)
        A = poses.place(pair.shape.bodies[0], pair.shape.a)
        B = poses.place(pair.shape.bodies[1], pair.shape.b)
        for k in range(len(qs)):
            expected = _brute(pair.ring, c[k], u[k], A[k], B[k], pair.shape.radius)
            assert 1e3 * measured["distance"][i, k] == pytest.approx(1e3 * expected, abs=1e-3)


def test_coal_matches_the_rings_exact_distance_along_the_capsules_axis(corner):
    """Every capsule pair of the example at a 5 × 3 grid: coal's distance is the ring's
    exact signed distance (numpy, from its section) at coal's own point on the capsule's
    axis, less its radius, and no capsule point comes nearer (sampled along the axis)."""
    sweep = _grid(np.linspace(-30, 30, 5), [-25.0, 0.0, 25.0])
    results = corner.run_sweep(sweep)
    qs = _qs(results)
    clearance = Clearance(corner)
    measured = clearance.measure(qs)
    checked = 0
    for i, pair in enumerate(clearance.pairs):
        if pair.shape.kind != "capsule":
            continue
        bodies = sorted({pair.ring.body, *pair.shape.bodies})
        poses = Poses(corner, bodies, qs)
        c = poses.place(pair.ring.body, pair.ring.centre)
        u = poses.turn(pair.ring.body, pair.ring.axis)
        A = poses.place(pair.shape.bodies[0], pair.shape.a)
        B = poses.place(pair.shape.bodies[1], pair.shape.b)
        t = np.linspace(0, 1, 4001)
        for k in range(len(qs)):
            d = measured["distance"][i, k]
            if d < 0:
                continue
            P = A[k] + t[:, None] * (B[k] - A[k])
            exact = ring_distance(pair.ring, P, c[k], u[k])[0].min() - pair.shape.radius
            assert 1e3 * d == pytest.approx(1e3 * exact, abs=2e-3), pair.name
            checked += 1
    assert checked > 300


# ------------------------------------------------------------------ the command


def _summary_worst(out: str):
    m = re.search(r"closest: (\S+) (-?[0-9.]+) mm at step ([0-9]+)", out)
    return m.group(1), float(m.group(2)), int(m.group(3))


def test_the_table_reread_has_the_summarys_worst_pair_and_step(tmp_path, capsys):
    out = tmp_path / "clearance.csv"
    assert main(["clearance", str(PACKAGING), str(GRID), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    pair, distance, step = _summary_worst(printed)
    table = pd.read_csv(out, comment="#")
    assert len(table) == 861 * table["pair"].nunique()
    worst = table.loc[table["distance"].idxmin()]
    assert (worst["pair"], int(worst["step"])) == (pair, step) == ("tyre/frame_tube", 40)
    assert worst["distance"] == pytest.approx(distance, abs=0.005)
    assert 0.0 < distance < 5.0  # the example: a few mm at full bump and full lock
    sweep = yaml.safe_load(GRID.read_text())
    assert sweep["targets"][0]["values"][step] == 30
    assert abs(sweep["targets"][1]["values"][step]) == 25
    # the closest points: their distance is the distance
    gap = np.linalg.norm(
        table[["wheel_x", "wheel_y", "wheel_z"]].to_numpy()
        - table[["body_x", "body_y", "body_z"]].to_numpy(),
        axis=1,
    )
    assert np.allclose(gap, np.abs(table["distance"]), atol=1e-4)
    assert "overlaps: none" in printed and "skipped: tyre/upright:" in printed


def test_an_overlap_is_a_warning_and_the_parquet_the_csvs_rows(tmp_path, capsys):
    data = yaml.safe_load(PACKAGING.read_text())
    data["clearance"]["bodies"][0]["tube"]["from"][1] = 775  # into the tyre at full lock
    data["clearance"]["bodies"][0]["tube"]["to"][1] = 775
    geometry = tmp_path / "g.yaml"
    geometry.write_text(yaml.safe_dump(data))
    sweep = tmp_path / "s.yaml"
    sweep.write_text(
        yaml.safe_dump(
            {
                "targets": [
                    {"point": "wheel_center", "direction": {"axis": "z"}, "values": [0, 30, 30]},
                    {
                        "point": "trackrod_inboard",
                        "direction": {"axis": "y"},
                        "values": [0, 0, -25],
                    },
                ]
            }
        )
    )
    csv, parquet = tmp_path / "c.csv", tmp_path / "c.parquet"
    assert main(["clearance", str(geometry), str(sweep), "-o", str(csv)]) == 0
    captured = capsys.readouterr()
    assert re.search(r"warning: 1 pairs overlap at [12] steps", captured.err)
    assert main(["clearance", str(geometry), str(sweep), "-o", str(parquet), "-q"]) == 0
    a, b = pd.read_csv(csv, comment="#"), pd.read_parquet(parquet)
    assert list(a.columns) == list(b.columns)
    assert np.allclose(a["distance"], b["distance"], atol=1e-6)
    assert (a.loc[a["pair"] == "tyre/frame_tube", "distance"].iloc[-1]) < 0


def test_the_replay_draws_the_closest_pair(tmp_path):
    sweep = tmp_path / "s.yaml"
    sweep.write_text(
        yaml.safe_dump(
            {
                "targets": [
                    {"point": "wheel_center", "direction": {"axis": "z"}, "values": [0, 30]},
                    {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": [0, -25]},
                ]
            }
        )
    )
    page, csv = tmp_path / "v.html", tmp_path / "c.csv"
    assert (
        main(["clearance", str(PACKAGING), str(sweep), "-o", str(csv), "--view", str(page), "-q"])
        == 0
    )
    import base64

    import umsgpack

    blobs = re.findall(r'base64,([A-Za-z0-9+/=]*)"\)', page.read_text())
    commands = [umsgpack.unpackb(base64.b64decode(b)) for b in blobs]
    tracks = {
        a["path"]: a["clip"]["tracks"]
        for c in commands
        if c["type"] == "set_animation"
        for a in c["animations"]
    }
    table = pd.read_csv(csv, comment="#")
    for step in (0, 1):
        rows = table[table["step"] == step]
        worst = rows.loc[rows["distance"].idxmin()]
        for end in ("wheel", "body"):
            (position,) = [
                t
                for t in tracks[f"/meshcat/pin_susp/clearance/closest_{end}"]
                if t["name"] == ".position"
            ]
            placed = np.array(position["keys"][step]["value"])
            expected = 1e-3 * worst[[f"{end}_x", f"{end}_y", f"{end}_z"]].to_numpy(dtype=float)
            assert np.allclose(placed, expected, atol=1e-9)
    assert "/meshcat/pin_susp/clearance/frame_tube" in tracks


# ------------------------------------------------------------------ the envelope


def test_the_envelope_is_closed_and_holds_every_tyre_pose(tmp_path, capsys):
    import trimesh

    sweep_data = {
        "targets": [
            {"point": "wheel_center", "direction": {"axis": "z"}, "values": []},
            {"point": "trackrod_inboard", "direction": {"axis": "y"}, "values": []},
        ]
    }
    for j, rack in enumerate([-25.0, 0.0, 25.0]):
        bumps = [-30.0, -15.0, 0.0, 15.0, 30.0]
        for bump in bumps if j % 2 == 0 else bumps[::-1]:
            sweep_data["targets"][0]["values"].append(bump)
            sweep_data["targets"][1]["values"].append(rack)
    sweep = tmp_path / "s.yaml"
    sweep.write_text(yaml.safe_dump(sweep_data))
    out, hull = tmp_path / "e.stl", tmp_path / "h.stl"
    assert main(["envelope", str(PACKAGING), str(sweep), "-o", str(out)]) == 0
    assert "watertight True" in capsys.readouterr().out
    assert main(["envelope", str(PACKAGING), str(sweep), "-o", str(hull), "--hull", "-q"]) == 0
    mesh, one = trimesh.load_mesh(out), trimesh.load_mesh(hull)
    assert mesh.is_watertight and one.is_watertight
    assert mesh.volume < one.volume  # the union is tighter than the hull
    # every pose's tyre surface, from the sweep's own wheel points (mm), a hair inside
    corner = load_subject(PACKAGING)
    results = corner.run_sweep(str(sweep))
    tyre = next(r for r in wheel_rings(corner) if r.part == "tyre")
    rng = np.random.default_rng(1)
    radius, half = 1e3 * tyre.outer - 1e-3, 1e3 * tyre.half_width - 1e-3
    for k in range(len(results)):
        a, b = _point(results, "wheel_inboard", k), _point(results, "wheel_outboard", k)
        u = (b - a) / np.linalg.norm(b - a)
        e = np.cross(u, [1.0, 0, 0])
        e /= np.linalg.norm(e)
        v = np.cross(u, e)
        theta = rng.uniform(0, 2 * np.pi, 400)
        s = np.concatenate([np.full(100, -half), np.full(100, half), rng.uniform(-half, half, 200)])
        rho = np.concatenate([rng.uniform(0, radius, 200), np.full(200, radius)])
        points = 0.5 * (a + b) + s[:, None] * u
        points += rho[:, None] * (np.cos(theta)[:, None] * e + np.sin(theta)[:, None] * v)
        assert mesh.contains(points).all(), k
        assert one.contains(points).all(), k
    assert not mesh.contains(np.array([[0.0, 0.0, 1e4]])).any()


# ------------------------------------------------------------------ bad keys


@pytest.mark.parametrize(
    "bodies, key, problem",
    [
        ([{"name": "a", "mesh": "missing.stl"}], "clearance.bodies[0].mesh", "no such file"),
        ([{"name": "a", "mesh": "bad.stl"}], "clearance.bodies[0].mesh", "not a readable STL"),
        ([{"name": "a", "cone": {}}], "clearance.bodies[0].cone", "unknown key"),
        ([{"name": "a"}], "clearance.bodies[0]", "exactly one of mesh, box, tube"),
        (
            [{"name": "a", "box": {"center": [0, 0, 0], "size": [1, 0, 1]}}],
            "clearance.bodies[0].box.size",
            "its y size must be > 0",
        ),
        (
            [{"name": "a", "tube": {"from": [0, 0, 0], "to": [1, 0, 0], "radius": -1}}],
            "clearance.bodies[0].tube.radius",
            "must be > 0",
        ),
        (
            [{"name": "a", "tube": {"from": [0, 0, 0], "to": [1, 0, 0], "radius": 1}}] * 2,
            "clearance.bodies[1].name",
            "given twice",
        ),
        ({"name": "a"}, "clearance.bodies", "expected a list"),
    ],
)
def test_a_bad_clearance_key_is_one_line_naming_the_file_and_key(
    tmp_path, capsys, bodies, key, problem
):
    data = yaml.safe_load(PACKAGING.read_text())
    data["clearance"] = {"bodies": bodies}
    geometry = tmp_path / "g.yaml"
    geometry.write_text(yaml.safe_dump(data))
    (tmp_path / "bad.stl").write_bytes(b"solid x\nfacet normal nonsense\n")
    code = main(["clearance", str(geometry), str(GRID), "-o", str(tmp_path / "c.csv")])
    err = capsys.readouterr().err.strip()
    assert code != 0 and len(err.splitlines()) == 1, err
    assert str(geometry) in err and key in err and problem in err, err
    assert not (tmp_path / "c.csv").exists()


def test_a_mesh_body_is_read_in_the_files_units_and_measured(tmp_path):
    """An STL box (trimesh's) given as a mesh measures as the same box given as a box."""
    import trimesh

    box = trimesh.creation.box(extents=[200.0, 200.0, 50.0])
    box.apply_translation([-20.0, 900.0, 760.0])
    box.export(tmp_path / "roof.stl")
    data = yaml.safe_load(PACKAGING.read_text())
    data["clearance"] = {
        "bodies": [
            {"name": "mesh", "mesh": "roof.stl"},
            {"name": "box", "box": {"center": [-20, 900, 760], "size": [200, 200, 50]}},
        ]
    }
    geometry = tmp_path / "g.yaml"
    geometry.write_text(yaml.safe_dump(data))
    from pin_susp.model.clearance_bodies import load_clearance

    model = load_subject(geometry)
    clearance = Clearance(model, load_clearance(geometry))
    clearance.pairs = [p for p in clearance.pairs if p.shape.name in ("mesh", "box")]
    d = clearance.measure([model.q_design])["distance"][:, 0]
    assert d[0] == pytest.approx(d[1], abs=1e-6) and d[0] > 0.05


# ------------------------------------------------------------------ axles and vehicles


@pytest.mark.parametrize(
    "geometry, sweep, left, right",
    [
        ("axle_front.yaml", "heave_roll.yaml", "left_tyre", "right_tyre"),
        ("vehicle_fs.yaml", "vehicle_roll.yaml", "fl_tyre", "fr_tyre"),
    ],
)
def test_mirrored_tubes_on_the_chassis_mirror_the_tyres_distances(
    tmp_path, geometry, sweep, left, right
):
    """A tube on the chassis above each front tyre, one the other's mirror: over a roll
    from −θ to +θ (symmetric steps), the left tyre's distance at a step is the right
    one's at the mirrored step — on an axle, and on a car whose body (and the tubes on
    it) rolls."""
    import shutil

    for path in EXAMPLES.glob("vehicle/*.yaml"):
        (tmp_path / "vehicle").mkdir(exist_ok=True)
        shutil.copy(path, tmp_path / "vehicle" / path.name)
    data = yaml.safe_load((EXAMPLES / geometry).read_text())
    tube = {"from": [-470, 780, 650], "to": [430, 780, 650], "radius": 12.7}
    mirror = {k: [v[0], -v[1], v[2]] if isinstance(v, list) else v for k, v in tube.items()}
    data["clearance"] = {
        "bodies": [{"name": "tube_l", "tube": tube}, {"name": "tube_r", "tube": mirror}]
    }
    path = tmp_path / geometry
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "c.csv"
    assert main(["clearance", str(path), str(EXAMPLES / sweep), "-o", str(out), "-q"]) == 0
    table = pd.read_csv(out, comment="#")
    a = table[table["pair"] == f"{left}/tube_l"].sort_values("step")["distance"].to_numpy()
    b = table[table["pair"] == f"{right}/tube_r"].sort_values("step")["distance"].to_numpy()
    assert len(a) == len(b) > 10 and np.ptp(a) > 1.0  # it moves
    assert np.allclose(a, b[::-1], atol=1e-4)
    on_tube = table[table["pair"] == f"{left}/tube_l"].sort_values("step")["body_z"].to_numpy()
    rolls = geometry.startswith("vehicle")  # the car's body rolls ±2°: its tube ±27 mm
    assert (np.ptp(on_tube) > 40.0) == rolls


@pytest.mark.parametrize(
    "argv",
    [["sweep", "-o", "out.csv"], ["envelope", "-o", "out.stl"], ["view", "--html", "out.html"]],
    ids=lambda a: a[0],
)
def test_a_bad_body_is_refused_by_every_command(tmp_path, capsys, argv):
    """The clearance: bodies are checked wherever the file is loaded, not only by
    pin-susp clearance: one line naming the key, exit 2, nothing written."""
    g = yaml.safe_load((EXAMPLES / "packaging.yaml").read_text())
    g["clearance"]["bodies"][0]["tube"]["radius"] = -12.7
    (tmp_path / "g.yaml").write_text(yaml.safe_dump(g))
    command, *out = argv
    assert main([command, "g.yaml", str(EXAMPLES / "bump.yaml"), *out]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "clearance.bodies[0].tube.radius: must be > 0" in err
    assert not (tmp_path / out[-1]).exists()
