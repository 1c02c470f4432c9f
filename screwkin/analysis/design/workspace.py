"""Workspaces: where an output link can go, how much of that is free of singularities, and
how well conditioned it is there.

Two methods:

- ``grid`` (parallel and closed-loop mechanisms; serial ones at a constant orientation):
  inverse kinematics on a grid of positions of the output link at one orientation (``pose``)
  or of its origin alone (``point``).  The grid spans the translations the output can make
  at that orientation (3 for a Delta or a Gough-Stewart platform, 2 in the plane of a planar
  mechanism).  From the output's position in the mechanism's assembled configuration the
  grid is filled outwards, wave by wave: each new point is solved (loop closures, the target,
  joint limits) from the solution at a neighbour, all points of a wave in one batched Newton
  solve (model.kernel.stacks.BatchClosure).  A solution must continue its neighbour's: it may not
  jump to another working mode (another branch of a leg), so the workspace is the one of
  the assembly mode the file is drawn in.  Along the grid's last axis every run of reached
  points is extended to the boundary by bisection (solved too), and the volume is the sum of
  those run lengths times the cell area: second-order accurate where the cell count is
  first-order.
- ``sampling`` (serial chains, the origin as a point): random joint values within the limits,
  the positions their forward kinematics reach counted in cells of the grid, with the
  measure of ``scan`` (smallest over largest singular value of the point's Jacobian).  A
  cell's measure is the best of its samples (the posture the arm would choose).

The measures at each point are those of analysis.singular, made dimensionless with the
mechanism's one characteristic length: ``actuator`` (relative smallest singular value of the
passive columns of K), ``serial`` (of the output's motion J_o V, relative to |J_o|), and the
``conditioning`` of the map from input rates to the output's motion (smallest over largest
singular value of J_o V V_a^+; for a serial chain the scan measure).  A point is free of
singularities when the actuator and serial measures are at least ``threshold``; the free
volume is integrated along the same runs with the crossings of the threshold located by
linear interpolation.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError, UsageError
from ...model.linalg import rank
from ...model.state import KinematicState
from ..singularities.batch import SerialJacobians
from ...model.kernel.scaling import dimensionless, dimensionless_twists
from ...model.kernel.stacks import BatchClosure, Unbatchable
from ...model.limits import within_limits
from ..singular import Generic
from .workspace_grid import MAX_POINTS, Grid, grid_axes, null_motions

if TYPE_CHECKING:
    from ...model.mechanism import Mechanism

__all__ = ["WorkspaceResult", "workspace", "DEFAULT_THRESHOLD", "MAX_ESTIMATE"]

DEFAULT_THRESHOLD = 0.01
#: Most grid points a --resolution may ask for, estimated from a first coarse pass before the work starts
#: (a grid point costs about 0.1 to 1 ms: this bounds a grid to about a minute or two).
MAX_ESTIMATE = 200_000
_BLOCK = 4096  # configurations per batched solve


@dataclass(frozen=True)
class WorkspaceResult:
    """The workspace of an output link (SI units: m, m^2 or m^3 for dimension 2 or 3)."""

    path: str
    output: str
    point: bool  # the output's origin as a point (orientation free) instead of its pose
    method: str  # "grid" | "sampling"
    dimension: int  # 2 (a plane) or 3
    origin: np.ndarray  # world position of grid index (0, ..., 0)
    axes: np.ndarray  # (dimension, 3) orthonormal world directions of the grid axes
    resolution: float  # grid step h [m]
    orientation: np.ndarray | None  # the output's rotation (grid, pose); None for a point
    index: np.ndarray  # (n, dimension) grid indices of the reached points (cells for sampling)
    positions: np.ndarray  # (n, 3) their world positions (cell centres for sampling)
    configurations: np.ndarray | None  # (n, nq) the solutions (grid)
    measures: dict  # "actuator", "serial", "conditioning" -> (n,) arrays
    free: np.ndarray  # (n,) free of actuator and serial singularities
    volume: float
    volume_cells: float  # reached points (cells) times the cell size
    free_volume: float
    conditioning_min: float | None  # over the free points
    conditioning_mean: float | None
    boundary: np.ndarray  # (b, 3) located points of the workspace's boundary
    free_boundary: np.ndarray  # (f, 3) located points where a measure crosses the threshold
    threshold: float
    length: float  # characteristic length of the measures [m]
    inputs: tuple
    bounds: np.ndarray  # (dimension, 2) the grid's range along each axis [m], world coordinates
    truncated: bool  # the bounds (or MAX_POINTS) cut the workspace
    solves: int  # configurations solved (grid) or sampled
    samples: int = 0
    notes: tuple = field(default_factory=tuple)

    @property
    def coordinates(self) -> np.ndarray:
        """(n, dimension) the reached points along the grid axes (world coordinates)."""
        return self.positions @ self.axes.T


# --------------------------------------------------------------------------------------- setup
class _Measures:
    """The workspace measures for stacks of assembled configurations."""

    def __init__(self, mech: Mechanism, output: str, point: bool, inputs: list, length: float) -> None:
        self.mech, self.point, self.L = mech, point, float(length or mech.length)
        self.closure = BatchClosure(mech, check=0) if (mech.cuts or mech.extra_rows) else None
        self.out = SerialJacobians(mech, output, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED, check=0)
        self.cols = np.array(self.out.chain.columns)
        self.generic = Generic(mech, inputs, output, point)
        self.a = mech.velocity_indices(inputs)
        self.slide = mech.translational
        self.position_rows = mech.closure.position_rows

    def __call__(self, Q: np.ndarray) -> dict:
        out = {"actuator": np.empty(len(Q)), "serial": np.empty(len(Q)), "conditioning": np.empty(len(Q))}
        for s in range(0, len(Q), _BLOCK):
            part = self._block(Q[s:s + _BLOCK])
            for k in out:
                out[k][s:s + _BLOCK] = part[k]
        return out

    def _block(self, Q: np.ndarray) -> dict:
        mech, g, L = self.mech, self.generic, self.L
        N, nv = len(Q), mech.nv
        J = np.zeros((N, 6, nv))
        J[:, :, self.cols] = self.out.poses(Q)[2]
        J = dimensionless_twists(J, self.slide, L)
        if self.point:
            J = J[:, :3]
        actuator = np.ones(N)
        if self.closure is not None and self.closure.nrows:
            K = dimensionless(self.closure.constraint_jacobians(Q), self.position_rows, self.slide, L)
            vt = np.linalg.svd(K, full_matrices=True)[2]
            V = vt[:, g.rank_K:].transpose(0, 2, 1)  # (N, nv, nv - rank)
            if g.rank_Kp:
                s = np.linalg.svd(K[:, :, g.p], compute_uv=False)
                actuator = np.where(s[:, 0] > 0, s[:, g.rank_Kp - 1] / np.where(s[:, 0] > 0, s[:, 0], 1), 0.0)
        else:
            V = np.broadcast_to(np.eye(nv), (N, nv, nv))
        JV = J @ V
        scale = np.linalg.svd(J, compute_uv=False)[:, 0]
        k = g.out_dim or 0
        if k:
            s = np.linalg.svd(JV, compute_uv=False)
            serial = np.where(scale > 0, s[:, k - 1] / np.where(scale > 0, scale, 1), 0.0) if s.shape[1] >= k \
                else np.zeros(N)
        else:
            serial = np.ones(N)
        # conditioning of the input -> output map: output twists per unit input rates
        Va = V[:, self.a, :]
        T = JV @ np.linalg.pinv(Va)
        s = np.linalg.svd(T, compute_uv=False)
        m = max(min(k, len(self.a)), 1)
        conditioning = np.where(s[:, 0] > 0, s[:, m - 1] / np.where(s[:, 0] > 0, s[:, 0], 1), 0.0)
        return {"actuator": actuator, "serial": serial, "conditioning": conditioning}


def _translations(mech: Mechanism, q: np.ndarray, output: str, point: bool) -> np.ndarray:
    """(3, k) directions the output (its origin for a point) can translate in at q, at a
    constant orientation unless ``point``: the linear part of the output twists that the loops
    allow with no rotation."""
    fid = mech.link_frame(output)
    J = KinematicState(mech, q).frame_jacobian(fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    K = mech.closure.jacobian(q) if mech.closure.nrows else np.zeros((0, mech.nv))
    V = null_motions(K, mech)
    T = J @ V
    if not point:
        T = T[:3] @ null_motions(T[3:], mech)
    else:
        T = T[:3]
    if not T.size:
        return np.zeros((3, 0))
    U, s, _ = np.linalg.svd(T)
    k = rank(T, mech.tolerances)
    return U[:, :k]


def workspace(mech: Mechanism, output: str, point: bool = False, orientation: np.ndarray | None=None, resolution: float | None = None,
              bounds=None, threshold: float = DEFAULT_THRESHOLD, length: float | None = None,
              method: str | None = None, samples: int = 200_000, seed: int = 0, inputs=None,
              timeout: float | None = None, q_start=None) -> WorkspaceResult:
    """The workspace of link ``output`` (see the module's text).

    point: its origin as a point (orientation free); else at a constant ``orientation`` (a 3x3
    rotation; default: the output's orientation in the assembled configuration).
    resolution: grid step [m] (default: about 24 steps across the workspace in 3-D, 120 in a
    plane, from a coarse first pass).  bounds: (dimension, 2) range along each grid axis,
    world coordinates [m] (default: no bound but MAX_POINTS).  threshold: the smallest
    actuator and serial measure of a singularity-free point.  length: characteristic length
    of the measures (default ``mech.length``).  method: "grid" or "sampling" (default:
    sampling for a serial chain's point, else grid).  samples, seed: of the sampling method.
    inputs: the input joints (default: the actuated ones, or every joint of a serial chain).
    q_start: an assembled configuration of the mode whose workspace it is (a command's --mode K), or a
    function giving it, called once the arguments are checked; default: the file's assembled one (or the
    nearest generic one when that is singular for the output).
    """
    if not (threshold >= 0 and np.isfinite(threshold)):
        raise UsageError(f"the threshold must be a non-negative number, got {threshold!r}")
    if resolution is not None and not (np.isfinite(resolution) and resolution > 0):
        raise UsageError(f"the resolution must be a positive length, got {resolution!r}")
    mech.link_frame(output)  # a clear error for an unknown link
    serial = not (mech.cuts or mech.extra_rows)
    method = method or ("sampling" if serial and point else "grid")
    if method not in ("grid", "sampling"):
        raise UsageError(f"unknown workspace method '{method}': grid or sampling")
    if method == "sampling" and not serial:
        raise UsageError(f"{mech.path}: the sampling method takes serial chains; this mechanism has closed loops "
                         "(use the grid method)")
    if method == "sampling" and orientation is not None:
        raise UsageError("the sampling method gives the positions the output's origin reaches with any "
                         "orientation: it takes no orientation (use the grid method)")
    inputs = list(inputs if inputs is not None else (mech.actuated or [c.joint for c in mech.coordinates]))
    if not inputs:
        raise UsageError(f"{mech.path}: the mechanism has no moving joint")
    L = float(length or mech.length)
    try:
        measures = _Measures(mech, output, point, inputs, L)
    except Unbatchable as e:  # the batched rows do not represent it (sliding contacts, multi-coordinate joints)
        raise UsageError(f"{e}: the workspace's batched solver does not take these yet (solve, sweep and ik do)") \
            from None
    if method == "sampling":
        return _sampling(mech, output, measures, resolution, bounds, threshold, L, samples, seed, inputs)
    deadline = None if timeout is None else time.monotonic() + float(timeout)
    return _grid(mech, output, point, orientation, measures, resolution, bounds, threshold, L, inputs, deadline,
                 q_start)


def _seed(mech: Mechanism, output: str, point: bool, orientation: np.ndarray | None, q_start=None) -> tuple:
    """The assembled configuration the grid starts from (``q_start`` when given), the output's position
    and the grid's orientation there (continued from the file's orientation to the one asked)."""
    assembly, generic = mech.generic_configurations()
    q_start = q_start() if callable(q_start) else q_start
    fid = mech.link_frame(output)
    bc = BatchClosure(mech, target=(output, "point" if point else "pose"), check=0)
    # the file's assembled configuration may be singular for the output (an arm drawn stretched,
    # a wrist with aligned axes): then the nearest generic one, where the rows' rank is largest
    best = None
    for q in [assembly.q] + list(generic) if q_start is None else [np.asarray(q_start, float)]:
        M = KinematicState(mech, q).frame_placement(fid)
        K = bc.evaluate(q[None], targets=(M.translation[None], M.rotation))[1][0]
        k = rank(K, mech.tolerances)
        if best is None or k > best[0]:
            best = (k, q, M.translation.copy(), M.rotation.copy())
    _, q, p, R0 = best
    if point or orientation is None:
        return q, p, (None if point else R0)
    R = np.asarray(orientation, float)
    if R.shape != (3, 3) or not np.allclose(R @ R.T, np.eye(3), atol=1e-9):
        raise UsageError("the orientation must be a rotation matrix")
    w = pin.log3(R0.T @ R)
    steps = max(int(np.ceil(np.linalg.norm(w) / np.radians(2.0))), 1)
    for k in range(1, steps + 1):
        Rk = R0 @ pin.exp3(w * k / steps)
        Qn, ok, res, _ = bc.solve(q[None], (p[None], Rk))
        if not ok[0]:
            raise AssemblyError(mech.path, float(res[0]), mech.tolerances.max_iterations,
                                detail=f"the output '{output}' cannot turn to the orientation asked at its "
                                       "position in the file's configuration")
        q = Qn[0]
    if not within_limits(mech, q[None])[0]:
        raise AssemblyError(mech.path, 0.0, 0, detail=f"turning '{output}' to the orientation asked at its position "
                                                      "in the file's configuration takes a joint past its limits")
    return q, p, R


def _index_bounds(bounds, p_seed: np.ndarray, axes: np.ndarray, h: float, dim: int) -> tuple:
    """Index ranges (lo, hi) per axis for world-coordinate bounds (dimension, 2), or None."""
    if bounds is None:
        return [-(10**9)] * dim, [10**9] * dim
    b = np.asarray(bounds, float)
    if b.shape != (dim, 2) or not np.all(np.isfinite(b)) or np.any(b[:, 1] <= b[:, 0]):
        raise UsageError(f"the bounds must be {dim} ranges low:high with low < high")
    c = axes @ p_seed
    lo = np.ceil((b[:, 0] - c) / h - 1e-9).astype(int)
    hi = np.floor((b[:, 1] - c) / h + 1e-9).astype(int)
    if np.any(lo > 0) or np.any(hi < 0):
        raise UsageError("the bounds must contain the output's position in the file's configuration "
                         f"({', '.join(f'{x:.6g}' for x in c)} m along the grid axes)")
    return list(lo), list(hi)


def _choose_resolution(mech: Mechanism, output: str, point: bool, R: np.ndarray | None, q_seed: np.ndarray,
                       p_seed: np.ndarray, axes: np.ndarray, bounds: Any, resolution: float | None, L: float,
                       deadline: float | None, notes: list[str]) -> float:
    """The grid's step: the one given, checked against the work a first pass at L/4 says it would take, or
    (None) ~24 (3-D) or ~120 (2-D) steps across the extent that pass reaches (said in ``notes``)."""
    dim = axes.shape[0]
    h0 = L / 4.0
    if resolution is not None and resolution >= h0:
        return resolution
    lo, hi = _index_bounds(bounds, p_seed, axes, h0, dim)
    coarse = Grid(mech, output, point, R, q_seed, p_seed, axes, h0, lo, hi)
    coarse.deadline = deadline
    idx = np.array(list(coarse.fill()), int)
    if resolution is None:
        extent = (idx.max(axis=0) - idx.min(axis=0) + 2) * h0
        resolution = float(extent.max()) / (24.0 if dim == 3 else 120.0)
        notes.append(f"resolution {resolution:.4g} m chosen from a first pass at {h0:.4g} m")
        return resolution
    estimate = len(idx) * (h0 / resolution) ** dim
    if estimate > MAX_ESTIMATE:
        least = h0 * (len(idx) / MAX_ESTIMATE) ** (1.0 / dim)
        least = float(f"{least * 1.05:.2g}")
        raise UsageError(f"--resolution {resolution:.4g} m would solve about {estimate:.2g} grid points "
                         f"(a first pass at {h0:.3g} m reached {len(idx)}), limit {MAX_ESTIMATE:,}: use "
                         f"--resolution {least:g} or more, or --bounds")
    return resolution


def _runs(grid: Grid, solved: dict, axes: np.ndarray, lo: list[int], hi: list[int]) -> tuple[
        np.ndarray, np.ndarray, dict[tuple[int, int], tuple[float, np.ndarray]], list[np.ndarray]]:
    """The runs along the last axis, completed and extended to the boundary by bisection: (the grid indices
    solved, their configurations, (point k, +1 | -1) -> (fraction of a step, configuration) of each located
    end, the boundary points)."""
    dim, h = axes.shape[0], grid.h
    last = np.zeros(dim, int)
    last[-1] = 1
    for a in range(dim - 1):  # the band along the boundary where it runs across the last axis
        step = np.zeros(dim, int)
        step[a] = 1
        grid.march(solved, step)
        grid.march(solved, -step)
    run_ends = {1: grid.march(solved, last), -1: grid.march(solved, -last)}
    index = np.array(list(solved), int).reshape(-1, dim)
    Q = np.array(list(solved.values()))
    key = {tuple(i): k for k, i in enumerate(index)}
    ends = {}
    boundary = []
    for sign, found in run_ends.items():
        for i, (f, qb) in found.items():
            k = key[i]
            ends[(k, sign)] = (f, qb)
            if f > 0 or lo[-1] <= i[-1] + sign <= hi[-1]:
                boundary.append(grid.position(index[k]) + sign * f * h * axes[-1])
    return index, Q, ends, boundary


def _run_lengths(grid: Grid, index: np.ndarray, ends: dict, worst: np.ndarray, end_min: dict, threshold: float,
                 axes: np.ndarray) -> tuple[float, float, list[np.ndarray]]:
    """(the runs' total length, their free length, the points where the free part ends) along the last axis."""
    h = grid.h
    volume_len = 0.0
    free_len = 0.0
    free_boundary: list[np.ndarray] = []
    columns: dict[tuple, list[tuple[int, int]]] = {}
    for k, i in enumerate(index):
        columns.setdefault(tuple(i[:-1]), []).append((int(i[-1]), k))
    for col in columns.values():
        col.sort()
        for n, (z, k) in enumerate(col):
            up = ends.get((k, 1))
            down = ends.get((k, -1))
            if down is not None:  # a run starts here
                volume_len += down[0] * h
                free_len += _free_part(worst[k], end_min[(k, -1)], down[0] * h, threshold, grid.position(index[k]),
                                       -axes[-1], free_boundary)
            if up is not None:
                volume_len += up[0] * h
                free_len += _free_part(worst[k], end_min[(k, 1)], up[0] * h, threshold, grid.position(index[k]),
                                       axes[-1], free_boundary)
            elif n + 1 < len(col) and col[n + 1][0] == z + 1:
                k2 = col[n + 1][1]
                volume_len += h
                free_len += _free_part(worst[k], worst[k2], h, threshold, grid.position(index[k]), axes[-1],
                                       free_boundary)
    return volume_len, free_len, free_boundary


def _grid(mech: Mechanism, output: str, point: bool, orientation: Any, measures: _Measures,
          resolution: float | None, bounds: Any, threshold: float, L: float, inputs: list[str],
          deadline: float | None = None, q_start=None) -> WorkspaceResult:
    try:
        BatchClosure(mech, target=(output, "point" if point else "pose"))  # raises Unbatchable
    except Unbatchable as e:
        raise UsageError(f"{e}: the workspace's batched solver does not take these yet") from None
    q_seed, p_seed, R = _seed(mech, output, point, orientation, q_start)
    directions = _translations(mech, q_seed, output, point)
    dim = directions.shape[1]
    if dim < 2 and not point and orientation is None and _translations(mech, q_seed, output, True).shape[1] >= 2:
        # the link cannot keep its orientation and move over an area (a five-bar's distal link):
        # what is asked is then where its origin goes
        res = _grid(mech, output, True, None, _Measures(mech, output, True, inputs, L), resolution, bounds,
                    threshold, L, inputs, deadline, q_start)
        note = (f"'{output}' moves over no area at a constant orientation: the workspace of its origin with "
                "any orientation (as --point)")
        return dataclasses.replace(res, notes=(note,) + tuple(res.notes))
    if dim < 2:
        what = "its origin" if point else f"'{output}' at a constant orientation"
        raise UsageError(f"{mech.path}: {what} moves along {'a curve' if dim == 1 else 'no direction'} "
                         f"({dim} translation{'s' if dim != 1 else ''}), not over an area or a volume: "
                         "use sweep" + ("" if point else ", or --point"))
    axes = grid_axes(directions)
    notes: list[str] = []
    h = resolution = _choose_resolution(mech, output, point, R, q_seed, p_seed, axes, bounds, resolution, L,
                                        deadline, notes)
    lo, hi = _index_bounds(bounds, p_seed, axes, resolution, dim)
    grid = Grid(mech, output, point, R, q_seed, p_seed, axes, resolution, lo, hi)
    grid.deadline = deadline
    solved = grid.fill()
    index, Q, ends, boundary = _runs(grid, solved, axes, lo, hi)
    m = measures(Q)
    free = (m["actuator"] >= threshold) & (m["serial"] >= threshold)
    # measures at the located ends, for the free runs
    end_keys = list(ends)
    end_measures = measures(np.array([ends[e][1] for e in end_keys])) if end_keys else None
    end_min = {e: min(end_measures["actuator"][n], end_measures["serial"][n]) for n, e in enumerate(end_keys)}
    worst = np.minimum(m["actuator"], m["serial"])
    volume_len, free_len, free_boundary = _run_lengths(grid, index, ends, worst, end_min, threshold, axes)
    cell = h ** (dim - 1)
    cond = m["conditioning"][free]
    truncated = grid.truncated and bounds is not None or len(index) >= MAX_POINTS
    if grid.truncated and bounds is None and len(index) < MAX_POINTS:
        truncated = False
    if grid.timed_out:
        truncated = True
        notes.append(f"stopped at the time limit (--timeout) after {len(index)} points: the volumes are lower "
                     "bounds, not the workspace's")
    positions = p_seed + (index * h) @ axes
    c = axes @ p_seed
    rng = np.array([[c[a] + index[:, a].min() * h, c[a] + index[:, a].max() * h] for a in range(dim)])
    return WorkspaceResult(
        mech.path, output, point, "grid", dim, p_seed.copy(), axes, h, R, index, positions, Q, m, free,
        volume_len * cell, len(index) * h**dim, free_len * cell,
        float(cond.min()) if cond.size else None, float(cond.mean()) if cond.size else None,
        np.array(boundary).reshape(-1, 3), np.array(free_boundary).reshape(-1, 3), float(threshold), L,
        tuple(inputs), rng, bool(truncated), grid.solves, 0, tuple(notes))


def _free_part(m0: float, m1: float, length: float, threshold: float, p0: np.ndarray, direction: np.ndarray, crossings: list) -> float:
    """The free length of a segment from a point of measure m0 to one of m1 (linear between),
    recording a crossing of the threshold."""
    a, b = m0 >= threshold, m1 >= threshold
    if a and b:
        return length
    if not a and not b:
        return 0.0
    t = (m0 - threshold) / (m0 - m1)  # where the linear measure meets the threshold, from p0
    crossings.append(p0 + t * length * direction)
    return t * length if a else (1.0 - t) * length


# ----------------------------------------------------------------------------------- sampling
def _sampling(mech: Mechanism, output: str, measures: _Measures, resolution: float | None, bounds, threshold: float, L: float, samples: int, seed: int, inputs: list) -> WorkspaceResult:
    samples = int(samples)
    if samples < 1:
        raise UsageError(f"the number of samples must be positive, got {samples}")
    model = mech.model
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
    hi = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
    slide = np.zeros(model.nq, bool)  # (serial chains here: every joint has one coordinate, nq = nv)
    slide[mech.translational] = True
    if (slide & ~(np.isfinite(model.lowerPositionLimit) & np.isfinite(model.upperPositionLimit))).any():
        raise UsageError(f"{mech.path}: a sliding joint without limits reaches without bound: give it <limit>")
    sj = measures.out
    positions = np.empty((samples, 3))
    values = np.empty(samples)
    Q = np.empty((min(samples, _BLOCK * 4), model.nq))
    for s in range(0, samples, len(Q)):
        n = min(len(Q), samples - s)
        Qs = rng.uniform(lo, hi, size=(n, model.nq))
        positions[s:s + n] = sj.poses(Qs)[1]
        values[s:s + n] = measures(Qs)["conditioning"]
    centre = positions.mean(axis=0)
    spread = np.linalg.svd((positions - centre).T, compute_uv=False)
    dim = int(np.sum(spread > 1e-9 * max(spread[0], 1e-300)))
    if dim < 2:
        raise UsageError(f"{mech.path}: the origin of '{output}' moves along a curve, not over an area or a volume")
    directions = np.linalg.svd((positions - centre).T, full_matrices=False)[0][:, :dim]
    axes = grid_axes(directions)
    coords = positions @ axes.T
    if resolution is None:
        extent = coords.max(axis=0) - coords.min(axis=0)
        resolution = float(extent.max()) / (24.0 if dim == 3 else 120.0)
    h = float(resolution)
    origin = np.zeros(3)
    keep = np.ones(samples, bool)
    if bounds is not None:
        b = np.asarray(bounds, float)
        if b.shape != (dim, 2) or np.any(b[:, 1] <= b[:, 0]):
            raise UsageError(f"the bounds must be {dim} ranges low:high with low < high")
        keep = np.all((coords >= b[:, 0]) & (coords <= b[:, 1]), axis=1)
    cells = np.floor(coords[keep] / h).astype(np.int64)
    if not len(cells):
        raise UsageError("no sample lies within the bounds")
    uniq, inverse = np.unique(cells, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    if len(uniq) > MAX_POINTS:
        raise UsageError(f"{len(uniq)} cells: more than {MAX_POINTS}; use a coarser resolution")
    best = np.full(len(uniq), -np.inf)
    np.maximum.at(best, inverse, values[keep])
    free = best >= threshold
    centres = (uniq + 0.5) * h @ axes
    cond = best[free]
    b = np.array([[uniq[:, a].min() * h, (uniq[:, a].max() + 1) * h] for a in range(dim)])
    m = {"actuator": np.ones(len(uniq)), "serial": best.copy(), "conditioning": best.copy()}
    vol = len(uniq) * h**dim
    return WorkspaceResult(
        mech.path, output, True, "sampling", dim, origin, axes, h, None, uniq, centres, None, m, free,
        vol, vol, int(free.sum()) * h**dim, float(cond.min()) if cond.size else None,
        float(cond.mean()) if cond.size else None, np.zeros((0, 3)), np.zeros((0, 3)), float(threshold), L,
        tuple(inputs), b, bounds is not None, samples, samples,
        (f"{samples} joint-space samples in {len(uniq)} cells of {h:.4g} m: a cell counts when a sample falls "
         "in it (more samples fill thin regions; boundary cells count whole)",))
