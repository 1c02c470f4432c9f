"""Motion along an input (sweeps): one assembly mode followed by continuation.

``sweep`` is the façade of the one continuation (analysis.motion.continuation): it chooses the
assembly mode to follow (``drawn_start``, or solve's first), then the engine -- the closed form of a
planar mechanism made of dyads (analysis.motion.dyads), else without ``turn`` the batched corrector
(analysis.motion.batch_sweep) on grids no coarser than the longest continuation step, else the
per-step tracker (analysis.motion.tracker), which also takes what the batched one cannot -- and
returns what the engine reached as a SweepResult, with the rates and accelerations at each value.
Limit positions (the input stops and turns back) are located and listed as actuator singularities
(``limit``); without ``turn`` the sweep stops there, as the physical mechanism would; with it the
sweep goes on along the other branch until the mechanism returns to its start, the input reaches the
end of the range, or the step budget is spent.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from ...errors import AssemblyError, UsageError, quote, shorten
from ...model.geometry import wrap_angle
from .batch_sweep import batch_closure, batched_motion, motion_rates
from .continuation import Curve, Motion, Stuck, continuation_steps
from .crossing import START, crossing, follow, passed
from .dyads import cached_plan, planar_sweep
from ...model.limits import outside_limits
from .tracker import Tracker
from ..singular import scaled_jacobians
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from screwkin.model.mechanism import Mechanism
    from screwkin.analysis.motion.crossing import ChangePoint
    from collections.abc import Callable
    from screwkin.analysis.motion.crossing import Crossing
    from collections.abc import Sequence

__all__ = ["sweep_inputs", "SweepResult", "SweepSingularity", "sweep", "MAX_TRACKED", "drawn_start", "BRANCHES"]

CHANGE_NOTE = "change point at "  # how the note naming a change point passed begins

#: What a motion does at a change point: go on along the branch whose tangent continues the incoming one,
#: or along the other one (sweep's ``branch``; the commands' --branch).
BRANCHES = ("continue", "other")

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
    point: object = None  # analysis.motion.crossing.ChangePoint of a constraint singularity: what it is


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
    change_points: tuple = ()  # analysis.motion.crossing.ChangePoint of each change point passed

    @property
    def change_point_notes(self) -> tuple:
        """The notes that name the change points passed and the branch taken at each (one line each)."""
        return tuple(n for n in self.notes if n.startswith(CHANGE_NOTE))

    @property
    def completed(self) -> bool:
        """The whole range, every grid value on it: not stopped short, no hole."""
        return self.stopped_at is None and not self.skipped


def sweep_inputs(mech: Mechanism, name: str, fixed: dict) -> list:
    """The input joints of a motion of ``name`` with the joints ``fixed`` names held (a sweep's, the
    dynamics'): the actuated ones when ``name`` is one of them, else ``name`` and the held ones."""
    if name in mech.actuated:
        return list(mech.actuated)
    return [name, *(n for n in fixed if n != name)]


def _drawn_regular(solver, values: dict) -> np.ndarray | None:
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
    if isinstance(cached_plan(solver, name), str):
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


def drawn_start(solver, values: dict) -> np.ndarray | None:
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


def _refined(f: Callable[..., np.ndarray], start: float, h: float, k: int):
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
          near: dict | None = None, rate: float = 1.0, progress: Callable[[int, int], object] | None=None, turn: bool = False,
          max_steps: int | None = None, q_start: np.ndarray | Callable | None=None, closed_form: bool = True, batch: bool = True,
          branch: str = "continue", prior: tuple[float, np.ndarray] | None=None) -> SweepResult:
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
    branch: at a change point (branches of the configuration space cross) the motion goes on along
    the branch whose tangent continues the incoming one ("continue"), or along the other ("other");
    each is named in ``change_points`` and said in ``notes`` (``_through_change_points``).
    prior: (input value, configuration) the motion came from before ``start`` (a chunk of a longer
    sweep): a change point on ``start`` is passed as inside a motion, not chosen as at its start.
    """
    if branch not in BRANCHES:
        raise UsageError(f"branch: one of {', '.join(BRANCHES)}, got {quote(str(branch), 40)}")
    fixed = _other_inputs(solver, name, steps, fixed)
    max_steps = max_steps or 20 * steps + 100
    q0 = _start(solver, name, start, fixed, near, q_start)
    res = _engine(solver, name, q0, start, stop, steps, fixed, rate, progress, turn, max_steps, closed_form, batch)
    return _through_change_points(solver, res, fixed, progress, max_steps, closed_form, batch, branch, prior)


def _engine(solver, name: str, q0: np.ndarray, start: float, stop: float, steps: int, fixed: dict, rate: float, progress: Callable[[int, int], object] | None, turn: bool, max_steps: int, closed_form: bool, batch: bool) -> SweepResult:
    """The SweepResult of the engine that applies (see ``sweep``), started from q0."""
    curve, requested = Curve(solver, name), (start, stop, steps)
    if closed_form:
        f = _closed_form(solver, name, q0, start, stop, steps, rate, turn, max_steps)
        if f is not None:
            return f
    h = (stop - start) / steps
    t, why = _start_tangent(curve, q0, h)
    # batched only on grids no coarser than the longest step the tracker takes (Tolerances.max_step): a
    # chunk corrected at once cannot take the shorter steps a coarse grid needs across a bend
    if batch and not turn and h != 0 and t is not None and abs(h) / curve.scale[curve.ix] <= solver.mech.tolerances.max_step:
        b = batched_motion(solver, curve, q0, t, start, stop, steps, _fallback(solver, curve, fixed), progress)
        if b is not None:
            return _finish(solver, name, b, rate, requested, False, curve.unit, "batched")
    _trackable(solver.mech, name, start, stop, steps)
    if t is None:
        motion = Motion([start], [q0], stopped=start, reason=why)
    else:
        motion = Tracker(curve, q0, t, start, stop, steps, turn, max_steps, progress).run()
    return _finish(solver, name, motion, rate, requested, turn, curve.unit)


def _other_inputs(solver, name: str, steps: int, fixed: dict | None) -> dict:
    """The other inputs' values (a copy of ``fixed``), once the arguments are checked."""
    if steps < 1:
        raise UsageError("a sweep needs at least 1 step")
    if name not in solver.inputs:
        raise UsageError(f"{solver.mech.path}: {quote(name, 40)} is not one of the inputs ({', '.join(shorten(i, 40) for i in solver.inputs)})")
    fixed = dict(fixed or {})
    missing = [n for n in solver.inputs if n != name and n not in fixed]
    if missing:
        raise UsageError(f"{solver.mech.path}: give values for the other inputs with --set: {', '.join(shorten(m, 40) for m in missing)}")
    return fixed


