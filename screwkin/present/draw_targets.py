"""A synthesized design's targets on its skeleton drawing (present/draw.py): each target pose as a
numbered arrow at its origin along its x axis, each target point as a numbered cross, each
target angle as a numbered ray from its pivot; the frame the linkage reaches there (a thin dark
arrow, or a dot), and the linkage ghosted at the other precision positions (at most NUMBERED
targets numbered and ghosted, evenly chosen; the others marked only).  Every artist has
a gid a program can find: ``target:K`` (the target's origin, a marker whose data are the
target's coordinates in the drawing's plane), ``targetaxis:K``, ``targetlabel:K``,
``reached:K`` (the reached frame's origin), ``reachedaxis:K``, ``carrier:K`` (dotted lines from it to
the pins of the link that carries it), ``ghost:K:N`` (link N at position K); K counts from 1 in the
file's order.
"""

from __future__ import annotations

import numpy as np

from ..analysis.course.skeleton import skeleton
from ..analysis.design.targets import design_targets
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from matplotlib.axes import Axes
    from collections.abc import Callable
    from screwkin.analysis.course.skeleton import Skeleton

__all__ = ["design_marks", "design_drawing", "target_marks", "draw_targets", "NUMBERED"]

TARGET_COLOUR = "#6a3d9a"
#: At most this many targets are numbered, listed and ghosted (evenly chosen, the first and the last
#: among them); the others are marked only (function generation may have 200 precision points).
NUMBERED = 12


def design_marks(mech: Mechanism, q: np.ndarray, skel: Skeleton, inputs: list | None = None, steps: int = 360) -> tuple:
    """(analysis.design.targets.DesignTargets, marks) of ``mech``'s file drawn at ``q`` as ``skel``:
    the marks (target_marks) with the linkage's skeleton at each precision position other than the
    one drawn (in skel's plane, ``inputs`` marked)."""
    found = design_targets(mech, q, steps=steps)
    n = len(found.targets)
    shown = set(range(n)) if n <= NUMBERED else {int(i) for i in np.linspace(0, n - 1, NUMBERED).round()}
    ghosts = {}
    for k, t in enumerate(found.targets):
        if k in shown and t.q is not None and float(np.max(np.abs(mech.difference(q, t.q)))) > mech.tolerances.equal:
            ghosts[k] = skeleton(mech, t.q, inputs, basis=skel.basis)
    marks = target_marks(found, skel.basis, ghosts)
    welded = {j.child: j.parent for j in mech.spec.joints if j.type == "fixed"}
    for k, m in enumerate(marks):  # numbered or not; the pins of the link that carries a guided frame or a coupler point
        m["numbered"] = k in shown
        carrier = m["link"]
        while carrier in welded:
            carrier = welded[carrier]
        at = ghosts.get(k, skel) if found.targets[k].q is not None else None
        outline = next((lk.outline for lk in at.links if lk.name == carrier), ()) if at is not None else ()
        m["carrier"] = [list(map(float, p)) for p in outline] if m["kind"] != "angle" and carrier != m["link"] else []
    return found, marks


def design_drawing(mech: Mechanism, q: np.ndarray, input_names: list, skel: Skeleton, steps: int, say: Callable[[str], object] | None=None, hint: str = "") -> tuple:
    """A synthesized file's targets (<screwkin:targets>) as the drawing's marks, the linkage at each
    precision position ghosted, and a path's coupler curve: (marks, (name, xy, stopped_at) or None).
    ``say``: where the lines that tell what was drawn go (None: nowhere, for --json)."""
    say = say or (lambda _line: None)
    found, marks = design_marks(mech, q, skel, input_names, steps=steps)
    ghosts = sum(m["ghost"] is not None for m in marks)
    kinds = sorted({m["kind"] for m in marks})
    numbered = sum(m["numbered"] for m in marks)
    which = f"; {numbered} of them numbered, evenly chosen" if numbered < len(marks) else ""
    say(f"drawn with the {len(marks)} target {'/'.join(kinds)}s the file states (<screwkin:targets>{hint}{which}), "
        f"the linkage ghosted at {ghosts} precision position(s)")
    for m in marks:
        if m["reached"] is None:
            say(f"target {m['number']} ({m['label']}): the linkage does not assemble at {m['input']} = "
                f"{m['value']:.6g}: nothing reached drawn")
    curve = None
    if found.curve is not None:
        e1, e2, _ = (np.asarray(v, float) for v in skel.basis)
        name = f"curve of {next(m['link'] for m in marks if m['kind'] == 'point')}"
        stops = [x for x, _ in found.stops if x is not None]
        curve = (name, np.stack([found.curve @ e1, found.curve @ e2], axis=1), stops or None)
        for m, i in zip(marks, found.on_curve):  # where the curve passes each target, for --json
            m["curve_index"] = i
            m["curve_input"] = None if i is None else float(found.curve_inputs[i])
        off = [m["number"] for m, i in zip(marks, found.on_curve) if m["kind"] == "point" and i is None]
        for x, why in found.stops:
            if x is not None:
                say(f"{name}: the input stops at {x:.6g} ({why}): the curve runs between its limit positions")
        if off:
            say(f"{name}: target(s) {', '.join(map(str, off))} are not met along the traced motion")
    return marks, curve


