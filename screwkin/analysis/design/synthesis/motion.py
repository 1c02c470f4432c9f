"""Motion generation (rigid-body guidance) of a four-bar: the coupler frame through 3, 4 or
5 given poses.

A dyad is a fixed pivot A0 (centre point) and a moving pivot a, fixed in the coupler
frame (circle point): the positions T_i a of the moving pivot lie on a circle about A0,

    |T_i a - A0|^2 = |T_1 a - A0|^2,   T_i a = R_i a + p_i,

which is linear in a for a given A0 (the inversion method):

    2 a . (R_i^T (p_i - A0) - R_1^T (p_1 - A0)) = |p_1 - A0|^2 - |p_i - A0|^2.

- three positions, fixed pivots given: two equations (i = 2, 3) in a, one dyad per pivot;
- three positions, moving pivots given: A0 is the centre of the circle through T_1 a, T_2 a, T_3 a;
- four positions (Burmester): three equations in two unknowns have a solution when the
  3 x 3 determinant D(A0) of [2 g_i | -rhs_i] vanishes: a cubic in A0, the centre-point
  curve (the circle points of its dyads make the circle-point curve).  Every pole P_ij of
  the displacements lies on it; the curve is traced by lines through one pole P: along
  each line D is a cubic in the distance t from P with the root t = 0, the other two roots
  are points of the curve;
- five positions: the Burmester points are the centre points common to the curves of the
  subsets (1, 2, 3, 4) and (1, 2, 3, 5) that are not poles: Newton on the two cubics from
  points of the first curve; each is kept when its moving pivot puts all five positions on
  one circle.

Pairs of dyads make four-bars; the first dyad of a pair is the crank (the input).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ....errors import UsageError
from ....model.geometry import TINY, wrap_angle
from ....tolerances import DEFAULT
from .designs import Design, Dyad, FourBar, MotionResult, SynthesisError, Target
from .fourbar import angle, branch, fourbar_linkage, pose_matrix, stored, travel_analysis

__all__ = ["moving_pivot", "fixed_pivot", "poles", "centre_point_curve", "dyad_candidates", "burmester_points",
           "rank_pairs", "motion_design", "fourbar_from_dyads", "scale_of"]

WHAT = "synthesize motion"


def scale_of(poses: list) -> float:
    """The size of the task: the largest distance between two pose origins (or 1 m)."""
    P = np.array([p[:2] for p in poses], float)
    d = max((float(np.hypot(*(P[i] - P[j]))) for i in range(len(P)) for j in range(i)), default=0.0)
    return d if d > 0 else 1.0


def _burmester_rows(poses: list, A0: np.ndarray) -> np.ndarray:
    """The rows [2 g_i, rhs_i] (i = 2..n) at fixed pivots A0 (..., 2): shape (..., n-1, 3)."""
    A0 = np.asarray(A0, float)
    R1, p1 = pose_matrix(poses[0])
    rows = []
    for pose in poses[1:]:
        Ri, pi = pose_matrix(pose)
        g = (pi - A0) @ Ri - (p1 - A0) @ R1  # row-vector form of R^T (p - A0)
        rhs = ((p1 - A0) ** 2).sum(-1) - ((pi - A0) ** 2).sum(-1)
        rows.append(np.concatenate([2 * g, rhs[..., None]], axis=-1))
    return np.stack(rows, axis=-2)


def moving_pivot(poses: list, A0: np.ndarray, what: str = WHAT) -> np.ndarray:
    """The moving pivot (coupler frame) of the dyad with fixed pivot A0 through three poses."""
    M = _burmester_rows(poses[:3], A0)
    G, r = M[:, :2], M[:, 2]
    scale = scale_of(poses)
    if abs(np.linalg.det(G)) < DEFAULT.zero * max(np.abs(G).max(), TINY) ** 2 or np.abs(G).max() < DEFAULT.zero * scale:
        raise SynthesisError(what, f"no moving pivot for the fixed pivot ({A0[0]:.6g}, {A0[1]:.6g}): it is a pole "
                                   "of the displacements or the positions are degenerate; move the pivot")
    return np.linalg.solve(G, r)


def fixed_pivot(poses: list, local, what: str = WHAT) -> np.ndarray:
    """The fixed pivot of a dyad whose moving pivot is ``local`` in the coupler frame: the centre
    of the circle through its three positions."""
    W = [pose_matrix(p)[0] @ np.asarray(local, float) + pose_matrix(p)[1] for p in poses[:3]]
    (x1, y1), (x2, y2), (x3, y3) = W
    M = np.array([[x2 - x1, y2 - y1], [x3 - x1, y3 - y1]])
    r = 0.5 * np.array([x2**2 - x1**2 + y2**2 - y1**2, x3**2 - x1**2 + y3**2 - y1**2])
    span = max(float(np.hypot(x2 - x1, y2 - y1)), float(np.hypot(x3 - x1, y3 - y1)), 1e-300)
    if abs(np.linalg.det(M)) < 1e-10 * span**2:
        raise SynthesisError(what, f"the moving pivot ({local[0]:.6g}, {local[1]:.6g}) moves on a straight line "
                                   "through the three positions: no circle (a slider would guide it); move the pivot")
    return np.linalg.solve(M, r)


def poles(poses: list) -> list:
    """(i, j, P) for each pair of positions whose displacement turns (a translation has its
    pole at infinity): P is the point that T_j T_i^-1 leaves in place."""
    out = []
    for i, j in itertools.combinations(range(len(poses)), 2):
        Ri, pi = pose_matrix(poses[i])
        Rj, pj = pose_matrix(poses[j])
        R = Rj @ Ri.T
        t = pj - R @ pi
        M = np.eye(2) - R
        if abs(np.linalg.det(M)) > DEFAULT.zero:
            out.append((i, j, np.linalg.solve(M, t)))
    return out


def _base_pole(poses: list) -> np.ndarray:
    """A pole P_1k (on the centre-point curve of these positions: its row vanishes), the one
    of the largest turn."""
    best = None
    for k in range(1, len(poses)):
        turn = abs(float(wrap_angle(poses[k][2] - poses[0][2], upper=True)))
        if turn > DEFAULT.equal and (best is None or turn > best[0]):
            best = (turn, k)
    if best is None:
        raise SynthesisError(WHAT, "the coupler does not turn between the positions (pure translations): "
                                   "no centre-point curve; a parallelogram guides a translating coupler")
    R1, p1 = pose_matrix(poses[0])
    Rk, pk = pose_matrix(poses[best[1]])
    R = Rk @ R1.T
    return np.linalg.solve(np.eye(2) - R, pk - R @ p1)


def centre_point_curve(poses: list, directions: int = 360, bound: float | None = None) -> tuple:
    """Points of the centre-point curve of four poses and their circle points (world, first
    position): (centre points (m, 2), circle points (m, 2), local moving pivots (m, 2),
    direction index (m,)), ordered by the direction of the line through the base pole and,
    on each, by distance.  ``bound``: keep points within this distance of the poses' centroid."""
    poses = list(poses)[:4]
    P = _base_pole(poses)
    L = scale_of(poses)
    centre = np.mean([p[:2] for p in poses], axis=0)
    bound = bound if bound is not None else 1e3 * L
    alphas = np.arange(directions) * np.pi / directions
    e = np.stack([np.cos(alphas), np.sin(alphas)], axis=-1)  # (m, 2)
    ts = np.array([-1.0, 1.0, 2.0]) * L
    pts = P + ts[None, :, None] * e[:, None, :]  # (m, 3, 2)
    f = np.linalg.det(_burmester_rows(poses, pts))  # (m, 3): f(t) = c1 t + c2 t^2 + c3 t^3
    V = np.stack([ts, ts**2, ts**3], axis=-1)
    coef = np.linalg.solve(V, f.T).T  # (m, 3)
    out_c, out_idx = [], []
    for k, (c1, c2, c3) in enumerate(coef):
        roots = np.roots([c3, c2, c1]) if abs(c3) > 0 or abs(c2) > 0 else np.array([])
        for t in sorted(r.real for r in roots if abs(r.imag) <= DEFAULT.equal * max(abs(r), 1.0)):
            if abs(t) < DEFAULT.equal * L:
                continue
            A0 = P + t * e[k]
            if np.hypot(*(A0 - centre)) <= bound:
                out_c.append(A0)
                out_idx.append(k)
    C = np.array(out_c).reshape(-1, 2)
    local, circle = _circle_points(poses, C)
    keep = np.all(np.isfinite(local), axis=1) & (np.hypot(*(circle - centre).T) <= bound)
    return C[keep], circle[keep], local[keep], np.array(out_idx, int)[keep]