def _start(solver, name: str, start: float, fixed: dict, near: dict | None, q_start: np.ndarray | Callable | None) -> np.ndarray:
    """The configuration the sweep starts from: q_start's mode closed at the first input value (q_start
    may be a function giving it, called now: a command's --mode K, said as it is chosen), else the
    drawing when it is solve's first mode there, else solve's first (near ``near``)."""
    if callable(q_start):
        q_start = q_start()
    if q_start is not None:
        return solver.track({name: start, **fixed}, q_start).q
    q0 = drawn_start(solver, {name: start, **fixed}) if near is None else None
    if q0 is None:
        q0 = solver.solve({name: start, **fixed}, near=near, starts=8 if near is None else 0).solutions[0].q
    return q0


def _closed_form(solver, name: str, q0: np.ndarray, start: float, stop: float, steps: int, rate: float, turn: bool, max_steps: int) -> SweepResult | None:
    """The SweepResult of the closed-form engine (analysis.motion.dyads; on a finer grid read at this
    one's values where this one is too coarse for it), or None where it does not apply."""
    f = planar_sweep(solver, name, q0, start, stop, steps, rate, turn, max_steps)
    if f is None and not turn and steps * REFINE <= max_steps:
        f = _refined(planar_sweep(solver, name, q0, start, stop, steps * REFINE, rate, turn, max_steps * REFINE),
                     start, (stop - start) / steps, REFINE)
    if f is None:
        return None
    limits = tuple(SweepSingularity("actuator", x, s, q, limit=True) for x, s, q in f.limits)
    return SweepResult(name, f.values, f.q, f.joints, f.rates, f.accelerations, tuple(solver.mech.coordinate_names),
                       rate, f.stopped_at, f.stop_reason, (start, stop, steps), limits, turn, f.circuit_closed, f.unit,
                       method="closed form")


