"""Witness points that prove every component of an actuator locus in the box was traced (issue 44): a planar
platform on three distances here, a five-bar (one RRR dyad on its two motors) in ``dyad_witnesses``.

For a platform on three distances (analysis.position.three_distances: a 3-RPR and its kin) mapped over two
legs' slides x, y with the third leg k held, every configuration is fixed by two angles: theta, the held
leg's direction in the plane, and phi, the platform's turn from its drawn pose (B_k = A_k + rho_k (cos
theta, sin theta), B_i = B_k + R(phi) (b_i - b_k)).  The actuator singularity is where the three legs'
lines meet in one point (or are parallel):

    G(theta, phi) = det [ e_i, (B_i - B_k) x e_i ]_(i = 1..3) = 0,   e_i = B_i - A_i,

a trigonometric polynomial of degree 3 in each angle, on a torus: no spurious factor, no angle at
infinity.  The box of the map is the region D of the torus where each mapped leg's squared length
|e_i|^2 lies between its values at the box's bounds (each slide moves its leg's length one way over the
box; checked).  A connected component of {G = 0} in D either meets D's boundary, where a leg is at a
bound of the box (G = 0 with |e_x|^2 or |e_y|^2 at a bound), or is a closed curve inside D: then it
either goes round the torus and crosses one of the circles theta = 0 (or pi) or phi = 0 (or pi), or it
bounds a disc and has a point where theta is largest (G = G_phi = 0).  So every component holds a real
root in D of one of these seven systems of two equations in two angles, each solved by model.krawczyk:
every root proved, or the boxes left undecided said (then nothing is certified).

A witness is on a traced curve when a point of the curve lies in its *arc box*: a box about it inside D
where G's gradient keeps one component away from zero and G keeps away from zero on the two faces across
it, so that {G = 0} in the box is one arc, through the witness (proved with the same enclosures); a
witness on the boundary, when the tracer's end on that bound lies in the Krawczyk box that proved the
witness the only root there.  Every witness on a traced curve: the locus is complete.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.geometry import wrap_angle
from ...model.krawczyk import TrigPoly, bounds, torus_roots
from ...model.state import KinematicState
from ..motion.dyads import ClosedFormCurve, cached_plan
from ..position.certified import closed_form
from ..position.three_distances import planar_platform, pose_onto_joints

__all__ = ["Witnesses", "witnesses", "dyad_witnesses", "unmatched"]

#: Arc boxes tried, half-width in radians, each half the one before, down to this.
ARC_START, ARC_MIN = 0.2, 1e-6
#: A traced point is on the locus to this (|G| relative to the sum of its coefficients' sizes).
ON = 1e-8
#: A root of the slide's quadratic is real below this imaginary part (relative); a leading coefficient below
#: TINY is none.
REAL, TINY = 1e-9, 1e-300
#: G's coefficients all below this (relative to L^4): the legs' lines meet everywhere.
FLAT = 1e-12
#: A root is inside a constraint's interval to this (squared lengths over L^2).
MARGIN = 1e-12
#: The tracer's end on a bound is the edge witness when this close (rad, on the torus).
END = 1e-7
#: A chord between two traced points is brought onto the curve at points this fraction of an arc box apart,
#: at most CHORD_POINTS of them, by CHORD_STEPS Gauss-Newton steps.
CHORD, CHORD_POINTS, CHORD_STEPS = 0.25, 4096, 8
#: A root of the cusp system is a cusp where y's rate is below CUSP (relative to the sum of its coefficients'
#: sizes), a turn where its enclosure over CLOSE (rad) about the root keeps away from zero.
CUSP, CLOSE = 1e-10, 1e-9


@dataclass(frozen=True)
class Witness:
    """One root: (theta, phi), its system ("theta largest", "theta = 0 or pi", "phi = 0 or pi", "edge"),
    its point in the plane (x, y) [the user's inputs, SI], its configuration q (None where it does not
    lift), and its arc box's half-width and axis (0: G = 0 a graph over phi) or, for an edge point, the
    half-widths of the box where it is the only root."""

    angles: np.ndarray
    system: str
    xy: tuple
    q: np.ndarray | None
    box: tuple | None


@dataclass(frozen=True)
class Witnesses:
    points: tuple
    certified: bool
    how: str
    G: TrigPoly | None = None
    torus: object = None  # q -> (theta, phi)
    cusps: tuple | None = None  # ((x, y), ...) every cusp in the box, None where not settled
    cusp_how: str = ""
    curve: tuple = ()  # the equations of the curve on the torus (default (G,))


def _quadratic(pp, k: int) -> tuple:
    """(a, b, c): leg k's squared length in the plane is a s^2 + b s + c at slide s (PlanarPlatform.quadratics)."""
    a, b, c = pp.quadratics()[k]
    return float(a), float(b), float(c)


