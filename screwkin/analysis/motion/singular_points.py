"""Singularities met along a sweep, located: between two recorded configurations where a singularity
measure's sign changes (the determinant of the relevant square Jacobian) the input value is found
by Brent's method, for serial, actuator and constraint singularities; a sweep's limit positions
are located already (analysis.motion.sweep).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...errors import AssemblyError
from ..singular import Generic, measures, scaled_jacobians
from .links import LOCATE_XTOL
from .crossing import dips, reclosing
from .sweep import SweepResult, SweepSingularity
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism

__all__ = ["locate_singularities"]

def _matrix(mech: Mechanism, q: np.ndarray, kind: str, g: Generic, V_ref: np.ndarray | None = None) -> np.ndarray:
    """The (scaled) matrix whose rank loss defines a singularity of this kind at q."""
    S = scaled_jacobians(mech, q, g.output, g.point)
    if kind == "constraint":
        return S.K
    if kind == "actuator":
        return S.K[:, g.p]
    N = S.V
    V = N if V_ref is None else N @ (N.T @ V_ref)  # a basis that varies smoothly with q
    return S.J @ V


def locate_singularities(solver, res: SweepResult, output: str | None=None, xtol: float = LOCATE_XTOL, point: bool = False) -> list:
    """Singular input values along a sweep, each refined to about 1e-9 or better: the limit
    positions the sweep located, and the other singularities.

    Each relative smallest singular value is scanned over the sweep; around each local
    minimum (between neighbours on one branch, where the input runs one way) the singular
    vectors u, v of that step give a smooth signed measure u . M(x) v that changes sign where
    M loses rank, and Brent's method finds its root (solutions re-closed at a tight
    tolerance).  Minima that are not zeros (no sign change) are not singular and are dropped.
    """
    from scipy.optimize import brentq

    mech = solver.mech
    tight = replace(mech.tolerances, closure=1e-14, max_iterations=60)
    g = Generic(mech, solver.inputs, output, point, configurations=solver.generic().configurations)
    table = [measures(mech, q, g) for q in res.q]
    rank_of = {"constraint": g.rank_K, "actuator": g.rank_Kp, "serial": g.out_dim or 0}
    found = list(res.limits)
    xs = res.values
    for kind in (table[0] if table else {}):
        m = np.array([t[kind] for t in table])
        r = rank_of[kind]
        if r == 0:
            continue
        for k, lo_k, hi_k in dips(m, xs):
            if (xs[k] - xs[lo_k]) * (xs[hi_k] - xs[k]) < 0:  # a turn between: that limit is listed already
                continue
            q_k = res.q[k]
            V_ref = None
            if kind == "serial":
                V_ref = scaled_jacobians(mech, q_k, output, point).V
            U, _, Vt = np.linalg.svd(_matrix(mech, q_k, kind, g, V_ref))
            u, v = U[:, r - 1], Vt[r - 1]
            q_at = reclosing(solver, res, q_k, tight)

            def signed(x, u=u, v=v, V_ref=V_ref) -> float:
                return float(u @ _matrix(mech, q_at(x), kind, g, V_ref) @ v)  # noqa: B023 - used within this iteration

            lo, hi = sorted((xs[lo_k], xs[hi_k]))
            try:
                f_lo, f_hi = signed(lo), signed(hi)
            except AssemblyError:
                continue
            if f_lo == 0 or f_hi == 0 or np.sign(f_lo) == np.sign(f_hi):
                continue
            x = brentq(signed, lo, hi, xtol=xtol, rtol=4 * np.finfo(float).eps, maxiter=200)
            q = q_at(x)
            sigma = measures(mech, q, g)[kind]
            if sigma < mech.tolerances.singular and not any(
                    s.kind == kind and abs(s.input - x) < 1e-7 for s in found):
                found.append(SweepSingularity(kind, float(x), float(sigma), q))
    found.sort(key=lambda s: s.input)
    return found
