"""The regions a box of two inputs is cut into by its singular loci, and their assembly modes (issue 44).

The traced curves (analysis.singularities.loci) are drawn onto the map's own grid: every grid node within
three quarters of a cell (in each direction) of a curve is blocked, the curves resampled at a quarter of
a cell, so that of the two ends of any grid edge or cell diagonal a curve crosses at least one is blocked
(the crossing is within 5/8 of a cell of one end in each direction); the unblocked nodes joined by grid
edges and diagonals are the regions.  Two curves closer than about a cell and a
half leave no node between them: a region that narrow is not seen (``Regions.resolution`` says so).
Each region's sample is its node farthest from the blocked ones, where the project's all-modes solve
counts its real assembly modes (analysis.position.position.PositionSolver.solve, with how it knows the
count: a certified one or a search).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import AssemblyError
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.analysis.singularities.loci import Loci
    from collections.abc import Callable

__all__ = ["Region", "Regions", "regions"]


@dataclass(frozen=True)
class Region:
    sample: tuple  # (x, y) [SI]
    modes: int | None  # real assembly modes at the sample (None: not counted)
    certain: bool  # the count is certified complete
    how: str  # how the count is known
    nodes: int  # grid nodes of the region


@dataclass(frozen=True)
class Regions:
    regions: tuple
    labels: np.ndarray  # (len(ys), len(xs)) int: region k + 1 at each node, 0 on a curve
    resolution: str
    notes: tuple = ()


def _blocked(curves: list, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    nx, ny = len(xs), len(ys)
    mask = np.zeros((ny, nx), bool)
    dx = (xs[-1] - xs[0]) / (nx - 1) if nx > 1 else 1.0
    dy = (ys[-1] - ys[0]) / (ny - 1) if ny > 1 else 1.0
    for P in curves:
        F = np.column_stack([(P[:, 0] - xs[0]) / dx, (P[:, 1] - ys[0]) / dy])  # fractional node indices
        if len(F) > 1:
            seg = np.diff(F, axis=0)
            pieces = np.maximum(1, np.ceil(np.abs(seg).max(axis=1) / 0.25)).astype(int)
            F = np.concatenate([F[k] + np.outer(np.arange(pieces[k]) / pieces[k], seg[k]) for k in range(len(seg))]
                               + [F[-1:]])
        lo_i, hi_i = np.ceil(F[:, 0] - 0.75).astype(int), np.floor(F[:, 0] + 0.75).astype(int)
        lo_j, hi_j = np.ceil(F[:, 1] - 0.75).astype(int), np.floor(F[:, 1] + 0.75).astype(int)
        for a in range(2):
            for b in range(2):
                i, j = lo_i + a, lo_j + b
                ok = (i <= hi_i) & (j <= hi_j) & (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
                mask[j[ok], i[ok]] = True
    return mask


def regions(solver: PositionSolver | None, loci: Loci, x_name: str, xs: np.ndarray, y_name: str, ys: np.ndarray, fixed: dict, count: bool = True, max_counted: int = 24,
            counter: Callable | None = None) -> Regions:
    """The regions of the grid xs x ys cut by ``loci`` (analysis.singularities.loci.Loci), each with its sample
    and (count) its number of real assembly modes there: ``counter(sample) -> (modes, certain, how)`` where
    given (a workspace section's inverse kinematics), else ``solver``'s all-modes solve."""
    from scipy import ndimage

    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    curves = [lc.points for lc in loci.loci if len(lc.points)]
    blocked = _blocked(curves, xs, ys)
    labels, n = ndimage.label(~blocked, structure=np.ones((3, 3), int))  # diagonal neighbours too
    cell = f"{(xs[-1] - xs[0]) / max(len(xs) - 1, 1):.3g} x {(ys[-1] - ys[0]) / max(len(ys) - 1, 1):.3g}"
    resolution = (f"regions on the {len(xs)} x {len(ys)} grid (cell {cell}): a region narrower than about "
                  "a cell and a half between two curves is not seen")
    if n == 0:
        return Regions((), labels, resolution)
    depth = ndimage.distance_transform_edt(~blocked)
    where = ndimage.maximum_position(depth, labels, index=np.arange(1, n + 1))
    sizes = ndimage.sum(np.ones_like(labels), labels, index=np.arange(1, n + 1))
    order = np.argsort(-np.asarray(sizes), kind="stable")
    out, notes = [None] * n, []
    for rank, k in enumerate(order):
        j, i = where[k]
        sample = (float(xs[i]), float(ys[j]))
        modes, certain, how = None, False, "not counted"
        if count and rank < max_counted and counter is not None:
            modes, certain, how = counter(sample)
        elif count and rank < max_counted:
            try:
                res = solver.solve({x_name: sample[0], y_name: sample[1], **fixed})
                modes = len(res.solutions)
                mc = res.modes
                certain = bool(mc is not None and mc.complete)
                how = (mc.method if mc is not None else "search") + ("" if certain else ": maybe not all")
            except AssemblyError as exc:  # a reason: every solution complex, certified (a closed form's count)
                modes, certain = 0, exc.reason is not None
                how = "no assembly mode: every solution is complex (certified)" if certain else "no assembly mode found"
        out[k] = Region(sample, modes, certain, how, int(sizes[k]))
    if count and n > max_counted:
        notes.append(f"{n - max_counted} of the {n} regions (the smallest) were not counted")
    return Regions(tuple(out), labels, resolution, tuple(notes))
