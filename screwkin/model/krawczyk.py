"""Every real root of two trigonometric polynomials in two angles inside a region of the torus, each one
proved by the Krawczyk test (interval Newton), or the boxes left undecided.

A trigonometric polynomial f(u, w) = Re sum_mn C_mn exp(i (m u + n w)) is kept by its coefficients (TrigPoly,
from samples by the FFT, its degree checked by the coefficients it leaves out).  Over a box of centre c and
half-widths r its values lie in f(c) +- (|f_u(c)| r_u + |f_w(c)| r_w + S(r) / 2 + eps), S(r) the bound
sum_mn |C_mn| (|m| r_u + |n| r_w)^2 of the second derivative along any direction in the box, eps the
rounding allowance (``ROUNDING`` times sum |C_mn|, far above the floating-point error of the sums).  Each
box of the region is then

- excluded: an equation's values or a constraint's keep away from zero (or from its interval),
- decided: Krawczyk's operator K(X) = m - Y F(m) + (I - Y F'(X)) (X - m), Y = F'(m)^-1, lies in the
  interior of X (inflated by ``INFLATE``): X holds exactly one root, polished by Newton; or K(X) misses X:
  none,
- or halved across its wider side, down to ``MIN_HALF_WIDTH``; a box still undecided there (a singular
  root: two roots meeting, a curve of roots) is reported, and the roots are then not all proved.

Roots found twice (in two inflated boxes) are one when Newton brings them to the same point.  This is the
branch-and-prune method of interval analysis (Moore, Kearfott & Cloud 2009, ch. 8; the Krawczyk operator,
Krawczyk 1969); here in floating point with the allowance above, not with outward rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import wrap_angle

__all__ = ["TrigPoly", "Roots", "torus_roots", "bounds"]

#: The rounding allowance: a value's enclosure is widened by this times the sum of its coefficients' sizes.
ROUNDING = 1e-12
#: Krawczyk's test is made on the box inflated by this factor (a root on a shared face is in some interior).
INFLATE = 1.25
#: Boxes narrower than this (rad) are left undecided.
MIN_HALF_WIDTH = 1e-9
#: At most this many boxes are examined, then the rest is left undecided.
MAX_BOXES = 400_000
#: Newton polishes a proved root until its step is below this (rad); two roots closer than SAME are one.
POLISHED, SAME = 1e-15, 1e-10
#: A Jacobian determinant below this is singular (no Krawczyk test: the box is halved).
SINGULAR = 1e-300


@dataclass(frozen=True)
class TrigPoly:
    """f(u, w) = Re sum C[a, b] exp(i (m[a] u + n[b] w)): ``C`` (len(m), len(n)) complex, ``m``, ``n`` the
    frequencies (integers)."""

    C: np.ndarray
    m: np.ndarray
    n: np.ndarray

    @staticmethod
    def fit(f, degree: tuple[int, int], check: float | None = 1e-11) -> TrigPoly:
        """The trigonometric polynomial of degree ``degree`` (in u, in w) that the vectorised f(u, w) is:
        sampled on a grid twice as fine as needed (``from_samples``)."""
        k1, k2 = 2 * degree[0] + 4, 2 * degree[1] + 4
        u, w = np.meshgrid(2 * np.pi * np.arange(k1) / k1, 2 * np.pi * np.arange(k2) / k2, indexing="ij")
        return TrigPoly.from_samples(np.asarray(f(u, w), float), degree, check)

    @staticmethod
    def from_samples(V: np.ndarray, degree: tuple[int, int], check: float | None = 1e-11) -> TrigPoly:
        """The trigonometric polynomial of degree ``degree`` through the samples V[a, b] at u = 2 pi a / k1,
        w = 2 pi b / k2 (k > 2 degree): the FFT's coefficients, those beyond the degree dropped -- they must
        vanish (relative to the largest, ``check``; None: round-off, not checked), else ValueError."""
        k1, k2 = V.shape
        F = np.fft.fft2(V) / (k1 * k2)
        m, n = np.fft.fftfreq(k1, 1.0 / k1).astype(int), np.fft.fftfreq(k2, 1.0 / k2).astype(int)
        keep_m, keep_n = np.abs(m) <= degree[0], np.abs(n) <= degree[1]
        big = max(np.abs(F).max(), SINGULAR)
        left = np.abs(F[~keep_m]).max(initial=0.0), np.abs(F[:, ~keep_n]).max(initial=0.0)
        if check is not None and max(left) > check * big:
            raise ValueError(f"not a trigonometric polynomial of degree {degree}: {max(left) / big:.2g} left over")
        return TrigPoly(F[np.ix_(keep_m, keep_n)], m[keep_m], n[keep_n])

    def d(self, du: int = 0, dw: int = 0) -> TrigPoly:
        """The partial derivative (du times in u, dw times in w)."""
        return TrigPoly(self.C * (1j * self.m[:, None]) ** du * (1j * self.n[None, :]) ** dw, self.m, self.n)

    def __sub__(self, other: float) -> TrigPoly:
        C = self.C.copy()
        C[(self.m == 0).argmax(), (self.n == 0).argmax()] -= other
        return TrigPoly(C, self.m, self.n)

    def at(self, u: np.ndarray, w: np.ndarray) -> np.ndarray:
        u, w = np.asarray(u, float), np.asarray(w, float)
        Eu, Ew = np.exp(1j * np.multiply.outer(u, self.m)), np.exp(1j * np.multiply.outer(w, self.n))
        return np.einsum("...a,ab,...b->...", Eu, self.C, Ew).real

    def curvature(self) -> tuple:
        """(sum |C| m^2, sum |C| |m n|, sum |C| n^2, sum |C|): S(r) = a r_u^2 + 2 b r_u r_w + c r_w^2."""
        A, M, N = np.abs(self.C), np.abs(self.m)[:, None], np.abs(self.n)[None, :]
        return float((A * M * M).sum()), float((A * M * N).sum()), float((A * N * N).sum()), float(A.sum())


def bounds(p: TrigPoly, c: np.ndarray, r: np.ndarray) -> tuple:
    """(value at the centres, half-width of the enclosure) of p over the boxes (centres c (k, 2), half-widths
    r (k, 2)); see the module."""
    a, b, cc, total = p.curvature()
    f = p.at(c[:, 0], c[:, 1])
    fu, fw = p.d(1, 0).at(c[:, 0], c[:, 1]), p.d(0, 1).at(c[:, 0], c[:, 1])
    S = a * r[:, 0] ** 2 + 2 * b * r[:, 0] * r[:, 1] + cc * r[:, 1] ** 2
    return f, np.abs(fu) * r[:, 0] + np.abs(fw) * r[:, 1] + 0.5 * S + ROUNDING * total


@dataclass(frozen=True)
class Roots:
    """``points`` (k, 2) the proved roots (polished), ``radii`` (k, 2) the half-widths of the box about each
    that proved it the only root there, ``undecided`` (j, 2, 2) the boxes left ([centre, half-widths]),
    ``boxes`` examined."""

    points: np.ndarray
    radii: np.ndarray
    undecided: np.ndarray
    boxes: int

    @property
    def complete(self) -> bool:
        return not len(self.undecided)


def _polish(F: tuple, x: np.ndarray) -> np.ndarray:
    J = [[f.d(1, 0), f.d(0, 1)] for f in F]
    for _ in range(8):
        v = np.array([f.at(*x) for f in F])
        M = np.array([[g.at(*x) for g in row] for row in J])
        try:
            dx = np.linalg.solve(M, -v)
        except np.linalg.LinAlgError:
            break
        x = x + dx
        if np.abs(dx).max() < POLISHED:
            break
    return x


def torus_roots(F: tuple[TrigPoly, TrigPoly], within: tuple = (), start: tuple = (32, 32),
                domain: tuple = ((-np.pi, np.pi), (-np.pi, np.pi)), max_boxes: int = MAX_BOXES) -> Roots:
    """Every root of F = (f1, f2) = 0 in ``domain`` where each constraint (g, lo, hi) of ``within`` has
    lo <= g <= hi (see the module): the domain cut into ``start`` boxes, then pruned and halved, at most
    ``max_boxes`` examined.  The whole
    torus (the default domain): roots are given in [-pi, pi) and found once."""
    (u0, u1), (w0, w1) = domain
    whole = np.allclose([u1 - u0, w1 - w0], 2 * np.pi)
    periodic = np.array([u0, w0]) if whole else None
    nu, nw = start
    hu, hw = (u1 - u0) / (2 * nu), (w1 - w0) / (2 * nw)
    cu, cw = np.meshgrid(u0 + hu * (2 * np.arange(nu) + 1), w0 + hw * (2 * np.arange(nw) + 1), indexing="ij")
    c = np.stack([cu.ravel(), cw.ravel()], axis=1)
    r = np.tile([hu, hw], (len(c), 1))
    J = [[f.d(1, 0), f.d(0, 1)] for f in F]
    found, undecided, examined = [], [], 0
    while len(c):
        examined += len(c)
        if examined > max_boxes:
            undecided += [np.stack([ci, ri]) for ci, ri in zip(c, r)]
            break
        keep = np.ones(len(c), bool)
        for g, lo, hi in within:
            v, e = bounds(g, c, r)
            keep &= (v + e >= lo) & (v - e <= hi)
        for f in F:
            v, e = bounds(f, c, r)
            keep &= np.abs(v) <= e
        c, r = c[keep], r[keep]
        if not len(c):
            break
        R = INFLATE * r
        Fm = np.stack([f.at(c[:, 0], c[:, 1]) for f in F], axis=1)
        Fe = np.stack([np.full(len(c), ROUNDING * f.curvature()[3]) for f in F], axis=1)
        Jc = np.empty((len(c), 2, 2))
        Jr = np.empty((len(c), 2, 2))
        for i in range(2):
            for k in range(2):
                Jc[:, i, k], Jr[:, i, k] = bounds(J[i][k], c, R)
        det = Jc[:, 0, 0] * Jc[:, 1, 1] - Jc[:, 0, 1] * Jc[:, 1, 0]
        ok = np.abs(det) > SINGULAR
        Y = np.zeros_like(Jc)  # the 2 x 2 inverse by its adjugate (no exception where nearly singular)
        Y[ok, 0, 0], Y[ok, 1, 1] = Jc[ok, 1, 1] / det[ok], Jc[ok, 0, 0] / det[ok]
        Y[ok, 0, 1], Y[ok, 1, 0] = -Jc[ok, 0, 1] / det[ok], -Jc[ok, 1, 0] / det[ok]
        Kc = c - np.einsum("kij,kj->ki", Y, Fm)
        # I - Y J(X) lies in (I - Y Jc) +- |Y| Jr (Jc the centre's Jacobian: I - Y Jc is round-off)
        rest = np.abs(np.eye(2) - np.einsum("kij,kjl->kil", Y, Jc)) + np.einsum("kij,kjl->kil", np.abs(Y), Jr)
        Kr = np.einsum("kij,kj->ki", rest, R) + np.einsum("kij,kj->ki", np.abs(Y), Fe)
        inside = ok & np.all(np.abs(Kc - c) + Kr < R, axis=1)
        away = ok & np.any(np.abs(Kc - c) - Kr > R, axis=1)
        for ci, Ri in zip(c[inside], R[inside]):
            x = _polish(F, ci)
            if np.any(np.abs(x - ci) >= Ri):
                continue  # Newton left the box it was proved in (it cannot: the root is there): not trusted
            x = x if periodic is None else (x - periodic[0]) % (2 * np.pi) + periodic[0]
            if not any(np.abs(x - y if periodic is None else wrap_angle(x - y)).max() < SAME for y, _ in found):
                found.append((x, Ri))
        split = ~inside & ~away
        c, r = c[split], r[split]
        small = r.max(axis=1) < MIN_HALF_WIDTH
        undecided += [np.stack([ci, ri]) for ci, ri in zip(c[small], r[small])]
        c, r = c[~small], r[~small]
        wide = (r[:, 1] > r[:, 0]).astype(int)  # the wider side
        step = np.zeros_like(r)
        step[np.arange(len(r)), wide] = r[np.arange(len(r)), wide] / 2
        half = r.copy()
        half[np.arange(len(r)), wide] /= 2
        c, r = np.vstack([c - step, c + step]), np.vstack([half, half])
    pts = np.array([x for x, _ in found]).reshape(-1, 2)
    radii = np.array([R for _, R in found]).reshape(-1, 2)
    return Roots(pts, radii, np.array(undecided).reshape(-1, 2, 2), examined)
