"""Skeleton diagrams and kinematic-chain graphs with matplotlib (the Agg backend: files, never
a window), in textbook notation, from the plain data of :mod:`screwkin.analysis.course.skeleton`.

Every symbol carries a gid that names what it stands for, so a program (a test, a report)
can find it in the returned Figure: ``link:N`` one artist per link (a bar, a polygon, a
slider block, the ground's dash-dot frame line), ``joint:X`` one per joint (a pin's circle,
a prismatic pair's guide line, a higher pair's contact point), ``ground:X`` and ``hatch:X``
the ground symbol under a ground pivot or along a ground guide, ``slider:X`` a sliding
block drawn for a prismatic pair whose links are both bars, ``profile:X:N`` a higher pair's
profile on link N, ``input:X`` the input arrow, ``angle:N`` an absolute-angle annotation,
``linklabel:N`` and ``jointlabel:X`` the numbers and letters; a chain graph has ``node:N``
and ``edge:X``.  The artists' labels say the symbol's kind ("bar", "polygon", "slider",
"pin", "guide", ...).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from ..analysis.course.skeleton import skeleton
from ..model.geometry import wrap_angle
from .draw_targets import design_drawing, draw_targets
from .plots import pyplot
from .outfile import write_figure
if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.course.skeleton import KinematicChain
    from collections.abc import Callable
    from collections.abc import Iterable
    from collections.abc import Sequence
    from screwkin.analysis.course.skeleton import SkeletonLink

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..analysis.course.skeleton import Skeleton, SkeletonJoint

__all__ = ["chain_dict", "draw_chain", "draw_mechanism", "draw_design", "save_figure", "skeleton_dict", "value_label",
           "wrapped_value", "configuration_text", "drawing_title", "number_colours"]

_TYPE_WORD = {"revolute": "R", "continuous": "R", "prismatic": "P", "cylindrical": "C", "universal": "U",
              "spherical": "S", "planar": "E", "helical": "H", "rolling": "rolling", "gear": "gear",
              "contact": "contact", "floating": "free", "fixed": "weld"}


def _plt():
    return pyplot("drawing")


def value_label(name: str, value: float, unit: str) -> str:
    """'crank = 30 deg' or 'slide = 12.5 mm': a value as a person reads it."""
    if unit == "m":
        return f"{name} = {value * 1000:.4g} mm"
    return f"{name} = {np.degrees(value):.5g} deg"


def wrapped_value(value: float, unit: str):
    """A coordinate's value as a drawing names it: a length [m] as it is, an angle in [-pi, pi)."""
    return value if unit == "m" else wrap_angle(value)


def configuration_text(skel: Skeleton) -> str:
    """The inputs a skeleton is drawn at ('crank = 30 deg, ...'), or 'assembled configuration'."""
    if not skel.inputs:
        return "assembled configuration"
    return ", ".join(value_label(k, v, skel.units[k]) for k, v in skel.inputs.items())


def drawing_title(mech: Mechanism, what: str) -> str:
    """A drawing's title: the file's name, then ``what``."""
    return f"{os.path.basename(str(mech.path))}: {what}"


def _short(name: str, n: int=26):
    return name if len(name) <= n else name[: n - 1] + "~"


def number_colours(n: int) -> dict:
    """Link number -> colour (2 .. n + 1; the ground, 1, is drawn grey): the colours drawings and the
    planar view share."""
    cycle = ["#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#bcbd22"]
    return {k: cycle[(k - 2) % len(cycle)] for k in range(2, n + 2)}


def _direction_2d(v: Sequence[float] | np.ndarray) -> np.ndarray:
    v = np.asarray(v, float)
    n = np.linalg.norm(v)
    return v / n if n > 1e-300 else np.array([1.0, 0.0])


def _fit_axes(fig: Figure, ax: Axes, points: np.ndarray, r: float, limits: tuple | None = None) -> None:
    """Equal aspect ratio and a margin of 8 % of the drawing's extent around every symbol (or the
    ``limits`` ((x0, x1), (y0, y1)) given: the frames of an animation share one)."""
    P = np.array(points) if points else np.zeros((1, 2))
    lo, hi = P.min(axis=0) - 3 * r, P.max(axis=0) + 3 * r
    pad = 0.08 * max(hi - lo)
    (x0, x1), (y0, y1) = limits if limits is not None else ((lo[0] - pad, hi[0] + pad), (lo[1] - pad, hi[1] + pad))
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_axis_off()


