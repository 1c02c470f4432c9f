"""Motion along an input (sweeps): one assembly mode followed by continuation.

The solutions of the closure equations with the other inputs held form a curve
(one DOF; idle spins aside).  It is followed by predictor-corrector steps:

- while the input is a good parameter of the curve (its share of the tangent is
  large), each step goes to the next value of the input's grid: the previous
  solution moved along the tangent predicts it, the closure solver corrects it
  with the input held;
- where it is not (near a limit position, where the input stops and turns
  back), the joint with the largest share of the tangent is held instead
  (local parametrization), so the curve is followed through the turn.

The tangent is the projection of the input's direction onto the null space of
the constraint Jacobian (idle spins have no part in it), oriented continuously,
in dimensionless coordinates (lengths divided by the characteristic length).
A limit position lies where the input's component of the tangent changes sign;
it is located by Brent's method on the held joint's value, to the precision of
the closure solver (the input there is accurate to far better than 1e-9, since
it is extremal), and listed as an actuator singularity (``limit``).  Without
``turn`` the sweep stops there, as the physical mechanism would; with it the
sweep goes on along the other branch, the input running back, until the
mechanism returns to its start (the whole circuit), the input reaches the end
of the range, or the step budget is spent.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError, UsageError, quote, shorten
from ...model.geometry import wrap_angle
from ...model.linalg import null_space
from .batch_sweep import batch_closure, batched_motion, motion_rates
from ...model.planar_graph import plan
from .dyads import planar_sweep
from .position import outside_limits
from ..singularities.singular import measures, scaled_jacobians

__all__ = ["sweep_inputs", "SweepResult", "SweepSingularity", "sweep", "Neighbour", "continuation_steps", "CONTINUATION_ROUNDS", "MAX_TRACKED",
           "drawn_start"]

#: Continuation steps a sweep may take per configuration it records (a bound on its work: a motion that
#: bends too sharply for any step the corrector accepts stops, said so, instead of running on).
CONTINUATION_ROUNDS = 50
#: The most continuation steps the per-step tracker is asked for by a grid coarser than its longest step
#: (Tolerances.max_step): --from 0 --to 1e5rad in 2,000 steps is a million steps of 0.1 rad, hours of
#: work; 100,000 (what sweep --steps allows) take about half a minute on a four-bar.
MAX_TRACKED = 100_000


@dataclass(frozen=True)
class SweepSingularity:
    kind: str  # "serial" | "actuator" | "constraint"
    input: float  # input value, refined [rad or m]
    sigma: float  # relative smallest singular value there
    q: np.ndarray
    limit: bool = False  # a limit position: the motion along the input cannot go on past it


@dataclass(frozen=True)
class SweepResult:
    input: str
    values: np.ndarray  # input values reached [rad or m], in the order of the motion
    q: np.ndarray  # (steps, nq)
    joints: np.ndarray  # (steps, n coordinates) joint values, names in `names`
    rates: np.ndarray  # (steps, nv): rates for an input rate of `rate`
    accelerations: np.ndarray  # (steps, nv)
    names: tuple  # coordinate names (velocity coordinates)
    rate: float
    stopped_at: float | None  # input value where the motion stopped short of the range, None when complete
    stop_reason: str | None
    requested: tuple  # (from, to, steps)
    limits: tuple = ()  # SweepSingularity: the limit positions met (located)
    turn: bool = False  # whether the sweep passed through limit positions
    circuit_closed: bool = False  # the motion came back to its starting configuration
    unit: str = "rad"  # the input's unit: "rad" or "m"
    coupled: dict | None = None  # <mimic> joint -> its values along the sweep
    skipped: tuple = ()  # input values on the grid the motion passed but could not solve at (holes)
    method: str = "tracker"  # how it was computed: "closed form" (dyads), "tracker", "batched" (see notes)
    notes: tuple = ()  # one line each: what the computation chose or fell back to

    @property
    def completed(self) -> bool:
        """The whole range, every grid value on it: not stopped short, no hole."""
        return self.stopped_at is None and not self.skipped


class _Stuck(Exception):
    pass


class _Tracker:
    """The continuation along one input of a PositionSolver (see the module docstring)."""

    def __init__(self, solver, name):
        mech = self.mech = solver.mech
        self.solver, self.model, self.closure = solver, solver.model, mech.closure
        self.name = name
        self.tol = mech.tolerances
        self.ix = int(mech.velocity_indices([name])[0])
        others = [n for n in solver.inputs if n != name]
        self.frozen_other = tuple(int(i) for i in mech.velocity_indices(others))
        self.free = np.setdiff1d(np.arange(mech.nv), self.frozen_other)
        self.scale = np.where(mech.translational, mech.length, 1.0)  # scaled rate -> rate
        # joints that can be held: one-DOF coordinates (revolute, prismatic, continuous)
        self.holdable = np.zeros(mech.nv, bool)
        for c in mech.coordinates:
            if c.nv == 1:
                self.holdable[c.idx_v] = True
        self.holdable[list(self.frozen_other)] = False

    def tangent(self, q, previous=None):
        """Unit tangent of the curve at q in scaled coordinates (nv; zero on the held inputs),
        oriented like ``previous``: the input's direction projected onto the null space of K."""
        K = self.closure.jacobian(q)
        nv = self.mech.nv
        Ks = (K * self.scale)[:, self.free] if K.size else np.zeros((0, len(self.free)))
        N = null_space(Ks, self.tol, len(self.free))
        e = np.zeros(len(self.free))
        e[np.searchsorted(self.free, self.ix)] = 1.0
        t = N @ (N.T @ e)
        if np.linalg.norm(t) < 1e-7 and previous is not None:  # at a limit position itself
            t = N @ (N.T @ previous[self.free])
        n = np.linalg.norm(t)
        if n < 1e-300:
            raise _Stuck("the mechanism cannot move along this input here")
        out = np.zeros(nv)
        out[self.free] = t / n
        if previous is not None and out @ previous < 0:
            out = -out
        return out

    def hold(self, t):
        """The velocity index of the joint to hold for a step along t: the input when it has a
        large share of the tangent, else the one-DOF joint with the largest share."""
        scores = np.where(self.holdable, np.abs(t), -1.0)
        best = int(np.argmax(scores))
        return self.ix if abs(t[self.ix]) >= 0.5 * scores[best] else best

    def step(self, q, t, sigma, held):
        """Move sigma (scaled) along t, hold joint ``held`` there, close the loops again."""
        pred = pin.integrate(self.model, q, self.scale * t * sigma)
        try:
            a = self.closure.solve(pred, frozen=tuple(sorted(set(self.frozen_other) | {held})))
        except AssemblyError:
            raise _Stuck("the loops cannot be closed") from None
        jump = np.linalg.norm(pin.difference(self.model, pred, a.q) / self.scale)
        if jump > max(0.5 * abs(sigma), 1e-7):
            raise _Stuck("the correction jumps away from the curve")
        return a.q

    def at_input(self, q_from, x_from, x, t):
        """The configuration at input value x, predicted from q_from (input x_from) along t."""
        dx = (x - x_from) / self.scale[self.ix]
        if abs(t[self.ix]) < 1e-12:
            raise _Stuck("the input does not move here")
        return self.step(q_from, t, dx / t[self.ix], self.ix)

    def on_arc(self, qa, xa, qb, held, x):
        """The configuration at input value x on the arc from qa (input xa) to qb, followed with
        joint ``held`` as the parameter (the input changes monotonically along it: no limit
        position strictly between): Brent's method on the held joint's share of the way.  Near a
        limit position the tangent predictor of ``at_input`` overshoots the curve's bend; this
        does not.  Raises _Stuck when x is not between the ends."""
        delta = pin.difference(self.model, qa, qb)
        frozen = tuple(sorted(set(self.frozen_other) | {held}))
        xb = xa + self.input_change(qa, qb)
        if (x - xa) * (x - xb) > 0:
            raise _Stuck("the value is not on this arc")
        cache = {0.0: qa, 1.0: qb}

        def at(u):
            if u not in cache:
                try:
                    cache[u] = self.closure.solve(pin.integrate(self.model, qa, u * delta), frozen=frozen).q
                except AssemblyError:
                    raise _Stuck("the loops cannot be closed on the arc") from None
            return cache[u]

        def f(u):
            return xa + self.input_change(qa, at(u)) - x

        from scipy.optimize import brentq

        fa, fb = f(0.0), f(1.0)
        if fa == 0:
            return qa
        if fb == 0:
            return qb
        if np.sign(fa) == np.sign(fb):
            raise _Stuck("the value is not on this arc")
        u = brentq(f, 0.0, 1.0, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=100)
        # polish at the exact input value (the held joint then follows); where the loops cannot be closed
        # with the input held there, the value is a hole of the motion (sweep records it), not an error
        try:
            return self.closure.solve(self.solver.set_inputs(at(u), {self.name: x}), frozen=tuple(
                sorted(set(self.frozen_other) | {self.ix}))).q
        except AssemblyError:
            raise _Stuck("the loops cannot be closed at this input value") from None

    def input_change(self, q0, q1) -> float:
        return float(pin.difference(self.model, q0, q1)[self.ix])

    def limit(self, qa, ta, qb, held):
        """The limit position between qa and qb (the input's tangent component changes sign),
        with joint ``held`` as the parameter: (configuration, input offset from qa)."""
        delta = pin.difference(self.model, qa, qb)
        frozen = tuple(sorted(set(self.frozen_other) | {held}))
        cache = {}

        def at(s):
            if s not in cache:
                cache[s] = self.closure.solve(pin.integrate(self.model, qa, s * delta), frozen=frozen).q
            return cache[s]

        def f(s):
            return float(self.tangent(at(s), ta)[self.ix])

        from scipy.optimize import brentq

        fa, fb = float(ta[self.ix]), f(1.0)
        if fa == 0 or fb == 0 or np.sign(fa) == np.sign(fb):  # pragma: no cover - the caller saw a change
            s = 1.0
        else:
            s = brentq(f, 0.0, 1.0, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=100)
        q = at(s)
        return q, self.input_change(qa, q)


