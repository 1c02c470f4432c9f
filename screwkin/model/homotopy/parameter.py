"""The coefficient-parameter homotopy of a Stewart-Gough platform from a generic solution set kept per
architecture (Morgan and Sommese 1989; Sommese and Wampler 2005, ch. 7).

The platform's closure, whichever way the file writes it (on a floating joint, or carried by one leg
in the tree), is the same system: six distances between ground points A_k and platform points B_k,
in the platform's pose (model.distances.SixDistances).  Its family over the squared leg lengths c is
solved once, at random complex c0: carried by one homotopy that moves A, B and c together
(``GeometrySegment``) from the general platform's 40 poses -- random complex A0, B0, c0, solved once
by monodromy and shipped (40 is the most for any geometry: Raghavan 1993, Wampler 1996; a general
platform has them all) --, 40 paths whose finite endpoints are every isolated pose at c0 (Morgan and
Sommese 1989); where a path fails, by monodromy from what was reached (model.homotopy.monodromy),
complete at 40 poses or when the trace test closes.
That set is kept in the cache folder (files.generic_cache) under the hash of (A, B).  Each query --
the legs' lengths of the inputs -- is one straight segment from c0 to c (``to_query``): by the theory
of coefficient-parameter homotopy every isolated pose of the query is the end of one of these paths
(some paths end at infinity, or at a singular pose).  Here the endpoints are sorted (closing, real,
distinct up to q -> -q, shared by several paths, complex without their conjugate); carrying the real
ones back to the file's joints and the certificate are analysis.position.generic_modes'.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ...files import generic_cache
from ...tolerances import Tolerances
from ..distances import SixDistances
from ..legs import chain_distance
from ..state import KinematicState
from .monodromy import Endpoints, Roots, all_roots, carry, to_target
from .symmetry import SignGroup

if TYPE_CHECKING:
    from ..kernel.algebraic import PolynomialClosure
    from ..mechanism import Mechanism

__all__ = ["BOUND", "GENERAL", "SOURCE", "Architecture", "GeometrySegment", "general_set", "architecture", "platform_group", "generic_set", "QueryEnds",
           "to_query"]

BOUND = 40
#: The general platform's generic set (random complex points and lengths) under this cache name.
GENERAL = generic_cache.key("six distances, general platform", [])
SOURCE = "Raghavan 1993; Wampler 1996: at most 40"
#: |G(x) - c0| of a cached root, relative: above it the file is not used.
_CACHED_ROOT = 1e-8
#: Routes from the general platform tried (see _from_general) before monodromy is used instead.
_TRIES = 3
#: A path lost before t = 1 - _ZONE * (the endgame's radius) is not put at infinity (monodromy.carry).
_ZONE = 0.1
#: A complex pose and its conjugate's endpoint agree to this (relative): both are tracked separately.
_CONJUGATE = 1e-6


class PlatformProblem(Protocol):
    """What ``architecture`` reads of the problem the certified search solves
    (analysis.position.certified.Problem)."""

    model: Any  # a pinocchio.Model
    frozen: np.ndarray
    q_in: np.ndarray
    target: bool


class Architecture:
    """A platform as six distances: ``A``, ``B`` (6, 3) [m] (A in the world, B in the frame of the
    platform's joint ``joint``), ``r2`` the squared lengths at the inputs [m^2], ``L`` the scale (the
    largest coordinate of A and B);
    ``carrier`` the leg in the tree as (head joints, tail joints) or None (a floating joint)."""

    def __init__(self, A: object, B: object, r2: object, joint: int,
                 carrier: tuple[list[int], list[int]] | None) -> None:
        self.A, self.B, self.r2 = np.asarray(A, float), np.asarray(B, float), np.asarray(r2, float)
        # the scale from the geometry alone: the same platform written either way shares its generic set
        L = self.L = float(max(np.abs(self.A).max(), np.abs(self.B).max(), 1e-9))
        self.joint, self.carrier = joint, carrier
        self.system = SixDistances(self.A / L, self.B / L)
        self.key = generic_cache.key("six distances", [self.A / L, self.B / L])


def architecture(problem: PlatformProblem, closure: PolynomialClosure, mech: Mechanism) -> Architecture | None:
    """The platform of a closure (its legs eliminated) that known_counts recognized as a Stewart-Gough
    platform (of ``mech``), or None."""
    L = mech.length
    model = problem.model
    if problem.target or any(leg.parent != 0 for leg in closure.legs):
        return None
    joints = {model.frames[leg.other].parentJoint for leg in closure.legs}
    if len(joints) != 1:
        return None
    joint = joints.pop()
    A = [np.asarray(leg.centre, float) for leg in closure.legs]
    B = [np.asarray(model.frames[leg.other].placement.translation, float) for leg in closure.legs]
    r2 = list(np.asarray(closure.r2, float) * L ** 2)
    carrier = None
    if len(closure.legs) == 6:
        if closure.kind[joint] != "F" or model.parents[joint] != 0 or set(closure.slices) != {joint}:
            return None
    elif len(closure.legs) == 5:
        got = chain_distance(model, problem.frozen, joint, L)
        if got is None:
            return None
        a, b = got
        chain = []
        j = joint
        while j > 0:
            chain.append(j)
            j = model.parents[j]
        chain.reverse()
        head, tail = chain[:2], chain[-3:]
        if any(closure.kind[j] != "R" or j not in closure.slices for j in head + tail):
            return None
        if set(closure.slices) != set(head + tail):  # nothing else unknown: the pose sets every joint
            return None
        placement = KinematicState(mech, problem.q_in).joint_placement(joint)
        A.insert(0, np.asarray(a, float))
        B.insert(0, np.asarray(b, float))
        r2.insert(0, float(np.sum((placement.act(np.asarray(b)) - a) ** 2)))
        carrier = (head, tail)
    else:
        return None
    return Architecture(A, B, r2, joint, carrier)


def platform_group() -> SignGroup:
    """The platform's one sign symmetry: q -> -q is the same pose."""
    return SignGroup(7, [[1, 1, 1, -1, -1, -1, -1]])


