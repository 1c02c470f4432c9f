"""Numerical path tracking of a homotopy H(x, t) = 0 from t = 0 to t = 1 for many paths at once.

The pieces, each on the stack of paths still moving (numpy, complex):
- predict: fourth-order Runge-Kutta on dx/dt = -H_x^-1 H_t (each stage one batched linear solve);
- correct: Newton on H(x, t + h) = 0, two iterations;
- accept: the corrector converged (its last step below ``track_tol`` relative to |x|) and contracted
  quadratically (the second step at most ``track_contraction`` times the first): a step that lands
  near another path does not contract so, and is refused (no path jumping);
- step control: the first Newton step is the predictor's error; the next step is scaled by
  (target error / error)^(1/5) (RK4's local error is O(h^5)), at most doubled, halved on a refusal.
A path fails when its step falls below ``track_min_step`` or it takes ``track_max_steps`` steps; it
diverges when |x| passes ``track_diverge`` (a solution at infinity).  Failures are counted by the
caller, never dropped.  The settings are the ``track_`` fields of screwkin.tolerances.Tolerances.

At t = 1 the paths are polished by ``newton``: the project's one Newton iteration (model.newton.iterate)
on the complex stack, its step undamped (``newton_step``) and its verdict accepting every finite step.

A homotopy is any object with ``n`` (its equations and tangent coordinates), ``evaluate(X, T,
index, jacobian)`` returning H (P, n) and its Jacobian in tangent coordinates (P, n, n),
``dt(X, T, index)`` returning H_t (P, n), and ``retract(X, dT)``, the points X moved by tangent steps
dT (x + dT in a vector space; along circles and spheres for model.kernel.algebraic), where ``index`` says
which of the homotopy's paths the rows X are (paths may have their own start and end parameters).
``Segment`` is the one used by the assembly-mode search: a system G(x) = c moved along straight
segments of its offset c, per path.

The corrector's first Jacobian also gives the next step's first predictor stage and the second
Newton step (a simplified Newton step: one factorization, its inverse, per step).

The Cauchy endgame (``cauchy``) finds where paths end when their endpoint is singular: it tracks
around t = 1 on loops of radius r in the complex t plane until each path closes up (its winding
number), and averages the samples (the trapezoid rule of Cauchy's integral formula).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np

from ...tolerances import DEFAULT, Tolerances
from ..kernel import newton as _newton

__all__ = ["Homotopy", "System", "Tracked", "Segment", "Paths", "track", "newton", "Polished", "newton_step",
           "capped_newton_step", "every_step", "every_finite_step", "cauchy", "OK", "FAILED", "DIVERGED"]

OK, FAILED, DIVERGED = 0, 1, 2
#: A step that ends within this fraction of the segment's length from its end is at the end (round-off).
_SNAP = 1e-15
#: Division guard of the step-size rule's error ratio.
_TINY = 1e-300
#: The Newton iteration's own stopping rule off (a residual below 0 never comes): the homotopy's Newton
#: takes the steps it asks for, and judges their ends itself.
_EVERY_STEP = Tolerances(closure=0.0)

Array = np.ndarray
#: A step of the Newton iteration (model.newton.iterate's ``step``): (K (N, n, n), r (N, n), free columns,
#: damping (N,)) -> (steps on the free columns (N, n), squared residuals of the linear model (N,)).
Step = Callable[[Array, Array, Array, Array], "tuple[Array, Array]"]
#: Its verdict (model.newton.judge's signature): -> (accepted, norms after, damping, nu, going on).
Verdict = Callable[..., "tuple[Array, Array, Array, Array, Array]"]


class System(Protocol):
    """A square polynomial system in tangent coordinates: G (P, n) and its Jacobian (P, n, n) at the
    points X (P, width), and the points moved by tangent steps."""

    n: int

    def equations(self, X: Array, jacobian: bool = True) -> tuple[Array, Array | None]: ...

    def retract(self, X: Array, dT: Array) -> Array: ...


class Homotopy(Protocol):
    """H(x, t) for the paths ``index`` (see the module)."""

    n: int

    def evaluate(self, X: Array, T: Array, index: Array, jacobian: bool = True) -> tuple[Array, Array | None]: ...

    def dt(self, X: Array, T: Array, index: Array) -> Array: ...

    def retract(self, X: Array, dT: Array) -> Array: ...


@dataclass
class Tracked:
    """Where the paths got: X (P, n) the last points, T (P,) their t, status (P,) OK, FAILED or
    DIVERGED, steps (P,) accepted steps, refused (P,) refused ones, residual (P,) |H| at the end."""

    X: np.ndarray
    T: np.ndarray
    status: np.ndarray
    steps: np.ndarray
    refused: np.ndarray
    residual: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        return self.status == OK


class Segment:
    """H(x, t) = G(x) - (a + t (b - a)): a system's equations offset along a straight segment from a
    to b (P, n), per path."""

    def __init__(self, system: System, a: Array, b: Array) -> None:
        self.system, self.n = system, system.n
        self.a = np.asarray(a, complex)
        self.d = np.asarray(b, complex) - self.a

    def evaluate(self, X: Array, T: Array, index: Array, jacobian: bool = True) -> tuple[Array, Array | None]:
        G, J = self.system.equations(X, jacobian)
        return G - (self.a[index] + np.asarray(T)[:, None] * self.d[index]), J

    def dt(self, X: Array, T: Array, index: Array) -> Array:
        return -self.d[index]

    def retract(self, X: Array, dT: Array) -> Array:
        return self.system.retract(X, dT)


def _finite(A: Array, B: Array | None = None) -> Array:
    """Rows of a stack whose entries are all finite (a path that overflowed is not)."""
    good = np.isfinite(A).reshape(len(A), -1).all(axis=1)
    if B is not None:
        good &= np.isfinite(B).reshape(len(B), -1).all(axis=1)
    return good


def _solve(A: Array, B: Array) -> Array:
    """Batched solve; nan for the matrices that are singular or not finite."""
    good = _finite(A, B)
    out = np.full(B.shape, np.nan, complex)
    if good.all():
        try:
            return np.linalg.solve(A, B)
        except np.linalg.LinAlgError:
            pass
    for i in np.flatnonzero(good):
        try:
            out[i] = np.linalg.solve(A[i], B[i])
        except np.linalg.LinAlgError:
            pass
    return out


def _norm(V: Array) -> Array:
    return np.sqrt(np.einsum("pi,pi->p", V.real, V.real) + np.einsum("pi,pi->p", V.imag, V.imag))


def newton_step(K: Array, r: Array, free: Array, mu: Array) -> tuple[Array, Array]:
    """Newton's own step, undamped, on a complex stack: -K^-1 r (nan where K is singular); the
    damping ``mu`` is not used, nor the linear model's residual (zeros)."""
    return -_solve(K, r[..., None])[..., 0], np.zeros(len(r))