class _Sheet:
    """A skeleton diagram being drawn: its axes, the symbols' unit ``r`` (a pin's radius), the links' colours,
    and every point drawn so far (the framing takes them all)."""

    def __init__(self, ax: Axes, skel: Skeleton, r: float) -> None:
        self.ax, self.skel, self.r = ax, skel, r
        self.colour = number_colours(len(skel.links))
        self.links = {lk.number: lk for lk in skel.links}
        self.points: list[tuple[float, ...]] = []

    def col(self, n: int) -> str:
        """Link ``n``'s colour (the ground grey)."""
        return "0.25" if n == 1 else self.colour[n]

    def ground_at(self, letter: str, p: np.ndarray, down: np.ndarray | None = None,
                  along: np.ndarray | None = None) -> None:
        """The ground symbol under a point (a pivot) or along a guide (direction ``along``)."""
        from matplotlib.patches import Polygon

        ax, r = self.ax, self.r
        p = np.asarray(p, float)
        down = np.array([0.0, -1.0]) if down is None else down
        side = np.array([-down[1], down[0]]) if along is None else np.asarray(along, float)
        if along is None:
            tri = [p, p + 2.6 * r * down + 1.8 * r * side, p + 2.6 * r * down - 1.8 * r * side]
            ax.add_patch(Polygon(tri, closed=True, facecolor="white", edgecolor="0.1", lw=1.2, zorder=3,
                                 gid=f"ground:{letter}", label="ground"))
            base, width = p + 2.6 * r * down, 2.8 * r
        else:
            base, width = p + 1.6 * r * down, 9 * r
            ax.plot(*zip(base - width * side, base + width * side), color="0.1", lw=1.4, zorder=3,
                    gid=f"ground:{letter}", label="ground")
        hatch = [base - width * side, base + width * side, base + width * side + 1.2 * r * down,
                 base - width * side + 1.2 * r * down]
        ax.add_patch(Polygon(hatch, closed=True, facecolor="none", edgecolor="0.2", hatch="////", lw=0, zorder=2,
                             gid=f"hatch:{letter}", label="hatch"))
        self.points.extend([tuple(base + width * side), tuple(base - width * side), tuple(base + 1.5 * r * down)])


def _draw_links(s: _Sheet) -> None:
    """Every link: the ground's frame line, bars, polygons, blocks; each numbered."""
    from matplotlib.patches import Polygon, Rectangle

    ax, r, col, skel = s.ax, s.r, s.col, s.skel
    for lk in skel.links:
        pts = [tuple(p) for p in lk.outline]
        s.points.extend(pts)
        n = lk.number
        if lk.shape == "ground":
            xs, ys = zip(*pts) if pts else ((), ())
            order = np.argsort(np.array(xs) if len(set(xs)) > 1 else np.array(ys)) if pts else []
            ax.plot([xs[i] for i in order], [ys[i] for i in order], ls="-.", lw=0.8, color="0.55", zorder=1,
                    gid=f"link:{n}", label="ground frame")
        elif lk.shape == "polygon":
            ax.add_patch(Polygon(pts, closed=True, facecolor=col(n), alpha=0.35, edgecolor=col(n), lw=2.5, zorder=2,
                                 gid=f"link:{n}", label="polygon"))
        elif lk.shape in ("bar", "stub"):
            ax.plot(*zip(*pts), color=col(n), lw=3.2, solid_capstyle="round", zorder=2, gid=f"link:{n}",
                    label="bar")
        elif lk.shape == "block":
            d = _block_direction(skel, lk)
            _block(ax, Rectangle, pts[0], d, r, col(n), f"link:{n}")
        else:
            ax.plot(*zip(*pts), "o", color=col(n), ms=4, zorder=2, gid=f"link:{n}", label="point")
        # its number
        if lk.shape != "ground" and pts:
            P = np.array(pts)
            c = P.mean(axis=0)
            if lk.shape in ("bar", "stub"):
                d = _direction_2d(P[-1] - P[0])
                c = c + 2.0 * r * np.array([-d[1], d[0]])
            elif lk.shape == "block":
                d = _block_direction(skel, lk)
                c = c + 2.6 * r * np.array([-d[1], d[0]])
            ax.text(*c, str(n), ha="center", va="center", fontsize=10, fontweight="bold", color=col(n), zorder=7,
                    gid=f"linklabel:{n}", bbox={"boxstyle": "circle,pad=0.15", "fc": "white", "ec": col(n), "lw": 0.8})


