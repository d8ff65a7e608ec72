"""The instant-centre construction on a drawing (``drawing.py``): a corner's front-
and side-view instant centres (the instant axis ∩ the view plane through the wheel
centre), each drawn from the kingpin's ends with the contact patch's line through
it — in front view on to the centreline, the roll centre of a symmetric axle — and
an axle's roll centre where its two contact-patch lines cross. An instant centre
at infinity, or further than IC_FAR, is noted, not drawn.
"""

from __future__ import annotations

import numpy as np

from ..columns.metrics import PointSet, X, Y

FRONT, SIDE = (1, 2), (0, 2)  # the world axes each view shows, in mm
IC_FAR = 20_000.0  # mm from the wheel centre: beyond this an instant centre is noted, not drawn
CONSTRUCTION = "#c2185b"  # instant-centre construction: a colour no body has
PARALLEL = "arms parallel: instant centre at infinity"
ANTI = {  # a car's anti columns (docs/vehicle.md), as its side view's note says them
    "anti_dive_front": "anti-dive front",
    "anti_lift_rear": "anti-lift rear (braking)",
    "anti_squat_rear": "anti-squat rear",
    "anti_lift_front": "anti-lift front (drive)",
}


def in_mm(c) -> dict[str, np.ndarray]:
    """A corner's (or a posed corner's) design positions, in mm."""
    return {k: v * 1e3 for k, v in c.design_positions.items()}


def instant_centres(front, side, corner) -> tuple[list[str], list[np.ndarray]]:
    """Draw the FVIC and SVIC constructions; which were drawn, and the points (mm) the
    view should keep."""
    design = {k: v[None] for k, v in corner.design_positions.items()}
    # with the rates at design: a mechanism's instant centres may come from its twist
    ps = PointSet(corner.motion([corner.q_design]), design, corner.geometry)
    rays = _kingpin_rays(ps, corner.geometry, lambda n: corner.body_of(n) == "chassis")
    p = in_mm(corner)
    drawn, keep = [], []
    for ax, axis, view, name in ((front, X, FRONT, "FVIC"), (side, Y, SIDE, "SVIC")):
        ic = _instant_centre(ps, axis)
        problem = _too_far(ic, p["wheel_center"][list(view)], name)
        if problem is not None:
            _note(ax, problem)
        else:
            keep += _construction(ax, p, rays, view, ic, name)
            drawn.append(name)
    return drawn, keep


def _kingpin_rays(ps: PointSet, geometry, on_chassis) -> list[np.ndarray]:
    """Where the instant-centre construction starts (mm, upper first): the kingpin's
    ends (ball joints, virtual or the top mount); without a kingpin (a trailing arm),
    the chassis points of the wheel's body (``on_chassis(point)``)."""
    from ..maths.jet import value

    with np.errstate(invalid="ignore", divide="ignore"):
        ends = ps.kingpin()
    if ends is None:
        names = geometry.mechanism.upright_points(geometry)
        ends = [ps[n] for n in names if on_chassis(n)][:2]
    return [value(e)[0] * 1e3 for e in reversed(ends)]


def _instant_centre(ps: PointSet, axis: int) -> np.ndarray:
    """The instant axis ∩ the view plane through WC normal to ``axis`` (mm, the view's
    two coordinates); NaN when there is none."""
    from ..maths.jet import value

    with np.errstate(invalid="ignore", divide="ignore"):
        return np.array([value(x)[0] for x in ps.instant_axis_point(axis)], dtype=float) * 1e3


def _too_far(ic: np.ndarray, wheel_centre: np.ndarray, name: str) -> str | None:
    """Why an instant centre is not drawn (at infinity, or beyond IC_FAR), or None."""
    if not np.all(np.isfinite(ic)):
        return PARALLEL
    far = float(np.linalg.norm(ic - wheel_centre))
    if far > IC_FAR:
        return f"arms nearly parallel: {name} {far / 1e3:.0f} m away, not drawn"
    return None


def _arms_to(ax, rays, view, ic, name, tag: str = "") -> None:
    """The kingpin's ends to the IC (dashed) and the IC, named."""
    v = list(view)
    for end in rays:
        line = np.array([end[v], ic])
        ax.plot(*line.T, "--", color=CONSTRUCTION, lw=0.9, gid=f"{name.lower()}_arm{tag}")
    ax.plot(*ic, "o", color=CONSTRUCTION, ms=4, gid=f"{name.lower()}{tag}")
    ax.annotate(
        name, ic, xytext=(4, -9), textcoords="offset points", fontsize=7, color=CONSTRUCTION
    )


