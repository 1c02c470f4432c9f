"""Two rigid bodies in a plane joined by three distances (a planar 3-RPR and its kin): every pose in
closed form, from one univariate polynomial in the half-angle tangent of the platform's turn.

Ground points a_k, platform points b_k (the platform's own coordinates at its drawn pose), squared
lengths c_k (k = 1, 2, 3); the platform turned by phi and moved so that b_1 lands at a_1 + u:

    |u + R(phi) d_k - e_k|^2 = c_k,   d_k = b_k - b_1,  e_k = a_k - a_1   (d_1 = e_1 = 0).

Less the first, rows 2 and 3 are linear in u:  M(phi) u = r(phi),  M's rows 2 (R d_k - e_k),
r_k = c_k - c_1 - |d_k|^2 - |e_k|^2 + 2 e_k . R d_k;  so u = adj(M) r / det M, and the first row
|adj(M) r|^2 = c_1 (det M)^2 is one equation in (cos phi, sin phi) of degree 4.  With t = tan(phi / 2),
cos phi = (1 - t^2) / (1 + t^2), sin phi = 2 t / (1 + t^2), and the denominators cleared, it is a
polynomial P(t) of degree at most 8, built here exactly by numpy's polynomial arithmetic on the
coefficients (no sampling).  P always has the factor 1 + t^2 (the circular points: t = +-i is no angle),
which leaves the sextic of Gosselin and Sefrioui (1991) -- six poses at most, over the complex numbers.
Each of its roots is accounted for:
- det M != 0: one pose, u from the linear rows, checked on all three distances;
- det M = 0 (the two rows parallel at that angle) and the rows inconsistent: no pose at all (adj(M) r
  is an isotropic vector, (x, +-i x): only a complex angle does it) -- a spurious root, which similar
  base and platform triangles bring (and so drop the count below six);
- det M = 0 and the rows consistent: u on the line M u = r and on the circle |u|^2 = c_1;
- a root at t = infinity (the leading coefficients zero): phi = pi, treated the same way.
Roots that give one pose (a multiple root: the platform at a singularity) are one pose with their
multiplicity.  A polynomial that vanishes identically (a continuum of poses: congruent triangles with
lengths that allow it) has no roots to count: ``planar_poses`` says so.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial import Polynomial

from ..tolerances import DEFAULT, Tolerances

__all__ = ["PlanarPose", "PlanarRoots", "half_angle_polynomial", "planar_poses"]

#: Shares of a root (1 / 2 for each pose of a line and circle) that add up to a whole within this [-].
_SHARE = 1e-9
#: The rows of M are parallel (det M = 0) at a root, and adj(M) r is zero there, when below this
#: relative to the product of their sizes [-]; between it and the verification a root is unexplained.
_PARALLEL = 1e-7


@dataclass(frozen=True)
class PlanarPose:
    """One pose: the turn ``phi`` [rad] (complex for a complex pose), ``u`` (2,) = B_1 - A_1 in the
    plane, ``roots`` of the polynomial that give it (more than one: a multiple root), ``real``, and
    ``how``: "linear" (det M != 0) or "line and circle" (det M = 0, the rows consistent)."""

    phi: complex
    u: np.ndarray
    roots: int
    real: bool
    how: str = "linear"


@dataclass(frozen=True)
class PlanarRoots:
    """Every root of the half-angle polynomial, accounted for.

    coefficients: P(t) (degree <= 8, lowest power first), scaled by the lengths' scale;
    circular:     factors 1 + t^2 taken out of P (roots t = +-i, no angle);
    degree:       the degree n of what is left (roots counted below, ``at_pi`` among them);
    at_pi:        roots at t = infinity (phi = pi): P's degree fell by that much;
    poses:        the PlanarPoses, real and complex;
    spurious:     roots where det M = 0 and the rows are inconsistent: no pose;
    unexplained:  roots none of the above accounts for (each a sentence): the count is then no
                  certificate."""

    coefficients: np.ndarray
    circular: int
    degree: int
    at_pi: int
    poses: list
    spurious: int
    unexplained: list = field(default_factory=list)

    @property
    def real(self) -> list:
        return [p for p in self.poses if p.real]

    @property
    def complex(self) -> list:
        return [p for p in self.poses if not p.real]

    @property
    def accounted(self) -> int:
        """Roots accounted for: those of the poses (with their multiplicity) and the spurious ones."""
        return sum(p.roots for p in self.poses) + self.spurious


def _half_angle_rows(a: np.ndarray, b: np.ndarray, c: np.ndarray):
    """(M rows, r) as polynomials in t, each times (1 + t^2) (so M(t) = rows / (1 + t^2))."""
    h, C, S = Polynomial([1.0, 0.0, 1.0]), Polynomial([1.0, 0.0, -1.0]), Polynomial([0.0, 2.0])
    rows, rhs = [], []
    for k in (1, 2):
        d, e = b[k] - b[0], a[k] - a[0]
        Rd = (d[0] * C - d[1] * S, d[0] * S + d[1] * C)
        rows.append((2 * (Rd[0] - e[0] * h), 2 * (Rd[1] - e[1] * h)))
        rhs.append((c[k] - c[0] - d @ d - e @ e) * h + 2 * (e[0] * Rd[0] + e[1] * Rd[1]))
    return rows, rhs


def half_angle_polynomial(a, b, c) -> tuple:
    """(P, det, N): the polynomial P(t) = |N|^2 - c_1 det^2 (see the module) and its parts det = (1 + t^2)^2
    det M, N = (1 + t^2)^2 adj(M) r, numpy Polynomials in t = tan(phi / 2).  ``a``, ``b`` (3, 2) the ground
    and platform points, ``c`` (3,) the squared lengths (one unit of length throughout)."""
    a, b, c = (np.asarray(v, float) for v in (a, b, c))
    ((m11, m12), (m21, m22)), (r1, r2) = _half_angle_rows(a, b, c)
    det = m11 * m22 - m12 * m21
    N = (m22 * r1 - m12 * r2, m11 * r2 - m21 * r1)
    return N[0] ** 2 + N[1] ** 2 - c[0] * det ** 2, det, N


def _linear_rows_at(a, b, c, cs) -> tuple:
    """(M (2, 2), r (2,)) at (cos phi, sin phi) = cs (complex)."""
    co, si = cs
    M, r = np.empty((2, 2), complex), np.empty(2, complex)
    for i, k in enumerate((1, 2)):
        d, e = b[k] - b[0], a[k] - a[0]
        Rd = np.array([co * d[0] - si * d[1], si * d[0] + co * d[1]])
        M[i] = 2 * (Rd - e)
        r[i] = c[k] - c[0] - d @ d - e @ e + 2 * (e @ Rd)
    return M, r


def _distance_miss(a, b, c, cs, u) -> float:
    """The largest |distance^2 - c_k| of the pose (cs, u), relative to 1 + c_k."""
    co, si = cs
    out = 0.0
    for k in range(3):
        d, e = b[k] - b[0], a[k] - a[0]
        v = u + np.array([co * d[0] - si * d[1], si * d[0] + co * d[1]]) - e
        out = max(out, abs(v @ v - c[k]) / (1.0 + abs(c[k])))
    return out


def _root_outcome(a, b, c, t, check: float) -> tuple:
    """What root t (None: t = infinity, phi = pi) gives: ("pose", [(phi, u, how)]) or ("spurious", why) or
    ("unexplained", why)."""
    if t is None:
        cs, phi = (-1.0 + 0j, 0j), np.pi + 0j
    else:
        t = complex(t)
        cs = ((1 - t * t) / (1 + t * t), 2 * t / (1 + t * t))
        phi = 2 * np.arctan(t)
    M, r = _linear_rows_at(a, b, c, cs)
    det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
    adj = np.array([[M[1, 1], -M[0, 1]], [-M[1, 0], M[0, 0]]])
    N = adj @ r
    size = np.linalg.norm(M[0]) * np.linalg.norm(M[1])
    where = f"t = {t:.6g}" if t is not None else "t = infinity"
    typical = 2 * sum(np.linalg.norm(b[k] - b[0]) + np.linalg.norm(a[k] - a[0]) for k in (1, 2))
    if np.abs(M).max() <= _PARALLEL * typical:  # both rows vanish: M u = r holds for every u, or for none
        if np.abs(r).max() > _PARALLEL * (1 + np.abs(c).max()):
            return "spurious", f"M = 0 at {where} and r is not: no pose"
        return "unexplained", (f"M = 0 and r = 0 at {where}: every point of a circle is a pose at this angle "
                               "(a continuum)")
    if abs(det) > _PARALLEL * size:
        u = N / det
        res = _distance_miss(a, b, c, cs, u)
        if res <= check:
            return "pose", [(phi, u, "linear")]
        return "unexplained", f"the pose at {where} misses a distance by {res:.2g} (relative)"
    if np.linalg.norm(N) > _PARALLEL * np.linalg.norm(adj) * np.linalg.norm(r):
        return "spurious", f"det M = 0 at {where} and the two linear rows are inconsistent: no pose"
    # det M = 0, the rows consistent: u on the line m . u = rho (the larger row) and on |u|^2 = c_1
    i = int(np.argmax(np.abs(M).sum(axis=1)))
    m, rho = M[i], r[i]
    mm = m @ m
    if abs(mm) <= _PARALLEL * (np.abs(m) @ np.abs(m)) or abs(mm) == 0:
        return "unexplained", f"det M = 0 at {where} and the rows are isotropic"
    u0, v = rho * m / mm, np.array([-m[1], m[0]])
    lam = np.sqrt((c[0] - u0 @ u0) / mm + 0j)
    out = []
    for s in ((1,) if abs(lam) == 0 else (1, -1)):
        u = u0 + s * lam * v
        res = _distance_miss(a, b, c, cs, u)
        if res > check:
            return "unexplained", f"det M = 0 at {where}, and a point of the line and circle misses a distance by {res:.2g}"
        out.append((phi, u, "line and circle"))
    return "pose", out


def _newton_root(Q: Polynomial, t: complex) -> complex:
    """A root of Q refined by Newton while |Q| falls (a few steps)."""
    dQ = Q.deriv()
    f = abs(Q(t))
    for _ in range(4):
        d = dQ(t)
        if d == 0:
            break
        s = t - Q(t) / d
        g = abs(Q(s))
        if not g < f:
            break
        t, f = s, g
    return t


def planar_poses(a, b, c, tol: Tolerances = DEFAULT) -> PlanarRoots | str:
    """Every pose of the platform (see the module) as PlanarRoots, or why there is no polynomial to
    count (it vanishes identically).  ``a``, ``b`` (3, 2), ``c`` (3,) as ``half_angle_polynomial``'s;
    ``tol``: zero (a coefficient, the remainder of a division by 1 + t^2), closed_check (a pose checked
    on the three distances), unit_circle (a real angle) and homotopy_same (two roots one pose) decide."""
    a, b, c = (np.asarray(v, float) for v in (a, b, c))
    L = max(np.abs(a).max(), np.abs(b - b[0]).max(), np.sqrt(np.abs(c).max()), 1e-300)
    a, b, c = (a - a[0]) / L, (b - b[0]) / L, c / L ** 2  # one scale, A_1 and B_1 at the origin
    P, det, N = half_angle_polynomial(a, b, c)
    scale = max(np.abs((N[0] ** 2 + N[1] ** 2).coef).max(initial=0.0), c[0] * np.abs((det ** 2).coef).max(initial=0.0))
    if np.abs(P.coef).max(initial=0.0) <= tol.closed_form * scale:
        return ("the polynomial in tan(phi/2) vanishes identically: the three distances leave the platform a "
                "continuum of poses (or none) at these lengths")
    big = np.abs(P.coef).max()
    h = Polynomial([1.0, 0.0, 1.0])
    circular, Q = 0, P
    while Q.degree() >= 2:
        q, rem = divmod(Q, h)
        if np.abs(rem.coef).max(initial=0.0) > tol.closed_form * big:
            break
        Q, circular = q, circular + 1
    coef = Q.coef.copy()
    at_pi = 0
    while len(coef) > 1 and abs(coef[-1]) <= tol.zero * big:
        coef, at_pi = coef[:-1], at_pi + 1
    Q = Polynomial(coef)
    degree = len(coef) - 1 + at_pi
    roots = [_newton_root(Q, t) for t in (Q.roots() if Q.degree() > 0 else [])] + [None] * at_pi
    outcomes = [_root_outcome(a, b, c, t, tol.closed_check) for t in roots]
    # a multiple root, which the companion matrix spreads (by eps^(1/k)): where a root is not accounted
    # for alone, its cluster's mean (accurate to round-off) is tried for every root of the cluster
    z = np.array([-1.0 if t is None else (1 + 1j * t) / (1 - 1j * t) for t in roots], complex)  # e^{i phi}
    for i, t in enumerate(roots):
        if outcomes[i][0] != "unexplained" or t is None:
            continue
        group = [j for j in range(len(roots)) if roots[j] is not None and outcomes[j][0] == "unexplained"
                 and abs(z[j] - z[i]) <= tol.unit_circle]
        if len(group) > 1:
            got = _root_outcome(a, b, c, np.mean([roots[j] for j in group]), tol.closed_check)
            if got[0] != "unexplained":
                for j in group:
                    outcomes[j] = got
    found, spurious, unexplained = [], 0, []  # found: [phi, u, roots, how]
    for kind, got in outcomes:
        if kind == "spurious":
            spurious += 1
            continue
        if kind == "unexplained":
            unexplained.append(got)
            continue
        share = 1.0 / len(got)  # a root of the line and circle stands for its two poses together
        for phi, u, how in got:
            for f in found:
                if abs(np.exp(1j * phi) - np.exp(1j * f[0])) <= tol.homotopy_same * 10 and \
                        np.abs(u - f[1]).max() <= tol.homotopy_same * 10 * (1 + np.abs(u).max()):
                    f[2] += share
                    break
            else:
                found.append([phi, u, share, how])
    poses = []
    for phi, u, n, how in found:
        real = abs(np.imag(phi)) <= tol.unit_circle and np.abs(np.imag(u)).max() <= tol.unit_circle * (1 + np.abs(u).max())
        phi = complex(np.real(phi)) if real else complex(phi)
        u = (np.real(u) if real else u) * L
        k = int(round(n))
        if abs(n - k) > _SHARE or k < 1:
            unexplained.append(f"a pose at phi = {phi:.6g} reached by {n:.3g} roots")
            k = max(k, 1)
        poses.append(PlanarPose(phi, u, k, bool(real), how))
    return PlanarRoots(P.coef * 1.0, circular, degree, at_pi, poses, spurious, unexplained)
