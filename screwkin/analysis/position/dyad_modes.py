"""Every assembly mode of a planar mechanism made of dyads, in closed form, and why that is all.

A planar mechanism that splits (model.planar_graph.plan) into its inputs and k class-II dyads
(RRR, RRP, PRR, RPR) is placed, at given inputs, one dyad after the other: each is a circle-circle
or a circle-line intersection on links already placed, a quadratic with two roots -- the dyad's
branch, the sign of the square root of its discriminant.  So the closure has exactly 2^k solutions
over the complex numbers, counted with multiplicity, one per branch vector (Bezout for a triangular
system of k quadratics; a dyad's two circles are never concentric where the plan applies, checked):
- a branch vector whose every discriminant is >= 0 is a real configuration, an assembly mode;
- a dyad whose discriminant is negative gives a complex pair (its links placed off the real
  plane, and every dyad placed on them complex too): no real assembly;
- a discriminant that is zero (to round-off: below Tolerances.zero, relative) is a limit
  position: that dyad's two branches are one double root, one mode, not a simple root.
The real set is therefore complete by construction -- no search, no trace test.  The placing is
analysis.motion.dyads' own (its continuation engine, ``ClosedFormCurve``, predicting every branch
vector at once); each configuration is checked by its closure residual on Pinocchio's closure
(model.kernel.closure) after the same undamped Newton polish as the homotopy's modes.  Where the plan does
not apply, or a check fails, the caller (analysis.position.certified) takes the homotopy.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...model.kernel import newton
from ...model.cuts import Assembly
from ...model.manifold import continuous_angle
from ..motion.dyads import ClosedFormCurve, cached_plan

__all__ = ["DyadModes", "dyad_modes", "MAX_DYADS"]

#: The most dyads whose 2^k branch vectors are enumerated (past it the homotopy takes over).
MAX_DYADS = 12


@dataclass(frozen=True)
class DyadModes:
    """The real modes [(q, model.cuts.Assembly, branch vectors that reach it, simple)] -- simple:
    None for a regular root (solve's measures decide), False for a double root (a dyad at a limit
    position) -- and the counts: ``dyads`` k, ``choices`` 2^k branch vectors (every complex
    solution, with multiplicity), ``real_choices`` those that are real, ``kinds`` the dyads' kinds
    in the order they are placed, ``swept`` the input the plan starts from, ``seconds``."""

    modes: list
    dyads: int
    choices: int
    real_choices: int
    kinds: tuple
    swept: str
    seconds: float

    @property
    def complex(self) -> int:
        return self.choices - self.real_choices


def dyad_modes(solver, values: dict) -> DyadModes | str:
    """Every assembly mode of ``solver``'s mechanism at the input ``values`` by its dyads (see the
    module), or why the closed form does not apply (a sentence)."""
    t0 = time.perf_counter()
    mech = solver.mech
    p, name, why = None, None, "no input joints"
    for name in solver.inputs:
        p = cached_plan(solver, name)
        if not isinstance(p, str):
            break
        why = p
    if p is None or isinstance(p, str):
        return why
    k = len(p.dyads)
    if k > MAX_DYADS:
        return f"{k} dyads: 2^{k} branch vectors are more than the closed form enumerates"
    # q0: the reference configuration with the held inputs at their values (closed when they are
    # the reference's); the swept input moves from its value there.  The geometry reads each link
    # on its own side of every joint, so q0 need not close once the held inputs are set: every
    # configuration placed is checked on Pinocchio's closure below.
    ref = solver.reference()
    q0 = solver.set_inputs(mech.neutral() if ref is None else ref, {n: v for n, v in values.items() if n != name})
    c = mech.coordinate(name)
    start = float(q0[c.idx_q]) if c.nq == 1 else float(continuous_angle(q0, c.idx_q))
    curve = ClosedFormCurve(mech, p, q0, start, probe=False)
    if not curve.ok:
        return curve.reason
    x = float(values[name])
    B = 1.0 - 2.0 * ((np.arange(2 ** k)[:, None] >> np.arange(k)[None]) & 1)  # (2^k, k) every branch vector
    _, discs = curve.predict(np.full(len(B), x), list(B.T))
    zero = mech.tolerances.zero
    negative = discs < -zero
    # a dyad placed on real links whose discriminant is not a number: its circles are concentric
    # (or its slide has no direction), a degenerate geometry the count 2^k does not hold for
    before = np.cumsum(negative, axis=0) - negative  # complex dyads before each one
    if np.any(~np.isfinite(discs) & (before == 0)):
        return "a dyad's circles are concentric or its slide has no direction (a degenerate geometry)"
    real = ~negative.any(axis=0)
    near = np.abs(discs) <= zero
    if np.any(near[:, real].sum(axis=0) > 1):
        return "two dyads at a limit position at once"
    clamp = np.where(near.any(axis=0), near.argmax(axis=0), -1)
    found = []  # [signature, q, Assembly, branch vectors, simple]
    for i in np.unique(clamp[real]):
        cols = np.flatnonzero(real & (clamp == i))
        poses, d = curve.predict(np.full(len(cols), x), list(B[cols].T), None if i < 0 else int(i))
        if np.any(d[np.arange(k) != i] < -zero):
            return "a dyad's discriminant changed sign when another's limit position was placed exactly"
        Q = curve.correct(poses, len(cols))[0]
        for q in Q:
            a = newton.polish(mech.closure.pinocchio, solver._wrap(q), solver.frozen)
            if not a.residual <= mech.tolerances.closure:
                return (f"a branch vector's configuration does not close the loops (residual {a.residual:.2g}): "
                        "the dyads' geometry was not read as Pinocchio places the links")
            q = solver._wrap(a.q)
            sig = solver.signature(q)
            same = next((m for m in found if solver.same_mode(m[0], sig)),
                        None)
            if same is not None:  # two branch vectors, one placement: a double root
                same[3] += 1
                same[4] = False
                continue
            found.append([sig, q, Assembly(q, a.residual, a.iterations, "the dyads' closed form"), 1,
                          None if i < 0 else False])
    kinds = tuple(d[0] for d in p.dyads)
    return DyadModes([(q, a, n, simple) for _, q, a, n, simple in found], k, len(B), int(real.sum()), kinds, name,
                     time.perf_counter() - t0)
