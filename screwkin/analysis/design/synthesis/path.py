"""Path generation with a four-bar: a coupler point through N points, by least squares.

Unknowns: the fixed pivots A0, B0, the crank a, coupler b and rocker c, the coupler point
(p, q) in the coupler's frame (origin A, x axis along A -> B), the crank angle theta_1 at
the first point and, unless the crank angles are prescribed (``timing``), the crank's
advance from each point to the next (at least 0.01 rad: the points are met in the order
given, the crank turning one way).  Residuals: the coupler point's distance to each point,
and a penalty wherever the linkage would not assemble at a point or between two (the
crank must turn from one to the next on one branch, sigma fixed per start).  The closed-form
position is the circle intersection of screwkin.analysis.design.synthesis.fourbar.

scipy.optimize.least_squares is run from ``starts`` seeded starts (both branches, both
directions of the crank), briefly, and the ``polish`` best of them (those not far above the
best) to round-off; of the
results that reach every point within the tolerance the one with the best transmission
angle along the motion is kept, else the one closest.
(pylinkage, on PyPI, searches coupler orientations on a grid for three to five points and
needs Python 3.11; this needs neither.)
"""

from __future__ import annotations

import math

import numpy as np

from ....errors import UsageError
from ....model.geometry import circle_circle, wrap_angle
from ....tolerances import DEFAULT
from .designs import Design, FourBar, PathResult, SynthesisError, Target
from .fourbar import fourbar_linkage, stored, travel_analysis
from typing import TYPE_CHECKING
if TYPE_CHECKING:
    from collections.abc import Sequence

__all__ = ["synthesize_path", "coupler_points", "path_points", "path_design", "MAX_POINTS"]

#: Most points a path may have (least squares over them: 12 to 100 points approximate a curve).
MAX_POINTS = 100

WHAT = "synthesize path"
TWO_PI = 2 * math.pi
_BETWEEN = np.array([0.25, 0.5, 0.75])


def _unpack(x: np.ndarray, timing: np.ndarray | None, direction: float) -> tuple:
    """The parameters of one design (x: (n,)) or of many (x: (m, n)), as arrays with the design
    index first: A0, B0 (m, 2), a, b, c, p, q (m,), crank angles th (m, N)."""
    X = np.atleast_2d(x)
    A0, B0 = X[:, 0:2], X[:, 2:4]
    a, b, c, p, q, th1 = X[:, 4:10].T
    if timing is not None:
        th = th1[:, None] + timing[None, :]
    else:
        steps = np.cumsum(X[:, 10:], axis=1)
        th = th1[:, None] + direction * np.concatenate([np.zeros((len(X), 1)), steps], axis=1)
    return A0, B0, a, b, c, p, q, th


def coupler_points(A0: np.ndarray, B0: np.ndarray, a: float | np.ndarray, b: float | np.ndarray, c: float | np.ndarray, p: float | np.ndarray, q: np.ndarray, th: np.ndarray, sigma: float) -> tuple:
    """Coupler point at crank angles th (..., N) of designs whose parameters (A0, B0 (..., 2); a,
    b, c, p, q scalars or (...,)) broadcast against them: (P (..., N, 2), h2 (..., N): < 0 where
    the linkage does not assemble, A, B)."""
    a, b, c, p, q = (np.asarray(v, float)[..., None] for v in (a, b, c, p, q))
    A = np.asarray(A0, float)[..., None, :] + a[..., None] * np.stack([np.cos(th), np.sin(th)], axis=-1)
    B, h2 = circle_circle(A, b, np.asarray(B0, float)[..., None, :], c, sigma)
    u = (B - A) / b[..., None]
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1)
    return A + p[..., None] * u + q[..., None] * n, h2, A, B


def _residuals(X: np.ndarray, pts: np.ndarray, timing: np.ndarray | None, direction: float, sigma: float, L: float) -> np.ndarray:
    """Residuals of designs X (m, n) -> (m, residuals): the distances to the points (over L),
    how far apart the circles are at and between the points (weighted), a turn exceeded."""
    A0, B0, a, b, c, p, q, th = _unpack(X, timing, direction)
    P, _, _, _ = coupler_points(A0, B0, a, b, c, p, q, th, sigma)
    r = ((P - pts[None]) / L).reshape(len(th), -1)
    mid = th[:, :-1, None] + (th[:, 1:] - th[:, :-1])[:, :, None] * _BETWEEN[None, None, :]
    every = np.concatenate([th, mid.reshape(len(th), -1)], axis=1)
    Am = A0[:, None, :] + a[:, None, None] * np.stack([np.cos(every), np.sin(every)], axis=-1)
    d = np.hypot(*np.moveaxis(B0[:, None, :] - Am, -1, 0))
    apart = np.maximum(d - (b + c)[:, None], 0.0) + np.maximum(np.abs(b - c)[:, None] - d, 0.0)
    travel = np.abs(th[:, -1] - th[:, 0])
    return np.concatenate([r, 10 * apart / L, np.maximum(travel - 0.98 * TWO_PI, 0.0)[:, None]], axis=1)