def _kept(system: SixDistances, c0: np.ndarray, X: np.ndarray, tol: Tolerances) -> bool:
    """Whether a set read back holds: every root closes G(x) = c0 on the quaternions' sphere, and no
    two are one pose."""
    group = platform_group()
    ok = (system.residual(X, c0) <= _CACHED_ROOT * (1 + np.abs(c0).max())) & system.on_variety(X, 1e-8)
    return bool(ok.all()) and len(group.distinct(X, tol.homotopy_same)) == len(X)


def general_set(rng: np.random.Generator, tol: Tolerances) -> tuple[tuple, np.ndarray, Path | None] | None:
    """The general platform's generic set: ((A0, B0, c0), its 40 poses X0 (40, 7), where it is kept) --
    random complex points A0, B0 and lengths c0, solved by monodromy until the published bound is
    reached (then complete) -- shipped with screwkin, else solved once and kept; None when monodromy
    stops short of 40."""
    got = generic_cache.read(GENERAL, 7, 42)
    if got is not None:
        p0, X, _how, kept = got
        A0, B0, c0 = p0[:18].reshape(6, 3), p0[18:36].reshape(6, 3), p0[36:]
        if len(X) == BOUND and _kept(SixDistances(A0, B0), c0, X, tol):
            return (A0, B0, c0), X, kept
    A0, B0 = (rng.normal(size=(2, 6, 3)) + 1j * rng.normal(size=(2, 6, 3))) / np.sqrt(2)
    system = SixDistances(A0, B0)
    roots = all_roots(system, platform_group(), system.random_points(rng, 1), rng, tol, trace_test=False,
                      stop_at=BOUND)
    if len(roots.X) != BOUND:
        return None
    path = generic_cache.write(GENERAL, np.r_[A0.ravel(), B0.ravel(), roots.c0], roots.X,
                               f"the published bound ({SOURCE})")
    return (A0, B0, roots.c0), roots.X, path


class GeometrySegment:
    """H(x, t) = G(x; A(t), B(t)) - c(t): the six distance rows (model.distances.SixDistances) with
    the points and the squared lengths all moving along one straight segment from p0 = (A0, B0, c0) to
    p1 = (A1, B1, c1) -- the homotopy in the coefficients that carries the general platform's poses to a
    platform's own (the tracker's Homotopy protocol; T may be complex, for the Cauchy endgame)."""

    def __init__(self, system: SixDistances, p0: tuple, p1: tuple) -> None:
        self.system, self.n = system, 6
        self.a = [np.asarray(v, complex) for v in p0]
        self.d = [np.asarray(w, complex) - v for v, w in zip(self.a, p1)]

    def _at(self, T: np.ndarray) -> tuple:
        T = np.asarray(T, complex)
        return tuple(v + T.reshape((-1,) + (1,) * v.ndim) * dv for v, dv in zip(self.a, self.d))

    def evaluate(self, X: np.ndarray, T: np.ndarray, index: np.ndarray, jacobian: bool = True) -> tuple:
        A, B, c = self._at(T)
        G, J = self.system.equations(X, jacobian, A, B)
        return G - c, J

    def dt(self, X: np.ndarray, T: np.ndarray, index: np.ndarray) -> np.ndarray:
        A, B, _ = self._at(T)
        return self.system.moved(X, self.d[0], self.d[1], A, B) - self.d[2]

    def retract(self, X: np.ndarray, dT: np.ndarray) -> np.ndarray:
        return self.system.retract(X, dT)


