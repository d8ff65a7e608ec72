"""The K&C report (``pin-susp kc --plot``): the classic four — lateral force steer and
camber, braking steer and recession (longitudinal compliance) — against wheel travel,
a line per wheel (docs/compliance.md)."""

from __future__ import annotations

import numpy as np

PANELS = (
    ("lateral_force_steer", "Lateral force steer", "deg/kN"),
    ("lateral_force_camber", "Lateral force camber", "deg/kN"),
    ("longitudinal_force_steer", "Braking steer (at the contact patch)", "deg/kN"),
    ("longitudinal_compliance", "Recession (at the contact patch)", "mm/kN"),
)


def kc_figure(results, labels: tuple[str, ...], suffix):
    """The four panels from a K&C Results (kc_results), x each wheel's travel (its
    ``wheel_travel`` column: mm, + up, relative to the chassis; a line per wheel on an
    axle or a car)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    first = results["load_case"] == results["load_case"][0]  # the rates: the same per case
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), constrained_layout=True)
    for ax, (name, title, unit) in zip(axes.flat, PANELS, strict=True):
        for label in labels:
            s = suffix(label)
            z = np.asarray(results[f"wheel_travel{s}"][first], dtype=float)
            y = np.asarray(results[f"{name}{s}"][first], dtype=float)
            ax.plot(z, y, label=label or "corner")
        ax.set_title(title)
        ax.set_xlabel("wheel travel [mm]")
        ax.set_ylabel(f"{name} [{unit}]")
        ax.grid(True, alpha=0.3)
    axes.flat[0].legend()
    method = results.meta.get("kc_method", "linear")
    fig.suptitle(
        f"pin_susp K&C ({method}): toe-in +; forces toward the centreline, braking rearward"
    )
    return fig
