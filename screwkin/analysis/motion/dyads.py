"""Planar motions in closed form: a sweep solved for every input value at once.

A planar mechanism (every revolute axis parallel to one normal n, every prismatic axis
in the plane) whose other inputs are held is split, when it can be, into the swept
input joint and class-II Assur groups (dyads: two links, three joints), in an order
where each dyad's two outer joints sit on links already placed:

- RRR: the inner joint B at the intersection of the circles about A and C;
- RRP / PRR: the circle about the revolute outer joint and the line of the slide;
- RPR: the two links turn together; the slide's offset from the line AC is fixed.

Every link is written as a planar displacement from the configuration q0 the sweep
starts from (``solver.solve``'s first solution, as ``sweep`` chooses it): a rotation
theta about n and a translation t, so that a material point at x0 (plane coordinates
at q0) is at R(theta) x0 + t.  Each dyad's branch (the sign of its square root) is
read off q0 and kept; a dyad's discriminant reaching zero between grid values is a
limit position, located by Brent's method on it.  The quantities are carried as
second-order jets (value, d/dx, d2/dx2 in the input x), so that the joint rates and
accelerations are the exact derivatives of the closed form: q' rate and q'' rate^2
(input acceleration zero, other inputs held), what PositionSolver.rates and
.accelerations give for a mechanism the inputs determine.

``ClosedFormCurve`` is the continuation engine (analysis.motion.continuation's interface) that does
this; ``plan`` says why a mechanism does not decompose (then ``sweep`` runs another engine);
``planar_sweep`` reproduces ``sweep``'s result (limits, turns, circuit, budget) from
the closed form, every configuration checked by its closure residual first.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.geometry import cross3, plane_basis
from ...model.manifold import continuous_angle, set_continuous_angle
from ...model.planar_graph import DyadPlan, plan
from ...model.state import KinematicState
from .batch_sweep import batch_closure
from .continuation import CHANGE_REASON, LIMIT_REASON, at_change_point, locate, returned
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["Jet", "ClosedFormSweep", "ClosedFormCurve", "planar_sweep", "cached_plan"]

_PARALLEL = 1e-9  # |axis x n| (or |axis . n| of a slide) accepted as parallel (normal) [-]
_NEAR_LIMIT = 1e-8  # a relative discriminant at q0 below this: q0 is (nearly) a limit position; not handled [-]


class Jet:
    """A value with its first and second derivatives along the input x (numpy arrays)."""

    __slots__ = ("v", "d", "dd")

    def __init__(self, v: np.ndarray, d: float=0.0, dd: float=0.0) -> None:
        self.v, self.d, self.dd = v, d, dd

    def __add__(self, o: Jet) -> Jet:
        if isinstance(o, Jet):
            return Jet(self.v + o.v, self.d + o.d, self.dd + o.dd)
        return Jet(self.v + o, self.d, self.dd)

    __radd__ = __add__

    def __neg__(self) -> Jet:
        return Jet(-self.v, -self.d, -self.dd)

    def __sub__(self, o: Jet | float) -> Jet:
        return self + (-o)

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o: Jet) -> Jet:
        if isinstance(o, Jet):
            return Jet(self.v * o.v, self.d * o.v + self.v * o.d, self.dd * o.v + 2 * self.d * o.d + self.v * o.dd)
        return Jet(self.v * o, self.d * o, self.dd * o)

    __rmul__ = __mul__

    def inverse(self) -> Jet:
        f = 1.0 / self.v
        return Jet(f, -self.d * f * f, (2 * self.d * self.d * f - self.dd) * f * f)

    def __truediv__(self, o: Jet) -> Jet:
        return self * o.inverse() if isinstance(o, Jet) else self * (1.0 / o)

    def sqrt(self) -> Jet:
        f = np.sqrt(self.v)
        return Jet(f, self.d / (2 * f), self.dd / (2 * f) - self.d * self.d / (4 * f ** 3))

    def cos(self) -> Jet:
        c, s = np.cos(self.v), np.sin(self.v)
        return Jet(c, -s * self.d, -c * self.d * self.d - s * self.dd)

    def sin(self) -> Jet:
        c, s = np.cos(self.v), np.sin(self.v)
        return Jet(s, c * self.d, -s * self.d * self.d + c * self.dd)

    @staticmethod
    def atan2(y: Jet, x: Jet) -> Jet:
        r2 = x.v * x.v + y.v * y.v
        num = x.v * y.d - y.v * x.d
        dr2 = 2 * (x.v * x.d + y.v * y.d)
        return Jet(np.arctan2(y.v, x.v), num / r2, (x.v * y.dd - y.v * x.dd) / r2 - num * dr2 / (r2 * r2))


class _Pose:
    """A link's planar displacement from q0: x -> R(th) x + t (jets)."""

    __slots__ = ("th", "c", "s", "tx", "ty")

    def __init__(self, th: Jet, tx: Jet, ty: Jet) -> None:
        self.th, self.c, self.s, self.tx, self.ty = th, th.cos(), th.sin(), tx, ty

    def rotate(self, u: np.ndarray | tuple) -> tuple:
        return self.c * u[0] - self.s * u[1], self.s * u[0] + self.c * u[1]

    def __call__(self, p: np.ndarray | tuple) -> tuple:
        x, y = self.rotate(p)
        return x + self.tx, y + self.ty

    @classmethod
    def through(cls, th: Jet, point: tuple, p0: np.ndarray) -> _Pose:
        """The displacement turning by th that takes the q0 point p0 to ``point``."""
        c, s = th.cos(), th.sin()
        return cls(th, point[0] - (c * p0[0] - s * p0[1]), point[1] - (s * p0[0] + c * p0[1]))