def _from_general(arch: Architecture, rng: np.random.Generator, tol: Tolerances) -> tuple[Roots | None, Roots | None, str]:
    """(the platform's generic set carried from the general platform's, or None; the roots found when
    they do not make a certain set, or None; why not).  A segment from (A0, B0, c0) to the platform's
    own points and random complex lengths c1 = G(x1) (x1 a random complex pose) reaches every isolated
    pose at c1 (Morgan and Sommese 1989) -- where each path's end is told rightly.  The set is taken
    when one route ends on 40 distinct regular poses (the bound: nothing can be missing), else when
    two routes to the same c1 (the second and third through other random complex lengths: ``_route``),
    none with a failed path, end on the same poses: an endgame that calls a finite pose "at infinity"
    (another branch point inside its loop) does not do so on two routes alike.  x1, a pose known
    beforehand, must be among them."""
    t0 = time.perf_counter()
    general = general_set(rng, tol)
    if general is None:
        return None, None, "the general platform's 40 poses were not found"
    p0, X0, _ = general
    system, group = arch.system, platform_group()
    x1 = system.random_points(rng, 1)
    c1 = system.offsets(x1)[0]
    p1 = (system.A, system.B, c1)
    sets: list[np.ndarray] = []
    union = np.zeros((0, 7), complex)
    paths, failed, why = 0, 0, ""
    for route in range(_TRIES):
        X, bad, n = _route(system, p0, X0, p1, rng if route else None, tol)
        paths, failed = paths + n, failed + bad
        both = np.concatenate([union, X])
        union = both[group.distinct(both, tol.homotopy_same)]
        if len(X) and not _kept(system, c1, X, tol):
            why = "the endpoints do not close"
            break
        if not bad:
            sets.append(X)
        # the bound reached by the distinct regular poses of the routes so far, or two clean routes alike
        if len(union) == BOUND or sum(len(S) == len(union) for S in sets) >= 2:
            roots = Roots(union, c1, True, None, "", route + 1, paths, failed, 0, time.perf_counter() - t0, group)
            if group.match(x1, union, tol.homotopy_same)[0] < 0:
                return None, roots, "the known pose was not reached"
            return roots, None, ""
        why = f"{bad} path(s) failed" if bad else "the routes ended on different poses"
    partial = Roots(union, c1, True, None, "", _TRIES, paths, failed, 0, time.perf_counter() - t0, group)
    return None, partial, why


def _route(system: SixDistances, p0: tuple, X0: np.ndarray, p1: tuple, rng: np.random.Generator | None,
           tol: Tolerances) -> tuple[np.ndarray, int, int]:
    """(the distinct regular endpoints at p1, the paths that failed or went astray, the paths tracked):
    X0 carried from p0 to p1 by one segment, or with ``rng`` by another route: a segment to the
    platform at other random complex lengths, then its finite poses along the lengths alone to p1's
    (between two generic lengths every pose stays finite and regular)."""
    group = platform_group()
    legs = [(p0, p1)]
    if rng is not None:
        via = (p1[0], p1[1], system.offsets(system.random_points(rng, 1))[0])
        legs = [(p0, via), (via, p1)]
    X, bad, paths = X0, 0, 0
    for k, (a, b) in enumerate(legs):
        ends = carry(GeometrySegment(system, a, b), X, tol, zone=_ZONE * tol.track_endgame)
        paths += len(X)
        regular = ends.status == "regular"
        # on the first leg a path may end at infinity (fewer poses than 40), never failed or at a singular
        # point: the set's words ("N finite, the rest at infinity") are then true
        bad += int(np.sum(np.isin(ends.status, ("failed", "singular")))) if k == 0 else int(np.sum(~regular))
        found = ends.X[regular]
        keep = group.distinct(found, tol.homotopy_same)
        bad += len(found) - len(keep)  # two paths on one pose: one went astray
        X = found[keep]
    return X, bad, paths