def _draw_joint(s: _Sheet, j: SkeletonJoint, p: np.ndarray) -> None:
    """A joint's symbol at ``p``: a prismatic pair's guide (and block), a contact point, or a pin with its kind's
    mark, with the ground symbol under a ground pivot or along a ground guide."""
    from matplotlib.patches import Circle, Rectangle

    ax, r, col = s.ax, s.r, s.col
    kind = j.type
    if kind == "prismatic":
        d = _direction_2d(j.direction if j.direction is not None else (1.0, 0.0))
        guide_link = j.links[0]
        length = 9 * r if guide_link == 1 else 4.5 * r
        a, b = p - length * d, p + length * d
        ax.plot(*zip(a, b), color=col(guide_link), lw=1.3, zorder=1.5, gid=f"joint:{j.letter}", label="guide")
        s.points.extend([tuple(a), tuple(b)])
        if all(s.links[n].shape != "block" for n in j.links):
            _block(ax, Rectangle, p, d, r, col(j.links[1]), f"slider:{j.letter}", alpha=0.5)
        if guide_link == 1:
            down = np.array([d[1], -d[0]])
            if down[1] > 0 or (down[1] == 0 and down[0] > 0):
                down = -down
            s.ground_at(j.letter, p, down, along=d)
    elif kind in ("rolling", "gear", "contact"):
        ax.plot(*p, "o", color="black", ms=4.5, zorder=6, gid=f"joint:{j.letter}", label="contact")
    else:
        ax.add_patch(Circle(tuple(p), r, facecolor="white", edgecolor="black", lw=1.3, zorder=5,
                            gid=f"joint:{j.letter}", label="pin"))
        if kind == "spherical":
            ax.add_patch(Circle(tuple(p), 0.45 * r, facecolor="black", zorder=5.5, label="ball"))
        elif kind == "universal":
            ax.plot([p[0] - r, p[0] + r], [p[1], p[1]], color="black", lw=0.8, zorder=5.5, label="cross")
            ax.plot([p[0], p[0]], [p[1] - r, p[1] + r], color="black", lw=0.8, zorder=5.5, label="cross")
        elif kind not in ("revolute", "continuous"):
            ax.text(*p, j.symbol, ha="center", va="center", fontsize=6, zorder=6, label="symbol")
        if j.direction is not None and kind != "prismatic":  # a tilted axis, projected (spatial)
            d = _direction_2d(j.direction) * 2.6 * r * np.sin(j.tilt)
            ax.plot(*zip(p - d, p + d), color="0.35", lw=1.0, ls="--", zorder=4.5, label="axis")
        if j.ground and kind in ("revolute", "continuous", "spherical", "universal", "cylindrical", "helical"):
            s.ground_at(j.letter, p)


