"""The Gram-matrix cofactors of each planar loop in symbols (``singularities --symbolic``).

The loops and symbols are those of ``screwkin equations`` (analysis/course/equations.py): each loop's
joints in the order walked, each revolute's planar twist (y, -x, 1) at its centre (x, y) written
as a sum of the loop's link vectors from its first joint, each prismatic joint's (cos b, sin b, 0)
along its guide, each rolling or gear pair's (y, -x, 1) at its contact point (rolling without slip
turns one link about it relative to the other; the no-slip law put in, as equations does).  With S the 3 x n matrix of a loop's twists and G = S^T S, the cofactor
C_i = det(G without row and column i) vanishes exactly where joint i is stationary in the loop's
one-freedom motion (see analysis.singular.GramLoop); for n = 4 it is det(S without column i)^2.
A loop of three joints through a gear or rolling pair (two gears pinned to one link: the pair's
contact on the line of their centres) has one freedom too: its C_i are the 2 x 2 Gram determinants.
The loop's freedoms are n - rank S at the configuration measured.
The zero set does not depend on where the origin is put (a change of origin multiplies S by a
matrix of determinant 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import UsageError
from ..course.det_conditions import SIMPLIFY_OPS, condition
from ...model.linalg import rank
from ..course.vector_loops import LENGTH_FLOOR, VectorLoops
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["SymbolicGramLoop", "symbolic_gram"]


@dataclass(frozen=True)
class SymbolicGramLoop:
    joints: tuple  # the loop's joints, in the order walked
    cofactors: dict  # joint -> C_i as a sympy string ("" when the loop has other than one freedom)
    zero_when: dict  # joint -> conditions (strings) under which C_i = 0, as equations gives det A's
    note: str | None = None


def _simplified(sp, expr) -> tuple:
    expr = sp.factor(sp.expand(expr))
    coeff, factors = sp.factor_list(expr)
    parts = []
    for f, m in factors:
        c, rest = (sp.trigsimp(f) if sp.count_ops(f) <= SIMPLIFY_OPS else f).as_coeff_Mul()
        coeff *= c ** m
        parts += [(g, m) for g in sp.Mul.make_args(rest)]
    return coeff * sp.Mul(*[g ** m for g, m in parts]), [g for g, _ in parts]


def _loop_rank(mech: Mechanism, S, here: dict) -> int:
    """The rank of the loop's twists at the configuration measured (lengths over the characteristic
    length: a row scaling, the rank unchanged)."""
    M = np.array(S.subs(here).evalf(), dtype=float)
    M[:2] /= max(mech.length, LENGTH_FLOOR)
    return rank(M, mech.tolerances)


def symbolic_gram(mech: Mechanism, q: np.ndarray, inputs: list[str] | None=None) -> tuple:
    """A SymbolicGramLoop for each independent loop of a planar mechanism of revolute and
    prismatic joints, rolling and gear pairs (the loops of screwkin equations), at the assembled
    configuration q."""
    if mech.topology(q).motion_space != "planar":
        raise UsageError(f"{mech.path}: --symbolic writes planar loops' cofactors (this mechanism is not planar)")
    loops = VectorLoops(mech, q, inputs)
    sp = loops.sp
    order = loops.unknowns + loops.input_syms
    variables = {loops.sym[n] for n in order}
    here = {**loops.constants, **{loops.sym[n]: v for n, v in loops.values(q).items()}}
    out = []
    for twists in loops.loop_twists:
        names = tuple(n for n, _ in twists)
        n = len(twists)
        S = sp.Matrix([[sp.sympify(t[r]) for _, t in twists] for r in range(3)])
        free = n - _loop_rank(mech, S, here)
        if free != 1:
            out.append(SymbolicGramLoop(names, {}, {}, f"the loop has {n} joints and {free} freedoms on its own in "
                                                          "the plane, so every cofactor is 0 identically or none is"))
            continue
        cof, zero = {}, {}
        for i, name in enumerate(names):
            minor = S[:, [k for k in range(n) if k != i]]
            # n = 4: det(G_i) = det(S_i)^2; fewer joints (a gear pair's loop: its three centres on a line): the Gram
            gram = minor.det(method="berkowitz") ** 2 if n == 4 else (minor.T * minor).det(method="berkowitz")
            expr, factors = _simplified(sp, gram)
            cof[name] = str(expr)
            conds = []
            for f in factors:
                base = f.base if f.is_Pow else f
                present = sorted(base.free_symbols & variables, key=lambda s: order.index(s.name))
                if present:
                    cond = condition(loops, base, present)[0]
                    if cond not in conds:
                        conds.append(cond)
            zero[name] = tuple(conds)
        out.append(SymbolicGramLoop(names, cof, zero))
    return tuple(out)
