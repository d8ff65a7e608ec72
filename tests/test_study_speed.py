"""The fast paths of a study (docs/studies.md, Speed) give what the slow ones give: a
variant's model copied from its structure's first one is the model parsed from its own
URDF, bit for bit; every variant's every step solved together from the design variant's solutions
gives each variant's summary as its own direct sweep does, and flags the same variants."""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml

from pin_susp import Corner, load_sweep
from pin_susp.model.sweep import Sweep
from pin_susp.model.urdf import read_closures, tree_to_urdf
from pin_susp.solve.bulk import Tree, tree_of
from pin_susp.study import (
    batch,
    batches,
    load_study,
    run_study,
    tasks,
    variant_data,
    variant_table,
)
from pin_susp.study.together import Together
from pin_susp.study.variants import build

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
BUMP = EXAMPLES / "bump_rack_held.yaml"
SUMMARY = ["camber", "roadwheel_angle", "deriv_roadwheel_angle_wrt_hub_z"]


def write_study(
    folder: Path, body: dict, geometry: str = "double_wishbone.yaml", sweep: Path = BUMP
) -> Path:
    data = {"version": 1, "geometry": str(EXAMPLES / geometry), "sweep": str(sweep)} | body
    path = folder / f"study_{Path(geometry).stem}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def counted(monkeypatch) -> list:
    """(variants offered, variants solved, how) of each batch solved together: "measured"
    from their trees' numbers (together.py), each variant's geometry the design's with
    its own hardpoints (geometry.with_points; "measured, geometry read whole" where its
    data was parsed whole), or "built" and then solved together (batch.py: the rest of
    a batch, offered after the measured)."""
    out = []
    together, measure = batch._together, Together.measure

    def counting(variants, *args):
        solved = together(variants, *args)
        out.append((len(variants), len(solved), "built"))
        return solved

    def measuring(self, table):
        measured = measure(self, table)
        how = "measured" if self.points is not None else "measured, geometry read whole"
        out.append((len(table), sum(m is not None for m in measured), how))
        return measured

    monkeypatch.setattr(batch, "_together", counting)
    monkeypatch.setattr(Together, "measure", measuring)
    return out


def direct(study, deltas) -> tuple:
    """A variant's own corner's direct sweep (marched) and its design state."""
    job = study.job()
    data = variant_data(study.geometry_data, study.variables, deltas)
    sweep = load_sweep(job.sweep)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        corner = Corner(data)
        return corner.run_sweep(sweep), corner.run_sweep(
            Sweep([t.at_design() for t in sweep.targets], "design")
        )


def same_rows(fast, marched) -> None:
    """Two runs' variants: the same converged, steps failed and error, each summary to
    1e-9 (blank where the other's is)."""
    for c in ("variant_id", "converged", "steps_failed", "error"):
        assert (fast[c] == marched[c]).all(), c
    numbers = [c for c in fast.columns if c.endswith(("_static", "_min", "_max"))]
    a, b = fast[numbers].to_numpy(float), marched[numbers].to_numpy(float)
    assert np.array_equal(np.isnan(a), np.isnan(b))
    assert np.allclose(a, b, atol=1e-9, rtol=0.0, equal_nan=True)


def fast_and_marched(study, tmp_path, monkeypatch) -> tuple:
    """A study's variants run as a study runs them (each batch's solves counted:
    ``counted``) and with every variant marched from the start (no guess)."""
    together = counted(monkeypatch)
    fast = run_study(study, tmp_path / "fast", scheduler=None).variants
    monkeypatch.undo()
    monkeypatch.setattr(tasks, "guess_of", lambda job, sweep: None)
    return fast, run_study(study, tmp_path / "marched", scheduler=None).variants, together


def tolerances(tmp_path, geometry: str, tolerance: float, samples: int, sweep: Path = BUMP):
    body = {
        "variables": {"all_hardpoints": {"tolerance": tolerance}},
        "kind": "monte_carlo",
        "monte_carlo": {"samples": samples, "seed": 4},
        "summary": SUMMARY
        if sweep == BUMP
        else ["camber" + ("_left" if "axle" in geometry else "")],
    }
    return load_study(write_study(tmp_path, body, geometry, sweep))


