"""Numerical path tracking of a homotopy H(x, t) = 0 from t = 0 to t = 1 for many paths at once.

The pieces, each on the stack of paths still moving (numpy, complex):
- predict: fourth-order Runge-Kutta on dx/dt = -H_x^-1 H_t (each stage one batched linear solve);
- correct: Newton on H(x, t + h) = 0, two iterations;
- accept: the corrector converged (its last step below ``tol`` relative to |x|) and contracted
  quadratically (the second step at most ``contraction`` times the first): a step that lands
  near another path does not contract so, and is refused (no path jumping);
- step control: the first Newton step is the predictor's error; the next step is scaled by
  (target error / error)^(1/5) (RK4's local error is O(h^5)), at most doubled, halved on a refusal.
A path fails when its step falls below ``min_step`` or it takes ``max_steps`` steps; it diverges when
|x| passes ``diverge`` (a solution at infinity).  Failures are counted by the caller, never dropped.

A homotopy is any object with ``n`` (its equations and tangent coordinates), ``evaluate(X, T,
index, jacobian)`` returning H (P, n) and its Jacobian in tangent coordinates (P, n, n),
``dt(X, T, index)`` returning H_t (P, n), and ``retract(X, dT)``, the points X moved by tangent steps
dT (x + dT in a vector space; along circles and spheres for model.algebraic), where ``index`` says
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

from dataclasses import dataclass

import numpy as np

__all__ = ["TrackerOptions", "Tracked", "Segment", "Paths", "track", "newton", "cauchy", "OK", "FAILED", "DIVERGED"]

OK, FAILED, DIVERGED = 0, 1, 2
#: A step that ends within this fraction of the segment's length from its end is at the end (round-off).
_SNAP = 1e-15


@dataclass(frozen=True)
class TrackerOptions:
    """tol: a corrected point's last Newton step, relative to 1 + |x|;
    target: the predictor error (first Newton step, relative) the step size aims at;
    contraction: the most the second Newton step may be of the first;
    first_step, min_step, max_step: step sizes in t; max_steps: per path;
    max_jump: the most a step may move a point, relative to 1 + |x|;
    closed: a Cauchy loop has closed when a path is back within this of its start (relative);
    diverge: |x| beyond which a path goes to infinity;
    polish: Newton iterations at t = 1; root_tol: |H| there (before the last), relative to 1 + |x|,
    below which a path has arrived at a root."""

    tol: float = 1e-7
    target: float = 1e-4
    contraction: float = 0.25
    first_step: float = 0.05
    min_step: float = 1e-9
    max_step: float = 0.3
    max_steps: int = 3000
    diverge: float = 1e8
    polish: int = 3
    root_tol: float = 1e-9
    max_jump: float = 2.0
    closed: float = 1e-6


DEFAULT_OPTIONS = TrackerOptions()


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
    to b (P, n), per path.  ``system`` has ``n``, ``equations(X, jacobian)`` -> (G (P, n), J (P, n,
    n)) and ``retract``."""

    def __init__(self, system, a, b):
        self.system, self.n = system, system.n
        self.a = np.asarray(a, complex)
        self.d = np.asarray(b, complex) - self.a

    def evaluate(self, X, T, index, jacobian: bool = True):
        G, J = self.system.equations(X, jacobian)
        return G - (self.a[index] + np.asarray(T)[:, None] * self.d[index]), J

    def dt(self, X, T, index):
        return -self.d[index]

    def retract(self, X, dT):
        return self.system.retract(X, dT)


def _finite(A, B=None):
    """Rows of a stack whose entries are all finite (a path that overflowed is not)."""
    good = np.isfinite(A).reshape(len(A), -1).all(axis=1)
    if B is not None:
        good &= np.isfinite(B).reshape(len(B), -1).all(axis=1)
    return good


def _solve(A, B):
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


def _norm(V):
    return np.sqrt(np.einsum("pi,pi->p", V.real, V.real) + np.einsum("pi,pi->p", V.imag, V.imag))


def newton(hom, X, T, index, iterations: int):
    """``iterations`` Newton steps on H(x, T) = 0 for every path: (X, last step norms, |H| before the
    last step)."""
    X = np.array(X, complex)
    step = np.zeros(len(X))
    res = np.zeros(len(X))
    for _ in range(iterations):
        H, J = hom.evaluate(X, T, index)
        dx = _solve(J, H[..., None])[..., 0]
        X = hom.retract(X, -dx)
        step, res = _norm(dx), _norm(H)
    return X, step, res


def _inverse(J):
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


def track(hom, X0, index=None, options: TrackerOptions = DEFAULT_OPTIONS, t0=0.0, t1=1.0) -> Tracked:
    """Track the paths starting at X0 (P, ...) at t0 (a solution of H(x, t0) = 0 each) to t1."""
    o = options
    X = np.array(X0, complex)
    P = len(X)
    index = np.arange(P) if index is None else np.asarray(index, int)
    T = np.full(P, float(t0))
    h = np.full(P, o.first_step * (t1 - t0))
    status = np.full(P, OK)
    steps = np.zeros(P, int)
    refused = np.zeros(P, int)
    span = t1 - t0
    K1 = np.zeros((P, hom.n), complex)
    known = np.zeros(P, bool)  # K1 holds the first stage at the path's point
    active = np.arange(P)
    with np.errstate(all="ignore"):  # a path that overflows is refused, then fails
        _loop(hom, X, T, h, K1, known, status, steps, refused, index, active, t1, span, o)
    ok = status == OK
    residual = np.full(P, np.inf)
    if ok.any() and o.polish:
        with np.errstate(all="ignore"):
            Xp, _, res = newton(hom, X[ok], T[ok], index[ok], o.polish)
        X[ok], residual[ok] = Xp, res
        # arrived only where Newton settles on a root (a path that strayed is a failure, not a root)
        status[ok & ~(residual <= o.root_tol * (1.0 + _norm(np.where(np.isfinite(X), X, 0))))] = FAILED
    return Tracked(X, T, status, steps, refused, residual)