def _construction(ax, p, rays, view, ic, name) -> list[np.ndarray]:
    """From the kingpin's ends (ball joints, virtual or the top mount) to the IC
    (dashed), the contact patch through it; front view: on to the centreline, the roll
    centre of a symmetric axle. Returns the roll centre, if any."""
    v = list(view)
    _arms_to(ax, rays, view, ic, name)
    cp = p["contact_patch_center"][v]
    text = f"{name}: {'y' if name == 'FVIC' else 'x'} = {ic[0]:.0f} mm, z = {ic[1]:.0f} mm"
    ends, keep = [0.0, 1.0], []  # along the line from CP (0) through the IC (1)
    if name == "FVIC":
        t = _roll_centre(cp, ic)
        if t is None:
            text += "\nRC (symmetric axle): further than 20 m, not drawn"
        else:
            ends.append(t)
            keep.append(rc := cp + t * (ic - cp))
            ax.plot(*rc, "D", color=CONSTRUCTION, ms=5, gid="roll_centre")
            ax.annotate(
                "RC (symmetric axle)",
                rc,
                xytext=(5, 5),
                textcoords="offset points",
                fontsize=7,
                color=CONSTRUCTION,
            )
            text += f"\nRC (symmetric axle): z = {rc[1]:.0f} mm"
    line = np.array([cp + t * (ic - cp) for t in (min(ends), max(ends))])
    ax.plot(*line.T, "-.", color=CONSTRUCTION, lw=0.9, gid=f"{name.lower()}_contact_patch")
    _note(ax, text)
    return keep


def _roll_centre(cp: np.ndarray, ic: np.ndarray) -> float | None:
    """Where the line CP → FVIC meets the centreline y = 0, as a multiple of FVIC − CP;
    None when that is further than IC_FAR (an FVIC straight above the patch)."""
    run = ic[0] - cp[0]
    if abs(run) * IC_FAR <= abs(cp[0]) * float(np.linalg.norm(ic - cp)):
        return None
    return -cp[0] / run


def _note(ax, text: str, x: float = 0.02, ha: str = "left") -> None:
    """A note in a box at the top of the view: its left side at ``x`` (of the axes'
    width), or its middle with ``ha="center"``."""
    ax.text(
        x,
        0.98,
        text,
        transform=ax.transAxes,
        va="top",
        ha=ha,
        fontsize=8,
        gid="ic_note",
        bbox={"facecolor": "white", "edgecolor": "0.7", "alpha": 0.85},
    )


def roll_centre_construction(ax, model, q, sides) -> tuple[bool, list[np.ndarray]]:
    """Each side's FVIC construction and the crossing of the contact-patch lines, the
    roll centre; whether it was drawn, and the points (mm) the view should keep."""
    from ..maths.vectors import roll_centre

    # with the rates (solved here): a mechanism's FVIC may come from its twist
    motion = model.motion([q])
    d = model.design_positions
    lines, notes = {}, []
    for s, c in sides.items():
        own = {k: motion[f"{s}_{k}"][s] for k in model.point_names[s]}
        ps = PointSet(own, {k: d[f"{s}_{k}"][None] for k in model.point_names[s]}, c.geometry)
        ic = _instant_centre(ps, X)
        p = in_mm(c)
        problem = _too_far(ic, p["wheel_center"][list(FRONT)], "FVIC")
        if problem is None:
            on_chassis = lambda n, s=s: model.points[f"{s}_{n}"].body == "chassis"  # noqa: E731
            _arms_to(ax, _kingpin_rays(ps, c.geometry, on_chassis), FRONT, ic, "FVIC", f"_{s}")
            notes.append(f"FVIC {s}: y = {ic[0]:.0f} mm, z = {ic[1]:.0f} mm")
        else:
            notes.append(f"{s}: {problem}")
        if np.all(np.isfinite(ic)):
            lines[s] = (p["contact_patch_center"][list(FRONT)], ic, problem is None)
    rc = None
    if len(lines) == 2:
        with np.errstate(invalid="ignore", divide="ignore"):
            rc = np.array(roll_centre([(*cp, *ic) for cp, ic, _ in lines.values()]), dtype=float)
        middle = 0.5 * (lines["left"][0] + lines["right"][0])
        if not np.all(np.isfinite(rc)):
            notes.append("RC: the contact-patch lines are parallel")
            rc = None
        elif (far := float(np.linalg.norm(rc - middle))) > IC_FAR:
            notes.append(f"RC {far / 1e3:.0f} m away, not drawn")
            rc = None
        else:
            ax.plot(*rc, "D", color=CONSTRUCTION, ms=6, gid="roll_centre")
            ax.annotate(
                "RC", rc, xytext=(6, 5), textcoords="offset points", fontsize=8, color=CONSTRUCTION
            )
            y, z = np.round(rc) + 0.0  # a centre a hair left of the centreline: 0, not -0
            notes.insert(0, f"RC: y = {y:.0f} mm, z = {z:.0f} mm")
    else:
        missing = [s for s in sides if s not in lines]
        notes.append("RC: no front-view instant centre on " + " and ".join(missing))
    for s, (cp, ic, near) in lines.items():
        ends = [0.0, 1.0] if near else [0.0]  # along CP (0) → FVIC (1)
        if rc is not None:
            ends.append(float((rc - cp) @ (ic - cp) / ((ic - cp) @ (ic - cp))))
        if len(ends) == 1:  # a far FVIC, no roll centre: towards the FVIC, as long as CP_y
            ends.append(abs(cp[0]) / float(np.linalg.norm(ic - cp)))
        line = np.array([cp + t * (ic - cp) for t in (min(ends), max(ends))])
        ax.plot(*line.T, "-.", color=CONSTRUCTION, lw=0.9, gid=f"fvic_contact_patch_{s}")
    _note(ax, "\n".join(notes))
    return rc is not None or any(near for *_, near in lines.values()), [] if rc is None else [rc]