def _fallback(solver, curve: Curve, fixed: dict) -> Callable:
    """The batched engine's fallback: the per-step tracker's Motion of n steps from qa (input xa) to xb,
    qa closed again at xa first (as a sweep started from it)."""

    def fallback(qa: np.ndarray, xa: float, xb: float, n: int):
        qa = solver.track({curve.name: xa, **fixed}, qa).q
        ta, why = _start_tangent(curve, qa, (xb - xa) / n)
        if ta is None:
            return Motion([xa], [qa], stopped=xa, reason=why)
        return Tracker(curve, qa, ta, xa, xb, n).run()

    return fallback


def _trackable(mech: Mechanism, name: str, start: float, stop: float, steps: int) -> None:
    """A range the per-step tracker takes more than MAX_TRACKED steps over (and more than its grid
    values) is a usage error naming the count."""
    needed = continuation_steps(mech, name, stop - start)
    if needed > max(steps, MAX_TRACKED):
        raise UsageError(f"{mech.path}: {quote(name, 40)} over this range takes {needed:,} continuation steps of at "
                         f"most {mech.tolerances.max_step:g} (rad or characteristic lengths) between {steps:,} grid "
                         f"values, more than the {MAX_TRACKED:,} a sweep tracks: give a smaller range")


def _start_tangent(curve: Curve, q0: np.ndarray, h: float) -> tuple:
    """(the tangent at q0 oriented along the grid step h, None) or (None, why the input cannot move)."""
    try:
        return curve.along(q0, h), None
    except Stuck as exc:
        return None, str(exc)


def _finish(solver, name: str, motion: Motion, rate: float, requested: tuple, turn: bool, unit: str, method: str="tracker") -> SweepResult:
    """The SweepResult of an engine's Motion: rates and accelerations at each configuration."""
    X, Q = motion.X, motion.Q
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
    limits = tuple(SweepSingularity("actuator", x, s, q, limit=True) for x, s, q in motion.limits)
    return SweepResult(name, np.array(X), Qa, mech.joint_value_rows(Qa) if len(Qa) else np.array([]),
                       np.array(V), np.array(A), tuple(mech.coordinate_names), rate, motion.stopped, motion.reason,
                       requested, limits, turn, motion.closed, unit, coupled, tuple(motion.skipped), method,
                       tuple(motion.notes))




