"""Compiled kernels for the inner loop of the closure solver (optional: ``pip install -e '.[fast]'``).

A damped-Newton iteration on a mechanism with welded (fixed) and spherical cut
joints -- the 6d and 3d closures of Extended-URDF files -- costs about 38 us in
numpy for one weld, of which Pinocchio's own calls are 3 us: the rest is the
overhead of numpy calls on 3-vectors.  Here the rows, their Jacobian and the damped step are
loops compiled by numba (cached on disk after the first use): the same numbers
as ``ClosureSystem.evaluate(q, solver=True)`` and model.kernel.newton.damped_step (tests check
both), about 2.5 times faster per solve (benchmarks/README.md).  Pinocchio still computes every
placement and frame Jacobian, and the Newton loop is model.kernel.newton.iterate, the numpy solver's own:
the rows, the step and the loop's verdict (model.kernel.newton.judge, compiled from its one definition)
are what is compiled.

The step's linear solve is numba's np.linalg.solve, which raises np.linalg.LinAlgError where
LAPACK finds the damped system singular in floating point ("Matrix is singular to machine
precision") or where K or r holds an inf or a NaN ("Array must not contain infs or NaNs"); nothing
else in the kernels raises.  ``damped_step`` then takes model.kernel.newton.damped_step, whose solve falls
back to least squares (and which gives NaN, as numpy does, for a NaN row).

Used only when asked (``PositionSolver(mech, compiled=True)`` or
``mech.closure.accelerate()``): importing numba costs about 0.25 s and the first
use compiles for about 15 s (8 s of it the rows and the step; loaded from the cache in about
0.5 s afterwards, on 2 busy cores), which a single command would not win back.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

try:
    import resource
except ImportError:  # not a POSIX system
    resource = None  # type: ignore[assignment]

import pinocchio as pin

from .._pin import frame_jacobian
from . import newton
from .newton import TRACE_FLOOR

__all__ = ["available", "kernels", "kinds_of", "damped_step", "one_step", "SPHERICAL", "FIXED", "cut_rows"]

SPHERICAL, FIXED = 0, 1  # the cut joint types the kernels know (3 and 12 solver rows)
_KERNELS = None


def available() -> bool:
    """Whether numba can be imported."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def cache_on_disk() -> bool:
    """Whether numba may keep its compiled kernels on disk: not under a limit on the size of the files
    this process writes (ulimit -f), which numba's cache files (several MB) would pass -- the write
    fails with EFBIG, and the kernels are then compiled in memory for this run only."""
    if resource is None:  # not a POSIX system
        return True
    return resource.getrlimit(resource.RLIMIT_FSIZE)[0] == resource.RLIM_INFINITY


def kernels() -> Any:
    """The compiled functions (compiled or loaded from the cache at the first call)."""
    global _KERNELS
    if _KERNELS is None:
        _KERNELS = _compile_kernels()
    return _KERNELS


