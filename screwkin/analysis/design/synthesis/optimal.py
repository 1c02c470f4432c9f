"""Constrained, optimal synthesis of four-bars: the best linkages that meet what a designer states
(analysis.design.synthesis.constraints), by a seeded global search and the exact local refinement
(analysis.design.synthesis.search), each design judged in closed form and listed, the best written
and checked with screwkin's own analyses by the caller (check.check_design).

Path generation (``optimal_path``), the unknowns the fixed pivots A0, B0, the crank a, coupler b,
rocker c and the coupler point (p, q) in the coupler's frame, and, with ``timing``, the crank angle
at the first point:

- without timing, the global search measures each point's distance to the coupler curve (the
  coupler point at 180 crank angles of a turn, on one branch): the points must be met in order, the
  crank turning one way less than a turn, never through a configuration that does not assemble
  (penalties); the refinement is path.py's least squares with the crank angles as unknowns,
  started from the nearest samples;
- with timing, the coupler point at the prescribed crank angles.

One run per branch (the side of A -> B0 the coupler-rocker pivot is on) and crank direction.  The
cost is the root mean square miss over the path's size, plus the constraints' penalties (x 10), plus
1 % of the worst transmission-angle deviation from 90 deg over the motion (a preference among the
designs that pass through the points, which a least-squares fit alone leaves open).
"""

from __future__ import annotations

import math

import numpy as np

from .constraints import grashof_type, motion_mu
from .designs import Candidate, PathResult, SynthesisError
from ....model.geometry import wrap_angle
from .fourbar import travel_analysis
from .path import _residuals, _unpack, coupler_points, path_design, path_points
from .search import SearchReport, box_text, distinct_best, evolve, run_all, task_seed
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.design.synthesis.constraints import Constraints
    from screwkin.analysis.design.synthesis.search import Search
    from collections.abc import Callable

__all__ = ["optimal_path", "PENALTY", "SAMPLES"]

#: Weight of the constraints' penalties against the relative miss in the search, and in the refinement
#: (where a design settles on a constraint's edge: heavy, so that it stays within the margin).
PENALTY = 10.0
PENALTY_REFINED = 1e4
#: Weight of the transmission angle's worst deviation from 90 deg (over pi/2) in the search's cost.
PREFER = 0.01
#: Crank angles of a turn at which the search measures the coupler curve.
SAMPLES = 180
#: Members of each run's final population refined (the best, apart from each other).
REFINED = 3
#: The refinement's evaluations at most, per unknown (its Jacobian is one batched evaluation); beyond
#: EXACT_UNKNOWNS unknowns (crank angles of many points) its trust-region steps are solved by LSMR (no SVD:
#: OpenBLAS's threads made a dense SVD of 240 x 49 take 8-48 ms on the shared cores, 1 ms on one thread).
REFINE_EVALUATIONS = 30
EXACT_UNKNOWNS = 40
#: The refinement's margin inside the constraints (times the path's size; in rad for the transmission angle).
MARGIN = 1e-6
#: Most points the global search measures (evenly chosen; the refinement fits them all).
SEARCHED = 24
TWO_PI = 2 * math.pi


def _path_box(pts: np.ndarray, constraints: Constraints, L: float) -> tuple[np.ndarray, np.ndarray]:
    """The search's box: the pivots inside the bounds (else 2 path sizes around the points), the links
    within the length range (else 2 % of the path's size to 4 times it), the coupler point within 3 sizes."""
    plo, phi = constraints.pivot_box(pts.mean(axis=0), L)
    llo, lhi = constraints.lengths if constraints.lengths is not None else (0.02 * L, 4 * L)
    lower = [*plo, *plo, llo, llo, llo, -3 * L, -3 * L]
    upper = [*phi, *phi, lhi, lhi, lhi, 3 * L, 3 * L]
    return np.array(lower, float), np.array(upper, float)


def _box(pts: np.ndarray, constraints: Constraints, L: float) -> str:
    """_path_box in words."""
    lower, upper = _path_box(pts, constraints, L)
    return box_text(constraints, (lower[0:2], upper[0:2]), (lower[4], upper[4])) + f"; coupler point within {3 * L:.4g} m"


