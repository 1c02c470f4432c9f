"""The textbook Newton iteration on a planar mechanism's vector-loop equations
(screwkin.analysis.course.vector_loops), from estimates a student gives: each step's residual F,
Jacobian A = dF/dz and step dz = -A^-1 F, as a course solution writes them out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import UsageError
from ...model.geometry import TINY, wrap_angle
from .symbols import GREEK, spelled
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.course.vector_loops import VectorLoops

__all__ = ["NewtonStep", "NewtonResult", "textbook_newton", "start_estimates", "differing"]


@dataclass(frozen=True)
class NewtonStep:
    """One textbook Newton iteration on the loop equations: at the estimates ``before``,
    residual F, Jacobian A = dF/dz, step dz = -A^-1 F, new estimates ``values``."""

    iteration: int
    before: dict
    residual: np.ndarray
    jacobian: np.ndarray
    step: np.ndarray
    values: dict


@dataclass(frozen=True)
class NewtonResult:
    unknowns: tuple
    inputs: dict  # input symbol -> value
    start: dict
    steps: tuple
    values: dict  # the estimates reached
    residual: float  # |F| at them [m]
    closes: bool  # |F| below the closure tolerance (x the characteristic length)
    converged: bool  # iterated to convergence (no iteration count given) and closed
    stopped: str | None  # why Newton stopped early (a singular Jacobian), else None


def textbook_newton(loops: VectorLoops, inputs: dict, start: dict, iterations: int | None = None) -> NewtonResult:
    """Plain (undamped) Newton on the loop equations, as a textbook does it: from the
    estimates ``start`` (every unknown symbol -> value), with the inputs (input symbol ->
    value) held.  ``iterations``: exactly that many steps (fewer only when the Jacobian is
    singular); None: until the residual is below the closure tolerance (at most the
    closure solver's iteration limit)."""
    mech = loops.mech
    missing = [n for n in loops.unknowns if n not in start]
    if missing:
        raise UsageError(f"{mech.path}: no starting estimate of {', '.join(missing)}")
    values = {**{n: float(v) for n, v in inputs.items()}, **{n: float(start[n]) for n in loops.unknowns}}
    tol = mech.tolerances.closure * max(mech.length, 1e-9)
    limit = iterations if iterations is not None else mech.tolerances.max_iterations
    steps, stopped = [], None
    for it in range(1, limit + 1):
        r = loops.residual(values)
        if iterations is None and np.linalg.norm(r) < tol:
            break
        A, _ = loops.matrices(values)
        if A.shape[0] != A.shape[1]:
            held = (" (or a rolling pair's centre distance is held by its loop as well, in a way the loop "
                    "equations do not reduce)") if getattr(loops, "pairs", None) and A.shape[0] > A.shape[1] else ""
            raise UsageError(f"{mech.path}: {A.shape[0]} equations in {A.shape[1]} unknowns: Newton needs as many "
                             f"inputs as the mechanism has degrees of freedom{held}")
        s = np.linalg.svd(A, compute_uv=False)
        if not np.all(np.isfinite(A)) or s[-1] <= mech.tolerances.zero * max(s[0], TINY):
            stopped = f"the Jacobian is singular at iteration {it} (det A = {np.linalg.det(A):.3g})"
            break
        dz = np.linalg.solve(A, -r)
        new = dict(values)
        for n, d in zip(loops.unknowns, dz):
            new[n] = values[n] + float(d)
        steps.append(NewtonStep(it, {n: values[n] for n in loops.unknowns}, r, A, dz,
                                {n: new[n] for n in loops.unknowns}))
        values = new
        if not np.all(np.isfinite(dz)):
            stopped = f"the step is not finite at iteration {it}"
            break
    res = float(np.linalg.norm(loops.residual(values)))
    closes = bool(np.isfinite(res) and res < tol)
    return NewtonResult(tuple(loops.unknowns), dict(inputs), {n: float(start[n]) for n in loops.unknowns},
                        tuple(steps), {n: values[n] for n in loops.unknowns}, res, closes,
                        closes and iterations is None, stopped)


def start_estimates(mech: Mechanism, loops: VectorLoops, solver, q_in: np.ndarray, values: dict, typed: list) -> tuple:
    """The estimates of every unknown of the loop equations from ``--start`` items (units.parse_typed_assignments):
    symbols, link names (their angles) or passive joint values (placed at q_in, the inputs set);
    returns (symbol -> estimate, symbol -> the units.Quantity typed)."""
    by_link = {}
    for n in loops.variables:
        info = loops.symbol_info[n]
        if info.kind == "angle":
            by_link[info.link] = n
    symbols, joints, units = {}, {}, {}
    joint_names = set(mech.coordinate_names)
    for name, typed_value in typed:
        v = typed_value.value
        as_typed = name
        if name not in by_link and name not in joint_names:  # θ3 as the text writes it, theta3 as JSON does
            name = spelled(name)
        if name in loops.input_joints or name in values:
            raise UsageError(f"{mech.path}: '{name}' is an input: give its value with --set")
        if name in loops.unknowns:
            symbols[name] = v
        elif name[-1:] in ("h", "v") and name[:-1] in loops.unknowns and loops.symbol_info[name[:-1]].kind == "slider":
            # the textbook's horizontal (h) or vertical (v) coordinate of the slider's centre, measured
            # from the same joint centre, for a guide on the ground: from + x u + e n, read along x or y
            guide = loops.ground_guide(name[:-1])
            if guide is None:
                raise UsageError(f"{mech.path}: --start {name}: the guide of {name[:-1]} turns with a link; give "
                                 f"{name[:-1]}, the distance along the guide")
            beta, e = guide
            c, s_ = (np.cos(beta), -np.sin(beta)) if name[-1] == "h" else (np.sin(beta), np.cos(beta))
            if abs(c) < mech.tolerances.geometry:
                other = "v" if name[-1] == "h" else "h"
                raise UsageError(f"{mech.path}: --start {name}: the guide of {name[:-1]} is "
                                 f"{'vertical' if name[-1] == 'h' else 'horizontal'}; give {name[:-1]}{other} or "
                                 f"{name[:-1]}")
            name = name[:-1]
            symbols[name] = (v - e * s_) / c
        elif name in by_link:
            symbols[by_link[name]] = v
            name = by_link[name]
        elif name in joint_names:
            joints[name] = v
            continue
        else:
            valid = ", ".join([f"{n} ({w})" if w != n else n for n, w in ((n, _as_symbol(n)) for n in loops.unknowns)]
                              + [lk for lk, n in by_link.items() if n in loops.unknowns])
            raise UsageError(f"{mech.path}: --start: no unknown, link or joint named '{as_typed[:80]}' "
                             f"(unknowns of the loop equations: {valid}; or passive joint names)")
        units[name] = typed_value
    start = loops.values(solver.set_inputs(q_in, joints)) if joints else {}
    covered = set(symbols)
    if joints:
        given = set(joints) | set(values)
        covered |= {n for n in loops.unknowns if _needed_joints(loops, n) <= given}
    missing = [n for n in loops.unknowns if n not in covered]
    if missing:
        raise UsageError(f"{mech.path}: --start gives no estimate of {', '.join(missing)} "
                         f"(links {', '.join(loops.symbol_info[n].link for n in missing)})")
    start = {n: symbols.get(n, start.get(n)) for n in loops.unknowns}
    return start, units


def _as_symbol(name: str) -> str:
    """A symbol as the text writes it (theta3 -> θ3), the other spelling --start takes."""
    for word, letter in GREEK:
        if name.startswith(word) and name[len(word):][:1].isdigit():
            return letter + name[len(word):]
    return name


def _needed_joints(loops: VectorLoops, name: str) -> set:
    """The tree joints whose values place the quantity ``name`` (the joints from the ground to the
    links it is measured on)."""
    mech = loops.mech
    model = mech.model
    info = loops.symbol_info[name]
    if info.kind == "angle":
        links = [info.link]
    else:
        joint = next(j for j, t in loops.slide_terms.items() if t["x"].name == name)
        links = [loops.slides[joint]["guide"], loops.slides[joint]["slider"]]
    out = set()
    for lk in links:
        jid = model.frames[mech.link_frame(lk)].parentJoint
        out |= {model.names[j] for j in model.supports[jid] if j > 0}
    return out


def differing(mech: Mechanism, loops: VectorLoops, a: dict, b: dict) -> list:
    """The unknowns of ``loops`` whose values in ``a`` and ``b`` (symbol -> value) differ: an angle by
    more than the geometry tolerance modulo a turn, a length by more than it times max(L, 1 m)."""
    tol = mech.tolerances.geometry * max(mech.length, 1.0)
    return [n for n in loops.unknowns
            if abs(wrap_angle(a[n] - b[n]) if loops.symbol_info[n].kind == "angle" else a[n] - b[n]) > tol]
