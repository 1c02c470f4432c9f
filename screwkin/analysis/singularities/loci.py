"""Singular loci in the plane of two inputs, traced (issue 44).

With the inputs other than x and y held, the configurations form a surface S (two DOF).  A kind of
singularity is the rank drop of a matrix A(q) whose columns are independent at generic configurations:

- actuator (direct kinematic, type II): A = K_p, the passive columns of the constraint Jacobian: the
  passive joints move with every input locked -- two assembly modes meet (a fold of S over the plane);
- serial (inverse kinematic, type I; needs an output): A = [K; J_o]: the joints move, loops closed,
  with the output at rest;

both dimensionless as in analysis.singular (lengths over the characteristic length L).
Its locus is the curve of S where A v = 0 for a unit v: the solutions z = (q, v) of the augmented system

    F(z) = [closure rows r(q); held inputs - their values; A(q) v; (v.v - 1)/2] = 0,

one equation short of the unknowns.  Each curve is followed by pseudo-arclength predictor-corrector
continuation in z (tangent: the null vector of dF; corrector: Newton with the step's hyperplane),
every point converged until |F| is round-off; its trace in the plane is read off q.  The derivative of
A(q) v is central differences of A (A itself comes from the analytic Jacobians of model.kernel.closure and
model.state); Newton's limit is the root of F, which is evaluated exactly.

Seeds: the assembly modes at the box's centre (the project's all-modes solve), each continued over a
coarse grid of the box (analysis.motion.continuation.Neighbour, the map's step); Newton on F from every
grid configuration next to a refused step (a fold lies between) or where the kind's relative singular
value has a local minimum along a grid line; then, where the modes come in closed form, the points of
each edge of the box where the mode count changes (loci_seeds.edge_seeds: a component that bounds a part
of the box no grid node's mode reaches, such as the corner of a 3-RPR's box where nothing assembles).
A component is missed when neither reaches it: ``complete`` stays False and ``how`` says this -- except
for a platform on three distances mapped over two legs, or one RRR dyad on the two inputs (loci_witness):
there witness points, every root of a few systems on a torus proved by the Krawczyk test, seed the tracer
last, and when each lies on a traced curve the actuator loci are complete, proved.

Cusps (where three assembly modes meet): points of a traced curve where its trace in the plane
reverses (the curve's tangent lies in the kernel of the projection onto the plane: the kernel vector
of A is tangent to the locus), located by Brent's method on the projected tangent's component along
the bracket's first one, each root a point converged on F.  Nodes: crossings of the traces of one kind,
refined by Newton on the two arclengths.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from ...errors import AssemblyError
from ...model.kernel.scaling import dimensionless, dimensionless_rows, dimensionless_twists
from ...model.manifold import continuous_angle
from ...model.state import KinematicState
from ..motion.continuation import locate, orient
from .loci_seeds import crossings, edge_seeds, refine_node, seed_configurations, sheets, unexplained_folds
from .loci_witness import unmatched, witnesses
from ..singular import LWA, Generic
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.position.position import PositionSolver
    from screwkin.model.mechanism import Coordinate
    from collections.abc import Callable
    from collections.abc import Iterator

__all__ = ["Loci", "Locus", "LocusSystem", "trace_loci"]

#: |F| below this (dimensionless: rows of r over L, A v) is a point on the locus.
RESIDUAL = 1e-11
#: Continuation steps [dimensionless arclength in (q, v)].
STEP, STEP_MIN, STEP_MAX = 0.02, 1e-7, 0.06
#: Points per curve, curves per kind: the tracing stops there (and says so).
MAX_POINTS, MAX_CURVES = 20000, 64
#: Central-difference step for d(A v)/dq.
FD = 1e-7
#: A traced cusp is the certificate's within this share of the box's span.
CUSP_MATCH = 1e-7


@dataclass(frozen=True)
class Locus:
    kind: str
    points: np.ndarray  # (n, 2) x, y [SI]
    q: np.ndarray  # (n, nq)
    closed: bool
    residual: float  # largest relative sigma_min of A at the points (|A v| / |A|)


@dataclass(frozen=True)
class Loci:
    loci: tuple
    cusps: tuple  # ((x, y), kind)
    nodes: tuple  # ((x, y), kind)
    complete: bool
    how: str
    notes: tuple = ()
    cusp_q: tuple = field(default=(), repr=False)
    traced: tuple = ()  # the kinds traced (the others: a note says why not)
    cusps_complete: bool = False  # every cusp in the box is among ``cusps``, proved (loci_witness)


class LocusSystem:
    """The augmented system F of one kind on S (see the module)."""

    def __init__(self, mech: Mechanism, inputs: list, x_name: str, y_name: str, fixed: dict, kind: str, output: str | None=None, point: bool=False, generic: Generic | None=None) -> None:
        self.mech, self.kind, self.output, self.point = mech, kind, output, point
        self.L = mech.length
        self.scale = np.where(mech.translational, self.L, 1.0)  # dq = scale * u: u dimensionless
        self.g = generic or Generic(mech, inputs, output, point)
        self.held = [(mech.coordinate(n), float(v), n) for n, v in fixed.items()]
        self.cx, self.cy = mech.coordinate(x_name), mech.coordinate(y_name)
        self.p = self.g.p
        self.pos = mech.closure.position_rows if mech.closure.nrows else None
        self.nv = mech.nv
        self.ncols = len(self.p) if kind == "actuator" else mech.nv
        names = list(mech.joint_values(mech.neutral()))  # the columns of joint_value_rows: which are angles
        self.angular = np.array([n in mech.coordinate_names and not mech.translational[mech.coordinate_names.index(n)]
                                 for n in names], bool)

    # ----------------------------------------------------------------- pieces
    def value(self, q: np.ndarray, c: Coordinate) -> float:
        """The coordinate's value [rad or m] (continuous joints: their unwrapped angle's atan2)."""
        return float(continuous_angle(q[None], c.idx_q)[0]) if c.nq == 2 else float(q[c.idx_q])

    def xy(self, q: np.ndarray) -> np.ndarray:
        return np.array([self.value(q, self.cx), self.value(q, self.cy)])

    def A(self, q: np.ndarray) -> np.ndarray:
        """The kind's matrix at q, dimensionless (the scaling of singular.scaled_jacobians, without its
        null space: K's position rows over L, sliding columns times L)."""
        mech = self.mech
        K = np.zeros((0, self.nv))
        if mech.closure.nrows:
            K = dimensionless(mech.closure.jacobian(q), self.pos, mech.translational, self.L)
        if self.kind == "actuator":
            return K[:, self.p]
        J = dimensionless_twists(KinematicState(mech, q).link_jacobian(self.output, LWA), mech.translational, self.L)
        return np.vstack([K, J[:3] if self.point else J])

    def integrate(self, q: np.ndarray, u: np.ndarray) -> np.ndarray:
        return self.mech.closure.integrator(q[None], (self.scale * u)[None])[0]

    def residual(self, q: np.ndarray, v: np.ndarray, A: np.ndarray | None=None) -> np.ndarray:
        mech = self.mech
        parts = []
        if mech.closure.nrows:
            r = dimensionless_rows(mech.closure.residual(q), self.pos, self.L)
            parts.append(r)
        held = []
        for c, target, _ in self.held:
            d = self.value(q, c) - target
            held.append(np.arctan2(np.sin(d), np.cos(d)) if not mech.translational[c.idx_v] else d / self.L)
        parts.append(np.array(held))
        A = self.A(q) if A is None else A
        parts += [A @ v, [0.5 * (v @ v - 1.0)]]
        return np.concatenate(parts)

    def jacobian(self, q: np.ndarray, v: np.ndarray, A: np.ndarray | None=None) -> np.ndarray:
        """dF/d(u, v) (rows of F, nv + columns of A); d(A v)/du by forward differences."""
        mech = self.mech
        A = self.A(q) if A is None else A
        blocks = []
        if mech.closure.nrows:
            K = dimensionless(mech.closure.jacobian(q), self.pos, mech.translational, self.L)
            blocks.append(np.hstack([K, np.zeros((len(K), len(v)))]))
        return np.vstack(blocks + self._held_kind_norm_rows(q, v, A))

    def _held_kind_norm_rows(self, q: np.ndarray, v: np.ndarray, A: np.ndarray) -> list:
        """The Jacobian's rows after the loops' (a section's too): the held inputs, d(A v)/d(u, v) (d/du by
        forward differences of step FD) and |v| = 1."""
        H = np.zeros((len(self.held), self.nv + len(v)))
        for k, (c, _, _) in enumerate(self.held):
            H[k, c.idx_v] = 1.0
        Av = A @ v
        D = np.empty((len(A), self.nv))
        for k in range(self.nv):
            e = np.zeros(self.nv)
            e[k] = FD
            D[:, k] = (self.A(self.integrate(q, e)) @ v - Av) / FD
        return [H, np.hstack([D, A]), np.concatenate([np.zeros(self.nv), v])[None]]

    def relative(self, q: np.ndarray, v: np.ndarray | None = None) -> float:
        """|A v| / |A| (v: A's smallest right singular vector when None): the point's distance from the
        kind's singular condition, relative."""
        A = self.A(q)
        s = np.linalg.svd(A, compute_uv=False)
        if v is None:
            return float(s[-1] / s[0]) if s[0] > 0 else 0.0
        return float(np.linalg.norm(A @ v) / s[0]) if s[0] > 0 else 0.0

    def kernel(self, q: np.ndarray) -> np.ndarray:
        return np.linalg.svd(self.A(q))[2][-1]

    def edge(self, axis: int, bound: float) -> Callable:
        """The extra row of ``newton`` that holds the plane's coordinate ``axis`` (0: x, 1: y) at ``bound``."""
        c = (self.cx, self.cy)[axis]

        def row(qc: np.ndarray, vc: np.ndarray) -> tuple:
            r = np.zeros(self.nv + len(vc))
            r[c.idx_v] = 1.0
            return r[None], np.array([(bound - self.value(qc, c)) / self.scale[c.idx_v]])

        return row

    # ------------------------------------------------------------ Newton, tangent
    def newton(self, q: np.ndarray, v: np.ndarray, extra: Callable | None=None, iterations: int = 30, max_step: float = 0.3, J: np.ndarray | None=None) -> tuple | None:
        """Newton (least squares, steps capped at max_step; the Jacobian kept while the residual falls
        fast: a chord step) on F, with ``extra`` rows (function (q, v) -> (rows, rhs), linear in the
        step): (q, v) converged (|F| < RESIDUAL), or None."""
        last = np.inf  # J: a Jacobian from nearby to start the chord steps with
        for k in range(iterations):
            A = self.A(q)
            F = self.residual(q, v, A)
            norm = float(np.linalg.norm(F))
            er, eb = extra(q, v) if extra is not None else (None, np.zeros(0))
            if norm < RESIDUAL and float(np.abs(eb).max(initial=0.0)) < self.mech.tolerances.zero:
                return q, v
            if k >= 6 and norm > 0.5 * last and norm > self.mech.tolerances.stalled:
                return None  # not converging
            if J is None or norm > 0.25 * last:
                J = self.jacobian(q, v, A)
            last = norm
            rows, rhs = J, -F
            if extra is not None:
                rows, rhs = np.vstack([J, er]), np.concatenate([-F, eb])
            dz = np.linalg.lstsq(rows, rhs, rcond=None)[0]
            n = float(np.linalg.norm(dz))
            if n > max_step:
                dz *= max_step / n
            q, v = self.integrate(q, dz[:self.nv]), v + dz[self.nv:]
            v = v / np.linalg.norm(v)
        F = self.residual(q, v)
        return (q, v) if float(np.linalg.norm(F)) < RESIDUAL else None

    def tangent(self, q: np.ndarray, v: np.ndarray, previous: np.ndarray | None=None, J: np.ndarray | None=None) -> np.ndarray:
        """Unit null vector of dF in (u, v) (J: dF at (q, v) when already computed), oriented along ``previous``."""
        t = np.linalg.svd(self.jacobian(q, v) if J is None else J)[2][-1]
        return orient(t, previous)  # the continuation's one branch rule

    def nullity_ok(self, q: np.ndarray, v: np.ndarray) -> bool:
        s = np.linalg.svd(self.jacobian(q, v), compute_uv=False)
        return len(s) >= self.nv + len(v) - 1 and s[self.nv + len(v) - 2] > self.mech.tolerances.crossing_rank * s[0]

    def projected(self, q: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The plane's velocity (dx, dy) [SI] along the tangent t of the curve."""
        du = self.scale * t[:self.nv]
        return np.array([du[self.cx.idx_v], du[self.cy.idx_v]])

    def along(self, q: np.ndarray, v: np.ndarray, t: np.ndarray, h: float, J: np.ndarray | None=None):
        """The point at arclength h along t from (q, v): predictor and corrector (hyperplane t . dz = h)."""
        qp, vp = self.integrate(q, h * t[:self.nv]), v + h * t[self.nv:]
        q0 = q

        def plane(qc: np.ndarray, vc: np.ndarray) -> tuple:
            d = np.concatenate([self.mech.difference(q0, qc) / self.scale, vc - v])
            return t[None], np.array([h - t @ d])

        return self.newton(qp, vp, plane, iterations=8, max_step=max(h, 1e-3), J=J)


def _in_box(p: np.ndarray, box: tuple, margin: float=0.0) -> bool:
    (x0, x1), (y0, y1) = box
    mx, my = margin * (x1 - x0), margin * (y1 - y0)
    return x0 - mx <= p[0] <= x1 + mx and y0 - my <= p[1] <= y1 + my


def _trace_one_way(sys: LocusSystem, q: np.ndarray, v: np.ndarray, box: tuple, direction: int) -> tuple:
    """Points from (q, v) along +-tangent until the box's edge, the start again, or MAX_POINTS.
    Returns (qs, vs, closed, truncated)."""
    J = sys.jacobian(q, v)
    t = direction * sys.tangent(q, v, None, J)
    qs, vs, ts = [q], [v], [t]
    h, travelled, start = STEP, 0.0, q
    while len(qs) < MAX_POINTS:
        res = sys.along(q, v, t, h, J)
        if res is None:
            h /= 2
            if h < STEP_MIN:
                return qs, vs, ts, False, True
            continue
        qn, vn = res
        Jn = sys.jacobian(qn, vn)
        tn = sys.tangent(qn, vn, t, Jn)
        if tn @ t < 0.96 and h > STEP_MIN * 4:  # turned too fast: smaller steps
            h /= 2
            continue
        travelled += h
        q, v, t, J = qn, vn, tn, Jn
        p = sys.xy(q)
        qs.append(q), vs.append(v), ts.append(t)
        if not _in_box(p, box):
            return qs, vs, ts, False, False
        if travelled > 4 * STEP and _dist(sys, q, start) < 0.75 * h:
            qs.append(start), vs.append(vs[0]), ts.append(ts[0])
            return qs, vs, ts, True, False
        h = min(h * 1.4, STEP_MAX)
    return qs, vs, ts, False, True


def _dist(sys: LocusSystem, q1: np.ndarray, q2: np.ndarray) -> float:
    return float(np.linalg.norm(sys.mech.difference(q1, q2) / sys.scale))


def _clip(sys: LocusSystem, qs: list, vs: list, box: tuple) -> tuple:
    """The points in the box; an end outside is replaced by the curve's crossing of the box's edge
    (Newton with the coordinate held at the edge)."""
    out_q, out_v = list(qs), list(vs)
    for end in (-1, 0):
        if len(out_q) < 2 or _in_box(sys.xy(out_q[end]), box):
            continue
        inner = out_q[end - 1] if end == -1 else out_q[1]
        inner_v = out_v[end - 1] if end == -1 else out_v[1]
        p_in, p_out = sys.xy(inner), sys.xy(out_q[end])
        best = None
        for axis in (0, 1):
            for bound in box[axis]:
                if (p_in[axis] - bound) * (p_out[axis] - bound) < 0:
                    frac = (bound - p_in[axis]) / (p_out[axis] - p_in[axis])
                    if best is None or frac < best[0]:
                        best = (frac, axis, bound)
        if best is None:
            out_q.pop(end), out_v.pop(end)
            continue
        _, axis, bound = best
        edge = sys.edge(axis, bound)
        res = sys.newton(inner, inner_v, edge, iterations=12, max_step=0.1)
        if res is not None and _in_box(sys.xy(res[0]), box, 1e-9):
            out_q[end], out_v[end] = res
        else:
            out_q.pop(end), out_v.pop(end)
    return out_q, out_v


def _onto_edge(sys: LocusSystem, q: np.ndarray, v: np.ndarray, box: tuple) -> tuple | None:
    """A locus point outside the box moved along the curve onto the box's edge: Newton on F with the
    coordinate outside held at the nearer bound (x, then y).  None when the curve does not reach it."""
    for axis in (0, 1):
        value = sys.xy(q)[axis]
        lo, hi = box[axis]
        if lo <= value <= hi:
            continue
        edge = sys.edge(axis, lo if value < lo else hi)
        res = sys.newton(q, v, edge, iterations=20, max_step=0.1)
        if res is not None and _in_box(sys.xy(res[0]), box, 1e-9):
            return res
    return None


def _cusps(sys: LocusSystem, qs: list, vs: list, ts: list) -> list:
    """Cusps on one traced curve: reversals of the plane's velocity between neighbouring points,
    each located by Brent's method on the arclength from the first point of the bracket."""
    out = []
    P = [sys.projected(q, t) for q, t in zip(qs, ts)]
    for k in range(len(qs) - 1):
        a, b = P[k], P[k + 1]
        na, nb = np.linalg.norm(a), np.linalg.norm(b)
        if na == 0 or nb == 0 or a @ b >= -0.5 * na * nb:
            continue  # no reversal
        q0, v0, t0 = qs[k], vs[k], ts[k]
        total = float(t0 @ np.concatenate([sys.mech.difference(q0, qs[k + 1]) / sys.scale, vs[k + 1] - v0]))
        ref = a / na
        cache = {}

        def phi(s: float, ref=ref, a=a, q0=q0, v0=v0, t0=t0, cache=cache) -> float:
            if s == 0:
                return float(ref @ a)
            res = sys.along(q0, v0, t0, s)
            if res is None:
                raise ValueError
            t = sys.tangent(*res, t0)
            cache[s] = res
            return float(ref @ sys.projected(res[0], t))

        try:
            hi = total
            if phi(hi) > 0:
                continue
            s = locate(phi, 0.0, hi, xtol=1e-13)
            qc, vc = cache.get(s) or sys.along(q0, v0, t0, s)
        except (ValueError, TypeError):
            continue
        # a cusp: the plane's velocity itself vanishes there (a sharp turn, where it only passes at right
        # angles to the bracket's first one, is none)
        if np.linalg.norm(sys.projected(qc, sys.tangent(qc, vc, t0))) > sys.mech.tolerances.cusp * max(na, nb):
            continue
        if not sys.nullity_ok(qc, vc):
            continue  # two singular curves cross there (the system drops rank): no cusp of one

        out.append((qc, vc))
    return out


def trace_loci(solver: PositionSolver, x_name: str, xs: np.ndarray, y_name: str, ys: np.ndarray, fixed: dict, output: str | None=None, point: bool=False, kinds=None, grid: int = 9,
               starts: int | None=None) -> Loci:
    """The singular loci of each kind in the box xs[0]..xs[-1] x ys[0]..ys[-1] (see the module).
    starts: configurations to seed from (default: every mode the solver finds at the box's centre)."""
    mech = solver.mech
    box = ((min(xs[0], xs[-1]), max(xs[0], xs[-1])), (min(ys[0], ys[-1]), max(ys[0], ys[-1])))
    notes = []
    g = Generic(mech, solver.inputs, output, point, configurations=solver.generic().configurations)
    if starts is None:
        starts, mode_how = _modes_in_box(solver, x_name, y_name, box, fixed)
    else:
        mode_how = f"{len(starts)} given configurations"
    grown = sheets(solver, x_name, y_name, box, starts, grid)
    wanted = kinds or ("actuator", "serial")
    loci, cusps, cusp_q, nodes, traced_kinds = [], [], [], [], []
    proof, left, cusps_complete = None, [], False
    for kind in wanted:
        why = _untraceable(mech, g, kind, output, solver.inputs)
        if why:
            if kinds or kind == "actuator" or output is not None:
                notes.append(f"{kind} loci not traced: {why}")
            continue
        traced_kinds.append(kind)
        sys = LocusSystem(mech, solver.inputs, x_name, y_name, fixed, kind, output, point, g)
        edged = edge_seeds(solver, sys, x_name, y_name, box, fixed) if kind == "actuator" else []
        if kind == "actuator":
            proof = witnesses(solver, x_name, y_name, box, fixed)
        # the grid's seeds first, then the edges' (a component none of the grid's reached), then the witnesses
        found = trace_kind(sys, kind, itertools.chain((q0 for q0, _ in seed_configurations(sys, grown)), edged,
                                                      (w.q for w in proof.points if w.q is not None)
                                                      if kind == "actuator" else ()), box, notes)
        if kind == "actuator" and proof.certified:
            left = unmatched(proof, found[0])
            if left:
                notes.append(f"actuator: {len(left)} witness point(s) of the certificate lie on no traced curve, at "
                             + ", ".join(f"({w.xy[0]:.6g}, {w.xy[1]:.6g})" for w in left[:4]))
        loci += found[0]
        cusps += found[1]
        cusp_q += found[2]
        nodes += found[3]
    complete = proof is not None and proof.certified and not left and traced_kinds == ["actuator"]
    missed = unexplained_folds(grown, loci, box, grid) if "actuator" in traced_kinds else 0
    if missed:
        steps = f"{missed} refused grid step{'s' if missed != 1 else ''} (a fold within a cell, or the corrector's jump)"
        notes.append(f"{steps} with no traced actuator curve within a cell and a half: " + (
            "not a missing component (the witnesses prove every one traced)" if complete else
            "a component of the locus may be missing"))
    unexplained = missed
    checked = ("No fold check (no actuator loci traced)" if "actuator" not in traced_kinds else
               "Not every refused grid step has an actuator curve within a cell and a half (see the notes)"
               if unexplained
               else "Checked: every refused grid step has an actuator curve within a cell and a half")
    notes = list(dict.fromkeys(notes))
    how = (f"seeds: Newton on [closure; A v = 0; |v| = 1] from the configurations of {mode_how}, each continued "
           f"over a {grid} x {grid} grid of the box, at the nodes next to a fold and where the kind's relative "
           "singular value has a local minimum along a grid line, and (where the modes come in closed form) from "
           "the points of the box's edges where the mode count changes, then (where a certificate applies: a 3-RPR, "
           "a five-bar) from its witness points; every curve then followed by pseudo-arclength "
           "continuation to the box's edges or round to its start; cusps located by Brent's method where the trace "
           f"reverses, nodes by Newton on the two arclengths. {checked}. ")
    if complete:
        how += (f"Complete: {proof.how}; each of the {len(proof.points)} witnesses lies on a traced curve (a traced point "
                "in a box about it where the locus is one arc through it, or the curve's end on that bound)")
        said, cusps_complete = cusps_checked(proof, [c for c in cusps if c[1] == "actuator"], box, notes)
        how += said
    else:
        why = "" if proof is None else f" ({proof.how}" + (
            f"; {len(left)} of them on no traced curve" if left else
            "; it covers the actuator loci only" if proof.certified and len(traced_kinds) > 1 else "") + ")"
        how += "A component none of the seeds reaches is missed, so completeness is not claimed" + why
    return Loci(tuple(loci), tuple(cusps), tuple(nodes), complete, how, tuple(notes), tuple(cusp_q),
                tuple(traced_kinds), cusps_complete)


def cusps_checked(proof, traced: list, box: tuple, notes: list, kind: str = "actuator") -> tuple:
    """The sentence on the cusps where the witnesses settle them: every cusp of the certificate among the traced
    ones and no other (within CUSP_MATCH of the box's span), else a note."""
    if proof.cusps is None:
        return f". Cusps: not certified ({proof.cusp_how})", False
    span = max(box[0][1] - box[0][0], box[1][1] - box[1][0], 1e-300)
    mine = [np.array(p) for p, _ in traced]
    missing = [c for c in proof.cusps if not any(np.abs(np.array(c) - p).max() <= CUSP_MATCH * span for p in mine)]
    extra = [p for p in mine if not any(np.abs(np.array(c) - p).max() <= CUSP_MATCH * span for c in proof.cusps)]
    if missing or extra:
        notes.append(f"{kind}: the traced cusps differ from the certificate's ({len(missing)} of its "
                     f"{len(proof.cusps)} not traced, {len(extra)} traced not among them)")
        return f". Cusps: not certified (the traced ones differ from the {proof.cusp_how})", False
    return (f". Cusps complete: {proof.cusp_how}" + ("; each is a traced cusp" if proof.cusps else "; none traced")), True


def trace_kind(sys: LocusSystem, kind: str, seeds: Iterator, box: tuple, notes: list) -> tuple:
    """The curves of one kind (sys: a LocusSystem or one like it) from the configurations ``seeds``, each
    brought onto the locus by Newton (onto the box's edge when outside) unless near a curve already traced:
    (loci, cusps ((x, y), kind), their configurations, nodes ((x, y), kind)); notes gets what it left."""
    loci, cusps, cusp_q, nodes = [], [], [], []
    traced = []
    for q0 in seeds:
        if len(traced) >= MAX_CURVES:
            notes.append(f"{kind}: stopped after {MAX_CURVES} curves")
            break
        if traced and min(_near(sys, q0, c[0]) for c in traced) < STEP_MAX * 1.5:
            continue  # a grid configuration next to a curve already traced
        res = sys.newton(q0, sys.kernel(q0))
        if res is not None and not _in_box(sys.xy(res[0]), box, 1e-9):
            res = _onto_edge(sys, *res, box)  # the curve nearest the grid point crosses the box elsewhere
        if res is None:
            continue
        q, v = res
        if traced and min(_near(sys, q, c[0]) for c in traced) < STEP_MAX * 1.5:
            continue
        if not sys.nullity_ok(q, v):
            notes.append(f"{kind}: seeds where the locus is not a curve (the augmented system drops rank: "
                         "several singularities meet, or a self-motion) were left")
            continue
        fwd = _trace_one_way(sys, q, v, box, +1)
        if fwd[3]:
            qs, vs, ts, closed = fwd[0], fwd[1], fwd[2], True
        else:
            bwd = _trace_one_way(sys, q, v, box, -1)
            qs = bwd[0][::-1] + fwd[0][1:]
            vs = bwd[1][::-1] + fwd[1][1:]
            ts = [-t for t in bwd[2][::-1]] + fwd[2][1:]
            closed = False
            if fwd[4] or bwd[4]:
                notes.append(f"{kind}: a curve was left unfinished (steps below {STEP_MIN:g} or "
                             f"{MAX_POINTS} points)")
        span = max(box[0][1] - box[0][0], box[1][1] - box[1][0], 1e-300)
        still = np.ptp(np.array([sys.xy(qk) for qk in qs[:: max(1, len(qs) // 50)]]), axis=0).max() < sys.mech.tolerances.equal * span
        cq = [] if still else _cusps(sys, qs, vs, ts)  # (a self-motion's curve stands still in the plane)
        if not closed:
            qs, vs = _clip(sys, qs, vs, box)
        traced.append((np.array(qs), np.array(vs), closed))
        for qc, _vc in cq:
            p = sys.xy(qc)
            if _in_box(p, box) and not any(np.allclose(p, c[0], atol=1e-7) for c in cusps):
                cusps.append((tuple(p), kind))
                cusp_q.append(qc)
    span = max(box[0][1] - box[0][0], box[1][1] - box[1][0], 1e-300)
    mine = []
    for Q, V, closed in traced:
        pts = np.array([sys.xy(q) for q in Q])
        worst = max(sys.relative(q, v) for q, v in zip(Q, V))
        if np.ptp(pts, axis=0).max() < sys.mech.tolerances.equal * span:  # the inputs stand still along the whole curve
            notes.append(f"{kind}: at ({pts[0][0]:.9g}, {pts[0][1]:.9g}) the mechanism moves with the inputs "
                         "held (a self-motion through the singular configurations): a point of the locus")
            pts, Q, closed = pts[:1], Q[:1], False
            if any(len(lc.points) == 1 and np.abs(lc.points[0] - pts[0]).max() < sys.mech.tolerances.equal * span
                   for lc in loci):
                continue  # another seed's configuration on the same self-motion: one point of the locus, once
        loci.append(Locus(kind, pts, Q, bool(closed), worst))
        mine.append((pts, Q, V))
    for c, k, c2, k2, f1, f2, p in crossings([m[0] for m in mine], box):
        refined = refine_node(sys, mine[c], k, f1, mine[c2], k2, f2, span)
        p = refined if refined is not None else p
        if not any(np.allclose(p, o[0], rtol=0, atol=1e-9 * span) for o in nodes):
            nodes.append((tuple(float(a) for a in p), kind))
    return loci, cusps, cusp_q, nodes


def _modes_in_box(solver: PositionSolver, x_name: str, y_name: str, box: tuple, fixed: dict) -> tuple[list, str]:
    """(configurations, in words): every mode the solver finds at the box's centre; where none assembles
    there, at the first of the other nodes of a 3 x 3 grid of the box that assembles."""
    (x0, x1), (y0, y1) = box
    points = [(0.5 * (x0 + x1), 0.5 * (y0 + y1))] + [(x, y) for y in (y0, 0.5 * (y0 + y1), y1)
                                                      for x in (x0, 0.5 * (x0 + x1), x1)
                                                      if (x, y) != (0.5 * (x0 + x1), 0.5 * (y0 + y1))]
    for k, (x, y) in enumerate(points):
        try:
            found = solver.solve({x_name: x, y_name: y, **fixed})
        except AssemblyError:
            continue
        where = "the box's centre" if k == 0 else f"({x:.6g}, {y:.6g}) (none at the box's centre)"
        how = f" ({found.modes.method}{', complete' if found.modes.complete else ', maybe not all'})" \
            if found.modes is not None else ""
        return [sol.q for sol in found.solutions], f"{len(found.solutions)} assembly modes at {where}{how}"
    return [], "no assembly mode at the centre, corners or edge midpoints of the box"


def _near(sys: LocusSystem, q: np.ndarray, Q: np.ndarray) -> float:
    """The distance (dimensionless: lengths over L) from q to the nearest of the configurations Q, by
    their joint values (angles the short way round)."""
    rows = sys.mech.joint_value_rows(np.vstack([q[None], Q]))
    D = rows[1:] - rows[0]
    D[:, sys.angular] = np.arctan2(np.sin(D[:, sys.angular]), np.cos(D[:, sys.angular]))
    D[:, ~sys.angular] /= sys.L
    return float(np.sqrt((D * D).sum(axis=1)).min())


def _untraceable(mech: Mechanism, g: Generic, kind: str, output: str, inputs: list) -> str | None:
    if kind == "actuator":
        if not mech.closure.nrows or not len(g.p):
            return "no loop, no passive joint"
        if g.rank_Kp != len(g.p):
            return "the passive joints are not determined by the inputs at generic configurations"
        return None
    if kind == "serial":
        if output is None:
            return "no --output"
        if g.out_dim + g.rank_K != mech.nv:
            return "the output's motion does not determine the joints' at generic configurations"
        return None
    return "not traced"


