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
  solve (analysis.batch_closure.BatchClosure).  A solution must continue its neighbour's: it may not
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

import numpy as np
import pinocchio as pin

from ..errors import AssemblyError, UsageError
from ..model.linalg import rank
from ..model.newton import damped_steps
from .batch import SerialJacobians
from .batch_closure import BatchClosure, Unbatchable
from .position import within_limits
from .singular import Generic

__all__ = ["WorkspaceResult", "workspace", "DEFAULT_THRESHOLD", "MAX_POINTS", "MAX_ESTIMATE"]

DEFAULT_THRESHOLD = 0.01
MAX_POINTS = 2_000_000  # reached grid points (or sampling cells) before a workspace stops
#: Most grid points a --resolution may ask for, estimated from a first coarse pass before the work starts
#: (a grid point costs about 0.1 to 1 ms: this bounds a grid to about a minute or two).
MAX_ESTIMATE = 200_000
_BLOCK = 4096  # configurations per batched solve
_BISECTIONS = 5  # boundary located to h / 32
_SUBSTEPS = 8  # at most this many substeps for a grid step near a fold (see _Grid.substeps)
_FOLD = 0.2  # sigma ~ _FOLD sqrt(d / L) a distance d inside a fold (measured: 0.2-0.5 on the five-bar)
_SINGULAR = 1e-6  # relative singular value under which a point is not grown from
_ITERATIONS = 8  # Newton from a neighbour's solution and the predictor converges in 2 to 4; a point that
#                   takes more lies beyond the boundary (or across a singularity) from that neighbour


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

    def __init__(self, mech, output, point, inputs, length):
        self.mech, self.point, self.L = mech, point, float(length or mech.length)
        self.closure = BatchClosure(mech, check=0) if (mech.cuts or mech.extra_rows) else None
        self.out = SerialJacobians(mech, output, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED, check=0)
        self.cols = np.array(self.out.chain.columns)
        self.generic = Generic(mech, inputs, output, point)
        self.a = mech.velocity_indices(inputs)
        self.slide = mech.translational
        self.position_rows = mech.closure.position_rows

    def __call__(self, Q) -> dict:
        out = {"actuator": np.empty(len(Q)), "serial": np.empty(len(Q)), "conditioning": np.empty(len(Q))}
        for s in range(0, len(Q), _BLOCK):
            part = self._block(Q[s:s + _BLOCK])
            for k in out:
                out[k][s:s + _BLOCK] = part[k]
        return out

    def _block(self, Q) -> dict:
        mech, g, L = self.mech, self.generic, self.L
        N, nv = len(Q), mech.nv
        J = np.zeros((N, 6, nv))
        J[:, :, self.cols] = self.out.poses(Q)[2]
        J[:, :3] /= L
        J[:, :, self.slide] *= L
        if self.point:
            J = J[:, :3]
        actuator = np.ones(N)
        if self.closure is not None and self.closure.nrows:
            K = self.closure.constraint_jacobians(Q)
            K[:, self.position_rows] /= L
            K[:, :, self.slide] *= L
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


def _translations(mech, q, output, point) -> np.ndarray:
    """(3, k) directions the output (its origin for a point) can translate in at q, at a
    constant orientation unless ``point``: the linear part of the output twists that the loops
    allow with no rotation."""
    fid = mech.link_frame(output)
    model, data = mech.model, mech.data
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    K = mech.closure.jacobian(q) if mech.closure.nrows else np.zeros((0, mech.nv))
    V = _null(K, mech)
    T = J @ V
    if not point:
        T = T[:3] @ _null(T[3:], mech)
    else:
        T = T[:3]
    if not T.size:
        return np.zeros((3, 0))
    U, s, _ = np.linalg.svd(T)
    k = rank(T, mech.tolerances)
    return U[:, :k]


def _null(A, mech):
    if not A.size:
        return np.eye(A.shape[1])
    _, s, vt = np.linalg.svd(A)
    k = rank(A, mech.tolerances)
    return vt[k:].T