def _circle_points(poses: list, C: np.ndarray) -> tuple:
    """Moving pivots (local, and world at the first position) of the dyads with fixed pivots C
    (least squares of the linear equations; exact on the curve)."""
    if len(C) == 0:
        return np.zeros((0, 2)), np.zeros((0, 2))
    M = _burmester_rows(poses, C)
    G, r = M[..., :2], M[..., 2]
    local = np.full((len(C), 2), np.nan)
    for k in range(len(C)):
        sol, *_ = np.linalg.lstsq(G[k], r[k], rcond=None)
        local[k] = sol
    R1, p1 = pose_matrix(poses[0])
    return local, local @ R1.T + p1


def dyad_candidates(poses: list, count: int = 24, bound: float | None = None) -> tuple:
    """Dyads of four positions for a list to choose from: the curve traced with ``count``
    lines through the base pole, points within ``bound`` (default 3 times the size of the
    task) of the poses' centroid, neither link shorter than 2 % of the task's size."""
    L = scale_of(poses)
    C, W, local, _ = centre_point_curve(poses, count, bound if bound is not None else 3 * L)
    out = []
    for c, w, a in zip(C, W, local):
        if np.hypot(*(w - c)) < 0.02 * L:
            continue
        out.append(Dyad(tuple(map(float, c)), tuple(map(float, w)), tuple(map(float, a))))
    return tuple(out)