def _leg_length2(pp, k: int, s: float) -> float:
    a, b, c = _quadratic(pp, k)
    return a * s * s + b * s + c


def _one_way(pp, k: int, lo: float, hi: float) -> bool:
    """Whether leg k's length moves one way as its slide goes from lo to hi, never zero: the quadratic's
    vertex not inside (lo, hi), its values at both ends positive."""
    a, b, _ = _quadratic(pp, k)
    vertex = -b / (2 * a) if abs(a) > TINY else np.inf
    return not lo < vertex < hi and min(_leg_length2(pp, k, lo), _leg_length2(pp, k, hi)) > 0


def _slide_for(pp, k: int, r2: float, lo: float, hi: float) -> float:
    """The slide of leg k in [lo, hi] at which its squared length is r2 (one: the length is monotone)."""
    a, b, c = _quadratic(pp, k)
    roots = np.roots([a, b, c - r2]) if abs(a) > TINY else np.array([(r2 - c) / b])
    roots = roots[np.abs(roots.imag) <= REAL * (1 + np.abs(roots))].real
    return float(min(roots, key=lambda s: max(lo - s, s - hi, 0.0)))


def witnesses(solver, x_name: str, y_name: str, box: tuple, fixed: dict) -> Witnesses:
    """The witness points of the module for the map of ``solver``'s mechanism over (x_name, y_name) in
    ``box`` with ``fixed`` held, or why none (certified False, ``how`` says why): a platform on three
    distances, or one RRR dyad on links the two inputs turn (a five-bar)."""
    pp = planar_platform(solver)
    if pp is not None:
        return _platform_witnesses(solver, pp, x_name, y_name, box, fixed)
    return dyad_witnesses(solver, x_name, y_name, box, fixed)


