"""The per-step tracker: a continuation engine that follows the curve one step at a time.

Its steps go through a ``Curve`` (analysis.motion.continuation: the shared tangent, jump test,
branch rule and limit location):

- while the input is a good parameter of the curve (its share of the tangent is large), each step
  goes to the next value of the input's grid: the previous solution moved along the tangent predicts
  it, the closure solver corrects it with the input held;
- where it is not (near a limit position, where the input stops and turns back), the joint with the
  largest share of the tangent is held instead (local parametrization), so the curve is followed
  through the turn.

A limit position lies where the input's component of the tangent changes sign; it is located by
Brent's method on the held joint's value, to the precision of the closure solver (the input there is
accurate to far better than 1e-9, since it is extremal).  Without ``turn`` the motion stops there, as
the physical mechanism would; with it the motion goes on along the other branch, the input running
back, until the mechanism returns to its start (the whole circuit), the input reaches the end of the
range, or the step budget is spent.
"""

from __future__ import annotations

import numpy as np

from .continuation import CHANGE_REASON, LIMIT_REASON, Motion, Stuck, at_change_point, passes_limit, returned
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

__all__ = ["Tracker", "CONTINUATION_ROUNDS"]

#: Continuation steps a sweep may take per configuration it records (a bound on its work: a motion that
#: bends too sharply for any step the corrector accepts stops, said so, instead of running on).
CONTINUATION_ROUNDS = 50
GRID_SLACK = 1e-9  # a value this fraction of a grid step short of a grid index counts as on it


