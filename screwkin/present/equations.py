"""Text and JSON of ``screwkin equations`` and of Newton's iterations from given estimates
(``solve --start``).  JSON expressions are in sympy syntax (``sympy.sympify`` reads them);
the text writes the same with theta, alpha, beta and pi as Greek letters."""

from __future__ import annotations

import re

import numpy as np

from ..analysis.course.symbols import GREEK as _GREEK, PlanarEquations
from ..units import unit_text
from .screws import screws_dict, screws_text
from .tables import shown_text, table
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.analysis.course.newton import NewtonResult
    from screwkin.analysis.course.equations import SpatialEquations

__all__ = ["equations_dict", "equations_text", "newton_dict", "newton_text", "greek", "Units"]

def greek(text: str) -> str:
    """theta3 -> θ3, alpha3b -> α3b, pi -> π, ** -> ^ (for reading; JSON keeps sympy syntax)."""
    for word, letter in _GREEK:
        text = re.sub(rf"\b{word}(?=\d)", letter, text)
    text = re.sub(r"\bpi\b", "π", text)
    return text.replace("**", "^")


def _matrix_text(name: str, rows: list | tuple, indent: str = "  ") -> list:
    """A matrix of expressions, one row a line."""
    lines = []
    for i, row in enumerate(rows):
        head = f"{name} = " if i == 0 else " " * (len(name) + 3)
        lines.append(indent + head + "[ " + " ,  ".join(greek(e) for e in row) + " ]")
    return lines


def _numbers_text(name: str, M: np.ndarray, indent: str = "    ") -> list:
    M = np.atleast_2d(np.asarray(M, float))
    lines = []
    for i, row in enumerate(M):
        head = f"{name} = " if i == 0 else " " * (len(name) + 3)
        lines.append(indent + head + "[" + " ".join(f"{shown_text(x):>12}" for x in row) + " ]")
    return lines


def _vector_equation(terms: tuple) -> str:
    out = ""
    for k, t in enumerate(terms):
        neg = t.startswith("-")
        t = t.lstrip("-").replace("*", " ")
        out += ("- " if neg else "") + t if k == 0 else (" - " if neg else " + ") + t
    return (out or "0") + " = 0"


def _pair_vectors(res: PlanarEquations) -> set:
    """The unit vectors named in the loops' terms by rolling and gear pairs (u32 of a rack's pitch line)."""
    return {f"u{res.numbers[p.links[0]]}{res.numbers[p.links[1]]}" for p in res.pairs if p.kind == "rack"}


def _pairs_text(res: PlanarEquations) -> list:
    lines = []
    for p in res.pairs:
        a, b = (res.numbers[lk] for lk in p.links)
        lines.append(f"{'rack-and-pinion' if p.kind == 'rack' else p.kind + ' rolling'} pair '{p.name}' "
                     f"({p.links[0]} {a}, {p.links[1]} {b}): no slip {greek(p.law)}")
        if p.kind == "rack":
            lines.append(f"  u{a}{b} = unit vector of the pitch line (fixed in link {a}), n{a}{b} = u{a}{b} turned +90 deg, "
                         f"x{a}{b} the contact point along it; in the loop: {greek(p.substitution)}")
        elif not p.in_system:
            lines.append(f"  e{a}{b} = unit vector of the line of centres at θ{a}{b}; in the loop: {greek(p.substitution)}")
        elif p.substitution is None:
            lines.append(f"  θ{a}{b} is constant (both centres fixed on one link): the law is the loop's equation")
        else:
            lines.append(f"  the rest of the loop turns the line of centres, {greek(p.substitution)}, and fixes the centre "
                         "distance: the law is the loop's equation")
    return lines


def equations_dict(res: PlanarEquations | SpatialEquations) -> dict:
    if not isinstance(res, PlanarEquations):
        return {"file": res.path, "motion_space": res.motion_space, "chains": screws_dict(res.chains),
                "constraint_jacobian": {"rows": res.rows, "columns": res.columns, "rank": res.rank,
                                        "generic_rank": res.generic_rank, "sigma_min": res.sigma_min,
                                        "singular": res.singular, "characteristic_length": res.length},
                "singular_conditions": list(res.singular_conditions)}
    known = [n for n, s in res.symbols.items() if s.role != "unknown"]
    return {
        "file": res.path,
        "motion_space": "planar",
        "plane_normal": list(res.normal),
        "links": {name: k for name, k in res.numbers.items()},
        "loops": [{"links": list(lp.links), "joints": list(lp.joints), "vector_equation": _vector_equation(lp.terms),
                   "terms": list(lp.terms), "equations": list(lp.equations)} for lp in res.loops],
        "vectors": [{"name": v.name, "link": v.link, "from": v.start, "to": v.end, "length": v.length,
                     "angle": v.angle} for v in res.vectors],
        "symbols": {n: {"link": s.link, "kind": s.kind, "value": s.value, "role": s.role, "meaning": s.meaning}
                    for n, s in res.symbols.items()},
        "known": known,
        "inputs": {n: res.input_joints[n][0] for n in res.inputs},
        "unknowns": list(res.unknowns),
        "velocity_equation": f"A [{', '.join(n + '_d' for n in res.unknowns)}] = "
                             f"B [{', '.join(n + '_d' for n in res.inputs)}]",
        "velocity_matrix_A": [list(r) for r in res.A],
        "velocity_matrix_B": [list(r) for r in res.B],
        "acceleration_equation": f"A [{', '.join(n + '_dd' for n in res.unknowns)}] = "
                                 f"B [{', '.join(n + '_dd' for n in res.inputs)}] + c",
        "acceleration_terms": list(res.acceleration_terms),
        "det_A": res.det_A,
        "singular_conditions": list(res.singular_conditions),
        "singular_words": list(res.singular_words),
        "at_configuration": {"A": res.A_value.tolist(), "B": res.B_value.tolist(), "det_A": res.det_A_value,
                             "unknown_rates_per_input_rate": None if res.rates is None else res.rates.tolist()},
        "notes": list(res.notes),
        **({"pairs": [{"name": p.name, "kind": p.kind, "links": list(p.links), "no_slip": p.law,
                       "substitution": p.substitution, "in_equations": p.in_system} for p in res.pairs]}
           if res.pairs else {}),
    }


