"""Every isolated root of a square polynomial system, with a certificate: monodromy and the trace
test on its linear-offset family (analysis.position.certified builds the system from a mechanism).

The family.  A system G(x) = [g(x); r(x)] (k constraints, never moved -- a revolute's circle, a
quaternion's norm --, then n - k rows) is solved for every offset c: r(x) = c.  A start pair is free:
x0 random on the constraints, c0 = r(x0).  The family's solution set is the graph of r over the
constraint variety, irreducible, so moving c around loops permutes the roots at c0 transitively
(Duff, Hill, Jensen, Lee, Leykin, Sommars, IMA J. Numer. Anal. 2019): monodromy tracks every known
root around triangles c0 -> c1 -> c2 -> c0 through random complex offsets and keeps the new
endpoints.  Roots are kept one per orbit of the system's sign symmetries (model.homotopy.symmetry).

The settings are the ``homotopy_`` (and the tracker's ``track_``) fields of screwkin.tolerances.Tolerances.

The certificate.  The trace test (Leykin, Rodriguez, Sottile, Arnold Math. J. 4, 2018), in the form
of HomotopyContinuation.jl's verify_solution_completeness (del Campo and Rodriguez 2017): in (x, l),
    [g(x); r(x) - l v; (ell(x) - 1) l] = [0; c0; -t]
has at t = 0 the known roots (x, 0) and the points where ell(x) = 1 on the curve r(x) in c0 + C v
(found by the same monodromy, on [g; r - l v; ell] = [0; c0; 1]).  Tracked along t = 0 -> gamma/2 ->
gamma, the sum of the roots' coordinates is an affine function of t exactly when no root is missing.
ell and the coordinates summed are functions the symmetries leave alone (the group's features), so
each orbit counts |orbit| times.  The test passes when the trace matrix [T0 T1 T2; 1 1 1] has a
relative third singular value below ``homotopy_trace_tol``.

Then one parameter homotopy from c0 to the target offset carries every root there; by the theory
of coefficient-parameter homotopy (Morgan and Sommese 1989) the endpoints include every isolated
root of the target (paths may end at infinity, or at singular roots, which the Cauchy endgame
finds).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ...tolerances import DEFAULT, Tolerances
from . import tracking
from .symmetry import SignGroup

#: Features of points count as independent above this relative singular value (fitting ell).
_INDEPENDENT = 1e-8
#: Division guard: an offset's size is never taken below this (a base offset of zero).
_SMALLEST_SCALE = 1e-3
#: The trace test's damped Newton from random points moves at most this far in a step (largest coordinate).
_NEWTON_CAP = 0.5
#: The condition number of a path's endpoint Jacobian past which it is no regular root (the Cauchy endgame's).
_ILL_CONDITIONED = 1e10

Array = np.ndarray


class PointSource(Protocol):
    """Random points on the constraint variety (the circles, the unit quaternions)."""

    def random_points(self, rng: np.random.Generator, P: int) -> Array: ...


class Family(Protocol):
    """A square system G(x) = c in its offsets c (model.homotopy.square.SquareSystem,
    model.distances.SixDistances): ``n`` equations and tangent coordinates on points of ``width``
    coordinates."""

    n: int
    width: int

    def equations(self, X: Array, jacobian: bool = True) -> tuple[Array, Array | None]: ...

    def offsets(self, X: Array) -> Array: ...

    def retract(self, X: Array, dT: Array) -> Array: ...

    def on_variety(self, X: Array) -> Array: ...


class Closure(Family, Protocol):
    """A Family of a mechanism's closure: also the map from tangent coordinates to the points'
    (``tangent``) and random points on its variety (``closure.random_points``), which the trace test
    needs."""

    @property
    def closure(self) -> PointSource: ...

    def tangent(self, X: Array) -> Array: ...

__all__ = ["carry", "Roots", "all_roots", "to_target", "Endpoints"]


@dataclass
class Roots:
    """The roots (one per orbit) at the base offset c0, and how they were found."""

    X: np.ndarray
    c0: np.ndarray
    complete: bool
    trace: float | None  # the trace test's relative singular value (None: not run)
    why: str  # why not complete ("" when complete)
    rounds: int
    paths: int  # paths tracked in all
    failed: int  # of those, failed
    witnesses: int  # the trace test's extra roots (orbits)
    seconds: float
    group: SignGroup = field(repr=False)


class _Offsets:
    """A monodromy run on a system G(x) = [0; c]: the roots known at c0 and the loops made."""

    def __init__(self, system: Family, group: SignGroup, X: Array, c0: Array, rng: np.random.Generator,
                 tol: Tolerances) -> None:
        self.system, self.group, self.rng, self.o = system, group, rng, tol
        self.c0 = np.asarray(c0, complex)
        self.X = np.zeros((0, system.width), complex)
        self.loops: list[list] = []  # [c1, c2, how many of X have been around it]
        self.paths = self.failed = 0
        self.last_only = False
        self.add(np.atleast_2d(X))

    def roots(self, X: Array) -> Array:
        """Which points of X are roots at the base: the equations there within round-off of c0 and
        a Newton step from them within round-off of nothing (a path that strayed near infinity
        and ended on no root is not one)."""
        X = np.asarray(X, complex)
        ok = np.isfinite(X).all(axis=1)
        if not ok.any():
            return ok
        with np.errstate(all="ignore"):
            G, J = self.system.equations(X[ok])
            assert J is not None
            H = G - self.c0
            step = np.abs(tracking._solve(J, H[..., None])[..., 0]).max(axis=1)
        size = 1.0 + np.abs(X[ok]).max(axis=1)
        scale = 1.0 + np.abs(self.c0).max()
        good = ((np.abs(H).max(axis=1) <= self.o.homotopy_root * scale) & (step <= self.o.track_root_tol * size)
                & self.system.on_variety(X[ok]))
        ok[np.flatnonzero(ok)[~good]] = False
        return ok

    def add(self, X: Array) -> int:
        """Keep the roots of X not yet known (up to the group); returns how many were new."""
        new = 0
        X = np.atleast_2d(X)
        for x in X[self.roots(X)]:
            Y = self.X
            if self.group.match(x[None], Y, self.o.homotopy_same)[0] < 0:
                self.X = np.vstack([Y, x[None]])
                new += 1
        return new

    def _random_offset(self) -> Array:
        """A random complex offset, about ten times the base's size times a log-normal factor: large
        loops encircle many branch points, and mix the roots faster (measured on the 3-RPR's trace
        fibre: 24 of 24 found in 3 rounds, against 22 or 23 of 24 after 6 rounds with loops of the
        base's size)."""
        m = len(self.c0)
        scale = (max(float(np.sqrt(np.mean(np.abs(self.c0) ** 2))), _SMALLEST_SCALE) * self.o.homotopy_loop_scale
                 * np.exp(np.clip(self.rng.normal(), -1, 1)))
        out = scale * (self.rng.normal(size=m) + 1j * self.rng.normal(size=m)) / np.sqrt(2)
        if self.last_only:  # loops in the last offset alone (the trace test's t), the others at the base
            out[:-1] = self.c0[:-1]
        return out

    def round(self) -> int:
        """One round: a new loop (several while few roots are known) for every root, and the roots
        found in the last round around the older loops.  Returns the number of new roots."""
        for _ in range(max(self.o.homotopy_loops, min(6, 48 // max(len(self.X), 1)))):
            self.loops.append([self._random_offset(), self._random_offset(), 0])
        jobs = [(i, li) for li, (_, _, done) in enumerate(self.loops) for i in range(done, len(self.X))]
        for loop in self.loops:
            loop[2] = len(self.X)
        if not jobs:
            return 0
        idx = np.array([i for i, _ in jobs])
        C1 = np.array([self.loops[li][0] for _, li in jobs])
        C2 = np.array([self.loops[li][1] for _, li in jobs])
        C0 = np.broadcast_to(self.c0, C1.shape)
        X = self.X[idx]
        alive = np.ones(len(idx), bool)
        for a, b in ((C0, C1), (C1, C2), (C2, C0)):
            res = tracking.track(tracking.Segment(self.system, a[alive], b[alive]), X[alive],
                                 tol=self.o)
            self.paths += int(alive.sum())
            self.failed += int((~res.ok).sum())
            X[alive] = res.X
            alive[np.flatnonzero(alive)[~res.ok]] = False
        return self.add(X[alive])


class _WithLine:
    """[r(x) - l v; ell(x)] (last="ell") or [r(x) - l v; (ell(x) - 1) l] (last="product") in (x, l):
    the trace test's extra witnesses are the roots of the first at offset [c0; 1], its homotopy the
    second at offset [c0; -t]."""

    def __init__(self, system: Closure, v: Array, ell: _Ell, last: str) -> None:
        self.system, self.v, self.ell, self.last = system, v, ell, last
        self.n, self.width = system.n + 1, system.width + 1

    def equations(self, Y: Array, jacobian: bool = True) -> tuple[Array, Array | None]:
        X, lam = Y[:, :-1], Y[:, -1]
        G, J = self.system.equations(X, jacobian)
        G = G - lam[:, None] * self.v
        e, de = self.ell(X)
        if self.last == "ell":
            last, dx, dl = e, de, np.zeros(len(Y), complex)
        else:
            last, dx, dl = (e - 1.0) * lam, de * lam[:, None], e - 1.0
        P, n = len(Y), self.n
        Gout = np.empty((P, n), complex)  # (filled in place: no concatenation of temporaries)
        Gout[:, :-1] = G
        Gout[:, -1] = last
        if not jacobian:
            return Gout, None
        assert J is not None
        out = np.empty((P, n, n), complex)
        out[:, :-1, :-1] = J
        out[:, :-1, -1] = -self.v
        out[:, -1, :-1] = np.einsum("pi,pij->pj", dx, self.system.tangent(X))
        out[:, -1, -1] = dl
        return Gout, out

    def offsets(self, Y: Array) -> Array:
        return self.equations(Y, jacobian=False)[0]

    def retract(self, Y: Array, dT: Array) -> Array:
        out = np.empty(Y.shape, complex)
        out[:, :-1] = self.system.retract(Y[:, :-1], dT[:, :-1])
        out[:, -1] = Y[:, -1] + dT[:, -1]
        return out

    def on_variety(self, Y: Array) -> Array:
        return self.system.on_variety(Y[:, :-1])


class _Ell:
    """ell(x) = sum_k alpha_k f_k(x) over the group's features f (linear in the unknowns it never
    changes when there are any, else the products within its classes)."""

    def __init__(self, group: SignGroup, rng: np.random.Generator) -> None:
        pairs = [(int(i), -1) for i in np.flatnonzero(group.fixed)]
        if not pairs:
            pairs = [(int(i), int(c[0])) for c in group.classes for i in c]
        self.I = np.array([i for i, _ in pairs])
        self.J = np.array([j for _, j in pairs])
        self.alpha = (rng.normal(size=len(pairs)) + 1j * rng.normal(size=len(pairs))) / np.sqrt(2 * len(pairs))
        self.n = group.n

    def __call__(self, X: Array) -> tuple[Array, Array]:
        value = self.features(X) @ self.alpha
        if (self.J < 0).all():  # linear: the gradient is alpha on the unknowns it reads, at every point
            grad = np.zeros((1, self.n), complex)
            grad[0, self.I] = self.alpha
            return value, np.broadcast_to(grad, (len(X), self.n))
        grad = np.zeros((len(X), self.n), complex)
        for k, (i, j) in enumerate(zip(self.I, self.J)):
            if j < 0:
                grad[:, i] += self.alpha[k]
            else:
                grad[:, i] += self.alpha[k] * X[:, j]
                grad[:, j] += self.alpha[k] * X[:, i]
        return value, grad

    def features(self, X: Array) -> Array:
        lin = self.J < 0
        return np.where(lin, X[:, self.I], X[:, self.I] * X[:, np.where(lin, 0, self.J)])

    def fit(self, X: Array) -> Array:
        """alpha with ell = 1 at as many points of X as their features allow (kept in order while
        their features stay independent: the roots may lie on a hyperplane), the least-norm fit plus
        a random part that keeps it generic.  Returns the mask of the points fitted."""
        F = self.features(X)
        keep = np.zeros(len(X), bool)
        for i in range(len(X)):
            trial = keep.copy()
            trial[i] = True
            s = np.linalg.svd(F[trial], compute_uv=False)
            if s[-1] > _INDEPENDENT * s[0] and trial.sum() <= max(len(self.alpha) - 1, 1):
                keep = trial
        Fk = F[keep]
        pinv = np.linalg.pinv(Fk)
        self.alpha = pinv @ np.ones(len(Fk)) + (np.eye(len(self.alpha)) - pinv @ Fk) @ self.alpha
        return keep


def _extended(group: SignGroup) -> SignGroup:
    """The group acting on (x, l): l never changes."""
    return SignGroup(group.n + 1, np.c_[group.generators, np.ones(len(group.generators))])


class _TraceRun:
    """The trace test's system [r(x) - l v; (ell(x) - 1) l] = [c0; -t] and the roots of its fibre at
    t = 0: the known roots (x, 0) and the extra witnesses, ell(x) = 1.  The witnesses are started
    from known roots carried to c0 + v (l = 1) with ell fitted to 1 at them; monodromy on this
    system over all its offsets (c, t) -- its solution set is the graph of (x, l) too -- finds the
    rest, and any root of the main system still missing (l = 0)."""

    def __init__(self, main: _Offsets, system: Closure, rng: np.random.Generator, o: Tolerances) -> None:
        group, c0 = main.group, main.c0
        self.closure = system
        self.main, self.o, self.rng = main, o, rng
        m = len(c0)
        scale = max(float(np.sqrt(np.mean(np.abs(c0) ** 2))), _SMALLEST_SCALE)
        self.v = scale * (rng.normal(size=m) + 1j * rng.normal(size=m)) / np.sqrt(2)
        self.ell = _Ell(group, rng)
        count = max(1, min(len(main.X), len(self.ell.alpha), 24))
        res = tracking.track(tracking.Segment(system, np.broadcast_to(c0, (count, m)),
                                              np.broadcast_to(c0 + self.v, (count, m))), main.X[:count],
                             tol=o)
        main.paths += count
        main.failed += int((~res.ok).sum())
        seeds = res.X[res.ok]
        seeds = seeds[self.ell.fit(seeds)] if len(seeds) else seeds
        self.system = _WithLine(system, self.v, self.ell, "product")
        Y0 = np.vstack([np.c_[main.X, np.zeros(len(main.X))], np.c_[seeds, np.ones(len(seeds))]])
        self.run = _Offsets(self.system, _extended(group), Y0, np.r_[c0, 0.0], rng, o)

    def newton(self, starts: int, iterations: int = 40) -> int:
        """Damped Newton on the fibre at t = 0 from ``starts`` random points (x on the variety, l complex
        normal): a cheap supplement to the loops, whose mixing leaves some witnesses unvisited for
        long (the roots it reaches are checked like every other)."""
        X = self.closure.closure.random_points(self.rng, starts)
        lam = (self.rng.normal(size=starts) + 1j * self.rng.normal(size=starts)) * 2.0
        Y = np.c_[X, lam]
        base = np.r_[self.main.c0, 0.0]
        seg = tracking.Segment(self.system, base[None], base[None])
        with np.errstate(all="ignore"):
            end = tracking.newton(seg, Y, np.zeros(starts), np.zeros(starts, int), iterations,
                                  tracking.capped_newton_step(_NEWTON_CAP), tracking.every_finite_step)
        Y = end.X[end.kept]
        self.main.paths += starts
        added = self.run.add(Y)
        self.settle()
        return added

    def settle(self) -> None:
        """Count this run's paths in the main run's, and let the main roots it found (l = 0) join them."""
        self.main.paths += self.run.paths
        self.main.failed += self.run.failed
        self.run.paths = self.run.failed = 0
        on_main = np.abs(self.run.X[:, -1]) <= self.o.homotopy_same * (1.0 + np.abs(self.run.X).max(axis=1))
        self.main.add(self.run.X[on_main, :-1])

    @property
    def witnesses(self) -> int:
        return int(len(self.run.X) - len(self.main.X))

    def trace(self) -> float | None:
        """The relative third singular value of [T0 T1 T2; 1 1 1] over the whole fibre (main roots and
        witnesses) carried along t = 0 -> gamma / 2 -> gamma; None when a path failed or two met."""
        group, o, c0 = self.main.group, self.o, self.main.c0
        on_main = np.abs(self.run.X[:, -1]) <= o.homotopy_same * (1.0 + np.abs(self.run.X).max(axis=1))
        Y = np.vstack([np.c_[self.main.X, np.zeros(len(self.main.X))], self.run.X[~on_main]])
        weights = group.orbit_sizes(Y[:, :-1], o.homotopy_same)
        gamma = np.exp(2j * np.pi * self.rng.uniform()) * 0.5
        traces, prev = [], 0.0
        for t in (0.0, 0.5 * gamma, gamma):
            if t != 0.0:
                a = np.broadcast_to(np.r_[c0, -prev], (len(Y), len(c0) + 1))
                b = np.broadcast_to(np.r_[c0, -t], (len(Y), len(c0) + 1))
                res = tracking.track(tracking.Segment(self.system, a, b), Y, tol=o)
                self.main.paths += len(Y)
                if not res.ok.all():
                    self.main.failed += int((~res.ok).sum())
                    return None
                Y = res.X
                if _duplicates(Y, o.homotopy_same):
                    return None
            prev = t
            traces.append(weights @ np.c_[group.features(Y[:, :-1]), Y[:, -1]])
        M = np.vstack([np.array(traces).T, np.ones(3)])
        s = np.linalg.svd(M, compute_uv=False)
        return float(s[2] / s[0])


def _duplicates(Y: Array, tol: float) -> bool:
    """Whether two rows of Y coincide (a path jumped onto another)."""
    if len(Y) < 2:
        return False
    scale = tol * (1.0 + np.abs(Y).max())
    order = np.argsort(Y[:, 0].real)
    Ys = Y[order]
    for i in range(len(Ys) - 1):
        j = i + 1
        while j < len(Ys) and Ys[j, 0].real - Ys[i, 0].real <= scale:
            if np.abs(Ys[j] - Ys[i]).max() <= scale:
                return True
            j += 1
    return False


def all_roots(system: Closure, group: SignGroup, x0: Array, rng: np.random.Generator, tol: Tolerances = DEFAULT,
              seeds: Array | None = None, trace_test: bool = True, trace_limit: int | None = None,
              stop_at: int | None = None) -> Roots:
    """Every root (one per orbit of ``group``) of system.equations(x) = c0 with c0 = G(x0), by
    monodromy, certified by the trace test (see the module) -- or, with ``trace_test`` False, until
    ``patience`` rounds find no new root (a known root count then decides).  ``seeds``: more roots at
    c0.  The work is bounded by ``tol.homotopy_budget`` paths.  ``stop_at``: a known bound on the number of
    roots (orbits): the loops stop as soon as it is reached (no trace test is needed then).

    With the trace test, the main loops stop at the first round that finds nothing; the test's own
    loops (over its fibre, the main roots among it) go on a round at a time, the test tried after
    each, until it closes: a small system is certified after a round or two."""
    t0 = time.perf_counter()
    o = tol
    x0 = np.atleast_2d(np.asarray(x0, complex))
    c0 = system.offsets(x0)[0]
    main = _Offsets(system, group, x0, c0, rng, o)
    if seeds is not None and len(seeds):
        main.add(seeds)
    why, rnd, stale = "", 0, 0
    limit = trace_limit if trace_test and trace_limit is not None else None
    budget = o.homotopy_budget if trace_test else o.homotopy_count_budget
    for _rnd in range(1, o.homotopy_max_rounds + 1):  # the main loops
        stale = stale + 1 if main.round() == 0 else 0
        if stop_at is not None and len(main.X) >= stop_at:
            break
        if len(main.X) >= o.homotopy_max_roots or main.paths > budget:
            why = (f"more than {o.homotopy_max_roots} roots" if len(main.X) >= o.homotopy_max_roots else
                   f"the budget of {budget} paths") + ": the search stopped there"
            break
        if limit is not None and len(main.X) > limit:
            break  # no certificate can come of it: the roots found so far are all the search gives
        if stale >= (1 if trace_test else o.homotopy_patience):
            break
    else:
        why = f"no round without a new root in {o.homotopy_max_rounds} monodromy rounds"
    if why or not trace_test:
        why = why or f"the monodromy found no new root in {stale} rounds (no trace test asked)"
        return Roots(main.X, c0, False, None, why, rnd, main.paths, main.failed, 0, time.perf_counter() - t0, group)
    if limit is not None and len(main.X) > limit:
        why = (f"the trace test is not tried past {limit} roots, its extra witnesses too many to collect "
               f"({len(main.X)} roots here)")
        return Roots(main.X, c0, False, None, why, rnd, main.paths, main.failed, 0, time.perf_counter() - t0, group)
    run, trace, complete, tries, stale, newton_done, redrawn = None, None, False, 0, 0, False, 0
    while True:
        if run is None:
            run, stale, newton_done = _TraceRun(main, system, rng, o), 0, False
        run.run.last_only = not run.run.last_only  # loops in t alone mix the two parts of the fibre
        new = run.run.round()
        run.settle()
        trace = run.trace()
        tries += 1
        if trace is not None and trace < o.homotopy_trace_tol:
            complete = True
            break
        stale = stale + 1 if new == 0 else 0
        if stale >= o.homotopy_patience:
            if not newton_done:  # Newton from random points adds witnesses the loops leave unvisited
                newton_done, stale = True, 0
                run.newton(o.homotopy_newton_starts)
            elif redrawn < o.homotopy_redraws:
                # nothing new: the missing witness may lie near infinity, where neither loops nor Newton
                # reach it -- the next try draws another line v and slice ell
                run, redrawn = None, redrawn + 1
            else:
                why = (f"the trace test did not close (relative singular value {trace:.2g}) and its witnesses "
                       f"stopped growing, after {main.paths} paths" if trace is not None else
                       f"the trace test failed after {main.paths} paths")
                break
        if tries >= o.homotopy_tries * (o.homotopy_patience + 2) or main.paths > o.homotopy_budget:
            why = ("the trace test failed" if trace is None else
                   f"the trace test did not close (relative singular value {trace:.2g})") + \
                f" after {main.paths} paths"
            break
    return Roots(main.X, c0, complete, trace, "" if complete else why, rnd, main.paths, main.failed,
                 0 if run is None else run.witnesses, time.perf_counter() - t0, group)


@dataclass
class Endpoints:
    """The roots carried to the target: X (P, n) (finite endpoints refined), status per path:
    "regular", "singular" (Cauchy endgame: cycle number in ``cycles``), "infinity", "failed"."""

    X: np.ndarray
    status: np.ndarray
    cycles: np.ndarray
    paths: int


def to_target(system: Family, roots: Roots, target: Array, tol: Tolerances = DEFAULT) -> Endpoints:
    """Every root at c0 carried to the offset ``target`` by one parameter homotopy.  A path that does
    not arrive at a regular root (Newton settles, the Jacobian's condition number below 1e10) is
    tracked again to t = 1 - ``tol.track_endgame`` and finished by the Cauchy endgame: a finite endpoint (the
    mean of the loop closes the system) is singular, one that does not is at infinity."""
    P = len(roots.X)
    a = np.broadcast_to(roots.c0, (P, len(roots.c0)))
    b = np.broadcast_to(np.asarray(target, complex), a.shape)
    return carry(tracking.Segment(system, a, b), roots.X, tol)


def carry(seg: tracking.Homotopy, X0: Array, tol: Tolerances = DEFAULT, zone: float | None = None) -> Endpoints:
    """The roots X0 of ``seg`` at t = 0 carried to t = 1, finished as ``to_target`` says (any homotopy
    of the tracker's protocol: an offset segment, or one that moves the system's coefficients).
    ``zone``: a path the tracker lost before t = 1 - zone that the endgame would put at infinity is
    called failed instead -- the trouble it met lies inside the endgame's loop but away from its
    centre (another branch point), where Cauchy's formula does not hold."""
    P = len(X0)
    status = np.full(P, "regular", dtype=object)
    cycles = np.ones(P, int)
    radius = tol.track_endgame
    res = tracking.track(seg, X0, tol=tol)
    X = res.X.copy()
    status[res.status == tracking.DIVERGED] = "infinity"
    regular = res.ok.copy()
    if regular.any():
        _, J = seg.evaluate(X[regular], np.ones(int(regular.sum())), np.flatnonzero(regular))
        assert J is not None
        good = np.isfinite(J).reshape(len(J), -1).all(axis=1)
        cond = np.full(len(J), np.inf)
        if good.any():
            sv = np.linalg.svd(J[good], compute_uv=False)
            cond[good] = sv[:, 0] / np.maximum(sv[:, -1], 1e-300)
        regular[np.flatnonzero(regular)[cond > _ILL_CONDITIONED]] = False
    bad = np.flatnonzero(~regular & (res.status != tracking.DIVERGED))
    if bad.size:
        back = tracking.track(seg, X0[bad], bad, tol, t1=1.0 - radius)
        status[bad[~back.ok]] = "failed"
        idx = bad[back.ok]
        if idx.size:
            ends, cyc, ok = tracking.cauchy(seg, back.X[back.ok], idx, radius, tol=tol)
            X[idx], cycles[idx] = ends, cyc
            with np.errstate(all="ignore"):
                H, _ = seg.evaluate(ends, np.ones(len(idx)), idx, jacobian=False)
            size = 1.0 + np.abs(np.where(np.isfinite(ends), ends, 0)).max(axis=1)
            closes = np.abs(H).max(axis=1) <= tol.homotopy_cauchy * size
            status[idx[ok & closes]] = "singular"
            status[idx[ok & ~closes]] = "infinity"
            status[idx[~ok]] = "failed"
            if zone is not None:
                early = idx[res.T[idx] < 1.0 - zone]
                status[early[status[early] == "infinity"]] = "failed"
    return Endpoints(X, status, cycles, P)