def _problem(pts: np.ndarray, timing: np.ndarray | None, direction: float, sigma: float, L: float) -> tuple:
    """(fun, jac) for scipy: the Jacobian by central differences, all 2n designs in one call."""
    def fun(x: np.ndarray):
        return _residuals(x[None], pts, timing, direction, sigma, L)[0]

    def jac(x: np.ndarray):
        h = 1e-7 * np.maximum(np.abs(x), L)
        E = np.diag(h)
        R = _residuals(np.concatenate([x + E, x - E]), pts, timing, direction, sigma, L)
        return ((R[: len(x)] - R[len(x):]) / (2 * h)[:, None]).T

    return fun, jac


def synthesize_path(points: Sequence[Sequence[float]] | np.ndarray, timing: np.ndarray | None=None, starts: int = 24, seed: int = 0, tolerance: float = 1e-6,
                    name: str = "synthesized_path", polish: int = 6) -> PathResult:
    """A four-bar whose coupler point passes through ``points`` ((x, y) [m]), in that order,
    with the crank angles ``timing`` (relative to the first point [rad]) when given."""
    from scipy.optimize import least_squares

    pts, timing, L = path_points(points, timing)
    n = len(pts)
    if starts < 1:
        raise UsageError("--starts must be at least 1")
    centre = pts.mean(axis=0)
    rng = np.random.default_rng(seed)
    lo = [*(centre - 3 * L), *(centre - 3 * L), 0.05 * L, 0.05 * L, 0.05 * L, -3 * L, -3 * L, -np.inf]
    hi = [*(centre + 3 * L), *(centre + 3 * L), 5 * L, 5 * L, 5 * L, 3 * L, 3 * L, np.inf]
    chords = np.hypot(*np.diff(pts, axis=0).T)
    if timing is None:
        lo += [0.01] * (n - 1)
        hi += [TWO_PI] * (n - 1)
    results, rough = [], []
    for k in range(starts):
        sigma = 1.0 if k % 2 == 0 else -1.0
        direction = 1.0 if (k // 2) % 2 == 0 else -1.0
        x0 = [*(centre + rng.uniform(-1.5, 1.5, 2) * L), *(centre + rng.uniform(-1.5, 1.5, 2) * L),
              rng.uniform(0.1, 0.6) * L, rng.uniform(0.5, 2.0) * L, rng.uniform(0.5, 2.0) * L,
              *rng.uniform(-1, 1, 2) * L, rng.uniform(-np.pi, np.pi)]
        if timing is None:
            total = rng.uniform(0.5, 0.9) * TWO_PI
            x0 += list(np.maximum(total * chords / chords.sum(), 0.02))
        x0 = np.clip(np.array(x0, float), np.array(lo) + 1e-12, np.array(hi) - 1e-12)
        fun, jac = _problem(pts, timing, direction, sigma, L)
        try:  # a first descent, short: starts that end in a local minimum stop early
            sol = least_squares(fun, x0, jac=jac, bounds=(lo, hi), x_scale="jac", xtol=1e-10, ftol=1e-10,
                                gtol=1e-10, max_nfev=30 * len(x0))
        except (ValueError, FloatingPointError):  # pragma: no cover - a degenerate start
            continue
        rough.append((float(sol.cost), sol.x, sigma, direction))
    rough.sort(key=lambda r: r[0])
    enough = 10 * rough[0][0] + 0.5 * n * (tolerance / L) ** 2 if rough else 0.0
    for cost, x1, sigma, direction in rough[:polish]:  # the most promising, polished to round-off
        if cost > enough:  # a local minimum far above the best: not worth polishing
            continue
        fun, jac = _problem(pts, timing, direction, sigma, L)
        sol = least_squares(fun, x1, jac=jac, bounds=(lo, hi), x_scale="jac", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            max_nfev=50 * len(x1))
        A0, B0, a, b, c, p, q, th = _unpack(sol.x, timing, direction)
        P, h2, A, B = (v[0] for v in coupler_points(A0, B0, a, b, c, p, q, th, sigma))
        th = th[0]
        if np.any(h2 < 0):
            continue
        errors = np.hypot(*(P - pts).T)
        results.append((float(errors.max()), sol.x, sigma, direction, errors, A, B, P, th))
    if not results:
        raise SynthesisError(WHAT, f"no start out of {starts} gave a four-bar that assembles at every point")
    good = [r for r in results if r[0] <= tolerance]

    def quality(r: tuple) -> tuple:
        _, x, sigma, direction, errors, A, B, P, th = r
        fb = FourBar(tuple(x[0:2]), tuple(A[0]), tuple(B[0]), tuple(x[2:4]), (*P[0], 0.0))
        res = travel_analysis(fb, th, np.full(len(th), sigma))
        mu = res["mu"]
        worst = max(abs(math.pi / 2 - mu[0]), abs(math.pi / 2 - mu[1])) if mu else math.pi
        return (len(res["defects"]), worst)

    best = min(good, key=quality) if good else min(results, key=lambda r: r[0])
    err, x, sigma, direction, errors, A, B, P, th = best
    design, rel = path_design(pts, x, sigma, A, B, P, th, errors, name)
    return PathResult(tuple(map(tuple, pts.tolist())), None if timing is None else tuple(map(float, timing)),
                      tuple(float(wrap_angle(t, upper=True)) if abs(t) < math.pi else float(t) for t in rel),
                      tuple(map(float, errors)), starts, len(good), tolerance, design)


def path_points(points: Sequence[Sequence[float]] | np.ndarray, timing: np.ndarray | None=None) -> tuple:
    """(points (n, 2), timing relative to the first point or None, the path's size L [m]), checked:
    3 to MAX_POINTS distinct points; one crank angle per point running one way within a turn."""
    pts = np.array(points, float)
    n = len(pts)
    if n < 3:
        raise UsageError(f"--points: path generation needs at least 3 points, got {n}")
    if n > MAX_POINTS:
        raise UsageError(f"--points: at most {MAX_POINTS} points, got {n}")
    L = max(float(np.hypot(*(pts[i] - pts[j]))) for i in range(n) for j in range(i))
    if L <= 0:
        raise UsageError("--points: the points are all the same")
    for i in range(n):
        for j in range(i):
            if np.hypot(*(pts[i] - pts[j])) < DEFAULT.equal * L:
                raise UsageError(f"--points: points {j + 1} and {i + 1} are the same")
    if timing is not None:
        timing = np.asarray(timing, float)
        if len(timing) != n:
            raise UsageError(f"--timing: give one crank angle per point ({n}), got {len(timing)}")
        timing = timing - timing[0]
        if np.any(np.abs(np.diff(timing)) < DEFAULT.equal):
            raise UsageError("--timing: two points have the same crank angle")
        if not (np.all(np.diff(timing) > 0) or np.all(np.diff(timing) < 0)) or abs(timing[-1]) >= TWO_PI:
            raise UsageError("--timing: the crank angles must run one way and within one turn")
    return pts, timing, L


def path_design(pts: np.ndarray, x: np.ndarray, sigma: float, A: np.ndarray, B: np.ndarray, P: np.ndarray, th: np.ndarray, errors: np.ndarray, name: str = "synthesized_path", exact: bool = True) -> tuple:
    """(the Design of the four-bar x (A0, B0, ...: path._unpack's order) drawn at the first point, its
    crank angles from the first point): A, B, P the moving pivots and coupler point at each point;
    ``exact`` False: the points are approximated (least squares), a miss is not a defect."""
    A0, B0 = tuple(map(float, x[0:2])), tuple(map(float, x[2:4]))
    phi1 = math.atan2(B[0][1] - A[0][1], B[0][0] - A[0][0])
    fb = FourBar(A0, tuple(map(float, A[0])), tuple(map(float, B[0])), B0, (float(P[0][0]), float(P[0][1]), phi1))
    lengths = fb.lengths
    rel = th - th[0]
    comment = ("Four-bar synthesized by screwkin for path generation: the point 'coupler_point' passes through\n"
               + "\n".join(f"  {x_:.9g} {y_:.9g} (crank {math.degrees(t):+.6g} deg, off by {e:.3g} m)"
                           for (x_, y_), t, e in zip(pts, rel, errors))
               + f"\nFixed pivots: crank_joint at ({A0[0]:.9g}, {A0[1]:.9g}), rocker_joint at ({B0[0]:.9g}, {B0[1]:.9g}); "
               "lengths [m]: "
               f"ground {lengths['ground']:.9g}, crank {lengths['crank']:.9g}, coupler {lengths['coupler']:.9g}, "
               f"rocker {lengths['rocker']:.9g}.\nDrawn closed at the first point; actuated: crank_joint.")
    linkage = fourbar_linkage(fb, name, comment, tool="coupler_point")
    targets = tuple(Target("point", (float(px), float(py)), float(t), f"point {k + 1}")
                    for k, ((px, py), t) in enumerate(zip(pts, rel)))
    return stored(Design("path", fb, linkage, targets, "crank_joint", "coupler_point", None, exact=exact)), rel
