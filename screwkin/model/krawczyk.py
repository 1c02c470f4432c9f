"""Every real root of n trigonometric polynomials in n angles (two or three) inside a region of the torus,
each one proved by the Krawczyk test (interval Newton), or the boxes left undecided.

A trigonometric polynomial f(t) = Re sum C_m exp(i m . t) is kept by its coefficients (TrigPoly, from samples
by the FFT, its degree checked by the coefficients it leaves out).  Over a box of centre c and half-widths r
its values lie in f(c) +- (sum_j |f_j(c)| r_j + S(r) / 2 + eps), S(r) = sum_m |C_m| (sum_j |m_j| r_j)^2 the
bound of the second derivative along any direction in the box, eps the
rounding allowance (``ROUNDING`` times sum |C_mn|, far above the floating-point error of the sums).  Each
box of the region is then

- excluded: an equation's values or a constraint's keep away from zero (or from its interval),
- decided: Krawczyk's operator K(X) = m - Y F(m) + (I - Y F'(X)) (X - m), Y = F'(m)^-1, lies in the
  interior of X (inflated by ``INFLATE``): X holds exactly one root, polished by Newton; or K(X) misses X:
  none,
- or halved across its widest side, down to ``MIN_HALF_WIDTH``; a box still undecided there (a singular
  root: two roots meeting, a curve of roots) is reported, and the roots are then not all proved.

Roots found twice (in two inflated boxes) are one when Newton brings them to the same point.  This is the
branch-and-prune method of interval analysis (Moore, Kearfott & Cloud 2009, ch. 8; the Krawczyk operator,
Krawczyk 1969); here in floating point with the allowance above, not with outward rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import wrap_angle

__all__ = ["TrigPoly", "Roots", "torus_roots", "bounds", "halve_widest"]

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
#: Points evaluated at once (the memory of a contraction: this many times the coefficients).
CHUNK = 20_000


@dataclass(frozen=True)
class TrigPoly:
    """f(t) = Re sum C[a, b, ...] exp(i (m0[a] t0 + m1[b] t1 + ...)) in n angles t: ``C`` complex with one axis
    per angle, ``freqs`` the frequencies (integers) along each; ``m``, ``n`` the first two."""

    C: np.ndarray
    freqs: tuple

    @property
    def m(self) -> np.ndarray:
        return self.freqs[0]

    @property
    def n(self) -> np.ndarray:
        return self.freqs[1]

    @staticmethod
    def fit(f, degree: tuple, check: float | None = 1e-11) -> TrigPoly:
        """The trigonometric polynomial of degree ``degree`` (in each angle) that the vectorised f(t0, t1, ...)
        is: sampled on a grid twice as fine as needed (``from_samples``)."""
        ks = [2 * d + 4 for d in degree]
        grids = np.meshgrid(*[2 * np.pi * np.arange(k) / k for k in ks], indexing="ij")
        return TrigPoly.from_samples(np.asarray(f(*grids), float), degree, check)

    @staticmethod
    def from_samples(V: np.ndarray, degree: tuple, check: float | None = 1e-11) -> TrigPoly:
        """The trigonometric polynomial of degree ``degree`` through the samples V[a, b, ...] at t_j = 2 pi a_j
        / k_j (k_j > 2 degree_j): the FFT's coefficients, those beyond the degree dropped -- they must vanish
        (relative to the largest, ``check``; None: round-off, not checked), else ValueError."""
        F = np.fft.fftn(V) / V.size
        freqs = [np.fft.fftfreq(k, 1.0 / k).astype(int) for k in V.shape]
        keep = [np.abs(f) <= d for f, d in zip(freqs, degree)]
        big = max(np.abs(F).max(), SINGULAR)
        inside = np.ix_(*keep)
        left = np.abs(F).copy()
        left[inside] = 0.0
        if check is not None and left.max() > check * big:
            raise ValueError(f"not a trigonometric polynomial of degree {tuple(degree)}: {left.max() / big:.2g} "
                             "left over")
        return TrigPoly(F[inside], tuple(f[k] for f, k in zip(freqs, keep)))

    def d(self, *orders: int) -> TrigPoly:
        """The partial derivative (orders[j] times in angle j)."""
        C = self.C
        for j, o in enumerate(orders):
            if o:
                shape = [1] * C.ndim
                shape[j] = -1
                C = C * ((1j * self.freqs[j]) ** o).reshape(shape)
        return TrigPoly(C, self.freqs)

    def __sub__(self, other: float) -> TrigPoly:
        C = self.C.copy()
        C[tuple(int((f == 0).argmax()) for f in self.freqs)] -= other
        return TrigPoly(C, self.freqs)

    def at(self, *t: np.ndarray) -> np.ndarray:
        """The values at the points (one array of each angle, broadcast together)."""
        return self._stacked(self.C[None], t)[0]

    def with_gradient(self, *t: np.ndarray) -> np.ndarray:
        """The values and the n partial derivatives at the points, stacked (n + 1, ...): one pass."""
        n = self.C.ndim
        shapes = [[-1 if k == j else 1 for k in range(n)] for j in range(n)]
        return self._stacked(np.stack([self.C] + [self.C * (1j * self.freqs[j]).reshape(shapes[j]) for j in range(n)]), t)

    def _stacked(self, Cs: np.ndarray, t: tuple) -> np.ndarray:
        """The values at the points of the polynomials of coefficients Cs[k] (these frequencies), stacked."""
        t = np.broadcast_arrays(*[np.asarray(x, float) for x in t])
        shape, flat = t[0].shape, [x.ravel() for x in t]
        out = np.empty((len(Cs), len(flat[0])))
        for s in range(0, len(flat[0]), CHUNK):  # one angle contracted at a time, a chunk of points at once
            part = np.einsum("pa,ka...->kp...", np.exp(1j * np.multiply.outer(flat[0][s:s + CHUNK], self.freqs[0])), Cs)
            for x, f in zip(flat[1:], self.freqs[1:]):
                part = np.einsum("pa,kpa...->kp...", np.exp(1j * np.multiply.outer(x[s:s + CHUNK], f)), part)
            out[:, s:s + CHUNK] = part.real
        return out.reshape((len(Cs),) + shape)

    def curvature(self) -> tuple:
        """(Q, sum |C|): Q[j, k] = sum |C| |m_j m_k|, so that the second derivative along any direction in a
        box of half-widths r is at most r Q r."""
        A = np.abs(self.C)
        grids = np.meshgrid(*[np.abs(f) for f in self.freqs], indexing="ij")
        Q = np.array([[float((A * a * b).sum()) for b in grids] for a in grids])
        return Q, float(A.sum())


def bounds(p: TrigPoly, c: np.ndarray, r: np.ndarray) -> tuple:
    """(value at the centres, half-width of the enclosure) of p over the boxes (centres c (k, n), half-widths
    r (k, n)); see the module."""
    Q, total = p.curvature()
    V = p.with_gradient(*c.T)
    f = V[0]
    slope = sum(np.abs(V[1 + j]) * r[:, j] for j in range(c.shape[1]))
    S = np.einsum("kj,jl,kl->k", r, Q, r)
    return f, slope + 0.5 * S + ROUNDING * total


def halve_widest(c: np.ndarray, r: np.ndarray) -> tuple:
    """The boxes (centres c, half-widths r) each cut in two across its widest side: (centres, half-widths)."""
    wide = r.argmax(axis=1)
    rows = np.arange(len(r))
    step = np.zeros_like(r)
    step[rows, wide] = r[rows, wide] / 2
    halves = r.copy()
    halves[rows, wide] /= 2
    return np.vstack([c - step, c + step]), np.vstack([halves, halves])


@dataclass(frozen=True)
class Roots:
    """``points`` (k, n) the proved roots (polished), ``radii`` (k, n) the half-widths of the box about each
    that proved it the only root there, ``undecided`` (j, 2, n) the boxes left ([centre, half-widths]),
    ``boxes`` examined."""

    points: np.ndarray
    radii: np.ndarray
    undecided: np.ndarray
    boxes: int

    @property
    def complete(self) -> bool:
        return not len(self.undecided)


def _unit_orders(n: int, j: int) -> list:
    return [int(k == j) for k in range(n)]


def _polish(F: tuple, x: np.ndarray) -> np.ndarray:
    n = len(x)
    J = [[f.d(*_unit_orders(n, j)) for j in range(n)] for f in F]
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


def _inverses(Jc: np.ndarray) -> tuple:
    """(the inverses of the stacked square matrices, which are invertible): zero where singular."""
    n = Jc.shape[1]
    Y = np.zeros_like(Jc)
    scale = np.abs(Jc).max(axis=(1, 2)) ** n
    ok = np.abs(np.linalg.det(Jc)) > SINGULAR * np.maximum(scale, SINGULAR)
    for k in np.flatnonzero(ok):  # (one at a time: a nearly singular one raises alone)
        try:
            Y[k] = np.linalg.inv(Jc[k])
        except np.linalg.LinAlgError:
            ok[k] = False
    return Y, ok


def torus_roots(F: tuple, within: tuple = (), start: tuple | None = None, domain: tuple | None = None,
                max_boxes: int = MAX_BOXES) -> Roots:
    """Every root of F = (f1, ..., fn) = 0 (n trigonometric polynomials in n angles, n = 2 or 3) in ``domain``
    (default the whole torus) where each constraint (g, lo, hi) of ``within`` has lo <= g <= hi (see the
    module): the domain cut into ``start`` boxes (default 32 a side in two angles, 16 in three), then pruned
    and halved, at most ``max_boxes`` examined.  On the whole torus roots are given in [-pi, pi) and found
    once."""
    n = len(F)
    domain = domain or ((-np.pi, np.pi),) * n
    start = start or ((32,) * n if n == 2 else (16,) * n)
    lo_d = np.array([a for a, _ in domain], float)
    span = np.array([b - a for a, b in domain], float)
    periodic = lo_d if np.allclose(span, 2 * np.pi) else None
    half = span / (2 * np.array(start))
    grids = np.meshgrid(*[lo_d[j] + half[j] * (2 * np.arange(start[j]) + 1) for j in range(n)], indexing="ij")
    c = np.stack([g.ravel() for g in grids], axis=1)
    r = np.tile(half, (len(c), 1))
    J = [[f.d(*_unit_orders(n, j)) for j in range(n)] for f in F]
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
            v, e = bounds(f, c[keep], r[keep])
            keep[keep] = np.abs(v) <= e
        c, r = c[keep], r[keep]
        if not len(c):
            break
        R = INFLATE * r
        cols = [c[:, j] for j in range(n)]
        Fm = np.stack([f.at(*cols) for f in F], axis=1)
        Fe = np.stack([np.full(len(c), ROUNDING * f.curvature()[1]) for f in F], axis=1)
        Jc = np.empty((len(c), n, n))
        Jr = np.empty((len(c), n, n))
        for i in range(n):
            for k in range(n):
                Jc[:, i, k], Jr[:, i, k] = bounds(J[i][k], c, R)
        Y, ok = _inverses(Jc)
        Kc = c - np.einsum("kij,kj->ki", Y, Fm)
        # I - Y J(X) lies in (I - Y Jc) +- |Y| Jr (Jc the centre's Jacobian: I - Y Jc is round-off)
        rest = np.abs(np.eye(n) - np.einsum("kij,kjl->kil", Y, Jc)) + np.einsum("kij,kjl->kil", np.abs(Y), Jr)
        Kr = np.einsum("kij,kj->ki", rest, R) + np.einsum("kij,kj->ki", np.abs(Y), Fe)
        inside = ok & np.all(np.abs(Kc - c) + Kr < R, axis=1)
        away = ok & np.any(np.abs(Kc - c) - Kr > R, axis=1)
        for ci, Ri in zip(c[inside], R[inside]):
            x = _polish(F, ci)
            if np.any(np.abs(x - ci) >= Ri):
                continue  # Newton left the box it was proved in (it cannot: the root is there): not trusted
            x = x if periodic is None else (x - periodic) % (2 * np.pi) + periodic
            if not any(np.abs(x - y if periodic is None else wrap_angle(x - y)).max() < SAME for y, _ in found):
                found.append((x, Ri))
        split = ~inside & ~away
        c, r = c[split], r[split]
        small = r.max(axis=1) < MIN_HALF_WIDTH
        undecided += [np.stack([ci, ri]) for ci, ri in zip(c[small], r[small])]
        c, r = c[~small], r[~small]
        c, r = halve_widest(c, r)
    pts = np.array([x for x, _ in found]).reshape(-1, n)
    radii = np.array([R for _, R in found]).reshape(-1, n)
    return Roots(pts, radii, np.array(undecided).reshape(-1, 2, n), examined)
