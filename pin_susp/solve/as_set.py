"""The as-set geometry: the camber shim and the length adjusters applied to the drawn
corner, before any sweep (docs/geometry.md, README "Setup").

``apply_setup`` fits the shim assembly (``shim.py``) first, then the length
adjusters on the main mechanism, holding the static load path — the rocker at
its design angle where there is a pushrod-rocker (the spring keeps its static
length), otherwise the wheel-centre height — and the rack at its design
position. The result is the design state of every later sweep;
``ride_height_change`` is −ΔCP_z from the drawn design.

This is the model's part of the setup: ``Corner`` and ``AxleModel`` build on the
as-set geometry. The setup's analyses — exact sensitivities, the setup sheet,
the inverse solve for targets — are ``setup.py``, above the corner.
"""

from __future__ import annotations

import copy
from dataclasses import replace
from functools import singledispatch

import numpy as np

from ..constraints import (
    MEASURES,
    DistanceClosure,
    JointTarget,
    LoopBranch,
    PointTarget,
    pick_branch,
)
from ..errors import InputError
from ..model.geometry import MM, Geometry, load_geometry
from .linkage import Linkage
from .solver import NewtonSolver

PARAMETER_KEYS = {
    "shim_thickness": "config.camber_shim.setup_thickness",
    "trackrod_length": "config.setup.trackrod_length_delta",
    "pushrod_length": "config.setup.pushrod_length_delta",
}
Z = np.array([0.0, 0.0, 1.0])


@singledispatch
def as_geometry(g) -> Geometry:
    """A Geometry from a path, a dict or a Geometry (as Corner accepts): a path or a
    dict read by ``load_geometry``, a Geometry as it is."""
    return load_geometry(g)


@as_geometry.register
def _as_read(g: Geometry) -> Geometry:
    return g


def apply_setup(g) -> Geometry:
    """The as-set geometry: shim, then adjusters. Unchanged (the same object) when
    the setup equals the design. ``g``: a path, a dict or a Geometry."""
    g = as_geometry(g)
    if not g.needs_setup:
        return g
    hardpoints = dict(g.hardpoints)
    shim = g.camber_shim
    if shim is not None and shim.setup_thickness != shim.design_thickness:
        from .shim import ShimAssembly  # a fitted shim only: a plain sweep needs none

        hardpoints.update(ShimAssembly(g).shimmed_hardpoints())
        check_branches(g, hardpoints, PARAMETER_KEYS["shim_thickness"])
    as_set = replace(g, hardpoints=hardpoints, drawn=g)
    if g.trackrod_length_delta != 0.0 or g.pushrod_length_delta != 0.0:
        hardpoints.update(adjusted_hardpoints(as_set))
        as_set = replace(as_set, hardpoints=hardpoints)
    cp_drawn = g.design_points()["contact_patch_center"][2]
    cp_set = as_set.design_points()["contact_patch_center"][2]
    return replace(as_set, ride_height_change=-(cp_set - cp_drawn))


def check_branches(drawn: Geometry, hardpoints: dict[str, np.ndarray], key: str) -> None:
    """The set-up corner must be the drawn mechanism: every loop on its drawn branch (an
    InputError at ``key`` otherwise)."""
    for loop in drawn.mechanism.tree(drawn).closures:
        if not loop.branch:
            continue
        measure = MEASURES[loop.branch_kind]
        points, before = pick_branch(loop.branch_candidates, measure, lambda n: drawn.hardpoints[n])
        after = measure(*(hardpoints[n] for n in points))
        if abs(before) >= LoopBranch.DEGENERATE and before * after <= 0.0:
            raise InputError(
                drawn.source,
                key,
                f"the corner assembles this way only with the {loop.name} loop flipped over "
                "(another assembly branch): beyond the linkage's reach",
            )


def adjusted_hardpoints(g: Geometry) -> dict[str, np.ndarray]:
    """Apply the trackrod/pushrod length changes with the static load path held: every
    hardpoint of the assembled corner."""
    corner = Linkage(g)
    delta = {
        "trackrod": g.trackrod_length_delta,
        "toe_link": g.trackrod_length_delta,
        "pushrod": g.pushrod_length_delta,
    }
    closures = [
        DistanceClosure(c.name, c.a, c.b, c.length + delta.get(c.name, 0.0))
        if isinstance(c, DistanceClosure)
        else c
        for c in corner.closures
    ]
    solver = NewtonSolver(
        corner.kin, closures, static_holds(corner, corner.q_design), corner.branches
    )
    solution = solver.newton(corner.q_design)
    if not solution.converged:
        key = "trackrod_length_delta" if g.pushrod_length_delta == 0.0 else "pushrod_length_delta"
        raise InputError(
            g.source,
            f"config.setup.{key}",
            f"the corner does not assemble with these lengths ({solution.why}): "
            "beyond the linkage's reach",
        )
    positions = corner.positions(solution.q)
    return {name: positions[name] for name in g.hardpoints}


def static_holds(corner, q_static: np.ndarray) -> list:
    """The static load path: rack at design; rocker at design, else wheel-centre height
    (at ``q_static``) — the rows a length change is applied with, and the sensitivities'
    second solve (setup.SetupModel)."""
    holds = []
    if corner.geometry.steering == "rack":
        holds.append(JointTarget(corner.model, "rack_slide"))
    if corner.geometry.has_pushrod:
        holds.append(JointTarget(corner.model, "rocker_pivot"))
    else:
        wc = corner.positions(q_static)["wheel_center"][2]
        holds.append(PointTarget(corner.points["wheel_center"], Z, wc))
    return holds


# ---------------------------------------------------------------- the setup written back


def geometry_data(g: Geometry) -> dict:
    """The geometry file's data with the setup values of g written in (mm)."""
    data = copy.deepcopy(g.data)
    config = data.setdefault("config", {})
    if g.camber_shim is not None:
        config["camber_shim"]["setup_thickness"] = g.camber_shim.setup_thickness / MM
    adjusters = {}
    if g.trackrod_length_delta:
        adjusters["trackrod_length_delta"] = g.trackrod_length_delta / MM
    if g.pushrod_length_delta:
        adjusters["pushrod_length_delta"] = g.pushrod_length_delta / MM
    if adjusters:
        config["setup"] = adjusters
    else:
        config.pop("setup", None)
    return data


def axle_data(axle, geometries: dict) -> dict:
    """The axle file's data (an AxleGeometry's) with each given side's setup values
    written in (``axle_config.<side>_setup``, mm). A mirrored axle's right side is the
    left's: only left_setup is written."""
    data = copy.deepcopy(axle.data)
    config = data["axle_config"]
    for side, g in geometries.items():
        if axle.mirrored and side == "right":
            continue
        corner = geometry_data(g)["config"]
        written = {"camber_shim": corner["camber_shim"]} if "camber_shim" in corner else {}
        written |= corner.get("setup", {})
        if written:
            config[f"{side}_setup"] = written
        else:
            config.pop(f"{side}_setup", None)
    return data