def _platform_witnesses(solver, pp, x_name: str, y_name: str, box: tuple, fixed: dict) -> Witnesses:
    mech = solver.mech
    idx = {mech.coordinate(name).idx_q: name for name in (x_name, y_name, *fixed)}
    if set(idx) != set(pp.slides) or len(fixed) != 1:
        return Witnesses((), False, "no certificate: witness points are built for a map over two legs' slides "
                                     "with the third held")
    legs = {name: pp.slides.index(mech.coordinate(name).idx_q) for name in (x_name, y_name, *fixed)}
    names = {i: name for name, i in legs.items()}
    ix, iy, k = legs[x_name], legs[y_name], legs[next(iter(fixed))]
    ranges = []
    for i, (lo, hi) in ((ix, box[0]), (iy, box[1])):
        if not _one_way(pp, i, lo, hi):
            return Witnesses((), False, "no certificate: a mapped leg's length does not move one way over the box")
        ends = _leg_length2(pp, i, lo), _leg_length2(pp, i, hi)
        ranges.append((min(ends), max(ends)))
    rho_k = np.sqrt(_leg_length2(pp, k, float(next(iter(fixed.values())))))
    a, b = pp.a, pp.b

    def parts(theta, phi):
        c, s = np.cos(phi), np.sin(phi)
        Bk = (a[k][0] + rho_k * np.cos(theta), a[k][1] + rho_k * np.sin(theta))
        out = []
        for i in range(3):
            d = b[i] - b[k]
            r = (c * d[0] - s * d[1], s * d[0] + c * d[1])
            e = (Bk[0] + r[0] - a[i][0], Bk[1] + r[1] - a[i][1])
            out.append((e, r[0] * e[1] - r[1] * e[0]))
        return out

    L = max(mech.length, 1e-3)

    def G(theta, phi):
        (e0, m0), (e1, m1), (e2, m2) = parts(theta, phi)
        return (e0[0] * (e1[1] * m2 - m1 * e2[1]) - e0[1] * (e1[0] * m2 - m1 * e2[0])
                + m0 * (e1[0] * e2[1] - e1[1] * e2[0])) / L ** 4

    def length2(i):
        return lambda theta, phi: (parts(theta, phi)[i][0][0] ** 2 + parts(theta, phi)[i][0][1] ** 2) / L ** 2

    try:
        g = TrigPoly.fit(G, (3, 3))
        lx, ly = TrigPoly.fit(length2(ix), (1, 1)), TrigPoly.fit(length2(iy), (1, 1))
    except ValueError as e:
        return Witnesses((), False, f"no certificate: {e}")
    if np.abs(g.C).max() < FLAT:
        return Witnesses((), False, "no certificate: the legs' lines meet at every configuration")
    Ix, Iy = (ranges[0][0] / L ** 2, ranges[0][1] / L ** 2), (ranges[1][0] / L ** 2, ranges[1][1] / L ** 2)
    inside = ((lx, *Ix), (ly, *Iy))
    # sin(theta) = Re(-i/2 e^{i theta} + i/2 e^{-i theta}); sin(phi) the same in the second angle
    sin_t = TrigPoly(np.array([[0.5j], [0.0], [-0.5j]]), (np.array([-1, 0, 1]), np.array([0])))
    sin_p = TrigPoly(np.array([[0.5j, 0.0, -0.5j]]), (np.array([0]), np.array([-1, 0, 1])))
    systems = [("theta largest", (g, g.d(0, 1)), inside), ("theta = 0 or pi", (g, sin_t), inside),
               ("phi = 0 or pi", (g, sin_p), inside)]
    edges = [(lx - Ix[0], inside[1]), (lx - Ix[1], inside[1]), (ly - Iy[0], inside[0]), (ly - Iy[1], inside[0])]
    systems += [("edge", (g, e), (other,)) for e, other in edges]
    found, undecided, examined = [], 0, 0
    for name, F, within in systems:
        got = torus_roots(F, within)
        examined += got.boxes
        undecided += len(got.undecided)
        for x in got.points:
            v = np.array([bounds(p, x[None], np.zeros((1, 2)))[0][0] for p, _, _ in within])
            if any(val < lo - MARGIN or val > hi + MARGIN for val, (_, lo, hi) in zip(v, within)):
                continue
            found.append((name, x, got.radii[np.abs(got.points - x).max(axis=1).argmin()]))
    torus = _torus_coordinates(mech, pp, k)
    points = []
    for name, x, radius in found:
        r2 = {ix: lx.at(*x) * L ** 2, iy: ly.at(*x) * L ** 2}
        s = {ix: _slide_for(pp, ix, r2[ix], *box[0]), iy: _slide_for(pp, iy, r2[iy], *box[1]),
             k: float(next(iter(fixed.values())))}
        e0 = parts(*x)[0][0]
        q = _witness_configuration(solver, pp, {names[i]: v for i, v in s.items()}, [s[i] for i in range(3)], x[1], np.array(e0))
        box_w = radius if name == "edge" else _arc_box(g, x, inside)
        points.append(Witness(np.array(x), name, (s[ix], s[iy]), q, box_w))
    certified = not undecided and all(w.q is not None and w.box is not None for w in points)
    counts = {n: sum(w.system == n for w in points) for n in ("theta largest", "theta = 0 or pi", "phi = 0 or pi",
                                                              "edge")}
    how = (f"witnesses: every component of the locus in the box holds a root of one of seven systems on the torus of "
           f"the held leg's direction and the platform's turn (G = 0, the legs' lines meeting: with G_phi = 0, "
           f"{counts['theta largest']}; with theta = 0 or pi, {counts['theta = 0 or pi']}; with phi = 0 or pi, "
           f"{counts['phi = 0 or pi']}; with a mapped leg at a bound of the box, {counts['edge']}), every root proved "
           f"by the Krawczyk test in {examined} boxes")
    if undecided:
        how += f", but {undecided} boxes were left undecided (a singular point of the locus?): no certificate"
    elif not certified:
        how += ", but a witness could not be put on the joints or boxed: no certificate"
    cusps, cusp_how = _certified_cusps(g, lx, ly, inside, lambda x: (_slide_for(pp, ix, lx.at(*x) * L ** 2, *box[0]),
                                                          _slide_for(pp, iy, ly.at(*x) * L ** 2, *box[1])))
    return Witnesses(tuple(points), certified, how, g, torus, cusps, cusp_how)


