"""Can two listed assembly modes be joined without a singularity?  (``solve --all --connect``, issue 44.)

For every pair of the modes found at the given inputs:

- the sign of det K_p (the actuator Jacobian, square: analysis.singular.actuator_det_rows) at each: opposite
  signs prove that every path between them meets an actuator singularity (det K_p is continuous on the
  configurations and changes sign only where it vanishes);
- same sign: a search for a path.  In the plane of two inputs (the others held at their values) the actuator
  loci are traced in a box round the given values (analysis.singularities.loci.trace_loci) and each mode is
  followed (connect.follow_inputs) round each cusp found, nearest first, both ways: on the ellipse centred on the
  cusp through the given inputs, then out to the cusp's wedge, once round it close by and back.  A loop that
  ends on another listed mode joins the two; loops chain (mode a to b, b to c joins a and c).  Nothing found
  is no proof: ``proved`` stays False.

Every path returned is checked again point by point (``check_path``): the loops closed, the held and the
plane's inputs at their values, no step longer than connect.JUMP, the actuator measure above
Tolerances.singular; its smallest value is reported.  The work is bounded (planes, cusps, steps) and says so.

``serial_connections`` (``ik --all --connect``) does the same for a chain without loops: det J's sign, and for
three joints placing a point, loops of the point round the cusps of a workspace section (section.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError
from ...model.state import KinematicState
from ..singular import LWA, Generic, actuator_det_rows, actuator_det_sign, measures, scaled_jacobians
from .loci import trace_loci
from .section import trace_section
from ..position.connect import JUMP, SAME, apart, follow_inputs, wedge_direction
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.position.position import PositionSolver

__all__ = ["Connection", "Connections", "check_path", "connect_modes", "det_signs", "serial_connections"]

#: Bounds of the search: planes of two inputs, cusps per plane (nearest first), modes compared (pairs:
#: MAX_MODES (MAX_MODES - 1) / 2), steps of a loop round a cusp close by.
MAX_PLANES, MAX_CUSPS, MAX_MODES, STEPS = 3, 4, 8, 720
#: Steps followed in all (each a damped Newton solve, about a millisecond): the search stops there and says so.
MAX_STEPS = 100_000
#: The box round the given inputs where the cusps are looked for: half-widths, lengths as a fraction of the
#: characteristic length, angles [rad]; kept within the joint limits.
BOX_LENGTH, BOX_ANGLE = 0.25, 0.5
#: The small loop round a cusp: its radius as a fraction of the box's sides (connect.cusp_loops').
LOOP = 0.02
#: Points of a path reported (thinned evenly; its first and last kept).
THIN = 100


@dataclass(frozen=True)
class Connection:
    modes: tuple  # (i, j): 0-based indices of the listed solutions
    joined: bool
    proved: bool  # the answer is certain (a checked path, or det signs); False: none found, not impossible
    why: str
    path: np.ndarray | None = None  # (n, nq) configurations from mode i to mode j, thinned
    inputs: np.ndarray | None = None  # (n, 2) the plane's two inputs along the path [SI]
    plane: tuple | None = None  # (x, y) names of the two inputs moved
    sigma_min: float | None = None  # smallest actuator measure along the whole path (re-checked)
    sigma_so_far: np.ndarray | None = None  # (n,) at each point of path: the smallest measure from the start to it
    #  (over every point followed, not only those kept)


@dataclass(frozen=True)
class Connections:
    connections: tuple
    signs: tuple  # det sign at each mode: +1, -1, 0 (too near a singularity), None (no argument)
    how: str
    notes: tuple = ()


def det_signs(mech, g: Generic, qs) -> tuple:
    """(signs (+1, -1, 0 or None for each of qs), why none): the sign of det K_p at each configuration."""
    rows, why = actuator_det_rows(mech, g)
    if rows is None:
        return tuple(None for _ in qs), why
    return tuple(actuator_det_sign(mech, q, g, rows) for q in qs), ""


def check_path(solver: PositionSolver, plane: tuple, fixed: dict, xy: np.ndarray, Q: np.ndarray) -> tuple:
    """(ok, smallest actuator measure, why): every configuration of Q closed (residual below
    Tolerances.closure, relative to L for lengths), with the plane's inputs at xy and the held ones at their
    values, every step at most JUMP, the actuator measure above Tolerances.singular all along."""
    ok, each, why = _checked_path(solver, plane, fixed, xy, Q)
    return ok, float(min(each, default=np.inf)), why


def _checked_path(solver: PositionSolver, plane: tuple, fixed: dict, xy: np.ndarray, Q: np.ndarray) -> tuple:
    """check_path's work: (ok, the actuator measure at each point checked, why)."""
    mech = solver.mech
    tol = mech.tolerances
    g = Generic(mech, solver.inputs, configurations=solver.generic().configurations)
    each = []
    for k, q in enumerate(Q):
        if mech.closure.nrows and float(np.linalg.norm(mech.closure.residual(q))) > 10 * tol.closure * max(1.0, mech.length):
            return False, each, f"the loops do not close at point {k}"
        values = mech.joint_values(q)
        want = {plane[0]: xy[k, 0], plane[1]: xy[k, 1], **fixed}
        for n, v in want.items():
            d = values[n] - v
            if not mech.translational[mech.coordinate(n).idx_v]:
                d = np.arctan2(np.sin(d), np.cos(d))
            if abs(d) > tol.equal * (mech.length if mech.translational[mech.coordinate(n).idx_v] else 1.0):
                return False, each, f"input {n} off its value at point {k}"
        if k and apart(mech, Q[k - 1], q) > JUMP:
            return False, each, f"step {k} jumps (another branch)"
        each.append(float(measures(mech, q, g)["actuator"]))
        if each[-1] < tol.singular:
            return False, each, f"the actuator measure falls below {tol.singular:g} at point {k}"
    return True, each, ""


