"""The grid a workspace is grown on (analysis.design.workspace's ``grid`` method): positions of the
output on axes spanning its translations, filled outwards wave by wave from the assembled
configuration by batched inverse kinematics (model.kernel.stacks.BatchClosure), each point
from a neighbour's solution along a first-order predictor, kept only when it continues that
neighbour's branch (the one continuation's jump test and branch rule, analysis.motion.continuation:
the sign of the rows' Jacobian determinant on the parent's row space), with
substeps near folds and runs extended to the boundary by bisection.
"""

from __future__ import annotations

import time

import numpy as np

from ...model.linalg import rank
from ...model.kernel.newton import damped_steps
from ...model.kernel.scaling import dimensionless
from ...model.kernel.stacks import BatchClosure
from ..motion.continuation import jumped, keeps_orientation
from ...model.limits import within_limits
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["Grid", "grid_axes", "null_motions", "MAX_POINTS"]

MAX_POINTS = 2_000_000  # reached grid points (or sampling cells) before a workspace stops

_BLOCK = 4096  # configurations per batched solve
_BISECTIONS = 5  # boundary located to h / 32
_SUBSTEPS = 8  # at most this many substeps for a grid step near a fold (see Grid.substeps)
_FOLD = 0.2  # sigma ~ _FOLD sqrt(d / L) a distance d inside a fold (measured: 0.2-0.5 on the five-bar)
_SINGULAR = 1e-6  # relative singular value under which a point is not grown from
_ITERATIONS = 8  # Newton from a neighbour's solution and the predictor converges in 2 to 4; a point that
#                   takes more lies beyond the boundary (or across a singularity) from that neighbour


def null_motions(A: np.ndarray, mech: Mechanism) -> np.ndarray:
    if not A.size:
        return np.eye(A.shape[1])
    _, s, vt = np.linalg.svd(A)
    k = rank(A, mech.tolerances)
    return vt[k:].T


def grid_axes(directions: np.ndarray) -> np.ndarray:
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
class Grid:
    """Batched inverse kinematics on a grid (see the module's text)."""

    def __init__(self, mech: Mechanism, output: str, point: bool, orientation, q_seed: np.ndarray, p_seed: np.ndarray, axes: np.ndarray, h: float, lo: list, hi: list, frozen: tuple=()) -> None:
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
        K = self.closure.evaluate(q_seed[None], targets=(self.position(np.zeros(len(axes)))[None], self.R))[1][0]
        self.rank = rank(K, mech.tolerances)
        Ks = self._scaled(K[None])[0]
        sv = np.linalg.svd(Ks, compute_uv=False)
        self.sigma = {(0,) * len(axes): float(sv[self.rank - 1] / sv[0]) if self.rank and sv[0] > 0 else 1.0}
        self.solves = 0
        self.truncated = False

    def position(self, index) -> np.ndarray:
        return self.p_seed + (np.asarray(index, float) * self.h) @ self.axes

    def solve(self, Q0: np.ndarray, P: np.ndarray) -> tuple:
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

    def predict(self, Q: np.ndarray | list, P_from: np.ndarray | list, P_to: np.ndarray) -> tuple:
        """First-order predictor: the joint steps that move the target from P_from to P_to
        (minimum norm through the solver's rows: K dq = -(change of the target rows)), and
        the rows' Jacobian at Q (it does not depend on where the target is)."""
        r0, K = self.closure.evaluate(Q, targets=(P_to, self.R))
        r1 = self.closure.evaluate(Q, False, (P_from, self.R))[0]
        dr = r0 - r1  # the rows' change from moving the target alone
        return Q + damped_steps(K, dr, np.full(len(Q), self.mech.tolerances.lm_damping))[0], K

    def _scaled(self, K: np.ndarray) -> np.ndarray:
        """The rows' Jacobians made dimensionless: lengths / L, sliding columns * L (model.kernel.scaling)."""
        return dimensionless(K, self.closure.solver_position_rows, self.slide, self.L)

    def kept(self, Q_from: np.ndarray, K_from: np.ndarray, Q_pred: np.ndarray, Q_new: np.ndarray, P_new: np.ndarray) -> tuple:
        """(kept, sigma) for new solutions solved from Q_from: kept when it continues the old
        solution -- near the predicted configuration, and on the same branch: the rows'
        Jacobian (loops and target) restricted to the old one's range and row space keeps the
        sign of its determinant (a jump across a fold to another working mode flips it);
        sigma: the new Jacobian's r-th singular value relative to its largest (dimensionless),
        how far it is from a fold (``substeps``)."""
        step = np.linalg.norm(Q_pred - Q_from, axis=1)
        ok = ~jumped(np.linalg.norm(Q_new - Q_pred, axis=1), step, self.mech.tolerances)
        K_new = self._scaled(self.closure.evaluate(Q_new, targets=(P_new, self.R))[1])
        r = self.rank
        if not r:
            return ok, np.ones(len(ok))
        ok &= keeps_orientation(self._scaled(K_from), K_new, r)
        ev = np.sqrt(np.maximum(np.linalg.eigvalsh(K_new.transpose(0, 2, 1) @ K_new), 0.0))[:, ::-1]
        return ok, np.where(ev[:, 0] > 0, ev[:, r - 1] / np.where(ev[:, 0] > 0, ev[:, 0], 1.0), 0.0)

    def substeps(self, sigma: float | np.ndarray) -> np.ndarray:
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

    def advance(self, Q: np.ndarray, P_from: np.ndarray, P_to: np.ndarray, n) -> tuple:
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

    def advance_all(self, Q: np.ndarray, P_from: np.ndarray, P_to: np.ndarray, n: int | np.ndarray, retry: bool=True) -> tuple:
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

    def fill(self) -> dict:
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

    def march(self, solved: dict, direction: np.ndarray) -> dict:
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

    def extend(self, starts: int | np.ndarray, Q: np.ndarray, direction: np.ndarray) -> tuple:
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
