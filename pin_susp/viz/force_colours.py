"""Members coloured by their force in the 3D view (``viz.py``). Under a load
case (``pin-susp view GEOMETRY SWEEP --cases LOADS --case NAME``)
the members are coloured by their force at each frame: the links drawn
between their ends and the coilover (its compression is the spring's
``force_spring``), and the URDF's rods that are two-force members (a
wishbone's legs, a multilink's tree link). The colour is matplotlib's
``coolwarm`` at 0.5 + 0.5·tension/scale: red in tension, blue in
compression, grey at zero, the scale being the largest |force| of any
coloured member over the sweep under that case; near-black at a toggle,
where the force is unbounded. A wishbone leg that is not a two-force member
(its arm carries a pushrod or a spring: its leg columns are blank) is
yellow-green, off the ramp. An axle's are both corners' and its droplinks,
under one scale; the bar's torque (``torque_arb``, N·m) is no force on that
scale, and the bar keeps its own colour. One replay shows one case: meshcat's
animation is one clip of poses and colours, and a selector would need
either a copy of every member per case or code reaching into meshcat's
player.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from .view_parts import ROOT, segments

FORCE_MAP = "coolwarm"  # matplotlib's: blue (compression) → grey (0) → red (tension)
UNBOUNDED = (0.1, 0.1, 0.1)  # a member at a toggle: its force has no bound
# a wishbone leg that is no two-force member (its arm carries a pushrod, say): no tension
# to colour, and none of the ramp's colours (its blue would read as compression)
NOT_TWO_FORCE = (0.6, 0.8, 0.2)  # yellow-green


def members(model, viz, columns) -> dict[str, str]:
    """Force column → the node drawing that member (``pin-susp loads``' names): a link
    drawn between its ends (``force_trackrod``, a multilink's links; the coilover for
    ``force_spring``), else the as-set model's rod between the member's ends (a
    wishbone's legs ``force_<arm>_front``/``_rear``, a multilink's tree link). An
    axle's columns end with their side (``force_trackrod_left``: the link
    ``left_trackrod``; ``force_droplink_right``: ``right_droplink``)."""
    drawn = segments(model, model.design_positions)
    data = model.model.createData()
    placed = viz.visual_model.createData()
    pin.updateGeometryPlacements(model.model, data, viz.visual_model, placed, model.q_design)
    middles = [
        (o, placed.oMg[i].translation) for i, o in enumerate(viz.visual_model.geometryObjects)
    ]
    p = model.design_positions
    out = {}
    for column in columns:
        name = column.removeprefix("force_")
        bare, _, label = name.rpartition("_")
        prefix = model.prefix(label) if label in model.labels else ""
        if prefix:  # an axle's: force_<member>_<side> is its side's <side>_<member>
            name = prefix + bare
        link = prefix + "coilover" if name == prefix + "spring" else name
        if not column.startswith("force_") or name == "rack":
            continue
        if link in drawn:
            out[column] = f"{ROOT}/links/{link}"
            continue
        arm, _, end = name.rpartition("_")
        for a, b in (
            (f"{name}_inboard", f"{name}_outboard"),
            (f"{arm}_inboard_{end}", f"{arm}_outboard"),
        ):
            if a in p and b in p:
                middle = 0.5 * (p[a] + p[b])
                rod = next((o for o, m in middles if np.linalg.norm(m - middle) < 1e-9), None)
                if rod is not None:
                    out[column] = viz.getViewerNodeName(rod, pin.GeometryType.VISUAL)
    return out


def force_colours(model, viz, forces, case: str) -> tuple[dict[str, np.ndarray], float, list[str]]:
    """Each member's colour at each step of ``forces`` (a Results or ResultsFile of
    ``pin-susp loads``) under the load case ``case``: {node: rgb rows}, and the scale
    (N): the largest |force| of a coloured member over the sweep. Tension red,
    compression blue, grey at zero (``FORCE_MAP``); UNBOUNDED where the force is
    blank (a toggle). A member whose column is blank at every other step (a leg of
    an arm that carries more than its ball joint: no two-force member) is
    NOT_TWO_FORCE, off the ramp; and those nodes."""
    import matplotlib

    rows = np.asarray(forces["load_case"]) == case
    bounded = np.asarray(forces["loads_unbounded"], dtype=float)[rows] == 0.0
    # a spring's column (each corner's) is its compression
    sign = {f"force_spring{model.suffix(label)}": -1.0 for label in model.labels}
    tension = {
        node: sign.get(column, 1.0) * np.asarray(forces[column], dtype=float)[rows]
        for column, node in members(model, viz, forces.columns).items()
    }
    # a leg blank wherever the forces are bounded is no two-force member (its arm
    # carries the pushrod): NOT_TWO_FORCE, off the scale
    bent = [n for n, t in tension.items() if bounded.any() and not np.isfinite(t).any()]
    tension = {n: t for n, t in tension.items() if n not in bent}
    scale = max((float(np.nanmax(np.abs(t), initial=0.0)) for t in tension.values()), default=0.0)
    ramp = matplotlib.colormaps[FORCE_MAP]
    out = {}
    for node, t in tension.items():
        share = t / scale if scale > 0.0 else np.zeros_like(t)
        rgb = ramp(0.5 + 0.5 * np.nan_to_num(share))[:, :3]
        rgb[~np.isfinite(t)] = UNBOUNDED
        out[node] = rgb
    for node in bent:
        rgb = np.tile(NOT_TWO_FORCE, (len(bounded), 1))
        rgb[~bounded] = UNBOUNDED
        out[node] = rgb
    return out, scale, bent


def set_colour(node, rgb) -> None:
    """A member's colour (rgb, 0 to 1): of the node's mesh, or of an animation frame (a
    colour track on the mesh's material)."""
    from meshcat.animation import AnimationFrameVisualizer

    rgb = [float(c) for c in rgb]
    if isinstance(node, AnimationFrameVisualizer):
        node["<object>"].set_property("material.color", "color", rgb)
    else:
        node.set_property("color", [*rgb, 1.0])


def force_key(case: str, scale: float, note: str = "", bent: bool = False) -> str:
    """The colours' key, one line of text: the case, the scale, what red and blue are;
    ``bent``: some legs are no two-force members (their colour said too)."""
    return (
        f"members coloured by force under {case!r}{f' ({note})' if note else ''}: "
        f"red tension, blue compression, grey 0, full colour at {scale:.0f} N "
        "(the largest |force| over the sweep); near-black: unbounded (a toggle)"
        + (
            "; yellow-green: a wishbone leg that is not a two-force member (its arm "
            "carries more than its ball joint: see its *_bushing_along_leg columns)"
            if bent
            else ""
        )
    )


def force_caption(case: str, scale: float, source: str = "", bent: bool = False) -> str:
    """The key as an HTML block over the replay: a colour bar from −scale to +scale
    (``bent``: and the colour of a leg that is no two-force member)."""
    import html

    import matplotlib

    ramp = matplotlib.colormaps[FORCE_MAP]
    stops = ", ".join(matplotlib.colors.to_hex(ramp(t)) for t in np.linspace(0.0, 1.0, 9))
    black = matplotlib.colors.to_hex(UNBOUNDED)
    return (
        '<div id="force_key" style="position:fixed;left:8px;top:8px;z-index:10;'
        "font:12px sans-serif;background:rgba(255,255,255,0.85);padding:6px 8px;"
        f'border-radius:4px">Load case <b>{html.escape(case)}</b>'
        f"{html.escape(f' ({source})') if source else ''}<br>"
        f'<div style="width:220px;height:10px;margin:4px 0;background:linear-gradient('
        f'to right, {stops})"></div>'
        f'<div style="display:flex;justify-content:space-between;width:220px">'
        f"<span>−{scale:.0f} N</span><span>0</span><span>+{scale:.0f} N</span></div>"
        f"compression ← → tension; "
        f'<span style="color:{black}">■</span> unbounded (toggle)'
        + (
            f'<br><span style="color:{matplotlib.colors.to_hex(NOT_TWO_FORCE)}">■</span> '
            "not a two-force member (no tension: its arm carries more than its ball joint)"
            if bent
            else ""
        )
        + "</div>"
    )
