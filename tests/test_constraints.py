"""Every row kind (pin_susp/constraints/, one per module) implements the one interface,
and its three forms agree: the plain residual and Jacobian, the Newton solver's fast
form (solver._Batch) and the batched form over many configurations (bulk.Rows) —
to 1e-12 at random configurations — and the Jacobian is the residual's derivative
(central finite differences). The solver and the batched path know no row kind."""

import ast
import importlib
import inspect
import pkgutil
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import EXAMPLES, ROOT, torsion_bar

import pin_susp
import pin_susp.constraints
from pin_susp.constraints import (
    BarTwist,
    FaceAlignment,
    JointTarget,
    PointTarget,
    RockerTurn,
    Row,
    ShimGap,
)
from pin_susp.model.sweep import load_sweep
from pin_susp.solve.bulk import Rows, tree_of
from pin_susp.solve.solver import _Batch
from pin_susp.subjects.axle import AxleModel, axle_rows, load_axle

ROWS_KNOWN = {"WORLD", "BranchGuard", "Kinematics", "StepFrames", "ManyFrames"}


def kinds_in_constraints() -> set[type]:
    """Every Row subclass defined in a module of pin_susp.constraints."""
    found = set()
    for info in pkgutil.iter_modules(pin_susp.constraints.__path__):
        module = importlib.import_module(f"pin_susp.constraints.{info.name}")
        for _, cls in inspect.getmembers(module, inspect.isclass):
            if issubclass(cls, Row) and cls is not Row and cls.__module__ == module.__name__:
                found.add(cls)
    return found


@pytest.mark.parametrize("module", ["solve/solver.py", "solve/bulk.py"])
def test_the_solver_and_the_batched_path_know_no_row_kind(module):
    """No isinstance at all in solver.py and bulk.py, and nothing imported from
    constraints/ but the frames' containers, the kinematics and the branch guard."""
    tree = ast.parse((ROOT / "pin_susp" / module).read_text())
    calls = [
        node
        for node in ast.walk(tree)
        if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "isinstance"
    ]
    assert not calls, f"{module}: isinstance at line {calls[0].lineno}"
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and "constraints" in (node.module or ""):
            assert {a.name for a in node.names} <= ROWS_KNOWN, module
        if isinstance(node, ast.ImportFrom) and (node.module or "").endswith("closures"):
            raise AssertionError(f"{module} imports closures")


def _rows() -> list:
    """(kin, q_design, rows) for every row kind, each on a model it is used on (or, for
    the shim's rows, on a corner's frames: their maths does not care which)."""
    out = []
    corner = pin_susp.Corner(EXAMPLES / "double_wishbone.yaml", warn=False)
    p = corner.points
    rng = np.random.default_rng(11)
    slanted = rng.normal(size=3)
    slanted /= np.linalg.norm(slanted)
    rows = [
        *corner.closures,
        PointTarget(p["wheel_center"], np.array([0.0, 0.0, 1.0]), 0.31),
        PointTarget(p["lower_wishbone_outboard"], slanted, -0.2),
        PointTarget(p["contact_patch_center"], slanted, 0.05),
        PointTarget(p["contact_patch_center"], np.array([0.0, 1.0, 0.0]), 0.7),
        JointTarget(corner.model, "rack_slide", 0.004),
        ShimGap("gap", p["upper_wishbone_outboard"], p["lower_wishbone_outboard"], slanted, 4e-3),
        FaceAlignment("faces", p["upper_wishbone_outboard"], p["wheel_center"], slanted),
    ]
    out.append((corner.kin, corner.q_design, rows))
    rocker = pin_susp.Corner(torsion_bar(), warn=False)
    out.append((rocker.kin, rocker.q_design, [RockerTurn(rocker)]))
    model = AxleModel(load_axle(EXAMPLES / "axle_front.yaml"))
    sweep = load_sweep(
        {
            "steps": 3,
            "targets": [
                {"quantity": "roll", "start": -3, "stop": 3},
                {"quantity": "heave", "start": 10, "stop": 10},
            ],
        }
    )
    axle = axle_rows(model, sweep.targets)
    axle[0].value, axle[1].value = 0.03, 0.012
    axle.append(BarTwist(model.model, ["left_arb_arm_pivot", "right_arb_arm_pivot"]))
    out.append((model.kin, model.q_design, [*model.closures, *axle]))
    return out


CASES = _rows()


def test_every_row_kind_is_covered_and_has_its_own_forms():
    covered = {type(row) for _, _, rows in CASES for row in rows}
    assert covered == kinds_in_constraints()
    for kind in covered:
        assert kind.fill is not Row.fill, kind  # its fast form, not the plain fallback
        assert kind.fill_many is not Row.fill_many, kind
        assert kind.residual is not Row.residual and kind.jacobian is not Row.jacobian


def _plain(kin, row, q):
    kin.update(q)
    return row.residual(kin).copy(), row.jacobian(kin).copy()