def capped_newton_step(cap: float) -> Step:
    """Newton's step shortened to at most ``cap`` in its largest coordinate (a damped Newton from far
    away: random starts)."""

    def step(K: Array, r: Array, free: Array, mu: Array) -> tuple[Array, Array]:
        d = _solve(K, r[..., None])[..., 0]
        size = np.abs(d).max(axis=1)
        d *= np.minimum(1.0, cap / np.where(np.isfinite(size), np.maximum(size, _TINY), 1.0))[:, None]
        return -d, np.zeros(len(r))

    return step


def every_step(norm: Array, r_new: Array, linear_squared: Array, mu: Array, nu: Array,
               *bounds: float) -> tuple[Array, Array, Array, Array, Array]:
    """The verdict of Newton's own iteration: every step taken, none the last (the count of
    iterations ends it)."""
    every = np.ones(len(norm), bool)
    return every, _norm(r_new), mu, nu, every


def every_finite_step(norm: Array, r_new: Array, linear_squared: Array, mu: Array, nu: Array,
                      *bounds: float) -> tuple[Array, Array, Array, Array, Array]:
    """Every step taken that lands where the rows are finite; a point whose step is not stops there
    (``Polished.kept`` false)."""
    new = _norm(r_new)
    finite = np.isfinite(new)
    return finite, new, mu, nu, finite