def _rate_along(g: TrigPoly, length: TrigPoly) -> TrigPoly:
    """The rate of ``length`` along G = 0 (grad length . (-G_phi, G_theta)): zero where the curve's image turns."""
    degree = (int(np.abs(g.m).max() + np.abs(length.m).max()), int(np.abs(g.n).max() + np.abs(length.n).max()))
    return TrigPoly.fit(lambda u, w: -length.d(1, 0).at(u, w) * g.d(0, 1).at(u, w)
                        + length.d(0, 1).at(u, w) * g.d(1, 0).at(u, w), degree)


def _certified_cusps(g: TrigPoly, lx: TrigPoly, ly: TrigPoly, inside: tuple, plane) -> tuple:
    """(the cusps in the plane, or None where not settled; in words): where three modes meet the locus's image
    turns back, both mapped lengths stationary along G = 0.  Every root of G = H = 0 in the box (H: x's rate
    along the curve; its image's x turns) is proved by model.krawczyk; each is a cusp where y's rate K
    vanishes to round-off there, and not one where K's enclosure over the root's neighbourhood keeps away
    from zero."""
    H, K = _rate_along(g, lx), _rate_along(g, ly)
    got = torus_roots((g, H), inside)
    if not got.complete:
        return None, f"the cusps are not settled ({len(got.undecided)} boxes undecided)"
    cusps, turns = [], 0
    scale = np.abs(K.C).sum()
    for x in got.points:
        if not all(lo - MARGIN <= p.at(*x) <= hi + MARGIN for p, lo, hi in inside):
            continue
        v, e = bounds(K, x[None], np.full((1, 2), CLOSE))
        if abs(v[0]) > e[0]:
            turns += 1
        elif abs(v[0]) <= CUSP * scale:
            cusps.append(tuple(float(c) for c in plane(x)))
        else:
            return None, "a root of the cusp system is neither a cusp nor a turn to round-off"
    return tuple(cusps), (f"{len(cusps)} cusps: every root of G = 0 with x stationary along it (G = H = 0) proved by "
                          f"the Krawczyk test in {got.boxes} boxes, {len(cusps)} with y stationary too (to round-off), "
                          f"{turns} where the curve only turns (y's rate proved away from zero)")


def _witness_configuration(solver, pp, values: dict, slides: list, phi: float, u: np.ndarray) -> np.ndarray | None:
    """The configuration at the slides ``values`` with the platform turned by phi and leg 1 along u (three
    distances' own lift onto the file's joints), or None where it does not lift."""
    ref = solver.reference()
    q_in = solver.set_inputs(solver.mech.neutral() if ref is None else ref, values)
    got = pose_onto_joints(solver, pp, q_in, np.array(slides, float), phi, u, ref)
    return None if isinstance(got, str) else got[0]


def _torus_coordinates(mech, pp, k: int):
    """q -> (theta, phi) of the module: the held leg's direction and the platform's turn, read off the
    platform's placement."""
    e1, e2, _ = pp.basis
    inverse = pp.platform.M0.inverse()

    def at(q: np.ndarray) -> np.ndarray:
        g = KinematicState(mech, q).joint_placement(pp.platform.out_joint) * inverse
        R, t = g.rotation, g.translation
        phi = np.arctan2(e2 @ R @ e1, e1 @ R @ e1)
        c, s = np.cos(phi), np.sin(phi)
        bk = pp.b[k]
        B = np.array([c * bk[0] - s * bk[1] + t @ e1, s * bk[0] + c * bk[1] + t @ e2])
        return np.array([np.arctan2(*(B - pp.a[k])[::-1]), phi])
    return at


