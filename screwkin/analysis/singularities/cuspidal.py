"""Whether a serial 3R chain moving a point is cuspidal: the aspects of its joint space, its inverse kinematics
in closed form, and a verdict that says what it rests on (issue 44).

A robot is cuspidal when it can go from one inverse-kinematic solution to another without meeting a
singularity, i.e. when two solutions of one point lie in one *aspect* (a connected part of det J != 0 in
joint space).  det J of the point's Jacobian over the three joints does not depend on the first joint (it
turns everything after it rigidly), so the aspects are those of the torus of (t2, t3) times the first
joint's circle.  det J there is a trigonometric polynomial of degree at most 4 in t2 and 3 in t3: it is
sampled on a 32 x 32 grid (Pinocchio's Jacobian), its Fourier coefficients are exact, and it is evaluated
from them anywhere (a fine grid by zero-padded FFT).  The aspects are the connected same-sign parts of that
fine grid (periodic), two nodes joined where det J keeps its sign at 17 points of the edge between them, the
nodes next to a singular point of det J = 0 (where its factors' curves cross, the wedges between them too
thin for the grid) left out.  The inverse kinematics at a point is the position stage of Pieper's closed form
(analysis.position.pieper.arm_positions: the real roots of a quartic), so the count of solutions at a point
is complete where it answers.

The verdict:

* two solutions of one point joined by a path of the grid along which det J keeps its sign and stays away
  from zero (checked densely on the exact polynomial): cuspidal, a witness;
* otherwise, a generic robot (det J's zero set on the torus has no singular point: det J and its gradient
  never vanish together) with a cusp on its traced singular curve: cuspidal (Salunkhe et al. 2022);
* otherwise, every sampled point of a section that holds the whole workspace (through the first axis) with
  its solutions in distinct aspects: not cuspidal -- for a generic robot this agrees with "no cusp"
  (Salunkhe et al. 2022), for a non-generic one (det J factoring, e.g. into posture terms each of constant
  sign on a solution: Wenger 1997; Baili, Wenger & Chablat 2004) it is what decides;
* anything else (det J identically zero, a joint not revolute, the box not holding the section, the
  evidence at odds): None, with the reason.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ...model._pin import joint_axis
from ...model.krawczyk import TrigPoly
from ...model.state import KinematicState
from ...tolerances import Tolerances
from ..position.pieper import arm_positions
from ..singular import LWA
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["Arm3R", "arm3r", "point_ik", "Aspects", "aspects", "Verdict", "verdict"]

SAMPLES = 32  # the det J samples per turn: degree <= 4 in t2, 3 in t3, exact below 16
FINE = 360  # the aspects' grid per turn (1 deg)
ZERO = 1e-9  # |det J| below this share of its largest: zero (a node on the singular set)
AWAY = 1e-3  # a witness path keeps |det J| above this share of its largest
EDGE = 16  # det J's values checked along each grid edge
TINY = 1e-300  # division guard
BLOCK = 3  # the cells round a singular point of det J's zero set left out of the aspects


@dataclass(frozen=True)
class Arm3R:
    """Three revolutes moving a frame's origin: their velocity indices (parents first), the configuration
    they turn from (held joints at their values, the three at 0), their world axes and points there, the
    point there, the frame id."""

    mech: object
    fid: int
    free: np.ndarray
    q0: np.ndarray
    axes: np.ndarray
    points: np.ndarray
    centre: np.ndarray

    def q(self, t) -> np.ndarray:
        dv = np.zeros(self.mech.nv)
        dv[self.free] = t
        return pin.integrate(self.mech.model, self.q0, dv)

    def det(self, t) -> float:
        st = KinematicState(self.mech, self.q(t))
        return float(np.linalg.det(st.frame_jacobian(self.fid, LWA)[:3][:, self.free]))


def arm3r(mech: Mechanism, fid: int, free: np.ndarray, q0: np.ndarray) -> tuple[Arm3R | None, str]:
    """(the Arm3R, "") or (None, why not): the three joints at velocity indices ``free`` must be revolutes,
    each moving the next."""
    model = mech.model
    coords = {c.idx_v: c for c in mech.coordinates}
    jids = [coords[k].joint_id if k in coords else None for k in sorted(free)]
    if None in jids or any(model.joints[j].nv != 1 or not model.joints[j].shortname().startswith(("JointModelR", "JointModelRU"))
                           for j in jids):
        return None, "the three joints moving the point are not all revolute (the criterion is a 3R's)"
    for a, b in zip(jids, jids[1:]):
        j = b
        while j > 0 and j != a:
            j = model.parents[j]
        if j != a:
            return None, "the three joints are not one serial chain"
    st = KinematicState(mech, q0)
    placements = [st.joint_placement(j) for j in jids]
    axes = np.array([M.rotation @ joint_axis(model.joints[j]) for M, j in zip(placements, jids)])
    points = np.array([M.translation for M in placements])
    centre = st.frame_placement(fid).translation.copy()
    return Arm3R(mech, fid, np.array(sorted(free)), q0, axes, points, centre), ""


def point_ik(arm: Arm3R, c: np.ndarray) -> tuple[list, str]:
    """([(t1, t2, t3)], why): every real solution placing the point at ``c`` (world) in closed form; ``why``
    non-empty where some are left out (the point on the first or second axis: a continuum)."""
    scale = max(float(np.abs(arm.points).max()), float(np.abs(c).max()), arm.mech.length, 1e-3)
    positions, _, why = arm_positions(arm.axes, arm.points, arm.centre, np.asarray(c, float), arm.mech.tolerances, scale)
    return [np.array(p) for p in positions], why


@dataclass(frozen=True)
class Aspects:
    poly: TrigPoly  # det J over (t2, t3): its Fourier coefficients, exact
    top: float  # the largest |det J| on the fine grid
    labels: np.ndarray  # (FINE, FINE): aspect k + 1 at each node, 0 where det J is zero
    count: int
    singular_points: tuple  # ((t2, t3), ...) where det J = 0 and its gradient too (non-generic)
    identically_zero: bool
    grid: np.ndarray = None  # (FINE, FINE) det J at the nodes

    def value(self, t2, t3, d2: int = 0, d3: int = 0) -> np.ndarray:
        """det J (or its derivative d2 times in t2, d3 in t3) at arrays of (t2, t3)."""
        t2, t3 = np.atleast_1d(np.asarray(t2, float)), np.atleast_1d(np.asarray(t3, float))
        return self.poly.d(d2, d3).at(t2, t3)

    def node(self, t2: float, t3: float) -> tuple[int, int]:
        h = 2 * np.pi / FINE
        return int(round(t2 / h)) % FINE, int(round(t3 / h)) % FINE

    def aspect_of(self, t: np.ndarray) -> int:
        """The aspect (1-based; 0: on the singular set or not told) of the configuration t = (t1, t2, t3)."""
        s = np.sign(self.value(t[1], t[2])[0])
        if abs(self.value(t[1], t[2])[0]) <= ZERO * self.top:
            return 0
        i, j = self.node(t[1], t[2])
        h = 2 * np.pi / FINE
        best, dist = 0, np.inf
        for a in (-1, 0, 1):
            for b in (-1, 0, 1):
                ii, jj = (i + a) % FINE, (j + b) % FINE
                lab = self.labels[ii, jj]
                if lab and np.sign(self.value(ii * h, jj * h)[0]) == s:
                    d = np.hypot(np.angle(np.exp(1j * (ii * h - t[1]))), np.angle(np.exp(1j * (jj * h - t[2]))))
                    if d < dist:
                        best, dist = int(lab), d
        return best


def _det_grid(arm: Arm3R) -> np.ndarray:
    ts = 2 * np.pi * np.arange(SAMPLES) / SAMPLES
    return np.array([[arm.det((0.0, a, b)) for b in ts] for a in ts])


def _label_periodic(mask: np.ndarray) -> tuple[np.ndarray, int]:
    from scipy import ndimage

    lab, n = ndimage.label(mask)
    parent = list(range(n + 1))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for A, B in ((lab[0, :], lab[-1, :]), (lab[:, 0], lab[:, -1])):
        for a, b in zip(A, B):
            if a and b:
                ra, rb = find(a), find(b)
                if ra != rb:
                    parent[ra] = rb
    roots = sorted({find(a) for a in range(1, n + 1)})
    new = np.zeros(n + 1, int)
    for a in range(1, n + 1):
        new[a] = roots.index(find(a)) + 1
    return new[lab], len(roots)


def aspects(arm: Arm3R) -> Aspects:
    """det J over the torus of (t2, t3), its aspects and the singular points of its zero set."""
    V = _det_grid(arm)
    coef = TrigPoly.from_samples(V, (6, 6), check=None)  # degree <= 4 and 3: the rest is round-off
    pad = np.zeros((FINE, FINE), complex)
    pad[np.ix_(coef.m % FINE, coef.n % FINE)] = coef.C
    F = np.fft.ifft2(pad).real * FINE**2
    top = float(np.abs(F).max())
    if np.abs(V).max() <= arm.mech.tolerances.zero * arm.mech.length**3:  # (L^3: det J's size)
        return Aspects(coef, top, np.zeros((FINE, FINE), int), 0, (), True, F)
    asp = Aspects(coef, top, np.zeros((FINE, FINE), int), 0, (), False, F)
    singular = _singular_points(asp, F, arm.mech.tolerances)
    labels, n = _label_aspects(asp, F, singular)
    return Aspects(coef, top, labels, n, singular, False, F)


def _edge_values(asp: Aspects, along: int) -> np.ndarray:
    """det J at EDGE points of every grid edge (endpoints included) along t2 (along = 0) or t3 (1): (FINE,
    FINE, EDGE + 1), [i, j] the edge from node (i, j) to its next neighbour (periodic), exact (the
    polynomial's terms: separable sums)."""
    p = asp.poly
    nodes = 2 * np.pi * np.arange(FINE) / FINE
    fine = 2 * np.pi * np.arange(FINE * EDGE + 1) / (FINE * EDGE)
    if along == 1:
        V = (np.exp(1j * np.outer(nodes, p.m)) @ p.C @ np.exp(1j * np.outer(fine, p.n)).T).real
    else:
        V = (np.exp(1j * np.outer(fine, p.m)) @ p.C @ np.exp(1j * np.outer(nodes, p.n)).T).real.T
    # (FINE, FINE * EDGE + 1)
    idx = np.arange(FINE)[:, None] * EDGE + np.arange(EDGE + 1)[None, :]
    out = V[:, idx]  # (FINE nodes across, FINE edges, EDGE + 1)
    return out if along == 1 else out.transpose(1, 0, 2)


def _label_aspects(asp: Aspects, F: np.ndarray, singular: tuple) -> tuple[np.ndarray, int]:
    """The aspects on the grid: nodes where det J is not zero and not within BLOCK cells of a singular point
    of its zero set, joined through grid edges along which det J keeps its sign (EDGE + 1 exact values each:
    a shallow crossing's thin wedge is seen where it is wider than a sixteenth of a cell, and the nodes next
    to the crossing, where it is thinner, are left out); labelled on the doubled periodic grid."""
    top = asp.top
    node_ok = np.abs(F) > ZERO * top
    h = 2 * np.pi / FINE
    g = np.arange(FINE) * h
    for a, b in singular:
        da = np.abs(np.angle(np.exp(1j * (g - a))))[:, None]
        db = np.abs(np.angle(np.exp(1j * (g - b))))[None, :]
        node_ok &= np.hypot(da, db) > BLOCK * h
    big = np.zeros((2 * FINE, 2 * FINE), bool)
    big[::2, ::2] = node_ok
    for along in (0, 1):
        E = _edge_values(asp, along)
        keeps = (np.all(E > ZERO * top, axis=2) | np.all(E < -ZERO * top, axis=2))
        nxt = np.roll(node_ok, -1, axis=along)
        if along == 0:
            big[1::2, ::2] = keeps & node_ok & nxt
        else:
            big[::2, 1::2] = keeps & node_ok & nxt
    lab, n = _label_periodic(big)
    return lab[::2, ::2], n


def _singular_points(asp: Aspects, F: np.ndarray, tol: Tolerances) -> tuple:
    """The points of the torus where det J and its gradient vanish together: Newton on grad det J = 0 from
    every node of the grid where det J is small and |grad det J| least among its eight neighbours."""
    from scipy import ndimage

    h = 2 * np.pi / FINE
    g = np.arange(FINE) * h
    T2, T3 = np.meshgrid(g, g, indexing="ij")
    p = asp.poly
    Em, En = np.exp(1j * np.outer(g, p.m)), np.exp(1j * np.outer(g, p.n))
    G2 = (Em @ p.d(1, 0).C @ En.T).real
    G3 = (Em @ p.d(0, 1).C @ En.T).real
    grad = np.hypot(G2, G3)
    gtop = max(float(grad.max()), TINY)
    seeds = (np.abs(F) < 0.05 * asp.top) & (grad <= ndimage.minimum_filter(grad, size=3, mode="wrap"))
    i, j = np.nonzero(seeds)
    found = []
    for n in np.argsort(grad[i, j])[:400]:
        if grad[i[n], j[n]] > 0.1 * gtop:
            break
        t = np.array([T2[i[n], j[n]], T3[i[n], j[n]]])
        for _ in range(30):
            gv = np.array([asp.value(*t, 1, 0)[0], asp.value(*t, 0, 1)[0]])
            H = np.array([[asp.value(*t, 2, 0)[0], asp.value(*t, 1, 1)[0]],
                          [asp.value(*t, 1, 1)[0], asp.value(*t, 0, 2)[0]]])
            try:
                step = np.linalg.solve(H, -gv)
            except np.linalg.LinAlgError:
                break
            t = t + np.clip(step, -0.1, 0.1)
            if np.abs(step).max() < tol.zero:
                break
        gv = np.hypot(asp.value(*t, 1, 0)[0], asp.value(*t, 0, 1)[0])
        if gv < tol.cusp * gtop and abs(asp.value(*t)[0]) < tol.cusp * asp.top:
            t = np.angle(np.exp(1j * t))
            if all(np.abs(np.angle(np.exp(1j * (t - s)))).max() > tol.singular for s in found):
                found.append(t)
    # a singular set of dimension one (a squared factor) gives many: a few stand for it
    return tuple(tuple(float(v) for v in s) for s in found[:64])


def witness(asp: Aspects, a: np.ndarray, b: np.ndarray) -> float | None:
    """The smallest |det J| (share of its largest) along a path of the fine grid joining configurations a
    and b within one same-sign part of |det J| >= AWAY, checked 8 times per step on the exact polynomial;
    None where there is no such path."""
    h = 2 * np.pi / FINE
    sa, sb = np.sign(asp.value(a[1], a[2])[0]), np.sign(asp.value(b[1], b[2])[0])
    if sa != sb:
        return None
    F = asp.grid
    ok = (np.sign(F) == sa) & (np.abs(F) >= AWAY * asp.top)
    start, goal = asp.node(a[1], a[2]), asp.node(b[1], b[2])
    if not ok[start] or not ok[goal]:
        return None
    prev = {start: None}
    todo = deque([start])
    while todo:
        n = todo.popleft()
        if n == goal:
            break
        for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            m = ((n[0] + di) % FINE, (n[1] + dj) % FINE)
            if m not in prev and ok[m]:
                prev[m] = n
                todo.append(m)
    if goal not in prev:
        return None
    path, n = [], goal
    while n is not None:
        path.append(n)
        n = prev[n]
    P = [np.array([a[1], a[2]])] + [np.array([i * h, j * h]) for i, j in reversed(path)] + [np.array([b[1], b[2]])]
    pts = []
    for p, q in zip(P, P[1:]):
        d = np.angle(np.exp(1j * (q - p)))  # the short way round
        pts.append(p + np.outer(np.arange(8) / 8, d))
    pts = np.vstack(pts + [P[-1][None]])
    D = asp.value(pts[:, 0], pts[:, 1])
    if np.any(np.sign(D) != sa):
        return None
    return float(np.abs(D).min() / asp.top)


@dataclass(frozen=True)
class Verdict:
    cuspidal: bool | None
    rests_on: str
    generic: bool | None
    aspects: int


def verdict(arm: Arm3R, asp: Aspects, points: list, cusps: int, covers: str, counted_all: bool) -> Verdict:
    """The verdict (see the module) from the IK at ``points`` (world: the region samples, a grid, rings round the
    cusps traced), the number of cusps traced, ``covers`` ("" where the section holds the whole workspace through the first axis, else
    why not) and whether every region was counted."""
    if asp.identically_zero:
        return Verdict(None, "det J of the point over the three joints is zero everywhere: they never move it in "
                             "three directions, so there are no aspects to tell solutions apart", None, 0)
    generic = not asp.singular_points
    shape = ("generic (det J's zero set on the (t2, t3) torus has no singular point)" if generic else
             "not generic: det J's zero set on the (t2, t3) torus is singular at (t2, t3) = "
             + ", ".join(f"({np.degrees(a):.4g} deg, {np.degrees(b):.4g} deg)" for a, b in asp.singular_points[:4])
             + " (it factors or crosses itself), so the cusp criterion does not apply and the aspects decide")
    grid = (f"{asp.count} aspects: the same-sign parts of det J on a {FINE} x {FINE} grid of the (t2, t3) torus, its "
            f"edges checked at {EDGE + 1} points each, {BLOCK} cells round each singular point of det J = 0 left out")
    shared, checked = None, 0
    for c in points:
        sols, why = point_ik(arm, c)
        if why or len(sols) < 2:
            continue
        dets = [abs(asp.value(t[1], t[2])[0]) for t in sols]
        if min(dets) < AWAY * asp.top:
            continue  # on or near the singular curve
        checked += 1
        labs = [asp.aspect_of(t) for t in sols]
        for i in range(len(sols)):
            for j in range(i + 1, len(sols)):
                if labs[i] and labs[i] == labs[j]:
                    m = witness(asp, sols[i], sols[j])
                    if m is not None:
                        return Verdict(True, f"two inverse-kinematic solutions of the point {_world_point(c)} are joined in joint "
                                             f"space with det J of one sign all along (|det J| at least {m:.2g} of its "
                                             f"largest, checked densely on its exact trigonometric polynomial): one "
                                             f"aspect holds both; {cusps} cusps traced; {grid}; the robot is {shape}",
                                       generic, asp.count)
                    shared = c if shared is None else shared
    if cusps and generic:
        return Verdict(True, f"{cusps} cusps of the serial singular curve in the section, three IK solutions meeting "
                             f"at each: a generic 3R with a cusp is cuspidal (Salunkhe et al. 2022); {grid}",
                       generic, asp.count)
    if shared is not None:
        return Verdict(None, f"two IK solutions of the point {_world_point(shared)} fall in one part of the grid but no path "
                             f"keeping |det J| above {AWAY:g} of its largest joins them; {grid}; the robot is {shape}",
                       generic, asp.count)
    if cusps:
        note = (f"; the {cusps} 'cusps' traced are where its non-generic singular curves meet, not three solutions "
                "meeting: no two solutions share an aspect on a ring round each")
    else:
        note = ""
    if covers:
        return Verdict(None, f"no two IK solutions in one aspect at {checked} points of the section, but {covers}",
                       generic, asp.count)
    if not counted_all:
        return Verdict(None, "some regions of the section were not counted, so not every part of the workspace was "
                             "checked", generic, asp.count)
    base = (f"the section holds the whole workspace (through the first axis); at {checked} points of it (every region's "
            f"sample, a grid, rings round any traced cusp) every IK solution (closed form) lies in an aspect of its own "
            f"({grid}), so none reaches another without a singularity (sampled, not proved)")
    if generic:
        return Verdict(False, f"{base}; the robot is {shape} and no cusp was traced, which agrees (Salunkhe et al. 2022)",
                       generic, asp.count)
    return Verdict(False, f"{base}; the robot is {shape} (e.g. det J factoring into posture terms of constant sign on "
                          f"each solution: Wenger 1997; Baili, Wenger & Chablat 2004){note}", generic, asp.count)


def _world_point(c) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in c) + ") m"