def continuation_steps(mech, name: str, dx: float) -> int:
    """How many steps a continuation takes to move input ``name`` by ``dx`` [rad or m]: steps of at most
    Tolerances.max_step (scaled: characteristic lengths for a sliding input), as the sweep takes them."""
    c = mech.coordinate(name)
    scale = mech.length if mech.translational[c.idx_v] else 1.0
    return int(np.ceil(abs(dx) / (mech.tolerances.max_step * scale)))


class Neighbour:
    """One continuation step along input ``name`` of a PositionSolver, from a configuration to
    a nearby input value on the same branch: the sweep's predictor along the curve's tangent,
    its corrector and its branch tests (a correction that jumps away from the curve, or a
    limit position between the two values, refuses the step).  Maps walk their grids with it."""

    def __init__(self, solver, name: str):
        self._tr = _Tracker(solver, name)

    def __call__(self, q, x_from: float, x_to: float):
        """The configuration at input value x_to on q's branch (q at x_from), or None."""
        tr = self._tr
        direction = np.sign(x_to - x_from)
        if direction == 0:
            return q
        pieces = continuation_steps(tr.mech, tr.name, x_to - x_from)
        try:
            t = tr.tangent(q)
            if t[tr.ix] * direction < 0:
                t = -t
            x = x_from
            for k in range(1, pieces + 1):
                x_next = x_to if k == pieces else x_from + (x_to - x_from) * k / pieces
                q = tr.at_input(q, x, x_next, t)
                t_next = tr.tangent(q, t)
                if t_next[tr.ix] * direction <= 0:
                    return None  # a limit position lies between the two values
                x, t = x_next, t_next
        except _Stuck:
            return None
        return q