def _turn_from(u0: np.ndarray, u: tuple) -> Jet:
    """The angle from the constant vector u0 to the jet vector u, in (-pi, pi]."""
    return Jet.atan2(u[1] * u0[0] - u[0] * u0[1], u[0] * u0[0] + u[1] * u0[1])


class _Geometry:
    """The plan's joints read at q0: plane basis, points and slide directions in plane
    coordinates, axis signs, the branch of each dyad (``probe``; without it ``branch`` is None:
    the caller chooses the branches, as dyad_modes does for every one of them)."""

    def __init__(self, mech: Mechanism, p: DyadPlan, q0: np.ndarray, probe: bool = True) -> None:
        state = KinematicState(mech, q0)
        axes, points = [], []  # per pair: (on the side of its first group, of its second)
        for pr in p.pairs:
            if pr.tree is not None:
                col = state.joint_twists(pr.tree)[:, 0]  # its unit twist (v at the world origin, w)
                v, w = col[:3], col[3:]
                if pr.kind == "R":
                    x = cross3(w, v) / (w @ w)
                    axes.append((w, w))
                else:
                    x = state.centre(("joint", pr.tree))
                    axes.append((v, v))
                points.append((x, x))
            else:  # each side from its own frame: exact on its link, whatever q0's closure residual
                cut = next(c for c in mech.cuts if c.name == pr.name)
                M1, M2 = state.frame_placement(cut.frame1), state.frame_placement(cut.frame2)
                a = np.asarray(cut.axis, float)
                axes.append((M1.rotation @ a, M2.rotation @ a))
                points.append((M1.translation.copy(), M2.translation.copy()))
        axes = [tuple(a / np.linalg.norm(a) for a in both) for both in axes]
        n = next((a[0] for a, pr in zip(axes, p.pairs) if pr.kind == "R"), None)
        self.ok = n is not None
        if not self.ok:
            self.reason = "no revolute joint: no plane"
            return
        for a, pr in zip((a for both in axes for a in both), (pr for pr in p.pairs for _ in (0, 1))):
            if (pr.kind == "R" and np.linalg.norm(cross3(a, n)) > _PARALLEL) or (pr.kind == "P" and abs(a @ n) > _PARALLEL):
                self.ok, self.reason = False, f"joint {pr.name} is out of the plane of the others"
                return
        e1, e2, n = plane_basis(n)
        self.pairs = p.pairs
        self._points = [tuple(np.array([e1 @ x, e2 @ x]) for x in both) for both in points]
        self._dirs = [tuple(np.array([e1 @ a, e2 @ a]) for a in both) for both in axes]
        self.signs = [float(np.sign(a[0] @ n)) for a in axes]
        self.branch = [] if probe else None
        if not probe:
            return
        for (kinds, ia, ib, ic), (g1, g2) in zip(p.dyads, p.order[1:]):
            d = _solve_dyad(self, kinds, ia, ib, ic, g1, g2, None, None, None, probe=True)
            if not (abs(d) > _NEAR_LIMIT):
                self.ok, self.reason = False, "the start is at (or next to) a limit position"
                return
            self.branch.append(float(np.sign(d)))

    def point(self, i: int, g: int) -> np.ndarray:
        """Pair i's point (plane coordinates at q0) on the link of group g."""
        return self._points[i][self.pairs[i].groups.index(g)]

    def other(self, i: int, g: int) -> np.ndarray:
        """Pair i's point on the link of its group other than g."""
        return self._points[i][1 - self.pairs[i].groups.index(g)]

    def dir(self, i: int, g: int) -> np.ndarray:
        """Pair i's axis (a slide's direction, plane coordinates at q0) on the link of group g."""
        return self._dirs[i][self.pairs[i].groups.index(g)]


