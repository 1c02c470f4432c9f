"""The textbook Newton iteration on a planar mechanism's vector-loop equations
(screwkin.analysis.course.vector_loops), from estimates a student gives: each step's residual F,
Jacobian A = dF/dz and step dz = -A^-1 F, as a course solution writes them out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import UsageError
from ...model.geometry import TINY

__all__ = ["NewtonStep", "NewtonResult", "newton"]


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


def newton(loops, inputs: dict, start: dict, iterations: int | None = None) -> NewtonResult:
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