class Paths:
    """The homotopy's continuation engine: the questions of analysis.motion.continuation's ``Engine``
    asked of a stack of paths in complex space (``predict``, ``correct``, ``accept``).  A path there
    has no branch to choose and no limit position to locate on its way -- between generic complex
    parameters it meets the singular set with probability zero -- so those two questions are not
    asked: a singular endpoint is the Cauchy endgame's (``cauchy``)."""

    def __init__(self, hom, options: TrackerOptions = DEFAULT_OPTIONS):
        self.hom, self.o = hom, options

    def field(self, x, t, idx):
        """dx/dt = -H_x^-1 H_t at the points x (parameter t)."""
        _, J = self.hom.evaluate(x, t, idx)
        return -_solve(J, self.hom.dt(x, t, idx)[..., None])[..., 0]

    def predict(self, x, t, hh, k1, idx):
        """Fourth-order Runge-Kutta from x at t by steps hh (k1: the first stage): the points at t + hh."""
        hom, field = self.hom, self.field
        half = 0.5 * hh
        k2 = field(hom.retract(x, half[:, None] * k1), t + half, idx)
        k3 = field(hom.retract(x, half[:, None] * k2), t + half, idx)
        k4 = field(hom.retract(x, hh[:, None] * k3), t + hh, idx)
        return hom.retract(x, (hh / 6.0)[:, None] * (k1 + 2 * k2 + 2 * k3 + k4))

    def correct(self, xp, tn, idx):
        """A Newton step, then a simplified one with the same Jacobian: (points, first and second step
        norms, the inverse Jacobian at the prediction)."""
        hom = self.hom
        H, J = hom.evaluate(xp, tn, idx)
        Ji = _inverse(J)
        dx1 = np.einsum("pij,pj->pi", Ji, H)
        x1 = hom.retract(xp, -dx1)
        H1, _ = hom.evaluate(x1, tn, idx, jacobian=False)
        dx2 = np.einsum("pij,pj->pi", Ji, H1)
        return hom.retract(x1, -dx2), _norm(dx1), _norm(dx2), Ji

    def accept(self, x, xc, d1, d2):
        """The corrector converged (its last step under tol relative to 1 + |x|) and contracted (the
        second step at most ``contraction`` times the first), and the step moved the point by at most
        max_jump (relative): a step that lands near another path is refused (no path jumping)."""
        o = self.o
        scale = 1.0 + _norm(x)  # the last accepted point's size: a step to a huge point is no step
        return (np.isfinite(d2) & (d2 <= o.tol * scale) & ((d2 <= o.contraction * d1) | (d1 <= o.tol * scale))
                & (_norm(xc - x) <= o.max_jump * scale))


def _loop(hom, X, T, h, K1, known, status, steps, refused, index, active, t1, span, o):
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
        grow = np.clip(0.9 * (o.target / np.maximum(err[good], 1e-300)) ** 0.2, 0.5, 2.0)
        h[acc] = np.minimum(hh[good] * grow, o.max_step * span)
        h[rej] = 0.5 * hh[~good]
        refused[rej] += 1
        big = ~(_norm(X[active]) <= o.diverge)  # nan too
        status[active[big]] = DIVERGED
        small = h[active] < o.min_step * span
        status[active[small & ~big]] = FAILED
        many = steps[active] + refused[active] > o.max_steps
        status[active[many & ~big & ~small]] = FAILED
        done = (T[active] >= t1) | (status[active] != OK)
        active = active[~done]


def cauchy(hom, X, index, radius: float, samples: int = 16, max_loops: int = 8,
           options: TrackerOptions = DEFAULT_OPTIONS):
    """The endpoints at t = 1 of paths that are at X (P, n) at t = 1 - radius (real), by Cauchy's
    integral formula: each path is tracked around the circle |t - 1| = radius (a polygon of
    ``samples`` vertices; ``hom`` is evaluated at complex t) until it returns to where it started,
    after c loops (its cycle number); the endpoint is the mean of the c * samples vertices.
    Returns (endpoints (P, n), cycle numbers (P,), ok (P,))."""
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
            res = track(chord, cur[active], index[active], options)
            ok[active[~res.ok]] = False
            cur[active[res.ok]] = res.X[res.ok]
            if k + 1 < samples:
                acc[active[res.ok]] += res.X[res.ok]
                count[active[res.ok]] += 1
        active = np.flatnonzero(~done & ok)
        back = _norm(cur[active] - start[active]) <= options.closed * (1.0 + _norm(start[active]))
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

    def __init__(self, hom, ta, tb):
        self.hom, self.n, self.ta, self.dtb = hom, hom.n, ta, tb - ta

    def evaluate(self, X, S, index, jacobian: bool = True):
        return self.hom.evaluate(X, self.ta + np.asarray(S) * self.dtb, index, jacobian)

    def dt(self, X, S, index):
        return self.hom.dt(X, self.ta + np.asarray(S) * self.dtb, index) * self.dtb

    def retract(self, X, dT):
        return self.hom.retract(X, dT)