def _draw_joints(s: _Sheet) -> None:
    """Every joint's symbol and letter (in the free corner farthest from the labels and pins placed so far), the
    ground's number 1 and the input arrows."""
    from matplotlib.patches import FancyArrowPatch

    ax, r, skel = s.ax, s.r, s.skel
    ground_labelled = False
    taken = [np.asarray(t.get_position(), float) for t in ax.texts]
    for j in skel.joints:
        p = np.asarray(j.point, float)
        s.points.append(tuple(p))
        _draw_joint(s, j, p)
        cands = [np.array(v) * 2.0 * r for v in ((1, 1), (-1, 1), (1, -1), (-1, -1), (0, 1.3), (1.3, 0), (-1.3, 0))]
        others = taken + [np.asarray(o.point, float) for o in skel.joints if o is not j]
        best = max(cands, key=lambda c: min([np.linalg.norm(p + c - t) for t in others] + [np.inf]))
        taken.append(p + best)
        ax.text(*(p + best), j.letter, fontsize=9, style="italic", ha="center", va="center", zorder=8,
                gid=f"jointlabel:{j.letter}",
                bbox={"boxstyle": "round,pad=0.05", "fc": "white", "ec": "none", "alpha": 0.8})
        if j.ground and not ground_labelled and j.type != "prismatic":
            ax.text(*(p + np.array([2.6 * r, -2.4 * r])), "1", ha="center", va="center", fontsize=10,
                    fontweight="bold", color="0.25", zorder=7, gid="linklabel:1",
                    bbox={"boxstyle": "circle,pad=0.15", "fc": "white", "ec": "0.25", "lw": 0.8})
            ground_labelled = True
        if j.input:
            _input_arrow(ax, FancyArrowPatch, j, p, r)
    if not ground_labelled and s.links[1].outline:
        p = np.asarray(s.links[1].outline[0], float)
        ax.text(*(p + np.array([2.6 * r, -3.6 * r])), "1", ha="center", va="center", fontsize=10,
                fontweight="bold", color="0.25", zorder=7, gid="linklabel:1",
                bbox={"boxstyle": "circle,pad=0.15", "fc": "white", "ec": "0.25", "lw": 0.8})


def _draw_profiles(s: _Sheet) -> None:
    """The higher pairs' profiles: circles, lines, points."""
    from matplotlib.patches import Circle

    ax, r, col, skel = s.ax, s.r, s.col, s.skel
    for pr in skel.profiles:
        c = np.asarray(pr.centre, float)
        gid = f"profile:{pr.joint}:{pr.link}"
        pair = skel.joint(pr.joint).type
        if pr.shape == "circle":
            ls = "-." if pair == "gear" else "-"
            ax.add_patch(Circle(tuple(c), pr.radius, facecolor=col(pr.link) if pair != "gear" else "none",
                                alpha=0.18 if pair != "gear" else 1.0, edgecolor=col(pr.link), lw=1.6, ls=ls,
                                zorder=1.8, gid=gid, label="profile"))
            if pair != "gear":
                ax.add_patch(Circle(tuple(c), pr.radius, facecolor="none", edgecolor=col(pr.link), lw=1.6, zorder=1.9,
                                    label="profile edge"))
            s.points.extend([tuple(c + pr.radius), tuple(c - pr.radius)])
        elif pr.shape == "line":
            d = _direction_2d(pr.direction)
            contact = np.asarray(skel.joint(pr.joint).point, float)
            t = (contact - c) @ d
            lo, hi = min(0.0, t) - 6 * r, max(0.0, t) + 6 * r
            a, b = c + lo * d, c + hi * d
            ax.plot(*zip(a, b), color=col(pr.link), lw=2.0, ls="-." if pair == "gear" else "-", zorder=1.8, gid=gid,
                    label="profile")
            s.points.extend([tuple(a), tuple(b)])
        else:
            ax.add_patch(Circle(tuple(c), 0.5 * r, facecolor=col(pr.link), edgecolor="black", lw=0.8, zorder=5.2,
                                gid=gid, label="profile"))


def _draw_angles(s: _Sheet) -> None:
    """The absolute link angles, each an arc from its reference line with its value."""
    from matplotlib.patches import Arc

    ax, col = s.ax, s.col
    for n, th in sorted(s.skel.angles.items()):
        if n == 1 and abs(th) < 1e-12:
            continue
        o = np.asarray(s.skel.angle_origins[n], float)
        rad = 4.5 * s.r
        ax.plot(*zip(o, o + np.array([1.5 * rad, 0.0])), color=col(n), lw=0.7, ls=":", zorder=4,
                label="angle reference")
        t1, t2 = (0.0, np.degrees(th)) if th >= 0 else (np.degrees(th), 0.0)
        ax.add_patch(Arc(tuple(o), 2 * rad, 2 * rad, theta1=t1, theta2=t2, color=col(n), lw=1.0, zorder=4,
                         gid=f"angle:{n}", label="angle"))
        m = np.radians((t1 + t2) / 2)
        u = np.array([np.cos(m), np.sin(m)])
        ax.text(*(o + 1.15 * rad * u), f"θ{n} = {np.degrees(th):.1f}°", fontsize=7.5, color=col(n),
                ha="left" if u[0] >= 0 else "right", va="bottom" if u[1] >= 0 else "top", zorder=7,
                gid=f"anglelabel:{n}")