def _solve_dyad(geo: _Geometry, kinds: str, ia: int, ib: int, ic: int, g1: int, g2: int, pa: _Pose | None, pc: _Pose, sigma: float | str, probe: bool=False, clamp: bool=False) -> float | tuple:
    """((pose of link 1, pose of link 2), relative discriminant) of one dyad on groups g1, g2;
    pa, pc: the poses of the links its outer joints A (on g1) and C (on g2) join.  probe: the
    signed branch value at q0 instead (no poses)."""
    if kinds == "PRR":  # the mirror of RRP
        out = _solve_dyad(geo, "RRP", ic, ib, ia, g2, g1, pc, pa, sigma, probe, clamp)
        return out if probe else ((out[0][1], out[0][0]), out[1])
    A1, B1, B2, C2 = geo.point(ia, g1), geo.point(ib, g1), geo.point(ib, g2), geo.point(ic, g2)
    AK, CK = geo.other(ia, g1), geo.other(ic, g2)
    if probe:
        if kinds == "RRR":
            w, u = CK - AK, B1 - A1
            return (w[0] * u[1] - w[1] * u[0]) / (np.linalg.norm(w) * np.linalg.norm(u))
        if kinds == "RRP":  # b = d . (B - A) relative to r1
            return geo.dir(ic, g2) @ (B2 - AK) / np.linalg.norm(B1 - A1)
        return geo.dir(ib, g1) @ (C2 - A1) / np.linalg.norm(C2 - A1)  # RPR
    if kinds == "RRR":
        A, C = pa(AK), pc(CK)
        r1s, r2s = float((B1 - A1) @ (B1 - A1)), float((B2 - C2) @ (B2 - C2))
        w = (C[0] - A[0], C[1] - A[1])
        d2 = w[0] * w[0] + w[1] * w[1]
        a = (d2 + (r1s - r2s)) / (2.0 * d2)
        disc = d2.inverse() * r1s - a * a
        h = _root(disc, clamp) * sigma
        B = (A[0] + a * w[0] - h * w[1], A[1] + a * w[1] + h * w[0])
        th1 = _turn_from(B1 - A1, (B[0] - A[0], B[1] - A[1]))
        th2 = _turn_from(B2 - C2, (B[0] - C[0], B[1] - C[1]))
        return (_Pose.through(th1, A, A1), _Pose.through(th2, C, C2)), disc.v * d2.v / r1s
    if kinds == "RRP":  # B on g2 slides along a line of C's other link
        A, P = pa(AK), pc(B2)
        dd = pc.rotate(geo.dir(ic, g2))
        e = (P[0] - A[0], P[1] - A[1])
        r1s = float((B1 - A1) @ (B1 - A1))
        b = dd[0] * e[0] + dd[1] * e[1]
        disc = b * b - (e[0] * e[0] + e[1] * e[1] - r1s)
        s = _root(disc, clamp) * sigma - b
        B = (P[0] + s * dd[0], P[1] + s * dd[1])
        th1 = _turn_from(B1 - A1, (B[0] - A[0], B[1] - A[1]))
        return (_Pose.through(th1, A, A1), _Pose.through(pc.th, B, B2)), disc.v / r1s
    # RPR: both links turn by the same angle; C - A = R(th) (C2 - A1 + s d)
    A, C = pa(AK), pc(CK)
    d0, v0 = geo.dir(ib, g1), C2 - A1
    w = (C[0] - A[0], C[1] - A[1])
    b = float(d0 @ v0)
    v0s = float(v0 @ v0)
    disc = (w[0] * w[0] + w[1] * w[1]) + (b * b - v0s)
    s = _root(disc, clamp) * sigma - b
    u = (s * d0[0] + v0[0], s * d0[1] + v0[1])
    th = Jet.atan2(u[0] * w[1] - u[1] * w[0], u[0] * w[0] + u[1] * w[1])
    return (_Pose.through(th, A, A1), _Pose.through(th, C, C2)), disc.v / v0s


