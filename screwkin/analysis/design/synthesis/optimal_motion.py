"""Constrained, optimal motion generation: the four-bars guiding the coupler frame through the poses
that meet the constraints (analysis.design.synthesis.constraints), best first.

A design is two dyads: fixed pivots A0 (the crank's) and B0, moving pivots a and b in the coupler's
frame.  It is judged as the four-bar it makes, drawn at the first pose and driven: at each pose k
the crank is turned to the angle the crank dyad has there, the coupler-rocker pivot found by circle
intersection on the first pose's branch, and the guided frame compared with the pose (its origin's
miss over the task's size, plus its angle's miss) -- so a pose on another branch, beyond a limit
position or reached in another order is a miss or a penalty, not a silent success.  What varies:

- 3 poses: the two fixed pivots (inside ``--bounds``); the moving pivots follow exactly (motion.py's
  inversion): every design meets the poses, the search looks for the one with the best transmission
  angle that meets the constraints;
- 4 poses: a point on the centre-point curve for each dyad (the angle of a line through a pole and
  which of its two other roots), the moving pivots exactly from it (Burmester);
- 5 poses: the Burmester points, every ordered pair of them (a finite set: no search needed);
- 6 poses or more: the four pivots freely (approximate guidance: least squares of the misses).

One run per crank direction (and, for 4 poses, per pair of roots); each seeded from the seed.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np

from ....errors import UsageError
from .constraints import grashof_type, motion_mu
from .designs import Candidate, Dyad, MotionResult, SynthesisError
from ....model.geometry import circle_circle, wrap_angle
from .fourbar import pose_matrix, travel_analysis
from .motion import _base_pole, _burmester_rows, _check_poses, _positions_of, burmester_points, motion_design, poles, scale_of
from .optimal import MARGIN, PENALTY, PREFER, REFINED, refined, _defect_words, rank_key
from .search import SearchReport, box_text, distinct_best, evolve, run_all, task_seed
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.design.synthesis.constraints import Constraints
    from screwkin.analysis.design.synthesis.search import Search

__all__ = ["optimal_motion", "MAX_POSES"]

#: Most poses motion generation takes (least squares over them beyond 5).
MAX_POSES = 100
#: Crank angles sampled between two consecutive poses to find a configuration that does not assemble.
BETWEEN = 8
TWO_PI = 2 * math.pi


def _frames(poses: list) -> tuple:
    R = np.array([pose_matrix(p)[0] for p in poses])
    p = np.array([p[:2] for p in poses], float)
    th = np.array([p[2] for p in poses], float)
    return R, p, th


def _driven(A0: np.ndarray, a: np.ndarray, B0: np.ndarray, b: np.ndarray, poses: list, direction: float, constraints: Constraints, L: float, equal: float) -> tuple:
    """(miss residuals (m, 2n): origin's miss over L and angle's miss per pose, penalties (m,), mu (lo, hi),
    the crank angles (m, n)) of designs A0, a, B0, b (m, 2) driven through the poses."""
    R, P, TH = _frames(poses)
    Aw = np.einsum("kij,mj->mki", R, a) + P[None]  # moving pivots where the dyads put them (m, n, 2)
    Bw = np.einsum("kij,mj->mki", R, b) + P[None]
    crank = np.hypot(*(Aw[:, 0] - A0).T)
    rocker = np.hypot(*(Bw[:, 0] - B0).T)
    coupler = np.hypot(*(a - b).T)
    th = np.arctan2(Aw[..., 1] - A0[:, None, 1], Aw[..., 0] - A0[:, None, 0])  # crank angle at each pose
    u = Bw[:, 0] - Aw[:, 0]
    w = B0 - Aw[:, 0]
    sigma = np.sign(w[:, 0] * u[:, 1] - w[:, 1] * u[:, 0])  # the first pose's branch (fourbar.branch)
    rel = np.mod(direction * (th - th[:, :1]), TWO_PI)  # travel from the first pose, the crank turning one way
    order = np.maximum(-np.diff(rel, axis=1), 0).sum(axis=1) / TWO_PI  # the poses met in another order

    def at(theta: float | np.ndarray) -> tuple:
        A = A0[:, None, :] + crank[:, None, None] * np.stack([np.cos(theta), np.sin(theta)], -1)
        B, h2 = circle_circle(A, coupler[:, None], B0[:, None, :], rocker[:, None], sigma[:, None])
        return A, B, h2

    A, B, h2 = at(th)
    phi = np.arctan2(B[..., 1] - A[..., 1], B[..., 0] - A[..., 0])  # the coupler's angle (x along a -> b in frame)
    phi_local = np.arctan2(b[:, 1] - a[:, 1], b[:, 0] - a[:, 0])
    turn = phi - phi_local[:, None]  # the frame's angle: the coupler's, less the angle of a -> b in it
    c, s = np.cos(turn), np.sin(turn)
    origin = A - np.stack([c * a[:, None, 0] - s * a[:, None, 1], s * a[:, None, 0] + c * a[:, None, 1]], -1)
    miss = np.hypot(*np.moveaxis(origin - P[None], -1, 0)) / L
    angle = np.abs(wrap_angle(turn - TH[None], upper=True))
    res = np.concatenate([miss, angle], axis=1)
    # every configuration between two poses must assemble (no limit position on the way)
    steps = (np.arange(1, BETWEEN + 1) / (BETWEEN + 1))
    mid = th[:, :1, None] + direction * (rel[:, :-1, None] + np.diff(rel, axis=1)[..., None] * steps)
    _, _, h2m = at(mid.reshape(len(A0), -1))
    apart = (np.maximum(-h2, 0).sum(axis=1) + np.maximum(-h2m, 0).sum(axis=1)) / L ** 2
    g = np.hypot(*(B0 - A0).T)
    phi0 = th[:, 0] - np.arctan2(B0[:, 1] - A0[:, 1], B0[:, 0] - A0[:, 0])
    mu_lo, mu_hi = motion_mu(g, crank, coupler, rocker, phi0, direction * rel[:, -1], equal)
    pen = constraints.penalty(A0, B0, g, crank, coupler, rocker, mu_lo, mu_hi, L) + order + apart
    return res, pen, (mu_lo, mu_hi), th


def _cost(A0: np.ndarray, a: np.ndarray, B0: np.ndarray, b: np.ndarray, poses: list, direction: float, constraints: Constraints, L: float, equal: float) -> np.ndarray:
    res, pen, (lo, hi), _ = _driven(A0, a, B0, b, poses, direction, constraints, L, equal)
    err = np.sqrt((res ** 2).mean(axis=1))
    deviation = np.where(np.isnan(lo), math.pi / 2, np.maximum(math.pi / 2 - lo, hi - math.pi / 2))
    cost = err + PENALTY * pen + PREFER * deviation / (math.pi / 2)
    return np.where(np.isfinite(cost), cost, 1e3)


def _solve2(G: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Batched 2 x 2 (or least-squares) solves, NaN where singular."""
    if G.shape[-2] != 2:
        G, r = np.einsum("mki,mkj->mij", G, G), np.einsum("mki,mk->mi", G, r)
    det = G[:, 0, 0] * G[:, 1, 1] - G[:, 0, 1] * G[:, 1, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.stack([(G[:, 1, 1] * r[:, 0] - G[:, 0, 1] * r[:, 1]) / det,
                      (-G[:, 1, 0] * r[:, 0] + G[:, 0, 0] * r[:, 1]) / det], -1)
    return np.where(np.isfinite(x), x, np.nan)


def _moving(poses: list, A0: np.ndarray) -> np.ndarray:
    """The moving pivots (m, 2) of the dyads with fixed pivots A0 (m, 2) through the poses (3: exactly;
    4: on the centre-point curve, exactly)."""
    M = _burmester_rows(poses, A0)
    return _solve2(M[..., :2], M[..., 2])


def _curve_points(poses: list, alpha: np.ndarray, root: int, L: float):
    """Points (m, 2) of the centre-point curve of four poses on the lines through the base pole at
    angles alpha (m,), the other root ``root`` (0 or 1) of each line's cubic; NaN where complex."""
    P = _base_pole(poses)
    e = np.stack([np.cos(alpha), np.sin(alpha)], -1)
    ts = np.array([-1.0, 1.0, 2.0]) * L
    pts = P + ts[None, :, None] * e[:, None, :]
    f = np.linalg.det(_burmester_rows(poses, pts))
    V = np.stack([ts, ts ** 2, ts ** 3], -1)
    c1, c2, c3 = np.linalg.solve(V, f.T)
    disc = c2 * c2 - 4 * c3 * c1
    with np.errstate(invalid="ignore", divide="ignore"):
        sq = np.sqrt(disc)
        t = np.where(root == 0, (-c2 - sq) / (2 * c3), (-c2 + sq) / (2 * c3))
    return P + t[:, None] * e


def _dyads_of(kind: str, X: np.ndarray, poses: list, L: float, root: tuple[int, int] | None=None) -> tuple:
    """(A0, a, B0, b) of designs X for a kind of run: "pivots" (3 poses), "curve" (4), "free" (6+)."""
    if kind == "pivots":
        A0, B0 = X[:, 0:2], X[:, 2:4]
        return A0, _moving(poses, A0), B0, _moving(poses, B0)
    if kind == "curve":
        A0 = _curve_points(poses, X[:, 0], root[0], L)
        B0 = _curve_points(poses, X[:, 1], root[1], L)
        return A0, _moving(poses, A0), B0, _moving(poses, B0)
    return X[:, 0:2], X[:, 2:4], X[:, 4:6], X[:, 6:8]


def _motion_box(kind: str, poses: list, constraints: Constraints, L: float) -> tuple[np.ndarray, np.ndarray]:
    """The search's box of a kind of run: the pivots inside the bounds (else 2 sizes around the poses),
    the curve parameters in [0, pi], the moving pivots within 3 sizes."""
    plo, phi = constraints.pivot_box(np.mean([p[:2] for p in poses], axis=0), L)
    if kind == "pivots":
        return np.array([*plo, *plo]), np.array([*phi, *phi])
    if kind == "curve":
        return np.zeros(2), np.full(2, math.pi)
    return np.array([*plo, -3 * L, -3 * L, *plo, -3 * L, -3 * L]), np.array([*phi, 3 * L, 3 * L, *phi, 3 * L, 3 * L])


def _motion_run(task: tuple) -> tuple:
    """One run (picklable: what a Dask worker computes): differential evolution, then the refinement of
    its best distinct members (Nelder-Mead on the cost for exact kinds, least squares on the misses
    for free pivots).  Returns ([(A0, a, B0, b, direction)], generations)."""
    from scipy.optimize import minimize

    kind, poses, root, direction, constraints, L, seed, generations, popsize, equal = task
    lower, upper = _motion_box(kind, poses, constraints, L)

    def cost(X: np.ndarray):
        return _cost(*_dyads_of(kind, X, poses, L, root), poses, direction, constraints, L, equal)

    pop, costs, nfev = evolve(cost, lower, upper, seed, generations, popsize)
    tight = constraints.tightened(MARGIN * L, MARGIN)
    out = []
    for k in distinct_best(pop, costs, lower, upper, REFINED):
        x = pop[k]
        if kind == "free":
            def residuals(X: np.ndarray, weight: float) -> np.ndarray:
                res, pen, _, _ = _driven(*_dyads_of(kind, X, poses, L), poses, direction, tight, L, equal)
                return np.concatenate([res, weight * pen[:, None]], axis=1)
            x = refined(residuals, x, lower, upper, L)
        else:
            sol = minimize(lambda x_: float(_cost(*_dyads_of(kind, x_[None], poses, L, root), poses, direction, tight, L,
                                                  equal)[0]), x, method="Nelder-Mead", bounds=list(zip(lower, upper)),
                           options={"xatol": 1e-10 * L, "fatol": 1e-12, "maxiter": 2000})
            x = sol.x if sol.fun <= costs[k] else x
        A0, a, B0, b = (v[0] for v in _dyads_of(kind, x[None], poses, L, root))
        if np.all(np.isfinite([*A0, *a, *B0, *b])):
            out.append((A0, a, B0, b, direction))
    return out, nfev


def _judge_motion(poses: list, A0: np.ndarray, a: np.ndarray, B0: np.ndarray, b: np.ndarray, direction: float, constraints: Constraints, L: float, tol: float, equal: float, run: str, exact: bool) -> tuple | None:
    R1, p1 = pose_matrix(poses[0])
    crank, rocker = Dyad(tuple(map(float, A0)), tuple(map(float, R1 @ a + p1)), tuple(map(float, a))), \
        Dyad(tuple(map(float, B0)), tuple(map(float, R1 @ b + p1)), tuple(map(float, b)))
    if min(crank.length, rocker.length, math.dist(crank.local, rocker.local), math.dist(crank.fixed, rocker.fixed)) \
            < 1e-3 * L:
        return None
    res, _, (lo, hi), th = _driven(A0[None], a[None], B0[None], b[None], poses, direction, constraints, L, equal)
    n = len(poses)
    miss, angle = res[0, :n] * L, res[0, n:]
    design = motion_design(poses, crank, rocker)
    if not exact:
        design = replace(design, exact=False)
    fb = design.fourbar
    thetas, sigmas = _positions_of(poses, crank, rocker)
    found = travel_analysis(fb, thetas, sigmas)
    Lk = fb.lengths
    mu = (float(lo[0]), float(hi[0])) if np.isfinite(lo[0]) else found["mu"]
    kind = grashof_type(Lk["ground"], Lk["crank"], Lk["coupler"], Lk["rocker"], equal)[0]
    defects = tuple(_defect_words(d) for d in found["defects"])
    unmet = tuple(constraints.unmet(fb.A0, fb.B0, Lk["ground"], Lk["crank"], Lk["coupler"], Lk["rocker"], mu, equal,
                                    tol))
    err = float(max(miss.max(), (angle * L).max()))
    return Candidate(design, err, float(np.sqrt(np.mean(miss ** 2))), mu, kind, defects, unmet, run), (crank, rocker)


def optimal_motion(poses: list, constraints: Constraints, search: Search, tolerance: float = 1e-9, equal: float = 1e-9) -> MotionResult:
    """The best four-bars guiding the coupler frame through ``poses`` that meet ``constraints`` (module
    docstring): the MotionResult of the best, its ``search`` report listing the best few."""
    poses = [tuple(float(x) for x in p) for p in poses]
    n = len(poses)
    if n < 3 or n > MAX_POSES:
        raise UsageError(f"--poses: motion generation takes 3 to {MAX_POSES} poses, got {n}")
    _check_poses(poses)
    constraints.check()
    L = scale_of(poses)
    tol = max(tolerance, 1e-9 * L)
    runs, tasks, fixed = [], [], []
    if n == 5:  # the Burmester points: every ordered pair, both crank directions
        dyads = burmester_points(poses)
        for i, j in itertools.permutations(range(len(dyads)), 2):
            for d in (1.0, -1.0):
                fixed.append((np.array(dyads[i].fixed), np.array(dyads[i].local), np.array(dyads[j].fixed),
                              np.array(dyads[j].local), d))
        method = f"the {len(dyads)} Burmester points of the five poses, every ordered pair judged"
    else:
        kind = "pivots" if n == 3 else "curve" if n == 4 else "free"
        roots = [(r1, r2) for r1 in (0, 1) for r2 in (0, 1)] if kind == "curve" else [None]
        for root in roots:
            for d in (1.0, -1.0):
                runs.append(f"crank {'counterclockwise' if d > 0 else 'clockwise'}" + (
                    f", curve roots {root[0] + 1} and {root[1] + 1}" if root else ""))
                tasks.append((kind, poses, root, d, constraints, L, task_seed(search.seed, len(tasks)),
                              search.generations, search.popsize, equal))
        method = {"pivots": "three poses: the fixed pivots searched (the moving pivots follow exactly)",
                  "curve": "four poses: a point of the centre-point curve searched for each dyad (Burmester)",
                  "free": f"{n} poses: the four pivots searched, the misses fitted by least squares"}[kind]
    results, seconds = run_all(search, _motion_run, tasks) if tasks else ([], 0.0)
    evaluations = sum(r[1] for r in results)
    found = [(x, run) for (xs, _), run in zip(results, runs) for x in xs]
    found += [(x, f"crank {'counterclockwise' if x[4] > 0 else 'clockwise'}") for x in fixed]
    cands = []
    for (A0, a, B0, b, d), run in found:
        judged = _judge_motion(poses, A0, a, B0, b, d, constraints, L, tol, equal, run, exact=n <= 5)
        if judged is not None:
            cands.append(judged)
    if not cands:
        raise SynthesisError("synthesize motion", f"the search found no four-bar through the {n} poses")
    cands.sort(key=lambda c: rank_key(c[0], tol))
    best, (crank, rocker) = cands[0]
    report = SearchReport(method + ("" if not tasks else "; differential evolution (scipy, best1bin), then the "
                                                         f"refinement of the best {REFINED} distinct members of each "
                                                         "run"), max(len(tasks), 1), evaluations, seconds, search.where,
                          search.seed, tuple(c[0] for c in cands[:search.best]),
                          box_text(constraints, constraints.pivot_box(np.mean([p[:2] for p in poses], axis=0), L)) if tasks else "")
    pole_list = tuple((i, j, tuple(map(float, P))) for i, j, P in poles(poses))
    return MotionResult(tuple(poses), "constrained search: " + method, (crank, rocker), (0, 1), best.design, (),
                        pole_list, (), report)