class Tracker:
    """One motion of ``curve`` from q0 (input ``start``, oriented tangent t) over the grid of ``steps``
    steps to ``stop``; ``run`` returns the Motion.  The state of the walk is its attributes."""

    def __init__(self, curve, q0: np.ndarray, t: np.ndarray, start: float, stop: float, steps: int, turn: bool=False, max_steps: int | None = None, progress=None) -> None:
        self.c, self.q0, self.start, self.stop, self.steps = curve, q0, float(start), float(stop), steps
        self.turn, self.progress = turn, progress
        self.max_steps = max_steps or 20 * steps + 100
        self.h = (stop - start) / steps
        self.direction = np.sign(self.h) or 1.0
        self.m = Motion([start], [q0])
        self.q, self.x, self.t = q0, float(start), t

    # -- the grid ------------------------------------------------------------------------------------
    def forward(self) -> bool:
        """The input runs the way of the range (not back after a limit position)."""
        return self.direction * np.sign(self.h) > 0

    def grid_between(self, xa: float, xb: float) -> list:
        """Grid values strictly after xa up to xb (inclusive) in the direction of motion, within the range."""
        h, start = self.h, self.start
        if h == 0:
            return []
        lo_k, hi_k = (xa - start) / h, (xb - start) / h
        ks = range(int(np.floor(lo_k + GRID_SLACK)) + 1, int(np.floor(hi_k + GRID_SLACK)) + 1) if hi_k > lo_k else \
            range(int(np.ceil(lo_k - GRID_SLACK)) - 1, int(np.ceil(hi_k - GRID_SLACK)) - 1, -1)
        return [start + j * h for j in ks]

    def past_end(self, x: float) -> bool:
        """x lies past the end of the range (going forward), beyond round-off."""
        return self.forward() and (x - self.stop) * self.direction > self.c.tol.zero * max(1.0, abs(self.stop))

    # -- recording grid values -------------------------------------------------------------------------
    def solved(self, g: float, first: Callable, arc: tuple):
        """The configuration at grid value g: ``first()`` (the tangent predictor), else the arc of
        the step it lies on (``arc``: (qa, xa, qb, held), near a limit position), else None."""
        try:
            return first()
        except Stuck:
            pass
        if arc is not None:
            try:
                return self.c.on_arc(*arc, g)
            except Stuck:
                pass
        return None

    def keep(self, g: float, qg: np.ndarray) -> None:
        if qg is None:
            self.m.skipped.append(float(g))  # said in the result: never a hole in a motion marked complete
        else:
            self.m.X.append(g)
            self.m.Q.append(qg)

    def arc(self, qa: np.ndarray, xa: float, qb: np.ndarray, held: int) -> tuple | None:
        return (qa, xa, qb, held) if held is not None and held != self.c.ix else None

    def record(self, qa: np.ndarray, xa: float, ta: np.ndarray, qb: np.ndarray, xb: float, tb: np.ndarray | None=None, held: int | None=None) -> None:
        """Record the grid values between configurations qa (input xa) and qb (xb), with no limit
        position between them, each predicted from the nearer end (not from a limit position:
        there the input does not move, pass tb=None for such an end); where the predictor fails
        (the curve bends near a limit position) on the arc step's own parametrization (held)."""
        c, arc = self.c, self.arc(qa, xa, qb, held)
        for g in self.grid_between(xa, xb):
            if self.past_end(g):
                break
            near_b = tb is not None and abs(g - xb) < abs(g - xa)
            self.keep(g, self.solved(g, (lambda g=g: c.at_input(qb, xb, g, tb)) if near_b else
                                     (lambda g=g: c.at_input(qa, xa, g, ta)), arc))

    def record_back(self, q_lim: np.ndarray, x_lim: float, qb: np.ndarray, xb: float, tb: np.ndarray, held: int | None=None) -> None:
        """After a limit position: the grid values between it and qb, predicted from qb."""
        arc = self.arc(q_lim, x_lim, qb, held)
        for g in self.grid_between(x_lim, xb):
            self.keep(g, self.solved(g, lambda g=g: self.c.at_input(qb, xb, g, tb), arc))

    def back_at_start(self) -> bool:
        m = self.m
        return (self.turn and self.forward() and len(m.X) > 2
                and returned(self.c.mech, m.X[-1], self.start, self.h, m.Q[-1], self.q0, self.c.scale))

    # -- the walk --------------------------------------------------------------------------------------
    def run(self) -> Motion:
        c, m = self.c, self.m
        if self.h == 0 or self.t is None:
            return self._end()
        # the longest step taken (scaled): a grid step, at most Tolerances.max_step -- a coarse grid is
        # followed by shorter steps, so that no step jumps across a bend of the curve to another branch
        self.longest = min(abs(self.h) / c.scale[c.ix], c.tol.max_step)
        self.sigma = self.longest
        rounds = 0
        while len(m.X) < self.max_steps:
            rounds += 1
            if rounds > CONTINUATION_ROUNDS * self.max_steps:  # a bound on the work, whatever the grid
                m.stopped, m.reason = self.x, (f"the continuation made no progress in {rounds - 1} steps (the motion "
                                               "bends too sharply for the steps it can take here)")
                break
            if self.forward() and (self.stop - self.x) * self.direction <= c.tol.zero * max(1.0, abs(self.stop)):
                break  # the input reached the end of the range
            held = c.hold(self.t)
            if held == c.ix:
                held = self.input_step()
                if held is None:
                    if self.back_at_start():
                        m.closed = True
                        break
                    if self.progress is not None:
                        self.progress(min(len(m.X), self.steps), self.steps)
                    continue
                if held is False:
                    break
            done = self.arc_step(held)
            if done:
                break
            if done is None:  # refused: tried again with a shorter step
                continue
            if self.progress is not None:
                self.progress(min(len(m.X), self.steps), self.steps)
        else:
            m.stopped, m.reason = self.x, f"the step budget ({self.max_steps} configurations) is spent"
        return self._end()

    def _end(self) -> Motion:
        m = self.m
        if self.turn and m.stopped is None and not m.closed and \
                (self.stop - self.x) * np.sign(self.h) > self.c.tol.equal * max(1.0, abs(self.stop)):
            m.stopped, m.reason = self.x, "the motion did not reach the end of the range"
        return m

    def input_step(self) -> bool | int | None:
        """A step with the input held, to its next grid value or toward it: None when taken; else the
        joint to hold for an arc step instead (a limit position lies in this step, or the step was
        refused), or False when none can be held (the motion stops, said so)."""
        c, m, direction = self.c, self.m, self.direction
        end_x = self.stop
        nxt = self.grid_between(self.x, self.x + direction * abs(self.h) * 1.000001)
        target = nxt[0] if nxt else self.x + direction * abs(self.h)
        if self.forward() and (target - end_x) * direction > 0:
            target = end_x
        reach = self.sigma * c.scale[c.ix]  # after a refused step, toward the grid value by shorter steps
        on_grid = abs(target - self.x) <= reach * (1 + c.tol.equal)
        if not on_grid:
            target = self.x + direction * reach
        try:
            q_new = c.at_input(self.q, self.x, target, self.t)
            t_new = c.tangent(q_new, self.t)
            if passes_limit(self.t, t_new, c.ix):
                raise Stuck("a limit position lies in this step")
        except Stuck:
            held = int(np.argmax(np.where(c.holdable & (np.arange(c.mech.nv) != c.ix), np.abs(self.t), -1)))
            if not c.holdable[held]:
                m.stopped, m.reason = self.x, "the motion cannot go on along this input"
                return False
            self.sigma = min(self.sigma, self.longest) * 0.5
            return held
        if on_grid:
            m.X.append(target)
            m.Q.append(q_new)
        self.q, self.x, self.t = q_new, target, t_new
        self.sigma = min(self.sigma * 1.5, self.longest)
        return None

    def arc_step(self, held: int) -> bool | None:
        """A step with the passive joint ``held`` held (a limit position located and passed on the way):
        True when the motion ends here, False when it goes on, None when the step was refused (the
        next one shorter)."""
        c, m = self.c, self.m
        q, x, t = self.q, self.x, self.t
        try:
            q_new = c.step(q, t, self.sigma, held)
            t_new = c.tangent(q_new, t)
        except Stuck as exc:
            self.sigma *= 0.5
            if self.sigma < c.tol.min_step:
                m.stopped, m.reason = x, f"the motion cannot be continued past this configuration ({exc})"
                return True
            return None
        x_new = x + c.input_change(q, q_new)
        if passes_limit(t, t_new, c.ix):  # the input turned back between q and q_new: a limit position
            q_lim, dx = c.locate_limit(q, t, q_new, held)
            x_lim = x + dx
            self.record(q, x, t, q_lim, x_lim, held=held)
            ms = at_change_point(c.solver, q_lim)
            m.limits.append((float(x_lim), float(ms["actuator"]), q_lim))
            if ms["change"]:  # not a limit: a change point, which sweep carries the motion through
                if not (self.forward() and (x_lim - self.stop) * self.direction >= 0):
                    m.stopped, m.reason = float(x_lim), CHANGE_REASON
                return True
            if not self.turn:
                if self.forward() and (x_lim - self.stop) * self.direction >= 0:
                    return True  # the limit lies at or past the end of the range: every value was reached
                m.stopped, m.reason = float(x_lim), LIMIT_REASON
                return True
            self.direction = -self.direction
            self.record_back(q_lim, x_lim, q_new, x_new, t_new, held=held)
        else:
            self.record(q, x, t, q_new, x_new, t_new, held=held)
        self.q, self.x, self.t = q_new, x_new, t_new
        self.sigma = min(self.sigma * 1.5, self.longest)
        if self.back_at_start():
            m.closed = True
            return True
        return False