def _subboxes(c: np.ndarray, r: np.ndarray, n: tuple) -> tuple:
    """The box (centre c, half-widths r) cut into n[0] x n[1] boxes (a zero half-width: one)."""
    us = c[0] + r[0] * ((2 * np.arange(n[0]) + 1) / n[0] - 1)
    ws = c[1] + r[1] * ((2 * np.arange(n[1]) + 1) / n[1] - 1)
    U, W = np.meshgrid(us, ws, indexing="ij")
    cs = np.stack([U.ravel(), W.ravel()], axis=1)
    return cs, np.tile([r[0] / n[0], r[1] / n[1]], (len(cs), 1))


def _arc_box(g: TrigPoly, x: np.ndarray, inside) -> tuple | None:
    """(half-width, axis) of the largest arc box about the witness x (see the module): axis 0 where G = 0
    is a graph over phi in it (G_theta away from zero, G away from zero on the faces theta = x0 +- r), 1
    the other way round; None where none is found down to ARC_MIN.  ``inside``: the constraints (p, lo, hi)
    of the region, or a function (centre, half-width) -> whether the box lies in it."""
    r = ARC_START
    while r >= ARC_MIN:
        fits = inside(x, r) if callable(inside) else all(
            np.all((v - e >= lo) & (v + e <= hi)) for p, lo, hi in inside
            for v, e in [bounds(p, *_subboxes(x, np.array([r, r]), (4, 4)))])
        if fits:
            for axis in (0, 1):
                v, e = bounds(g.d(1 - axis, axis), *_subboxes(x, np.array([r, r]), (4, 4)))
                if not (np.all(v - e > 0) or np.all(v + e < 0)):
                    continue
                clear = True
                for side in (-1, 1):
                    c = x.copy()
                    c[axis] += side * r
                    half = np.array([0.0, r]) if axis == 0 else np.array([r, 0.0])
                    v, e = bounds(g, *_subboxes(c, half, (16, 1) if axis else (1, 16)))
                    clear &= bool(np.all(np.abs(v) > e))
                if clear:
                    return (r, axis)
        r /= 2
    return None


def _onto(eqs: tuple, X: np.ndarray) -> np.ndarray:
    """The points X (m, n) brought onto eqs = 0 by Gauss-Newton's least change (a few steps)."""
    n = X.shape[1]
    grads = [[f.d(*[int(k == j) for k in range(n)]) for j in range(n)] for f in eqs]
    for _ in range(CHORD_STEPS):
        F = np.stack([f.at(*X.T) for f in eqs], axis=1)
        J = np.stack([np.stack([d.at(*X.T) for d in row], axis=1) for row in grads], axis=1)  # (m, k, n)
        JJ = np.einsum("mkn,mln->mkl", J, J)
        ok = np.abs(np.linalg.det(JJ)) > TINY
        step = np.zeros_like(X)
        step[ok] = -np.einsum("mkn,mk->mn", J[ok], np.linalg.solve(JJ[ok], F[ok][..., None])[..., 0])
        X = X + step
    return X


def _on_a_chord(eqs: tuple, scale: list, curves: list, wt: Witness, reach: np.ndarray) -> bool:
    """Whether a point of the curve between two traced points next to the witness (their chord, at points a
    CHORD of its arc box apart, brought onto the curve) lies in its arc box."""
    for T in curves:
        if len(T) < 2:
            continue
        d = np.abs(wrap_angle(T - wt.angles)).max(axis=1)
        for i in np.argsort(d)[:3]:
            for j in (i - 1, i + 1):
                if not 0 <= j < len(T):
                    continue
                chord = wrap_angle(T[j] - T[i])
                m = int(min(CHORD_POINTS, np.ceil(np.abs(chord).max() / (CHORD * reach.min())) + 1))
                X = _onto(eqs, T[i] + np.outer(np.linspace(0.0, 1.0, m + 1), chord))
                on = np.all([np.abs(f.at(*X.T)) <= ON * s for f, s in zip(eqs, scale)], axis=0)
                if np.any(on & np.all(np.abs(wrap_angle(X - wt.angles)) < reach, axis=1)):
                    return True
    return False