def _root(disc: Jet, clamp: bool) -> Jet:
    """The square root of a discriminant (NaN where it is negative); clamp: of max(disc, 0),
    values only (at a limit position, where the derivatives are infinite)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return Jet(np.sqrt(np.maximum(disc.v, 0.0))) if clamp else disc.sqrt()


def _evaluate(geo: _Geometry, p: DyadPlan, xs: np.ndarray, start: float, branch: str, clamp: int | None = None) -> tuple:
    """(pose of every group, discriminants (dyads, N)) at input values xs on the given branches;
    clamp: the index of a dyad whose discriminant is taken as max(disc, 0) (at its limit).
    Past a limit the values are NaN; at it the derivatives are infinite (never reported)."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        return _evaluate_all(geo, p, xs, start, branch, clamp)


def _evaluate_all(geo: _Geometry, p: DyadPlan, xs: np.ndarray, start: float, branch: str, clamp: int | None) -> tuple:
    xs = np.asarray(xs, float)
    zero = Jet(np.zeros(len(xs)))
    poses = {p.groups[0]: _Pose(zero, zero, zero)}
    sw = p.pairs[p.swept]
    delta = Jet(xs - start, 1.0, 0.0)
    k, u = p.order[0]
    g = poses[k]
    if sw.kind == "R":
        a0 = geo.point(p.swept, k)
        turn = delta * geo.signs[p.swept] * (1.0 if k == sw.groups[0] else -1.0)
        poses[u] = _Pose.through(g.th + turn, g(a0), a0)
    else:
        o0, d0 = geo.point(p.swept, k), geo.dir(p.swept, k)
        step = delta * (1.0 if k == sw.groups[0] else -1.0)
        poses[u] = _Pose.through(g.th, g((step * d0[0] + o0[0], step * d0[1] + o0[1])), o0)
    discs = np.empty((len(p.dyads), len(xs)))
    for i, ((kinds, ia, ib, ic), (g1, g2)) in enumerate(zip(p.dyads, p.order[1:])):
        pa_group = next(g for g in p.pairs[ia].groups if g != g1)
        pc_group = next(g for g in p.pairs[ic].groups if g != g2)
        (p1, p2), discs[i] = _solve_dyad(geo, kinds, ia, ib, ic, g1, g2, poses[pa_group], poses[pc_group],
                                         branch[i], clamp=clamp == i)
        poses[g1], poses[g2] = p1, p2
    return poses, discs