def pitch_centre_construction(ax, results, ends: dict) -> list[np.ndarray]:
    """A whole car's side view at a step of its results (row 0, mm, the chassis frame):
    each axle's SVIC (``ends``: end → its corners' labels; the mean of their
    ``svic_x_<c>``, ``svic_z_<c>``), the line from its contact patch (the mean of its
    two) through it, and where the two lines meet, the pitch centre (``pitch_center_x``,
    ``_z``: docs/vehicle.md). An SVIC at infinity (blank) or further than IC_FAR, or a
    pitch centre blank or that far, is noted, not drawn. The points (mm) the view
    should keep: the pitch centre, where drawn."""

    def at(name):
        return float(results[name][0]) if name in results.columns else np.nan

    pc = np.array([at("pitch_center_x"), at("pitch_center_z")])
    lines, notes = {}, []
    for end, labels in ends.items():
        cp = np.mean([[at(f"{c}_contact_patch_center_{k}") for k in "xz"] for c in labels], 0)
        sv = np.mean([[at(f"svic_{k}_{c}") for k in "xz"] for c in labels], axis=0)
        problem = _too_far(sv, cp, f"SVIC {end}")
        if problem is None:
            ax.plot(*sv, "o", color=CONSTRUCTION, ms=4, gid=f"svic_{end}")
            ax.annotate(
                f"SVIC {end}",
                sv,
                xytext=(4, -9),
                textcoords="offset points",
                fontsize=7,
                color=CONSTRUCTION,
            )
            notes.append(f"SVIC {end}: x = {sv[0]:.0f} mm, z = {sv[1]:.0f} mm")
        else:
            notes.append(f"{end}: {problem}".replace("arms", "arms in side view", 1))
        if np.all(np.isfinite(sv)):
            lines[end] = (cp, sv, problem is None)
    middle = np.mean([cp for cp, _, _ in lines.values()], axis=0) if lines else None
    keep = []
    if not np.all(np.isfinite(pc)):
        notes.insert(0, "pitch centre: none (an SVIC at infinity, or the lines parallel)")
        pc = None
    elif (far := float(np.linalg.norm(pc - middle))) > IC_FAR:
        notes.insert(0, f"pitch centre {far / 1e3:.0f} m away, not drawn")
        pc = None
    else:
        ax.plot(*pc, "D", color=CONSTRUCTION, ms=6, gid="pitch_centre")
        ax.annotate(
            "PC", pc, xytext=(6, 5), textcoords="offset points", fontsize=8, color=CONSTRUCTION
        )
        x, z = np.round(pc) + 0.0
        notes.insert(0, f"pitch centre: x = {x:.0f} mm, z = {z:.0f} mm")
        keep.append(pc)
    for end, (cp, sv, near) in lines.items():
        ends_at = [0.0, 1.0] if near else [0.0]  # along CP (0) → SVIC (1)
        if pc is not None:
            ends_at.append(float((pc - cp) @ (sv - cp) / ((sv - cp) @ (sv - cp))))
        if len(ends_at) == 1:  # a far SVIC, no pitch centre: towards it, a wheelbase long
            ends_at.append(float(np.linalg.norm(middle - cp)) * 2 / float(np.linalg.norm(sv - cp)))
        line = np.array([cp + t * (sv - cp) for t in (min(ends_at), max(ends_at))])
        ax.plot(*line.T, "-.", color=CONSTRUCTION, lw=0.9, gid=f"pitch_line_{end}")
    for name, said in ANTI.items():
        if np.isfinite(value := at(name)):
            notes.append(f"{said}: {value:.1f} %")
    _note(ax, "\n".join(notes), 0.5, "center")  # between the axles: the corners at its sides
    return keep