def sweep_inputs(mech, name: str, fixed) -> list:
    """The input joints of a motion of ``name`` with the joints ``fixed`` names held (a sweep's, the
    dynamics'): the actuated ones when ``name`` is one of them, else ``name`` and the held ones."""
    if name in mech.actuated:
        return list(mech.actuated)
    return [name, *(n for n in fixed if n != name)]


def _drawn_regular(solver, values: dict):
    """The file's drawn configuration, when it is closed as drawn, at the input ``values``, within the
    joint limits, and regular by its own ranks for a mechanism the inputs determine by dyads (the plan of
    analysis.motion.dyads exists: its passive joints follow from the inputs, so the generic ranks of K
    and of its passive columns are both the number of passive coordinates); then it is, by
    solve's own order (physical, not singular, nearest the reference: itself, of the largest rank), the
    mode solve(values) puts first, found without the generic configurations' search.  None otherwise."""
    mech, tol = solver.mech, solver.mech.tolerances
    name = next(iter(values), None)
    if mech.generic_known or name is None or not mech.cuts:
        return None
    key = ("dyads.plan", tuple(solver.inputs), name)
    if key not in mech.cache:
        mech.cache[key] = plan(mech, solver.inputs, name)
    if isinstance(mech.cache[key], str):
        return None
    try:
        a = mech.assemble()
    except AssemblyError:
        return None
    if a.iterations or a.starts != 1:  # not closed as drawn
        return None
    drawn, angular = solver.joint_values(a.q), set(solver.angular_names())
    for n, v in values.items():
        d = drawn.get(n, np.inf) - v
        if not abs(wrap_angle(d) if n in angular else d) <= tol.equal:
            return None
    if outside_limits(mech, a.q):
        return None
    K = scaled_jacobians(mech, a.q).K
    n_p = len(solver.passive)
    s_K, s_p = (np.linalg.svd(M, compute_uv=False) for M in (K, K[:, solver.passive]))
    if len(s_p) < n_p or not (s_K[n_p - 1] >= tol.singular * s_K[0] and s_p[n_p - 1] >= tol.singular * s_p[0]):
        return None
    if len(s_K) > n_p and s_K[n_p] >= tol.singular * s_K[0]:  # more rank than the plan allows: not this case
        return None
    return a.q


