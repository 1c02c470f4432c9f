"""Batched continuation: a sweep's grid values corrected a chunk at a time (issue 26 item 2).

For mechanisms the closed form (dyads.py) does not cover -- spatial loops, triads -- but whose
closure BatchClosure represents (1-DOF revolute and prismatic joints), the grid values of the
input are taken a chunk at a time:

- predict every value of the chunk from the last configuration reached, along its tangent
  (sweep's predictor, the input held at each grid value);
- correct them all at once with BatchClosure.solve (the one damped-Newton step of
  model/newton.py, each configuration its own damping);
- check each is on the branch, as sweep's tracker does: it converged, the correction is small
  next to the predicted step (at most half of it), and no limit position lies between it and
  the previous one (the tangent's input component keeps its sign: the unoriented tangents
  P e, P the projector onto the null space of the scaled constraint Jacobian, of neighbours
  have a positive dot product).

The configurations before the first that fails are kept; the chunk is halved and tried again
from there; a chunk of the smallest size that still fails is handed to the per-step tracker
(``fallback``: sweep itself, which locates limit positions), and that is said in the notes.
"""

from __future__ import annotations

import numpy as np

from .batch_closure import BatchClosure, Unbatchable

__all__ = ["batch_closure", "batched_motion", "motion_rates", "SMALLEST", "LARGEST"]

SMALLEST, LARGEST = 4, 256  # grid values a chunk: it starts at 16 and doubles while it goes well
_JUMP_FLOOR = 1e-7  # the smallest correction always accepted (scaled), as sweep._Tracker.step's [-]


def batch_closure(mech):
    """The mechanism's BatchClosure (cached), or None when it cannot be batched."""
    key = "dyads.batch"  # (the one dyads.py checks its residuals with)
    if key not in mech.cache:
        try:
            mech.cache[key] = BatchClosure(mech, check=0)
        except Unbatchable:
            mech.cache[key] = None
    return mech.cache[key]


def _tangents(bc, tr, Q):
    """Unoriented tangents P e (N, nv) at the configurations Q: the input's direction projected
    onto the null space of the scaled constraint Jacobian (sweep._Tracker.tangent, batched)."""
    K = bc.constraint_jacobians(Q)
    N, nv = len(Q), tr.mech.nv
    free = tr.free
    e_col = int(np.searchsorted(free, tr.ix))
    out = np.zeros((N, nv))
    if K.shape[1] == 0:
        out[:, tr.ix] = 1.0
        return out
    Ks = (K * tr.scale)[:, :, free]
    _, s, vt = np.linalg.svd(Ks, full_matrices=True)
    sp = np.zeros((N, len(free)))
    sp[:, :s.shape[1]] = s
    tol = tr.tol
    ranked = sp > np.maximum(tol.rank_rtol * sp[:, :1], tol.rank_atol)
    ranked &= (sp[:, :1] > tol.rank_atol)  # a zero matrix: everything is null space
    coef = vt[:, :, e_col] * ~ranked
    out[:, free] = np.einsum("nk,nkj->nj", coef, vt)
    return out


def batched_motion(solver, tr, q0, t0, start, stop, steps, fallback, progress=None):
    """The grid values from start to stop (steps steps) on q0's branch, batched (see the module
    docstring).  tr: sweep's _Tracker; t0: its oriented tangent at q0 (the input's component
    along the motion); fallback(q, x_from, x_to, n): the tracker's SweepResult of n steps;
    progress(done, total): called as grid values are reached (None: not).
    Returns (X, Q, limits, stopped, reason, skipped, notes) or None when the mechanism cannot
    be batched."""
    mech = solver.mech
    bc = batch_closure(mech)
    if bc is None or mech.model.nq != mech.model.nv or bc.target is not None:
        return None
    h = (stop - start) / steps
    frozen = tuple(sorted(set(tr.frozen_other) | {tr.ix}))
    X, Q = [float(start)], [np.array(q0, float)]
    limits, skipped, notes = [], [], []
    stopped = reason = None
    q, x, t = Q[0], float(start), np.array(t0, float)
    u = _tangents(bc, tr, q[None])[0]  # unoriented, for the branch test
    k, size = 0, 16
    while k < steps:
        if progress is not None:
            progress(k, steps)
        m = min(size, steps - k)
        js = np.arange(k + 1, k + m + 1)
        xs = start + js * h
        if js[-1] == steps and (xs[-1] - stop) * np.sign(h) > 0:
            xs[-1] = stop
        sig = (xs - x) / tr.scale[tr.ix] / t[tr.ix]  # predicted steps along the tangent (scaled)
        pred = q[None] + (tr.scale * t)[None] * sig[:, None]  # (nq == nv: integrate is a sum)
        Qc, ok, _, _ = bc.solve(pred, frozen=frozen)
        ok &= np.all(np.isfinite(Qc), axis=1)
        Qc[~ok] = pred[~ok]  # (refused below; finite for the tangents)
        jump = np.linalg.norm((Qc - pred) / tr.scale, axis=1)
        ok &= jump <= np.maximum(0.5 * np.abs(sig), _JUMP_FLOOR)
        U = _tangents(bc, tr, Qc)
        prev = np.vstack([u[None], U[:-1]])
        ok &= np.einsum("ij,ij->i", U, prev) > 0
        bad = np.flatnonzero(~ok)
        n_ok = int(bad[0]) if len(bad) else m
        if n_ok:
            X += [float(v) for v in xs[:n_ok]]
            Q += list(Qc[:n_ok])
            # the oriented tangent at the last kept configuration
            w = U[n_ok - 1]
            nw = np.linalg.norm(w)
            t_new = w / nw if nw > 0 else t
            if t_new @ t < 0:
                t_new = -t_new
            q, x, t, u, k = Qc[n_ok - 1], float(xs[n_ok - 1]), t_new, U[n_ok - 1], k + n_ok
        if n_ok == m:
            size = min(2 * size, LARGEST)
            continue
        if n_ok == 0 and m <= SMALLEST:  # the smallest chunk fails at once: the tracker takes it
            res = fallback(q, x, float(xs[-1]), m)
            notes.append(f"the batched corrector failed at {tr.name} = {x:.9g} (a limit position or a sharp bend "
                         f"near): the per-step tracker took {m} step{'s' if m > 1 else ''} from there")
            X += [float(v) for v in res.values[1:]]
            Q += [np.array(v, float) for v in res.q[1:]]
            limits += list(res.limits)
            skipped += list(res.skipped)
            if res.stopped_at is not None:
                stopped, reason = res.stopped_at, res.stop_reason
                break
            q, x = Q[-1], X[-1]
            u = _tangents(bc, tr, q[None])[0]
            nu = np.linalg.norm(u)
            if not nu > 0:
                stopped, reason = x, "the mechanism cannot move along this input here"
                break
            t = u / nu if u @ t >= 0 else -u / nu
            k += m
            size = 16
            continue
        size = max(SMALLEST, size // 2)
    return X, Q, limits, stopped, reason, skipped, notes


def motion_rates(solver, bc, Q, values: dict):
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