def _D(poses4: list, X: np.ndarray):
    return np.linalg.det(_burmester_rows(poses4, X))


def burmester_points(poses: list, seeds: int = 360) -> tuple:
    """The Burmester points of five poses as dyads (at most four)."""
    poses = list(poses)[:5]
    L = scale_of(poses)
    first, second = poses[:4], poses[:3] + [poses[4]]
    C, _, _, _ = centre_point_curve(first, seeds, 1e3 * L)
    X = C.copy()
    h = 1e-6 * L
    for _ in range(60):
        F = np.stack([_D(first, X), _D(second, X)], axis=-1)
        J = np.empty((len(X), 2, 2))
        for j in range(2):
            dX = np.zeros(2)
            dX[j] = h
            J[:, 0, j] = (_D(first, X + dX) - _D(first, X - dX)) / (2 * h)
            J[:, 1, j] = (_D(second, X + dX) - _D(second, X - dX)) / (2 * h)
        det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
        ok = np.abs(det) > TINY  # division guard
        step = np.zeros_like(X)
        step[ok, 0] = (J[ok, 1, 1] * F[ok, 0] - J[ok, 0, 1] * F[ok, 1]) / det[ok]
        step[ok, 1] = (-J[ok, 1, 0] * F[ok, 0] + J[ok, 0, 0] * F[ok, 1]) / det[ok]
        size = np.hypot(*step.T)
        step *= np.minimum(1.0, 0.5 * L / np.maximum(size, 1e-300))[:, None]  # no leaps across the plane
        X = X - step
        if np.all(size < 1e-15 * L):
            break
    pole_pts = [P for i, j, P in poles(poses)]
    found = []
    for x in X:
        if not np.all(np.isfinite(x)) or np.hypot(*x) > 1e3 * L:
            continue
        if any(np.hypot(*(x - P)) < DEFAULT.geometry * L for P in pole_pts):
            continue
        if any(np.hypot(*(x - y)) < 1e-7 * L for y in found):
            continue
        M = _burmester_rows(poses, x)
        G, r = M[:, :2], M[:, 2]
        a, *_ = np.linalg.lstsq(G, r, rcond=None)
        if np.linalg.matrix_rank(G, tol=DEFAULT.equal * max(np.abs(G).max(), TINY)) < 2:
            continue
        if np.abs(G @ a - r).max() > DEFAULT.equal * max(np.abs(r).max(), L * L):
            continue
        # the five positions of the moving pivot on one circle about x
        R1, p1 = pose_matrix(poses[0])
        radii = [np.hypot(*(pose_matrix(p)[0] @ a + pose_matrix(p)[1] - x)) for p in poses]
        if max(radii) - min(radii) > 1e-8 * max(max(radii), L):
            continue
        found.append(x)
    out = []
    for x in found:
        M = _burmester_rows(poses, x)
        a, *_ = np.linalg.lstsq(M[:, :2], M[:, 2], rcond=None)
        R1, p1 = pose_matrix(poses[0])
        out.append(Dyad(tuple(map(float, x)), tuple(map(float, R1 @ a + p1)), tuple(map(float, a))))
    out.sort(key=lambda d: (d.fixed[0], d.fixed[1]))
    return tuple(out)