class Polished(NamedTuple):
    """Where ``newton`` left the points: X (P, width); step (P,) the norm of each one's last step;
    residual (P,) |H| before it (inf for a point not stepped); kept (P,) every step was taken."""

    X: np.ndarray
    step: np.ndarray
    residual: np.ndarray
    kept: np.ndarray


def newton(hom: Homotopy, X: Array, T: Array, index: Array, iterations: int, step: Step = newton_step,
           verdict: Verdict = every_step) -> Polished:
    """``iterations`` Newton steps on H(x, T) = 0 for every path: the project's one Newton iteration
    (model.newton.iterate) on the complex stack, with the step ``step`` (Newton's own, or
    ``capped_newton_step``) and the verdict ``verdict`` (``every_step`` or ``every_finite_step``)."""
    X = np.array(X, complex)
    P = len(X)
    T, index = np.asarray(T), np.asarray(index)
    last_step, before = np.full(P, np.inf), np.full(P, np.inf)
    if not P or iterations <= 0:
        return Polished(X, last_step, before, np.ones(P, bool))

    def evaluate(Q: Array, which: Array, jacobian: bool) -> tuple[Array, Array | None]:
        return hom.evaluate(Q, T[which], index[which], jacobian)

    def trace(which: Array, k: int, Q: Array, r: Array, K: Array, dQ: Array, ok: Array) -> None:
        last_step[which], before[which] = _norm(dQ), _norm(r)

    out = _newton.iterate(evaluate, X, np.arange(hom.n), _EVERY_STEP, hom.retract, step, iterations, trace,
                          verdict)
    return Polished(out.q, last_step, before, out.iterations >= iterations)


def _inverse(J: Array) -> Array:
    """Batched inverse; nan for the matrices that are singular or not finite."""
    good = _finite(J)
    if good.all():
        try:
            return np.linalg.inv(J)
        except np.linalg.LinAlgError:
            pass
    out = np.full(J.shape, np.nan, complex)
    for i in np.flatnonzero(good):
        try:
            out[i] = np.linalg.inv(J[i])
        except np.linalg.LinAlgError:
            pass
    return out


def track(hom: Homotopy, X0: Array, index: Array | None = None, tol: Tolerances = DEFAULT, t0: float = 0.0,
          t1: float = 1.0) -> Tracked:
    """Track the paths starting at X0 (P, ...) at t0 (a solution of H(x, t0) = 0 each) to t1 (the
    ``track_`` fields of ``tol``)."""
    X = np.array(X0, complex)
    P = len(X)
    index = np.arange(P) if index is None else np.asarray(index, int)
    T = np.full(P, float(t0))
    h = np.full(P, tol.track_first_step * (t1 - t0))
    status = np.full(P, OK)
    steps = np.zeros(P, int)
    refused = np.zeros(P, int)
    span = t1 - t0
    K1 = np.zeros((P, hom.n), complex)
    known = np.zeros(P, bool)  # K1 holds the first stage at the path's point
    active = np.arange(P)
    with np.errstate(all="ignore"):  # a path that overflows is refused, then fails
        _loop(hom, X, T, h, K1, known, status, steps, refused, index, active, t1, span, tol)
    ok = status == OK
    residual = np.full(P, np.inf)
    if ok.any() and tol.track_polish:
        with np.errstate(all="ignore"):
            end = newton(hom, X[ok], T[ok], index[ok], tol.track_polish)
        X[ok], residual[ok] = end.X, end.residual
        # arrived only where Newton settles on a root (a path that strayed is a failure, not a root)
        status[ok & ~(residual <= tol.track_root_tol * (1.0 + _norm(np.where(np.isfinite(X), X, 0))))] = FAILED
    return Tracked(X, T, status, steps, refused, residual)


