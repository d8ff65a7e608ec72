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