def drawn_start(solver, values: dict):
    """The configuration the file is drawn in, when it is already at the input ``values`` and is the
    mode ``solver.solve(values)`` puts first (one the mechanism reaches, not singular: the nearest to
    the drawing of those), found without solve's search from random starts (a sweep from the drawn
    position: 1 ms, not 13 ms, for the Strider); None otherwise."""
    quick = _drawn_regular(solver, values)
    if quick is not None:
        return quick
    ref = solver.reference()
    if ref is None:
        return None
    drawn = solver.joint_values(ref)
    angular, tol = set(solver.angular_names()), solver.mech.tolerances
    for n, v in values.items():
        if n not in drawn:
            return None
        d = drawn[n] - v
        if abs(wrap_angle(d) if n in angular else d) > tol.equal:
            return None
    sol = solver.solve(values, near=drawn, starts=0).solutions[0]
    far = np.linalg.norm(solver.signature(sol.q) - solver.signature(ref))
    if not sol.physical or sol.singular or far > tol.geometry * solver.mech.length:
        return None
    return sol.q


#: A closed-form sweep the grid is too coarse for (a joint turns more than a quarter turn between two
#: values, so which turn it is on is ambiguous) is computed on a grid this many times finer and read at the
#: grid's values: the closed form costs little per value, the tracker it would fall back to much more.
REFINE = 8
ON_GRID = 1e-6  # a value within this fraction of a fine step of a fine grid value is on that grid


def _refined(f, start, h, k):
    """The closed-form sweep ``f`` of a grid k times finer (step h / k) at the values of the grid of step h
    (and its located limit position, off both grids); None for None."""
    if f is None:
        return None
    j = (np.asarray(f.values) - start) / (h / k)
    on_fine = np.abs(j - np.round(j)) < ON_GRID
    keep = ~on_fine | (np.round(j).astype(int) % k == 0)
    return replace(f, values=f.values[keep], q=f.q[keep], joints=f.joints[keep], rates=f.rates[keep],
                   accelerations=f.accelerations[keep])