def fourbar_from_dyads(poses: list, crank: Dyad, rocker: Dyad) -> FourBar:
    return FourBar(tuple(crank.fixed), tuple(crank.moving), tuple(rocker.moving), tuple(rocker.fixed),
                   tuple(float(x) for x in poses[0]))


def _positions_of(poses: list, crank: Dyad, rocker: Dyad) -> tuple[np.ndarray, np.ndarray]:
    """Crank angles and branches of the four-bar at each pose (from the dyads themselves)."""
    thetas, sigmas = [], []
    for pose in poses:
        R, p = pose_matrix(pose)
        A = R @ np.array(crank.local) + p
        B = R @ np.array(rocker.local) + p
        thetas.append(angle(A - np.array(crank.fixed)))
        sigmas.append(float(branch(A, B, rocker.fixed)))
    return np.array(thetas), np.array(sigmas)


def targets_of(poses: list, crank: Dyad) -> tuple:
    thetas = []
    for pose in poses:
        R, p = pose_matrix(pose)
        thetas.append(angle(R @ np.array(crank.local) + p - np.array(crank.fixed)))
    return tuple(Target("pose", tuple(float(x) for x in pose), float(wrap_angle(t - thetas[0], upper=True)),
                        f"position {k + 1}")
                 for k, (pose, t) in enumerate(zip(poses, thetas)))


def rank_pairs(poses: list, dyads: list, limit: int | None = None) -> list:
    """Every ordered pair (crank i, rocker j) of dyads, best first, in closed form
    (fourbar.travel_analysis): pairs without defects first, then by the worst transmission
    angle over the motion (the largest |90 deg - mu|).  Pairs whose ground is shorter than
    2 % of the task are left out.  Returns [(i, j, defects, (mu_min, mu_max))]."""
    L = scale_of(poses)
    scored = []
    for i, j in itertools.permutations(range(len(dyads)), 2):
        ci, cj = dyads[i], dyads[j]
        if math.dist(ci.fixed, cj.fixed) < 0.02 * L or math.dist(ci.moving, cj.moving) < 0.02 * L:
            continue
        thetas, sigmas = _positions_of(poses, ci, cj)
        if not np.all(sigmas != 0):
            continue
        fb = fourbar_from_dyads(poses, ci, cj)
        res = travel_analysis(fb, thetas, sigmas)
        mu = res["mu"]
        worst = max(abs(math.pi / 2 - mu[0]), abs(math.pi / 2 - mu[1])) if mu else math.pi
        scored.append((len(res["defects"]), worst, i, j, tuple(res["defects"]), mu))
    scored.sort(key=lambda s: (s[0], s[1]))
    return [(i, j, d, mu) for _, _, i, j, d, mu in scored[:limit]]


def motion_design(poses: list | tuple, crank: Dyad, rocker: Dyad, name: str = "synthesized_motion", notes: tuple=()) -> Design:
    """The four-bar of two dyads drawn at the first pose, with its targets."""
    fb = fourbar_from_dyads(poses, crank, rocker)
    L = fb.lengths
    comment = ("Four-bar synthesized by screwkin for motion generation (rigid-body guidance):\n"
               f"the frame 'coupler_frame' passes through {len(poses)} poses (x y theta, m and deg):\n"
               + "\n".join(f"  {p[0]:.9g} {p[1]:.9g} {math.degrees(p[2]):.9g}" for p in poses)
               + f"\nFixed pivots: crank_joint at ({fb.A0[0]:.9g}, {fb.A0[1]:.9g}), rocker_joint at ({fb.B0[0]:.9g}, "
               f"{fb.B0[1]:.9g});"
               f"\nlengths [m]: ground {L['ground']:.9g}, crank {L['crank']:.9g}, coupler {L['coupler']:.9g}, "
               f"rocker {L['rocker']:.9g}.\nDrawn closed at the first pose; actuated: crank_joint.")
    linkage = fourbar_linkage(fb, name, comment, tool="coupler_frame")
    return stored(Design("motion", fb, linkage, targets_of(poses, crank), "crank_joint", "coupler_frame", None,
                         tuple(notes)))


