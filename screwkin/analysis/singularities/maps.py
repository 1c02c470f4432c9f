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

from ...errors import UsageError, quote, shorten
from ..singular import Generic, measures
from ..motion.continuation import Neighbour
from ..position.connect import apart
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.position.position import PositionSolver
    from collections.abc import Callable

__all__ = ["SingularityMap", "singularity_map", "seams"]


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
    first = {x_name: xs[0], y_name: ys[0], **fixed}
    # the mode mapped: the one of q_start (a command's --mode K), else solve's first at the first corner
    q_start = q_start() if callable(q_start) else q_start  # (a function: called once the arguments are checked)
    q_first = solver.solve(first).solutions[0].q if q_start is None else solver.track(first, q_start).q
    g = Generic(mech, solver.inputs, output, point, configurations=solver.generic().configurations)
    logs = np.full((len(ys), len(xs)), np.nan)
    kinds = np.full((len(ys), len(xs)), "", dtype=object)
    qs = np.full((len(ys), len(xs), mech.nq), np.nan)
    reached = np.zeros((len(ys), len(xs)), bool)
    steps = {x_name: Neighbour(solver, x_name), y_name: Neighbour(solver, y_name)}
    grids = {x_name: xs, y_name: ys}
    queue = deque([(0, 0)])
    qs[0, 0], reached[0, 0] = q_first, True
    while queue:  # breadth first: each cell from its nearest reached neighbour
        j, i = queue.popleft()
        for dj, di in ((0, 1), (1, 0), (0, -1), (-1, 0)):
            jn, in_ = j + dj, i + di
            if not (0 <= jn < len(ys) and 0 <= in_ < len(xs)) or reached[jn, in_]:
                continue
            name, a, b = (x_name, i, in_) if di else (y_name, j, jn)
            q = steps[name](qs[j, i], float(grids[name][a]), float(grids[name][b]))
            if q is not None:
                qs[jn, in_], reached[jn, in_] = q, True
                queue.append((jn, in_))
    for j, i in zip(*np.nonzero(reached)):
        m = measures(mech, qs[j, i], g)
        kind = min(m, key=m.get)
        logs[j, i] = np.log10(max(m[kind], 1e-16))
        kinds[j, i] = kind
    seam = seams(mech, qs, reached, steps[x_name], steps[y_name], xs, ys)
    off = int(reached.size - reached.sum())
    notes = (f"{off} of {reached.size} points are not reached from the first one by continuation on its "
             "assembly mode (another mode, past a limit position, or not assembled): left blank",) if off else ()
    if len(seam):
        notes += (f"{len(seam)} pairs of neighbouring points lie on different sheets of the mode (their "
                  f"configurations differ by more than {mech.tolerances.near_far:g} rad: continuation from one "
                  "does not arrive at the other): a seam between them",)
    return SingularityMap(x_name, y_name, xs, ys, logs, kinds, qs, reached, notes, seam)


def seams(mech: Mechanism, qs: np.ndarray, reached: np.ndarray, step_x: Neighbour | None=None, step_y: Neighbour | None=None, xs: np.ndarray | None=None, ys: np.ndarray | None=None) -> np.ndarray:
    """Neighbouring reached cells (one input step apart) on different sheets of the mapped mode:
    their configurations differ by more than Tolerances.near_far (rad; lengths over the
    characteristic length) and -- when the steps (analysis.motion.continuation.Neighbour along x and y) and
    grids are given -- continuation from one does not arrive at the other (a steep but continuous
    stretch near a singular point is no seam).  Continuation round a singular point can come back on
    another sheet: the map's mode is one sheet only up to these seams.  (k, 4) int rows j, i, j2, i2."""
    out = []
    tol = mech.tolerances.near_far
    for (dj, di), step, grid in (((0, 1), step_x, xs), ((1, 0), step_y, ys)):
        for j, i in zip(*np.nonzero(reached)):
            jn, in_ = j + dj, i + di
            if jn >= reached.shape[0] or in_ >= reached.shape[1] or not reached[jn, in_]:
                continue
            if apart(mech, qs[j, i], qs[jn, in_]) <= tol:
                continue
            if step is not None:
                a, b = (i, in_) if di else (j, jn)
                q = step(qs[j, i], float(grid[a]), float(grid[b]))
                if q is not None and apart(mech, q, qs[jn, in_]) <= tol:
                    continue
            out.append((j, i, jn, in_))
    return np.array(out, int).reshape(-1, 4)
