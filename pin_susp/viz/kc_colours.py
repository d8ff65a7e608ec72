"""The K&C replay (``pin-susp kc GEOMETRY SWEEP --cases KC.yaml --view kc.html``,
docs/compliance.md): the sweep's motion with a small sphere at each bushing's pickup,
coloured at every frame by that bushing's deflection under one load case — its
translational magnitude √(radial² + axial²) (mm, the K&C table's
``bushing_<pickup>_radial``/``_axial`` columns) on matplotlib's ``YlOrRd``: pale
yellow at zero, dark red at the largest of any bushing over the sweep under that case.
One replay shows one case (``--case``, default the first), as the force replay does.
"""

from __future__ import annotations

import numpy as np

from .view_parts import ROOT

KC_MAP = "YlOrRd"  # matplotlib's: pale yellow (0) → dark red (the largest deflection)
SPHERE = 0.014  # m: a bushing's sphere


def bushing_node(column: str) -> str:
    """The scene node of a bushing (its columns' stem: ``bushing_<pickup>[_<label>]``)."""
    return f"{ROOT}/bushings/{column}"


def deflections(table, bushings, case: str) -> dict[str, np.ndarray]:
    """Each bushing's translational deflection (mm) at each step under ``case``:
    {stem: values}; ``bushings``: (stem, radial column, axial column, point) rows
    (analyses.compliance.KC.bushing_columns)."""
    rows = np.asarray(table["load_case"]) == case
    return {
        stem: np.hypot(
            np.asarray(table[radial], dtype=float)[rows],
            np.asarray(table[axial], dtype=float)[rows],
        )
        for stem, radial, axial, _ in bushings
    }


def kc_colours(table, bushings, case: str) -> tuple[dict[str, np.ndarray], float]:
    """{node: rgb rows, one per step} and the scale (mm): the largest deflection of
    any bushing over the sweep under ``case`` (a step that did not solve: grey)."""
    import matplotlib

    d = deflections(table, bushings, case)
    scale = max((float(np.nanmax(v, initial=0.0)) for v in d.values()), default=0.0)
    ramp = matplotlib.colormaps[KC_MAP]
    out = {}
    for stem, v in d.items():
        share = v / scale if scale > 0.0 else np.zeros_like(v)
        rgb = ramp(np.nan_to_num(share))[:, :3]
        rgb[~np.isfinite(v)] = (0.5, 0.5, 0.5)
        out[bushing_node(stem)] = rgb
    return out, scale


def add_bushings(scene, bushings) -> None:
    """A sphere per bushing in the scene (placed and coloured by the animation)."""
    import meshcat.geometry as mg

    for stem, *_ in bushings:
        scene.viewer[bushing_node(stem)].set_object(
            mg.Sphere(SPHERE), mg.MeshLambertMaterial(color=0xFFFFCC)
        )


def bushing_places(model, bushings, qs: list) -> dict[str, np.ndarray]:
    """Each bushing's pickup (m) at each pose (a car's chassis moves them; a step
    with no pose: NaN)."""
    out = {bushing_node(stem): np.full((len(qs), 3), np.nan) for stem, *_ in bushings}
    for i, q in enumerate(qs):
        if q is None:
            continue
        p = model.positions(q)
        for stem, _, _, point in bushings:
            out[bushing_node(stem)][i] = p[point]
    return out


def kc_caption(case: str, scale: float, source: str = "") -> str:
    """The key as an HTML block over the replay: a colour bar from 0 to the scale."""
    import html

    import matplotlib

    ramp = matplotlib.colormaps[KC_MAP]
    stops = ", ".join(matplotlib.colors.to_hex(ramp(t)) for t in np.linspace(0.0, 1.0, 9))
    return (
        '<div id="kc_key" style="position:fixed;left:8px;top:8px;z-index:10;'
        "font:12px sans-serif;background:rgba(255,255,255,0.85);padding:6px 8px;"
        f'border-radius:4px">Bushing deflection under <b>{html.escape(case)}</b>'
        f"{html.escape(f' ({source})') if source else ''}<br>"
        f'<div style="width:220px;height:10px;margin:4px 0;background:linear-gradient('
        f'to right, {stops})"></div>'
        f'<div style="display:flex;justify-content:space-between;width:220px">'
        f"<span>0</span><span>{scale:.4g} mm</span></div>"
        "√(radial² + axial²) at each bushing's pickup</div>"
    )


def kc_replay(scene, model, table, bushings, qs: list, case: str, source: str = "", fps=10.0):
    """Animate ``scene`` through ``qs`` with the bushings coloured under ``case``; the
    page (self-contained HTML), its frames and the scale (mm)."""
    add_bushings(scene, bushings)
    colours, scale = kc_colours(table, bushings, case)
    places = bushing_places(model, bushings, qs)
    frames = scene.animate(qs, fps=fps, colours=colours, places=places)
    return scene.html(kc_caption(case, scale, source)), frames, scale
