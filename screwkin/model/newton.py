"""The one damped-Newton (Levenberg-Marquardt) step of every closure solver.

The single solver (model.closure.ClosureSystem.solve), the batched one
(analysis.motion.batch_closure.BatchClosure.solve) and the compiled kernel (model.compiled)
take the same step with the same constants:

- the step is the minimum-norm damped step on the free columns of K,
  ``dq_f = -K_f^T (K_f K_f^T + lambda I)^-1 r`` with ``lambda = mu * trace / rows``
  (with more rows than free columns the same step is
  ``(K_f^T K_f + lambda I)^-1 K_f^T (-r)``, a smaller system);
- the damping ``mu`` starts at ``Tolerances.lm_damping``; an accepted step
  updates it from the gain ratio rho (actual over predicted decrease of the
  squared residual) by Nielsen's rule, never below ``Tolerances.lm_damping_min``;
  a refused one multiplies it by nu (2, 4, 8, ...); past
  ``Tolerances.lm_damping_max`` the solver gives up.

``polish`` is the undamped step at the end: from a configuration near a root (a damped solve's, a
homotopy's real endpoint), Newton's own step until the residual stops falling -- round-off for a
simple root, where damped steps stop at the closure tolerance.

The residual rows may be evaluated one configuration at a time (Pinocchio),
for a stack (numpy) or compiled (numba); tests compare the three, the program
does not at run time.  Every function here works on one configuration or, where
named so, on a stack of them.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ..errors import AssemblyError
from .cuts import Assembly

__all__ = ["TRACE_FLOOR", "damped_step", "damped_steps", "gain_ratio", "accept", "refuse", "given_up", "solve", "polish", "NU"]

#: Division guard: the damping is relative to the mean squared row norm, which is never taken
#: below this (a zero Jacobian) [same units as K^2].
TRACE_FLOOR = 1e-12

#: Nielsen's factor on the damping after a refused step starts at this and doubles.
NU = 2.0


def damped_step(K, r, free, mu):
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


def damped_steps(Kf, r, mu):
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


def gain_ratio(norm, new_norm, linear_squared):
    """Actual over predicted decrease of the squared residual (scalars or arrays); 0 where
    the linear model predicts no decrease."""
    norm, new_norm, linear_squared = np.asarray(norm), np.asarray(new_norm), np.asarray(linear_squared)
    predicted = norm**2 - linear_squared
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = np.where(predicted > 0, (norm**2 - new_norm**2) / predicted, 0.0)
    return rho if rho.ndim else float(rho)


def accept(mu, rho, tol):
    """The damping after an accepted step of gain ratio rho (Nielsen), and nu reset:
    (mu, nu); scalars or arrays."""
    mu = np.maximum(np.asarray(mu) * np.maximum(1.0 / 3.0, 1.0 - (2.0 * np.asarray(rho) - 1.0) ** 3),
                    tol.lm_damping_min)
    return (mu if mu.ndim else float(mu)), NU


def refuse(mu, nu):
    """The damping after a refused step, and the next factor: (mu * nu, 2 nu)."""
    return mu * nu, nu * 2.0


def given_up(mu, tol):
    """Whether the damping has grown past the point where the solver stops (scalar or array)."""
    return mu > tol.lm_damping_max


def solve(system, q0, frozen, tol, trace=None) -> Assembly:
    """Damped Newton on a model.closure.ClosureSystem from q0 with the velocity indices
    ``frozen`` held: the step and damping above, Tolerances ``tol`` (closure, max_iterations and
    the lm_ fields).  When Newton is about to converge quadratically (the next residual near
    norm^2) the residual alone is computed first, as the Jacobian there is not needed."""
    model = system.model
    q = np.array(q0, float)
    if system.nrows == 0:
        return Assembly(q, 0.0, 0)
    frozen = tuple(int(f) for f in np.asarray(frozen, int).ravel())
    free = system.free_columns(frozen)
    evaluate, step = system.solver_pass()
    r, K = evaluate(q)
    last = q  # the configuration whose placements are in the system's Data
    norm = float(np.sqrt(r @ r))
    best = norm
    mu, nu = tol.lm_damping, NU
    it = 0
    dq = np.zeros(model.nv)
    while it < tol.max_iterations:
        if norm < tol.closure:
            break
        it += 1
        dq[free], lin2 = step(K, r, free, mu)
        q_new = pin.integrate(model, q, dq)
        final = norm < 0.1 * np.sqrt(tol.closure)
        r_new, K_new = evaluate(q_new, jacobian=not final)
        last = q_new
        n_new = float(np.sqrt(r_new @ r_new))
        if final and tol.closure <= n_new < norm:
            r_new, K_new = evaluate(q_new)
        accepted = n_new < norm
        if trace is not None:
            trace(it, q, r, K, dq.copy(), accepted)
        if accepted:
            mu, nu = accept(mu, gain_ratio(norm, n_new, lin2), tol)
            q, r, K, norm = q_new, r_new, K_new, n_new
            best = min(best, norm)
        else:
            mu, nu = refuse(mu, nu)
            if given_up(mu, tol):
                break
    if norm >= tol.closure:
        raise AssemblyError(system.path, best, it)
    bad = system.wrong_branch(q, placed=q is last)
    if bad:
        raise AssemblyError(system.path, best, it,
                            detail=f"the solution found assembles {', '.join(bad)} with a reversed axis")
    return Assembly(q, norm, it)


def polish(system, q0, frozen=(), iterations: int = 8) -> Assembly:
    """Undamped Newton from q0, which is already near a root of ``system`` (a model.closure.ClosureSystem),
    with the velocity indices ``frozen`` held: the minimum-norm step on the free columns of the
    solver's rows (least squares: the rows are redundant), while the residual keeps falling.  A simple
    root is reached to round-off in two or three steps.  Returns the configuration with the smallest
    residual seen (its norm, the steps taken)."""
    model = system.model
    free = system.free_columns(tuple(int(f) for f in np.asarray(frozen, int).ravel()))
    q = np.array(q0, float)
    r, K = system.evaluate(q, jacobian=True, solver=True)
    best_q, best, it = q, float(np.linalg.norm(r)), 0
    for it in range(1, iterations + 1):
        dq = np.zeros(model.nv)
        dq[free] = -np.linalg.lstsq(K[:, free], r, rcond=None)[0]
        q_new = pin.integrate(model, q, dq)
        r, K = system.evaluate(q_new, jacobian=True, solver=True)
        norm = float(np.linalg.norm(r))
        if not norm < best:
            break
        best_q, best, q = q_new, norm, q_new
    return Assembly(best_q, best, it)