def sweep(solver, name: str, start: float, stop: float, steps: int, fixed: dict | None = None,
          near: dict | None = None, rate: float = 1.0, progress=None, turn: bool = False,
          max_steps: int | None = None, q_start=None, closed_form: bool = True, batch: bool = True) -> SweepResult:
    """Follow one assembly mode while input ``name`` goes from start to stop in ``steps``
    steps of the input (see the module docstring).

    solver: a PositionSolver whose inputs include ``name``; the other inputs stay at ``fixed``.
    q_start: a configuration of the assembly mode to follow (a neighbour's, in a map or a
    study): the loops are closed from it at the first input value (raises AssemblyError when
    they cannot be); without it the mode is ``solver.solve``'s first at ``start`` (near ``near``).
    It may be a function giving that configuration, called once the arguments are checked.
    turn: pass through limit positions onto the other branch (the input then runs back);
    the sweep ends when the mechanism is back at its start, the input reaches ``stop``, or
    after ``max_steps`` recorded configurations (default 20 * steps + 100).
    closed_form: a planar mechanism made of dyads is solved at every grid value at once
    (screwkin.analysis.motion.dyads), the same result; False: always the tracker.
    batch: without turn, a mechanism the closed form does not cover is corrected a chunk of grid
    values at a time (screwkin.analysis.motion.batch_sweep), the tracker taking the chunks that
    fail (said in ``notes``); False: the per-step tracker.
    progress: a callable ``progress(done, total)`` told of the grid values reached as the tracker
    goes (present/progress.Progress draws it on a terminal); None: not told.
    """
    if steps < 1:
        raise UsageError("a sweep needs at least 1 step")
    if name not in solver.inputs:
        raise UsageError(f"{solver.mech.path}: {quote(name, 40)} is not one of the inputs ({', '.join(shorten(i, 40) for i in solver.inputs)})")
    fixed = dict(fixed or {})
    others = [n for n in solver.inputs if n != name]
    missing = [n for n in others if n not in fixed]
    if missing:
        raise UsageError(f"{solver.mech.path}: give values for the other inputs with --set: {', '.join(shorten(m, 40) for m in missing)}")
    mech = solver.mech
    tr = _Tracker(solver, name)
    max_steps = max_steps or 20 * steps + 100
    h = (stop - start) / steps
    if callable(q_start):  # chosen once the arguments are checked (a command's --mode K, said as it is chosen)
        q_start = q_start()
    if q_start is not None:
        q0 = solver.track({name: start, **fixed}, q_start).q
    else:
        q0 = drawn_start(solver, {name: start, **fixed}) if near is None else None
        if q0 is None:
            first = solver.solve({name: start, **fixed}, near=near, starts=8 if near is None else 0)
            q0 = first.solutions[0].q
    if closed_form:
        f = planar_sweep(solver, name, q0, start, stop, steps, rate, turn, max_steps)
        if f is None and not turn and steps * REFINE <= max_steps:
            f = _refined(planar_sweep(solver, name, q0, start, stop, steps * REFINE, rate, turn, max_steps * REFINE),
                         start, (stop - start) / steps, REFINE)
        if f is not None:
            limits = tuple(SweepSingularity("actuator", x, s, q, limit=True) for x, s, q in f.limits)
            return SweepResult(name, f.values, f.q, f.joints, f.rates, f.accelerations, tuple(mech.coordinate_names),
                               rate, f.stopped_at, f.stop_reason, (start, stop, steps), limits, turn,
                               f.circuit_closed, f.unit, method="closed form")
    unit = "m" if mech.translational[tr.ix] else "rad"
    X, Q = [start], [q0]
    limits = []
    stopped = reason = None
    closed = False
    direction = np.sign(h) or 1.0
    try:
        t = tr.tangent(q0)
    except _Stuck as exc:
        t, stopped, reason = None, start, str(exc)
    if t is not None and t[tr.ix] * direction < 0:
        t = -t
    # batched only on grids no coarser than the longest step the tracker takes (Tolerances.max_step): a
    # chunk corrected at once cannot take the shorter steps a coarse grid needs across a bend
    if batch and not turn and h != 0 and t is not None and abs(h) / tr.scale[tr.ix] <= mech.tolerances.max_step:
        b = batched_motion(solver, tr, q0, t, start, stop, steps, lambda qa, xa, xb, n: sweep(
            solver, name, xa, xb, n, fixed=fixed, rate=rate, q_start=qa, closed_form=False, batch=False), progress)
        if b is not None:
            X, Q, limits, stopped, reason, skipped, notes = b
            return _finish(solver, name, X, Q, rate, stopped, reason, (start, stop, steps), limits, False, False,
                           unit, skipped, "batched", notes)
    q, x = q0, float(start)

    def grid_between(xa, xb):
        """Grid values strictly after xa up to xb (inclusive) in the direction of motion, within the range."""
        if h == 0:
            return []
        lo_k = (xa - start) / h
        hi_k = (xb - start) / h
        ks = range(int(np.floor(lo_k + 1e-9)) + 1, int(np.floor(hi_k + 1e-9)) + 1) if hi_k > lo_k else \
            range(int(np.ceil(lo_k - 1e-9)) - 1, int(np.ceil(hi_k - 1e-9)) - 1, -1)
        return [start + j * h for j in ks]

    skipped = []  # grid values of the input the motion passed but could not be solved at

    def solved(g, first, arc):
        """The configuration at grid value g: ``first()`` (the tangent predictor), else the arc of
        the step it lies on (``arc``: (qa, xa, qb, held), near a limit position), else None."""
        try:
            return first()
        except _Stuck:
            pass
        if arc is not None:
            try:
                return tr.on_arc(*arc[:2], arc[2], arc[3], g)
            except _Stuck:
                pass
        return None

    def keep(g, qg):
        if qg is None:
            skipped.append(float(g))  # said in the result: never a hole in a motion marked complete
        else:
            X.append(g)
            Q.append(qg)

    def record(qa, xa, ta, qb, xb, tb=None, held=None):
        """Record the grid values between configurations qa (input xa) and qb (xb), with no limit
        position between them, each predicted from the nearer end (not from a limit position:
        there the input does not move, pass tb=None for such an end); where the predictor fails
        (the curve bends near a limit position) on the arc step's own parametrization (held)."""
        arc = (qa, xa, qb, held) if held is not None and held != tr.ix else None
        for g in grid_between(xa, xb):
            if forward() and (g - stop) * direction > 1e-12 * max(1.0, abs(stop)):
                break
            near_b = tb is not None and abs(g - xb) < abs(g - xa)
            keep(g, solved(g, (lambda g=g: tr.at_input(qb, xb, g, tb)) if near_b else
                           (lambda g=g: tr.at_input(qa, xa, g, ta)), arc))

    def record_back(q_lim, x_lim, qb, xb, tb, held=None):
        """After a limit position: the grid values between it and qb, predicted from qb."""
        arc = (q_lim, x_lim, qb, held) if held is not None and held != tr.ix else None
        for g in grid_between(x_lim, xb):
            keep(g, solved(g, lambda g=g: tr.at_input(qb, xb, g, tb), arc))

    def forward():
        return direction * np.sign(h) > 0

    def back_at_start():
        return (turn and forward() and len(X) > 2 and abs(X[-1] - start) < 1e-9 * max(1.0, abs(h))
                and np.linalg.norm(pin.difference(mech.model, Q[-1], q0) / tr.scale) < 1e-6)

    needed = continuation_steps(mech, name, stop - start)
    if needed > max(steps, MAX_TRACKED):
        raise UsageError(f"{solver.mech.path}: {quote(name, 40)} over this range takes {needed:,} continuation steps of at "
                         f"most {mech.tolerances.max_step:g} (rad or characteristic lengths) between {steps:,} grid "
                         f"values, more than the {MAX_TRACKED:,} a sweep tracks: give a smaller range")
    if h != 0 and t is not None:
        # the longest step taken (scaled): a grid step, at most Tolerances.max_step -- a coarse grid is
        # followed by shorter steps, so that no step jumps across a bend of the curve to another branch
        longest = min(abs(h) / tr.scale[tr.ix], mech.tolerances.max_step)
        sigma = longest
        rounds = 0
        while len(X) < max_steps:
            rounds += 1
            if rounds > CONTINUATION_ROUNDS * max_steps:  # a bound on the work, whatever the grid
                stopped, reason = x, (f"the continuation made no progress in {rounds - 1} steps (the motion bends "
                                      "too sharply for the steps it can take here)")
                break
            end_x = float(stop)
            if forward() and (end_x - x) * direction <= 1e-12 * max(1.0, abs(end_x)):
                break  # the input reached the end of the range
            held = tr.hold(t)
            if held == tr.ix:  # the input is a good parameter: go to its next grid value, or toward it
                nxt = grid_between(x, x + direction * abs(h) * 1.000001)
                target = nxt[0] if nxt else x + direction * abs(h)
                if forward() and (target - end_x) * direction > 0:
                    target = end_x
                reach = sigma * tr.scale[tr.ix]  # after a refused step, toward the grid value by shorter steps
                on_grid = abs(target - x) <= reach * (1 + mech.tolerances.equal)
                if not on_grid:
                    target = x + direction * reach
                try:
                    q_new = tr.at_input(q, x, target, t)
                    t_new = tr.tangent(q_new, t)
                    if t_new[tr.ix] * direction <= 0:
                        raise _Stuck("a limit position lies in this step")
                except _Stuck:
                    held = int(np.argmax(np.where(tr.holdable & (np.arange(mech.nv) != tr.ix), np.abs(t), -1)))
                    if not tr.holdable[held]:
                        stopped, reason = x, "the motion cannot go on along this input"
                        break
                    sigma = min(sigma, longest) * 0.5
                else:
                    if on_grid:
                        X.append(target)
                        Q.append(q_new)
                    q, x, t = q_new, target, t_new
                    sigma = min(sigma * 1.5, longest)
                    if back_at_start():
                        closed = True
                        break
                    continue
            # an arc step with a passive joint held
            try:
                q_new = tr.step(q, t, sigma, held)
                t_new = tr.tangent(q_new, t)
            except _Stuck as exc:
                sigma *= 0.5
                if sigma < 1e-10:
                    stopped, reason = x, f"the motion cannot be continued past this configuration ({exc})"
                    break
                continue
            x_new = x + tr.input_change(q, q_new)
            if t_new[tr.ix] * t[tr.ix] < 0:  # the input turned back between q and q_new: a limit position
                q_lim, dx = tr.limit(q, t, q_new, held)
                x_lim = x + dx
                record(q, x, t, q_lim, x_lim, held=held)
                sig = measures(mech, q_lim, solver.generic())["actuator"]
                limits.append(SweepSingularity("actuator", float(x_lim), float(sig), q_lim, limit=True))
                if not turn:
                    if forward() and (x_lim - stop) * direction >= 0:
                        break  # the limit lies at or past the end of the range: every value was reached
                    stopped = float(x_lim)
                    reason = ("limit position: the passive joints become undetermined (an actuator singularity); "
                              "the input cannot go further on this branch")
                    break
                direction = -direction
                record_back(q_lim, x_lim, q_new, x_new, t_new, held=held)
            else:
                record(q, x, t, q_new, x_new, t_new, held=held)
            q, x, t = q_new, x_new, t_new
            sigma = min(sigma * 1.5, longest)
            if back_at_start():
                closed = True
                break
            if progress is not None:
                progress(min(len(X), steps), steps)
        else:
            stopped, reason = x, f"the step budget ({max_steps} configurations) is spent"
    if turn and stopped is None and not closed and (stop - x) * np.sign(h) > 1e-9 * max(1.0, abs(stop)):
        stopped, reason = x, "the motion did not reach the end of the range"
    return _finish(solver, name, X, Q, rate, stopped, reason, (start, stop, steps), limits, turn, closed, unit,
                   skipped)