def _draw_traces(s: _Sheet, traces: dict[str, np.ndarray]) -> None:
    """Named points' paths (draw --trace), each from its first point."""
    for k, (name, xy) in enumerate(traces.items()):
        xy = np.asarray(xy, float)
        s.ax.plot(xy[:, 0], xy[:, 1], color=f"C{k}", lw=1.2, ls="--", zorder=2.5, gid=f"trace:{name}",
                  label=f"path of {name}")
        s.ax.plot(*xy[0], "o", color=f"C{k}", markersize=4, zorder=6, gid=f"tracepoint:{name}")
        s.ax.annotate(name, xy[0], xytext=(4, 4), textcoords="offset points", fontsize=8, color=f"C{k}")
        s.points += [tuple(p) for p in xy]


def draw_mechanism(skel: Skeleton, title: str | None = None, angles: bool = False, subtitle: str | None = None,
                   traces: dict | None = None, size: float | None = None,
                   limits: tuple[tuple[float, float], tuple[float, float]] | None = None,
                   marks: list | None = None) -> Figure:
    """The skeleton diagram of a :class:`~screwkin.analysis.course.skeleton.Skeleton` as a matplotlib
    Figure: ground hatched, pins as small circles, sliders as blocks on their guide lines,
    higher pairs as their profiles, binary links as bars, ternary and larger links as filled
    polygons, links numbered (ground 1) and joints lettered with a legend to the file's
    names, the input joints marked with a curved arrow (a straight one for a sliding input),
    and with ``angles`` the absolute link angles (planar mechanisms).  ``size`` [m] (default the
    skeleton's) sets the symbols' scale and ``limits`` ((x0, x1), (y0, y1)) [m] the framing: the
    frames of an animation share both.  ``marks``: a synthesized design's targets
    (present.draw_targets.target_marks), drawn with the linkage ghosted at each."""
    plt = _plt()
    fig = plt.figure(figsize=(10, 6.4))
    ax = fig.add_axes([0.03, 0.06, 0.66, 0.82])
    r = 0.022 * (size or skel.size)  # pin radius: the unit of every symbol
    s = _Sheet(ax, skel, r)
    _draw_links(s)
    _draw_joints(s)
    _draw_profiles(s)
    if angles and skel.angles:
        _draw_angles(s)
    _draw_traces(s, traces or {})
    if marks:
        s.points += draw_targets(ax, marks, r, size or skel.size, s.col)
    _fit_axes(fig, ax, s.points, r, limits)
    fig.suptitle(title or os.path.basename(skel.path), fontsize=11, x=0.36, y=0.97)
    if subtitle:
        fig.text(0.36, 0.905, subtitle, ha="center", va="center", fontsize=8.5, color="0.3")
    _legend(fig, skel.links, skel.joints, marks)
    return fig


def _block_direction(skel: Skeleton, lk: SkeletonLink) -> np.ndarray:
    for j in skel.joints:
        if lk.number in j.links and j.type in ("prismatic", "cylindrical") and j.direction is not None:
            return _direction_2d(j.direction)
    return np.array([1.0, 0.0])


def _block(ax: Axes, Rectangle, p: np.ndarray, d: np.ndarray, r: float, colour: str, gid: str, alpha: float=0.85) -> None:
    w, h = 4.2 * r, 2.6 * r
    p = np.asarray(p, float)
    n = np.array([-d[1], d[0]])
    corner = p - 0.5 * w * d - 0.5 * h * n
    ax.add_patch(Rectangle(tuple(corner), w, h, angle=float(np.degrees(np.arctan2(d[1], d[0]))), facecolor=colour,
                           alpha=alpha, edgecolor="black", lw=1.2, zorder=3.5, gid=gid, label="slider"))