def _compile_kernels() -> Any:
    import numba as nb

    cache = cache_on_disk()

    @nb.njit(cache=cache)
    def cut_rows(kinds: np.ndarray, R1: np.ndarray, R2: np.ndarray, t1: np.ndarray, t2: np.ndarray, J1: np.ndarray,
                 J2: np.ndarray, r: np.ndarray, K: np.ndarray, jacobian: bool) -> int:
        """Solver rows of each cut joint c, in order: F2's origin along F1's axes
        (e . d, e fixed in F1), then for welds R2 e - R1 e for the three axes e.
        Their derivative: e . (v2 - v1) + (e x d) . w1 and [R1 e]x w1 - [R2 e]x w2."""
        nv = K.shape[1]
        i = 0
        for c in range(kinds.shape[0]):
            d0 = t2[c, 0] - t1[c, 0]
            d1 = t2[c, 1] - t1[c, 1]
            d2 = t2[c, 2] - t1[c, 2]
            for a in range(3):
                r[i + a] = R1[c, 0, a] * d0 + R1[c, 1, a] * d1 + R1[c, 2, a] * d2
            if jacobian:
                for col in range(nv):
                    w0, w1, w2 = J1[c, 3, col], J1[c, 4, col], J1[c, 5, col]
                    g0 = J2[c, 0, col] - J1[c, 0, col] + d1 * w2 - d2 * w1
                    g1 = J2[c, 1, col] - J1[c, 1, col] + d2 * w0 - d0 * w2
                    g2 = J2[c, 2, col] - J1[c, 2, col] + d0 * w1 - d1 * w0
                    for a in range(3):
                        K[i + a, col] = R1[c, 0, a] * g0 + R1[c, 1, a] * g1 + R1[c, 2, a] * g2
            i += 3
            if kinds[c] == FIXED:
                for a in range(3):
                    u0, u1, u2 = R1[c, 0, a], R1[c, 1, a], R1[c, 2, a]
                    v0, v1, v2 = R2[c, 0, a], R2[c, 1, a], R2[c, 2, a]
                    r[i] = v0 - u0
                    r[i + 1] = v1 - u1
                    r[i + 2] = v2 - u2
                    if jacobian:
                        for col in range(nv):
                            x0, x1, x2 = J1[c, 3, col], J1[c, 4, col], J1[c, 5, col]
                            y0, y1, y2 = J2[c, 3, col], J2[c, 4, col], J2[c, 5, col]
                            K[i, col] = (u1 * x2 - u2 * x1) - (v1 * y2 - v2 * y1)
                            K[i + 1, col] = (u2 * x0 - u0 * x2) - (v2 * y0 - v0 * y2)
                            K[i + 2, col] = (u0 * x1 - u1 * x0) - (v0 * y1 - v1 * y0)
                    i += 3
        return i

    @nb.njit(cache=cache)
    def damped_step(K: np.ndarray, r: np.ndarray, free: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, Any]:
        """model.kernel.newton.damped_step, compiled: the minimum-norm damped step on the free columns
        (the smaller of the two normal systems) and |r + K_f dq_f|^2 (the linear model's residual)."""
        m, nf = K.shape[0], free.shape[0]
        Kf = np.empty((m, nf))
        for a in range(m):
            for b in range(nf):
                Kf[a, b] = K[a, free[b]]
        tall = m > nf
        A = Kf.T @ Kf if tall else Kf @ Kf.T
        trace = 0.0
        for a in range(A.shape[0]):
            trace += A[a, a]
        damping = mu * max(trace / m, TRACE_FLOOR)
        for a in range(A.shape[0]):
            A[a, a] += damping
        if tall:
            dqf = -np.linalg.solve(A, Kf.T @ r)
        else:
            dqf = -(Kf.T @ np.linalg.solve(A, r))
        lin = r + Kf @ dqf
        return dqf, lin @ lin

    # the loop's verdict, compiled from its one definition
    return SimpleNamespace(cut_rows=cut_rows, damped_step=damped_step, judge=nb.njit(cache=cache)(newton.judge))


def damped_step(K: np.ndarray, r: np.ndarray, free: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, Any]:
    """model.kernel.newton.damped_step through the compiled kernel (K C-contiguous, free int64), with
    the numpy step where numba's solve raises np.linalg.LinAlgError (a singular damped system:
    the numpy step's least-squares fallback; an inf or NaN in K or r: NaN, as numpy gives)."""
    try:
        return kernels().damped_step(K, r, free, mu)
    except np.linalg.LinAlgError:
        return newton.damped_step(K, r, free, mu)


#: damped_step as the step of model.kernel.newton.iterate (the single solve's, compiled).
one_step = newton.one_at_a_time(damped_step)


def kinds_of(cuts: Any) -> np.ndarray | None:
    """The kernel code of each cut joint, or None when one of them is of a type the kernels
    do not know."""
    codes = {"spherical": SPHERICAL, "fixed": FIXED}
    if not cuts or any(c.type not in codes for c in cuts):
        return None
    return np.array([codes[c.type] for c in cuts], np.int64)


def cut_rows(system: Any, q: np.ndarray, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """system.evaluate(q, jacobian, solver=True) of a model.kernel.closure.ClosureSystem through the
    compiled kernel (the same rows; after system.accelerate())."""
    LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    assert system._compiled is not None
    kernels, kinds = system._compiled
    ws = system._workspace()
    if ws.buffers is None:  # this thread's buffers for the kernel
        n, nv = len(system.cuts), system.model.nv
        ws.buffers = (np.empty((n, 3, 3)), np.empty((n, 3, 3)), np.empty((n, 3)), np.empty((n, 3)),
                      np.empty((n, 6, nv)), np.empty((n, 6, nv)))
    R1, R2, t1, t2, J1, J2 = ws.buffers
    model, data = system.model, ws.data
    system._kinematics(q, jacobian, data)
    for j, (cut, (a, b, c, d)) in enumerate(zip(system.cuts, ws.placements)):
        R1[j], R2[j], t1[j], t2[j] = a, b, c, d
        if jacobian:
            J1[j] = frame_jacobian(model, data, cut.frame1, LWA)
            J2[j] = frame_jacobian(model, data, cut.frame2, LWA)
    nrows = system._rows(True)
    r = np.empty(nrows)
    K = np.empty((nrows, model.nv)) if jacobian else np.empty((0, model.nv))
    kernels.cut_rows(kinds, R1, R2, t1, t2, J1, J2, r, K, jacobian)
    return r, (K if jacobian else None)
