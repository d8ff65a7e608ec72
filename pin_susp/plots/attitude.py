"""The attitude's g-g plot (``pin-susp attitude --plot``, docs/vehicle.md): over the
accelerations (ay across, ax up, in g), the TLLTD, the body's roll and pitch and each
corner's camber to ground, a panel each — filled contours where the points span an
area (a grid), coloured points otherwise; the points with no equilibrium crossed.
"""

from __future__ import annotations

import numpy as np

PANELS = (
    ("tlltd", "TLLTD (front share of the lateral load transfer)", "%"),
    ("roll", "Body roll (+ right side down)", "deg"),
    ("pitch", "Body pitch (+ nose down)", "deg"),
    ("camber_to_ground_fl", "Camber to ground, front left", "deg"),
    ("camber_to_ground_fr", "Camber to ground, front right", "deg"),
    ("camber_to_ground_rl", "Camber to ground, rear left", "deg"),
    ("camber_to_ground_rr", "Camber to ground, rear right", "deg"),
)


def gg_figure(results, title: str):
    """The figure (matplotlib, Agg) of an attitude's results (Results: ``ax``, ``ay``
    and the panels' columns)."""
    from matplotlib.figure import Figure
    from matplotlib.tri import Triangulation

    ax_g, ay_g = np.asarray(results["ax"]), np.asarray(results["ay"])
    ok = np.asarray(results["solver_converged"], dtype=bool)
    drawn = [p for p in PANELS if p[0] in results and np.isfinite(results[p[0]]).any()]
    cols = 4 if len(drawn) > 4 else len(drawn)
    rows = -(-len(drawn) // cols)
    fig = Figure(figsize=(4.2 * cols, 3.8 * rows + 0.6))
    fig.suptitle(title)
    area = _spans_area(ay_g[ok], ax_g[ok])
    for k, (name, text, unit) in enumerate(drawn):
        axis = fig.add_subplot(rows, cols, k + 1)
        values = np.asarray(results[name], dtype=float)
        good = ok & np.isfinite(values)
        if area and good.sum() >= 3 and _spans_area(ay_g[good], ax_g[good]):
            tri = Triangulation(ay_g[good], ax_g[good])
            filled = axis.tricontourf(tri, values[good], levels=14, cmap="viridis")
            lines = axis.tricontour(tri, values[good], levels=7, colors="k", linewidths=0.5)
            axis.clabel(lines, fontsize=7, fmt="%.3g")
        else:
            filled = axis.scatter(ay_g[good], ax_g[good], c=values[good], cmap="viridis", s=40)
        fig.colorbar(filled, ax=axis, label=unit)
        if (~ok).any():
            axis.plot(ay_g[~ok], ax_g[~ok], "x", color="crimson", label="no equilibrium")
            axis.legend(loc="lower right", fontsize=7)
        axis.set_title(text, fontsize=9)
        axis.set_xlabel("ay (g, + left)")
        axis.set_ylabel("ax (g, + forward)")
        axis.grid(alpha=0.3)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    return fig


def _spans_area(x: np.ndarray, y: np.ndarray) -> bool:
    """Whether the points span an area (not all on one line)."""
    if len(x) < 3:
        return False
    pts = np.stack([x - x.mean(), y - y.mean()], axis=1)
    s = np.linalg.svd(pts, compute_uv=False)
    return bool(s[-1] > 1e-9 * max(s[0], 1e-300))