def _input_arrow(ax: Axes, FancyArrowPatch, j: SkeletonJoint, p: np.ndarray, r: float) -> None:
    if j.type == "prismatic":
        d = _direction_2d(j.direction if j.direction is not None else (1.0, 0.0))
        n = np.array([-d[1], d[0]])
        a = p + 3.2 * r * n - 2.5 * r * d
        b = p + 3.2 * r * n + 2.5 * r * d
        ax.add_patch(FancyArrowPatch(tuple(a), tuple(b), arrowstyle="-|>", mutation_scale=12, color="#c00000",
                                     lw=1.6, zorder=6, gid=f"input:{j.letter}", label="input"))
        return
    rad = 2.6 * r
    a0, a1 = np.radians(200), np.radians(340)
    a = p + rad * np.array([np.cos(a0), np.sin(a0)])
    b = p + rad * np.array([np.cos(a1), np.sin(a1)])
    if j.ground:  # above the ground symbol
        a = p + rad * np.array([np.cos(np.radians(160)), np.sin(np.radians(160))])
        b = p + rad * np.array([np.cos(np.radians(20)), np.sin(np.radians(20))])
        ax.add_patch(FancyArrowPatch(tuple(a), tuple(b), connectionstyle="arc3,rad=-0.55", arrowstyle="-|>",
                                     mutation_scale=12, color="#c00000", lw=1.6, zorder=6, gid=f"input:{j.letter}",
                                     label="input"))
        return
    ax.add_patch(FancyArrowPatch(tuple(a), tuple(b), connectionstyle="arc3,rad=0.55", arrowstyle="-|>",
                                 mutation_scale=12, color="#c00000", lw=1.6, zorder=6, gid=f"input:{j.letter}",
                                 label="input"))


def _legend(fig: Figure, links: Sequence[SkeletonLink], joints: Sequence[SkeletonJoint], marks: list | None = None) -> None:
    lines = ["links"]
    lines += [f" {lk.number:>2}  {_short(lk.name)}" + ("  (ground)" if lk.ground else "") for lk in links]
    lines.append("")
    lines.append("joints")
    for j in joints:
        tags = [_TYPE_WORD.get(j.type, j.type)]
        if j.input:
            tags.append("input")
        if j.cut:
            tags.append("loop")
        lines.append(f" {j.letter:>2}  {_short(j.name)}  {', '.join(tags)}  {j.links[0]}-{j.links[1]}")
    if marks:
        listed = [m for m in marks if m.get("numbered", True)]
        lines += ["", "targets (purple; black: reached)"]
        if len(listed) < len(marks):
            lines.append(f" {len(listed)} of the {len(marks)} numbered")
        width = len(str(len(marks)))
        lines += [f" {m['number']:>{max(width, 2)}}  {_short(m['label'], 42 - width)}" for m in listed]
    size = 8 if len(lines) <= 40 else max(3.0, 8 * 40 / len(lines))
    fig.text(0.71, 0.88, "\n".join(lines), ha="left", va="top", family="monospace", fontsize=size, gid="legend")


