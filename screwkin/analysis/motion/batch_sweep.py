"""Batched continuation: a sweep's grid values corrected a chunk at a time (issue 26 item 2).

For mechanisms the closed form (dyads.py) does not cover -- spatial loops, triads -- but whose
closure BatchClosure represents (1-DOF revolute and prismatic joints), the grid values of the
input are taken a chunk at a time by ``BatchedCurve``, the batched engine of the one continuation
(analysis.motion.continuation: its tangent, jump test and branch rule, on stacks):

- predict every value of the chunk from the last configuration reached, along its tangent
  (the input held at each grid value);
- correct them all at once with BatchClosure.solve (the one damped-Newton step of
  model/kernel/newton.py, each configuration its own damping);
- accept each that is on the branch, as the per-step tracker does: it converged, the correction
  passes the jump test, and no limit position lies between it and the previous one (the input's
  share of the tangent, oriented along the chunk, keeps its sign).

The configurations before the first that fails are kept; the chunk is halved and tried again
from there; a chunk of the smallest size that still fails is handed to the per-step tracker
(``fallback``, which locates limit positions: BatchedCurve's ``locate_limit`` is the Curve's),
and that is said in the notes.
"""

from __future__ import annotations

import numpy as np

from ...model.kernel.stacks import BatchClosure, Unbatchable
from ...model.geometry import TINY
from .continuation import Curve, Motion, jumped, passes_limit, projections
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from collections.abc import Callable

__all__ = ["batch_closure", "BatchedCurve", "GridNeighbours", "batched_motion", "motion_rates", "SMALLEST", "LARGEST"]

SMALLEST, LARGEST = 4, 256  # grid values a chunk: it starts at 16 and doubles while it goes well


def batch_closure(mech: Mechanism) -> BatchClosure:
    """The mechanism's BatchClosure (cached), or None when it cannot be batched."""
    key = "dyads.batch"  # (the one dyads.py checks its residuals with)
    if key not in mech.cache:
        try:
            mech.cache[key] = BatchClosure(mech, check=0)
        except Unbatchable:
            mech.cache[key] = None
    return mech.cache[key]


class BatchedCurve(Curve):
    """The Curve's engine on stacks of configurations (one per row), its closure batched."""

    def __init__(self, solver, name: str, bc: BatchClosure) -> None:
        super().__init__(solver, name)
        self.bc = bc

    def tangents(self, Q: np.ndarray, previous: np.ndarray) -> np.ndarray:
        """Unit tangents at the configurations Q, each oriented like the row before it, the first
        like ``previous`` (``choose_branch``); a zero row where the input cannot move."""
        U = self.input_directions(self.bc.constraint_jacobians(Q))
        n = np.linalg.norm(U, axis=1)
        return self.choose_branch(U / np.where(n > TINY, n, 1.0)[:, None], previous)

    def predict(self, q: np.ndarray | list, t: np.ndarray | list, sigma: float) -> np.ndarray:
        return q[None] + (self.scale * t)[None] * sigma[:, None]  # (nq == nv: integrate is a sum)

    def correct(self, predicted: np.ndarray, held: int) -> tuple:
        Qc, ok, _, _ = self.bc.solve(predicted, frozen=self.frozen(held))
        ok &= np.all(np.isfinite(Qc), axis=1)
        Qc[~ok] = predicted[~ok]  # (refused by accept; finite for the tangents)
        return Qc, ok

    def accept(self, predicted: np.ndarray, corrected: np.ndarray, sigma: float, t: np.ndarray | None=None, T: np.ndarray | None=None):
        """Rows that pass the jump test and, given the tangent t before the stack and the stack's T,
        have no limit position between them and the row before."""
        ok = ~jumped(np.linalg.norm((corrected - predicted) / self.scale, axis=1), sigma, self.tol)
        if T is not None:
            ok &= ~passes_limit(np.vstack([t[None], T[:-1]]), T, self.ix)
        return ok


