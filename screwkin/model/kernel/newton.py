"""The one damped-Newton (Levenberg-Marquardt) loop of every closure solver, and its step.

``iterate`` is the loop, written once for a stack of N configurations; the single solve
(``solve``: model.kernel.closure.ClosureSystem.solve) runs it on a stack of one, the batched one
(model.kernel.stacks.BatchClosure.solve) on many, the compiled path (model.kernel.compiled) with
the rows, the step and the verdict compiled by numba from the same definitions.  Whoever wants to
change how Newton iterates changes it here:

- the step is the minimum-norm damped step on the free columns of K,
  ``dq_f = -K_f^T (K_f K_f^T + lambda I)^-1 r`` with ``lambda = mu * trace / rows``
  (with more rows than free columns the same step is
  ``(K_f^T K_f + lambda I)^-1 K_f^T (-r)``, a smaller system); where the damped system is singular
  in floating point, its least-squares solution;
- the configuration moves by the step on the configuration manifold (pin.integrate, for stacks
  model.manifold.Integrator), and the step is accepted when the residual norm goes down;
- the damping ``mu`` starts at ``Tolerances.lm_damping``; an accepted step
  updates it from the gain ratio rho (actual over predicted decrease of the
  squared residual) by Nielsen's rule, never below ``Tolerances.lm_damping_min``;
  a refused one multiplies it by nu (2, 4, 8, ...) (``judge``);
- a configuration stops when its residual norm is below ``Tolerances.closure`` (converged), at
  ``Tolerances.max_iterations``, or when a refused step takes its damping past
  ``Tolerances.lm_damping_max`` (given up).

``polish`` is the undamped step at the end: from a configuration near a root (a damped solve's, a
homotopy's real endpoint), Newton's own step until the residual stops falling -- round-off for a
simple root, where damped steps stop at the closure tolerance.

The residual rows may be evaluated one configuration at a time (Pinocchio),
for a stack (numpy) or compiled (numba); tests compare the three, the program
does not at run time.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ...errors import AssemblyError
from ...tolerances import Tolerances
from ..cuts import Assembly
from .contract import ClosureKernel

Array = NDArray[Any]

__all__ = ["TRACE_FLOOR", "NU", "damped_step", "damped_steps", "stacked_steps", "one_at_a_time", "one_step", "judge",
           "Iterates", "iterate", "solve", "undamped", "polish"]

#: Division guard: the damping is relative to the mean squared row norm, which is never taken
#: below this (a zero Jacobian) [same units as K^2].
TRACE_FLOOR = 1e-12

#: Nielsen's factor on the damping after a refused step starts at this and doubles.
NU = 2.0


def damped_step(K: np.ndarray, r: np.ndarray, free: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, float]:
    """The damped step of one configuration on the free columns of K (rows, nv): the step on
    those columns and the squared residual of the linear model |r + K_f dq_f|^2."""
    Kf = K[:, free]
    rows, cols = Kf.shape
    tall = rows > cols
    A = Kf.T @ Kf if tall else Kf @ Kf.T
    diagonal = A.ravel()[:: len(A) + 1]  # a view
    diagonal += mu * max(diagonal.sum() / rows, TRACE_FLOOR)
    b = Kf.T @ r if tall else r
    try:
        y = np.linalg.solve(A, b)
    except np.linalg.LinAlgError:  # singular in floating point
        y = np.linalg.lstsq(A, b, rcond=None)[0]
    dqf = -y if tall else -(Kf.T @ y)
    lin = r + Kf @ dqf
    return dqf, float(lin @ lin)


def damped_steps(Kf: np.ndarray, r: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """damped_step for a stack, on columns already chosen: Kf (N, m, n), r (N, m), mu (N,) ->
    (steps (N, n), squared residuals of the linear model (N,))."""
    N, m, n = Kf.shape
    tall = m > n
    Kt = Kf.transpose(0, 2, 1)
    A = Kt @ Kf if tall else Kf @ Kt
    size = A.shape[1]
    trace = np.trace(A, axis1=1, axis2=2)
    A[:, np.arange(size), np.arange(size)] += (mu * np.maximum(trace / m, TRACE_FLOOR))[:, None]
    b = (Kt @ r[:, :, None])[:, :, 0] if tall else r
    try:
        y = np.linalg.solve(A, b[:, :, None])[:, :, 0]
    except np.linalg.LinAlgError:  # one of them singular in floating point: least squares for all
        y = np.stack([np.linalg.lstsq(Ai, bi, rcond=None)[0] for Ai, bi in zip(A, b)])
    dq = -y if tall else -(Kt @ y[:, :, None])[:, :, 0]
    lin = r + (Kf @ dq[:, :, None])[:, :, 0]
    return dq, np.einsum("ni,ni->n", lin, lin)


def stacked_steps(K: np.ndarray, r: np.ndarray, free: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """damped_steps on the free columns of a stack: K (N, rows, nv), r (N, rows), mu (N,) ->
    (steps on the free columns (N, free), squared residuals of the linear model (N,)): the step
    of ``iterate`` for stacks."""
    return damped_steps(K[:, :, free], r, mu)


def one_at_a_time(step: Callable[..., tuple[np.ndarray, Any]]) -> Callable[..., tuple[np.ndarray, Any]]:
    """The step of ``iterate`` for stacks from a step of one configuration,
    ``step(K (rows, nv), r, free, mu) -> (step on the free columns, squared linear residual)``
    (damped_step, or model.kernel.compiled.damped_step): one call per configuration."""

    def steps(K: np.ndarray, r: np.ndarray, free: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, Any]:
        if len(K) == 1:  # (the squared residual as a float: it broadcasts)
            dq, lin = step(K[0], r[0], free, float(mu[0]))
            return dq[None], lin
        out = [step(Ki, ri, free, float(mi)) for Ki, ri, mi in zip(K, r, mu)]
        return np.array([dq for dq, _ in out]).reshape(len(K), len(free)), np.array([lin for _, lin in out])

    return steps


#: damped_step as the step of ``iterate`` (the single solve's).
one_step = one_at_a_time(damped_step)


def judge(norm: np.ndarray, r_new: np.ndarray, linear_squared: np.ndarray, mu: np.ndarray, nu: np.ndarray,
          closure: float, mu_min: float, mu_max: float) -> tuple:
    """The verdict on one step of each configuration of a stack: residual norms before (n,), the
    residual rows after (n, rows), squared residual of the linear model, damping and Nielsen's
    factor nu (n,); Tolerances.closure, lm_damping_min, lm_damping_max.

    A step is accepted when it lowers the residual norm.  The damping after an accepted step
    follows Nielsen's rule from the gain ratio rho (actual over predicted decrease of the squared
    residual; 0 where the linear model predicts no decrease): mu max(1/3, 1 - (2 rho - 1)^3), never
    below mu_min, and nu = 2; after a refused one, mu nu and 2 nu.  A configuration goes on while
    its residual norm is at least ``closure`` and no refused step has taken its damping past
    mu_max.  Returns (accepted, residual norms after, mu, nu, going on).  Plain numpy on arrays:
    model.kernel.compiled compiles this same function."""
    new_norm = np.sqrt((r_new * r_new).sum(axis=1))
    accepted = new_norm < norm
    count = np.count_nonzero(accepted)
    if count == 0:  # (every step refused: the same as below, in fewer operations)
        mu = mu * nu
        return accepted, new_norm, mu, 2.0 * nu, (norm >= closure) & (mu <= mu_max)
    squared = norm * norm
    predicted = squared - linear_squared
    decrease = predicted > 0.0
    if np.count_nonzero(decrease) == len(decrease):  # (the model predicts a decrease: as below, in fewer operations)
        rho = (squared - new_norm * new_norm) / predicted
    else:
        rho = np.where(decrease, squared - new_norm * new_norm, 0.0) / np.where(decrease, predicted, 1.0)
    nielsen = np.maximum(mu * np.maximum(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), mu_min)
    if count == len(accepted):  # (every step accepted: the same, in fewer operations)
        return accepted, new_norm, nielsen, np.full(len(accepted), NU), new_norm >= closure
    mu = np.where(accepted, nielsen, mu * nu)
    nu = np.where(accepted, NU, 2.0 * nu)
    going_on = (np.where(accepted, new_norm, norm) >= closure) & (accepted | (mu <= mu_max))
    return accepted, new_norm, mu, nu, going_on


class Iterates(NamedTuple):
    """Where ``iterate`` left each configuration of a stack."""

    q: np.ndarray  #: (N, nq) the last accepted configurations
    residual: np.ndarray  #: (N,) their residual norms [the rows' units]
    iterations: np.ndarray  #: (N,) steps tried (accepted or refused)
    converged: np.ndarray  #: (N,) residual below Tolerances.closure
    placed: np.ndarray  #: (N,) the last configuration evaluated is q (no step tried, or the last accepted)


def iterate(evaluate: Callable[..., tuple[np.ndarray, Any]], Q0: np.ndarray, free: np.ndarray,
            tol: Tolerances, integrate: Callable[[np.ndarray, np.ndarray], np.ndarray],
            step: Callable[..., tuple[np.ndarray, Any]] = stacked_steps, iterations: int | None = None,
            trace: Callable[..., None] | None = None, verdict: Callable[..., tuple] = judge) -> Iterates:
    """The damped-Newton loop, for a stack of N configurations (N = 1: one configuration).

    evaluate(Q (n, nq), which (n,), jacobian) -> (r (n, rows), K (n, rows, nv) or None): the rows
    at the configurations ``which`` of the stack (indices into Q0: what varies per configuration,
    a target, is looked up with them); integrate(Q, dQ) -> Q (+) dQ on the configuration manifold
    (model.manifold.Integrator); step(K, r, free, mu): the damped step on the free velocity
    columns (``stacked_steps``, or ``one_at_a_time`` of a one-configuration step); iterations:
    the limit (Tolerances.max_iterations when None); trace: None or callable(which, k, Q, r, K, dQ,
    accepted) called after the k-th step with the configurations it started from (the loop's own
    arrays: a trace copies what it keeps); verdict: ``judge`` (or its compiled form).

    Q0 may be complex (the homotopy's Newton, model.homotopy.tracking.newton: its step undamped and its
    verdict accepting every finite step): the stack and its steps stay complex, the norms are moduli.

    Each configuration has its own damping and its own end (see the module).  When every
    configuration still iterating is about to converge quadratically (residual below
    0.1 sqrt(closure): the next one near its square) the residual alone is computed first, and the
    residual and Jacobian again, for the active stack, only when some step there is accepted without
    converging."""
    Q = np.array(Q0, complex if np.iscomplexobj(Q0) else float)  # complex: the homotopy's (model.homotopy)
    N = len(Q)
    every = np.arange(N)
    r, K = evaluate(Q, every, True)
    norm = _norms(r)
    mu, nu = np.empty(N), np.empty(N)
    mu.fill(tol.lm_damping)
    nu.fill(NU)
    its, refused = np.zeros(N, int), np.zeros(N, bool)  # the iteration each one stopped at, its last step refused
    closure, near, nv = tol.closure, 0.1 * math.sqrt(tol.closure), K.shape[2]
    bounds = (closure, tol.lm_damping_min, tol.lm_damping_max)
    active = norm >= closure  # a configuration stops once and for all: the active ones are at iteration k
    n = np.count_nonzero(active)
    limit, k = int(tol.max_iterations if iterations is None else iterations), 0
    while n and k < limit:
        k += 1
        whole = n == N  # (then the same operations on the arrays themselves: no copies)
        if whole:
            idx, Qa, ra, Ka, na, mua, nua = every, Q, r, K, norm, mu, nu
        else:
            idx = active.nonzero()[0]
            Qa, ra, Ka, na, mua, nua = Q[idx], r[idx], K[idx], norm[idx], mu[idx], nu[idx]
        dQ = np.zeros((n, nv), Q.dtype)
        dQ[:, free], lin2 = step(Ka, ra, free, mua)
        Qn = integrate(Qa, dQ)
        final = np.maximum.reduce(na) < near
        rn, Kn = evaluate(Qn, idx, not final)
        ok, nn, mua, nua, going = verdict(na, rn, lin2, mua, nua, *bounds)
        if final and np.count_nonzero(going & ok):  # accepted, not converged: its Jacobian after all
            rn, Kn = evaluate(Qn, idx, True)
        if trace is not None:
            trace(idx, k, Qa, ra, Ka, dQ, ok)
        accepted = np.count_nonzero(ok)
        if whole:  # (new arrays, nothing written into: a trace may hold the old ones)
            mu, nu, active, refused = mua, nua, going, ~ok
            if accepted == n:
                Q, r, norm = Qn, rn, nn
                K = K if Kn is None else Kn  # (without it: every one converged)
            elif accepted:
                Q, r, norm = np.where(ok[:, None], Qn, Q), np.where(ok[:, None], rn, r), np.where(ok, nn, norm)
                if Kn is not None:
                    K = np.where(ok[:, None, None], Kn, K)
        else:
            a = idx[ok]
            Q[a], r[a], norm[a] = Qn[ok], rn[ok], nn[ok]
            if Kn is not None:
                K[a] = Kn[ok]
            mu[idx], nu[idx], refused[idx], active[idx] = mua, nua, ~ok, going
        stopped = n - np.count_nonzero(going)
        n -= stopped
        if stopped:
            its[idx[~going]] = k
    its[active] = k
    return Iterates(Q, norm, its, norm < closure, ~refused)


def _norms(r: np.ndarray) -> np.ndarray:
    """The residual norm of each row of a stack (real or complex)."""
    if np.iscomplexobj(r):
        return np.sqrt(np.add.reduce(r.real * r.real + r.imag * r.imag, axis=1))
    return np.sqrt(np.add.reduce(r * r, axis=1))


def solve(kernel: ClosureKernel, q0: Array, frozen: Any, tol: Tolerances,
          trace: Callable[..., None] | None = None) -> Assembly:
    """``iterate`` on one configuration of a kernel (a ClosureSystem's: ``ClosureSystem.kernel``) from
    q0 (nq,) with the velocity indices ``frozen`` held (Tolerances ``tol``: closure, max_iterations and
    the lm_ fields); trace: None or callable(iteration, q, r, K, dq, accepted) (ClosureSystem.solve).
    Raises AssemblyError with the residual reached when it does not converge, or when the solution
    assembles a cut joint upside down (``kernel.reversed_joints``)."""
    q = np.array(q0, float)
    if kernel.m == 0:
        return Assembly(q, 0.0, 0)
    step, verdict = kernel.newton_parts() or (stacked_steps, judge)
    evaluate = kernel.evaluate
    hook = None if trace is None else (
        lambda which, k, Q, r, K, dQ, ok: trace(k, Q[0], r[0], K[0], dQ[0], bool(ok[0])))
    out = iterate(lambda Q, which, jacobian: evaluate(Q, jacobian), q[None], kernel.free_columns(frozen), tol,
                  kernel.integrate, step, trace=hook, verdict=verdict)
    q, norm, it = out.q[0], float(out.residual[0]), int(out.iterations[0])
    if not out.converged[0]:
        raise AssemblyError(kernel.name, norm, it)
    bad = kernel.reversed_joints(q, placed=bool(out.placed[0]))
    if bad:
        raise AssemblyError(kernel.name, norm, it,
                            detail=f"the solution found assembles {', '.join(bad)} with a reversed axis")
    return Assembly(q, norm, it)


def undamped(kernel: ClosureKernel, q0: Array, free: Array, iterations: int, closure: float | None = None) -> Assembly:
    """Newton's own step (undamped, the minimum-norm least-squares step on the free columns (k,): the
    rows may be redundant) from q0 (nq,) on ``kernel``'s rows, at most ``iterations`` steps.  Without
    ``closure``: while the residual keeps falling (the polish: a simple root to round-off in two or
    three steps; the configuration with the smallest residual seen is kept); with it: until the
    residual norm is below ``closure``, whether or not each step lowers it (Gauss-Newton; the caller
    reads the residual to know whether it converged).  Returns (q, its residual norm, steps taken)."""
    q = np.array(q0, float)
    r, K = kernel.evaluate(q[None], True)
    assert K is not None
    norm, it = float(np.linalg.norm(r[0])), 0
    for it in range(1, iterations + 1):
        if closure is not None and norm < closure:
            it -= 1
            break
        dq = np.zeros(kernel.nv)
        dq[free] = -np.linalg.lstsq(K[0][:, free], r[0], rcond=None)[0]
        q_new = kernel.integrate(q[None], dq[None])[0]  # q (+) dq on the manifold, as the loop moves
        r, K = kernel.evaluate(q_new[None], True)
        assert K is not None
        new = float(np.linalg.norm(r[0]))
        if closure is None and not new < norm:
            break
        q, norm = q_new, new
    return Assembly(q, norm, it)


def polish(kernel: ClosureKernel, q0: Array, frozen: Any = (), iterations: int = 8) -> Assembly:
    """Undamped Newton (``undamped``) from q0, which is already near a root of ``kernel``'s rows (a
    ClosureSystem's: ``ClosureSystem.pinocchio``), with the velocity indices ``frozen`` held, while
    the residual keeps falling.  Returns the configuration with the smallest residual seen (its
    norm, the steps taken)."""
    free = kernel.free_columns(tuple(int(f) for f in np.asarray(frozen, int).ravel()))
    return undamped(kernel, q0, free, iterations)
