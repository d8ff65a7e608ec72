"""What the vehicle tests share: a sweep of the body's pose built in code."""

from __future__ import annotations

import numpy as np

from pin_susp.model.sweep import Sweep, Target


def body_sweep(heave, pitch, roll, steer=0.0, roads=None) -> Sweep:
    """A vehicle sweep of the body's heave (mm), pitch and roll (deg), the steering
    wheel (deg) and, where given, each corner's road height (mm; ``roads``: corner →
    values): scalars or arrays, every target the longest's length."""
    values = (heave, pitch, roll, steer, *(roads or {}).values())
    n = max(len(np.atleast_1d(v)) for v in values)
    full = lambda v: np.broadcast_to(np.asarray(v, dtype=float), (n,)).copy()  # noqa: E731
    targets = [
        Target(None, None, full(heave), quantity="heave"),
        Target(None, None, full(pitch), quantity="pitch"),
        Target(None, None, full(roll), quantity="roll"),
        Target(None, None, full(steer), quantity="steering_wheel"),
    ]
    for label, z in (roads or {}).items():
        targets.append(Target(None, None, full(z), side=label, quantity="road_z"))
    return Sweep(targets, "<test>")


def axle_alone(car, end: str, results):
    """That axle's own model (its AxleModel, from the car's AxleGeometry) and the sweep
    that holds it at the vehicle's chassis-frame wheel-centre heights (and the rack's
    travel) of ``results``: an independent model of the same axle."""
    from pin_susp.subjects.axle import AxleModel
    from pin_susp.subjects.vehicle import AXLES

    model = AxleModel(getattr(car.vehicle, end))
    first, second = AXLES[end]
    targets = [
        Target("wheel_center", "z", results[f"{label}_wheel_center_z"], "absolute", side=side)
        for label, side in ((first, "left"), (second, "right"))
    ]
    if model.model.existJointName("rack_slide"):
        rack = results[f"{first}_trackrod_inboard_y"]
        targets.append(Target("trackrod_inboard", "y", rack, "absolute", side="left"))
    return model, Sweep(targets, "<alone>")
