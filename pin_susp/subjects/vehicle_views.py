"""What the 3D view and the drawing ask a vehicle (docs/vehicle.md, "View" and "Draw"):
its design state on the road, the markers in the road's frame (each axle's roll centre,
the pitch centre, the CG) and each axle on its own, posed at the car's design step for
its front view.

``VehicleViews`` is a part of :class:`~pin_susp.subjects.vehicle.Vehicle`: it reads the
vehicle's ``vehicle`` (its VehicleGeometry), ``body`` (the body on the road) and its
sweep.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..model.sweep import Sweep, Target
from .elements import rack
from .vehicle_file import AXLES

DESIGN = "<the design state on the road>"  # the design sweep's source, as messages name it


class VehicleViews:
    """A vehicle's answers to the 3D view and the drawing (scene.py, drawing.py)."""

    # the view's markers, each from the results' columns put in the road's frame
    markers = ("roll_centre_front", "roll_centre_rear", "pitch_centre", "cg")
    # its drawing: the whole car's side view with the pitch-centre construction, and each
    # axle's front view (its axle drawing, the roll centre where its two lines cross)
    drawing_views = ("car side", "front axle", "rear axle")
    axle_labels = AXLES  # end (front, rear) → its corners' labels, left first

    def design_sweep(self) -> Sweep:
        """One step at design: the body's heave, pitch and roll 0 (the road 0 under every
        wheel, the rack held at design)."""
        zero = np.zeros(1)
        targets = [Target(None, None, zero, quantity=q) for q in ("heave", "pitch", "roll")]
        return Sweep(targets, DESIGN)

    def design_results(self):
        """Its results at design (one row): the design sweep solved, the wheels on the
        road. Solved once, then kept."""
        kept = self.__dict__.get("_design_results")
        if kept is None:
            kept = self.__dict__["_design_results"] = self.run_sweep(self.design_sweep())
            if not kept["solver_converged"][0]:
                raise InputError(
                    self.source, "hardpoints", "its design state on the road does not close"
                )
        return kept

    @property
    def q_rest(self) -> np.ndarray:
        """The design step's configuration: its body at heave, pitch and roll 0 with every
        wheel on the road (a car whose file's wheels are off the road at design settles
        them onto it)."""
        return self.design_results().meta["q"][0]

    def to_road(self, points: np.ndarray, results) -> np.ndarray:
        """Chassis-frame points (n, 3) mm, one per step of ``results``, in the road's
        frame (m) at each step's body pose: w = c + heave·ẑ + R_y(pitch)·R_x(roll)·(p − c)
        (docs/vehicle.md, "The points")."""
        heave = np.asarray(results["heave"], dtype=float) * 1e-3
        pitch, roll = (np.radians(np.asarray(results[k], dtype=float)) for k in ("pitch", "roll"))
        return self.body.to_world(np.asarray(points, dtype=float) * 1e-3, heave, pitch, roll)

    def marker_places(self, results) -> dict:
        """Each axle's roll centre (``roll_center_y_<end>``, ``_z_<end>``, x midway
        between its contact patches: the front view it is found in), the pitch centre
        (``pitch_center_x``, ``_z``, on the centre plane) and the CG, each step's in the
        road's frame (m, NaN where a column is blank)."""
        n = len(results["heave"])
        blank = np.full(n, np.nan)

        def column(name):
            return np.asarray(results.columns.get(name, blank), dtype=float)

        out = {}
        for end, (a, b) in AXLES.items():
            x = 0.5 * (
                column(f"{a}_contact_patch_center_x") + column(f"{b}_contact_patch_center_x")
            )
            at = np.column_stack(
                [x, column(f"roll_center_y_{end}"), column(f"roll_center_z_{end}")]
            )
            out[f"roll_centre_{end}"] = self.to_road(at, results)
        at = np.column_stack([column("pitch_center_x"), np.zeros(n), column("pitch_center_z")])
        out["pitch_centre"] = self.to_road(at, results)
        out["cg"] = self.to_road(np.tile(self.body.cg * 1e3, (n, 1)), results)
        return out

    def axles_at_design(self) -> dict:
        """end → (its axle on its own, an AxleModel of its axle file; its configuration):
        each wheel centre at its chassis-frame height at the car's design step and the
        rack at its travel there. Its front view's roll centre is then the car's
        ``roll_center_y_<end>``, ``_z_<end>`` at design (an axle's columns are its own
        sweep's: docs/vehicle.md)."""
        from .axle import AxleModel

        results = self.design_results()
        out = {}
        for end, (left, right) in AXLES.items():
            axle = AxleModel(getattr(self.vehicle, end))
            z = {
                s: results[f"{c}_wheel_center_z"][0] * 1e-3
                for s, c in (("left", left), ("right", right))
            }
            travel = 0.0
            if axle.model.existJointName(rack.JOINT):
                travel = results["rack_displacement"][0] * 1e-3
            solution = axle.solve(z, travel)
            if not solution.converged:
                raise InputError(
                    self.source,
                    end,
                    f"its {end} axle on its own does not reach the car's design pose",
                )
            out[end] = (axle, solution.q)
        return out