class GridNeighbours:
    """continuation.Neighbour along either of two inputs, for a stack: row k taken from input value
    x_from[k] to x_to[k] of input ``names[axis[k]]`` on the branch of configuration Q[k], by the same
    pieces (continuation_steps), tangent (Curve.along, Curve.tangent), corrector, jump test and limit test
    as Neighbour takes them one configuration at a time -- the same answers to round-off.  Both inputs'
    steps hold every input (the one moved at its new value), so the rows of both are corrected together
    (BatchClosure.solve: the one Newton loop, each row its own damping and its own end).  A map walks its
    grid with it a wavefront at a time (analysis.singularities.maps)."""

    def __init__(self, solver, names: tuple, bc: BatchClosure) -> None:
        self.curves = [BatchedCurve(solver, n, bc) for n in names]
        self.bc, self.mech, self.tol = bc, solver.mech, solver.mech.tolerances
        self.scale = self.curves[0].scale

    def directions(self, Q: np.ndarray) -> np.ndarray:
        """(N, 2, nv) each input's unnormalized tangent at Q (Curve.input_directions), and (N, rows, nv) K."""
        K = self.bc.constraint_jacobians(Q) if self.bc.nrows else np.zeros((len(Q), 0, self.mech.nv))
        return np.stack([c.input_directions(K) for c in self.curves], axis=1), K

    def __call__(self, Q: np.ndarray, axis: np.ndarray, x_from: np.ndarray, x_to: np.ndarray,
                 U: np.ndarray | None = None) -> tuple:
        """(configurations (N, nq), reached (N,) bool, their directions (N, 2, nv)): each row at input value
        x_to on its branch (rows not reached keep their start; their directions are NaN).  U: the
        directions at Q when known (``directions``)."""
        Q = np.array(np.atleast_2d(Q), float)
        N, tol, scale = len(Q), self.tol, self.scale
        axis = np.asarray(axis, int)
        x_from, x_to = np.asarray(x_from, float), np.asarray(x_to, float)
        ix = np.array([c.ix for c in self.curves])[axis]
        rows = np.arange(N)
        U = self.directions(Q)[0] if U is None else np.array(U, float)
        direction = np.sign(x_to - x_from)
        pieces = np.ceil(np.abs(x_to - x_from) / (tol.max_step * scale[ix])).astype(int)  # continuation_steps
        out, ok, U_out = Q.copy(), np.ones(N, bool), U.copy()
        t = U[rows, axis]
        n = np.linalg.norm(t, axis=1)
        good = (n >= TINY) | (direction == 0)  # Curve.along: the unit tangent, the input moving the way of x_to
        t = t / np.where(n >= TINY, n, 1.0)[:, None]
        t *= np.where(t[rows, ix] * np.where(direction == 0, 1.0, direction) < 0, -1.0, 1.0)[:, None]
        live = rows[(direction != 0) & good]
        ok[~good] = False
        q, x, t = Q[live], x_from[live], t[live]
        for k in range(1, int(pieces.max(initial=0)) + 1):
            keep = k <= pieces[live]
            live, q, x, t = live[keep], q[keep], x[keep], t[keep]
            if not len(live):
                break
            a, b, m, i, ax = x_from[live], x_to[live], pieces[live], ix[live], axis[live]
            x_next = np.where(k == m, b, a + (b - a) * k / m)
            share = t[np.arange(len(live)), i]
            moves = np.abs(share) >= tol.zero  # Curve.at_input: the input moves here
            sigma = (x_next - x) / scale[i] / np.where(moves, share, 1.0)
            pred = q + scale * t * sigma[:, None]  # (nq == nv: integrate is a sum)
            Qc, good = self.curves[0].correct(pred, self.curves[0].ix)  # (every input held: either curve's)
            good &= moves & ~jumped(np.linalg.norm((Qc - pred) / scale, axis=1), sigma, tol)
            Un, K = self.directions(Qc)
            T = Un[np.arange(len(live)), ax]
            nt = np.linalg.norm(T, axis=1)
            low = nt < tol.limit_share  # Curve.tangent at a limit position itself: the previous one projected
            for c in (0, 1):
                sel = low & (ax == c)
                if sel.any():
                    cv = self.curves[c]
                    T[sel] = projections(K[sel], t[sel], scale, cv.free, tol)
                    nt[sel] = np.linalg.norm(T[sel], axis=1)
            good &= nt >= TINY
            T = T / np.where(nt >= TINY, nt, 1.0)[:, None]
            T *= np.where(np.einsum("ij,ij->i", T, t) < 0, -1.0, 1.0)[:, None]  # orient
            r = np.arange(len(live))
            good &= ~passes_limit(t[r, i][:, None], T[r, i][:, None], 0)
            ok[live[~good]] = False
            out[live[good]], U_out[live[good]] = Qc[good], Un[good]
            live, q, x, t = live[good], Qc[good], x_next[good], T[good]
        out[~ok] = Q[~ok]
        U_out[~ok] = np.nan
        return out, ok, U_out


