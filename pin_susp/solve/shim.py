"""The camber-shim assembly: a small Pinocchio model of the split upright.

Adding shim between the camber block (which carries the upper ball joint)
and the upright body (which carries the lower ball joint, the axle and the
trackrod arm) changes the upright itself, so it is solved before any sweep:

| body           | joint to parent                              |
|----------------|----------------------------------------------|
| chassis        | root; the rack and the lower wishbone stay put |
| upper_wishbone | revolute about its pivot line (1 unknown)    |
| camber_block   | ball at the upper ball joint (3 unknowns)    |
| upright_body   | ball at the lower ball joint (3 unknowns)    |

Ten residuals: datum A and datum B closures (faces separated by the fitted
stack along the block's normal, 3 + 3), face normal alignment (3) and the
trackrod length with the rack fixed (1). Gauss-Newton from zero rotations
reaches the consistent solution. The solved UBJ and the upright body's
points are the as-shimmed hardpoints: the design state of every later sweep.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..constraints import DistanceClosure, FaceAlignment, FramePoint, Kinematics, ShimGap
from ..errors import InputError
from ..model.geometry import Geometry, unit
from ..model.mechanisms.double_wishbone import upright_mounts
from ..model.tree import Body, Joint, Tree
from ..model.urdf import tree_to_urdf
from .solver import NewtonSolver

KEY = "config.camber_shim.setup_thickness"


def shim_tree(g: Geometry) -> Tree:
    """The split upright at its design state, datums on both faces."""
    p = g.design_points()
    shim = g.camber_shim
    half = 0.5 * shim.design_thickness * shim.normal
    front = p["upper_wishbone_inboard_front"]
    inner, _ = g.steering_points
    bodies = [
        Body("chassis"),
        Body(
            "upper_wishbone",
            "chassis",
            Joint(
                "upper_wishbone_pivot",
                "revolute",
                front,
                unit(p["upper_wishbone_inboard_rear"] - front),
            ),
        ),
        Body(
            "camber_block",
            "upper_wishbone",
            Joint("camber_block_ball", "ball", p["upper_wishbone_outboard"]),
        ),
        Body(
            "upright_body",
            "chassis",
            Joint("upright_body_ball", "ball", p["lower_wishbone_outboard"]),
        ),
    ]
    points = {
        inner: ("chassis", p[inner]),
        "upper_wishbone_outboard": ("upper_wishbone", p["upper_wishbone_outboard"]),
        "datum_a_block": ("camber_block", shim.point_a - half),
        "datum_b_block": ("camber_block", shim.point_b - half),
        "datum_a_body": ("upright_body", shim.point_a + half),
        "datum_b_body": ("upright_body", shim.point_b + half),
    }
    points |= {name: ("upright_body", p[name]) for name in upright_mounts(g)}
    return Tree("camber_shim_assembly", bodies, points, closures=[])


class ShimAssembly:
    """The shim model, its ten residual rows and their Gauss-Newton solve."""

    def __init__(self, g: Geometry):
        self.geometry = g
        self.tree = shim_tree(g)
        self.model = pin.buildModelFromXML(tree_to_urdf(self.tree))
        self.kin = Kinematics(self.model)
        self.points = {
            name: FramePoint(name, self.model.getFrameId(name), body)
            for name, (body, _) in self.tree.points.items()
        }
        inner, outer = g.steering_points
        shim, pt = g.camber_shim, self.points
        length = float(np.linalg.norm(g.hardpoints[outer] - g.hardpoints[inner]))
        self.gaps = [
            ShimGap(
                f"datum {d}",
                pt[f"datum_{d}_block"],
                pt[f"datum_{d}_body"],
                shim.normal,
                shim.setup_thickness,
            )
            for d in "ab"
        ]
        self.rows = self.gaps + [
            FaceAlignment("face normals", pt["datum_a_block"], pt["datum_a_body"], shim.normal),
            DistanceClosure("trackrod", pt[inner], pt[outer], length),
        ]

    def solve(self, thickness: float | None = None):
        """Assemble with the fitted stack ``thickness`` (m; default: the file's setup)."""
        for gap in self.gaps:
            gap.thickness = (
                self.geometry.camber_shim.setup_thickness if thickness is None else thickness
            )
        solution = NewtonSolver(self.kin, self.rows, []).newton(pin.neutral(self.model))
        if not solution.converged:
            raise InputError(
                self.geometry.source,
                KEY,
                f"the shimmed upright does not assemble (residual "
                f"{solution.max_residual * 1e3:.3g} mm): beyond the linkage's reach",
            )
        pin.framesForwardKinematics(self.model, self.kin.data, solution.q)
        return solution

    def shimmed_hardpoints(self, thickness: float | None = None) -> dict[str, np.ndarray]:
        """The hardpoints that move with a shim change, at the assembled state."""
        self.solve(thickness)
        moved = ["upper_wishbone_outboard"] + [
            n for n in upright_mounts(self.geometry) if n in self.geometry.hardpoints
        ]
        return {n: self.points[n].position(self.kin).copy() for n in moved}
