"""The state every row reads: a Pinocchio model and its data at one configuration."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

WORLD = pin.LOCAL_WORLD_ALIGNED


class Kinematics:
    """Pinocchio model + data; ``update(q)`` computes every frame and Jacobian."""

    def __init__(self, model: pin.Model, data: pin.Data | None = None):
        """``data``: the Data of a model of the same joints (a study's variant), reused."""
        self.model = model
        # (not model.createData(): that returns its Data by value, a copy as long again
        # as the build, which for a sensitivity model's 80 joints costs 10 ms)
        self.data = pin.Data(model) if data is None else data

    def update(self, q: np.ndarray) -> None:
        self.q = q
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)

    def update_positions(self, q: np.ndarray) -> None:
        """Frame placements only (no Jacobians): enough for residuals."""
        self.q = q
        pin.framesForwardKinematics(self.model, self.data, q)

    def frame_jacobian(self, frame_id: int) -> np.ndarray:
        """6×nv: linear velocity of the frame origin, then angular velocity, world axes.
        (Pinocchio returns a 6-vector when nv = 1: reshaped.)"""
        return pin.getFrameJacobian(self.model, self.data, frame_id, WORLD).reshape(6, -1)