def draw_chain(chain: KinematicChain, title: str | None = None):
    """The kinematic chain (:class:`~screwkin.analysis.course.skeleton.KinematicChain`) as a Figure: a
    node per link (a circle for a link with at most two joints, a triangle for a ternary link,
    a square for a quaternary one ...; the ground hatched), an edge per joint labelled with its
    letter and type (R, P, S, U, rolling, contact, ...), several joints between two links as
    separate arcs; the layout from networkx (Kamada-Kawai) when it is installed, else a
    circle."""
    plt = _plt()
    from matplotlib.patches import Circle, FancyArrowPatch, RegularPolygon

    pos = _layout(chain)
    fig = plt.figure(figsize=(10, 6.4))
    ax = fig.add_axes([0.03, 0.06, 0.66, 0.82])
    R = 0.09
    seen = {}
    for e in chain.edges:
        a, b = e.links
        key = tuple(sorted((a, b)))
        k = seen.get(key, 0)
        seen[key] = k + 1
        mult = sum(1 for x in chain.edges if tuple(sorted(x.links)) == key)
        rad = 0.0 if mult == 1 else 0.35 * (k - (mult - 1) / 2)
        p0, p2 = np.asarray(pos[a]), np.asarray(pos[b])
        ax.add_patch(FancyArrowPatch(tuple(p0), tuple(p2), connectionstyle=f"arc3,rad={rad}", arrowstyle="-",
                                     color="0.2", lw=1.8,
                                     zorder=1, gid=f"edge:{e.letter}", label=e.symbol))
        dx, dy = p2 - p0
        mid = (p0 + p2) / 2 + 0.5 * rad * np.array([dy, -dx])
        ax.text(*mid, f"{e.letter}: {_TYPE_WORD.get(e.type, e.type)}", fontsize=9, ha="center", va="center", zorder=3,
                bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.9}, gid=f"edgelabel:{e.letter}")
    for nd in chain.nodes:
        c = tuple(pos[nd.number])
        face = "white" if nd.ground else "#cfe2f3"
        if nd.degree <= 2:
            patch = Circle(c, R, facecolor=face, edgecolor="black", lw=1.4, zorder=2, gid=f"node:{nd.number}",
                           label="binary" if nd.degree == 2 else "node")
        else:
            patch = RegularPolygon(c, numVertices=nd.degree, radius=1.35 * R, facecolor=face, edgecolor="black", lw=1.4,
                                   zorder=2, gid=f"node:{nd.number}", label=f"{nd.degree}-joint link")
        if nd.ground:
            patch.set_hatch("////")
        ax.add_patch(patch)
        ax.text(*c, str(nd.number), ha="center", va="center", fontsize=11, fontweight="bold", zorder=4,
                bbox={"boxstyle": "circle,pad=0.1", "fc": "white", "ec": "none"} if nd.ground else None,
                gid=f"nodelabel:{nd.number}")
    P = np.array(list(pos.values()))
    lo, hi = P.min(axis=0) - 2.5 * R, P.max(axis=0) + 2.5 * R
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal", adjustable="box")
    ax.set_axis_off()
    n, j = len(chain.nodes), len(chain.edges)
    fig.suptitle(title or f"kinematic chain of {os.path.basename(chain.path)}", fontsize=11, x=0.36, y=0.97)
    fig.text(0.36, 0.905, f"N = {n} links, J = {j} joints, L = J - N + 1 = {chain.loops} loops; "
             f"{chain.count_name} {chain.count} ({chain.motion_space})", ha="center", fontsize=8.5, color="0.3")
    lines = ["links (nodes)"] + [f" {nd.number:>2}  {_short(nd.name)}  {nd.degree} joints" + (" (ground)" if nd.ground
                                                                                              else "")
                                 for nd in chain.nodes]
    lines += ["", "joints (edges)"] + [f" {e.letter:>2}  {_short(e.name)}  {_TYPE_WORD.get(e.type, e.type)}, "
                                       f"f = {e.dof}{', loop' if e.cut else ''}  {e.links[0]}-{e.links[1]}"
                                       for e in chain.edges]
    size = 8 if len(lines) <= 40 else max(3.0, 8 * 40 / len(lines))
    fig.text(0.71, 0.88, "\n".join(lines), ha="left", va="top", family="monospace", fontsize=size, gid="legend")
    return fig