class _Layout:
    """Where each tree joint's coordinate comes from: the groups of its two links, its kind."""

    def __init__(self, mech: Mechanism, p: DyadPlan, geo: _Geometry, q0: np.ndarray) -> None:
        model = mech.model
        self.rows = []  # (idx_q, nq, idx_v, kind, parent group, child group, pair index or None)
        by_tree = {pr.tree: i for i, pr in enumerate(p.pairs) if pr.tree is not None}
        for j in range(1, model.njoints):
            i = by_tree.get(j)  # None: a held input (both links in one group)
            self.rows.append((model.idx_qs[j], model.nqs[j], model.idx_vs[j], p.pairs[i].kind if i is not None else None,
                              p.groups[model.parents[j]], p.groups[j], i))
        self.geo, self.q0, self.nq, self.nv = geo, q0, model.nq, model.nv
        self.wrapped = [(iq, iv) for iq, nq, iv, kind, _, _, _ in self.rows if kind == "R" and nq == 1]

    def __call__(self, poses: dict, N: int) -> tuple:
        """(Q (N, nq) with the one-coordinate angles not yet unwrapped, dq/dx, d2q/dx2 (N, nv))."""
        geo, q0 = self.geo, self.q0
        Q = np.tile(q0, (N, 1))
        V, A = np.zeros((N, self.nv)), np.zeros((N, self.nv))
        for iq, nq, iv, kind, gp, gc, i in self.rows:
            if kind is None:
                continue
            pp, pc = poses[gp], poses[gc]
            if kind == "R":
                rel = (pc.th - pp.th) * geo.signs[i]
                if nq == 2:
                    set_continuous_angle(Q, iq, continuous_angle(q0, iq) + rel.v)
                else:
                    Q[:, iq] = q0[iq] + rel.v
            else:
                o0, d0 = geo.point(i, gp), geo.dir(i, gp)
                (xc, yc), (xp, yp) = pc(o0), pp(o0)
                dx, dy = xc - xp, yc - yp
                # d0 . R(-th_p) (g_c(o0) - g_p(o0))
                rel = (pp.c * dx + pp.s * dy) * d0[0] + (pp.c * dy - pp.s * dx) * d0[1]
                Q[:, iq] = q0[iq] + rel.v
            V[:, iv] = rel.d
            A[:, iv] = rel.dd
        return Q, V, A