def _search_box(mech, name: str, value: float) -> tuple:
    c = mech.coordinate(name)
    w = BOX_LENGTH * mech.length if mech.translational[c.idx_v] else BOX_ANGLE
    lo, hi = value - w, value + w
    j = mech.model.lowerPositionLimit[c.idx_q], mech.model.upperPositionLimit[c.idx_q]
    if c.nq == 1 and np.isfinite(j[0]) and np.isfinite(j[1]) and j[0] < j[1]:
        lo, hi = max(lo, float(j[0])), min(hi, float(j[1]))
    return lo, hi


def _match(mech, q: np.ndarray, qs) -> int | None:
    gaps = [apart(mech, q, qk) for qk in qs]
    k = int(np.argmin(gaps))
    return k if gaps[k] < SAME else None


def _planes(inputs: list) -> list:
    """The planes of two inputs tried, the first input held first (as Zein, Wenger & Chablat hold rho1 of a
    3-RPR), at most MAX_PLANES."""
    pairs = list(combinations(inputs, 2))
    return (pairs[::-1])[:MAX_PLANES]


def _loops_round(solver, plane, fixed, u0, cusp, span, wedge, q, steps, budget: list) -> list:
    """The closed input paths from u0 round the cusp, each way, and where mode q ends: [(xy, Q)] of the
    regular ones that end on another configuration.  budget: [steps left, whether it ran out], spent here."""
    out = []

    def spend(xy, q0):
        budget[0] -= len(xy)
        return follow_inputs(solver, *plane, fixed, xy, q0)

    c = np.asarray(cusp, float)
    d = (u0 - c) / span
    rho = float(np.hypot(*d))
    th0 = float(np.arctan2(d[1], d[0]))
    # 1. the ellipse centred on the cusp through u0
    n = int(np.clip(steps * rho / LOOP, steps, 4 * steps))
    for turn in (1, -1):
        if budget[0] < n:
            budget[1] = True
            return out
        a = th0 + turn * np.linspace(0.0, 2 * np.pi, n + 1)
        xy = np.column_stack([c[0] + rho * span[0] * np.cos(a), c[1] + rho * span[1] * np.sin(a)])
        xy[0] = xy[-1] = u0
        lp = spend(xy, q)
        if lp.regular and lp.joined:
            out.append((xy, lp.q))
    if out:
        return out
    # 2. out to the wedge, once round the cusp close by, back
    s = c + LOOP * span * np.array([np.cos(wedge), np.sin(wedge)])
    k = max(10, int(np.ceil(np.hypot(*((s - u0) / span)) / (2 * np.pi * LOOP / steps))))
    seg = u0 + np.linspace(0.0, 1.0, min(k, 4 * steps) + 1)[:, None] * (s - u0)
    if budget[0] < 2 * len(seg) + 2 * steps:
        budget[1] = True
        return out
    there = spend(seg, q)
    if not there.regular:
        return out
    for turn in (1, -1):
        a = wedge + turn * np.linspace(0.0, 2 * np.pi, steps + 1)
        ring = np.column_stack([c[0] + LOOP * span[0] * np.cos(a), c[1] + LOOP * span[1] * np.sin(a)])
        ring[0] = ring[-1] = s
        lp = spend(ring, there.q[-1])
        if not (lp.regular and lp.joined):
            continue
        back = spend(seg[::-1], lp.q[-1])
        if back.regular:
            out.append((np.vstack([seg, ring[1:], seg[::-1][1:]]), np.vstack([there.q, lp.q[1:], back.q[1:]])))
    return out