def _layout(chain: KinematicChain) -> dict:
    """Node positions in a unit box: networkx's Kamada-Kawai layout, else a circle; the ground
    at the bottom."""
    numbers = [nd.number for nd in chain.nodes]
    pos = None
    try:
        import networkx as nx

        g = nx.MultiGraph()
        g.add_nodes_from(numbers)
        g.add_edges_from(e.links for e in chain.edges)
        if len(numbers) > 2:
            simple = nx.Graph(g)
            planar, _ = nx.check_planarity(simple)
            start = nx.planar_layout(simple) if planar else None
            pos = nx.kamada_kawai_layout(simple, pos=start)
            if planar and _crossings(pos, simple.edges()):
                pos = start
        else:
            pos = nx.circular_layout(g)
        pos = {k: np.asarray(v, float) for k, v in pos.items()}
    except (ImportError, ValueError, np.linalg.LinAlgError):  # networkx or scipy missing, a degenerate layout
        pos = None
    if pos is None:
        t = 2 * np.pi * np.arange(len(numbers)) / max(len(numbers), 1) - np.pi / 2
        pos = {k: np.array([np.cos(a), np.sin(a)]) for k, a in zip(numbers, t)}
    if len(numbers) == 1:
        return {numbers[0]: np.zeros(2)}
    P = np.array([pos[k] for k in numbers])
    c = P.mean(axis=0)
    g = pos[numbers[0]] - c  # turn the drawing so that the ground is at the bottom
    if np.linalg.norm(g) > 1e-9:
        a = -np.pi / 2 - np.arctan2(g[1], g[0])
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        P = (P - c) @ rot.T
    span = max(np.ptp(P, axis=0).max(), 1e-9)
    P = (P - P.mean(axis=0)) / span
    return {k: P[i] for i, k in enumerate(numbers)}


def _crossings(pos: dict, edges: Iterable[tuple]) -> bool:
    """Whether two edges without a common node cross in the layout."""
    edges = list(edges)

    def ccw(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
        return (c[1] - a[1]) * (b[0] - a[0]) - (b[1] - a[1]) * (c[0] - a[0])

    for i, (a, b) in enumerate(edges):
        for c, d in edges[i + 1:]:
            if {a, b} & {c, d}:
                continue
            A, B, C, D = (np.asarray(pos[k]) for k in (a, b, c, d))
            if ccw(A, B, C) * ccw(A, B, D) < 0 and ccw(C, D, A) * ccw(C, D, B) < 0:
                return True
    return False


def save_figure(fig: Figure, path: str, close: bool = True) -> None:
    """Write a Figure to ``path`` (PNG or SVG by its suffix; present/outfile.write_figure) and close it
    (unless ``close`` is False: the same figure written to another file next)."""
    plt = _plt()
    try:
        write_figure(fig, path, dpi=110)
    except BaseException:  # any failure, Ctrl-C too: the figure is closed, the error goes on
        plt.close(fig)
        raise
    if close:
        plt.close(fig)


def draw_design(mech: Mechanism, paths: list, steps: int = 360, say: Callable[[str], object] | None=None) -> list:
    """``mech`` (a synthesized file) drawn at its own configuration with its targets into each of
    ``paths`` (.png or .svg), as ``screwkin draw FILE --png F`` draws it: the marks (as --json)."""
    q = mech.assemble().q
    input_names = list(mech.actuated)
    skel = skeleton(mech, q, input_names)
    marks, curve = (None, None) if not mech.spec.targets else design_drawing(mech, q, input_names, skel, steps, say)
    traces = {} if curve is None else {curve[0]: curve[1]}
    for path in paths:
        fig = draw_mechanism(skel, title=drawing_title(mech, configuration_text(skel)), traces=traces, marks=marks)
        save_figure(fig, path)
    return [{k: v for k, v in m.items() if k != "ghost"} for m in marks or ()]


def skeleton_dict(skel: Skeleton) -> dict:
    """The numbering and symbols of a drawing, for --json."""
    return {
        "planar": skel.planar,
        "motion_space": skel.motion_space,
        "links": [{"number": lk.number, "name": lk.name, "shape": lk.shape, "joints": list(lk.joints)}
                  for lk in skel.links],
        "joints": [{"letter": j.letter, "name": j.name, "type": j.type, "links": list(j.links), "cut": j.cut,
                    "input": j.input, "point": list(j.point)} for j in skel.joints],
        "inputs": dict(skel.inputs),
        "link_angles": None if skel.angles is None else {str(k): v for k, v in skel.angles.items()},
    }


def chain_dict(chain: KinematicChain) -> dict:
    return {
        "nodes": [{"number": nd.number, "name": nd.name, "degree": nd.degree, "ground": nd.ground}
                  for nd in chain.nodes],
        "edges": [{"letter": e.letter, "name": e.name, "type": e.type, "dof": e.dof, "links": list(e.links),
                   "cut": e.cut} for e in chain.edges],
        "loops": chain.loops,
        "count": chain.count,
        "count_name": chain.count_name,
    }