def _grid_axes(directions) -> np.ndarray:
    """Grid axes spanning the translation directions: the world axes in 3-D; in a plane the two
    world axes of a coordinate plane, else an orthonormal basis of the plane."""
    k = directions.shape[1]
    if k == 3:
        return np.eye(3)
    normal = np.cross(directions[:, 0], directions[:, 1])
    normal /= np.linalg.norm(normal)
    for i in range(3):
        if abs(abs(normal[i]) - 1) < 1e-9:
            return np.delete(np.eye(3), i, axis=0)
    u = directions[:, 0] / np.linalg.norm(directions[:, 0])
    return np.array([u, np.cross(normal, u)])


# --------------------------------------------------------------------------------------- grid
class _Grid:
    """Batched inverse kinematics on a grid (see the module's text)."""

    def __init__(self, mech, output, point, orientation, q_seed, p_seed, axes, h, lo, hi, frozen=()):
        self.mech, self.axes, self.h = mech, axes, float(h)
        self.deadline = None  # time.monotonic() past which the growth stops (the result marked truncated)
        self.timed_out = False
        self.p_seed = p_seed
        self.R = np.eye(3) if orientation is None else orientation
        self.closure = BatchClosure(mech, target=(output, "point" if point else "pose"))
        self.lo, self.hi = lo, hi  # index ranges (inclusive) per axis
        self.q_seed = q_seed
        self.L, self.slide = float(mech.length), mech.translational
        # the rank of the rows' Jacobian (loops and target) in the working mode: at the seed
        K = self.closure.evaluate(q_seed[None], (self.position(np.zeros(len(axes)))[None], self.R))[1][0]
        self.rank = rank(K, mech.tolerances)
        Ks = self._scaled(K[None])[0]
        sv = np.linalg.svd(Ks, compute_uv=False)
        self.sigma = {(0,) * len(axes): float(sv[self.rank - 1] / sv[0]) if self.rank and sv[0] > 0 else 1.0}
        self.solves = 0
        self.truncated = False

    def position(self, index) -> np.ndarray:
        return self.p_seed + (np.asarray(index, float) * self.h) @ self.axes

    def solve(self, Q0, P):
        """Solve from Q0 (N, nq) for targets P (N, 3): (Q, ok) with ok: converged and within
        the joint limits."""
        Q = np.empty_like(Q0)
        ok = np.zeros(len(Q0), bool)
        for s in range(0, len(Q0), _BLOCK):
            q, conv, _, _ = self.closure.solve(Q0[s:s + _BLOCK], (P[s:s + _BLOCK], self.R), iterations=_ITERATIONS)
            Q[s:s + _BLOCK], ok[s:s + _BLOCK] = q, conv
        self.solves += len(Q0)
        if ok.any():
            ok[ok] &= within_limits(self.mech, Q[ok])
        return Q, ok

    def predict(self, Q, P_from, P_to):
        """First-order predictor: the joint steps that move the target from P_from to P_to
        (minimum norm through the solver's rows: K dq = -(change of the target rows)), and
        the rows' Jacobian at Q (it does not depend on where the target is)."""
        r0, K = self.closure.evaluate(Q, (P_to, self.R))
        r1 = self.closure.evaluate(Q, (P_from, self.R), jacobian=False)[0]
        dr = r0 - r1  # the rows' change from moving the target alone
        return Q + damped_steps(K, dr, np.full(len(Q), self.mech.tolerances.lm_damping))[0], K

    def _scaled(self, K):
        """The rows' Jacobians made dimensionless: lengths / L, sliding columns * L."""
        K = K.copy()
        K[:, self.closure.solver_position_rows] /= self.L
        K[:, :, self.slide] *= self.L
        return K

    def kept(self, Q_from, K_from, Q_pred, Q_new, P_new):
        """(kept, sigma) for new solutions solved from Q_from: kept when it continues the old
        solution -- near the predicted configuration, and on the same branch: the rows'
        Jacobian (loops and target) restricted to the old one's range and row space keeps the
        sign of its determinant (a jump across a fold to another working mode flips it);
        sigma: the new Jacobian's r-th singular value relative to its largest (dimensionless),
        how far it is from a fold (``substeps``)."""
        step = np.linalg.norm(Q_pred - Q_from, axis=1)
        miss = np.linalg.norm(Q_new - Q_pred, axis=1)
        ok = miss <= 0.5 * step + 1e-6
        K_new = self._scaled(self.closure.evaluate(Q_new, (P_new, self.R))[1])
        r = self.rank
        if not r:
            return ok, np.ones(len(ok))
        # the old row space C: the top r eigenvectors of Ks^T Ks (half the cost of an SVD); the
        # old range is Ks C / s, so det(B^T K_new C) has the sign of det(C^T Ks^T K_new C)
        Ks = self._scaled(K_from)
        C = np.linalg.eigh(Ks.transpose(0, 2, 1) @ Ks)[1][:, :, -r:]
        KC = Ks @ C
        ok &= np.linalg.det(KC.transpose(0, 2, 1) @ K_new @ C) > 0
        ev = np.sqrt(np.maximum(np.linalg.eigvalsh(K_new.transpose(0, 2, 1) @ K_new), 0.0))[:, ::-1]
        return ok, np.where(ev[:, 0] > 0, ev[:, r - 1] / np.where(ev[:, 0] > 0, ev[:, 0], 1.0), 0.0)

    def substeps(self, sigma) -> np.ndarray:
        """Substeps for a grid step from points of relative singular value sigma: two branches
        of a fold a distance d inside it differ by about sqrt(d / L) in the joints, and so does
        sigma there, so a step of h may land on either below about sqrt(h / L): the step is cut
        into n with _FOLD sqrt(h / (n L)) <= sigma, n a power of two up to _SUBSTEPS (closer to a
        fold than that, _SUBSTEPS and the branch test of ``kept``; 0 at a singular point (sigma
        under _SINGULAR): it is not grown from, the runs reach past it)."""
        sigma = np.asarray(sigma, float)
        need = (self.h / self.L) * (_FOLD / np.maximum(sigma, _SINGULAR)) ** 2
        n = np.minimum(2 ** np.ceil(np.log2(np.clip(need, 1.0, _SUBSTEPS))), _SUBSTEPS)
        return np.where(sigma >= _SINGULAR, n, 0).astype(int)

    def advance(self, Q, P_from, P_to, n):
        """Solve from Q at P_from to P_to in n equal substeps (n: an int, or one per point,
        all advanced together): (Q, ok, sigma, jumped) -- jumped: a substep converged within
        the limits but ``kept`` refused it (another branch, or far from the prediction)."""
        n = np.broadcast_to(np.asarray(n, int), (len(Q),))
        ok = np.ones(len(Q), bool)
        jumped = np.zeros(len(Q), bool)
        sigma = np.zeros(len(Q))
        Qc, Pc = Q.copy(), P_from.copy()
        for k in range(1, int(n.max(initial=0)) + 1):
            sel = np.flatnonzero(ok & (n >= k))
            if not len(sel):
                break
            Pk = P_from[sel] + (P_to[sel] - P_from[sel]) * (k / n[sel])[:, None]
            Q0, K = self.predict(Qc[sel], Pc[sel], Pk)
            Qn, good = self.solve(Q0, Pk)
            kept, sig = self.kept(Qc[sel], K, Q0, Qn, Pk)
            jumped[sel] = good & ~kept
            good &= kept
            ok[sel] = good
            Qc[sel[good]], Pc[sel[good]], sigma[sel] = Qn[good], Pk[good], sig
        return Qc, ok, sigma, jumped

    def advance_all(self, Q, P_from, P_to, n, retry=True):
        """advance for points with each their number of substeps n (> 0), in blocks; with
        ``retry``, a step refused as a jump to another branch is tried again in twice as many
        substeps, up to _SUBSTEPS (a step that does not converge -- past the boundary -- is not)."""
        Qn, ok, sigma = np.empty_like(Q), np.zeros(len(Q), bool), np.zeros(len(Q))
        jumped = np.zeros(len(Q), bool)
        n = np.asarray(n, int).copy()
        todo = np.arange(len(Q))
        while len(todo):
            for s_ in range(0, len(todo), _BLOCK):
                sel = todo[s_:s_ + _BLOCK]
                Qn[sel], ok[sel], sigma[sel], jumped[sel] = self.advance(Q[sel], P_from[sel], P_to[sel], n[sel])
            todo = todo[jumped[todo] & (n[todo] < _SUBSTEPS)] if retry else todo[:0]
            n[todo] *= 2
        return Qn, ok, sigma

    def _late(self) -> bool:
        """Past the deadline: the growth stops here and the result says it was cut."""
        if self.deadline is not None and time.monotonic() > self.deadline:
            self.truncated = self.timed_out = True
        return self.timed_out

    def fill(self):
        """{grid index: configuration} of the points reached, filled wave by wave (also
        ``self.sigma``: index -> relative singular value of the rows' Jacobian there)."""
        d = len(self.axes)
        offsets = np.vstack([np.eye(d, dtype=int), -np.eye(d, dtype=int)])
        solved = {(0,) * d: self.q_seed}
        sigma = self.sigma
        failed = {}  # index -> attempts
        wave = [(0,) * d]
        while wave:
            # candidates: unsolved in-range neighbours of the last wave, each from one parent
            cand = {}
            for idx in wave:
                base = np.array(idx)
                for off in offsets:
                    n = tuple(base + off)
                    if n in solved or n in cand or failed.get(n, 0) >= 2:
                        continue
                    if any(x < a or x > b for x, a, b in zip(n, self.lo, self.hi)):
                        self.truncated = True
                        continue
                    cand[n] = idx
            if not cand:
                break
            if self._late():
                break
            if len(solved) + len(cand) > MAX_POINTS:
                self.truncated = True
                break
            targets = list(cand)
            parents = [cand[t] for t in targets]
            Qp = np.array([solved[p] for p in parents])
            Pp = np.array([self.position(p) for p in parents])
            Pt = np.array([self.position(t) for t in targets])
            steps = self.substeps(np.array([sigma[p] for p in parents]))
            Q, ok, sig = self.advance_all(Qp, Pp, Pt, steps)
            wave = []
            for t, q, good, sg in zip(targets, Q, ok, sig):
                if good:
                    solved[t] = q
                    sigma[t] = float(sg)
                    if self.substeps(np.array([sg]))[0]:
                        wave.append(t)
                else:
                    failed[t] = failed.get(t, 0) + 1
        return solved

    def march(self, solved: dict, direction) -> dict:
        """Complete the runs along ``direction`` (a unit index vector): from every solved point
        whose neighbour that way is not solved (and within the bounds), step on point by point
        (each solved from the last, kept on its branch) until a step fails, then bisect that
        step.  The band along a fold that ``fill`` does not grow from is filled this way, one
        line at a time.  Adds the points it reaches to ``solved``; returns {index of a run's last
        point: (fraction of the next step reached, configuration there)}."""
        direction = np.asarray(direction, int)
        axis = int(np.flatnonzero(direction)[0])
        lo, hi = self.lo[axis], self.hi[axis]
        ends = {}
        current = [i for i in solved if tuple(np.add(i, direction)) not in solved]
        for i in [i for i in current if not lo <= i[axis] + direction[axis] <= hi]:
            ends[i] = (0.0, solved[i])  # the run meets the bounds
        current = [i for i in current if lo <= i[axis] + direction[axis] <= hi]
        while current:
            if len(solved) + len(current) > MAX_POINTS or self._late():
                self.truncated = True
                for i in current:
                    ends[i] = (0.0, solved[i])
                break
            nxt = [tuple(np.add(i, direction)) for i in current]
            Qc = np.array([solved[i] for i in current])
            Pc = np.array([self.position(i) for i in current])
            Pn = np.array([self.position(i) for i in nxt])
            steps = self.substeps(np.array([self.sigma.get(i, 0.0) for i in current]))
            Qn, ok, sig = self.advance_all(Qc, Pc, Pn, np.where(steps > 0, steps, _SUBSTEPS), retry=False)
            failed = [k for k in range(len(current)) if not ok[k]]
            if failed:
                starts = np.array([current[k] for k in failed])
                frac, Qb = self.extend(starts, Qc[failed], direction)
                for k, f, qb in zip(failed, frac, Qb):
                    ends[current[k]] = (float(f), qb)
            following = []
            for k in np.flatnonzero(ok):
                n = nxt[k]
                if n in solved:  # met another run: they join
                    continue
                solved[n] = Qn[k]
                self.sigma[n] = float(sig[k])
                if lo <= n[axis] + direction[axis] <= hi:
                    if tuple(np.add(n, direction)) not in solved:
                        following.append(n)
                else:
                    ends[n] = (0.0, Qn[k])
            current = following
        return ends

    def extend(self, starts, Q, direction):
        """Bisection from the reached points ``starts`` (m, d) (configurations Q) towards their
        unreached neighbours along ``direction`` (a unit index vector): the reached fraction of
        the step (0..1) and the configurations there."""
        lo = np.zeros(len(starts))
        hi = np.ones(len(starts))
        Qlo = Q.copy()
        P0 = np.array([self.position(s) for s in starts])
        step = (np.asarray(direction, float) * self.h) @ self.axes
        for _ in range(_BISECTIONS):
            mid = 0.5 * (lo + hi)
            P_from = P0 + lo[:, None] * step
            P_to = P0 + mid[:, None] * step
            Q0, Kp = self.predict(Qlo, P_from, P_to)
            Qn, ok = self.solve(Q0, P_to)
            ok &= self.kept(Qlo, Kp, Q0, Qn, P_to)[0]
            lo = np.where(ok, mid, lo)
            hi = np.where(ok, hi, mid)
            Qlo[ok] = Qn[ok]
        return lo, Qlo