def connect_modes(solver: PositionSolver, values: dict, qs, steps: int = STEPS, pairs=None) -> Connections:
    """Which of the configurations qs (the modes listed at the inputs ``values``) can be joined without a
    singularity, and how (see the module).  ``pairs``: the (i, j) (0-based) answered, a path from mode i to
    mode j (default: every pair, i < j); every mode listed may be a step of a chain of loops between them."""
    mech = solver.mech
    g = Generic(mech, solver.inputs, configurations=solver.generic().configurations)
    notes = []
    qs = [np.asarray(q, float) for q in qs]
    if pairs is None and len(qs) > MAX_MODES:
        notes.append(f"only the first {MAX_MODES} of the {len(qs)} modes compared")
        qs = qs[:MAX_MODES]
    signs, why_none = det_signs(mech, g, qs)
    pending, result = [], {}
    for i, j in (combinations(range(len(qs)), 2) if pairs is None else pairs):
        si, sj = signs[i], signs[j]
        if si is None:
            result[i, j] = Connection((i, j), False, False, f"unknown: {why_none}")
        elif si == 0 or sj == 0:
            result[i, j] = Connection((i, j), False, False, f"unknown: mode {(i if si == 0 else j) + 1} is at an "
                                      "actuator singularity (its det K_p has no sign)")
        elif si != sj:
            result[i, j] = Connection((i, j), False, True, "det J of opposite signs (det K_p "
                                      f"{'+' if si > 0 else '-'} at mode {i + 1}, {'+' if sj > 0 else '-'} at mode "
                                      f"{j + 1}): every path between them meets an actuator singularity")
        else:
            pending.append((i, j))
    edges = {}  # (a, b) -> (plane, xy, Q): a loop from mode a to mode b
    tried_planes, searched = [], []
    if pending and len(solver.inputs) < 2:
        notes.append("one input: no plane of two inputs to loop in")
    u = {n: float(v) for n, v in values.items()}
    budget = [MAX_STEPS, False]
    for plane in (_planes(list(solver.inputs)) if pending and len(solver.inputs) >= 2 else []):
        if all(_chained(edges, i, j) for i, j in pending):
            break
        fixed = {n: v for n, v in u.items() if n not in plane}
        u0 = np.array([u[plane[0]], u[plane[1]]])
        (x0, x1), (y0, y1) = _search_box(mech, plane[0], u0[0]), _search_box(mech, plane[1], u0[1])
        span = np.array([x1 - x0, y1 - y0])
        if (span <= 0).any():
            continue
        tried_planes.append(f"({plane[0]}, {plane[1]}) in [{x0:.6g}, {x1:.6g}] x [{y0:.6g}, {y1:.6g}]")
        try:
            traced = trace_loci(solver, plane[0], np.linspace(x0, x1, 21), plane[1], np.linspace(y0, y1, 21),
                                fixed, kinds=("actuator",))
        except AssemblyError:
            continue
        cusps = [np.array(p) for p, kind in traced.cusps if kind == "actuator"]
        cusps.sort(key=lambda p: float(np.hypot(*((p - u0) / span))))
        if len(cusps) > MAX_CUSPS:
            notes.append(f"plane ({plane[0]}, {plane[1]}): the {MAX_CUSPS} cusps nearest the given inputs of "
                         f"{len(cusps)} tried")
        pts = [lc.points for lc in traced.loci if lc.kind == "actuator"]
        P = np.concatenate(pts) / span if pts else np.zeros((0, 2))
        for c in cusps[:MAX_CUSPS]:
            searched.append(f"({plane[0]}, {plane[1]}) = ({c[0]:.6g}, {c[1]:.6g})")
            wedge = wedge_direction(P, c / span, LOOP) if len(P) else 0.0
            for a in sorted({m for pair in pending for m in pair}):
                if all(_chained(edges, i, j) for i, j in pending):
                    break
                for xy, Q in _loops_round(solver, plane, fixed, u0, c, span, wedge, qs[a], steps, budget):
                    b = _match(mech, Q[-1], qs)
                    if b is not None and b != a and (a, b) not in edges:
                        edges[a, b] = (plane, xy, Q)
    if budget[1]:
        notes.append(f"the search stopped at its bound of {MAX_STEPS:,} steps followed")
    for i, j in pending:
        route = _loop_route(edges, i, j)
        if route is None:
            where = "; ".join(tried_planes) or "no plane"
            result[i, j] = Connection((i, j), False, False, (
                f"same sign of det J, but no loop round a cusp joins them (cusps tried: {len(searched)}; planes "
                f"{where}): not proved impossible"))
            continue
        pieces = [edges[a, b] if (a, b) in edges else _reversed(edges[b, a]) for a, b in route]
        plane = pieces[0][0]  # (the first loop may have been found the other way: edges[b, a])
        planes = [pl for pl, _, _ in pieces]
        Q = np.vstack([pieces[0][2]] + [p[2][1:] for p in pieces[1:]])
        xy_all = np.vstack([pieces[0][1]] + [p[1][1:] for p in pieces[1:]])
        ok, each, why = True, [], ""
        for k, (pl, xy, Qp) in enumerate(pieces):
            fixed = {n: v for n, v in u.items() if n not in pl}
            ok, e, why = _checked_path(solver, pl, fixed, xy, Qp)
            each += e if k == 0 else e[1:]  # (a piece starts where the last one ended)
            if not ok:
                break
        if not ok:
            result[i, j] = Connection((i, j), False, False, f"a loop was found but its check failed: {why}")
            continue
        so_far = np.minimum.accumulate(np.asarray(each))
        smallest = float(so_far[-1])
        keep = np.unique(np.linspace(0, len(Q) - 1, min(THIN, len(Q))).round().astype(int))
        via = " then ".join(f"({p[0]}, {p[1]})" for p in planes)
        result[i, j] = Connection((i, j), True, True, (
            f"joined without a singularity: {len(route)} loop{'s' if len(route) > 1 else ''} of the inputs {via} "
            f"round a cusp of the actuator singular curve (path of {len(Q)} points checked; smallest actuator "
            f"measure {smallest:.3g})"), Q[keep], xy_all[keep] if len(planes) == 1 else None, plane, smallest, so_far[keep])
    how = (f"det K_p's sign at each mode; pairs of the same sign: loops of two inputs round the cusps of the "
           f"actuator singular curve traced in a box round the given inputs (half-widths {BOX_LENGTH:g} L for "
           f"lengths, {BOX_ANGLE:g} rad for angles, within the joint limits), at most {MAX_PLANES} planes, the "
           f"{MAX_CUSPS} nearest cusps each, loops of at least {steps} steps, {MAX_STEPS:,} steps in all, each path "
           "checked again point by point")
    if tried_planes:
        notes.insert(0, "planes of two inputs (the others held at their values): " + "; ".join(tried_planes))
    return Connections(tuple(result[k] for k in sorted(result)), tuple(signs), how, tuple(notes))