def _through_change_points(solver, res: SweepResult, fixed: dict, progress: Callable[[int, int], object] | None, max_steps: int, closed_form: bool, batch: bool, branch: str, prior: tuple[float, np.ndarray] | None=None) -> SweepResult:
    """The motion res carried through the change points it meets (analysis.motion.crossing: passed,
    crossing, follow): at each, the branch chosen by the tangent cone (``branch``), followed from the
    change point to the grid values after it; where the engine's own result is not that branch (it
    slipped onto the other, or stopped or turned back there as at a limit position) the motion is cut
    there and the sweep goes on from the branch's configuration at the next grid value (with ``turn``,
    until it is back there: the whole circuit from the change point on).  A change point met with the
    input running back (after a limit position, with ``turn``) is named, the engine's motion kept.
    Each change point is named in ``change_points`` and in ``notes``."""
    name = res.input
    start, stop, steps = res.requested
    h = (stop - start) / steps if steps else 0.0
    if not solver.mech.cuts or h == 0 or len(res.values) < 1:
        return res
    curve = Curve(solver, name)
    tol, ix = solver.mech.tolerances, curve.ix
    named, notes = [], []
    for c in passed(solver, res):
        if abs(c.x - stop) <= tol.geometry * max(1.0, abs(h)):  # the motion ends on it
            if not c.limit:
                continue
            # an engine stopped on it as at a limit position: the range's last value is the change point
            try:
                q_end = solver.mech.closure.solve(solver.set_inputs(c.q, {name: stop}), frozen=curve.frozen(ix)).q
            except AssemblyError:
                q_end = c.q
            end = _finish(solver, name, Motion([stop], [q_end]), res.rate, res.requested, res.turn, res.unit)
            return replace(_joined(solver, res, _slice(res, c.before + 1), end, None, (), (), c),
                           change_points=res.change_points + tuple(named), notes=_once(res.notes + tuple(notes)))
        cp, v, why = crossing(solver, curve, res, c, branch == "other", prior if c.before < 0 else None)
        named.append(cp)
        notes.append(_change_point_note(solver, name, res.unit, cp, why, branch))
        if len(cp.local.branches) < 2 and not c.limit:  # not a crossing of branches: the engine went on along its one
            named.pop()
            notes.pop()
            continue
        if v is None or v[ix] * np.sign(h) < 0:  # not drivable through, or met running back (turn)
            if v is not None:
                notes[-1] += "; met with the input running back: the motion is the engine's"
            continue
        # the grid values on and after the change point, in the direction of the motion, on the branch followed
        j = int(np.floor((c.x - start) / h + GRID_ON))
        on = abs(start + j * h - c.x) <= tol.geometry * max(1.0, abs(h))
        j = j if on else j + 1
        X, Q, q_next = [], [], None
        while j <= steps:
            x = start + j * h
            q = follow(curve, c.q, c.x, v, x)
            if q is None:
                break
            if abs(x - c.x) >= tol.local_step * curve.scale[ix]:
                q_next = (j, x, q)
                break
            X.append(x)
            Q.append(q)
            j += 1
        if q_next is None and j <= steps:  # the branch cannot be followed: the engine's motion stands
            notes[-1] += "; the branch could not be followed from it: the motion is the engine's"
            continue
        # where the engine's own result is that branch, it stands
        k0 = c.before + 1
        after = list(zip(X, Q)) + ([q_next[1:]] if q_next is not None else [])
        if not c.limit and _engine_took(solver, curve, res, k0, after, h):
            continue
        head = _slice(res, k0)
        middle = _finish(solver, name, Motion(X, Q), res.rate, res.requested, res.turn, res.unit) if X else None
        if middle is not None and on:
            middle.rates[0] = v / v[ix] * res.rate  # at the change point: the followed branch's tangent
        tail = None
        if q_next is not None:
            j_n, x_n, q_n = q_next
            tail = sweep(solver, name, x_n, stop, steps - j_n, fixed=fixed, rate=res.rate, progress=progress,
                         turn=res.turn, max_steps=max(max_steps - len(head.values) - len(X), 1), q_start=q_n,
                         closed_form=closed_form, batch=batch, branch=branch)
        return _joined(solver, res, head, middle, tail, named, notes, c)
    if not named:
        return res
    return replace(res, change_points=res.change_points + tuple(named), notes=_once(res.notes + tuple(notes)))


def _once(notes: tuple) -> tuple:
    """The notes, each said once (a motion through limit positions passes one change point again and again)."""
    return tuple(dict.fromkeys(notes))


def _engine_took(solver, curve: Curve, res: SweepResult, k0: int, after: list, h: float) -> bool:
    """Whether the engine's recorded configurations from index k0 are ``after`` ((input value,
    configuration) each, the branch followed), the input running the way of h."""
    tol = solver.mech.tolerances
    for i, (x, q) in enumerate(after):
        k = k0 + i
        if k >= len(res.values) or abs(res.values[k] - x) > tol.equal * max(1.0, abs(h)):
            return False
        if k > 0 and (res.values[k] - res.values[k - 1]) * h <= 0:
            return False
        if np.linalg.norm(pin.difference(solver.mech.model, res.q[k], q) / curve.scale) > tol.geometry and \
                np.linalg.norm(solver.signature(res.q[k]) - solver.signature(q)) > tol.geometry * solver.mech.length:
            return False  # (the joint centres apart: not an angle written a turn away)
    return True


GRID_ON = 1e-9  # a value this fraction of a grid step short of a grid index counts as on it