@pytest.mark.parametrize(
    "geometry",
    [
        "double_wishbone.yaml",
        "macpherson.yaml",
        "multilink_front.yaml",
        "multilink_rear.yaml",
        "pushrod_rocker.yaml",
        "semi_trailing_arm.yaml",
        "fixed_toe_link.yaml",
        "axle_front.yaml",
    ],
)
def test_a_variants_model_is_the_one_parsed_from_its_urdf(tmp_path, geometry):
    """Each later variant of a structure is a copy of the first's model with its own
    joint origins, axes and frame offsets: compared with a fresh parse of its own URDF
    (every joint placement, joint kind and axis, frame and closure anchor, bit for bit)."""
    if geometry.startswith("axle"):
        sweep = EXAMPLES / "roll.yaml"
    else:  # a bump alone: every kind of corner takes it (a rack's held)
        sweep = tmp_path / "bump.yaml"
        targets = [
            {
                "point": "wheel_center",
                "direction": {"axis": "z"},
                "mode": "relative",
                "values": [0.0, 10.0],
            }
        ]
        sweep.write_text(yaml.safe_dump({"version": 1, "targets": targets}))
    study = tolerances(tmp_path, geometry, 0.8, 3, sweep)
    job = study.job()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for deltas in variant_table(study):  # the first primes its structure's model
            subject = build(variant_data(job.geometry, job.variables, deltas), "v", True)
    text = tree_to_urdf(replace(subject.tree, visuals=[]))
    parsed = pin.buildModelFromXML(text)
    model = subject.model
    assert list(model.names) == list(parsed.names)
    for a, b in zip(model.jointPlacements, parsed.jointPlacements, strict=True):
        assert np.array_equal(a.homogeneous, b.homogeneous)
    for a, b in zip(model.joints, parsed.joints, strict=True):
        assert a.shortname() == b.shortname() and (a.idx_q, a.idx_v) == (b.idx_q, b.idx_v)
        if a.shortname().endswith("Unaligned"):
            assert np.array_equal(a.extract().axis, b.extract().axis)
    for a, b in zip(list(model.frames)[: parsed.nframes], parsed.frames, strict=True):
        assert (a.name, a.parentJoint, a.type) == (b.name, b.parentJoint, b.type)
        assert np.array_equal(a.placement.homogeneous, b.placement.homogeneous)
    # its bulk tree (Tree.like, from the first's) as one built from its model
    given, built = tree_of(subject.kin), Tree(model)
    assert given.model is model and given._identity == built._identity
    for a, b in zip(given.joints, built.joints, strict=True):
        assert a[0] == b[0] and a[1] == b[1] and a[5] == b[5]
        assert all(np.array_equal(x, y) for x, y in zip(a[2:5], b[2:5], strict=True))
    # the closures' anchors (frames added after the URDF's) as the text says
    for spec, closure in zip(read_closures(text), subject.tree.closures, strict=True):
        for i, (link, offset) in enumerate(spec.anchors):
            frame = model.frames[model.getFrameId(f"{closure.name}/{i}")]
            parent = parsed.frames[parsed.getFrameId(link)]
            expected = parent.placement * pin.SE3(np.eye(3), offset)
            assert np.array_equal(frame.placement.homogeneous, expected.homogeneous)


@pytest.mark.parametrize("way", ["measured", "built"])
def test_variants_solved_at_once_equal_their_own_direct_sweeps(tmp_path, monkeypatch, way):
    """A random sample of a Monte Carlo's variants: each summary equals its own corner's
    direct sweep (Corner(variant geometry).run_sweep, marched) to 1e-9, every variant's
    steps having been solved at once from the design variant's solutions — measured from
    the trees' numbers alone (together.py), or (that way turned off) each variant built
    and the batch's steps then solved together (batch.py)."""
    if way == "built":
        monkeypatch.setattr(batch, "_together_of", lambda *args: None)
    together = counted(monkeypatch)
    study = tolerances(tmp_path, "double_wishbone.yaml", 1.5, 12)
    outcome = run_study(study, tmp_path / "out", scheduler=None)
    variants = outcome.variants
    assert sum(k for _, k, _ in together) == len(variants)  # each solved together
    measured = sum(k for _, k, how in together if how == "measured")
    assert measured == (len(variants) if way == "measured" else 0)
    for vid in np.random.default_rng(7).choice(len(variants), 4, replace=False):
        row = variants.iloc[vid]
        steps, static = direct(study, row[study.names].to_numpy())
        assert row["converged"] and steps["solver_converged"].all()
        for m in SUMMARY:
            assert row[f"{m}_min"] == pytest.approx(np.min(steps[m]), abs=1e-9)
            assert row[f"{m}_max"] == pytest.approx(np.max(steps[m]), abs=1e-9)
            assert row[f"{m}_static"] == pytest.approx(static[m][0], abs=1e-9)