def _reversed(edge: tuple) -> tuple:
    plane, xy, Q = edge
    return plane, xy[::-1], Q[::-1]


def _loop_route(edges: dict, i: int, j: int) -> list | None:
    """The shortest chain of loops (either way) from mode i to mode j: [(a, b), ...], or None."""
    nbr = {}
    for a, b in edges:
        nbr.setdefault(a, set()).add(b)
        nbr.setdefault(b, set()).add(a)
    prev, frontier = {i: None}, [i]
    while frontier:
        nxt = []
        for a in frontier:
            for b in sorted(nbr.get(a, ())):
                if b not in prev:
                    prev[b] = a
                    nxt.append(b)
        frontier = nxt
    if j not in prev:
        return None
    route, b = [], j
    while prev[b] is not None:
        route.append((prev[b], b))
        b = prev[b]
    return route[::-1]


def _chained(edges: dict, i: int, j: int) -> bool:
    return _loop_route(edges, i, j) is not None


def serial_connections(mech, output: str, qs, point: bool, target=None) -> Connections:
    """``ik --all --connect``: for a chain without loops whose output's motion (its origin's with ``point``)
    has as many rows as the joints, the sign of det J (dimensionless, analysis.singular's scaling) at each
    solution: opposite signs prove every joint-space path between them meets a serial singularity.  Same
    signs, for three joints placing a point (``target``, [m]): a search as ``connect_modes``'s, in the section
    of the workspace through the target (x, z; y held, analysis.singularities.section): each solution
    followed with the point moved on an ellipse centred on a cusp of the section's serial singular curve
    through the target, both ways; a loop ending on another listed solution joins them, checked again point
    by point.  Otherwise same signs are said not searched."""
    tol = mech.tolerances
    qs = [np.asarray(q, float) for q in qs][:MAX_MODES]
    signs, why_none = [], ""
    if mech.closure.nrows:
        why_none = "a mechanism with loops: ik --connect compares the solutions of a chain without loops only"
    for q in qs:
        if why_none:
            signs.append(None)
            continue
        J = scaled_jacobians(mech, q, output, point).J
        if J.shape[0] != J.shape[1]:
            why_none = (f"the output's Jacobian is {J.shape[0]} x {J.shape[1]} (rows x joints): not square, its "
                        "determinant's sign is no argument")
            signs.append(None)
            continue
        s = np.linalg.svd(J, compute_uv=False)
        signs.append(0 if s[-1] < tol.singular * s[0] else int(np.sign(np.linalg.det(J))))
    if why_none:
        signs = [None] * len(qs)
    pending = [(i, j) for i, j in combinations(range(len(qs)), 2) if signs[i] is not None and signs[i] != 0
               and signs[i] == signs[j]]
    searchable = point and target is not None and mech.nv == 3 and not mech.closure.nrows
    edges, notes, searched = {}, [], 0
    if pending and searchable:
        edges, notes, searched = _section_search(mech, output, qs, np.asarray(target, float), pending)
    out = []
    for i, j in combinations(range(len(qs)), 2):
        si, sj = signs[i], signs[j]
        if si is None:
            out.append(Connection((i, j), False, False, f"unknown: {why_none}"))
        elif si == 0 or sj == 0:
            out.append(Connection((i, j), False, False, f"unknown: solution {(i if si == 0 else j) + 1} is at a "
                                  "serial singularity (its det J has no sign)"))
        elif si != sj:
            out.append(Connection((i, j), False, True, f"det J of opposite signs ({'+' if si > 0 else '-'} at "
                                  f"solution {i + 1}, {'+' if sj > 0 else '-'} at solution {j + 1}): every joint "
                                  "path between them meets a serial singularity"))
        elif not searchable:
            out.append(Connection((i, j), False, False, (
                "unknown: same sign of det J; ik --connect searches a path only for three joints placing a point "
                "(--position): not proved impossible")))
        else:
            out.append(_serial_pair(mech, output, edges, i, j, target, searched))
    how = ("the sign of det J (the output's Jacobian over the joints, dimensionless) at each solution"
           + (f"; pairs of the same sign: the point moved round the cusps of the serial singular curve of the "
              f"workspace section y = {float(target[1]):.6g} m through the target (x, z within {SECTION_BOX:g} L of "
              f"it, the {MAX_CUSPS} nearest cusps), each path checked again point by point" if searchable else
              "; paths between solutions of the same sign are searched only for three joints placing a point"))
    return Connections(tuple(out), tuple(signs), how, tuple(notes))