def unmatched(w: Witnesses, loci: list) -> list:
    """The witnesses no traced curve of ``loci`` passes through (see the module): a traced point in the
    witness's arc box, or a point between two traced ones brought onto the curve (_on_a_chord); an edge
    witness, the tracer's end on that bound."""
    if not w.points:
        return []
    eqs = w.curve or (w.G,)
    scale = [np.abs(f.C).sum() for f in eqs]
    n = w.G.C.ndim
    curves = [np.array([w.torus(q) for q in lc.q]).reshape(-1, n) for lc in loci]
    pts = np.vstack(curves) if curves else np.zeros((0, n))
    on = np.all([np.abs(f.at(*pts.T)) <= ON * s for f, s in zip(eqs, scale)], axis=0) if len(pts) else \
        np.zeros(0, bool)
    left = []
    for wt in w.points:
        d = np.abs(wrap_angle(pts - wt.angles))
        reach = np.broadcast_to(np.array(wt.box[0] if wt.system != "edge" else wt.box, float), (n,))
        hit = on & np.all(d < reach, axis=1)
        if wt.system == "edge":  # the tracer's end on that bound: the one root of the edge's system there
            hit &= np.all(d < END, axis=1)
        elif not hit.any():
            hit = np.array([_on_a_chord(eqs, scale, curves, wt, reach)])
        if not hit.any():
            left.append(wt)
    return left


def _first_dyad_ends(curve: ClosedFormCurve, xs: np.ndarray) -> tuple | None:
    """For a closed form whose first dyad is an RRR (placed on links the inputs alone move): its outer joints
    A and C (N, 2) in plane coordinates at the input values xs and its links' lengths (r1, r2) -- it folds
    where |C - A| = r1 + r2 or |r1 - r2|; None for another kind."""
    p, geo = curve.p, curve.geo
    kinds, ia, ib, ic = p.dyads[0]
    if kinds != "RRR":
        return None
    g1, g2 = p.order[1]
    poses, _ = curve.predict(xs, [1.0] * len(p.dyads))
    pa = poses[next(g for g in p.pairs[ia].groups if g != g1)]
    pc = poses[next(g for g in p.pairs[ic].groups if g != g2)]
    A, C = pa(geo.other(ia, g1)), pc(geo.other(ic, g2))
    r1 = float(np.linalg.norm(geo.point(ib, g1) - geo.point(ia, g1)))
    r2 = float(np.linalg.norm(geo.point(ib, g2) - geo.point(ic, g2)))
    return np.stack([A[0].v, A[1].v], axis=1), np.stack([C[0].v, C[1].v], axis=1), r1, r2