def _free_cost(X: np.ndarray, pts: np.ndarray, sigma: float, direction: float, constraints: Constraints, L: float, equal: float) -> tuple:
    """The search's cost of designs X (m, 9) without timing (module docstring), and each point's
    nearest sample (m, n)."""
    A0, B0 = X[:, 0:2], X[:, 2:4]
    a, b, c, p, q = X[:, 4:9].T
    th = np.arange(SAMPLES) * (TWO_PI / SAMPLES)
    P, h2, _, _ = coupler_points(A0, B0, a, b, c, p, q, np.broadcast_to(th, (len(X), SAMPLES)), sigma)
    ok = h2 >= 0
    # squared distances (m, n, samples) as |P|^2 - 2 P.t + |t|^2 (one product, not an array of differences)
    d2 = (P * P).sum(-1)[:, None, :] - 2 * np.einsum("msk,nk->mns", P, pts) + (pts * pts).sum(-1)[None, :, None]
    d2 = np.where(ok[:, None, :], np.maximum(d2, 0.0), np.inf)
    j = np.argmin(d2, axis=2)
    err = np.sqrt(np.take_along_axis(d2, j[..., None], 2)[..., 0].mean(axis=1)) / L
    steps = np.mod((j[:, 1:] - j[:, :-1]) * direction, SAMPLES)
    total = steps.sum(axis=1)
    order = np.maximum(total - SAMPLES, 0) / SAMPLES  # more than a turn: not in the order given
    # a configuration that does not assemble between two consecutive points: a limit position on the way
    bad = (~ok).astype(int)
    if direction < 0:
        bad = bad[:, ::-1]
        jj = SAMPLES - 1 - j
    else:
        jj = j
    cum = np.concatenate([np.zeros((len(X), 1), int), np.cumsum(np.concatenate([bad, bad], axis=1), axis=1)], axis=1)
    start = jj[:, :-1]
    stop = start + np.mod(jj[:, 1:] - jj[:, :-1], SAMPLES)
    gaps = (np.take_along_axis(cum, stop + 1, 1) - np.take_along_axis(cum, start, 1) > 0).mean(axis=1)
    g = np.hypot(*(B0 - A0).T)
    phi0 = th[j[:, 0]] - np.arctan2(B0[:, 1] - A0[:, 1], B0[:, 0] - A0[:, 0])
    mu_lo, mu_hi = motion_mu(g, a, b, c, phi0, direction * total * (TWO_PI / SAMPLES), equal)
    pen = constraints.penalty(A0, B0, g, a, b, c, mu_lo, mu_hi, L)
    deviation = np.where(np.isnan(mu_lo), math.pi / 2, np.maximum(math.pi / 2 - mu_lo, mu_hi - math.pi / 2))
    cost = err + PENALTY * (pen + order + gaps) + PREFER * deviation / (math.pi / 2)
    return np.where(np.isfinite(cost), cost, 1e3), j


def _timed_cost(X: np.ndarray, pts: np.ndarray, timing: np.ndarray | None, sigma: float, constraints: Constraints, L: float, equal: float) -> np.ndarray:
    """The search's cost of designs X (m, 10) with the crank angles prescribed."""
    A0, B0, a, b, c, p, q, th = _unpack(X, timing, 1.0)
    R = _residuals(X, pts, timing, 1.0, sigma, L)
    n = len(pts)
    err = np.sqrt((R[:, :2 * n] ** 2).sum(axis=1) / n)
    apart = R[:, 2 * n:].sum(axis=1)
    g = np.hypot(*(B0 - A0).T)
    phi0 = th[:, 0] - np.arctan2(B0[:, 1] - A0[:, 1], B0[:, 0] - A0[:, 0])
    mu_lo, mu_hi = motion_mu(g, a, b, c, phi0, th[:, -1] - th[:, 0], equal)
    pen = constraints.penalty(A0, B0, g, a, b, c, mu_lo, mu_hi, L)
    deviation = np.where(np.isnan(mu_lo), math.pi / 2, np.maximum(math.pi / 2 - mu_lo, mu_hi - math.pi / 2))
    cost = err + PENALTY * (pen + apart) + PREFER * deviation / (math.pi / 2)
    return np.where(np.isfinite(cost), cost, 1e3)