class Paths:
    """The homotopy's continuation engine: the questions of analysis.motion.continuation's ``Engine``
    asked of a stack of paths in complex space (``predict``, ``correct``, ``accept``).  A path there
    has no branch to choose and no limit position to locate on its way -- between generic complex
    parameters it meets the singular set with probability zero -- so those two questions are not
    asked: a singular endpoint is the Cauchy endgame's (``cauchy``)."""

    def __init__(self, hom: Homotopy, tol: Tolerances = DEFAULT) -> None:
        self.hom, self.tol = hom, tol

    def field(self, x: Array, t: Array, idx: Array) -> Array:
        """dx/dt = -H_x^-1 H_t at the points x (parameter t)."""
        _, J = self.hom.evaluate(x, t, idx)
        assert J is not None
        return -_solve(J, self.hom.dt(x, t, idx)[..., None])[..., 0]

    def predict(self, x: Array, t: Array, hh: Array, k1: Array, idx: Array) -> Array:
        """Fourth-order Runge-Kutta from x at t by steps hh (k1: the first stage): the points at t + hh."""
        hom, field = self.hom, self.field
        half = 0.5 * hh
        k2 = field(hom.retract(x, half[:, None] * k1), t + half, idx)
        k3 = field(hom.retract(x, half[:, None] * k2), t + half, idx)
        k4 = field(hom.retract(x, hh[:, None] * k3), t + hh, idx)
        return hom.retract(x, (hh / 6.0)[:, None] * (k1 + 2 * k2 + 2 * k3 + k4))

    def correct(self, xp: Array, tn: Array, idx: Array) -> tuple[Array, Array, Array, Array]:
        """A Newton step, then a simplified one with the same Jacobian: (points, first and second step
        norms, the inverse Jacobian at the prediction)."""
        hom = self.hom
        H, J = hom.evaluate(xp, tn, idx)
        assert J is not None
        Ji = _inverse(J)
        dx1 = np.einsum("pij,pj->pi", Ji, H)
        x1 = hom.retract(xp, -dx1)
        H1, _ = hom.evaluate(x1, tn, idx, jacobian=False)
        dx2 = np.einsum("pij,pj->pi", Ji, H1)
        return hom.retract(x1, -dx2), _norm(dx1), _norm(dx2), Ji

    def accept(self, x: Array, xc: Array, d1: Array, d2: Array) -> Array:
        """The corrector converged (its last step under track_tol relative to 1 + |x|) and contracted
        (the second step at most ``track_contraction`` times the first), and the step moved the point
        by at most track_max_jump (relative): a step that lands near another path is refused (no path
        jumping)."""
        o = self.tol
        scale = 1.0 + _norm(x)  # the last accepted point's size: a step to a huge point is no step
        return (np.isfinite(d2) & (d2 <= o.track_tol * scale)
                & ((d2 <= o.track_contraction * d1) | (d1 <= o.track_tol * scale))
                & (_norm(xc - x) <= o.track_max_jump * scale))