def dyad_witnesses(solver, x_name: str, y_name: str, box: tuple, fixed: dict) -> Witnesses:
    """The witnesses of a mechanism of one RRR dyad whose outer joints A and C the two mapped inputs (revolute)
    move (a five-bar; other inputs held): in the plane of the inputs themselves it folds where
    G(x, y) = (|C - A|^2 - (r1 + r2)^2) (|C - A|^2 - (r1 - r2)^2) = 0, a trigonometric polynomial of degree
    2 in each.  A component in the box either meets an edge (G = 0 with x or y at a bound) or is closed
    inside it and has a point where x is largest (G = G_y = 0).  With one dyad at most two modes meet: no
    cusp."""
    mech = solver.mech
    plan = cached_plan(solver, x_name)
    if isinstance(plan, str) or len(plan.dyads) != 1 or plan.dyads[0][0] != "RRR":
        return Witnesses((), False, "no certificate: witness points are built for a planar platform on three "
                                     "distances (a 3-RPR) or one RRR dyad on two turning inputs (a five-bar)")
    if any(mech.translational[mech.coordinate(n).idx_v] for n in (x_name, y_name)) or \
            max(box[0][1] - box[0][0], box[1][1] - box[1][0]) > 2 * np.pi:
        return Witnesses((), False, "no certificate: the mapped inputs are not both turns within one turn")
    ref = solver.reference()
    c = mech.coordinate(x_name)
    L = max(mech.length, 1e-3)
    k = 8  # samples per turn: degree 2 in each input, checked by the fit

    def G(xs: np.ndarray, y: float) -> np.ndarray | None:
        q0 = solver.set_inputs(mech.neutral() if ref is None else ref, {y_name: y, **fixed})
        start = float(q0[c.idx_q]) if c.nq == 1 else float(np.arctan2(q0[c.idx_q + 1], q0[c.idx_q]))
        curve = ClosedFormCurve(mech, plan, q0, start, probe=False)
        got = _first_dyad_ends(curve, xs) if curve.ok else None
        if got is None:
            return None
        A, C, r1, r2 = got
        d2 = ((C - A) ** 2).sum(axis=1)
        return (d2 - (r1 + r2) ** 2) * (d2 - (r1 - r2) ** 2) / L ** 4

    turns = 2 * np.pi * np.arange(k) / k
    columns = [G(turns, y) for y in turns]
    if any(col is None for col in columns):
        return Witnesses((), False, "no certificate: the dyad's outer joints could not be placed")
    try:
        g = TrigPoly.from_samples(np.stack(columns, axis=1), (2, 2))
    except ValueError as e:
        return Witnesses((), False, f"no certificate: the dyad's fold is {e}")
    (x0, x1), (y0, y1) = box
    h = min(1e-3, 0.25 * (x1 - x0), 0.25 * (y1 - y0))
    systems = [("x largest", (g, g.d(0, 1)), box)]
    for axis, bound in ((0, x0), (0, x1), (1, y0), (1, y1)):
        line = TrigPoly.fit(lambda u, w, a=axis, b=bound: np.sin((u if a == 0 else w) - b), (1 - axis, axis))
        domain = ((bound - h, bound + h), box[1]) if axis == 0 else (box[0], (bound - h, bound + h))
        systems.append(("edge", (g, line), domain))
    found, undecided, examined = [], 0, 0
    for name, F, domain in systems:
        got = torus_roots(F, (), domain=domain)
        examined += got.boxes
        undecided += len(got.undecided)
        for x, radius in zip(got.points, got.radii):
            if x0 - MARGIN <= x[0] <= x1 + MARGIN and y0 - MARGIN <= x[1] <= y1 + MARGIN:
                found.append((name, x, radius))

    def fits(x: np.ndarray, r: float) -> bool:
        return x0 <= x[0] - r and x[0] + r <= x1 and y0 <= x[1] - r and x[1] + r <= y1

    points = []
    for name, x, radius in found:
        modes = closed_form(solver, {x_name: float(x[0]), y_name: float(x[1]), **fixed})
        q = modes.modes[0][0] if not isinstance(modes, str) and modes.modes else None
        points.append(Witness(np.array(x), name, (float(x[0]), float(x[1])), q,
                              radius if name == "edge" else _arc_box(g, x, fits)))
    certified = not undecided and all(w.q is not None and w.box is not None for w in points)
    counts = {n: sum(w.system == n for w in points) for n in ("x largest", "edge")}
    how = (f"witnesses: every component of the locus in the box holds a root of one of five systems in the plane of "
           f"the inputs (G = 0, the dyad's links in line: with G_y = 0, {counts['x largest']}; with an input at a "
           f"bound of the box, {counts['edge']}), every root proved by the Krawczyk test in {examined} boxes")
    if undecided:
        how += f", but {undecided} boxes were left undecided (a singular point of the locus?): no certificate"
    elif not certified:
        how += ", but a witness could not be put on the joints or boxed: no certificate"
    values = mech.joint_values

    def plane(q: np.ndarray) -> np.ndarray:
        v = values(q)
        return np.array([v[x_name], v[y_name]])
    return Witnesses(tuple(points), certified, how, g, plane, (),
                     "no cusps: one dyad, so at most two modes meet")
