"""Singularity maps over two inputs: log10 of the smallest relative singular value on a grid.

One assembly mode is mapped: the first solution at the grid's first corner, and
from it every cell that continuation reaches, each from a neighbour already
reached (one input changes), by the sweep's step (analysis.motion.continuation.Neighbour:
tangent predictor, corrector, branch tests).  A step that would jump to another
branch or cross a limit position is refused, so a cell is either on the mapped
branch or marked off it (``reached`` False, NaN, no kind): near a fold no cell
of another mode is ever mixed in.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from ...errors import AssemblyError, UsageError, quote, shorten
from ..singular import Generic, measures, stacked_measures
from ..motion.batch_sweep import GridNeighbours, batch_closure
from ..motion.continuation import Neighbour
from ..position.connect import apart
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.position.position import PositionSolver
    from collections.abc import Callable

__all__ = ["SingularityMap", "singularity_map", "seams", "start_cells", "first_assembled"]


@dataclass(frozen=True)
class SingularityMap:
    x_name: str
    y_name: str
    xs: np.ndarray
    ys: np.ndarray
    log_sigma: np.ndarray  # (len(ys), len(xs)): log10 of the smallest relative singular value (NaN off the branch)
    kind: np.ndarray  # (len(ys), len(xs)) object array: which singularity the minimum belongs to ("" off the branch)
    q: np.ndarray  # (len(ys), len(xs), nq) configurations (NaN off the branch)
    reached: np.ndarray | None = None  # (len(ys), len(xs)) bool: the cell lies on the mapped branch
    notes: tuple = ()  # what the continuation could not reach, in words
    seams: np.ndarray | None = None  # (k, 4) int: j, i, j2, i2 of neighbouring reached cells on different sheets

    @property
    def off_branch(self) -> int:
        """Cells the mapped assembly mode does not reach by continuation."""
        return int(self.reached.size - self.reached.sum()) if self.reached is not None else 0


def singularity_map(solver: PositionSolver, x_name: str, xs: np.ndarray, y_name: str, ys: np.ndarray, fixed: dict | None=None, output: str | None=None, point: bool = False,
                    q_start: Callable | None=None) -> SingularityMap:
    mech = solver.mech
    fixed = dict(fixed or {})
    if x_name == y_name:
        raise UsageError(f"--x and --y name the same input '{x_name}': a map needs two inputs")
    twice = sorted({x_name, y_name} & set(fixed))
    if twice:
        raise UsageError(f"{', '.join(twice)} is given by --x/--y and by --set: a map input is not also held")
    for n in (x_name, y_name):
        if n not in solver.inputs:
            raise UsageError(f"{mech.path}: {quote(n, 40)} is not an input ({', '.join(shorten(i, 40) for i in solver.inputs)})")
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    # the mode mapped: the one of q_start (a command's --mode K), else solve's first at the first corner; where
    # the first corner does not assemble, at the first of the box's centre, other corners and edge midpoints
    # that does (q_start may say which: (configuration, (j, i)))
    q_start = q_start() if callable(q_start) else q_start  # (a function: called once the arguments are checked)
    start = (0, 0)
    if isinstance(q_start, tuple):
        q_start, start = q_start
    if q_start is None:
        q_first, start = first_assembled(len(xs), len(ys), lambda j, i: solver.solve(
            {x_name: xs[i], y_name: ys[j], **fixed}).solutions[0].q)
    else:
        q_first = solver.track({x_name: xs[start[1]], y_name: ys[start[0]], **fixed}, q_start).q
    g = Generic(mech, solver.inputs, output, point, configurations=solver.generic().configurations)
    logs = np.full((len(ys), len(xs)), np.nan)
    kinds = np.full((len(ys), len(xs)), "", dtype=object)
    steps = {x_name: Neighbour(solver, x_name), y_name: Neighbour(solver, y_name)}
    bc = batch_closure(mech)
    batched = None
    if bc is not None and bc.target is None and mech.model.nq == mech.model.nv:
        batched = GridNeighbours(solver, (x_name, y_name), bc)
        qs, reached = _grow_batched(batched, mech.nq, xs, ys, q_first, start)
    else:
        qs, reached = _grow(steps, mech.nq, x_name, xs, y_name, ys, q_first, start)
    J, I = np.nonzero(reached)
    table = None
    if bc is not None and len(J):
        table = stacked_measures(mech, qs[J, I], g, bc.constraint_jacobians(qs[J, I]))
    if table is not None:
        names = list(table)
        M = np.column_stack([table[k] for k in names])
        best = np.argmin(M, axis=1)  # (the first of equal ones, as min over the dict)
        logs[J, I] = np.log10(np.maximum(M[np.arange(len(J)), best], 1e-16))
        kinds[J, I] = np.array(names, dtype=object)[best]
    else:
        for j, i in zip(J, I):
            m = measures(mech, qs[j, i], g)
            kind = min(m, key=m.get)
            logs[j, i] = np.log10(max(m[kind], 1e-16))
            kinds[j, i] = kind
    seam = seams(mech, qs, reached, steps[x_name], steps[y_name], xs, ys, batched=batched)
    off = int(reached.size - reached.sum())
    notes = ()
    if start != (0, 0):
        notes += (f"nothing assembles at the first corner ({x_name} = {xs[0]:.6g}, {y_name} = {ys[0]:.6g}): the map "
                  f"starts at ({x_name} = {xs[start[1]]:.6g}, {y_name} = {ys[start[0]]:.6g}), the first of the box's "
                  "centre, corners and edge midpoints where it does",)
    if off:
        notes += (f"{off} of {reached.size} points are not reached from the "
                  f"{'first one' if start == (0, 0) else 'starting point'} by continuation on its assembly mode "
                  "(another mode, past a limit position, or not assembled): left blank",)
    if len(seam):
        notes += (f"{len(seam)} pairs of neighbouring points lie on different sheets of the mode (their "
                  f"configurations differ by more than {mech.tolerances.near_far:g} rad: continuation from one "
                  "does not arrive at the other): a seam between them",)
    return SingularityMap(x_name, y_name, xs, ys, logs, kinds, qs, reached, notes, seam)


_DIRECTIONS = ((0, 1), (1, 0), (0, -1), (-1, 0))  # the order each cell tries its neighbours in


def start_cells(nx: int, ny: int) -> list:
    """The cells (j, i) a map may start from, in order: the first corner, the centre, the other corners, the
    edges' midpoints."""
    return list(dict.fromkeys([(0, 0), (ny // 2, nx // 2), (0, nx - 1), (ny - 1, 0), (ny - 1, nx - 1),
                               (0, nx // 2), (ny // 2, 0), (ny // 2, nx - 1), (ny - 1, nx // 2)]))


def first_assembled(nx: int, ny: int, attempt: Callable) -> tuple:
    """(attempt(j, i), (j, i)) for the first of start_cells where attempt -- a configuration there -- does not
    raise AssemblyError; the first corner's AssemblyError where every one does."""
    first_error = None
    for j, i in start_cells(nx, ny):
        try:
            return attempt(j, i), (j, i)
        except AssemblyError as e:
            first_error = first_error or e
    raise first_error


def _grow(steps: dict, nq: int, x_name: str, xs: np.ndarray, y_name: str, ys: np.ndarray, q_first: np.ndarray,
          start: tuple = (0, 0)) -> tuple:
    """The map's cells reached from the start cell (j, i) (the first corner), breadth first, each from its first
    reached neighbour (in queue order, neighbours in _DIRECTIONS' order) whose step (continuation.Neighbour)
    arrives: (qs (ny, nx, nq) NaN where not reached, reached (ny, nx))."""
    qs = np.full((len(ys), len(xs), nq), np.nan)
    reached = np.zeros((len(ys), len(xs)), bool)
    grids = {x_name: xs, y_name: ys}
    queue = deque([start])
    qs[start], reached[start] = q_first, True
    while queue:
        j, i = queue.popleft()
        for dj, di in _DIRECTIONS:
            jn, in_ = j + dj, i + di
            if not (0 <= jn < len(ys) and 0 <= in_ < len(xs)) or reached[jn, in_]:
                continue
            name, a, b = (x_name, i, in_) if di else (y_name, j, jn)
            q = steps[name](qs[j, i], float(grids[name][a]), float(grids[name][b]))
            if q is not None:
                qs[jn, in_], reached[jn, in_] = q, True
                queue.append((jn, in_))
    return qs, reached


def _grow_batched(steps: GridNeighbours, nq: int, xs: np.ndarray, ys: np.ndarray, q_first: np.ndarray,
                  start: tuple = (0, 0)) -> tuple:
    """``_grow``'s breadth-first walk a wavefront at a time, its steps batched (motion.batch_sweep.
    GridNeighbours): the same cells from the same neighbours in the same order.  Breadth first, the
    cells of one level are all taken before any of the next, and a cell of the next is reached by the
    first of its tries (its neighbours of this level in queue order, each's directions in _DIRECTIONS'
    order) that arrives; a try's answer depends only on its start and its two input values.  So every
    cell's first try is taken at once, then the second of those whose first failed, and so on; the next
    level's queue order is the order of the tries that reached its cells."""
    ny, nx = len(ys), len(xs)
    qs = np.full((ny, nx, nq), np.nan)
    U = np.full((ny, nx, 2, nq), np.nan)  # each reached cell's tangent directions (GridNeighbours.directions)
    reached = np.zeros((ny, nx), bool)
    qs[start], U[start], reached[start] = q_first, steps.directions(q_first[None])[0][0], True
    level = [start]
    while level:
        tries = {}  # cell -> its tries ((position of the source in the level, direction), ...) in order
        for pos, (j, i) in enumerate(level):
            for d, (dj, di) in enumerate(_DIRECTIONS):
                jn, in_ = j + dj, i + di
                if 0 <= jn < ny and 0 <= in_ < nx and not reached[jn, in_]:
                    tries.setdefault((jn, in_), []).append((pos, d))
        won = {}  # cell -> the try that reached it
        which = dict.fromkeys(tries, 0)
        while which:
            cells = list(which)
            pick = [tries[c][which[c]] for c in cells]
            S = np.array([level[pos] for pos, _ in pick])
            C = np.array(cells)
            axis = np.array([0 if _DIRECTIONS[d][1] else 1 for _, d in pick])
            a = np.where(axis == 0, xs[np.where(axis == 0, S[:, 1], 0)], ys[np.where(axis == 1, S[:, 0], 0)])
            b = np.where(axis == 0, xs[np.where(axis == 0, C[:, 1], 0)], ys[np.where(axis == 1, C[:, 0], 0)])
            Qn, ok, Un = steps(qs[S[:, 0], S[:, 1]], axis, a, b, U[S[:, 0], S[:, 1]])
            for k, c in enumerate(cells):
                if ok[k]:
                    won[c] = pick[k]
                    qs[c], U[c] = Qn[k], Un[k]
                    del which[c]
                else:
                    which[c] += 1
                    if which[c] == len(tries[c]):
                        del which[c]
        level = sorted(won, key=won.get)
        for c in level:
            reached[c] = True
    return qs, reached


def seams(mech: Mechanism, qs: np.ndarray, reached: np.ndarray, step_x: Neighbour | None=None, step_y: Neighbour | None=None, xs: np.ndarray | None=None, ys: np.ndarray | None=None,
          batched: tuple | None = None) -> np.ndarray:
    """Neighbouring reached cells (one input step apart) on different sheets of the mapped mode:
    their configurations differ by more than Tolerances.near_far (rad; lengths over the
    characteristic length) and -- when the steps (analysis.motion.continuation.Neighbour along x and y) and
    grids are given -- continuation from one does not arrive at the other (a steep but continuous
    stretch near a singular point is no seam).  Continuation round a singular point can come back on
    another sheet: the map's mode is one sheet only up to these seams.  (k, 4) int rows j, i, j2, i2.
    batched: the steps as motion.batch_sweep.GridNeighbours, taken all at once (the same answers)."""
    out = []
    tol = mech.tolerances.near_far
    for axis, ((dj, di), step, grid) in enumerate((((0, 1), step_x, xs), ((1, 0), step_y, ys))):
        ny, nx = reached.shape
        both = reached[:ny - dj, :nx - di] & reached[dj:, di:]
        J, I = np.nonzero(both)
        if not len(J):
            continue
        far = _apart(mech, qs[J, I], qs[J + dj, I + di]) > tol
        J, I = J[far], I[far]
        if step is not None and len(J):
            a, b = (I, I + di) if di else (J, J + dj)
            if batched is not None:
                Q, ok, _ = batched(qs[J, I], np.full(len(J), axis), grid[a], grid[b])
                joined = ok & (_apart(mech, Q, qs[J + dj, I + di]) <= tol)
            else:
                joined = np.zeros(len(J), bool)
                for k, (j, i) in enumerate(zip(J, I)):
                    q = step(qs[j, i], float(grid[a[k]]), float(grid[b[k]]))
                    joined[k] = q is not None and apart(mech, q, qs[j + dj, i + di]) <= tol
            J, I = J[~joined], I[~joined]
        out += [(j, i, j + dj, i + di) for j, i in zip(J, I)]
    return np.array(out, int).reshape(-1, 4)


def _apart(mech: Mechanism, Q1: np.ndarray, Q2: np.ndarray) -> np.ndarray:
    """position.connect.apart of every row pair (N,)."""
    if len(Q1) == 0:
        return np.zeros(0)
    D = mech.difference(Q1, Q2)
    D[:, mech.translational] /= mech.length
    return np.sqrt((D * D).sum(axis=1))