#: The workspace section searched by ik --connect: half-widths round the target, a fraction of L.
SECTION_BOX = 1.0


def _section_search(mech, output: str, qs, target: np.ndarray, pending: list) -> tuple:
    """(edges (a, b) -> (("x", "z"), xy, Q), notes, cusps tried): the solutions followed round the cusps of the
    section y = target's y."""
    L = mech.length
    u0 = np.array([target[0], target[2]])
    w = SECTION_BOX * L
    xs, zs = np.linspace(u0[0] - w, u0[0] + w, 41), np.linspace(u0[1] - w, u0[1] + w, 41)
    sec = trace_section(mech, output, "x", xs, "z", zs, float(target[1]), samples=200, certify=False)  # (its cusps only)
    span = np.array([2 * w, 2 * w])
    cusps = sorted((np.array(p) for p, _ in sec.loci.cusps), key=lambda p: float(np.hypot(*((p - u0) / span))))
    notes = [f"the section y = {target[1]:.6g} m: {len(cusps)} cusps of its serial singular curve within "
             f"{w:.6g} m of the target ({sec.loci.how.split('. ')[0]})"]
    fid = mech.link_frame(output)
    edges, budget = {}, [MAX_STEPS]
    for c in cusps[:MAX_CUSPS]:
        d = (u0 - c) / span
        rho, th0 = float(np.hypot(*d)), float(np.arctan2(d[1], d[0]))
        n = int(np.clip(STEPS * rho / LOOP, STEPS, 4 * STEPS))
        for a in sorted({m for pair in pending for m in pair}):
            if all(_chained(edges, i, j) for i, j in pending) or budget[0] < n:
                break
            for turn in (1, -1):
                ang = th0 + turn * np.linspace(0.0, 2 * np.pi, n + 1)
                xy = np.column_stack([c[0] + rho * span[0] * np.cos(ang), c[1] + rho * span[1] * np.sin(ang)])
                xy[0] = xy[-1] = u0
                budget[0] -= len(xy)
                Q = _follow_point(mech, fid, float(target[1]), xy, qs[a])
                if Q is None:
                    continue
                b = _match(mech, Q[-1], qs)
                if b is not None and b != a and (a, b) not in edges:
                    edges[a, b] = (("x", "z"), xy, Q)
    if budget[0] <= 0:
        notes.append(f"the search stopped at its bound of {MAX_STEPS:,} steps followed")
    return edges, notes, min(len(cusps), MAX_CUSPS)