class _Unwrap:
    """Makes the one-coordinate revolute angles continuous along the motion: each new sample
    takes the turn (2 pi k) nearest to the previous one moved by its slopes d angle / dx
    (trapezoid).  ``ambiguous``: a step turned a joint by more than a quarter turn, where the
    choice could be wrong (a coarse grid; next to a limit, where the slope is infinite)."""

    _SAFE = np.pi / 2  # the largest turn between two samples taken as unambiguous [rad]
    _SLACK = 0.01  # relative slack of the bounds |s| dx on a monotone step

    def __init__(self, wrapped: list) -> None:
        self.cols = np.array([iq for iq, _ in wrapped], int)
        self._iv = np.array([iv for _, iv in wrapped], int)
        self.last = None  # (raw, slope, x, turns) of the last sample
        self.ambiguous = False

    def __call__(self, Q: np.ndarray, D: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """Q with its angles unwrapped; D (N, nv): dq/dx."""
        if not len(self.cols) or not len(xs):
            return Q
        raw = Q[:, self.cols]
        slope = D[:, self._iv]
        if self.last is None:
            self.last = (raw[0], slope[0], xs[0], np.zeros(len(self.cols)))
        r0, s0, x0, k0 = self.last
        rr = np.vstack([r0, raw])
        ss = np.vstack([s0, slope])
        xx = np.concatenate([[x0], xs])
        dx = np.diff(xx)[:, None]
        with np.errstate(invalid="ignore", over="ignore"):
            pred = 0.5 * (ss[1:] + ss[:-1]) * dx
        pred = np.where(np.isfinite(pred), pred, 0.0)
        dr = np.diff(rr, axis=0)
        k = np.round((pred - dr) / (2 * np.pi))
        # next to a limit position the slope grows without bound and the trapezoid overshoots by turns:
        # where both slopes have one sign, the angle moves monotonically by between |s| dx at the
        # smaller slope and at the larger; the smallest turn that does so is taken instead
        k_near = np.round(-dr / (2 * np.pi))
        near = dr + 2 * np.pi * k_near
        a0, a1 = np.abs(ss[:-1] * dx), np.abs(ss[1:] * dx)
        with np.errstate(invalid="ignore"):
            monotone = (np.sign(ss[1:]) == np.sign(ss[:-1])) & (np.sign(near) == np.sign(ss[1:] * dx))
            fits = monotone & (np.abs(near) >= np.minimum(a0, a1) * (1 - self._SLACK)) & (
                np.abs(near) <= np.maximum(a0, a1) * (1 + self._SLACK))
        k = np.where(fits, k_near, k)
        if np.any(np.abs(np.diff(rr, axis=0) + 2 * np.pi * k) > self._SAFE):
            self.ambiguous = True
        turns = k0 + np.cumsum(k, axis=0)
        Q = Q.copy()
        Q[:, self.cols] = raw + 2 * np.pi * turns
        self.last = (raw[-1], slope[-1], xs[-1], turns[-1])
        return Q


@dataclass(frozen=True)
class ClosedFormSweep:
    """What ``sweep`` reports, from the closed form (screwkin.analysis.motion.sweep.SweepResult's fields)."""

    values: np.ndarray  # input values in the order of the motion [rad or m]
    q: np.ndarray  # (steps, nq)
    joints: np.ndarray  # (steps, names) Mechanism.joint_values
    rates: np.ndarray  # (steps, nv)
    accelerations: np.ndarray  # (steps, nv)
    stopped_at: float | None
    stop_reason: str | None
    limits: tuple  # (input value, relative sigma of K_p, q) of each limit position met
    circuit_closed: bool
    unit: str


def cached_plan(solver, name: str) -> DyadPlan | str:
    """model.planar_graph.plan of the solver's mechanism swept along ``name`` with its other inputs
    held (a DyadPlan, or why not), kept in the mechanism's cache."""
    mech = solver.mech
    key = ("dyads.plan", tuple(solver.inputs), name)
    if key not in mech.cache:
        mech.cache[key] = plan(mech, solver.inputs, name)
    return mech.cache[key]


class ClosedFormCurve:
    """The closed form's continuation engine (analysis.motion.continuation's interface, every input value
    at once): the plan ``p``'s dyads read at q0 (input ``start``) and placed at input values.  ``ok`` is
    False (``reason`` why) when the geometry does not apply; probe=False: no branch is read off q0 (the
    caller passes its branch vectors, as dyad_modes does for every one of them)."""

    def __init__(self, mech: Mechanism, p: DyadPlan, q0: np.ndarray, start: float, probe: bool = True) -> None:
        self.mech, self.p, self.start = mech, p, start
        self.geo = _Geometry(mech, p, q0, probe)
        self.ok, self.reason = self.geo.ok, getattr(self.geo, "reason", None)
        if self.ok:
            self.layout = _Layout(mech, p, self.geo, q0)
            self.branch = None if self.geo.branch is None else list(self.geo.branch)

    def predict(self, xs: np.ndarray | list, branch: str | list | None=None, clamp: int | None = None) -> tuple:
        """(pose of every group, discriminants (dyads, N)) at the input values xs, on ``branch`` (a
        sign per dyad, or per dyad an array of them; default the branch followed); clamp: the dyad
        at its limit (its discriminant taken as max(disc, 0))."""
        return _evaluate(self.geo, self.p, xs, self.start, self.branch if branch is None else branch, clamp)

    @staticmethod
    def accept(discs: np.ndarray) -> int:
        """How many leading values are placed: every discriminant non-negative (past a limit the branch
        does not exist; its values are NaN)."""
        bad = np.flatnonzero(~(discs.min(axis=0) >= 0)) if len(discs) else np.zeros(0, int)
        return int(bad[0]) if len(bad) else discs.shape[1]

    def correct(self, poses: dict, n: int) -> tuple:
        """The closed form is exact: the poses of the first n values as joint coordinates
        (Q with its one-coordinate angles not yet unwrapped, dq/dx, d2q/dx2)."""
        return self.layout({g: _Pose(_take(q.th, n), _take(q.tx, n), _take(q.ty, n)) for g, q in poses.items()}, n)

    def choose_branch(self, which) -> None:
        """Past the limit position of dyad ``which`` the motion goes on along its other branch."""
        self.branch[which] = -self.branch[which]

    def locate_limit(self, lo: float, hi: float):
        """(input value, joint coordinates Q (1, nq; angles not yet unwrapped), dq/dx, dyad) of the limit
        position between the input values lo (placed) and hi (not): Brent's method (continuation.locate)
        on the smallest discriminant; None when lo's is not positive (two limit positions in one step)."""

        def worst(x) -> float:
            d = self.predict([x])[1][:, 0]
            return float(np.min(np.where(np.isnan(d), -1.0, d)))

        if not worst(lo) > 0:
            return None
        x_lim = locate(worst, lo, hi, xtol=1e-15, maxiter=200)
        d_lim = self.predict([x_lim])[1][:, 0]
        which = int(np.argmin(np.abs(np.where(np.isnan(d_lim), np.inf, d_lim))))
        Q, D, _ = self.correct(self.predict([x_lim], clamp=which)[0], 1)
        return x_lim, Q, D, which


def _ready(solver, name: str, q0: np.ndarray, start: float) -> ClosedFormCurve | None:
    """The ClosedFormCurve for sweeping ``name`` from q0, or None when the closed form does not apply."""
    p = cached_plan(solver, name)
    if isinstance(p, str):
        return None
    curve = ClosedFormCurve(solver.mech, p, q0, start)
    return curve if curve.ok else None


def _residuals_ok(mech: Mechanism, Q: np.ndarray) -> bool:
    """Every configuration closes the loops within the closure tolerance (batched where it can be)."""
    tol = mech.tolerances.closure
    if not len(Q) or not mech.cuts:
        return True
    bc = batch_closure(mech)
    if bc is None:
        return all(np.linalg.norm(mech.closure.residual(q)) <= tol for q in Q)
    r = bc.evaluate(Q, jacobian=False)[0]
    return bool(np.all(np.sqrt(np.einsum("ij,ij->i", r, r)) <= tol))


def _next_values(start: float, stop: float, steps: int, h: float, k_pos: float, forward: bool, first: bool,
                 budget: int) -> np.ndarray | None:
    """The input values of the next pass of planar_sweep: the grid values after grid position ``k_pos``
    (forward; from the first on the ``first`` pass) or before it (back, after a limit position), at most
    ``budget``, the last forward one at ``stop``; None when none is left forward."""
    if forward:
        j0 = int(np.floor(k_pos + 1e-9)) + 1
        js = np.arange(0 if first else j0, steps + 1)[:budget]
        if not len(js):
            return None
    else:
        j0 = int(np.ceil(k_pos - 1e-9)) - 1
        js = np.arange(j0, j0 - budget, -1)
    xs = start + js * h
    if forward and js[-1] == steps and (xs[-1] - stop) * np.sign(h) > 0:
        xs[-1] = stop
    if h == 0:
        xs = xs[:1]
    return xs


def planar_sweep(solver, name: str, q0: np.ndarray, start: float, stop: float, steps: int, rate: float=1.0, turn: bool=False, max_steps: int | None=None) -> ClosedFormSweep | None:
    """``sweep``'s result from the closed form, started from q0 (its assembly mode); None when
    the mechanism does not decompose into dyads, or where the result would not be sweep's
    (two limits between grid values, a configuration not closing the loops)."""
    curve = _ready(solver, name, q0, start)
    if curve is None:
        return None
    mech = solver.mech
    max_steps = max_steps or 20 * steps + 100
    h = (stop - start) / steps
    scale = np.where(mech.translational, mech.length, 1.0)
    unwrap = _Unwrap(curve.layout.wrapped)
    Xs, Qs, Vs, As, limits = [], [], [], [], []
    count, k_pos, forward = 0, 0.0, True
    stopped = reason = None
    closed = False
    last_x = float(start)
    first = True
    while True:
        if count >= max_steps:  # (the tracker stops at its last step, which may lie past the last grid value)
            stopped, reason = last_x, f"the step budget ({max_steps} configurations) is spent"
            break
        if h == 0 and not first:
            break
        xs = _next_values(start, stop, steps, h, k_pos, forward, first, max_steps - count)
        if xs is None:
            break
        poses, discs = curve.predict(xs)
        n_ok = curve.accept(discs)
        if first and n_ok == 0:
            return None
        if n_ok:
            Q, D, DD = curve.correct(poses, n_ok)
            Q, V, A = unwrap(Q, D, xs[:n_ok]), D * rate, DD * rate * rate
            xs_ok = xs[:n_ok]
            if turn and forward and not first:  # back at the start: the circuit is closed
                near = np.flatnonzero(np.abs(xs_ok - start) < mech.tolerances.equal * max(1.0, abs(h)))  # (cheap first)
                for i in near:
                    if count + i + 1 > 2 and returned(mech, xs_ok[i], start, h, Q[i], q0, scale):
                        n_ok, closed = int(i) + 1, True
                        Q, V, A, xs_ok = Q[:n_ok], V[:n_ok], A[:n_ok], xs_ok[:n_ok]
                        break
            Xs.append(xs_ok), Qs.append(Q), Vs.append(V), As.append(A)
            count += n_ok
            last_x = float(xs_ok[-1])
            k_pos = (last_x - start) / h if h else 0.0
        first = False
        if closed:
            break
        if n_ok == len(xs):
            continue  # the end of the range (forward), or the budget (back): said at the top
        # a limit position between last_x and xs[n_ok]
        found = curve.locate_limit(last_x, float(xs[n_ok]))
        if found is None:
            return None  # two limit positions within one step of the grid
        x_lim, Q, D, which = found
        q_lim = unwrap(Q, D, np.array([x_lim]))[0]
        if not _residuals_ok(mech, q_lim[None]):
            return None
        m = at_change_point(solver, q_lim)
        limits.append((float(x_lim), float(m["actuator"]), q_lim))
        if m["change"]:  # not a limit: a change point, which sweep carries the motion through
            stopped, reason = float(x_lim), CHANGE_REASON
            break
        if not turn:
            stopped, reason = float(x_lim), LIMIT_REASON
            break
        curve.choose_branch(which)
        forward = not forward
        k_pos = (x_lim - start) / h
        last_x = float(x_lim)
    if unwrap.ambiguous:
        return None  # the tracker, which follows the turns of every joint step by step
    X = np.concatenate(Xs)
    Q, V, A = np.vstack(Qs), np.vstack(Vs), np.vstack(As)
    if not _residuals_ok(mech, Q):
        return None
    if turn and stopped is None and not closed and (stop - last_x) * np.sign(h) > mech.tolerances.equal * max(1.0, abs(stop)):
        stopped, reason = last_x, "the motion did not reach the end of the range"
    unit = "m" if curve.p.pairs[curve.p.swept].kind == "P" else "rad"
    return ClosedFormSweep(X, Q, mech.joint_value_rows(Q), V, A, stopped, reason, tuple(limits), closed, unit)


def _take(j, n: int) -> Jet:
    return Jet(*(np.broadcast_to(a, np.shape(j.v))[:n] if np.ndim(a) else a for a in (j.v, j.d, j.dd)))