def refined(residuals: Callable[..., np.ndarray], x0: np.ndarray, lower: np.ndarray, upper: np.ndarray, scale: float, weights: tuple[float, ...]=(PENALTY, PENALTY_REFINED)):
    """Least squares of ``residuals(X, weight)`` (designs X (m, d) -> (m, r), the penalty residual weighted)
    from x0 within [lower, upper]: first with the search's weight, then, when a constraint is still missed,
    again from there with a heavy one (a design that settles on a constraint's edge then stays on its side,
    which the margin of the tightened constraints keeps it inside)."""
    from scipy.optimize import least_squares

    x = np.clip(x0, lower + 1e-12 * scale, upper - 1e-12 * scale)
    for k, w in enumerate(weights):
        def fun(x_: np.ndarray, w: float=w):
            return residuals(x_[None], w)[0]

        def jac(x_: np.ndarray, w: float=w):
            h = 1e-7 * np.maximum(np.abs(x_), scale)
            E = np.diag(h)
            R = residuals(np.concatenate([x_ + E, x_ - E]), w)
            return ((R[: len(x_)] - R[len(x_):]) / (2 * h)[:, None]).T

        sol = least_squares(fun, x, jac=jac, bounds=(lower, upper), x_scale="jac", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            max_nfev=(REFINE_EVALUATIONS if k == 0 else REFINE_EVALUATIONS // 3) * max(len(x), 10),
                            tr_solver="exact" if len(x) <= EXACT_UNKNOWNS else "lsmr")
        x = sol.x
        if not residuals(x[None], 1.0)[0, -1] > 0:  # no constraint missed (the last residual: the penalty)
            break
    return x


def _refine(x0: np.ndarray, pts: np.ndarray, timing: np.ndarray | None, direction: float, sigma: float, constraints: Constraints, L: float, lower: np.ndarray, upper: np.ndarray, equal: float):
    """path.py's least squares from x0 (its parameter order), with the constraints' penalty as one more
    residual; the pivots and links kept in the search's box."""
    n = len(pts)
    constraints = constraints.tightened(MARGIN * L, MARGIN)  # on the right side of a constraint it settles on

    def residuals(X: np.ndarray, weight: float) -> np.ndarray:
        R = _residuals(X, pts, timing, direction, sigma, L)
        A0, B0, a, b, c, _, _, th = _unpack(X, timing, direction)
        g = np.hypot(*(B0 - A0).T)
        phi0 = th[:, 0] - np.arctan2(B0[:, 1] - A0[:, 1], B0[:, 0] - A0[:, 0])
        mu_lo, mu_hi = motion_mu(g, a, b, c, phi0, th[:, -1] - th[:, 0], equal)
        pen = constraints.penalty(A0, B0, g, a, b, c, mu_lo, mu_hi, L)
        return np.concatenate([R, weight * pen[:, None]], axis=1)

    lo = np.concatenate([lower[:9], [-np.inf], [0.01] * (n - 1) if timing is None else []])
    hi = np.concatenate([upper[:9], [np.inf], [TWO_PI] * (n - 1) if timing is None else []])
    lo[7:9], hi[7:9] = -np.inf, np.inf  # the coupler point: anywhere on the coupler
    return refined(residuals, x0, lo, hi, L)


def _path_run(task: tuple) -> tuple:
    """One run of the path search (picklable: what a Dask worker computes): differential evolution (on
    at most SEARCHED points, evenly chosen, when there are more), then the refinement of its best
    distinct members on all the points.  Returns ([(x, sigma, direction)], generations)."""
    pts, timing, sigma, direction, constraints, L, seed, generations, popsize, equal = task
    lower, upper = _path_box(pts, constraints, L)
    few = np.unique(np.linspace(0, len(pts) - 1, min(len(pts), SEARCHED)).round().astype(int))
    if timing is None:
        def cost(X: np.ndarray):
            return _free_cost(X, pts[few], sigma, direction, constraints, L, equal)[0]
        lo, hi = lower, upper
    else:
        def cost(X: np.ndarray):
            return _timed_cost(X, pts[few], timing[few] - timing[few[0]], sigma, constraints, L, equal)
        lo, hi = np.append(lower, -math.pi), np.append(upper, math.pi)
    pop, costs, nfev = evolve(cost, lo, hi, seed, generations, popsize)
    out = []
    for k in distinct_best(pop, costs, lo, hi, REFINED if len(pts) <= SEARCHED else 1):  # (many points: the best)
        x = pop[k]
        if timing is None:  # the crank angle at every point from its nearest sample of the coupler curve
            j = _free_cost(x[None], pts, sigma, direction, constraints, L, equal)[1][0]
            th = j * (TWO_PI / SAMPLES)
            steps = np.maximum(np.mod(direction * np.diff(th), TWO_PI), 0.02)
            x0 = np.concatenate([x, [th[0]], steps])
        else:
            x0 = x
        out.append((_refine(x0, pts, timing, direction, sigma, constraints, L, lower, upper, equal), sigma, direction))
    return out, nfev


def _judge(pts: np.ndarray, x: np.ndarray, sigma: float, direction: float, timing: np.ndarray | None, constraints: Constraints, L: float, tol: float, equal: float, run: str) -> tuple | None:
    """A refined design as a Candidate (closed form: errors, motion, defects, constraints)."""
    A0, B0, a, b, c, p, q, th = _unpack(x, timing, direction)
    P, h2, A, B = (v[0] for v in coupler_points(A0, B0, a, b, c, p, q, th, sigma))
    th = th[0]
    if np.any(h2 < 0):
        return None
    errors = np.hypot(*(P - pts).T)
    design, rel = path_design(pts, x, sigma, A, B, P, th, errors, exact=bool(errors.max() <= tol))
    fb = design.fourbar
    res = travel_analysis(fb, th, np.full(len(th), sigma))
    L4 = fb.lengths
    g, a_, b_, c_ = L4["ground"], L4["crank"], L4["coupler"], L4["rocker"]
    kind = grashof_type(g, a_, b_, c_, equal)[0]
    phi0 = float(th[0] - math.atan2(B0[0][1] - A0[0][1], B0[0][0] - A0[0][0]))
    lo, hi = motion_mu(g, a_, b_, c_, phi0, float(th[-1] - th[0]), equal)
    mu = (float(lo), float(hi)) if np.isfinite(lo) else res["mu"]
    defects = tuple(_defect_words(d) for d in res["defects"])
    unmet = tuple(constraints.unmet(fb.A0, fb.B0, g, a_, b_, c_, mu, equal, tol))
    return Candidate(design, float(errors.max()), float(np.sqrt(np.mean(errors ** 2))), mu, kind, defects, unmet,
                     run), errors, rel


def _defect_words(d: tuple) -> str:
    kind, k, detail = d
    if kind == "branch":
        return f"branch: point {k + 1} is on another branch"
    if kind == "limit":
        return f"limit: a limit position stops the crank before point {k + 1}" if k is not None else \
            "limit: a limit position stops the crank"
    return "order: the points are not met in the order given"


def rank_key(cand: Candidate, tol: float) -> tuple:
    """Feasible first, then without defects, then the miss (within ``tol`` counted as none), then the
    transmission angle's worst deviation from 90 deg."""
    mu = cand.transmission
    deviation = max(math.pi / 2 - mu[0], mu[1] - math.pi / 2) if mu else math.pi
    return (not cand.feasible, len(cand.defects), max(cand.error - tol, 0.0), deviation, cand.error)


def optimal_path(points, timing: np.ndarray | None, constraints: Constraints, search: Search, tolerance: float = 1e-6, equal: float = 1e-9) -> PathResult:
    """The best four-bars whose coupler point passes through ``points`` (with the crank angles
    ``timing`` when given) that meet ``constraints``, found by ``search`` (module docstring); the
    PathResult of the best, its ``search`` report listing the best few (Candidates)."""
    pts, timing, L = path_points(points, timing)
    constraints.check()
    directions = (1.0, -1.0) if timing is None else (1.0,)
    runs = [(s, d) for s in (1.0, -1.0) for d in directions]
    tasks = [(pts, timing, s, d, constraints, L, task_seed(search.seed, k), search.generations, search.popsize, equal)
             for k, (s, d) in enumerate(runs)]
    results, seconds = run_all(search, _path_run, tasks)
    cands, evaluations = [], 0
    for (s, d), (found, nfev) in zip(runs, results):
        evaluations += nfev
        run = f"branch {'+' if s > 0 else '-'}" + ("" if timing is not None else
                                                   f", crank {'counterclockwise' if d > 0 else 'clockwise'}")
        for x, sigma, direction in found:
            judged = _judge(pts, x, sigma, direction, timing, constraints, L, tolerance, equal, run)
            if judged is not None:
                cands.append((judged, x, sigma, direction))
    if not cands:
        raise SynthesisError("synthesize path", f"no run of the search found a four-bar that assembles at every point "
                                                f"({len(runs)} runs, {evaluations} designs evaluated)")
    cands.sort(key=lambda c: rank_key(c[0][0], tolerance))
    (best, errors, rel), x, sigma, direction = cands[0]
    listed = tuple(c[0][0] for c in cands[:search.best])
    report = SearchReport(f"differential evolution (scipy, best1bin, population {search.popsize} x dimensions, at most "
                          f"{search.generations} generations), then least squares from the best "
                          f"{REFINED} distinct members of each run", len(runs), evaluations, seconds, search.where,
                          search.seed, listed, _box(pts, constraints, L))
    return PathResult(tuple(map(tuple, pts.tolist())), None if timing is None else tuple(map(float, timing)),
                      tuple(float(wrap_angle(t, upper=True)) if abs(t) < math.pi else float(t) for t in rel),
                      tuple(map(float, errors)),
                      len(runs), sum(c[0][0].error <= tolerance for c in cands), tolerance, best.design, report)