def equations_text(res, explain: bool = True) -> str:
    """The equations as text; without ``explain`` (the command's default, --explain for all) the values at the
    configuration are det A and the rates A^-1 B on one line, without the matrices A and B in numbers."""
    if not isinstance(res, PlanarEquations):
        lines = [f"{res.motion_space} mechanism {res.path}: the product-of-exponentials structure equations of each "
                 "chain (the loops close where the chains to both sides of each cut joint meet)", ""]
        lines.append(screws_text(res.chains))
        lines.append(f"constraint Jacobian K: {res.rows} rows x {res.columns} joint rates, rank {res.rank} here, "
                     f"{res.generic_rank} generic (dimensionless with L = {res.length:.4g} m)")
        lines += [f"  {c}" for c in res.singular_conditions]
        return "\n".join(lines)
    num = ", ".join(f"{k} {name}" for name, k in sorted(res.numbers.items(), key=lambda t: t[1]))
    lines = [f"Vector-loop equations of {res.path} (planar, normal ({', '.join(shown_text(x) for x in res.normal)}))",
             f"links: {num}", ""]
    rows = [[greek(n), s.link, s.kind, shown_text(s.value) + (" rad" if s.kind == "angle" else " m"), s.role, greek(s.meaning)]
            for n, s in res.symbols.items()]
    lines.append(table(["symbol", "link", "kind", "value", "role", "meaning"], rows))
    lines.append("vectors: " + "; ".join(f"{v.name} = {greek(v.length)} at {greek(v.angle)}" for v in res.vectors))
    slides = sorted({t.lstrip("-").split("*")[1] for lp in res.loops for t in lp.terms if "*u" in t} - _pair_vectors(res))
    if slides:
        lines.append("guides: " + "; ".join(f"{u} = unit vector of the guide of x{u[1:]}, n{u[1:]} = {u} turned +90 deg"
                                           for u in slides))
    lines += _pairs_text(res)
    for k, lp in enumerate(res.loops, 1):
        lines.append(f"\nloop {k}: {' -> '.join(lp.links)} -> {lp.links[0]}  (joints {', '.join(lp.joints)})")
        lines.append(f"  {greek(_vector_equation(lp.terms))}")
        if len(lp.equations) == 2:
            lines.append(f"  x: {greek(lp.equations[0])} = 0")
            lines.append(f"  y: {greek(lp.equations[1])} = 0")
        else:  # a pair's no-slip law stands for the loop (screwkin.analysis.course.rolling)
            lines += [f"  no slip: {greek(e)} = 0" for e in lp.equations]
    known = [n for n, s in res.symbols.items() if s.role == "constant"]
    lines.append("")
    lines.append(f"known: {', '.join(greek(n) for n in known)} (constants); "
                 + ", ".join(f"{greek(n)} (input {res.input_joints[n][0]})" for n in res.inputs))
    lines.append(f"unknowns: {', '.join(greek(n) for n in res.unknowns)}")
    z = ", ".join(greek(n) + "'" for n in res.unknowns)
    w = ", ".join(greek(n) + "'" for n in res.inputs)
    lines.append(f"\nvelocity: A [{z}] = B [{w}]      (A = dF/d unknowns, B = -dF/d inputs)")
    lines += _matrix_text("A", res.A)
    lines += _matrix_text("B", res.B)
    zz = ", ".join(greek(n) + "''" for n in res.unknowns)
    ww = ", ".join(greek(n) + "''" for n in res.inputs)
    lines.append(f"acceleration: A [{zz}] = B [{ww}] + c      (rates written NAME_d)")
    lines += _matrix_text("c", [[e] for e in res.acceleration_terms])
    if not explain:
        here = ([f"det A = {shown_text(res.det_A_value)}"] if res.det_A_value is not None else []) + (
            ["unknown rates per unit input rate (A^-1 B): " + ", ".join(
                f"{greek(n)}' = " + " + ".join(f"({shown_text(x)}) {greek(m)}'" for x, m in zip(row, res.inputs))
                for n, row in zip(res.unknowns, res.rates))] if res.rates is not None else [])
        lines.append("\nat this configuration: " + "; ".join(here or ["-"]) + " (--explain: A and B in numbers)")
    else:
        lines.append("\nat this configuration:")
        lines += _numbers_text("A", res.A_value)
        lines += _numbers_text("B", res.B_value)
    if explain and res.det_A_value is not None:
        lines.append(f"    det A = {shown_text(res.det_A_value)}")
    if explain and res.rates is not None:
        lines.append("    unknown rates per unit input rate, A^-1 B:")
        for n, row in zip(res.unknowns, res.rates):
            lines.append(f"      {greek(n)}' = " + " + ".join(f"({shown_text(x)}) {greek(m)}'" for x, m in zip(row, res.inputs)))
    if res.det_A is not None:
        lines.append(f"\ndet A = {greek(res.det_A)}")
    lines.append("singular (det A = 0) where:" if res.singular_conditions else "")
    for c, wd in zip(res.singular_conditions, res.singular_words):
        lines.append(f"  {greek(c)}    [{greek(wd)}]")
    for wd in res.singular_words[len(res.singular_conditions):]:
        lines.append(f"  {greek(wd)}")
    for n in res.notes:
        lines.append(f"note: {n}")
    return "\n".join(lines).rstrip()