# --------------------------------------------------------------------------------------- main
def workspace(mech, output: str, point: bool = False, orientation=None, resolution: float | None = None,
              bounds=None, threshold: float = DEFAULT_THRESHOLD, length: float | None = None,
              method: str | None = None, samples: int = 200_000, seed: int = 0, inputs=None,
              timeout: float | None = None) -> WorkspaceResult:
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
    return _grid(mech, output, point, orientation, measures, resolution, bounds, threshold, L, inputs, deadline)


def _seed(mech, output, point, orientation):
    """The assembled configuration the grid starts from, the output's position and the grid's
    orientation there (continued from the file's orientation to the one asked)."""
    assembly, generic = mech.generic_configurations()
    fid = mech.link_frame(output)
    bc = BatchClosure(mech, target=(output, "point" if point else "pose"), check=0)
    # the file's assembled configuration may be singular for the output (an arm drawn stretched,
    # a wrist with aligned axes): then the nearest generic one, where the rows' rank is largest
    best = None
    for q in [assembly.q] + list(generic):
        pin.framesForwardKinematics(mech.model, mech.data, q)
        M = mech.data.oMf[fid]
        K = bc.evaluate(q[None], (M.translation[None], M.rotation))[1][0]
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


def _index_bounds(bounds, p_seed, axes, h, dim):
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