def _check_poses(poses: list) -> None:
    L = scale_of(poses)
    for i, j in itertools.combinations(range(len(poses)), 2):
        a, b = poses[i], poses[j]
        if math.hypot(a[0] - b[0], a[1] - b[1]) < DEFAULT.equal * L \
                and abs(float(wrap_angle(a[2] - b[2], upper=True))) < DEFAULT.equal:
            raise UsageError(f"--poses: positions {i + 1} and {j + 1} are the same pose: give distinct poses")


def synthesize_motion(poses: list, pivots: list | None=None, moving=None, pick=None, count: int = 24) -> MotionResult:
    """Dyads for the poses and the pair to build: three poses with ``pivots`` (two fixed
    pivots) or ``moving`` (two moving pivots in the coupler frame); four or five poses by
    Burmester theory, the pair ``pick`` (indices into the candidates, crank first) or, when
    None, every pair ranked (MotionResult.ranked; the design is the first of them: the caller
    checks the ranked pairs in turn)."""
    poses = [tuple(float(x) for x in p) for p in poses]
    n = len(poses)
    if n < 3 or n > 5:
        raise UsageError(f"--poses: motion generation takes 3, 4 or 5 poses, got {n}")
    _check_poses(poses)
    pole_list = tuple((i, j, tuple(map(float, P))) for i, j, P in poles(poses))
    curves = ()
    if n == 3:
        if (pivots is None) == (moving is None):
            raise UsageError("three positions need either the two fixed pivots (--pivots) or the two moving pivots "
                             "(--moving)")
        given = pivots if pivots is not None else moving
        if len(given) != 2:
            raise UsageError(f"--{'pivots' if pivots is not None else 'moving'}: give two pivots, got {len(given)}")
        R1, p1 = pose_matrix(poses[0])
        dyads = []
        for g in given:
            g = np.asarray(g, float)
            if pivots is not None:
                a = moving_pivot(poses, g)
                dyads.append(Dyad(tuple(map(float, g)), tuple(map(float, R1 @ a + p1)), tuple(map(float, a))))
            else:
                A0 = fixed_pivot(poses, g)
                dyads.append(Dyad(tuple(map(float, A0)), tuple(map(float, R1 @ g + p1)), tuple(map(float, g))))
        method = "three positions, fixed pivots given" if pivots is not None else \
            "three positions, moving pivots given"
        pick = (0, 1)
        ranked = ()
    else:
        if pivots is not None or moving is not None:
            raise UsageError("--pivots and --moving apply to three positions; four and five positions are solved by "
                             "Burmester theory (choose a pair with --pick)")
        if n == 4:
            dyads = list(dyad_candidates(poses, count))
            C, W, _, _ = centre_point_curve(poses, 720, 3 * scale_of(poses))
            curves = ((C, W),)
            method = "Burmester, four positions (centre-point and circle-point curves)"
        else:
            dyads = list(burmester_points(poses))
            curves = tuple((C, W) for C, W, _, _ in (centre_point_curve(sub, 720, 3 * scale_of(poses))
                                                   for sub in (poses[:4], poses[:3] + [poses[4]])))
            method = "Burmester, five positions (Burmester points)"
        if len(dyads) < 2:
            raise SynthesisError(WHAT, f"only {len(dyads)} dyad{'s' if len(dyads) != 1 else ''} found for the "
                                       f"{n} positions: no four-bar guides the coupler through them")
        if pick is not None:
            i, j = pick
            if not (0 <= i < len(dyads) and 0 <= j < len(dyads)) or i == j:
                raise UsageError(f"--pick {i},{j}: give two different candidates between 0 and {len(dyads) - 1}")
            ranked = ()
        else:
            ranked = tuple(rank_pairs(poses, dyads))
            if not ranked:
                raise SynthesisError(WHAT, "no pair of the candidate dyads makes a four-bar (grounds too short)")
            pick = ranked[0][:2]
    design = motion_design(poses, dyads[pick[0]], dyads[pick[1]])
    return MotionResult(tuple(poses), method, tuple(dyads), tuple(pick), design, curves, pole_list, ranked)
