"""Witness points that prove every component of a serial 3R arm's singular curve in a workspace section was
traced, and every cusp of it (issue 44).

The arm's three joint angles t (from the configuration it turns from) range over a three-torus; its point
p(t) / L is a trigonometric polynomial P of degree 1 in each, and G = det (dP/dt) one of degree at most 4 in
t2 and 3 in t3 and none in t1 (t1 turns everything after it rigidly; analysis.singularities.cuspidal).  The
section's singular curve is the image in the plane (x, y) of the curve C = {E = P_h - level = 0, G = 0} of
the torus.  A component of C in the box either

- meets an edge of the box (C with P_x or P_y at a bound: three equations in three angles), or
- is closed inside it: along it cos t2 is largest somewhere, where grad cos t2 is a combination of grad E
  and grad G, i.e. det [grad cos t2; grad E; grad G] = sin t2 E_t1 G_t3 = 0 -- t2 is 0 or pi, the first
  joint's circle touches the plane (E_t1 = 0), or det J = 0 turns in t2 (G_t3 = 0).

Where the plane holds the first axis, the arm's point on that axis (det J = 0 there, its first column zero)
stays in the plane for every t1: C holds whole circles of t1 there, no box about them is decided, so a tube
r^2 <= AXIS L^2 about the axis (r the point's distance from it: a function of (t2, t3) alone) is cut out of
the closed components' systems, and its boundary is a bound too: the roots of (G, r^2 - AXIS) on the (t2, t3)
torus, each lifted to the two t1 that put the point in the plane.  Inside the tube nothing is missed when
(checked): the points on the axis are isolated (the roots of its two perpendicular offsets, proved), and
G = 0 neither turns in t2 nor has a singular point there (no root of (G, G_t3) with r^2 <= AXIS, or none of
(G, G_t2)).  Then G = 0 crosses the tube's (t2, t3) in arcs from its boundary to its boundary, C over each
is two graphs t1 = alpha - phi(s), alpha + pi - phi(s) (the point's turn about the axis onto the plane) that
meet the circles over the axis points, and every component of C in the tube reaches its boundary.

Every root of these systems is proved by model.krawczyk, or the boxes left undecided are said, naming the
system (then no certificate: det J's curves crossing -- a non-generic arm, checked first in (t2, t3) --, the
section tangent to the singular surface).  Two sections are refused before any search, said: a plane square
to the first axis (the point's height does not depend on t1, so the curve is circles about the axis) and a
box whose edge lies on the first axis (the edge's roots would be whole circles of t1).

A witness is on a traced curve (loci_witness.unmatched) when a traced configuration, or a point of C
between two traced ones (their chord brought onto C by Newton), lies in its arc box: a box about it in
which the 2 x 2 Jacobian of (E, G) over two of the angles is regular (interval arithmetic) and (E, G) keeps
away from zero on the four faces across them, so that C in it is one arc, a graph over the third angle; a
witness on an edge, when the tracer's end on that edge is it.

Cusps.  The point's Jacobian is the first joint's turn times its Jacobian at t1 = 0, so its kernel k(s)
depends on s = (t2, t3) alone.  The image of C is stationary (a cusp) exactly where C's tangent is that
kernel: where k is tangent to G = 0 too, H = grad G . k = 0 (k a column of adj (dP/dt)).  The cusps are
the roots of (G, H) on the (t2, t3) torus, each lifted to the t1 that put the point in the plane: proved
roots, each checked on the other columns of adj (a root where the column used vanishes is no cusp).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...model.krawczyk import TrigPoly, bounds, halve_widest, torus_roots
from ...model.state import KinematicState
from .loci_witness import ARC_MIN, ARC_START, CLOSE, CUSP, FLAT, MARGIN, Witness, Witnesses

__all__ = ["section_witnesses"]

#: The tube about the first axis cut out of the torus: the point's squared distance from it over L^2.
AXIS = 1e-4
#: The plane holds the first axis when the axis' component across it and its distance from it (over L) are
#: below this.
ALONG = 1e-12
#: Each system's branch and prune examines at most this many boxes (a non-generic section leaves boxes
#: undecided whatever the budget).
SECTION_BOXES = 60_000
#: A face of an arc box is halved this many times at most to show E and G have no common zero on it.
FACE_DEPTH = 24


def _subboxes3(c: np.ndarray, r: np.ndarray, n: int) -> tuple:
    """The box (centre c, half-widths r, three angles) cut into n a side along each angle of positive width."""
    axes = [c[j] + r[j] * ((2 * np.arange(n) + 1) / n - 1) if r[j] > 0 else np.array([c[j]]) for j in range(3)]
    grids = np.meshgrid(*axes, indexing="ij")
    cs = np.stack([g.ravel() for g in grids], axis=1)
    return cs, np.tile([r[j] / n if r[j] > 0 else 0.0 for j in range(3)], (len(cs), 1))


def _grad(p: TrigPoly) -> list:
    return [p.d(*[int(k == j) for k in range(3)]) for j in range(3)]


def _interval_product(a: tuple, b: tuple) -> tuple:
    v = [a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1]]
    return np.minimum.reduce(v), np.maximum.reduce(v)


def _clear(E: TrigPoly, G: TrigPoly, c: np.ndarray, r: np.ndarray, depth: int = FACE_DEPTH) -> bool:
    """Whether E and G have no common zero in the boxes: each excluded by one of them, the others halved
    along their widest side, ``depth`` times at most."""
    for _ in range(depth + 1):
        vE, eE = bounds(E, c, r)
        vG, eG = bounds(G, c, r)
        left = ~((np.abs(vE) > eE) | (np.abs(vG) > eG))
        if not left.any():
            return True
        c, r = halve_widest(c[left], r[left])
    return False


def _arc_box3(E: TrigPoly, G: TrigPoly, x: np.ndarray, inside) -> tuple | None:
    """(half-width, the angle C is a graph over) of the largest arc box about x (see the module), or None."""
    gE, gG = _grad(E), _grad(G)
    r = ARC_START
    while r >= ARC_MIN:
        R = np.full(3, r)
        if inside(x, R):
            cs, rs = _subboxes3(x, R, 3)
            for c in range(3):
                a, b = [j for j in range(3) if j != c]
                ent = {}
                for name, p in (("Ea", gE[a]), ("Eb", gE[b]), ("Ga", gG[a]), ("Gb", gG[b])):
                    v, e = bounds(p, cs, rs)
                    ent[name] = (v - e, v + e)
                lo1, hi1 = _interval_product(ent["Ea"], ent["Gb"])
                lo2, hi2 = _interval_product(ent["Eb"], ent["Ga"])
                lo, hi = lo1 - hi2, hi1 - lo2
                if not (np.all(lo > 0) or np.all(hi < 0)):
                    continue
                faces = []
                for j in (a, b):
                    for side in (-1, 1):
                        cf = x.copy()
                        cf[j] += side * r
                        half = R.copy()
                        half[j] = 0.0
                        faces.append((cf, half))
                if all(_clear(E, G, *_subboxes3(cf, half, 4)) for cf, half in faces):  # (stops at the first not)
                    return (r, c)
        r /= 2
    return None



def _on_torus2(p: TrigPoly) -> TrigPoly:
    """A TrigPoly of (t1, t2, t3) of degree 0 in t1 as one of (t2, t3)."""
    return TrigPoly(p.C[0], p.freqs[1:])


def _in_t1(p: TrigPoly) -> TrigPoly:
    """A TrigPoly of (t2, t3) as one of (t1, t2, t3), of degree 0 in t1."""
    return TrigPoly(p.C[None], (np.array([0]),) + tuple(p.freqs))


def _lifts(E: TrigPoly, s: np.ndarray) -> list | None:
    """The t1 where E(t1, s) = 0 (E of degree 1 in t1: a cos t1 + b sin t1 + c), in closed form; None where E
    vanishes for every t1 there (the point on the first axis, in the plane)."""
    e0, e1, e2 = (float(E.at(t, *s)) for t in (0.0, np.pi / 2, np.pi))
    c, a = (e0 + e2) / 2, (e0 - e2) / 2
    b, rho = e1 - c, np.hypot((e0 - e2) / 2, e1 - c)
    if rho <= FLAT:
        return None if abs(c) <= FLAT else []
    if abs(c) > rho:
        return []
    base, half = np.arctan2(b, a), np.arccos(np.clip(-c / rho, -1.0, 1.0))
    return [base - half, base + half] if half > 0 else [base]


def _cofactor(M: np.ndarray, i: int, j: int) -> np.ndarray:
    """The signed cofactor (i, j) of the 3 x 3 matrices M[..., 3, 3] (cyclic indices)."""
    a, b, c, d = (i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3
    return M[a, c] * M[b, d] - M[a, d] * M[b, c]


def _section_cusps(P: list, g: TrigPoly, E: TrigPoly, px: TrigPoly, py: TrigPoly, box: tuple) -> tuple:
    """(the cusps (x, y) / L in the box, or None where not settled; how, in words; boxes examined)."""
    grad = [[p.d(*[int(k == j) for k in range(3)]) for j in range(3)] for p in P]
    gs = [None, g.d(1, 0), g.d(0, 1)]

    def H(i: int):
        def value(t2, t3):
            z = np.zeros_like(t2)
            M = np.array([[grad[a][b].at(z, t2, t3) for b in range(3)] for a in range(3)])
            return sum(gs[j].at(t2, t3) * _cofactor(M, i, j) for j in (1, 2))
        return TrigPoly.fit(value, (6, 5))

    Hs = [H(i) for i in range(3)]
    order = sorted(range(3), key=lambda i: -np.abs(Hs[i].C).sum())
    examined = 0
    for i in order:
        got = torus_roots((g, Hs[i]), max_boxes=SECTION_BOXES)
        examined += got.boxes
        if len(got.undecided):
            continue
        found, stationary, axis = [], 0, 0
        for s in got.points:
            others = [Hs[k] for k in range(3) if k != i]
            if any(abs(v[0]) > e[0] for v, e in (bounds(h, s[None], np.full((1, 2), CLOSE)) for h in others)):
                continue  # column i of adj vanishes here, the kernel is not tangent: no cusp
            if any(abs(h.at(*s)) > CUSP * np.abs(h.C).sum() for h in others):
                return None, "not settled (a root of the cusp system neither proved one nor excluded)", examined
            lifts = _lifts(E, s)
            if lifts is None:  # the point on the first axis: the kernel is t1's turn, the IK a circle
                axis += 1
                continue
            stationary += 1
            for t1 in lifts:
                xy = (float(px.at(t1, *s)), float(py.at(t1, *s)))
                if all(lo - MARGIN <= v <= hi + MARGIN for v, (lo, hi) in zip(xy, box)):
                    found.append(xy)
        return tuple(found), (f"{len(found)} cusps: the points of the plane over the {stationary} roots of "
                              f"(det J, grad det J . k) on the (t2, t3) torus (k the kernel; each proved by the "
                              f"Krawczyk test in {examined} boxes), where the curve's image is stationary"
                              + (f"; {axis} with the point on the first axis in the plane (the kernel there the "
                                 "first joint's turn, the point's IK a circle) are no cusp" if axis else "")), examined
    return None, "not settled (the cusp system left boxes undecided)", examined


def section_witnesses(arm, axes: tuple, h: int, level: float, box: tuple) -> Witnesses:
    """The witnesses of the module for the Arm3R ``arm`` (analysis.singularities.cuspidal) in the section of
    coordinates ``axes`` (x, y indices) with coordinate ``h`` at ``level`` [m], over ``box``."""
    mech = arm.mech
    L = max(mech.length, 1e-3)

    def point(*t):
        t = np.broadcast_arrays(*t)
        out = np.empty((3,) + t[0].shape)
        for idx in np.ndindex(t[0].shape):
            st = KinematicState(mech, arm.q(np.array([x[idx] for x in t])))
            out[(slice(None),) + idx] = st.frame_placement(arm.fid).translation / L
        return out

    try:
        grids = np.meshgrid(*[2 * np.pi * np.arange(6) / 6] * 3, indexing="ij")
        samples = point(*grids)
        P = [TrigPoly.from_samples(samples[j], (1, 1, 1)) for j in range(3)]
        dP = [_grad(p) for p in P]
        G = TrigPoly.fit(lambda *t: np.linalg.det(np.moveaxis(np.array([[d.at(*t) for d in row] for row in dP]),
                                                              (0, 1), (-2, -1))), (0, 4, 3))
    except ValueError as e:
        return Witnesses((), False, f"no certificate: {e}")
    if np.abs(G.C).max() < FLAT:
        return Witnesses((), False, "no certificate: det J vanishes everywhere")
    g = _on_torus2(G)
    crossing_curves = torus_roots((g, g.d(0, 1)), max_boxes=SECTION_BOXES)
    if len(crossing_curves.undecided):  # (a curve of roots too: det J = 0 a line t2 = constant)
        return Witnesses((), False, "no certificate: det J = 0 has a singular point on the (t2, t3) torus (its curves "
                                    f"cross: a non-generic arm; {len(crossing_curves.undecided)} boxes undecided)")
    E = P[h] - level / L
    (x0, x1), (y0, y1) = ((a / L, b / L) for a, b in box)
    px, py = P[axes[0]], P[axes[1]]
    o, a = arm.points[0] / L, arm.axes[0] / np.linalg.norm(arm.axes[0])
    tube = abs(a[h]) <= ALONG and abs(o[h] - level / L) <= ALONG
    if abs(abs(a[h]) - 1.0) <= ALONG:
        return Witnesses((), False, "no certificate: the plane is square to the first axis, so the point's height "
                                    "does not depend on the first joint and the curve there is circles about that axis "
                                    "(whole circles of t1 on the joints' torus), which these witnesses do not take")
    for k, (lo, hi) in zip(axes, box):
        on = [b for b in (lo, hi) if tube and abs(a[k]) <= ALONG and abs(o[k] - b / L) <= ALONG]
        if on:
            return Witnesses((), False, f"no certificate: the box's edge {'xyz'[k]} = {on[0]:.6g} m lies on the first "
                                        "axis, where the point stays for a whole turn of the first joint (the edge's "
                                        "witnesses would be circles, not points); a box whose edges are off the axis "
                                        "can be certified")
    # the point's offset from the first axis at t1 = 0 across it (along u and v, a x u), over (t2, t3)
    u = np.cross(a, np.eye(3)[int(np.argmin(np.abs(a)))])
    u /= np.linalg.norm(u)
    perp = [TrigPoly.fit(lambda t2, t3, e=e: sum((P[j].at(np.zeros_like(t2), t2, t3) - o[j]) * e[j] for j in range(3)),
                         (1, 1)) for e in (u, np.cross(a, u))]
    r2 = TrigPoly.fit(lambda t2, t3: sum(p.at(t2, t3) ** 2 for p in perp), (2, 2))
    off = ((_in_t1(r2), AXIS, np.inf),) if tube else ()
    inside = ((px, x0, x1), (py, y0, y1)) + off
    sin2 = TrigPoly.fit(lambda t1, t2, t3: np.sin(t2) + 0 * t1 + 0 * t3, (0, 1, 0))
    systems = [("edge", (E, G, px - b), ((py, y0, y1),)) for b in (x0, x1)]
    systems += [("edge", (E, G, py - b), ((px, x0, x1),)) for b in (y0, y1)]
    systems += [("t2 = 0 or pi", (E, G, sin2), inside), ("turn of det J", (E, G, G.d(0, 0, 1)), inside)]
    if not tube:  # (a circle about the first axis touches a plane through that axis only where it is a point)
        systems.append(("circle touching", (E, G, E.d(1, 0, 0)), inside))
    found, undecided, examined, why, stuck = [], 0, crossing_curves.boxes, "", []
    for name, F, within in systems:
        got = torus_roots(F, within, max_boxes=SECTION_BOXES)
        examined += got.boxes
        undecided += len(got.undecided)
        stuck += [name] if len(got.undecided) else []
        for x, radius in zip(got.points, got.radii):
            if all(lo - MARGIN <= p.at(*x) <= hi + MARGIN for p, lo, hi in within):
                found.append((name, x, radius))
    if tube and not undecided:
        on_axis = torus_roots(tuple(perp), max_boxes=SECTION_BOXES)
        # no turn in t2 inside the tube: no root of (G, G_t3) there -- every root on the torus is known already
        # (crossing_curves, complete), or else none of (G, G_t2) there
        plain = not any(r2.at(*x) <= AXIS + MARGIN for x in crossing_curves.points)
        if not plain:
            other = torus_roots((g, g.d(1, 0)), ((r2, -np.inf, AXIS),), max_boxes=SECTION_BOXES)
            examined += other.boxes
            plain = other.complete and not len(other.points)
        examined += on_axis.boxes
        if len(on_axis.undecided) or not plain:
            why = ("the arm's point meets the first axis along a curve, or det J = 0 turns inside the tube about it"
                   if len(on_axis.undecided) else "det J = 0 turns inside the tube about the first axis")
        crossing = torus_roots((g, r2 - AXIS), max_boxes=SECTION_BOXES)
        examined += crossing.boxes
        undecided += len(crossing.undecided)
        stuck += ["tube"] if len(crossing.undecided) else []
        for s in crossing.points:
            for t1 in _lifts(E, s) or []:
                x = np.array([t1, *s])
                if all(lo - MARGIN <= p.at(*x) <= hi + MARGIN for p, lo, hi in inside[:2]):
                    found.append(("tube", x, None))

    def fits(x: np.ndarray, R: np.ndarray) -> bool:
        cs, rs = _subboxes3(x, R, 3)
        return all(np.all((v - e >= lo) & (v + e <= hi)) for p, lo, hi in inside for v, e in [bounds(p, cs, rs)])

    def anywhere(x: np.ndarray, R: np.ndarray) -> bool:  # the tube's witnesses: the arc may cross its boundary
        cs, rs = _subboxes3(x, R, 3)
        return all(np.all((v - e >= lo) & (v + e <= hi)) for p, lo, hi in inside[:2] for v, e in [bounds(p, cs, rs)])

    points = []
    for name, x, radius in found:
        xy = (float(px.at(*x) * L), float(py.at(*x) * L))
        box_w = radius if name == "edge" else _arc_box3(E, G, x, anywhere if name == "tube" else fits)
        points.append(Witness(np.array(x), name, xy, arm.q(x), box_w))
    certified = not undecided and not why and all(w.box is not None for w in points)
    counts = {n: sum(w.system == n for w in points) for n in ("edge", "t2 = 0 or pi", "circle touching",
                                                            "turn of det J", "tube")}
    how = (f"witnesses: every component of the curve in the box holds a root of one of the systems on the torus of "
           f"the three joints (p_h at its level and det J = 0 with x or y at a bound of the box, {counts['edge']}; "
           f"closed components, where cos t2 is largest along them: t2 = 0 or pi, {counts['t2 = 0 or pi']}; "
           f"det J = 0 turning in t2, {counts['turn of det J']}" + (
               "" if tube else f"; the first joint's circle touching the plane, {counts['circle touching']}"))
    if tube:
        how += (f"; the plane holds the first axis, so the first joint's circles touch it only on the axis: a tube of "
                f"radius {np.sqrt(AXIS) * L:.2g} m about the axis cut out, its "
                f"boundary crossed at {counts['tube']}, and inside it det J = 0 only crosses (no turn, no singular "
                "point) and meets the axis at isolated points")
    how += f"), every root proved by the Krawczyk test in {examined} boxes"
    if undecided:
        names = {"edge": "an edge's", "t2 = 0 or pi": "t2 = 0 or pi", "turn of det J": "det J = 0 turning in t2",
                 "circle touching": "the circle touching the plane", "tube": "the tube's boundary"}
        how += (f", but {undecided} boxes were left undecided in the system" + ("s" if len(set(stuck)) > 1 else "")
                + " of " + ", ".join(dict.fromkeys(names[n] for n in stuck)) + " (a singular point of the curve there: "
                "the section tangent to the singular surface, or a curve of roots): no certificate")
    elif why:
        how += f", but {why}: no certificate"
    elif not certified:
        how += ", but a witness could not be boxed: no certificate"
    cusps, cusp_how, _ = (None, "not settled", 0) if undecided else _section_cusps(P, g, E, px, py, ((x0, x1), (y0, y1)))
    cusps = None if cusps is None else tuple((u * L, v * L) for u, v in cusps)
    model = mech.model

    def torus(q: np.ndarray) -> np.ndarray:
        return pin.difference(model, arm.q0, q)[arm.free]
    return Witnesses(tuple(points), certified, how, G, torus, cusps, cusp_how, curve=(E, G))