def _finish(solver, name, X, Q, rate, stopped, reason, requested, limits, turn, closed, unit, skipped,
            method="tracker", notes=()):
    """The SweepResult of the configurations Q at input values X: rates and accelerations at each."""
    mech = solver.mech
    rates_in = {n: 0.0 for n in solver.inputs}
    rates_in[name] = rate
    bc = batch_closure(mech) if method == "batched" else None
    if bc is not None:
        V, A = motion_rates(solver, bc, Q, rates_in)
    else:
        V, A = [], []
        for qk in Q:
            K = mech.closure.jacobian(qk)
            solve, _ = solver.passive_solver(K)
            qd = solver.rates(qk, K, rates_in, solve)
            V.append(qd)
            A.append(solver.accelerations(qk, K, qd, {}, solve))
    Qa = np.array(Q)
    coupled = None
    if mech.couplings:
        values = [mech.coupled_values(qq) for qq in Q]
        coupled = {c.joint: np.array([v[c.joint] for v in values]) for c in mech.couplings}
    return SweepResult(name, np.array(X), Qa, mech.joint_value_rows(Qa) if len(Qa) else np.array([]),
                       np.array(V), np.array(A), tuple(mech.coordinate_names), rate, stopped, reason,
                       requested, tuple(limits), turn, closed, unit, coupled, tuple(skipped), method, tuple(notes))


