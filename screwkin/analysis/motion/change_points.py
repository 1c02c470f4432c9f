"""Singularities of the configuration space met along a sweep: change points, shaky points, the points
where branches of another mobility meet -- located, analysed (analysis.local) and told by the branch the
motion comes in on and the one it continues on.

A sweep that meets a change point may go on along either branch (a four-bar folded flat: from the
parallelogram onto the anti-parallelogram): the constraint measure (analysis.singular)
dips to zero there without changing sign, so it is not among the sign changes that
analysis.motion.singular_points locates.  Here every local minimum of the constraint measure along the
recorded sweep (crossing.dips: below LOOK_BELOW, lower than both neighbours) is refined by
bounded minimization of the measure over the input between the neighbours (the loops closed again at each value from the
sweep's configuration), and kept where the measure falls below ``Tolerances.singular``.  At each such
configuration -- and at the constraint singularities already located -- the local analysis decides
what the point is; the branch the motion comes in on and the one it continues on are those whose
tangents are nearest (largest |cos|) the sweep's joint rates on either side.

"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...errors import AssemblyError
from ..local import local_analysis
from ..singular import Generic, measures
from .crossing import TIGHT_CLOSURE, ChangePoint, dips, nearest_branch, reclosing



__all__ = ["change_points"]



def change_points(solver, res, located: list=(), xtol: float | None = None) -> tuple:
    """ChangePoint for each constraint singularity along the sweep ``res`` of ``solver``: those of
    ``located`` (SweepSingularity of kind "constraint" from singular_points) and the dips found here."""
    from scipy.optimize import minimize_scalar

    mech = solver.mech
    tol = mech.tolerances
    g = Generic(mech, solver.inputs, configurations=solver.generic().configurations)
    if not g.rank_K or len(res.q) == 0:
        return ()
    m = np.array([measures(mech, q, g)["constraint"] for q in res.q])
    xs = res.values
    tight = replace(tol, closure=TIGHT_CLOSURE, max_iterations=60)  # near a crossing Newton is slow: close tighter
    points = [(s.input, s.sigma, s.q, False) for s in located if s.kind == "constraint"]
    for k, lo_k, hi_k in dips(m, xs):
        lo, hi = sorted((xs[lo_k], xs[hi_k]))
        q_k = res.q[k]
        q_at = reclosing(solver, res, q_k, tight)

        def sigma(x, q_at=q_at):
            try:
                return measures(mech, q_at(x), g)["constraint"]
            except AssemblyError:
                return np.inf

        if m[k] < tol.singular:
            x, q = float(xs[k]), q_k
        else:
            found = minimize_scalar(sigma, bounds=(lo, hi), method="bounded",
                                    options={"xatol": xtol or tol.closure})
            x = float(found.x)
            try:
                q = q_at(x)
            except AssemblyError:
                continue
        s = measures(mech, q, g)["constraint"]
        if s < tol.singular and not any(abs(x - p[0]) <= tol.geometry * max(1.0, abs(x)) for p in points):
            points.append((x, s, q, True))
    out = []
    n = len(xs)
    for x, s, q, new in sorted(points, key=lambda p: p[0]):
        local = local_analysis(mech, q, inputs=solver.inputs, generic_rank=g.rank_K)
        j = int(np.argmin(np.abs(xs - x)))
        if abs(xs[j] - x) <= tol.geometry * max(1.0, abs(x)):  # at a recorded step: its neighbours
            a, b = j - 1, j + 1
        elif j > 0 and (xs[j - 1] - x) * (xs[j] - x) < 0:
            a, b = j - 1, j
        else:
            a, b = j, j + 1
        came = nearest_branch(mech, local, res.rates[a]) if 0 <= a < n else None
        goes = nearest_branch(mech, local, res.rates[b]) if 0 <= b < n else None
        out.append(ChangePoint(float(x), float(s), q, local, came, goes, new))
    return tuple(out)