CORNERS = {  # every mechanism, spring and steering kind of the examples: a study's sweep
    "double_wishbone.yaml": "bump_steer.yaml",
    "macpherson.yaml": "bump_rack_held.yaml",
    "multilink_front.yaml": "bump_steer.yaml",
    "multilink_rear.yaml": "bump.yaml",
    "pushrod_rocker.yaml": "bump_steer.yaml",
    "semi_trailing_arm.yaml": "bump.yaml",
    "fixed_toe_link.yaml": "bump.yaml",
    "packaging.yaml": "bump_steer.yaml",
    "wheel_centre.yaml": "bump_steer.yaml",
    "camber_shim.yaml": "bump_rack_held.yaml",  # (a setup solve per variant: built)
}


@pytest.mark.parametrize("geometry", sorted(CORNERS))
def test_every_mechanisms_variants_measured_together_equal_their_direct_sweeps(
    tmp_path, monkeypatch, geometry
):
    """Each example corner (every mechanism; rocker, torsion bar, toe link): a Monte
    Carlo's variants (every hardpoint within ±1 mm) measured together from their trees'
    numbers, each summary — camber, toe, its derivative by hub z, the motion ratio where
    the summary may read it — equal to its own direct sweep's to 1e-9."""
    sweep = EXAMPLES / CORNERS[geometry]
    summary = ["camber", "roadwheel_angle", "deriv_roadwheel_angle_wrt_hub_z", "fvic_z"]
    summary += ["scrub_radius", "wheel_travel"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if "motion_ratio" in Corner(EXAMPLES / geometry).run_sweep(sweep):  # a spring's
            summary.append("motion_ratio")
    body = {
        "variables": {"all_hardpoints": {"tolerance": 1.0}},
        "kind": "monte_carlo",
        "monte_carlo": {"samples": 6, "seed": 2},
        "summary": summary,
    }
    study = load_study(write_study(tmp_path, body, geometry, sweep))
    together = counted(monkeypatch)
    variants = run_study(study, tmp_path / "out", scheduler=None).variants
    measured = sum(k for _, k, how in together if how == "measured")
    assert measured == (0 if geometry == "camber_shim.yaml" else len(variants))
    assert variants["converged"].all()
    for vid in (0, 3, 5):
        row = variants.iloc[vid]
        steps, static = direct(study, row[study.names].to_numpy())
        for m in summary:
            values = steps[m][np.isfinite(steps[m])]
            if not values.size:  # (undefined: a trailing arm's scrub radius)
                assert np.isnan(row[f"{m}_min"]) and np.isnan(row[f"{m}_max"]), m
                continue
            assert row[f"{m}_min"] == pytest.approx(values.min(), rel=1e-9, abs=1e-9), m
            assert row[f"{m}_max"] == pytest.approx(values.max(), rel=1e-9, abs=1e-9), m
            at = pytest.approx(static[m][0], rel=1e-9, abs=1e-9, nan_ok=True)
            assert row[f"{m}_static"] == at, m


def test_failed_variants_are_flagged_as_when_marched(tmp_path, monkeypatch):
    """A DOE over a box so wide that some variants' sweeps fail part way (±200 mm of
    travel): the same rows — converged, steps failed, error, summaries — whether each
    variant's steps are first solved at once from the design variant's (where that
    converges: some here) or marched from the start (no guess)."""
    sweep = tmp_path / "deep.yaml"
    targets = [
        {"point": "wheel_center", "direction": {"axis": "z"}, "mode": "relative"},
        {"point": "trackrod_inboard", "direction": {"axis": "y"}, "mode": "relative"},
    ]
    targets[0] |= {"start": -200, "stop": 200}
    targets[1] |= {"start": 0, "stop": 0}
    sweep.write_text(yaml.safe_dump({"version": 1, "steps": 21, "targets": targets}))
    body = {
        "variables": [
            {"point": "upper_wishbone_inboard_front", "axis": "z", "range": [-250, 250]},
            {"point": "lower_wishbone_outboard", "axis": "y", "range": [-150, 150]},
        ],
        "kind": "doe",
        "doe": {"method": "full_factorial", "levels": 3},
        "summary": ["camber", "roadwheel_angle"],
    }
    study = load_study(write_study(tmp_path, body, "double_wishbone.yaml", sweep))
    fast, marched, together = fast_and_marched(study, tmp_path, monkeypatch)
    solved = sum(k for _, k, _ in together)  # some solved together, some marched
    assert 0 < solved < len(fast)
    assert (~fast["converged"]).sum() >= 2 and (fast["steps_failed"] < 21).all()
    same_rows(fast, marched)


def test_variants_their_geometry_refuses_are_refused_as_when_built(tmp_path, monkeypatch):
    """A DOE whose box puts some variants' points where a file's would be refused (the
    trackrod's outer end across the centreline or on the steering axis, the lower ball
    joint on the arm's pivot axis): measured together, each variant's hardpoints checked
    as a file's are, the rows — converged, error, summaries — those of every variant
    built and marched on its own."""
    body = {
        "variables": [
            {"point": "trackrod_outboard", "axis": "y", "range": [-1000, 0]},
            {"point": "lower_wishbone_outboard", "axis": "y", "range": [-500, 0]},
        ],
        "kind": "doe",
        "doe": {"method": "full_factorial", "levels": 6},
        "summary": ["camber", "roadwheel_angle"],
    }
    study = load_study(write_study(tmp_path, body, "double_wishbone.yaml"))
    fast, marched, together = fast_and_marched(study, tmp_path, monkeypatch)
    assert sum(k for _, k, how in together if how == "measured") > 0
    refused = marched["error"].str.contains("hardpoints.")
    assert refused.sum() >= 3 and marched["converged"][~refused].sum() >= 3
    same_rows(fast, marched)


@pytest.mark.parametrize("column", ["spring_force", "wheel_rate", "solver_converged"])
def test_a_summary_the_metric_functions_do_not_give_is_built_instead(tmp_path, monkeypatch, column):
    """A summary column that is no metric function's (a rated spring's force and rate,
    a solver's column): no variant measured together, every one built and swept, and
    the rows its direct sweep gives."""
    body = {
        "variables": {"all_hardpoints": {"tolerance": 0.5}},
        "kind": "monte_carlo",
        "monte_carlo": {"samples": 3, "seed": 2},
        "summary": ["camber", column],
    }
    study = load_study(write_study(tmp_path, body, "pushrod_rocker.yaml"))
    together = counted(monkeypatch)
    variants = run_study(study, tmp_path / "out", scheduler=None).variants
    assert sum(k for _, k, how in together if how == "measured") == 0
    assert variants["converged"].all()
    row = variants.iloc[1]
    steps, static = direct(study, row[study.names].to_numpy())
    for m in ("camber", column):
        values = steps[m].astype(float)
        assert row[f"{m}_min"] == pytest.approx(values.min(), rel=1e-9, abs=1e-9), m
        assert row[f"{m}_max"] == pytest.approx(values.max(), rel=1e-9, abs=1e-9), m
        assert row[f"{m}_static"] == pytest.approx(float(static[m][0]), rel=1e-9, abs=1e-9)


def test_a_batch_raises_the_allocators_thresholds_once(tmp_path, monkeypatch):
    """Every batch's process sets glibc's mmap and trim thresholds (solve/allocator.py)
    before its solve; where glibc is the C library, mallopt takes both."""
    import platform

    from pin_susp.solve import allocator

    calls = []
    monkeypatch.setattr(allocator, "tune", lambda: calls.append(1) or True)
    study = tolerances(tmp_path, "double_wishbone.yaml", 0.5, 2)
    run_study(study, tmp_path / "out", scheduler=None)
    assert len(calls) == len(batches(study))
    monkeypatch.undo()
    glibc = platform.libc_ver()[0] == "glibc"
    assert allocator.tune() is glibc and allocator.tune() is glibc