def _point_at(mech, fid: int, q: np.ndarray, level: float, x: float, z: float) -> np.ndarray | None:
    """q moved by Newton on the three joints until the point is at (x, level, z), or None."""
    goal = np.array([x, level, z])
    for _ in range(30):
        st = KinematicState(mech, q)
        e = goal - st.frame_placement(fid).translation
        if float(np.linalg.norm(e)) < mech.tolerances.closure * max(1.0, mech.length):
            return q
        J = st.frame_jacobian(fid, LWA)[:3]
        q = pin.integrate(mech.model, q, np.linalg.lstsq(J, e, rcond=None)[0])
    return None


def _follow_point(mech, fid: int, level: float, xy: np.ndarray, q0: np.ndarray) -> np.ndarray | None:
    """The configurations along the point's path xy (x, z) from q0, each by Newton from the last: None where a
    step fails, jumps (connect.JUMP) or meets a serial singularity (measure below Tolerances.singular)."""
    Q = [np.asarray(q0, float)]
    for x, z in xy[1:]:
        q = _point_at(mech, fid, Q[-1], level, x, z)
        if q is None or apart(mech, Q[-1], q) > JUMP:
            return None
        Q.append(q)
    Q = np.array(Q)
    return Q if _serial_smallest(mech, fid, Q) > mech.tolerances.singular else None


