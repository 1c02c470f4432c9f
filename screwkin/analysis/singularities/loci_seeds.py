"""Seeds and checks of the singular loci (analysis.singularities.loci): the modes at the box's centre
continued over a coarse grid (analysis.motion.continuation.Neighbour, the map's step), the grid
configurations Newton starts from, the folds the traced curves must explain, and the crossings of the
traces (nodes), refined by Newton on the two arclengths."""

from __future__ import annotations

import numpy as np

from ..motion.continuation import Neighbour
from ..position.certified import closed_forms
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.position.position import PositionSolver

__all__ = ["seed_configurations", "crossings", "refine_node", "sheets", "unexplained_folds", "edge_seeds"]

TINY = 1e-300  # division guard: two segments parallel
#: Points per edge of the box where edge_seeds counts the modes, and bisections of a change between two
#: (Newton on the locus, with the edge held, finishes from there).
EDGE_SAMPLES, EDGE_BISECTIONS = 41, 12


def _complete_count(solver: PositionSolver, values: dict) -> tuple | None:
    """(number of real modes, their configurations) where every mode comes in closed form (dyads, or a
    planar platform on three distances; 0 where that proves none assembles), else None: no homotopy is run
    here (it would be a search per point)."""
    got, _ = closed_forms(solver, values)
    if got is None or not got.count.complete:
        return None
    return len(got.modes), [m[0] for m in got.modes]


def edge_seeds(solver: PositionSolver, sys, x_name: str, y_name: str, box: tuple, fixed: dict) -> list:
    """Points of the actuator locus on the box's edges, where the modes come in closed form: along each
    edge at EDGE_SAMPLES points, every change of the count (two modes meet between) bisected
    EDGE_BISECTIONS times, the mode of the larger count with the smallest measure taken onto the locus by
    Newton with the edge held.  A component that crosses an edge between two
    samples where the count is the same on both sides (two crossings, or a tangency) is not seen here."""
    out = []
    (x0, x1), (y0, y1) = box
    for axis, bound, (a, b) in ((0, x0, (y0, y1)), (0, x1, (y0, y1)), (1, y0, (x0, x1)), (1, y1, (x0, x1))):
        def at(u: float, axis=axis, bound=bound) -> tuple | None:
            x, y = (bound, u) if axis == 0 else (u, bound)
            return _complete_count(solver, {x_name: x, y_name: y, **fixed})
        us = np.linspace(a, b, EDGE_SAMPLES)
        counts = [at(us[0])]
        if counts[0] is None:
            return out  # no closed form here: no walk
        counts += [at(u) for u in us[1:]]
        for k in range(EDGE_SAMPLES - 1):
            lo, hi = counts[k], counts[k + 1]
            if lo is None or hi is None or lo[0] == hi[0]:
                continue
            ua, ub = us[k], us[k + 1]
            for _ in range(EDGE_BISECTIONS):
                um = 0.5 * (ua + ub)
                mid = at(um)
                if mid is None:
                    break
                if mid[0] == lo[0]:
                    ua, lo = um, mid
                else:
                    ub, hi = um, mid
            more = lo if lo[0] > hi[0] else hi
            if not more[1]:
                continue
            q = min(more[1], key=sys.relative)
            res = sys.newton(q, sys.kernel(q), sys.edge(axis, bound))
            if res is not None:
                out.append(res[0])
    return out


def unexplained_folds(sheets: list, loci: list, box: tuple, n: int) -> int:
    """How many grid nodes a continuation step was refused from (a fold within a cell, or the corrector's
    jump away from the curve) have no traced actuator curve within a cell and a half."""
    span = np.array([box[0][1] - box[0][0], box[1][1] - box[1][0]], float)
    span[span == 0] = 1.0
    cell = 1.0 / max(n - 1, 1)
    pts = [lc.points for lc in loci if lc.kind == "actuator"]
    P = (np.concatenate(pts) - [box[0][0], box[1][0]]) / span if pts else np.zeros((0, 2))
    missed = 0
    for _, refused in sheets:
        for j, i in zip(*np.nonzero(refused)):
            node = np.array([i, j], float) * cell
            if not len(P) or np.abs(P - node).max(axis=1).min() > 1.5 * cell:
                missed += 1
    return missed


def sheets(solver: PositionSolver, x_name: str, y_name: str, box: tuple, starts: int | None, n: int) -> list:
    """Each start continued over an n x n grid of the box from its nearest node: a list of
    (qs (n, n, nq) with NaN where not reached, refused (n, n) bool: a step from there refused)."""
    mech = solver.mech
    gx, gy = np.linspace(*box[0], n), np.linspace(*box[1], n)
    steps = {x_name: Neighbour(solver, x_name), y_name: Neighbour(solver, y_name)}
    out = []
    for q0 in starts:
        qs = np.full((n, n, mech.nq), np.nan)
        refused = np.zeros((n, n), bool)
        # the node nearest the start, reached by two steps (an angle taken the whole turns into the box)
        q0 = np.array(q0, float)
        vals = {}
        for name, grid in ((x_name, gx), (y_name, gy)):
            c = mech.coordinate(name)
            v = float(q0[c.idx_q]) if c.nq == 1 else float(np.arctan2(q0[c.idx_q + 1], q0[c.idx_q]))
            if c.nq == 1 and not mech.translational[c.idx_v]:
                turns = np.round((0.5 * (grid[0] + grid[-1]) - v) / (2 * np.pi))
                if grid.min() <= v + 2 * np.pi * turns <= grid.max():
                    q0[c.idx_q] += 2 * np.pi * turns
                    v += 2 * np.pi * turns
            vals[name] = v
        i0, j0 = int(np.abs(gx - vals[x_name]).argmin()), int(np.abs(gy - vals[y_name]).argmin())
        q = steps[x_name](q0, vals[x_name], float(gx[i0])) if vals[x_name] != gx[i0] else q0
        q = steps[y_name](q, vals[y_name], float(gy[j0])) if q is not None and vals[y_name] != gy[j0] else q
        if q is None:
            continue
        qs[j0, i0] = q
        queue = [(j0, i0)]
        while queue:
            j, i = queue.pop(0)
            for dj, di in ((0, 1), (1, 0), (0, -1), (-1, 0)):
                jn, in_ = j + dj, i + di
                if not (0 <= jn < n and 0 <= in_ < n) or np.isfinite(qs[jn, in_, 0]):
                    continue
                name, a, b = (x_name, gx[i], gx[in_]) if di else (y_name, gy[j], gy[jn])
                qn = steps[name](qs[j, i], float(a), float(b))
                if qn is None:
                    refused[j, i] = True
                    continue
                qs[jn, in_] = qn
                queue.append((jn, in_))
        out.append((qs, refused))
    return out