class Units:
    """How a person typed each quantity: angles in deg or rad, lengths in a unit of length (written by
    units.unit_text)."""

    def __init__(self, degrees: bool, lengths: dict | None = None) -> None:
        self.degrees = degrees
        self.lengths = lengths or {}  # symbol -> unit ("mm"); m when not given

    def value(self, name: str, kind: str, v: float) -> str:
        if kind == "angle":
            return unit_text(v, "deg" if self.degrees else "rad")
        return unit_text(v, self.lengths.get(name, "m"))

    def step(self, name: str, kind: str, v: float) -> str:
        if kind == "angle":
            return unit_text(v, "rad") + (f" = {unit_text(v, 'deg')}" if self.degrees else "")
        return unit_text(v, self.lengths.get(name, "m"))


def newton_text(res: NewtonResult, symbols: dict, units: Units, path: str) -> str:
    kinds = {n: symbols[n].kind for n in symbols}
    z = ", ".join(greek(n) for n in res.unknowns)
    ins = ", ".join(f"{greek(n)} = {units.value(n, kinds[n], v)}" for n, v in res.inputs.items())
    lines = [f"Newton-Raphson on the vector-loop equations of {path} (screwkin equations writes them)",
             f"inputs held: {ins}",
             f"unknowns z = [{z}]; each iteration: F(z), A = dF/dz, A dz = -F, z + dz",
             "start: " + ", ".join(f"{greek(n)} = {units.value(n, kinds[n], v)}" for n, v in res.start.items())]
    for st in res.steps:
        lines.append(f"\niteration {st.iteration}: at " + ", ".join(
            f"{greek(n)} = {units.value(n, kinds[n], st.before[n])}" for n in res.unknowns))
        lines.append("  F  = [" + " ".join(f"{shown_text(x):>12}" for x in st.residual) + " ]  m")
        lines += _numbers_text("A ", st.jacobian, indent="  ")
        lines.append("  dz = " + ", ".join(f"d{greek(n)} = {units.step(n, kinds[n], d)}"
                                         for n, d in zip(res.unknowns, st.step)))
        lines.append("  new estimates: " + ", ".join(
            f"{greek(n)} = {units.value(n, kinds[n], st.values[n])}" for n in res.unknowns))
    if res.stopped:
        lines.append(f"\nstopped: {res.stopped}")
    n = len(res.steps)
    lines.append(f"\nafter {n} iteration{'s' if n != 1 else ''}: "
                 + ", ".join(f"{greek(k)} = {units.value(k, kinds[k], v)}" for k, v in res.values.items()))
    if res.closes:
        lines.append(f"|F| = {res.residual:.3g} m: these values close the loops")
    else:
        lines.append(f"|F| = {res.residual:.3g} m: these estimates do NOT close the loops -- an iterate, not a solution")
    return "\n".join(lines)


def newton_dict(res: NewtonResult) -> dict:
    return {"unknowns": list(res.unknowns), "inputs": dict(res.inputs), "start": dict(res.start),
            "trace": [{"iteration": st.iteration, "estimates": dict(st.before), "residual": st.residual.tolist(),
                       "jacobian": st.jacobian.tolist(), "step": st.step.tolist(), "values": dict(st.values)}
                      for st in res.steps],
            "values": dict(res.values), "residual": res.residual, "closes": res.closes, "converged": res.converged,
            "stopped": res.stopped}
