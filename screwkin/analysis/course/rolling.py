"""Rolling and gear pairs in the vector-loop equations (screwkin.analysis.course.vector_loops):
the no-slip law written in the loop's symbols and substituted into the loop, so that the
unknowns stay the mechanism's own angles and slider coordinates.

A pair joins link a (its circle 1, or its line: a rack, a track) and link b (circle 2), of
pitch radii rho_a, rho_b (docs/format.md section 2b).  With theta_a, theta_b the links'
absolute angles (the ground's: 0) and theta_ab the angle of the line of centres (from
circle a's centre to circle b's):

- external rolling (gears in mesh): rho_a (theta_a - theta_ab) + rho_b (theta_b - theta_ab) = c_ab;
  the loop crosses the pair by (rho_a + rho_b) (cos theta_ab, sin theta_ab) with
  theta_ab = (rho_a theta_a + rho_b theta_b - c_ab) / (rho_a + rho_b);
- internal rolling (circle b inside circle a): rho_a (theta_a - theta_ab) - rho_b (theta_b -
  theta_ab) = c_ab, the vector (rho_a - rho_b) at theta_ab = (rho_a theta_a - rho_b theta_b -
  c_ab) / (rho_a - rho_b);
- a circle on a line (rack and pinion): with u the line's unit vector (angle theta_u, fixed in
  link a), n = u turned +90 deg and x_ab the contact point along the line from a point fixed
  on it, x_ab = rho_b (theta_b - theta_u) + c_ab; the loop crosses the pair by
  x_ab u - rho_b n.

c_ab (an arc length [m]) is measured at the configuration the equations are built at, and is
0 where the marks on both pitch circles touch there.  These are the coupling rows
r1 a1 +- r2 a2 = 0 (x + r2 a2 = 0) of model.cuts.CouplingRow written in the links' angles.

When the rest of a pair's loop fixes the line of centres -- it is constant (two gears pinned to
one frame), or one link's vector (a planet pinned to an arm: theta_ab is the arm's angle) --
the loop holds the centre distance as the pair does: its vector equation holds for every
motion, and the no-slip law with that theta_ab is the loop's equation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.cuts import in_plane, pair_contact
from ...model.geometry import nearest_turn
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.state import KinematicState

__all__ = ["HIGHER", "RollingPair", "measure_pairs", "pair_term", "substitute_pairs", "turns_through_pairs",
           "unwrapped", "drop_constant_rows", "virtual_coordinates"]

#: The higher pairs the vector-loop equations take.
HIGHER = ("rolling", "gear")


@dataclass(frozen=True)
class RollingPair:
    """One rolling or gear pair of the equations: ``kind`` "external", "internal" or "rack";
    ``law`` the no-slip relation (sympy syntax, "lhs = rhs"); ``substitution`` the expression
    put in the loop for theta_ab (x_ab for a rack), or None where theta_ab is a constant
    (then ``law`` is an equation of the system)."""

    name: str
    kind: str
    links: tuple  # (link a, link b)
    law: str
    substitution: str | None
    in_system: bool  # the law is one of the equations F (theta_ab constant)


def measure_pairs(loops, state: KinematicState) -> dict:
    """Per rolling/gear loop joint of ``loops`` (a VectorLoops being built; ``state``: its
    model.state.KinematicState at loops.q): the anchors of its two centres on its two links
    (loops.keep) and a dict of what the loop terms need."""
    mech = loops.mech
    model = mech.model
    specs = {c.name: c for c in mech.spec.cut_joints}
    out = {}
    for j in loops.topo.joints:
        if j.type not in HIGHER:
            continue
        c = specs[j.name]
        la, lb = j.links
        f1 = model.getFrameId(f"{j.name}@F1")
        f2 = model.getFrameId(f"{j.name}@F2")
        M1, M2 = state.frame_placement(f1), state.frame_placement(f2)
        loops.keep((j.name, la), la, M1.translation)
        loops.keep((j.name, lb), lb, M2.translation)
        p1 = loops._p2(M1.translation)
        d = loops._p2(pair_contact(c, M1, M2)[0]) - p1  # the contact point (model.cuts) from F1's origin
        rack = bool(np.isinf(c.radius1))
        rec = {"name": j.name, "a": la, "b": lb, "r1": None if rack else float(c.radius1), "r2": float(c.radius2),
               "kind": "rack" if rack else ("internal" if c.contact == "internal" else "external")}
        if rack:
            u = loops._p2(M1.rotation @ in_plane(c.axis)[1])
            u = u / np.linalg.norm(u)
            rec["u_angle"] = float(np.arctan2(u[1], u[0]))  # absolute angle of the line at q
            rec["x"] = float(d @ u)  # contact point along the line from F1's origin
        else:
            rec["k_angle"] = float(np.arctan2(d[1], d[0]))  # line of centres at q (towards the contact)
        out[j.name] = rec
    return out


def _times(radius, angle, line) -> str:
    """rho*(theta - theta_ab) as a textbook writes it (the ground's angle 0: -rho*theta_ab)."""
    return f"-{radius}*{line}" if angle == 0 else f"{radius}*({angle} - {line})"


def pair_term(loops, rec, placeholder=None) -> tuple:
    """(fx, fy, term names) of crossing the pair from link a to link b, and the RollingPair
    record; ``placeholder``: a sympy symbol to stand for theta_ab (replaced later).  Sets
    rec["contact"]: the contact point from link a's anchor (circle a's centre: rho_a along the
    line of centres; a rack's point: x_ab along the line), where the pair's relative motion is
    a rotation (no slip: the contact point is the instantaneous centre); a rack's also
    rec["facing"]: the contact point from the pinion's centre (rho_b n)."""
    sp = loops.sp
    a, b = rec["a"], rec["b"]
    na, nb = loops.numbers[a], loops.numbers[b]
    tol = loops.mech.tolerances

    def theta(link: str):
        return sp.Integer(0) if loops.rep[link] == loops.topo.ground else loops._theta(link)

    def theta_q(link: str) -> float:
        return 0.0 if loops.rep[link] == loops.topo.ground else float(loops.theta_q[loops.rep[link]])

    def radius(link: str, value):
        k = loops.numbers[link]
        return loops._new_symbol(f"rho{k}{loops._suffix(k, loops.used_rho)}", link, "length", value, "constant",
                                 f"pitch radius on link '{link}' of the pair '{rec['name']}'")

    def offset(value):
        if abs(value) <= tol.geometry * max(loops.mech.length, 1.0):
            return sp.Integer(0)
        return loops._new_symbol(f"c{na}{nb}", a, "length", value, "constant",
                                 f"arc-length offset of the no-slip law of '{rec['name']}' (the marks that "
                                 "touch at the configuration measured)")

    ta, tb = theta(a), theta(b)
    rb = radius(b, rec["r2"])
    if rec["kind"] == "rack":
        beta = loops.wrap(rec["u_angle"] - theta_q(a))
        exact = loops.exact_angle(beta)
        if exact is None:
            exact = loops._new_symbol(f"beta{na}{nb}", a, "angle", beta, "constant",
                                      f"angle of the pitch line of '{rec['name']}' from theta{na}")
        tu = ta + exact
        tu_q = theta_q(a) + beta
        c = offset(rec["x"] - rec["r2"] * (theta_q(b) - tu_q))
        x = rb * (tb - tu) + c
        rec.update({"x_expr": x, "tu": tu, "ta": ta, "tb": tb, "contact": (x * sp.cos(tu), x * sp.sin(tu)),
                    "facing": (-rb * sp.sin(tu), rb * sp.cos(tu))})
        name = f"x{na}{nb}"
        law = f"{name} = {x}"
        fx = x * sp.cos(tu) + rb * sp.sin(tu)
        fy = x * sp.sin(tu) - rb * sp.cos(tu)
        return fx, fy, [f"{name}*u{na}{nb}", f"-rho{nb}*n{na}{nb}"], RollingPair(
            rec["name"], "rack", (a, b), law, f"{name} = {x}", False)
    ra = radius(a, rec["r1"])
    s = 1 if rec["kind"] == "external" else -1
    tk_q = rec["k_angle"]
    c = offset(rec["r1"] * (theta_q(a) - tk_q) + s * rec["r2"] * (theta_q(b) - tk_q))
    R = ra + s * rb
    name = f"theta{na}{nb}"
    tk = sp.Symbol(name, real=True)
    law = f"{_times(ra, ta, tk)} {'+' if s > 0 else '-'} {_times(rb, tb, tk)} = {c}"
    expr = (ra * ta + s * rb * tb - c) / R
    t = placeholder if placeholder is not None else expr
    rec.update({"expr": expr, "law_expr": ra * (ta - tk) + s * rb * (tb - tk) - c, "tk": tk, "tk_q": tk_q,
                "ta": ta, "tb": tb, "contact": (ra * sp.cos(t), ra * sp.sin(t))})
    return R * sp.cos(t), R * sp.sin(t), [f"({R})*e{na}{nb}"], RollingPair(
        rec["name"], rec["kind"], (a, b), law, f"{name} = {expr}", False)


def virtual_coordinates(loops, q: np.ndarray, values: dict, before) -> np.ndarray:
    """Set in q (in place) the coordinates of each pair's virtual joints (model.loader's
    equivalent linkage: a1 and -a2, or x and -a2) for the link angles ``values`` (symbol ->
    value; the others as ``before``, their values at loops.q), moved from their values at
    loops.q by what the no-slip law turns and rolls."""
    mech = loops.mech
    known = {**loops.constants, **{loops.sym[n]: v for n, v in {**before, **values}.items() if n in loops.sym}}
    known0 = {**loops.constants, **{loops.sym[n]: v for n, v in before.items() if n in loops.sym}}

    def delta(e):
        return float(loops.sp.sympify(e).subs(known)) - float(loops.sp.sympify(e).subs(known0))

    for name, rec in loops.pair_geometry.items():
        if "ta" not in rec:
            continue  # in no loop
        j1, j2 = (mech.coordinate(n) for n in mech.virtual_joints[name])
        s = _axis_sign(loops, name)
        d_a, d_b = delta(rec["ta"]), delta(rec["tb"])
        if rec["kind"] == "rack":
            d_u = delta(rec["tu"])
            q[j1.idx_q] = loops.q[j1.idx_q] + delta(rec["x_expr"])
            q[j2.idx_q] = loops.q[j2.idx_q] - s * (d_u - d_b)
        else:
            d_k = delta(rec["fixed"] if rec.get("fixed") is not None else rec["expr"])
            q[j1.idx_q] = loops.q[j1.idx_q] + s * (d_k - d_a)
            q[j2.idx_q] = loops.q[j2.idx_q] - s * (d_k - d_b)
    return q


def _axis_sign(loops, name: str) -> float:
    """+1 when the pair's axis (in F1) points along the plane's normal at loops.q, else -1."""
    mech = loops.mech
    f1 = mech.model.getFrameId(f"{name}@F1")
    axis = next(c.axis for c in mech.spec.cut_joints if c.name == name)
    return float(np.sign((loops.state.frame_placement(f1).rotation @ np.asarray(axis, float)) @ loops.n))


def turns_through_pairs(loops, q: np.ndarray, values) -> dict:
    """``values`` (symbol -> value at q, each link's angle counted in turns along the tree) with
    the angle of a link turned through a rolling pair counted instead by the pair's virtual
    joints, which count turns as the no-slip law does (the tree may hold a gear's joint a whole
    turn from there, the same pose): the whole turns nearest the angle of the pair's other link
    plus what the pair turned.  Inputs keep their values."""
    mech = loops.mech
    out = dict(values)
    inputs = set(getattr(loops, "input_joints", {}) or {})

    def name_of(link: str) -> str | None:
        r = loops.rep[link]
        return None if r == loops.topo.ground else f"theta{loops.numbers[r]}"

    for _ in range(2):  # a train of pairs: each one's driven link from its driver, twice over
        for pname, rec in loops.pair_geometry.items():
            na, nb = name_of(rec["a"]), name_of(rec["b"])
            j1, j2 = (mech.coordinate(n) for n in mech.virtual_joints[pname])
            s = _axis_sign(loops, pname)
            dv1, dv2 = q[j1.idx_q] - loops.q[j1.idx_q], q[j2.idx_q] - loops.q[j2.idx_q]
            da = (out[na] - loops.theta_q[loops.rep[rec["a"]]]) if na in out else 0.0
            turned = s * dv2 if rec["kind"] == "rack" else s * (dv1 + dv2)  # theta_b - theta_a (- theta_u)
            if nb in out and nb not in inputs:
                want = loops.theta_q[loops.rep[rec["b"]]] + da + turned
                out[nb] = nearest_turn(out[nb], want)
            elif na in out and na not in inputs and nb in out:
                db = out[nb] - loops.theta_q[loops.rep[rec["b"]]]
                want = loops.theta_q[loops.rep[rec["a"]]] + db - turned
                out[na] = nearest_turn(out[na], want)
    return out


def _line_of_centres(loops, rows: list, hold, rec):
    """The angle of the pair's line of centres as the rest of its loop fixes it, or None: where
    the rest is constant (two gears pinned to one link) or one link's vector (a planet's arm),
    the loop fixes the centre distance as the pair does and theta_ab follows the rest alone."""
    sp = loops.sp
    variables = {loops.sym[n] for n in loops.variables}
    values = {**loops.constants_now(), **{loops.sym[n]: loops.symbol_info[n].value for n in loops.variables}}
    kx = rows[0].coeff(sp.cos(hold))
    rx, ry = sp.expand(rows[0].subs(sp.cos(hold), 0)), sp.expand(rows[1].subs(sp.sin(hold), 0))
    if not (rx.free_symbols | ry.free_symbols) & variables:
        return loops._constant_angle(str(rec["tk"]), rec["a"], rec["tk_q"],
                                     f"constant angle of the line of centres of '{rec['name']}'")
    terms = sp.Add.make_args(rx)
    cosines = [f for f in sp.Mul.make_args(terms[0]) if isinstance(f, sp.cos)] if len(terms) == 1 else []
    if len(cosines) != 1:
        return None
    phi = cosines[0].args[0]
    k = sp.simplify(rx / sp.cos(phi))
    if k.free_symbols & variables or sp.simplify(ry - k * sp.sin(phi)) != 0:
        return None
    # sign R e(theta_ab) + k e(phi) = 0: theta_ab = phi (opposite signs) or phi + pi, within whole turns of the angle
    # measured (so that the offset of the law stays the one measured)
    flip = 0 if float(kx.subs(values)) * float(k.subs(values)) < 0 else sp.pi
    here = float((phi + flip).subs(values))
    return phi + flip + 2 * sp.pi * int(np.round((rec["tk_q"] - here) / (2 * np.pi)))


def substitute_pairs(loops, number, rows: list, crossed: list, twists=()) -> tuple:
    """The loop's rows with each rolling pair's line-of-centres angle replaced: by its no-slip
    expression in the links' angles; or, where the rest of the loop fixes the line of centres
    (two gears pinned to one link, a planet on an arm: screwkin.analysis.course.rolling), by
    that, the vector rows (identities then) replaced by the no-slip law.  ``twists``: the loop's
    planar twists [(joint, (vx, vy, w))], returned with the same angle put in (rows, twists)."""
    holds = [h for _, h, _ in crossed if h is not None]
    tk = _line_of_centres(loops, rows, holds[0], crossed[0][0]) if len(crossed) == 1 and holds else None
    put = {hold: (tk if tk is not None else rec["expr"]) for rec, hold, _ in crossed if hold is not None}
    twists = [(name, tuple(loops.sp.sympify(e).subs(put) for e in t)) for name, t in twists]
    out = []
    for rec, hold, pair in crossed:
        if hold is None:
            loops.pairs.append(pair)
            continue
        if tk is not None:
            rec["fixed"] = tk
            out.append(rec["law_expr"].subs(rec["tk"], tk))
            loops.pairs.append(RollingPair(pair.name, pair.kind, pair.links, pair.law,
                                           None if not tk.free_symbols - set(loops.constants_now()) else
                                           f"{rec['tk']} = {tk}", True))
            loops.pair_notes.append(f"loop {number}: the rest of the loop fixes the line of centres of the pair "
                                    f"'{rec['name']}' ({rec['tk']} = {tk}) and its centre distance, as the pair does: "
                                    "its vector equation holds for every motion and the no-slip law is the loop's "
                                    "equation")
        else:
            rows = [r.subs(hold, rec["expr"]) for r in rows]
            loops.pairs.append(pair)
    return (out if tk is not None else rows), twists


def unwrapped(loops, link: str, angle, q: np.ndarray) -> float | np.ndarray:
    """A link's angle at q counted in turns from the configuration the equations were built at
    (the no-slip law of a rolling pair is not periodic in one link's angle): its value there
    plus the turns of the revolute joints from the ground to it, ``angle`` (its value at q)
    moved by whole turns to that."""
    model, mech = loops.mech.model, loops.mech
    jid = model.frames[mech.link_frame(link)].parentJoint
    turned = 0.0
    for k in model.supports[jid][1:]:
        c = mech.coordinate(model.names[k])
        j = loops.tree.get(model.names[k])
        if j is None or j.type not in ("revolute", "continuous") or c.nq != 1:
            continue
        turned += float(np.sign(np.asarray(j.direction) @ loops.n)) * (q[c.idx_q] - loops.q[c.idx_q])
    guess = loops.theta_q[link] + turned
    return nearest_turn(angle, guess)


def drop_constant_rows(loops) -> None:
    """Leave out of loops.F a row of constants only (a rack's centre distance, fixed by the guides
    too): an identity of the configuration measured; said in a note."""
    variables = {loops.sym[n] for n in loops.variables}
    kept = [r for r in loops.F if r.free_symbols & variables]
    if len(kept) < len(loops.F):
        loops.pair_notes.append(f"{len(loops.F) - len(kept)} loop row(s) hold the constants only (the pair's centre "
                                "distance, fixed by the other joints too): left out of F")
        loops.F = kept