def _grid(mech, output, point, orientation, measures, resolution, bounds, threshold, L, inputs,
          deadline=None) -> WorkspaceResult:
    try:
        BatchClosure(mech, target=(output, "point" if point else "pose"))  # raises Unbatchable
    except Unbatchable as e:
        raise UsageError(f"{e}: the workspace's batched solver does not take these yet") from None
    q_seed, p_seed, R = _seed(mech, output, point, orientation)
    directions = _translations(mech, q_seed, output, point)
    dim = directions.shape[1]
    if dim < 2 and not point and orientation is None and _translations(mech, q_seed, output, True).shape[1] >= 2:
        # the link cannot keep its orientation and move over an area (a five-bar's distal link):
        # what is asked is then where its origin goes
        res = _grid(mech, output, True, None, _Measures(mech, output, True, inputs, L), resolution, bounds,
                    threshold, L, inputs, deadline)
        note = (f"'{output}' moves over no area at a constant orientation: the workspace of its origin with "
                "any orientation (as --point)")
        return dataclasses.replace(res, notes=(note,) + tuple(res.notes))
    if dim < 2:
        what = "its origin" if point else f"'{output}' at a constant orientation"
        raise UsageError(f"{mech.path}: {what} moves along {'a curve' if dim == 1 else 'no direction'} "
                         f"({dim} translation{'s' if dim != 1 else ''}), not over an area or a volume: "
                         "use sweep" + ("" if point else ", or --point"))
    axes = _grid_axes(directions)
    notes = []
    h0 = L / 4.0
    if resolution is None or resolution < h0:  # a coarse pass: the extent, or the work a fine grid would be
        lo, hi = _index_bounds(bounds, p_seed, axes, h0, dim)
        coarse = _Grid(mech, output, point, R, q_seed, p_seed, axes, h0, lo, hi)
        coarse.deadline = deadline
        idx = np.array(list(coarse.fill()), int)
        if resolution is None:  # ~24 (3-D) or ~120 (2-D) steps across the extent
            extent = (idx.max(axis=0) - idx.min(axis=0) + 2) * h0
            resolution = float(extent.max()) / (24.0 if dim == 3 else 120.0)
            notes.append(f"resolution {resolution:.4g} m chosen from a first pass at {h0:.4g} m")
        else:
            estimate = len(idx) * (h0 / resolution) ** dim
            if estimate > MAX_ESTIMATE:
                least = h0 * (len(idx) / MAX_ESTIMATE) ** (1.0 / dim)
                least = float(f"{least * 1.05:.2g}")
                raise UsageError(f"--resolution {resolution:.4g} m would solve about {estimate:.2g} grid points "
                                 f"(a first pass at {h0:.3g} m reached {len(idx)}), limit {MAX_ESTIMATE:,}: use "
                                 f"--resolution {least:g} or more, or --bounds")
    lo, hi = _index_bounds(bounds, p_seed, axes, resolution, dim)
    grid = _Grid(mech, output, point, R, q_seed, p_seed, axes, resolution, lo, hi)
    grid.deadline = deadline
    solved = grid.fill()
    # runs along the last axis, completed and extended to the boundary by bisection
    h = resolution
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
    ends = {}  # (point k, +1 | -1) -> (fraction, configuration)
    boundary = []
    for sign, found in run_ends.items():
        for i, (f, qb) in found.items():
            k = key[i]
            ends[(k, sign)] = (f, qb)
            if f > 0 or lo[-1] <= i[-1] + sign <= hi[-1]:
                boundary.append(grid.position(index[k]) + sign * f * h * axes[-1])
    m = measures(Q)
    free = (m["actuator"] >= threshold) & (m["serial"] >= threshold)
    # measures at the located ends, for the free runs
    end_keys = list(ends)
    end_measures = measures(np.array([ends[e][1] for e in end_keys])) if end_keys else None
    end_min = {e: min(end_measures["actuator"][n], end_measures["serial"][n]) for n, e in enumerate(end_keys)}
    volume_len = 0.0
    free_len = 0.0
    free_boundary = []
    worst = np.minimum(m["actuator"], m["serial"])
    columns = {}
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


def _free_part(m0, m1, length, threshold, p0, direction, crossings) -> float:
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
def _sampling(mech, output, measures, resolution, bounds, threshold, L, samples, seed, inputs) -> WorkspaceResult:
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
    axes = _grid_axes(directions)
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
