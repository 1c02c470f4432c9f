"""A motion through a change point (issue 41): the change points a recorded motion meets, the branch it
goes on along at each, and that branch followed from there -- the pieces analysis.motion.sweep applies to
whatever engine ran the motion, and analysis.motion.change_points names the points with.

A motion passes a change point on the branch whose tangent continues the incoming one: the change points
the recorded motion meets are located (``passed``: the dips of the constraint measure, a "limit position"
an engine located where K itself loses rank, the start); the local analysis (analysis.local) gives the
tangent cone there -- the branches' tangent lines -- and the branch the motion came in on is the one
whose line, followed back from the change point, reaches nearest the configuration recorded before it
(``crossing``).  The motion goes on along that line (or, asked for, the other one), followed from the
change point by continuation to the grid values after it (``follow``).  At the start of a motion there
is no incoming tangent: the branch the file's configuration lies on is taken, else the one nearest the
input's own direction projected on ker K, said so.

The constraint measure along a motion (``constraint_profile``, ``dips``) and the configuration closed again
at another input value (``reclosing``) are also analysis.motion.singular_points' and change_points'.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...errors import AssemblyError
from ...model.geometry import wrap_angle
from ..local import LocalAnalysis, local_analysis
from .batch_sweep import batch_closure
from .continuation import Neighbour, Stuck
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.motion.continuation import Curve
    from screwkin.tolerances import Tolerances
    from collections.abc import Callable
    from collections.abc import Iterator
    from screwkin.analysis.local import Branch

__all__ = ["ChangePoint", "Crossing", "passed", "crossing", "follow", "constraint_profile", "dips", "reclosing",
           "LOOK_BELOW", "TIGHT_CLOSURE", "START", "nearest_branch"]

#: The closure tolerance the refined configurations are solved to when Newton gets there (singular_points' too).
TIGHT_CLOSURE = 1e-14

#: A dip of a relative singular value along a sweep deeper than this is looked at more closely.
LOOK_BELOW = 0.5


def dips(m: np.ndarray, xs: np.ndarray) -> Iterator:
    """(k, k - 1, k + 1) for each recorded step k where the measure m is lowest among its neighbours and
    below LOOK_BELOW (the neighbours' indices clipped to the sweep)."""
    for k in range(len(m)):
        left = m[k - 1] if k > 0 else np.inf
        right = m[k + 1] if k + 1 < len(m) else np.inf
        if m[k] <= left and m[k] <= right and m[k] <= LOOK_BELOW:
            yield k, max(k - 1, 0), min(k + 1, len(xs) - 1)


def reclosing(solver, res, q_k: np.ndarray, tight: Tolerances) -> Callable:
    """x -> the configuration at input value x closed from the sweep's q_k (tolerances ``tight`` when
    Newton gets there, the mechanism's otherwise); raises AssemblyError when neither closes."""
    mech, frozen = solver.mech, solver.frozen

    def q_at(x: float):
        q0 = solver.set_inputs(q_k, {res.input: x})
        try:
            return mech.closure.solve(q0, frozen=frozen, tolerances=tight).q
        except AssemblyError:
            return mech.closure.solve(q0, frozen=frozen).q

    return q_at


@dataclass(frozen=True)
class ChangePoint:
    """A constraint singularity met along a sweep: ``input`` [rad or m], the measure there, the
    configuration, its local analysis, and the branches (indices into local.branches) the motion comes
    in on and continues on (None when the motion does not run on either side, or no branch is near)."""

    input: float
    sigma: float
    q: np.ndarray
    local: LocalAnalysis
    came: int | None
    goes: int | None
    located: bool  # found here (a dip without a sign change), not by singular_points
    switched: bool = False  # a motion passing it took the other branch, as asked (sweep's branch="other")


def _direction(mech: Mechanism, rates: np.ndarray):
    v = np.asarray(rates, float).copy()
    v[mech.translational] /= mech.length
    n = np.linalg.norm(v)
    return v / n if n > 0 else None


def nearest_branch(mech: Mechanism, local: LocalAnalysis, rates: np.ndarray):
    """The branch whose tangent is nearest the direction of ``rates`` (joint rates), or None."""
    u = _direction(mech, rates)
    if u is None or not local.branches:
        return None
    names = mech.coordinate_names
    best, score = None, 0.0
    for k, b in enumerate(local.branches):
        t = _direction(mech, [b.tangent.get(n, 0.0) for n in names])
        if t is None:
            continue
        c = abs(float(u @ t))
        if c > score:
            best, score = k, c
    return best


@dataclass(frozen=True)
class Crossing:
    """A change point a motion meets (``passed``): its input value x, configuration q, relative sigma,
    and where it lies in the recorded motion: after the configuration of index ``before`` (-1: at
    the start) -- on the grid value of index ``at`` when one lies on it (else None); ``limit``: an
    engine reported it as a limit position (it is not one: K itself loses rank there)."""

    x: float
    q: np.ndarray
    sigma: float
    before: int
    at: int | None = None
    limit: bool = False
    rank: int = 0  # the generic rank of K the measure was taken at


def constraint_profile(mech: Mechanism, Q: np.ndarray | list, rank: int | None = None) -> tuple:
    """(the relative smallest singular value of the scaled K at each configuration of Q (N,), the rank
    it is taken at): analysis.singular.measures' "constraint", with ``rank`` (default the
    largest rank met along Q: a motion's configurations are generic but for isolated ones) for the
    generic one; the Jacobians batched where the closure is (analysis.motion.batch_sweep.batch_closure)."""
    Q = np.atleast_2d(np.asarray(Q, float))
    if not mech.cuts or not len(Q):
        return np.ones(len(Q)), 0
    bc = batch_closure(mech) if len(Q) > 1 else None
    if bc is not None and mech.model.nq == mech.model.nv:
        K = bc.constraint_jacobians(Q)
    else:
        K = np.array([mech.closure.jacobian(q) for q in Q])
    if K.ndim < 3 or K.shape[1] == 0:
        return np.ones(len(Q)), 0
    K = K.copy()
    K[:, np.asarray(mech.closure.position_rows, bool)] /= mech.length
    K[:, :, mech.translational] *= mech.length
    s = np.linalg.svd(K, compute_uv=False)
    tol = mech.tolerances
    top = s[:, :1]
    r = rank if rank is not None else int(np.max(np.sum(s > np.maximum(tol.singular * top, tol.rank_atol), axis=1)))
    if r == 0 or r > s.shape[1]:
        return np.ones(len(Q)), 0
    return np.where(top[:, 0] > 0, s[:, r - 1] / np.where(top[:, 0] > 0, top[:, 0], 1.0), 0.0), r


def passed(solver, res) -> list:
    """The change points the recorded motion ``res`` (a SweepResult) meets, in the order of the motion
    (Crossing each): a configuration where the constraint measure (``constraint_profile``) is below
    Tolerances.singular -- at the start, at a dip between two recorded configurations (refined by
    bounded minimization over the input, the loops closed again from the recorded one), or at a limit
    position an engine located (an actuator singularity where K itself loses rank: a change point)."""
    mech, tol = solver.mech, solver.mech.tolerances
    xs = np.asarray(res.values, float)
    if not len(xs):
        return []
    m, r = constraint_profile(mech, res.q)
    out = []
    if r == 0:
        return out
    tight = replace(tol, closure=TIGHT_CLOSURE, max_iterations=60)
    for k, lo_k, hi_k in dips(m, xs):
        if 0 < k < len(xs) - 1 and (xs[k] - xs[lo_k]) * (xs[hi_k] - xs[k]) < 0:
            continue  # the input turns back here: a limit position (listed by the engine)
        if m[k] < tol.singular:
            x, q, s = float(xs[k]), res.q[k], float(m[k])
        elif _may_reach_zero(m, xs, k):
            bounds = sorted((xs[lo_k], xs[hi_k]))
            found = _again(solver, out, res, k, lo_k, hi_k, bounds) or _least(solver, res, res.q[k], bounds, r, tight)
            if found is None:
                continue
            x, q, s = found
        else:
            continue
        if not s < tol.singular:
            continue
        at = next((j for j in (k, lo_k, hi_k) if abs(xs[j] - x) <= tol.equal * max(1.0, abs(x))), None)
        if at == len(xs) - 1 and at > 0:
            continue  # the motion ends on it: not passed
        elif at is not None:
            before = at - 1
        elif k > 0 and (xs[k - 1] - x) * (xs[k] - x) < 0:
            before = k - 1
        elif k + 1 < len(xs) and (xs[k] - x) * (xs[k + 1] - x) < 0:
            before = k
        else:
            continue  # outside the recorded motion
        out.append(Crossing(x, np.asarray(q, float), s, before, at, rank=r))
    for lim in res.limits:  # a "limit position" where K loses rank is a change point
        s = _measure(mech, lim.q, r)
        if not s < tol.singular:
            continue
        before = _limit_index(xs, lim.input)
        x, q = float(lim.input), np.asarray(lim.q, float)
        # located as a limit (a double root: to about the square root of round-off), refined as a dip is
        half = max(0.5 * abs(xs[before] - x), tol.geometry)
        found = _least(solver, res, q, (x - half, x + half), r, tight)
        if found is not None and found[2] < s:
            x, q, s = found
        out.append(Crossing(x, np.asarray(q, float), s, before, None, True, rank=r))
    seen, unique = [], []
    for c in sorted(out, key=lambda c: c.before):
        if any(abs(c.x - d.x) <= tol.geometry * max(1.0, abs(c.x)) and abs(c.before - d.before) <= 1 for d in seen):
            continue
        seen.append(c)
        unique.append(c)
    return unique


def _may_reach_zero(m: np.ndarray, xs: np.ndarray, k: int) -> bool:
    """Whether the dip of the measure m at the recorded configuration k (not at an end) may reach zero
    between its neighbours: near a change point the smallest singular value is |linear| in the input
    (a V), so it is at most the steeper side's slope times the step there (twice that, for the
    curvature); a smooth minimum well above that is not looked at (a bounded minimization each)."""
    if k == 0 or k == len(m) - 1:
        return False
    slopes = [(m[j] - m[k]) / abs(xs[j] - xs[k]) for j in (k - 1, k + 1) if xs[j] != xs[k]]
    step = max(abs(xs[k + 1] - xs[k]), abs(xs[k] - xs[k - 1]))
    return bool(slopes) and m[k] <= 2 * max(slopes) * step


def _measure(mech: Mechanism, q: np.ndarray, rank: int) -> float:
    return float(constraint_profile(mech, [q], rank)[0][0])


def _again(solver, out: list, res, k: int, lo_k: int, hi_k: int, bounds: list) -> tuple | None:
    """(x, configuration, measure) of a change point already found (in ``out``) that this dip is another
    pass of (a motion through limit positions passes one point again and again): its input within the
    dip's bounds, its joint centres nearer the recorded configuration k than the neighbours are; else None."""
    sig = solver.signature
    reach = max(np.linalg.norm(sig(res.q[lo_k]) - sig(res.q[k])), np.linalg.norm(sig(res.q[hi_k]) - sig(res.q[k])))
    for c in out:
        if bounds[0] <= c.x <= bounds[1] and np.linalg.norm(sig(c.q) - sig(res.q[k])) <= reach:
            return c.x, c.q, c.sigma
    return None


def _least(solver, res, q: np.ndarray, bounds: list | tuple, rank: int, tight: Tolerances) -> tuple | None:
    """(x, configuration, measure) where the constraint measure is least for the input within bounds, the
    loops closed again from q at each value (bounded minimization, to the closure tolerance); None
    where they cannot be closed there."""
    from scipy.optimize import minimize_scalar

    mech = solver.mech
    q_at = reclosing(solver, res, q, tight)

    def sigma(x: float):
        try:
            return _measure(mech, q_at(x), rank)
        except AssemblyError:
            return np.inf

    x = float(minimize_scalar(sigma, bounds=tuple(bounds), method="bounded", options={"xatol": mech.tolerances.closure}).x)
    try:
        q = q_at(x)
    except AssemblyError:
        return None
    return x, q, _measure(mech, q, rank)


def _limit_index(xs: np.ndarray, x: float) -> int:
    """The index of the recorded configuration a located limit position comes after: the first place
    near it where the input turns back (or repeats a value: the grid value before a limit, recorded
    going and coming back), else the last configuration (a motion that stopped there)."""
    d = np.diff(xs)
    for k in range(len(d)):
        turns = d[k] == 0 or (k > 0 and d[k] * d[k - 1] < 0)
        if turns and abs(xs[k] - x) <= 2 * np.max(np.abs(d[max(k - 1, 0):k + 2])):
            return k
    return len(xs) - 1


def _branch_rates(mech: Mechanism, branch: Branch) -> np.ndarray:
    """A branch's tangent as joint rates (nv), in the order of the coordinates."""
    return np.array([branch.tangent.get(n, 0.0) for n in mech.coordinate_names], float)


def follow(curve: Curve, q: np.ndarray, x: float, rates: np.ndarray, x_to: float):
    """The configuration at input value x_to reached from the configuration q (input x) along the
    branch of tangent ``rates`` (joint rates): a first step of Tolerances.local_step along it (where
    the local analysis confirms its branches), then the continuation's steps (Neighbour) to x_to.
    None when the branch does not move the input, or a step fails."""
    tol = curve.tol
    t = np.asarray(rates, float) / curve.scale
    n = np.linalg.norm(t)
    if not n > 0:
        return None
    t = t / n
    if x_to == x:
        return q
    if abs(t[curve.ix]) < tol.limit_share:
        return None
    if t[curve.ix] * (x_to - x) < 0:
        t = -t
    x1 = x + tol.local_step * t[curve.ix] * curve.scale[curve.ix]
    if abs(x1 - x) >= abs(x_to - x):
        x1 = x_to
    try:
        q1 = curve.at_input(q, x, x1, t)
    except Stuck:
        return None
    if x1 == x_to:
        return q1
    return Neighbour(curve.solver, curve.name)(q1, x1, x_to)


def crossing(solver, curve: Curve, res, c: Crossing, switch: bool, prior=None) -> tuple:
    """At the change point c of the motion res: (ChangePoint, the followed branch's tangent as joint
    rates oriented along the motion or None, why-not text or None).  The incoming branch is the one
    whose line, followed back from c (``follow``), reaches nearest the configuration recorded before
    it; the followed one is it (``switch`` False) or the other; at the start of the motion, the branch
    nearest the input's direction projected on ker K -- unless ``prior`` (input value, configuration)
    gives where the motion came from before it (a chunk of a longer sweep)."""
    mech = solver.mech
    local = _local(solver, c)
    branches = [_branch_rates(mech, b) for b in local.branches]
    xs = np.asarray(res.values, float)
    direction = _arriving(xs, c, res.requested)
    # the branches the motion can take: the input moves along them, the other inputs stay held
    held = list(curve.frozen_other)
    moving = [k for k, v in enumerate(branches) if abs(v[curve.ix]) > curve.tol.limit_share * np.linalg.norm(v)
              and not np.any(np.abs(v[held]) > curve.tol.limit_share * np.linalg.norm(v))]
    came = None
    if (c.before >= 0 or prior is not None) and len(branches) > 1:
        b = c.before  # a recorded configuration the branches' lines tell apart (not next to c)
        while b > 0 and abs(xs[b] - c.x) < curve.tol.local_step * curve.scale[curve.ix] and \
                (xs[b] - xs[b - 1]) * direction > 0:
            b -= 1
        xa, qa = (float(xs[b]), res.q[b]) if b >= 0 else (float(prior[0]), np.asarray(prior[1], float))
        miss = [np.inf] * len(branches)
        seen = solver.signature(qa)  # (joint centres: the same whatever turn an angle is written on)
        for k, v in enumerate(branches):
            back = follow(curve, c.q, c.x, v, xa)
            if back is not None:
                miss[k] = float(np.linalg.norm(solver.signature(back) - seen))
        came = int(np.argmin(miss)) if np.isfinite(min(miss)) else nearest_branch(mech, local, res.rates[max(b, 0)])
    elif branches:
        came = 0 if c.before >= 0 or prior is not None else None
    why = None
    if c.before < 0 and prior is None and branches:  # the start: no incoming tangent
        came, why = _starting(solver, curve, local, branches, moving, c, direction)
    goes = came
    if switch:
        others = [k for k in moving if k != came]
        if others:
            goes = others[0]
        else:
            why = (why + "; " if why else "") + "the other branch does not move the input: the motion continues on this one"
    incoming = None if c.before < 0 and prior is None else came  # (at the start: none; came is the default there)
    if goes is None or goes not in moving:
        return ChangePoint(c.x, c.sigma, c.q, local, incoming, None, True), None, None
    v = branches[goes]
    if v[curve.ix] * direction < 0:
        v = -v
    return ChangePoint(c.x, c.sigma, c.q, local, incoming, goes, True, switched=goes != came), v, why


def _starting(solver, curve: Curve, local: LocalAnalysis, branches: list, moving: list, c: Crossing, direction: float) -> tuple:
    """(the branch a motion starting on the change point c takes, the rule in words): of the branches
    that move the input, the one the file's configuration lies on (followed from c to its input value,
    it reaches the drawing: solve's first mode is the one nearest the drawing); where none does (the
    file drawn on the change point itself, or elsewhere), the one nearest the input's own direction
    projected on ker K."""
    mech = solver.mech
    try:
        ref = mech.assemble().q
    except AssemblyError:
        ref = None
    if ref is not None and len(moving) > 1:
        x_ref = float(solver.joint_values(ref).get(curve.name, c.x))
        if curve.name in solver.angular_names():
            x_ref = c.x + float(wrap_angle(x_ref - c.x))
        if abs(x_ref - c.x) > curve.tol.local_step * curve.scale[curve.ix]:
            drawn = solver.signature(ref)
            on = [k for k in moving if _reaches(solver, curve, c, branches[k], x_ref, drawn)]
            if len(on) == 1:  # (the drawing on another change point lies on both branches: no answer)
                return on[0], f"{START}: taking the branch the file's configuration lies on"
    K = mech.closure.jacobian(c.q) * curve.scale  # ker K of the rank the local analysis found
    null = np.linalg.svd(K[:, curve.free])[2][local.rank:] if K.size else np.eye(len(curve.free))
    e = np.zeros(mech.nv)
    e[curve.free] = null.T @ (null @ curve.e[curve.free])
    came = nearest_branch(mech, local, e * curve.scale if np.linalg.norm(e) > 0 else curve.e)
    if came not in moving and moving:
        came = moving[0]
    return came, f"{START}: taking the branch nearest the input's own direction (projected on ker K)"


def _reaches(solver, curve: Curve, c: Crossing, rates: np.ndarray, x: float, drawn) -> bool:
    """Whether the branch of tangent ``rates`` at the change point c, followed to input value x, reaches the
    configuration whose signature (PositionSolver.signature) is ``drawn``."""
    q = follow(curve, c.q, c.x, rates, x)
    return q is not None and bool(np.linalg.norm(solver.signature(q) - drawn) <= solver.mech.tolerances.geometry
                                  * solver.mech.length)


#: How a change point at the start of a motion is said (analysis.motion.sweep's notes read it).
START = "the motion starts on it"


def _local(solver, c: Crossing) -> LocalAnalysis:
    """The local analysis at the change point c, kept in the mechanism's cache by its configuration (to
    Tolerances.geometry): a motion through limit positions (``turn``) passes the same point again and again."""
    mech = solver.mech
    key = ("crossing.local", tuple(solver.inputs), c.rank,
           tuple(np.round(np.asarray(c.q) / mech.tolerances.geometry).astype(np.int64)))
    if key not in mech.cache:
        mech.cache[key] = local_analysis(mech, c.q, inputs=solver.inputs, generic_rank=c.rank or None)
    return mech.cache[key]


def _arriving(xs: np.ndarray, c: Crossing, requested: tuple) -> float:
    """The sign of the input's motion at the change point c (+1 or -1)."""
    if c.before >= 0:
        d = c.x - xs[c.before]
        if d == 0 and c.before > 0:
            d = xs[c.before] - xs[c.before - 1]
    else:
        d = xs[1] - xs[0] if len(xs) > 1 else requested[1] - requested[0]
    return float(np.sign(d) or 1.0)


def _cos(a: np.ndarray, b: np.ndarray) -> float:
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    return float(a @ b / (na * nb)) if na > 0 and nb > 0 else 0.0