def target_marks(design, basis: tuple, skeletons: dict | None = None) -> list:
    """The drawing's data of an analysis.design.targets.DesignTargets in the plane (e1, e2, n) of
    the skeleton: one dict per target with number, kind, label, target (x, y), direction (a unit
    vector or None), reached (x, y) and reached_direction (None where the file does not
    assemble), and ``ghost`` (the Skeleton at that position, from ``skeletons``, or None)."""
    e1, e2 = (np.asarray(v, float) for v in basis[:2])

    def plane(v: np.ndarray) -> list:
        v = np.asarray(v, float)
        return [float(v @ e1), float(v @ e2)]

    def heading(yaw: float):
        return None if yaw is None else plane((np.cos(yaw), np.sin(yaw), 0.0))

    out = []
    for k, t in enumerate(design.targets):
        s = t.spec
        out.append({"number": k + 1, "kind": s.kind, "label": s.label, "link": s.link, "input": s.input,
                    "value": s.value, "target": plane(s.xyz), "direction": heading(s.yaw),
                    "reached": None if t.position is None else plane(t.position),
                    "reached_direction": None if t.position is None or s.kind == "point" else heading(t.yaw),
                    "error": t.error, "angle_error": t.angle_error,
                    "ghost": (skeletons or {}).get(k)})
    return out


def draw_targets(ax: Axes, marks: list | None, r: float, size: float, colour_of) -> list:
    """Draw ``marks`` (target_marks) on ``ax``; ``r``: the pin radius (the symbols' unit),
    ``size``: the drawing's length scale [m]; colour_of(link number) the links' colours.
    Returns the points drawn (for the framing)."""
    from matplotlib.patches import FancyArrowPatch

    points = []
    arrow = 0.18 * size
    for m in marks:
        k, p = m["number"], np.asarray(m["target"], float)
        ghost = m["ghost"]
        if ghost is not None:
            for lk in ghost.links:
                if lk.shape == "ground" or len(lk.outline) < 2:
                    continue
                P = np.array(lk.outline + ((lk.outline[0],) if lk.shape == "polygon" else ()), float)
                ax.plot(P[:, 0], P[:, 1], "-", color=colour_of(lk.number), lw=1.0, alpha=0.35, zorder=1.2,
                        gid=f"ghost:{k}:{lk.number}", label="ghost")
                points += [tuple(x) for x in P]
        start = p
        if m["kind"] == "point":
            ax.plot(*p, "x", color=TARGET_COLOUR, ms=9, mew=2.0, zorder=6.5, gid=f"target:{k}", label="target point")
        else:
            ax.plot(*p, "s" if m["kind"] == "pose" else "D", color=TARGET_COLOUR, ms=5, zorder=6.5, gid=f"target:{k}",
                    label=f"target {m['kind']}")
            tip = p + arrow * np.asarray(m["direction"], float)
            bold = m.get("numbered", True)
            ax.add_patch(FancyArrowPatch(tuple(p), tuple(tip), arrowstyle="-|>", mutation_scale=14 if bold else 6,
                                         lw=2.4 if bold else 0.6, color=TARGET_COLOUR, alpha=0.55, zorder=6.4,
                                         gid=f"targetaxis:{k}", label="target axis"))
            points.append(tuple(tip))
            start = tip if m["kind"] == "angle" else p
        if m["reached"] is not None:
            q = np.asarray(m["reached"], float)
            for c in m.get("carrier", ()):  # the guided frame (coupler point) tied to its link's pins
                ax.plot([c[0], q[0]], [c[1], q[1]], ":", color="0.45", lw=0.8, zorder=1.3, gid=f"carrier:{k}",
                        label="carrier")
            ax.plot(*q, "o", color="black", ms=3, zorder=6.6, gid=f"reached:{k}", label="reached")
            if m["reached_direction"] is not None and m.get("numbered", True):
                tip = q + arrow * np.asarray(m["reached_direction"], float)
                ax.add_patch(FancyArrowPatch(tuple(q), tuple(tip), arrowstyle="-|>", mutation_scale=9, lw=0.9,
                                             color="black", zorder=6.7, gid=f"reachedaxis:{k}", label="reached axis"))
        if m.get("numbered", True):
            ax.annotate(str(k), tuple(start), xytext=(-9, 6), textcoords="offset points", fontsize=9,
                        fontweight="bold", color=TARGET_COLOUR, zorder=8, gid=f"targetlabel:{k}")
        points.append(tuple(p))
    return points
