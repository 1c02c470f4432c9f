"""Screws and gears count turns: the whole turns typed for a revolute input (720deg), carried through the
higher pairs whose coupling rows are linear in unwrapped angles (a lead screw's turn, a gear's roll).

A solve finds the modes within a turn, keeps those whose counted angles continue the assembled
configuration's (the thread a nut engages, the tooth a gear meets, as the file draws them), then turns
them on by the inputs' whole turns along the loops' rates before Newton closes at the typed values.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError
from ...model.cuts import Assembly
from ...model.geometry import wrap_angle

__all__ = ["whole_turns", "engaged", "turn_on"]


def whole_turns(solver, values: dict) -> dict:
    """Input name -> the whole turns [rad] of a revolute input's typed value, when the mechanism has
    higher pairs whose coupling rows count turns (screws, gears): 720deg is not 0 there."""
    if not solver.mech.counted_turns:
        return {}
    out = {}
    for name, v in values.items():
        c = next((c for c in solver.mech.coordinates if c.joint == name and c.nq == 1), None)
        if c is not None and solver.model.joints[c.joint_id].shortname().startswith("JointModelR"):
            w = float(v - wrap_angle(v))
            if abs(w) > 0:
                out[name] = w
    return out


def engaged(solver, found, values: dict):
    """The solutions whose counted angles (a screw's turn, a gear's roll) continue the assembled
    configuration's: each predicted from there by the loops' rates (linear for screws and gears) and
    kept when within half a turn of it; the others differ by whole turns of a thread or a tooth
    that no motion from the file's configuration reaches."""
    try:
        ref = solver.mech.assemble().q
    except AssemblyError:
        return found
    dv = {n: float(values[n]) - float(solver.mech.joint_values(ref).get(n, 0.0)) for n in solver.inputs}
    qd = solver.rates(ref, solver.mech.closure.jacobian(ref), dv)
    counted = sorted(solver.mech.counted_turns)
    vidx = [next(c.idx_v for c in solver.mech.coordinates if c.idx_q == t) for t in counted]
    pred = np.array([ref[t] for t in counted]) + qd[vidx]
    off = [float(np.max(np.abs(np.array([q[t] for t in counted]) - pred))) for _, q, _ in found]
    kept = [f for f, d in zip(found, off) if d < np.pi]
    if kept:
        # the others are other turns of the same engagement (dropped) or other assembly modes (kept: a
        # friction wheel's lower assembly has counted angles of its own, not the upper one's turned)
        for f, d in zip(found, off):
            if d >= np.pi and not any(_turned(solver, f[1], k[1], counted) for k in kept):
                kept.append(f)
        return kept
    # no start reached the counted angles the motion from the file's configuration gives (a start lies
    # within a turn of each, the motion may not: an idler's two meshes count its turn each on its own):
    # Newton from that motion's linear prediction (exact for gears and screws on fixed centres)
    q_pred = solver.set_inputs(pin.integrate(solver.model, ref, qd), values)
    try:
        a = solver.mech.closure.solve(q_pred, frozen=solver.frozen)
    except AssemblyError:
        return [found[int(np.argmin(off))]]
    if float(np.max(np.abs(np.array([a.q[t] for t in counted]) - pred))) < np.pi:
        return [(solver.signature(a.q), a.q, a)]
    return [found[int(np.argmin(off))]]


def _turned(solver, q: np.ndarray, other, counted: list) -> bool:
    """Whether q is ``other`` with some of its pairs turned on by whole turns: for each higher pair's
    coupling row, one of its counted angles differs from other's by a whole number of turns (a
    thread, a tooth), at least one by a nonzero number."""
    shift = False
    for row in solver.mech.extra_rows:
        members = [iq for iq, _, _ in getattr(row, "terms", ()) if iq in counted]
        if not members:
            continue
        turns = [(q[iq] - other[iq]) / (2 * np.pi) for iq in members]
        whole = [abs(k - round(k)) < solver.mech.tolerances.geometry for k in turns]
        if not any(whole):
            return False
        shift |= any(w and round(k) != 0 for w, k in zip(whole, turns))
    return shift


def turn_on(solver, q: np.ndarray, whole: dict, typed: dict) -> tuple:
    """(q, assembly) of the solution ``q`` found within a turn, turned on by the inputs' whole turns:
    the loops' rates per unit input move every joint and every counted angle linearly (exactly, for
    gears and screws), then Newton closes at the typed inputs."""
    K = solver.mech.closure.jacobian(q)
    qd = solver.rates(q, K, {n: whole.get(n, 0.0) for n in solver.inputs})
    a = solver.mech.closure.solve(solver.set_inputs(pin.integrate(solver.model, q, qd), typed), frozen=solver.frozen)
    return a.q, Assembly(a.q, a.residual, a.iterations)