def _change_point_note(solver, name: str, unit: str, cp: ChangePoint, why: str | None, branch: str) -> str:
    """change point at crank = 180 deg: two branches cross; continuing on ... (the other: --branch other)."""
    # (located where the constraint measure is least: to about the square root of the closure's round-off)
    at = f"{cp.input:.7g} m" if unit == "m" else f"{cp.input:.7g} rad ({np.degrees(cp.input):.6g} deg)"
    n = len(cp.local.branches)
    what = f"{_WORDS.get(n, str(n))} branches cross" if n > 1 else \
        f"the loops' Jacobian loses rank (local analysis: {cp.local.kind})"
    if cp.goes is not None and why and why.startswith(START):
        how = why.split("; ")[0] + ("; taking the other one instead, as --branch other asks" if cp.switched else "")
        why = "; ".join(why.split("; ")[1:]) or None
    elif cp.goes is None:
        how = ("no branch through it moves the input with the other inputs held" if n else
               "the local analysis finds no branch through it")
        how += ": the motion is the engine's"
    elif cp.switched:
        how = "continuing on the other branch, as --branch other asks (the default continues the motion's tangent)"
    else:
        how = "continuing on the branch whose tangent continues the motion"
    other = " (the other: --branch other)" if branch == "continue" and n > 1 and cp.goes is not None else ""
    return f"{CHANGE_NOTE}{name} = {at}: {what}; {how}{other}" + (f"; {why}" if why else "")


_WORDS = {2: "two", 3: "three", 4: "four"}


def _slice(res: SweepResult, n: int):
    """The first n configurations of res (n >= 0), its limits before them."""
    xs = res.values[:n]
    lim = tuple(s for s in res.limits if n and _between(s.input, res.values[0], res.values[n - 1]))
    coupled = None if res.coupled is None else {k: v[:n] for k, v in res.coupled.items()}
    return replace(res, values=xs, q=res.q[:n], joints=res.joints[:n], rates=res.rates[:n],
                   accelerations=res.accelerations[:n], limits=lim, coupled=coupled,
                   skipped=tuple(x for x in res.skipped if n and _between(x, res.values[0], res.values[n - 1])))


def _between(x: float, a: float, b: float) -> bool:
    return min(a, b) <= x <= max(a, b)


def _joined(solver, res: SweepResult, head: SweepResult, middle: SweepResult | None, tail: SweepResult, named: Sequence, notes: Sequence, c: Crossing):
    """head + middle + tail (SweepResults; middle or tail may be None): one motion."""
    parts = [p for p in (head, middle, tail) if p is not None and len(p.values)]
    cat = (lambda f: np.concatenate([getattr(p, f) for p in parts])) if parts else (lambda f: getattr(head, f))
    last = tail if tail is not None else (middle or head)
    coupled = None
    if res.coupled is not None:
        coupled = {k: np.concatenate([p.coupled[k] for p in parts if p.coupled is not None]) for k in res.coupled}
    methods = [] if tail is None or tail.method == head.method else [
        f"from {res.input} = {tail.values[0]:.9g} on (after the change point) the motion is computed by: {tail.method}"]
    stopped, reason = (last.stopped_at, last.stop_reason) if tail is not None else (None, None)
    if tail is None and middle is not None and len(middle.values) and \
            abs(middle.values[-1] - res.requested[1]) > solver.mech.tolerances.equal * max(1.0, abs(res.requested[1])):
        stopped, reason = float(middle.values[-1]), "the branch could not be followed further"
    return replace(res, values=cat("values"), q=np.vstack([p.q for p in parts]), joints=np.vstack([p.joints for p in parts]),
                   rates=np.vstack([p.rates for p in parts]), accelerations=np.vstack([p.accelerations for p in parts]),
                   stopped_at=stopped, stop_reason=reason,
                   limits=head.limits + (tail.limits if tail is not None else ()),
                   circuit_closed=bool(tail is not None and tail.circuit_closed), coupled=coupled,
                   skipped=head.skipped + (tail.skipped if tail is not None else ()),
                   notes=_once(head.notes + tuple(methods) + tuple(notes) + (tail.notes if tail is not None else ())),
                   change_points=head.change_points + tuple(named) + (tail.change_points if tail is not None else ()))