def _serial_smallest(mech, fid: int, Q: np.ndarray) -> float:
    """The smallest relative singular value of the point's Jacobian (dimensionless) along Q."""
    worst = np.inf
    for q in Q:
        J = KinematicState(mech, q).frame_jacobian(fid, LWA)[:3] * np.where(mech.translational, mech.length, 1.0)
        s = np.linalg.svd(J / mech.length, compute_uv=False)
        worst = min(worst, float(s[-1] / s[0]))
    return worst


def check_point_path(mech, fid: int, level: float, xy: np.ndarray, Q: np.ndarray) -> tuple:
    """(ok, smallest serial measure, why): the point of every configuration of Q at (x, level, z) of xy (to
    Tolerances.equal relative to L), every step at most JUMP, the point's Jacobian's relative smallest singular
    value above Tolerances.singular all along."""
    tol = mech.tolerances
    for k, q in enumerate(Q):
        p = KinematicState(mech, q).frame_placement(fid).translation
        if float(np.linalg.norm(p - [xy[k, 0], level, xy[k, 1]])) > tol.equal * mech.length:
            return False, np.nan, f"the point is off its path at point {k}"
        if k and apart(mech, Q[k - 1], q) > JUMP:
            return False, np.nan, f"step {k} jumps (another branch)"
    smallest = _serial_smallest(mech, fid, Q)
    if smallest < tol.singular:
        return False, smallest, f"the serial measure falls below {tol.singular:g}"
    return True, smallest, ""


def _serial_pair(mech, output: str, edges: dict, i: int, j: int, target, searched: int) -> Connection:
    route = _loop_route(edges, i, j)
    if route is None:
        return Connection((i, j), False, False, (
            f"same sign of det J, but no loop of the point round a cusp of the workspace section joins them (cusps "
            f"tried: {searched}): not proved impossible"))
    pieces = [edges[a, b] if (a, b) in edges else _reversed(edges[b, a]) for a, b in route]
    fid = mech.link_frame(output)
    smallest = np.inf
    for _, xy, Q in pieces:
        ok, s, why = check_point_path(mech, fid, float(target[1]), xy, Q)
        if not ok:
            return Connection((i, j), False, False, f"a loop was found but its check failed: {why}")
        smallest = min(smallest, s)
    Q = np.vstack([pieces[0][2]] + [p[2][1:] for p in pieces[1:]])
    xy = np.vstack([pieces[0][1]] + [p[1][1:] for p in pieces[1:]])
    keep = np.unique(np.linspace(0, len(Q) - 1, min(THIN, len(Q))).round().astype(int))
    return Connection((i, j), True, True, (
        f"joined without a singularity: the tool point moved {len(route)} time{'s' if len(route) > 1 else ''} "
        f"round a cusp of the workspace section y = {float(target[1]):.6g} m and back to the target (path of "
        f"{len(Q)} points checked; smallest serial measure {smallest:.3g})"), Q[keep], xy[keep], ("x", "z"),
        float(smallest))
