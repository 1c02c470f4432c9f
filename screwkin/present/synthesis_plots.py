"""Pictures of synthesis results with matplotlib (optional: ``pip install -e '.[plot]'``):
Burmester's centre-point and circle-point curves with the poses, poles, candidates and the
four-bar chosen, ghosted at the other positions with the guided frame it reaches there."""

from __future__ import annotations

import math

import numpy as np

from ..analysis.design.synthesis.designs import MotionResult
from ..analysis.design.synthesis.fourbar import crank_angle, positions
from .plots import pyplot
from .outfile import write_figure

__all__ = ["burmester_png"]


def burmester_png(result: MotionResult, path: str) -> None:
    """The curves of a four- or five-position MotionResult (three positions: the poses and
    the four-bar only) into a PNG."""
    plt = pyplot("--png")
    fig, ax = plt.subplots(figsize=(8, 7))
    styles = (("tab:blue", "tab:orange"), ("tab:cyan", "tab:red"))
    for k, (C, W) in enumerate(result.curves):
        cc, cw = styles[k % 2]
        which = "" if len(result.curves) == 1 else (" (positions 1-4)" if k == 0 else " (positions 1, 2, 3, 5)")
        ax.plot(C[:, 0], C[:, 1], ".", ms=1.5, color=cc)
        ax.plot(W[:, 0], W[:, 1], ".", ms=1.5, color=cw)
        ax.plot([], [], "-", color=cc, label=f"centre-point curve{which}")  # legend entries of readable size
        ax.plot([], [], "-", color=cw, label=f"circle-point curve{which}")
    P = np.array([p[:2] for p in result.poses])
    L = max(float(np.ptp(P[:, 0])), float(np.ptp(P[:, 1])), 1e-9)
    for k, (x, y, th) in enumerate(result.poses):
        ax.annotate("", xy=(x + 0.15 * L * math.cos(th), y + 0.15 * L * math.sin(th)), xytext=(x, y),
                    arrowprops={"arrowstyle": "->", "color": "k"})
        ax.text(x, y, f" {k + 1}", fontsize=9, clip_on=True)
    if result.poles:
        Q = np.array([p for _, _, p in result.poles])
        ax.plot(Q[:, 0], Q[:, 1], "k+", ms=7, label="poles")
    five = len(result.poses) == 5
    for k, d in enumerate(result.candidates):
        ax.plot(*d.fixed, "*" if five else "o", ms=9 if five else 3, color="tab:purple" if five else "tab:blue",
                label=("Burmester points" if five else "candidates (centre points)") if k == 0 else None)
        ax.text(*d.fixed, f" {k}", fontsize=8 if five else 7, color="tab:purple" if five else "tab:blue",
                clip_on=True)
    fb = result.design.fourbar
    chain = np.array([fb.A0, fb.A, fb.B, fb.B0])
    ax.plot(chain[:, 0], chain[:, 1], "-o", color="tab:green", lw=2, label=f"four-bar chosen {result.pick}")
    for k, t in enumerate(result.design.targets[1:], 2):  # the four-bar (closed form) at the other positions
        best = None
        for sigma in (1.0, -1.0):
            p = positions(fb, crank_angle(fb) + t.input, sigma)
            if p["h2"] < 0:
                continue
            miss = math.hypot(float(p["x"]) - t.value[0], float(p["y"]) - t.value[1])
            if best is None or miss < best[0]:
                best = (miss, p)
        if best is None:
            continue
        p = best[1]
        ghost = np.array([fb.A0, p["A"], p["B"], fb.B0])
        ax.plot(ghost[:, 0], ghost[:, 1], "-", color="tab:green", lw=1, alpha=0.35, gid=f"ghost:{k}",
                label="the four-bar at the other positions" if k == 2 else None)
        x, y, th = float(p["x"]), float(p["y"]), float(p["angle"])
        ax.plot([p["A"][0], x, p["B"][0]], [p["A"][1], y, p["B"][1]], ":", color="0.45", lw=0.8)
        ax.annotate("", xy=(x + 0.1 * L * math.cos(th), y + 0.1 * L * math.sin(th)), xytext=(x, y),
                    arrowprops={"arrowstyle": "->", "color": "tab:green", "lw": 0.8}, gid=f"reached:{k}")
    ax.plot([fb.A0[0], fb.B0[0]], [fb.A0[1], fb.B0[1]], "^", color="tab:green", ms=10)
    fixed = np.array([d.fixed for d in result.candidates]).reshape(-1, 2)
    xs = np.concatenate([P[:, 0], chain[:, 0], fixed[:, 0]])
    ys = np.concatenate([P[:, 1], chain[:, 1], fixed[:, 1]])
    half = max(np.ptp(xs), np.ptp(ys)) / 2 + 1.5 * L  # a square window: equal scales on both axes
    cx, cy = (xs.min() + xs.max()) / 2, (ys.min() + ys.max()) / 2
    ax.set_xlim(cx - half, cx + half)
    ax.set_ylim(cy - half, cy + half)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(result.method)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    try:
        write_figure(fig, path, dpi=100)
    finally:
        plt.close(fig)