def batched_motion(solver, curve: Curve, q0: np.ndarray, t0: np.ndarray, start: float, stop: float, steps: int, fallback: Callable, progress=None):
    """The grid values from start to stop (steps steps) on q0's branch, batched (see the module
    docstring).  curve: the sweep's Curve; t0: its oriented tangent at q0 (the input's component
    along the motion); fallback(q, x_from, x_to, n): the tracker's Motion of n steps;
    progress(done, total): called as grid values are reached (None: not).
    Returns a Motion, or None when the mechanism cannot be batched."""
    mech = solver.mech
    bc = batch_closure(mech)
    if bc is None or mech.model.nq != mech.model.nv or bc.target is not None:
        return None
    c = BatchedCurve(solver, curve.name, bc)
    h = (stop - start) / steps
    m = Motion([float(start)], [np.array(q0, float)])
    q, x, t = m.Q[0], float(start), np.array(t0, float)
    k, size = 0, 16
    while k < steps:
        if progress is not None:
            progress(k, steps)
        n = min(size, steps - k)
        js = np.arange(k + 1, k + n + 1)
        xs = start + js * h
        if js[-1] == steps and (xs[-1] - stop) * np.sign(h) > 0:
            xs[-1] = stop
        sig = (xs - x) / c.scale[c.ix] / t[c.ix]  # predicted steps along the tangent (scaled)
        pred = c.predict(q, t, sig)
        Qc, ok = c.correct(pred, c.ix)
        T = c.tangents(Qc, t)
        ok &= c.accept(pred, Qc, sig, t, T)
        bad = np.flatnonzero(~ok)
        n_ok = int(bad[0]) if len(bad) else n
        if n_ok:
            m.X += [float(v) for v in xs[:n_ok]]
            m.Q += list(Qc[:n_ok])
            q, x, t, k = Qc[n_ok - 1], float(xs[n_ok - 1]), T[n_ok - 1], k + n_ok
        if n_ok == n:
            size = min(2 * size, LARGEST)
            continue
        if n_ok == 0 and n <= SMALLEST:  # the smallest chunk fails at once: the tracker takes it
            res = fallback(q, x, float(xs[-1]), n)
            m.notes.append(f"the batched corrector failed at {c.name} = {x:.9g} (a limit position or a sharp bend "
                           f"near): the per-step tracker took {n} step{'s' if n > 1 else ''} from there")
            m.X += [float(v) for v in res.X[1:]]
            m.Q += [np.array(v, float) for v in res.Q[1:]]
            m.limits += list(res.limits)
            m.skipped += list(res.skipped)
            if res.stopped is not None:
                m.stopped, m.reason = res.stopped, res.reason
                break
            q, x = m.Q[-1], m.X[-1]
            t_new = c.tangents(q[None], t)[0]
            if not np.linalg.norm(t_new) > 0:
                m.stopped, m.reason = x, "the mechanism cannot move along this input here"
                break
            t, k, size = t_new, k + n, 16
            continue
        size = max(SMALLEST, size // 2)
    return m


def motion_rates(solver, bc: BatchClosure, Q: np.ndarray | list, values: dict) -> tuple:
    """Joint rates and accelerations (N, nv) at the closed configurations Q for the input rates
    ``values`` (input accelerations zero): PositionSolver.rates and .accelerations of every row,
    the constraint Jacobians, the bias K'(q, q') q' and the minimum-norm passive solves batched
    (BatchClosure's rows, the same as ClosureSystem.jacobian's and .bias's)."""
    mech = solver.mech
    Q = np.atleast_2d(np.asarray(Q, float))
    N, nv = len(Q), mech.nv
    fr, pa = np.asarray(solver.frozen, int), np.asarray(solver.passive, int)
    V, A = np.zeros((N, nv)), np.zeros((N, nv))
    V[:, fr] = solver._input_vector(values)
    K = bc.constraint_jacobians(Q) if N else np.zeros((0, 0, nv))
    if not N or K.shape[1] == 0 or not len(pa):
        return V, A
    Kp = K[:, :, pa]
    U, s, Vt = np.linalg.svd(Kp, full_matrices=False)
    cut = np.finfo(float).eps * max(Kp.shape[1:]) * s[:, :1]
    keep = (s > cut) & (s[:, :1] > 0)
    inv = np.where(keep, 1.0 / np.where(keep, s, 1.0), 0.0)

    def solve(B):  # minimum-norm least squares of Kp x = B, row by row (PositionSolver.passive_solver)
        return np.einsum("nkp,nk->np", Vt, inv * np.einsum("nmk,nm->nk", U, B))

    V[:, pa] = -solve(np.einsum("nmf,nf->nm", K[:, :, fr], V[:, fr]))
    bias = bc.bias(Q, V)
    A[:, pa] = solve(-bias)
    return V, A
