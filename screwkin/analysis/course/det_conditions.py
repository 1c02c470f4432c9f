"""det A of a planar mechanism's vector-loop equations (screwkin.analysis.course.vector_loops),
factored, and where each factor vanishes: the limit positions and dead centres, as
conditions on the angles (sympy) and in words.
"""

from __future__ import annotations

__all__ = ["determinant", "condition", "SIMPLIFY_OPS"]

#: Factors of det A up to this many operations are simplified with sympy's trigsimp (0.1-1 s
#: for a 3-RRR's); larger ones (a 3-RPR's: 7 s) are left expanded.
SIMPLIFY_OPS = 80


def determinant(loops) -> tuple:
    """(det A simplified, its singular conditions as strings, the same in words) of the
    vector loops ``loops`` (screwkin.analysis.course.vector_loops.VectorLoops)."""
    sp = loops.sp
    A = loops.Am
    if A.shape[0] != A.shape[1] or A.shape[0] == 0:
        return None, (), (f"A is {A.shape[0]} x {A.shape[1]}: no determinant (the inputs do not match the "
                          "mobility)",)
    d = sp.expand(A.det(method="berkowitz"))
    if d == 0:
        return d, ("0 = 0",), ("det A vanishes identically: the inputs never determine the unknowns",)
    coeff, factors = sp.factor_list(d)
    parts = []
    for f, m in factors:  # trigsimp each factor: sin(a)cos(b) - cos(a)sin(b) -> sin(a - b)
        # (a factor of more than SIMPLIFY_OPS operations is left as factored: trigsimp takes seconds there)
        c, rest = (sp.trigsimp(f) if sp.count_ops(f) <= SIMPLIFY_OPS else f).as_coeff_Mul()
        coeff *= c ** m
        parts += [(g, m) for g in sp.Mul.make_args(rest)]
    d = coeff * sp.Mul(*[g ** m for g, m in parts])
    order = loops.unknowns + loops.input_syms
    variables = {loops.sym[n] for n in order}
    conds, words = [], []
    for f, _m in parts:
        present = sorted(f.free_symbols & variables, key=lambda s: order.index(s.name))
        if not present:
            continue  # a constant (a length): not zero
        cond, word = condition(loops, f, present)
        if cond not in conds:
            conds.append(cond)
            words.append(word)
    if not conds:
        words.append("det A never vanishes: the inputs always determine the unknowns")
    return d, tuple(conds), tuple(words)


def condition(loops, f, present: list) -> tuple:
    """(the condition that factor f of det A vanishes, in symbols; the same in words): f a
    sine or cosine of one argument is solved for its first symbol in ``present``."""
    sp = loops.sp
    links = ", ".join(f"'{loops.symbol_info[s.name].link}'" for s in present)
    v = present[0]
    if f.func in (sp.sin, sp.cos) and len(f.args) == 1:
        arg = f.args[0]
        roots = (0, sp.pi) if f.func is sp.sin else (sp.pi / 2, -sp.pi / 2)
        try:
            sols = [sp.solve(sp.Eq(arg, r), v) for r in roots]
        except NotImplementedError:  # pragma: no cover - linear in v
            sols = [[], []]
        if all(len(s) == 1 for s in sols):
            rhs = " or ".join(str(s[0]) for s in sols)
            cond = f"{f} = 0: {v} = {rhs}"
        else:
            cond = f"{f} = 0"
        if f.func is sp.sin:
            word = (f"{links}: the directions {arg} apart are parallel (stretched out or folded)"
                    if len(present) > 1 else f"{links}: {arg} is 0 or pi (along the guide)")
        else:
            word = (f"{links}: {arg} is +-pi/2 (perpendicular)" if len(present) > 1 else
                    f"{links}: {arg} is +-pi/2 (perpendicular to the direction its angle is measured from)")
        return cond, word
    return f"{f} = 0", f"{links}: {f} = 0"