def _measure(kin, row, q, moved):
    """What the row's Jacobian differentiates, at ``moved``: its residual, or for a held
    row (zero residual) the turn it measures from q — the rocker's about its axis (the
    log of its frame's rotation), the bar's arms' difference."""
    if isinstance(row, BarTwist):
        return row.row @ (moved - q)
    if isinstance(row, RockerTurn):
        kin.update_positions(q)
        before, axis = kin.data.oMf[row.point.frame_id].rotation.copy(), row.axis(kin)
        kin.update_positions(moved)
        after = kin.data.oMf[row.point.frame_id].rotation
        return np.array([pin.log3(after @ before.T) @ axis])
    return _plain(kin, row, moved)[0]


@pytest.mark.parametrize("case", range(len(CASES)))
def test_plain_fast_and_batched_forms_agree_and_the_jacobian_is_the_derivative(case):
    kin, q0, rows = CASES[case]
    rng = np.random.default_rng(5 + case)
    qs = q0 + rng.normal(0.0, 0.03, (6, len(q0)))
    nv = kin.model.nv
    for row in rows:
        target = hasattr(row, "value")
        bulk = Rows(tree_of(kin), [row], 1 if target else 0)
        assert bulk.supported
        values = np.full((len(qs), 1), getattr(row, "value", 0.0))
        r_many, J_many = bulk.evaluate(qs, values)
        r_only, _ = bulk.evaluate(qs, values, jacobian=False)
        batch = _Batch(kin.model, [row])
        for n, q in enumerate(qs):
            r, J = _plain(kin, row, q)
            scale = 1.0 + np.abs(r).max()
            fast_r, fast_J = np.empty(row.size), np.empty((row.size, nv))
            batch.fill(kin, q, fast_r, fast_J)
            np.testing.assert_allclose(fast_r, r, rtol=0, atol=1e-12 * scale, err_msg=row.name)
            np.testing.assert_allclose(fast_J, J, rtol=0, atol=1e-12 * (1 + np.abs(J).max()))
            kin.update_positions(q)
            alone = np.empty(row.size)
            batch.fill(kin, q, alone, None)
            np.testing.assert_allclose(alone, r, rtol=0, atol=1e-12 * scale)
            np.testing.assert_allclose(r_many[n], r, rtol=0, atol=1e-12 * scale, err_msg=row.name)
            np.testing.assert_allclose(r_only[n], r, rtol=0, atol=1e-12 * scale)
            np.testing.assert_allclose(
                J_many[n], J, rtol=0, atol=1e-12 * (1 + np.abs(J).max()), err_msg=row.name
            )
            # central differences along a random direction (q is a vector space here)
            h, dq = 1e-6, rng.normal(size=nv)
            plus, minus = (_measure(kin, row, q, q + s * h * dq) for s in (1.0, -1.0))
            np.testing.assert_allclose(
                J @ dq, (plus - minus) / (2 * h), rtol=1e-6, atol=1e-8, err_msg=row.name
            )


def test_a_target_rows_batched_value_is_its_column():
    """The batched form reads a target's value from the sweep's column, not the row."""
    kin, q0, rows = CASES[0]
    target = next(r for r in rows if isinstance(r, PointTarget))
    bulk = Rows(tree_of(kin), [target], 1)
    r, _ = bulk.evaluate(q0[None], np.array([[target.value + 0.25]]))
    kin.update(q0)
    assert r[0, 0] == pytest.approx(target.residual(kin)[0] - 0.25, abs=1e-15)


def test_the_closures_module_is_gone():
    assert not Path(pin_susp.__file__).with_name("closures.py").exists()


def test_a_contact_patch_target_on_a_one_freedom_corner():
    """A trailing arm (nv = 1: Pinocchio's frame Jacobians come as 6-vectors) held by a
    target on its contact patch along a tilted direction — a derived point's fast form
    on a one-column Jacobian (found by the fuzzer: it raised). Every step meets its
    target, recomputed from the results' own contact-patch columns."""
    corner = pin_susp.Corner(EXAMPLES / "semi_trailing_arm.yaml")
    assert corner.model.nv == 1
    d = np.array([0.23, 0.0, 1.0]) / np.hypot(0.23, 1.0)
    values = np.linspace(-20.0, 20.0, 15)
    sweep = {"steps": 15, "targets": [{"point": "contact_patch_center",
             "direction": {"vector": [0.23, 0.0, 1.0]}, "start": -20.0, "stop": 20.0}]}  # fmt: skip
    results = corner.run_sweep(sweep)
    assert results["solver_converged"].all()
    cp = np.column_stack([results[f"contact_patch_center_{a}"] for a in "xyz"])  # mm
    design = corner.geometry.design_points()["contact_patch_center"] * 1e3
    np.testing.assert_allclose((cp - design) @ d, values, rtol=0, atol=1e-9)