def seed_configurations(sys, sheets: list) -> list:
    """Grid configurations to seed Newton from, most singular first: next to a refused step, or a local
    minimum of the kind's relative singular value along a grid line."""
    cands = []
    for qs, refused in sheets:
        n = qs.shape[0]
        sig = np.full((n, n), np.nan)
        for j in range(n):
            for i in range(n):
                if np.isfinite(qs[j, i, 0]):
                    sig[j, i] = sys.relative(qs[j, i])
        for j in range(n):
            for i in range(n):
                if not np.isfinite(sig[j, i]):
                    continue
                s = sig[j, i]
                local = False
                for dj, di in ((0, 1), (1, 0)):
                    a = sig[j - dj, i - di] if j - dj >= 0 and i - di >= 0 else np.inf
                    b = sig[j + dj, i + di] if j + dj < n and i + di < n else np.inf
                    a = np.inf if np.isnan(a) else a
                    b = np.inf if np.isnan(b) else b
                    local |= s <= a and s <= b
                if refused[j, i] or local:
                    cands.append((s, qs[j, i]))
    cands.sort(key=lambda c: c[0])
    return [(q, s) for s, q in cands]


def crossings(curves: list, box: tuple) -> list:
    """Points where two traces (or one with itself, away from its neighbours) cross: segment
    intersections of the polylines (the traces are dense: each segment is one continuation step)."""
    out = []
    span = np.array([box[0][1] - box[0][0], box[1][1] - box[1][0]])
    span[span == 0] = 1.0
    segs = []
    for c, P in enumerate(curves):
        P = P / span
        for k in range(len(P) - 1):
            segs.append((c, k, P[k], P[k + 1]))
    if len(segs) < 2:
        return out
    A = np.array([s[2] for s in segs])
    B = np.array([s[3] for s in segs])
    lo, hi = np.minimum(A, B), np.maximum(A, B)
    for m, (c, k, a, b) in enumerate(segs):
        cand = np.nonzero((lo[m + 1:, 0] <= hi[m, 0]) & (hi[m + 1:, 0] >= lo[m, 0])
                          & (lo[m + 1:, 1] <= hi[m, 1]) & (hi[m + 1:, 1] >= lo[m, 1]))[0] + m + 1
        for n_ in cand:
            c2, k2, a2, b2 = segs[n_]
            if c2 == c and abs(k2 - k) <= 2:
                continue
            d1, d2 = b - a, b2 - a2
            den = d1[0] * d2[1] - d1[1] * d2[0]
            if abs(den) < TINY:
                continue
            w = a2 - a
            s = (w[0] * d2[1] - w[1] * d2[0]) / den
            t = (w[0] * d1[1] - w[1] * d1[0]) / den
            if 0 <= s < 1 and 0 <= t < 1:
                out.append((c, k, c2, k2, s, t, (a + s * d1) * span))
    return out


def refine_node(sys, one: tuple, k1: int, f1: float, other: tuple, k2: int, f2: float, span: float) -> np.ndarray | None:
    """The crossing of two traces near their segments k1 and k2 (at fractions f1, f2 of them): Newton on
    the two arclengths s1, s2 from the segments' first points, xy(curve1(s1)) = xy(curve2(s2)), each
    point converged on F (LocusSystem.along).  None when it does not converge."""
    starts = []
    for (_P, Q, V), k, f in ((one, k1, f1), (other, k2, f2)):
        q, v = Q[k], V[k]
        t = sys.tangent(q, v)
        dz = np.concatenate([sys.mech.difference(q, Q[k + 1]) / sys.scale, V[k + 1] - v])
        if t @ dz < 0:
            t = -t
        starts.append((q, v, t, f * float(t @ dz)))
    s = np.array([starts[0][3], starts[1][3]])
    for _ in range(12):
        pts, vel = [], []
        for (q, v, t, _), si in zip(starts, s):
            res = sys.along(q, v, t, si) if si != 0 else (q, v)
            if res is None:
                return None
            pts.append(sys.xy(res[0]))
            vel.append(sys.projected(res[0], sys.tangent(*res, t)))
        gap = pts[1] - pts[0]
        if np.abs(gap).max() < sys.mech.tolerances.zero * span:
            return 0.5 * (pts[0] + pts[1])
        M = np.column_stack([vel[0], -vel[1]])
        try:
            s = s + np.linalg.solve(M, gap)
        except np.linalg.LinAlgError:
            return None
    return None