def section_extent(arm: Arm3R, asp: Aspects, h_axis: int, level: float, axes: tuple) -> tuple[np.ndarray | None, str]:
    """(the corners (xmin, xmax, ymin, ymax) of the workspace's section in the plane, or None, and "" or why the
    plane does not meet every orbit of the first joint): the point's distance from the first axis and height
    along it over a 90 x 90 grid of (t2, t3)."""
    w1, r1 = arm.axes[0], arm.points[0]
    L = arm.mech.length
    tol = arm.mech.tolerances.closed_form
    if abs(w1[h_axis]) > tol or abs(r1[h_axis] - level) > tol * max(L, 1.0):
        return None, "the section's plane does not contain the first joint's axis, so it does not meet every orbit of the workspace"
    g = np.linspace(0, 2 * np.pi, 90, endpoint=False)
    P = np.array([KinematicState(arm.mech, arm.q((0.0, a, b))).frame_placement(arm.fid).translation for a in g for b in g])
    d = P - r1
    hgt = d @ w1
    rho = np.linalg.norm(d - np.outer(hgt, w1), axis=1)
    e = np.zeros(3)
    e[h_axis] = 1.0
    n = np.cross(e, w1)
    n /= np.linalg.norm(n)
    pts = np.vstack([r1 + np.outer(hgt, w1) + np.outer(s * rho, n) for s in (1, -1)])
    X, Y = pts[:, axes[0]], pts[:, axes[1]]
    return np.array([X.min(), X.max(), Y.min(), Y.max()]), ""