def generic_set(arch: Architecture, rng: np.random.Generator,
                tol: Tolerances) -> tuple[Roots, str | None, Path | None, bool]:
    """(Roots at generic c0, how its completeness is known or None, where it is kept or None, reused):
    kept from before, else carried from the general platform's set (``_from_general``), else -- where
    that does not hold -- by monodromy closed by the published count or the trace test."""
    system, group = arch.system, platform_group()
    got = generic_cache.read(arch.key, 7, 6)
    if got is not None:
        c0, X, how, kept = got
        whole = len(X) == BOUND if how.startswith("the published bound") else len(X) <= BOUND
        if whole and _kept(system, c0, X, tol):
            roots = Roots(X, c0, True, None, "", 0, 0, 0, 0, 0.0, group)
            return roots, how, kept, True
    carried, partial, _why = _from_general(arch, rng, tol)
    if carried is not None:
        how = (f"a parameter homotopy from the general platform's {BOUND} poses ({SOURCE}; Morgan and Sommese "
               f"1989): {len(carried.X)} finite, {BOUND - len(carried.X)} at infinity")
        return carried, how, generic_cache.write(arch.key, carried.c0, carried.X, how), False
    # monodromy, from the poses the segments did reach where they reached any
    seeds = partial.X if partial is not None and len(partial.X) else None
    x0 = seeds[:1] if seeds is not None else system.random_points(rng, 1)
    roots = all_roots(system, group, x0, rng, tol, seeds=seeds, trace_test=False, stop_at=BOUND)
    how = None
    if len(roots.X) == BOUND:
        how = f"the published bound ({SOURCE})"
    elif len(roots.X) < BOUND:
        roots = all_roots(system, group, roots.X[:1], rng, replace(tol, homotopy_budget=tol.homotopy_fallback_budget),
                          seeds=roots.X, trace_test=True, trace_limit=None)
        if roots.complete and len(roots.X) <= BOUND:
            how = f"the trace test (relative singular value {roots.trace:.1g})"
    path = generic_cache.write(arch.key, roots.c0, roots.X, how) if how else None
    return roots, how, path, False


@dataclass(frozen=True)
class QueryEnds:
    """The generic set's paths carried to a query's leg lengths, sorted.

    ends: the endpoints (model.homotopy.monodromy.Endpoints; X (P, 7) in (t / L, q));
    closes (P,): a finite endpoint where the six rows hold; real (P,): one of those with a real pose;
    distinct: the index of one endpoint per pose (q and -q one pose), in path order;
    meets (P,): an endpoint another path reached too (a multiple pose);
    lone: complex poses whose conjugate is not among the distinct ones (the lengths are real: a lone
    one is a real pose misjudged, or a path gone astray)."""

    ends: Endpoints
    closes: np.ndarray
    real: np.ndarray
    distinct: list[int]
    meets: np.ndarray
    lone: int


def to_query(arch: Architecture, roots: Roots, tol: Tolerances, rng: np.random.Generator | None = None) -> QueryEnds:
    """The generic set ``roots`` carried to the leg lengths of ``arch`` (its ``r2``) and sorted.  With
    ``rng``, a query whose paths did not all arrive cleanly (a path failed, a complex pose without its
    conjugate, two paths on one pose) is carried again by another route -- through random complex
    lengths on the way, which changes every path but not where they end -- and the route with fewer
    such endpoints is kept."""
    target = arch.r2 / arch.L ** 2
    got = _sorted(arch, to_target(arch.system, roots, target, tol), target, tol)
    if rng is None or not _troubles(got):
        return got
    c = np.asarray(roots.c0, complex)
    mid = 0.5 * (c + target) + np.abs(c - target).max() * (rng.normal(size=c.shape) + 1j * rng.normal(size=c.shape))
    half = to_target(arch.system, roots, mid, tol)
    if not np.all(half.status == "regular"):
        return got
    again = _sorted(arch, to_target(arch.system, replace(roots, X=half.X, c0=mid), target, tol), target, tol)
    again = replace(again, ends=replace(again.ends, paths=again.ends.paths + half.paths + got.ends.paths))
    return again if _troubles(again) < _troubles(got) else got


def _troubles(q: QueryEnds) -> int:
    """How many endpoints of a query did not arrive cleanly (see ``to_query``)."""
    return int(np.sum(q.ends.status == "failed")) + q.lone + int(q.meets.sum())


def _sorted(arch: Architecture, ends: Endpoints, target: np.ndarray, tol: Tolerances) -> QueryEnds:
    """The endpoints of a query sorted (QueryEnds)."""
    group, system = platform_group(), arch.system
    X, status = ends.X, ends.status
    finite = np.isin(status, ("regular", "singular"))
    safe = np.where(np.isfinite(X), X, 0)
    scale = 1.0 + np.abs(safe).max(axis=1)
    closes = finite & (system.residual(safe, target) <= tol.homotopy_closes * scale ** 2)
    real = closes & (np.abs(safe.imag).max(axis=1) <= tol.homotopy_real * scale)
    distinct: list[int] = []
    meets = np.zeros(len(X), bool)
    for i in np.flatnonzero(closes):
        j = group.match(X[i][None], X[distinct], tol.homotopy_same)[0] if distinct else -1
        if j >= 0:
            meets[i] = meets[distinct[j]] = True
        else:
            distinct.append(int(i))
    cplx = [i for i in distinct if not real[i]]
    lone = sum(group.match(np.conj(X[i])[None], X[[k for k in cplx if k != i]], _CONJUGATE)[0] < 0 for i in cplx) \
        if len(cplx) > 1 else len(cplx)
    return QueryEnds(ends, closes, real, distinct, meets, int(lone))