def _loop(hom: Homotopy, X: Array, T: Array, h: Array, K1: Array, known: Array, status: Array, steps: Array,
          refused: Array, index: Array, active: Array, t1: float, span: float, o: Tolerances) -> None:
    """The predictor-corrector iterations of ``track`` on the arrays it passes (changed in place)."""
    paths = Paths(hom, o)
    while active.size:
        x, t, idx = X[active], T[active], index[active]
        hh = np.minimum(h[active], t1 - t)
        k1 = K1[active]
        fresh = ~known[active]
        if fresh.any():
            k1[fresh] = paths.field(x[fresh], t[fresh], idx[fresh])
        tn = t + hh
        xp = paths.predict(x, t, hh, k1, idx)
        xc, d1, d2, Ji = paths.correct(xp, tn, idx)
        good = paths.accept(x, xc, d1, d2)
        scale = 1.0 + _norm(x)
        err = d1 / scale
        acc, rej = active[good], active[~good]
        X[acc], T[acc] = xc[good], np.where(tn[good] >= t1 - _SNAP * abs(span), t1, tn[good])
        K1[acc] = -np.einsum("pij,pj->pi", Ji[good], hom.dt(xc[good], tn[good], idx[good]))
        known[acc] = True
        steps[acc] += 1
        grow = np.clip(0.9 * (o.track_target / np.maximum(err[good], _TINY)) ** 0.2, 0.5, 2.0)
        h[acc] = np.minimum(hh[good] * grow, o.track_max_step * span)
        h[rej] = 0.5 * hh[~good]
        refused[rej] += 1
        big = ~(_norm(X[active]) <= o.track_diverge)  # nan too
        status[active[big]] = DIVERGED
        small = h[active] < o.track_min_step * span
        status[active[small & ~big]] = FAILED
        many = steps[active] + refused[active] > o.track_max_steps
        status[active[many & ~big & ~small]] = FAILED
        done = (T[active] >= t1) | (status[active] != OK)
        active = active[~done]


def cauchy(hom: Homotopy, X: Array, index: Array, radius: float, samples: int = 16, max_loops: int = 8,
           tol: Tolerances = DEFAULT) -> tuple[Array, Array, Array]:
    """The endpoints at t = 1 of paths that are at X (P, n) at t = 1 - radius (real), by Cauchy's
    integral formula: each path is tracked around the circle |t - 1| = radius (a polygon of
    ``samples`` vertices; ``hom`` is evaluated at complex t) until it returns to where it started
    (within ``tol.track_closed``), after c loops (its cycle number); the endpoint is the mean of the
    c * samples vertices.  Returns (endpoints (P, n), cycle numbers (P,), ok (P,))."""
    P = len(X)
    start = np.array(X, complex)
    cur = start.copy()
    acc = start.copy()
    count = np.ones(P)
    cycles = np.zeros(P, int)
    ok = np.ones(P, bool)
    done = np.zeros(P, bool)
    theta = 2 * np.pi * np.arange(samples + 1) / samples
    tau = 1.0 - radius * np.exp(1j * theta)
    for loop in range(max_loops):
        for k in range(samples):
            active = np.flatnonzero(~done & ok)
            if not active.size:
                break
            chord = _Chord(hom, tau[k], tau[k + 1])
            res = track(chord, cur[active], index[active], tol)
            ok[active[~res.ok]] = False
            cur[active[res.ok]] = res.X[res.ok]
            if k + 1 < samples:
                acc[active[res.ok]] += res.X[res.ok]
                count[active[res.ok]] += 1
        active = np.flatnonzero(~done & ok)
        back = _norm(cur[active] - start[active]) <= tol.track_closed * (1.0 + _norm(start[active]))
        cycles[active[back]] = loop + 1
        done[active[back]] = True
        if done[ok].all():
            break
        acc[active[~back]] += cur[active[~back]]
        count[active[~back]] += 1
    ok &= done
    return acc / count[:, None], cycles, ok


class _Chord:
    """The homotopy ``hom`` along the straight chord from complex t = ta to t = tb, as s goes 0 -> 1."""

    def __init__(self, hom: Homotopy, ta: complex, tb: complex) -> None:
        self.hom, self.n, self.ta, self.dtb = hom, hom.n, ta, tb - ta

    def evaluate(self, X: Array, S: Array, index: Array, jacobian: bool = True) -> tuple[Array, Array | None]:
        return self.hom.evaluate(X, self.ta + np.asarray(S) * self.dtb, index, jacobian)

    def dt(self, X: Array, S: Array, index: Array) -> Array:
        return self.hom.dt(X, self.ta + np.asarray(S) * self.dtb, index) * self.dtb

    def retract(self, X: Array, dT: Array) -> Array:
        return self.hom.retract(X, dT)
