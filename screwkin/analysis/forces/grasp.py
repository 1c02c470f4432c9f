"""Grasp analysis: the grasp map, form and force closure with a certificate, the internal
forces and the Ferrari-Canny quality of contacts on one object (Murray, Li and Sastry,
*A Mathematical Introduction to Robotic Manipulation*, 1994, ch. 5).

Wrenches are (force, moment) about the object frame's origin, as Pinocchio orders them.
Contact i has a frame R_i = [t1 t2 n] (n: the inward normal) at the point p_i; the
contact's wrench basis B_i (frictionless: the normal force; point contact with friction:
the three forces; soft finger: the three forces and the torsion about n) is carried to
the object by G_i = [[R_i, 0], [p_i^ R_i, R_i]] B_i, and G = [G_1 ... G_k].  The friction
cones: |f_t| <= mu f_n, and for a soft finger also |torsion| <= mu_torsion f_n.
A planar grasp has wrenches (fx, fy, mz): a contact with friction has the forces along
its tangent t = (-n_y, n_x) and its normal, its cone is exactly the two edges n +- mu t.

Every test is made on dimensionless wrenches: moments divided by a characteristic length
L (by default the mean distance of the contacts from their centroid).

* Force closure (G maps the cones onto all of wrench space) is decided by linear
  programs (scipy.optimize.linprog, HiGHS) on the cones' generators W = G C: the
  generators positively span wrench space iff they have full rank and a strictly
  positive null vector (an internal force strictly inside every cone).  When not, a
  second linear program finds u with u . (G c) >= 0 for every generator c: the external
  wrench u cannot be resisted (G f = -u would give -|u|^2 = u . G f >= 0).
* Circular cones are replaced by N-facet pyramids, inscribed (generators on the cone:
  inside it, a yes is exact) and circumscribed (friction mu / cos(pi/N): around it, a no
  is exact).  Between the two, the certificates found are checked against the circular
  cones themselves (f_t against mu f_n; u_n >= mu |u_t| + mu_torsion |u_torsion|); if
  neither decides, N doubles up to a bound, and then the answer is "undecided".
* Form closure: the same test with every contact taken frictionless (normals only).
* Quality: Ferrari and Canny's epsilon for the L1 bound (sum of normal forces <= 1): the
  radius of the largest ball about the origin inside the convex hull of the primitive
  wrenches (each cone generator with unit normal force), by Qhull (scipy.spatial.ConvexHull);
  with pyramids the inscribed value is a lower and the circumscribed one an upper bound.

scipy is imported inside the functions that need it (0.6 s to import).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...files.grasp import GraspSpec
from ...tolerances import DEFAULT
from .grasp_map import (
    exact_cones,
    generator_matrix,
    scaled_points,
    grasp_characteristic_length,
    cone_error,
    generators,
    grasp_map,
)
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from typing import Any

__all__ = ["GraspTolerances", "GRASP_TOLERANCES", "ContactForce", "Certificate", "GraspQuality", "GraspResult",
           "analyze_grasp"]


@dataclass(frozen=True)
class GraspTolerances:
    """Tolerances of the grasp analysis (all dimensionless: wrenches scaled by L).

    rank_rtol:   singular values of the scaled grasp map below rank_rtol * the largest count as zero.
    margin:      a certificate must clear its bound by this much: an internal force's smallest
                 generator weight (the weights summing to 1, times their count), its friction and
                 torsion ratios below 1 - margin; an unresisted wrench u (unit length) with
                 u . w >= -margin for every primitive wrench w of unit normal force.
    lp:          primal and dual feasibility tolerances given to HiGHS.
    max_facets:  the most facets a pyramid gets when refining an ambiguous answer.
    max_generators: refinement also stops before the cones have more generators than this in all.
    max_hull_points: the quality is given up when its lazy hull (see _epsilon) needs more primitive
                 wrenches than this (Qhull's time and memory grow with the facets of the hull).
    """

    rank_rtol: float = 1e-9
    margin: float = 1e-9
    lp: float = 1e-9
    max_facets: int = 256
    max_generators: int = 200_000
    max_hull_points: int = 150


GRASP_TOLERANCES = GraspTolerances()


@dataclass(frozen=True)
class ContactForce:
    """One contact's part of an internal force: normal force [N], tangential force in the
    contact frame (t1, t2) [N] (planar: along t), torsion about the normal [N m] (soft
    fingers, else None), force in the object frame [N], and the share of the cone used:
    friction_ratio = |f_t| / (mu f_n), torsion_ratio = |torsion| / (mu_torsion f_n) (None
    when the coefficient is 0: the force then has no such component)."""

    contact: int
    normal: float
    tangential: tuple
    torsion: float | None
    force: tuple
    friction_ratio: float | None
    torsion_ratio: float | None


@dataclass(frozen=True)
class Certificate:
    """Why the answer is what it is.

    kind "internal_force": f (the coordinates of G's columns) with G f = 0 and every contact's
    force strictly inside its cone; normalized to a total normal force of 1 N; residual = |G f|.
    kind "unresisted_wrench": an external wrench (force N, moment N m; unit length once moments
    are divided by L) that no contact forces inside the cones balance; ``both_signs`` when its
    opposite cannot be resisted either (it lies outside the span of G).
    margin: how far inside the bound the certificate is, checked against the circular cones
    (1 - the largest friction or torsion ratio, or the smallest generator weight for polyhedral
    cones; for a wrench, the smallest u . w over primitive wrenches w of unit normal force).
    cones: which cones it was found with ("exact", "inscribed", "circumscribed")."""

    kind: str
    internal_force: np.ndarray | None = field(default=None, repr=False)
    contact_forces: tuple = ()
    residual: float | None = None
    unresisted_wrench: np.ndarray | None = None
    both_signs: bool = False
    margin: float = 0.0
    cones: str = "exact"


@dataclass(frozen=True)
class GraspQuality:
    """Ferrari-Canny epsilon (L1: the hull of the primitive wrenches of unit normal force),
    dimensionless (moments divided by torque_scale [m]); epsilon_upper: the value with the
    circumscribed pyramids (epsilon is then the inscribed one: the circular cones' value lies
    between), equal to epsilon for exact cones; None with ``reason`` when not computed."""

    epsilon: float | None
    epsilon_upper: float | None
    norm: str
    torque_scale: float
    reason: str | None = None
    points: int = 0


@dataclass(frozen=True)
class GraspResult:
    """The analysis of a grasp (see the module's notes).

    grasp_map: G (p x m, p = 6 or 3 for planar; force rows in N, moment rows in N m per unit
    contact coordinate), columns: its column labels ("2:t1", "2:n", "3:torsion");
    force_closure: True, False or None (undecided at the tolerance); how: the way it was
    decided; facets: the pyramids' facets finally used (facets_requested at first);
    cone_error: 1 - cos(pi/N), the largest relative shortfall in mu of the inscribed
    pyramid (the circumscribed one exceeds mu by at most 1/cos(pi/N) - 1), 0 when every
    cone is exact; length: the characteristic length L [m] and length_source."""

    spec: GraspSpec
    grasp_map: np.ndarray = field(repr=False)
    columns: tuple
    rank: int
    wrench_dimension: int
    internal_force_dimension: int
    form_closure: bool
    force_closure: bool | None
    certificate: Certificate | None
    how: str
    facets: int
    facets_requested: int
    cone_error: float
    exact_cones: bool
    quality: GraspQuality
    length: float
    length_source: str
    tolerance: float
    notes: tuple = ()


def _linprog(c: np.ndarray, tol: GraspTolerances, **kw: Any) -> np.ndarray | None:
    """scipy's HiGHS; the solution x, or None when infeasible or when the solver gives up."""
    from scipy.optimize import linprog

    res = linprog(c, method="highs", options={"primal_feasibility_tolerance": tol.lp,
                                              "dual_feasibility_tolerance": tol.lp}, **kw)
    return res.x if res.status == 0 and res.x is not None else None


def _relative_rank(A: np.ndarray, rtol: float) -> int:
    s = np.linalg.svd(A, compute_uv=False) if A.size else np.zeros(0)
    return int(np.sum(s > rtol * s[0])) if s.size and s[0] > 0 else 0


def _positive_null_vector(W: np.ndarray, tol: GraspTolerances) -> tuple:
    """lambda > 0 (summing to 1) with W lambda = 0, maximizing its smallest entry t, and k t
    (1 when all are equal); (None, margin) when there is none: LP  max t  s.t.
    W (mu + t 1) = 0, 1.mu + k t = 1, mu >= 0, t >= 0; then projected exactly onto null(W)."""
    p, k = W.shape
    A = np.zeros((p + 1, k + 1))
    A[:p, :k] = W
    A[:p, k] = W.sum(axis=1)
    A[p, :k] = 1.0
    A[p, k] = k
    b = np.zeros(p + 1)
    b[p] = 1.0
    cost = np.zeros(k + 1)
    cost[k] = -1.0
    x = _linprog(cost, tol, A_eq=A, b_eq=b, bounds=[(0, None)] * (k + 1))
    if x is None:
        return None, 0.0
    lam = x[:k] + x[k]
    lam = lam - np.linalg.lstsq(W, W @ lam, rcond=None)[0]  # onto null(W): G f = 0 to round-off
    total = lam.sum()
    if not total > 0:
        return None, 0.0
    lam /= total
    margin = float(k * lam.min())
    return (lam, margin) if margin > tol.margin else (None, margin)


def _separator(W: np.ndarray, tol: GraspTolerances) -> tuple:
    """(u, both): a unit u with u . w >= 0 for every column w of W (up to the LP's tolerance),
    or (None, False) when there is none (the columns positively span).  both: u is orthogonal
    to every column (W lacks rank): -u is one too."""
    p = W.shape[0]
    R = np.linalg.qr(W.T, mode="r")  # W W^T = R^T R: the left singular vectors without W's k x k right ones
    U, s, _ = np.linalg.svd(R.T, full_matrices=True)
    r = int(np.sum(s > tol.rank_rtol * s[0])) if s.size and s[0] > 0 else 0
    if r < p:  # outside the span of W: of the null directions, the one nearest a coordinate axis
        N = U[:, r:]
        j = int(np.argmax(np.linalg.norm(N, axis=1) - 1e-9 * np.arange(p)))  # forces first on ties
        u = N @ N[j]
        return u / np.linalg.norm(u), True
    x = _linprog(-W.sum(axis=1), tol, A_ub=-W.T, b_ub=np.zeros(W.shape[1]), bounds=[(-1.0, 1.0)] * p)
    if x is None or not np.linalg.norm(x) > 0:
        return None, False
    u = x / np.linalg.norm(x)
    if (W.T @ u).min() < -tol.margin * max(1.0, np.abs(W).max()) or (W.T @ u).max() <= tol.margin:
        return None, False
    return u, False


# ------------------------------------------------------------------ exact cone checks
def _contact_forces(spec: GraspSpec, G: np.ndarray, blocks: tuple, f: np.ndarray) -> tuple:
    out = []
    for k, (c, b) in enumerate(zip(spec.contacts, blocks), 1):
        fi = f[b]
        if c.model == "frictionless":
            fn, ft, tau = fi[0], (), None
        elif spec.planar:
            fn, ft, tau = fi[1], (float(fi[0]),), None
        else:
            fn, ft, tau = fi[2], (float(fi[0]), float(fi[1])), (float(fi[3]) if c.model == "soft_finger" else None)
        force = G[:3 if not spec.planar else 2, b] @ fi
        tn = math.hypot(*ft) if ft else 0.0
        fr = tn / (c.mu * fn) if c.mu > 0 and fn > 0 and c.model != "frictionless" else None
        tr = abs(tau) / (c.mu_torsion * fn) if tau is not None and c.mu_torsion > 0 and fn > 0 else None
        out.append(ContactForce(k, float(fn), ft, tau, tuple(float(x) for x in force),
                                None if fr is None else float(fr), None if tr is None else float(tr)))
    return tuple(out)


def _force_margin(spec: GraspSpec, forces: tuple, tol: GraspTolerances) -> float:
    """How far inside the circular cones the contact forces are (1 - the largest ratio), or a
    negative number when one is not strictly inside (a normal force <= 0, or a tangential or
    torsion component where the coefficient is 0)."""
    worst = 1.0
    total = sum(cf.normal for cf in forces)
    for _c, cf in zip(spec.contacts, forces):
        if not cf.normal > tol.margin * total:
            return -1.0
        for ratio, comp in ((cf.friction_ratio, math.hypot(*cf.tangential) if cf.tangential else 0.0),
                            (cf.torsion_ratio, abs(cf.torsion) if cf.torsion is not None else 0.0)):
            if ratio is None:
                if comp > tol.margin * cf.normal:
                    return -1.0
            else:
                worst = min(worst, 1.0 - ratio)
    return worst


def _dual_margin(spec: GraspSpec, Gs: np.ndarray, blocks: tuple, u: np.ndarray) -> float:
    """min over contacts of the smallest u . (G_s f) over the circular cone's section f_n = 1:
    u_n - mu |u_t| - mu_torsion |u_torsion| (>= 0: u separates the cone)."""
    worst = math.inf
    for c, b in zip(spec.contacts, blocks):
        ui = Gs[:, b].T @ u
        if c.model == "frictionless":
            v = ui[0]
        elif spec.planar:
            v = ui[1] - c.mu * abs(ui[0])
        else:
            v = ui[2] - c.mu * math.hypot(ui[0], ui[1])
            if c.model == "soft_finger":
                v -= c.mu_torsion * abs(ui[3])
        worst = min(worst, float(v))
    return worst


# ------------------------------------------------------------------ closure
def _internal_certificate(spec: GraspSpec, G: np.ndarray, Gs: np.ndarray, blocks: tuple, W: np.ndarray, parts: list, lam: np.ndarray, cones: str, tol: GraspTolerances) -> Certificate:
    f = np.zeros(G.shape[1])
    for (sl, C), b in zip(parts, blocks):
        f[b] = C @ lam[sl]
    forces = _contact_forces(spec, G, blocks, f)
    total = sum(cf.normal for cf in forces)
    f /= total
    forces = _contact_forces(spec, G, blocks, f)
    margin = _force_margin(spec, forces, tol)
    if cones == "exact":  # polyhedral cones: the weights' margin is the one that means something
        margin = min(margin, float(W.shape[1] * lam.min()))
    return Certificate("internal_force", internal_force=f, contact_forces=forces,
                       residual=float(np.linalg.norm(G @ f)), margin=margin, cones=cones)


def _wrench_certificate(spec: GraspSpec, Gs: np.ndarray, blocks: tuple, u: np.ndarray, both: bool, L: float, cones: str) -> Certificate:
    p = Gs.shape[0]
    w = u.copy()  # the scaled wrench (f, m / L) = u as (f, m)
    w[3 if p == 6 else 2:] *= L
    return Certificate("unresisted_wrench", unresisted_wrench=w, both_signs=bool(both),
                       margin=_dual_margin(spec, Gs, blocks, u), cones=cones)


def _closure(spec: GraspSpec, G: np.ndarray, Gs: np.ndarray, blocks: tuple, W: np.ndarray, parts: list, cones: str, tol: GraspTolerances, L: float) -> tuple:
    """(closed, certificate) for one set of polyhedral cones (exact or a pyramid)."""
    p = W.shape[0]
    if _relative_rank(W, tol.rank_rtol) == p:
        lam, _ = _positive_null_vector(W, tol)
        if lam is not None:
            return True, _internal_certificate(spec, G, Gs, blocks, W, parts, lam, cones, tol)
    u, both = _separator(W, tol)
    if u is None:
        return None, None
    return False, _wrench_certificate(spec, Gs, blocks, u, both, L, cones)


def _decide_closure(spec: GraspSpec, G: np.ndarray, Gs: np.ndarray, blocks: tuple, facets: int, tol: GraspTolerances, L: float) -> tuple:
    """(force_closure, certificate, how, facets used, notes)."""
    notes = []
    if all(exact_cones(c, spec.planar) for c in spec.contacts):
        W, parts = generator_matrix(spec, Gs, blocks, facets)
        closed, cert = _closure(spec, G, Gs, blocks, W, parts, "exact", tol, L)
        how = "exact: every cone is polyhedral" + (" (planar)" if spec.planar else "")
        if closed is None:
            notes.append("the linear programs decided neither way (numerical trouble)")
        return closed, cert, how, facets, notes
    n = facets
    while True:
        W_in, parts_in = generator_matrix(spec, Gs, blocks, n)
        closed, cert_in = _closure(spec, G, Gs, blocks, W_in, parts_in, "inscribed", tol, L)
        if closed:
            return True, cert_in, f"exact: the inscribed {n}-facet pyramids already close", n, notes
        W_out, parts_out = generator_matrix(spec, Gs, blocks, n, circumscribed=True)
        closed_out, cert_out = _closure(spec, G, Gs, blocks, W_out, parts_out, "circumscribed", tol, L)
        if closed_out is False:
            return False, cert_out, f"exact: not even the circumscribed {n}-facet pyramids close", n, notes
        # between the pyramids: check the certificates against the circular cones themselves
        if closed_out and cert_out.margin > tol.margin:
            return True, cert_out, (f"exact: the internal force found with the circumscribed {n}-facet pyramids "
                                    "lies strictly inside the circular cones"), n, notes
        if closed is False and cert_in.margin >= -tol.margin:
            return False, cert_in, (f"exact: the wrench found with the inscribed {n}-facet pyramids is resisted "
                                    "by no force in the circular cones"), n, notes
        k = sum(generators(c, spec.planar, 2 * n).shape[1] for c in spec.contacts)
        if 2 * n > tol.max_facets or k > tol.max_generators:
            notes.append(f"undecided at the tolerance: the inscribed and circumscribed {n}-facet pyramids disagree "
                         f"(cone error {cone_error(n):.2g}) and neither certificate holds for the circular cones; "
                         "the grasp is at (or within the tolerance of) the boundary of force closure")
            return None, None, f"undecided at {n} facets", n, notes
        n *= 2


# ------------------------------------------------------------------ quality
def _qhull(X: np.ndarray):
    """Qhull's hull of the points X (rows); joggled ("QJ") when the exact hull fails on nearly
    coplanar points (fine pyramids): its facets then move by about 1e-11 (relative)."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        return ConvexHull(X)
    except QhullError:
        return ConvexHull(X, qhull_options="QJ")


def _epsilon(W: np.ndarray, tol: GraspTolerances) -> tuple:
    """(lower, upper, reason): bounds on the distance epsilon from the origin to the boundary of
    the hull of W's columns (0 when the origin is not strictly inside); equal unless the work
    bound stopped the search (reason says so).

    The hull of all the primitive wrenches in 6-D has far too many facets (800 of them: 300,000
    facets, 3 s; 8,000: 11 million), so it is built lazily: the hull of a subset S, whose nearest
    facet (distance b, outer unit normal a) is checked against every point; when no point lies
    beyond it (max_j a . w_j <= b), it is a facet of the whole hull and epsilon = b (the hull of
    S lies inside the whole hull, so no facet of the whole is nearer).  Else the points farthest
    beyond the nearest facets join S and the hull is rebuilt.  At any stage b <= epsilon <=
    max_j a . w_j for every unit a: when S would outgrow tol.max_hull_points these bounds are
    returned."""
    from scipy.spatial import QhullError

    p = W.shape[0]
    W = np.unique(W.T, axis=0).T
    r = _relative_rank(W, tol.rank_rtol)
    if r < p:
        return 0.0, 0.0, f"the primitive wrenches span {r} of {p} dimensions (the hull is flat: epsilon 0)"
    if _relative_rank(W - W[:, :1], tol.rank_rtol) < p:
        return 0.0, 0.0, "the primitive wrenches lie on a hyperplane that misses the origin (epsilon 0)"
    scale = float(np.abs(W).max())
    _, _, Vt = np.linalg.svd(W @ W.T)
    dirs = np.hstack([np.eye(p), -np.eye(p), Vt.T, -Vt.T])
    S = list(dict.fromkeys(int(j) for j in np.argmax(W.T @ dirs, axis=0)))
    while True:  # affinely independent points: directions off the affine hull of S
        X = W[:, S] - W[:, S[:1]]
        U, s, _ = np.linalg.svd(X, full_matrices=True)
        k = int(np.sum(s > tol.rank_rtol * s[0])) if s.size and s[0] > 0 else 0
        if k == p:
            break
        v = W.T @ U[:, k]
        S += [j for j in (int(np.argmax(v)), int(np.argmin(v))) if j not in S]
    upper = math.inf
    while True:
        try:
            hull = _qhull(W[:, S].T)
        except (QhullError, ValueError) as exc:
            first = (str(exc).strip().splitlines() or ["?"])[0]
            return None, None, f"Qhull failed: {first[:120]}"
        a = hull.equations[:, :-1]
        norms = np.linalg.norm(a, axis=1)
        a = a / norms[:, None]
        b = -hull.equations[:, -1] / norms
        order = np.argsort(b)[: 8 * p]
        support = W.T @ a[order].T  # (points, facets)
        worst = np.argmax(support, axis=0)
        h = support[worst, np.arange(len(order))]
        upper = min(upper, float(h.min()))
        over = h - b[order] > DEFAULT.zero * scale
        lower = max(float(b[order[0]]), 0.0)
        if not over[0]:
            return (lower, lower, None) if lower > 0 else \
                (0.0, 0.0, "the origin is not strictly inside the hull of the primitive wrenches")
        added = list(dict.fromkeys(int(j) for j, o in zip(worst, over) if o and int(j) not in S))
        if not added:  # pragma: no cover - a point of S beyond its own hull: Qhull's precision
            return lower, max(upper, lower), "Qhull's precision limits the quality"
        if len(S) + len(added) > tol.max_hull_points:
            return lower, max(upper, lower), (f"bounds only: the hull search stopped at {len(S)} of "
                                              f"{W.shape[1]} primitive wrenches")
        S += added


def _quality(spec: GraspSpec, Gs: np.ndarray, blocks: tuple, facets: int, exact: bool, closed: bool | None, tol: GraspTolerances, L: float) -> GraspQuality:
    W_in, _ = generator_matrix(spec, Gs, blocks, facets)
    eps, upper, reason = _epsilon(W_in, tol)
    if not exact:
        W_out, _ = generator_matrix(spec, Gs, blocks, facets, circumscribed=True)
        _, upper, reason_out = _epsilon(W_out, tol)
        reason = reason or reason_out
    if closed is False:  # the hull and the linear programs can disagree only at round-off
        eps = 0.0 if eps is not None else eps
    return GraspQuality(eps, upper, "L1", L, reason, W_in.shape[1])


# ------------------------------------------------------------------ the analysis
def analyze_grasp(spec: GraspSpec, facets: int = 8, length: float | None = None,
                  tol: GraspTolerances = GRASP_TOLERANCES) -> GraspResult:
    """Grasp map, rank, internal forces, form and force closure with a certificate, and the
    Ferrari-Canny quality of ``spec`` (see the module's notes).  facets: the pyramids'
    facets to start with (>= 3); length: the characteristic length L [m] (default: the mean
    distance of the contacts from their centroid)."""
    if facets < 3:
        raise ValueError("a friction pyramid needs at least 3 facets")
    G, labels, blocks = grasp_map(spec)
    p = G.shape[0]
    if length is None:
        L, source = grasp_characteristic_length(spec)
    else:
        L, source = float(length), "given"
    Gs = G * scaled_points(p, L)[:, None]
    rank = _relative_rank(Gs, tol.rank_rtol)
    Wf, parts_f = generator_matrix(spec, Gs, blocks, facets, frictionless=True)
    form, _ = _closure_form(Wf, tol)
    closed, cert, how, n, notes = _decide_closure(spec, G, Gs, blocks, facets, tol, L)
    exact = all(exact_cones(c, spec.planar) for c in spec.contacts)
    quality = _quality(spec, Gs, blocks, n, exact, closed, tol, L)
    if rank < p:
        notes.insert(0, f"G has rank {rank} < {p}: some wrenches are resisted by no contact force at all")
    return GraspResult(spec, G, labels, rank, p, G.shape[1] - rank, form, closed, cert, how, n, facets,
                       0.0 if exact else cone_error(n), exact, quality, L, source, tol.margin, tuple(notes))


def _closure_form(Wf: np.ndarray, tol: GraspTolerances) -> tuple:
    """Form closure: the normals' wrenches positively span wrench space (an exact test)."""
    if _relative_rank(Wf, tol.rank_rtol) < Wf.shape[0]:
        return False, None
    lam, margin = _positive_null_vector(Wf, tol)
    return lam is not None, lam
